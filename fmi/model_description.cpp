#include "fmi/model_description.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <sstream>

namespace dydp::fmi {
namespace {

/// Shortest text that reads back to the same double (17 significant digits at most).
std::string number(double v) {
  char text[32];
  for (int digits = 6; digits <= 17; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, v);
    if (std::strtod(text, nullptr) == v) break;
  }
  return text;
}

std::string list(const std::vector<uint32_t>& refs) {
  std::string s;
  for (uint32_t r : refs) s += (s.empty() ? "" : " ") + std::to_string(r);
  return s;
}

const char* causality(Role r) {
  switch (r) {
    case Role::time: return "independent";
    case Role::parameter: return "parameter";
    case Role::input: return "input";
    case Role::output_signal:
    case Role::output_objective:
    case Role::output_sensitivity: return "output";
    default: return "local";
  }
}

bool is_output(Role r) {
  return r == Role::output_signal || r == Role::output_objective || r == Role::output_sensitivity;
}

/// The attributes both interface elements share.
std::string capabilities() {
  return " canGetAndSetFMUState=\"true\" canSerializeFMUState=\"true\" providesDirectionalDerivatives=\"true\""
         " providesAdjointDerivatives=\"true\"";
}

}  // namespace

std::string xml_escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string model_description_xml(const engine::Diagram& d, const VariableTable& t, const DescriptionOptions& o) {
  std::ostringstream x;
  x << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  x << "<fmiModelDescription fmiVersion=\"3.0\" modelName=\"" << xml_escape(o.model_name) << "\" instantiationToken=\""
    << t.token << "\"";
  if (!o.description.empty()) x << " description=\"" << xml_escape(o.description) << "\"";
  x << " generationTool=\"dydp\"";
  if (!o.generation_date.empty()) x << " generationDateAndTime=\"" << o.generation_date << "\"";
  x << " variableNamingConvention=\"structured\">\n";
  if (o.model_exchange)
    x << "  <ModelExchange modelIdentifier=\"" << o.model_identifier << "\"" << capabilities()
      << " needsCompletedIntegratorStep=\"false\"/>\n";
  if (o.co_simulation)
    x << "  <CoSimulation modelIdentifier=\"" << o.model_identifier << "\"" << capabilities()
      << " canHandleVariableCommunicationStepSize=\"true\" hasEventMode=\"false\"/>\n";
  std::set<std::string> units;
  for (const Variable& v : t.variables)
    if (!v.unit.empty()) units.insert(v.unit);
  if (!units.empty()) {
    x << "  <UnitDefinitions>\n";
    for (const std::string& u : units) x << "    <Unit name=\"" << xml_escape(u) << "\"/>\n";
    x << "  </UnitDefinitions>\n";
  }
  x << "  <LogCategories>\n"
       "    <Category name=\"logStatusError\" description=\"errors: misuse of the interface, a block refusing a point, a solver failure\"/>\n"
       "    <Category name=\"logStatusDiscard\" description=\"a block refused the point: the integrator should retry with a smaller step\"/>\n"
       "    <Category name=\"logEvents\" description=\"events at the blocks' breakpoints\"/>\n"
       "  </LogCategories>\n";
  x << "  <DefaultExperiment startTime=\"" << number(d.time.start) << "\" stopTime=\"" << number(d.time.stop)
    << "\" tolerance=\"" << number(d.solver.rtol) << "\" stepSize=\"" << number(d.time.output_step) << "\"/>\n";
  x << "  <ModelVariables>\n";
  for (const Variable& v : t.variables) {
    x << "    <Float64 name=\"" << xml_escape(v.name) << "\" valueReference=\"" << v.value_reference << "\"";
    if (!v.description.empty()) x << " description=\"" << xml_escape(v.description) << "\"";
    x << " causality=\"" << causality(v.role) << "\"";
    x << " variability=\"" << (v.role == Role::parameter ? "tunable" : "continuous") << "\"";
    if (v.role == Role::state || v.role == Role::derivative || is_output(v.role) || v.role == Role::event_indicator)
      x << " initial=\"calculated\"";
    if (v.role == Role::parameter) x << " initial=\"exact\"";
    if (!v.unit.empty()) x << " unit=\"" << xml_escape(v.unit) << "\"";
    if (std::isfinite(v.min)) x << " min=\"" << number(v.min) << "\"";
    if (std::isfinite(v.max)) x << " max=\"" << number(v.max) << "\"";
    if (v.role == Role::state) x << " nominal=\"" << number(t.nominals[v.index]) << "\"";
    if (v.role == Role::derivative) x << " derivative=\"" << t.first_state + v.index << "\"";
    if (v.has_start && (v.role == Role::parameter || v.role == Role::input)) x << " start=\"" << number(v.start) << "\"";
    x << "/>\n";
  }
  x << "  </ModelVariables>\n";
  x << "  <ModelStructure>\n";
  for (const Variable& v : t.variables)
    if (is_output(v.role))
      x << "    <Output valueReference=\"" << v.value_reference << "\" dependencies=\"" << list(v.dependencies) << "\"/>\n";
  for (const Variable& v : t.variables)
    if (v.role == Role::derivative)
      x << "    <ContinuousStateDerivative valueReference=\"" << v.value_reference << "\" dependencies=\""
        << list(v.dependencies) << "\"/>\n";
  for (const Variable& v : t.variables)
    if (is_output(v.role) || v.role == Role::state || v.role == Role::derivative)
      x << "    <InitialUnknown valueReference=\"" << v.value_reference << "\"/>\n";
  for (const Variable& v : t.variables)
    if (v.role == Role::event_indicator)
      x << "    <EventIndicator valueReference=\"" << v.value_reference << "\" dependencies=\"\"/>\n";
  x << "  </ModelStructure>\n";
  x << "</fmiModelDescription>\n";
  return x.str();
}

}  // namespace dydp::fmi
