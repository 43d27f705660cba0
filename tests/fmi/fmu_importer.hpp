// An FMI 3.0 importer for the tests: unpacks an FMU archive, reads its modelDescription.xml
// (the variables by name, the interface elements' attributes), loads the shared object with
// dlopen and looks up the functions with dlsym, and collects what the FMU logs.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "fmi/fmi3_interface.h"

namespace dydp::test {

struct DescribedVariable {
  std::string name;
  fmi3ValueReference value_reference = 0;
  std::map<std::string, std::string> attributes;  ///< every attribute of the <Float64> element
};

/// modelDescription.xml read with regular expressions (its shape is fixed by the writer; the
/// test of the description checks the shape itself).
struct Description {
  std::string xml;
  std::map<std::string, std::string> root;  ///< attributes of <fmiModelDescription>
  std::map<std::string, std::string> model_exchange, co_simulation;
  std::vector<DescribedVariable> variables;
  /// ModelStructure entries: (element name, attributes), in order.
  std::vector<std::pair<std::string, std::map<std::string, std::string>>> structure;

  const DescribedVariable& variable(const std::string& name) const;
  fmi3ValueReference vr(const std::string& name) const { return variable(name).value_reference; }
  /// The value references of every variable whose causality (or, for "state" and
  /// "derivative", role) is `kind`, in order.
  std::vector<fmi3ValueReference> of(const std::string& kind) const;
};

Description read_description(const std::string& path);

/// The functions of one FMU's shared object.
struct Fmi3Functions {
#define DYDP_FMI3_FUNCTION(name) decltype(&::name) name = nullptr;
  DYDP_FMI3_FUNCTION(fmi3GetVersion)
  DYDP_FMI3_FUNCTION(fmi3SetDebugLogging)
  DYDP_FMI3_FUNCTION(fmi3InstantiateModelExchange)
  DYDP_FMI3_FUNCTION(fmi3InstantiateCoSimulation)
  DYDP_FMI3_FUNCTION(fmi3FreeInstance)
  DYDP_FMI3_FUNCTION(fmi3EnterInitializationMode)
  DYDP_FMI3_FUNCTION(fmi3ExitInitializationMode)
  DYDP_FMI3_FUNCTION(fmi3EnterEventMode)
  DYDP_FMI3_FUNCTION(fmi3Terminate)
  DYDP_FMI3_FUNCTION(fmi3Reset)
  DYDP_FMI3_FUNCTION(fmi3GetFloat64)
  DYDP_FMI3_FUNCTION(fmi3SetFloat64)
  DYDP_FMI3_FUNCTION(fmi3GetInt32)
  DYDP_FMI3_FUNCTION(fmi3GetFMUState)
  DYDP_FMI3_FUNCTION(fmi3SetFMUState)
  DYDP_FMI3_FUNCTION(fmi3FreeFMUState)
  DYDP_FMI3_FUNCTION(fmi3SerializedFMUStateSize)
  DYDP_FMI3_FUNCTION(fmi3SerializeFMUState)
  DYDP_FMI3_FUNCTION(fmi3DeserializeFMUState)
  DYDP_FMI3_FUNCTION(fmi3GetDirectionalDerivative)
  DYDP_FMI3_FUNCTION(fmi3GetAdjointDerivative)
  DYDP_FMI3_FUNCTION(fmi3UpdateDiscreteStates)
  DYDP_FMI3_FUNCTION(fmi3EnterContinuousTimeMode)
  DYDP_FMI3_FUNCTION(fmi3CompletedIntegratorStep)
  DYDP_FMI3_FUNCTION(fmi3SetTime)
  DYDP_FMI3_FUNCTION(fmi3SetContinuousStates)
  DYDP_FMI3_FUNCTION(fmi3GetContinuousStateDerivatives)
  DYDP_FMI3_FUNCTION(fmi3GetEventIndicators)
  DYDP_FMI3_FUNCTION(fmi3GetContinuousStates)
  DYDP_FMI3_FUNCTION(fmi3GetNominalsOfContinuousStates)
  DYDP_FMI3_FUNCTION(fmi3GetNumberOfEventIndicators)
  DYDP_FMI3_FUNCTION(fmi3GetNumberOfContinuousStates)
  DYDP_FMI3_FUNCTION(fmi3GetNumberOfVariableDependencies)
  DYDP_FMI3_FUNCTION(fmi3DoStep)
#undef DYDP_FMI3_FUNCTION
};

/// What the FMU sent to the logger.
struct LogRecord {
  fmi3Status status;
  std::string category, message;
};

/// One unpacked FMU: its folder, description and loaded shared object.
class Fmu {
 public:
  /// Unpacks `archive` into `folder` and loads binaries/x86_64-linux/ID.so.
  Fmu(const std::string& archive, const std::string& folder);
  ~Fmu();
  Fmu(const Fmu&) = delete;
  Fmu& operator=(const Fmu&) = delete;

  const Description& description() const { return description_; }
  const Fmi3Functions& f() const { return f_; }
  std::string resources() const { return folder_ + "/resources/"; }
  std::string token() const { return description_.root.at("instantiationToken"); }

  fmi3Instance instantiate_me(const std::string& name = "me");
  fmi3Instance instantiate_cs(const std::string& name = "cs");

  std::vector<LogRecord> log;  ///< every message the instances sent
  /// The last message at fmi3Error or above, "" if none.
  std::string last_error() const;

 private:
  std::string folder_;
  Description description_;
  void* handle_ = nullptr;
  Fmi3Functions f_;
};

}  // namespace dydp::test
