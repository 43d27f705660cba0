#include "fmi/fmu_state_bytes.hpp"

#include <cstdint>
#include <cstring>
#include <stdexcept>

namespace dydp::fmi {
namespace {

// Version 2: the states' sensitivities after the parameters.
constexpr char kStateMagic[8] = {'D', 'Y', 'D', 'P', 'F', 'M', 'U', '2'};

}  // namespace

std::vector<fmi3Byte> serialise(const std::string& token, const ModelSnapshot& s) {
  const uint64_t sizes[5] = {token.size(), s.states.size(), s.inputs.size(), s.parameters.size(),
                             s.sensitivities.size()};
  std::vector<fmi3Byte> out(
      sizeof kStateMagic + sizeof sizes + token.size() +
      (2 + s.states.size() + s.inputs.size() + s.parameters.size() + s.sensitivities.size()) * sizeof(double));
  size_t at = 0;
  auto put = [&out, &at](const void* p, size_t n) {
    if (n) std::memcpy(out.data() + at, p, n);
    at += n;
  };
  put(kStateMagic, sizeof kStateMagic);
  put(sizes, sizeof sizes);
  put(token.data(), token.size());
  put(&s.time, sizeof(double));
  put(&s.segment_start, sizeof(double));
  put(s.states.data(), s.states.size() * sizeof(double));
  put(s.inputs.data(), s.inputs.size() * sizeof(double));
  put(s.parameters.data(), s.parameters.size() * sizeof(double));
  put(s.sensitivities.data(), s.sensitivities.size() * sizeof(double));
  return out;
}

ModelSnapshot deserialise(const std::string& token, const ModelSnapshot& now, const fmi3Byte* data, size_t size) {
  size_t at = 0;
  auto take = [&](void* p, size_t n) {
    if (size - at < n) throw std::invalid_argument("serialized FMU state too short");
    if (n) std::memcpy(p, data + at, n);  // an empty vector's data() may be null
    at += n;
  };
  char magic[8];
  take(magic, 8);
  if (std::memcmp(magic, kStateMagic, 8) != 0) throw std::invalid_argument("not a serialized FMU state of dydp");
  uint64_t sizes[5];
  take(sizes, sizeof sizes);
  if (sizes[0] != token.size() || sizes[1] != now.states.size() || sizes[2] != now.inputs.size() ||
      sizes[3] != now.parameters.size() || sizes[4] != now.sensitivities.size())
    throw std::invalid_argument("serialized FMU state of another model");
  std::string their(token.size(), ' ');
  take(their.data(), their.size());
  if (their != token) throw std::invalid_argument("serialized FMU state of another model (token " + their + ")");
  ModelSnapshot s = now;
  take(&s.time, sizeof(double));
  take(&s.segment_start, sizeof(double));
  take(s.states.data(), s.states.size() * sizeof(double));
  take(s.inputs.data(), s.inputs.size() * sizeof(double));
  take(s.parameters.data(), s.parameters.size() * sizeof(double));
  take(s.sensitivities.data(), s.sensitivities.size() * sizeof(double));
  if (at != size) throw std::invalid_argument("serialized FMU state has trailing bytes");
  return s;
}

}  // namespace dydp::fmi
