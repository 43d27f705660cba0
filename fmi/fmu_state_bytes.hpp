// An FMU state as bytes (fmi3SerializeFMUState, fmi3DeserializeFMUState): a header, the
// instantiation token of the model it belongs to, then time, segment start, states, inputs,
// parameters and the states' sensitivities (when the FMU has directions), so that bytes of
// another model or damaged bytes are refused.
#pragma once

#include <string>
#include <vector>

#include "fmi/fmi3_interface.h"
#include "fmi/fmu_model.hpp"

namespace dydp::fmi {

std::vector<fmi3Byte> serialise(const std::string& token, const ModelSnapshot& s);
/// The state in `data`, checked against the token and the sizes of `like` (the instance's own
/// state). Throws std::invalid_argument.
ModelSnapshot deserialise(const std::string& token, const ModelSnapshot& like, const fmi3Byte* data, size_t size);

}  // namespace dydp::fmi
