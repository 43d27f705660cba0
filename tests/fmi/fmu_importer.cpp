#include "tests/fmi/fmu_importer.hpp"

#include <dlfcn.h>

#include <cstring>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>

#include "fmi/fmu_archive.hpp"

namespace dydp::test {
namespace {

std::map<std::string, std::string> attributes_of(const std::string& element) {
  static const std::regex attribute(R"re(([A-Za-z_:][A-Za-z0-9_:.-]*)="([^"]*)")re");
  std::map<std::string, std::string> out;
  for (auto it = std::sregex_iterator(element.begin(), element.end(), attribute); it != std::sregex_iterator(); ++it)
    out[(*it)[1]] = (*it)[2];
  return out;
}

std::string unescape(std::string s) {
  const std::pair<const char*, const char*> entities[] = {{"&lt;", "<"}, {"&gt;", ">"}, {"&quot;", "\""}, {"&apos;", "'"}, {"&amp;", "&"}};
  for (const auto& [from, to] : entities)
    for (size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + 1)) s.replace(at, std::strlen(from), to);
  return s;
}

void log_to(fmi3InstanceEnvironment environment, fmi3Status status, fmi3String category, fmi3String message) {
  static_cast<Fmu*>(environment)->log.push_back({status, category ? category : "", message ? message : ""});
}

}  // namespace

const DescribedVariable& Description::variable(const std::string& name) const {
  for (const DescribedVariable& v : variables)
    if (v.name == name) return v;
  throw std::out_of_range("no variable " + name + " in modelDescription.xml");
}

std::vector<fmi3ValueReference> Description::of(const std::string& kind) const {
  std::vector<fmi3ValueReference> out;
  for (const DescribedVariable& v : variables) {
    const bool derivative = v.attributes.count("derivative") > 0;
    bool state = false;
    for (const DescribedVariable& w : variables)
      if (w.attributes.count("derivative") && std::stoul(w.attributes.at("derivative")) == v.value_reference) state = true;
    const std::string causality = v.attributes.count("causality") ? v.attributes.at("causality") : "local";
    if ((kind == "state" && state) || (kind == "derivative" && derivative) || kind == causality)
      out.push_back(v.value_reference);
  }
  return out;
}

Description read_description(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  Description d;
  d.xml = s.str();
  std::smatch m;
  if (std::regex_search(d.xml, m, std::regex("<fmiModelDescription[^>]*>"))) d.root = attributes_of(m.str());
  if (std::regex_search(d.xml, m, std::regex("<ModelExchange[^>]*>"))) d.model_exchange = attributes_of(m.str());
  if (std::regex_search(d.xml, m, std::regex("<CoSimulation[^>]*>"))) d.co_simulation = attributes_of(m.str());
  static const std::regex float64("<Float64 [^>]*>");
  for (auto it = std::sregex_iterator(d.xml.begin(), d.xml.end(), float64); it != std::sregex_iterator(); ++it) {
    DescribedVariable v;
    v.attributes = attributes_of(it->str());
    for (auto& [key, value] : v.attributes) value = unescape(value);
    v.name = v.attributes["name"];
    v.value_reference = static_cast<fmi3ValueReference>(std::stoul(v.attributes["valueReference"]));
    d.variables.push_back(v);
  }
  static const std::regex entry("<(Output|ContinuousStateDerivative|InitialUnknown|EventIndicator) [^>]*>");
  for (auto it = std::sregex_iterator(d.xml.begin(), d.xml.end(), entry); it != std::sregex_iterator(); ++it)
    d.structure.emplace_back((*it)[1], attributes_of(it->str()));
  return d;
}

Fmu::Fmu(const std::string& archive, const std::string& folder) : folder_(folder) {
  fmi::extract_archive(archive, folder);
  description_ = read_description(folder + "/modelDescription.xml");
  const std::string id = !description_.model_exchange.empty() ? description_.model_exchange.at("modelIdentifier")
                                                              : description_.co_simulation.at("modelIdentifier");
  const std::string so = folder + "/binaries/x86_64-linux/" + id + ".so";
  handle_ = dlopen(so.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle_) throw std::runtime_error(std::string("dlopen: ") + dlerror());
#define DYDP_FMI3_LOOKUP(name)                                                                         \
  f_.name = reinterpret_cast<decltype(f_.name)>(dlsym(handle_, #name));                                \
  if (!f_.name) throw std::runtime_error(so + ": no symbol " #name);
  DYDP_FMI3_LOOKUP(fmi3GetVersion)
  DYDP_FMI3_LOOKUP(fmi3SetDebugLogging)
  DYDP_FMI3_LOOKUP(fmi3InstantiateModelExchange)
  DYDP_FMI3_LOOKUP(fmi3InstantiateCoSimulation)
  DYDP_FMI3_LOOKUP(fmi3FreeInstance)
  DYDP_FMI3_LOOKUP(fmi3EnterInitializationMode)
  DYDP_FMI3_LOOKUP(fmi3ExitInitializationMode)
  DYDP_FMI3_LOOKUP(fmi3EnterEventMode)
  DYDP_FMI3_LOOKUP(fmi3Terminate)
  DYDP_FMI3_LOOKUP(fmi3Reset)
  DYDP_FMI3_LOOKUP(fmi3GetFloat64)
  DYDP_FMI3_LOOKUP(fmi3SetFloat64)
  DYDP_FMI3_LOOKUP(fmi3GetInt32)
  DYDP_FMI3_LOOKUP(fmi3GetFMUState)
  DYDP_FMI3_LOOKUP(fmi3SetFMUState)
  DYDP_FMI3_LOOKUP(fmi3FreeFMUState)
  DYDP_FMI3_LOOKUP(fmi3SerializedFMUStateSize)
  DYDP_FMI3_LOOKUP(fmi3SerializeFMUState)
  DYDP_FMI3_LOOKUP(fmi3DeserializeFMUState)
  DYDP_FMI3_LOOKUP(fmi3GetDirectionalDerivative)
  DYDP_FMI3_LOOKUP(fmi3GetAdjointDerivative)
  DYDP_FMI3_LOOKUP(fmi3UpdateDiscreteStates)
  DYDP_FMI3_LOOKUP(fmi3EnterContinuousTimeMode)
  DYDP_FMI3_LOOKUP(fmi3CompletedIntegratorStep)
  DYDP_FMI3_LOOKUP(fmi3SetTime)
  DYDP_FMI3_LOOKUP(fmi3SetContinuousStates)
  DYDP_FMI3_LOOKUP(fmi3GetContinuousStateDerivatives)
  DYDP_FMI3_LOOKUP(fmi3GetEventIndicators)
  DYDP_FMI3_LOOKUP(fmi3GetContinuousStates)
  DYDP_FMI3_LOOKUP(fmi3GetNominalsOfContinuousStates)
  DYDP_FMI3_LOOKUP(fmi3GetNumberOfEventIndicators)
  DYDP_FMI3_LOOKUP(fmi3GetNumberOfContinuousStates)
  DYDP_FMI3_LOOKUP(fmi3GetNumberOfVariableDependencies)
  DYDP_FMI3_LOOKUP(fmi3DoStep)
#undef DYDP_FMI3_LOOKUP
}

Fmu::~Fmu() {
  if (handle_) dlclose(handle_);
}

fmi3Instance Fmu::instantiate_me(const std::string& name) {
  return f_.fmi3InstantiateModelExchange(name.c_str(), token().c_str(), resources().c_str(), false, false, this, log_to);
}

fmi3Instance Fmu::instantiate_cs(const std::string& name) {
  return f_.fmi3InstantiateCoSimulation(name.c_str(), token().c_str(), resources().c_str(), false, false, false, false,
                                        nullptr, 0, this, log_to, nullptr);
}

std::string Fmu::last_error() const {
  for (auto it = log.rbegin(); it != log.rend(); ++it)
    if (it->status >= fmi3Error) return it->message;
  return "";
}

}  // namespace dydp::test
