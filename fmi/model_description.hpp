// modelDescription.xml (FMI 3.0, 2.4 "FMU Description Schema") from the FMU's variable table:
// the interface types, units, log categories, the default experiment (the scene's time span
// and solver), the variables and the ModelStructure with the diagram's dependencies.
#pragma once

#include <string>

#include "engine/framework/diagram.hpp"
#include "fmi/variable_table.hpp"

namespace dydp::fmi {

struct DescriptionOptions {
  std::string model_identifier;  ///< the shared object's name: binaries/x86_64-linux/ID.so
  std::string model_name;
  std::string description;
  bool model_exchange = true;
  bool co_simulation = true;
  std::string generation_date;   ///< ISO 8601; empty: left out
};

std::string model_description_xml(const engine::Diagram& d, const VariableTable& t, const DescriptionOptions& o);

/// `text` with &, <, >, " and ' escaped for an XML attribute.
std::string xml_escape(const std::string& text);

}  // namespace dydp::fmi
