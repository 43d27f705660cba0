// The FMU archive and its modelDescription.xml (required elements and attributes of FMI 3.0,
// and the ModelStructure's dependencies against the tangents), the export's errors (named by
// file, line and field, nothing written), and misuse of the FMI functions: calls in the wrong
// state, unknown value references, freeing twice, NaN inputs, a block refusing a point. Each
// returns its error code and logs why; none crashes.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <set>

#include "engine/evaluation/evaluator.hpp"
#include "engine/framework/errors.hpp"
#include "engine/linear/signal_lookup.hpp"
#include "fmi/fmu_archive.hpp"
#include "tests/fmi/fmu_fixture.hpp"

namespace dydp::test {
namespace {

namespace fs = std::filesystem;

bool has(const std::vector<std::string>& v, const std::string& s) { return std::find(v.begin(), v.end(), s) != v.end(); }

TEST(FmuArchive, HoldsTheDescriptionTheSharedObjectAndTheScene) {
  auto fmu = load_fmu(kQuarterCar, "quarter_car_cdc", "archive");
  const auto entries = fmi::archive_entries((FmuFolder::path() / "quarter_car_cdc.fmu").string());
  EXPECT_TRUE(has(entries, "modelDescription.xml"));
  EXPECT_TRUE(has(entries, "binaries/x86_64-linux/quarter_car_cdc.so"));
  EXPECT_TRUE(has(entries, "resources/fmu.yaml"));
  EXPECT_TRUE(has(entries, "resources/model/quarter_car_cdc.yaml"));
  // A subsystem's scene carries the subsystem file, at its place beside the scene.
  auto corner = load_fmu(kCornerRig, "corner_rig", "archive");
  const auto corner_entries = fmi::archive_entries((FmuFolder::path() / "corner_rig.fmu").string());
  EXPECT_TRUE(has(corner_entries, "resources/model/fmu/corner_rig_scene.yaml"));
  EXPECT_TRUE(has(corner_entries, "resources/model/subsystems/corner_rig.yaml"));
}

/// An FMU of the description checks: its source (a function: a description written into the
/// test folder), its name, and whether it is Co-Simulation only (sensitivity outputs).
struct DescribedFmu {
  std::function<std::string()> source;
  std::string name;
  bool cs_only = false;
};

void PrintTo(const DescribedFmu& c, std::ostream* os) { *os << c.name; }

class Description : public ::testing::TestWithParam<DescribedFmu> {};

TEST_P(Description, HasTheRequiredElementsAndAttributes) {
  const DescribedFmu c = GetParam();
  const std::string name = c.name;
  auto fmu = load_fmu(c.source(), name, "description", c.cs_only);
  const auto& d = fmu->description();
  const std::string file = (FmuFolder::path() / (name + "_description") / "modelDescription.xml").string();
  ASSERT_EQ(std::system("command -v xmllint > /dev/null 2>&1"), 0) << "xmllint missing (scripts/setup.sh installs libxml2-utils)";
  EXPECT_EQ(std::system(("xmllint --noout " + file).c_str()), 0) << "not well-formed XML";
  EXPECT_EQ(d.root.at("fmiVersion"), "3.0");
  EXPECT_EQ(d.root.at("modelName"), name);
  EXPECT_FALSE(d.root.at("instantiationToken").empty());
  EXPECT_EQ(d.model_exchange.empty(), c.cs_only);
  for (const auto* element : {&d.model_exchange, &d.co_simulation}) {
    if (element->empty() && c.cs_only) continue;
    ASSERT_FALSE(element->empty());
    EXPECT_EQ(element->at("modelIdentifier"), name);
    EXPECT_EQ(element->at("providesDirectionalDerivatives"), "true");
    EXPECT_EQ(element->at("providesAdjointDerivatives"), "true");
    EXPECT_EQ(element->at("canGetAndSetFMUState"), "true");
    EXPECT_EQ(element->at("canSerializeFMUState"), "true");
  }
  EXPECT_NE(d.xml.find("<DefaultExperiment "), std::string::npos);
  EXPECT_NE(d.xml.find("<ModelVariables>"), std::string::npos);
  EXPECT_NE(d.xml.find("<ModelStructure>"), std::string::npos);
  // Elements in the schema's order.
  std::vector<std::string> order = {"<ModelExchange ", "<CoSimulation ", "<LogCategories>", "<DefaultExperiment ",
                                    "<ModelVariables>", "<ModelStructure>"};
  if (c.cs_only) order.erase(order.begin());
  for (size_t k = 1; k < order.size(); ++k) EXPECT_LT(d.xml.find(order[k - 1]), d.xml.find(order[k])) << order[k];

  std::set<fmi3ValueReference> refs;
  std::set<std::string> names;
  int independent = 0;
  const std::set<std::string> causalities = {"parameter", "calculatedParameter", "input", "output", "local", "independent", "structuralParameter"};
  const std::set<std::string> variabilities = {"constant", "fixed", "tunable", "discrete", "continuous"};
  for (const DescribedVariable& v : d.variables) {
    EXPECT_TRUE(refs.insert(v.value_reference).second) << "value reference " << v.value_reference << " twice";
    EXPECT_TRUE(names.insert(v.name).second) << v.name << " twice";
    ASSERT_TRUE(v.attributes.count("causality")) << v.name;
    EXPECT_TRUE(causalities.count(v.attributes.at("causality"))) << v.name;
    EXPECT_TRUE(variabilities.count(v.attributes.at("variability"))) << v.name;
    independent += v.attributes.at("causality") == "independent";
    if (v.attributes.at("causality") == "parameter" || v.attributes.at("causality") == "input") {
      EXPECT_TRUE(v.attributes.count("start")) << v.name << " needs a start value";
    }
    if (v.attributes.count("derivative")) {
      const auto& state = d.variables.at(std::stoul(v.attributes.at("derivative")));
      EXPECT_EQ(v.name, "der(" + state.name + ")");
      EXPECT_TRUE(state.attributes.count("nominal")) << state.name;
      EXPECT_GT(std::stod(state.attributes.at("nominal")), 0.0);
    }
    if (v.attributes.count("unit")) {
      EXPECT_NE(d.xml.find("<Unit name=\"" + v.attributes.at("unit") + "\""), std::string::npos) << v.name;
    }
  }
  EXPECT_EQ(independent, 1);
  size_t outputs = 0, derivatives = 0, events = 0;
  const auto states = d.of("state"), inputs = d.of("input");
  for (const auto& [element, attributes] : d.structure) {
    const fmi3ValueReference vr = std::stoul(attributes.at("valueReference"));
    ASSERT_LT(vr, d.variables.size());
    if (element == "Output") {
      EXPECT_EQ(d.variables[vr].attributes.at("causality"), "output");
      EXPECT_EQ(vr, d.of("output").at(outputs++));
    }
    if (element == "ContinuousStateDerivative") {
      EXPECT_EQ(vr, d.of("derivative").at(derivatives++));
    }
    if (element == "EventIndicator") ++events;
    if (attributes.count("dependencies")) {
      std::istringstream list(attributes.at("dependencies"));
      for (unsigned long dep; list >> dep;)
        EXPECT_TRUE(std::count(states.begin(), states.end(), dep) || std::count(inputs.begin(), inputs.end(), dep))
            << element << " " << vr << " depends on " << dep << ", neither a state nor an input";
    }
  }
  EXPECT_EQ(outputs, d.of("output").size());
  EXPECT_EQ(derivatives, d.of("derivative").size());
  EXPECT_EQ(derivatives, states.size());
  fmi3Instance inst = c.cs_only ? fmu->instantiate_cs() : fmu->instantiate_me();
  ASSERT_NE(inst, nullptr) << fmu->last_error();
  size_t n_events = 0, n_states = 0;
  EXPECT_EQ(fmu->f().fmi3GetNumberOfEventIndicators(inst, &n_events), fmi3OK);
  EXPECT_EQ(fmu->f().fmi3GetNumberOfContinuousStates(inst, &n_states), fmi3OK);
  EXPECT_EQ(n_events, events);
  EXPECT_EQ(n_states, states.size());
  fmu->f().fmi3FreeInstance(inst);
}

TEST_P(Description, DependenciesCoverEveryNonZeroOfTheJacobian) {
  const DescribedFmu c = GetParam();
  auto fmu = load_fmu(c.source(), c.name, "dependencies", c.cs_only);
  const auto& d = fmu->description();
  const Fmi3Functions& f = fmu->f();
  fmi3Instance inst = c.cs_only ? fmu->instantiate_cs() : fmu->instantiate_me();
  ASSERT_EQ(f.fmi3EnterInitializationMode(inst, false, 0.0, 0.0, false, 0.0), fmi3OK);
  ASSERT_EQ(f.fmi3ExitInitializationMode(inst), fmi3OK);
  std::vector<fmi3ValueReference> knowns = d.of("state");
  for (fmi3ValueReference vr : d.of("input")) knowns.push_back(vr);
  int nonzeros = 0;
  for (const auto& [element, attributes] : d.structure) {
    if (element != "Output" && element != "ContinuousStateDerivative") continue;
    const fmi3ValueReference vr = std::stoul(attributes.at("valueReference"));
    std::set<unsigned long> deps;
    std::istringstream list(attributes.at("dependencies"));
    for (unsigned long dep; list >> dep;) deps.insert(dep);
    size_t count = 0;
    ASSERT_EQ(f.fmi3GetNumberOfVariableDependencies(inst, vr, &count), fmi3OK);
    EXPECT_EQ(count, deps.size());
    // A sensitivity output lists its output's dependencies; its own partial derivatives
    // (second derivatives) are not given.
    if (d.variables[vr].name.rfind("d(", 0) == 0) {
      const std::string base = d.variables[vr].name.substr(2, d.variables[vr].name.find(")/d(") - 2);
      const auto& of = d.structure;
      const auto it = std::find_if(of.begin(), of.end(), [&](const auto& e) {
        return e.first == "Output" && std::stoul(e.second.at("valueReference")) == d.vr(base);
      });
      ASSERT_NE(it, of.end()) << base;
      EXPECT_EQ(it->second.at("dependencies"), attributes.at("dependencies")) << d.variables[vr].name;
      continue;
    }
    for (fmi3ValueReference k : knowns) {
      const double one = 1.0;
      double value = 0.0;
      ASSERT_EQ(f.fmi3GetDirectionalDerivative(inst, &vr, 1, &k, 1, &one, 1, &value, 1), fmi3OK) << fmu->last_error();
      if (value != 0.0) {
        ++nonzeros;
        EXPECT_TRUE(deps.count(k)) << d.variables[vr].name << " moves with " << d.variables[k].name
                                   << " but does not list it in its dependencies";
      }
    }
  }
  EXPECT_GT(nonzeros, 0);
  f.fmi3FreeInstance(inst);
}

INSTANTIATE_TEST_SUITE_P(Fmus, Description,
                         ::testing::Values(DescribedFmu{[] { return kQuarterCar; }, "quarter_car_cdc"},
                                           DescribedFmu{[] { return kDamper; }, "cdc_damper"},
                                           DescribedFmu{[] { return kCornerRig; }, "corner_rig"},
                                           DescribedFmu{[] { return damper_sensitivity_description(false); },
                                                        "cdc_damper_sens", true}),
                         [](const auto& info) { return info.param.name; });

TEST(FmuExport, KindMeWritesModelExchangeOnly) {
  fmi::ExportOptions o;
  o.source = kDamper;
  o.out = (FmuFolder::path() / "damper_me.fmu").string();
  o.co_simulation = false;
  const fmi::ExportSummary s = fmi::export_fmu(o);
  EXPECT_NE(s.model_description.find("<ModelExchange "), std::string::npos);
  EXPECT_EQ(s.model_description.find("<CoSimulation "), std::string::npos);
  EXPECT_EQ(s.inputs, 2);
  EXPECT_EQ(s.outputs, 4);
  EXPECT_EQ(s.parameters, 2);
}

/// The export of a description file with `text`, expecting InputError; returns its message.
std::string export_error(const std::string& name, const std::string& text) {
  const fs::path description = FmuFolder::path() / (".test_" + name + ".yaml");
  std::ofstream(description) << text;
  fmi::ExportOptions o;
  o.source = description.string();
  o.out = (FmuFolder::path() / (name + ".fmu")).string();
  std::string message;
  try {
    fmi::export_fmu(o);
  } catch (const engine::InputError& e) {
    message = e.what();
  }
  fs::remove(description);
  EXPECT_FALSE(fs::exists(o.out)) << "nothing is written on bad input";
  return message;
}

TEST(FmuExport, BadDescriptionsNameFileLineAndField) {
  const std::string head = "fmu: bad\nscene: " + kDamperRig + "\n";
  std::string m = export_error("unknown_input", head + "inputs: [stroke.y, nosuch.y]\n");
  EXPECT_NE(m.find(".test_unknown_input.yaml:3: inputs"), std::string::npos) << m;
  EXPECT_NE(m.find("nosuch"), std::string::npos) << m;
  m = export_error("unknown_output", head + "outputs:\n  - damper.force\n  - damper.nosuch\n");
  EXPECT_NE(m.find(".test_unknown_output.yaml:5: outputs"), std::string::npos) << m;
  EXPECT_NE(m.find("has no output nosuch"), std::string::npos) << m;
  m = export_error("unknown_parameter", head + "parameters: [valve_current, spring_rate]\n");
  EXPECT_NE(m.find(".test_unknown_parameter.yaml:3: parameters"), std::string::npos) << m;
  EXPECT_NE(m.find("spring_rate"), std::string::npos) << m;
  m = export_error("unknown_key", head + "exports: [x]\n");
  EXPECT_NE(m.find(":3: exports"), std::string::npos) << m;
  m = export_error("no_scene", "fmu: bad\nscene: " + FmuFolder::path().string() + "/nosuch.yaml\n");
  EXPECT_NE(m.find(":2: scene"), std::string::npos) << m;
  m = export_error("twice", head + "inputs: [stroke.y, stroke.y]\n");
  EXPECT_NE(m.find("listed twice"), std::string::npos) << m;
}

TEST(FmuExport, CommandLineExitsWithTwoOnBadInputAndWritesNothing) {
  const fs::path out = FmuFolder::path() / "cli_bad.fmu";
  const std::string command = std::string(DYDP_BINARY) + " fmu " + DYDP_SOURCE_DIR +
                              "/scenarios/subsystems/corner_rig.yaml --out " + out.string() + " 2> " +
                              (FmuFolder::path() / "cli_bad.err").string();
  const int status = std::system(command.c_str());
  EXPECT_EQ(WEXITSTATUS(status), 2);
  EXPECT_FALSE(fs::exists(out));
  std::ifstream err(FmuFolder::path() / "cli_bad.err");
  const std::string text((std::istreambuf_iterator<char>(err)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("corner_rig.yaml:1: scene: a subsystem file"), std::string::npos) << text;
  const fs::path good = FmuFolder::path() / "cli_good.fmu";
  EXPECT_EQ(WEXITSTATUS(std::system((std::string(DYDP_BINARY) + " fmu " + kDamper + " --out " + good.string() +
                                     " --kind cs > /dev/null").c_str())),
            0);
  EXPECT_TRUE(fs::exists(good));
}

class Misuse : public ::testing::Test {
 protected:
  void SetUp() override {
    fmu = load_fmu(kDamper, "cdc_damper", "misuse");
    inputs = fmu->description().of("input");
    outputs = fmu->description().of("output");
  }
  const Fmi3Functions& f() const { return fmu->f(); }
  fmi3Instance initialised_me() {
    fmi3Instance inst = fmu->instantiate_me();
    EXPECT_EQ(f().fmi3EnterInitializationMode(inst, false, 0.0, 0.0, false, 0.0), fmi3OK);
    EXPECT_EQ(f().fmi3ExitInitializationMode(inst), fmi3OK);
    return inst;
  }
  std::unique_ptr<Fmu> fmu;
  std::vector<fmi3ValueReference> inputs, outputs;
};

TEST_F(Misuse, CallsInTheWrongStateAreRefusedAndLogged) {
  fmi3Instance inst = fmu->instantiate_me();
  ASSERT_NE(inst, nullptr);
  EXPECT_EQ(f().fmi3SetTime(inst, 0.1), fmi3Error);
  EXPECT_NE(fmu->last_error().find("fmi3SetTime: not allowed in Instantiated"), std::string::npos) << fmu->last_error();
  EXPECT_EQ(f().fmi3ExitInitializationMode(inst), fmi3Error);
  double x[8];
  EXPECT_EQ(f().fmi3GetContinuousStateDerivatives(inst, x, 5), fmi3Error);
  fmi3Boolean b = false;
  fmi3Float64 last = 0.0;
  EXPECT_EQ(f().fmi3DoStep(inst, 0.0, 0.01, false, &b, &b, &b, &last), fmi3Error);
  ASSERT_EQ(f().fmi3EnterInitializationMode(inst, false, 0.0, 0.0, false, 0.0), fmi3OK);
  EXPECT_EQ(f().fmi3EnterInitializationMode(inst, false, 0.0, 0.0, false, 0.0), fmi3Error);
  ASSERT_EQ(f().fmi3ExitInitializationMode(inst), fmi3OK);
  EXPECT_EQ(f().fmi3CompletedIntegratorStep(inst, true, &b, &b), fmi3Error);  // Event Mode, not Continuous-Time
  size_t n = 0;
  f().fmi3GetNumberOfContinuousStates(inst, &n);
  EXPECT_EQ(f().fmi3SetContinuousStates(inst, x, n + 1), fmi3Error);
  EXPECT_NE(fmu->last_error().find("nContinuousStates"), std::string::npos);
  f().fmi3FreeInstance(inst);

  fmi3Instance cs = fmu->instantiate_cs();
  ASSERT_EQ(f().fmi3EnterInitializationMode(cs, false, 0.0, 0.0, false, 0.0), fmi3OK);
  ASSERT_EQ(f().fmi3ExitInitializationMode(cs), fmi3OK);
  EXPECT_EQ(f().fmi3DoStep(cs, 0.5, 0.01, false, &b, &b, &b, &last), fmi3Error);  // not the FMU's time
  EXPECT_EQ(f().fmi3DoStep(cs, 0.0, -0.01, false, &b, &b, &b, &last), fmi3Error);
  EXPECT_EQ(f().fmi3SetTime(cs, 0.1), fmi3Error);
  f().fmi3FreeInstance(cs);
}

TEST_F(Misuse, UnknownValueReferencesAndWrongTypesAreRefused) {
  fmi3Instance inst = initialised_me();
  const fmi3ValueReference unknown = 100000;
  double value = 0.0;
  EXPECT_EQ(f().fmi3GetFloat64(inst, &unknown, 1, &value, 1), fmi3Error);
  EXPECT_NE(fmu->last_error().find("unknown value reference 100000"), std::string::npos) << fmu->last_error();
  EXPECT_EQ(f().fmi3SetFloat64(inst, &outputs[0], 1, &value, 1), fmi3Error);
  EXPECT_NE(fmu->last_error().find("cannot be set"), std::string::npos);
  fmi3Int32 i32 = 0;
  EXPECT_EQ(f().fmi3GetInt32(inst, &outputs[0], 1, &i32, 1), fmi3Error);
  EXPECT_EQ(f().fmi3GetFloat64(inst, outputs.data(), 2, &value, 1), fmi3Error);  // nValues != nValueReferences
  const double one = 1.0;
  double out = 0.0;
  EXPECT_EQ(f().fmi3GetDirectionalDerivative(inst, &unknown, 1, &inputs[0], 1, &one, 1, &out, 1), fmi3Error);
  EXPECT_EQ(f().fmi3GetDirectionalDerivative(inst, &outputs[0], 1, &outputs[0], 1, &one, 1, &out, 1), fmi3Error);
  EXPECT_NE(fmu->last_error().find("damper.force is not a known"), std::string::npos) << fmu->last_error();
  EXPECT_EQ(f().fmi3GetDirectionalDerivative(inst, &inputs[0], 1, &inputs[0], 1, &one, 1, &out, 1), fmi3Error);
  EXPECT_NE(fmu->last_error().find("stroke.y is not an unknown"), std::string::npos) << fmu->last_error();
  size_t count = 0;
  EXPECT_EQ(f().fmi3GetNumberOfVariableDependencies(inst, unknown, &count), fmi3Error);
  f().fmi3FreeInstance(inst);
}

TEST_F(Misuse, FreeingTwiceAndStaleHandlesAreHarmless) {
  fmi3Instance inst = initialised_me();
  fmi3FMUState state = nullptr;
  ASSERT_EQ(f().fmi3GetFMUState(inst, &state), fmi3OK);
  fmi3FMUState copy = state;
  EXPECT_EQ(f().fmi3FreeFMUState(inst, &state), fmi3OK);
  EXPECT_EQ(state, nullptr);
  EXPECT_EQ(f().fmi3FreeFMUState(inst, &state), fmi3OK);  // null: nothing to free
  EXPECT_EQ(f().fmi3FreeFMUState(inst, &copy), fmi3Error);  // freed before
  EXPECT_EQ(f().fmi3SetFMUState(inst, copy), fmi3Error);
  f().fmi3FreeInstance(inst);
  f().fmi3FreeInstance(inst);  // twice: ignored
  double value = 0.0;
  EXPECT_EQ(f().fmi3GetFloat64(inst, &outputs[0], 1, &value, 1), fmi3Error);
  EXPECT_EQ(f().fmi3DoStep(inst, 0.0, 0.1, false, nullptr, nullptr, nullptr, nullptr), fmi3Error);
  f().fmi3FreeInstance(nullptr);
  EXPECT_EQ(f().fmi3EnterInitializationMode(nullptr, false, 0.0, 0.0, false, 0.0), fmi3Error);
}

TEST_F(Misuse, NotANumberAndOutOfRangeValuesAreRefusedAndChangeNothing) {
  fmi3Instance inst = initialised_me();
  double before = 0.0, after = 0.0;
  ASSERT_EQ(f().fmi3GetFloat64(inst, &inputs[0], 1, &before, 1), fmi3OK);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(f().fmi3SetFloat64(inst, &inputs[0], 1, &nan, 1), fmi3Error);
  EXPECT_NE(fmu->last_error().find("stroke.y"), std::string::npos) << fmu->last_error();
  EXPECT_NE(fmu->last_error().find("not a finite number"), std::string::npos) << fmu->last_error();
  ASSERT_EQ(f().fmi3GetFloat64(inst, &inputs[0], 1, &after, 1), fmi3OK);
  EXPECT_EQ(before, after);
  const fmi3ValueReference current = fmu->description().vr("valve_current");
  const double too_high = 5.0;
  EXPECT_EQ(f().fmi3SetFloat64(inst, &current, 1, &too_high, 1), fmi3Error);
  EXPECT_NE(fmu->last_error().find("valve_current"), std::string::npos) << fmu->last_error();
  size_t n = 0;
  f().fmi3GetNumberOfContinuousStates(inst, &n);
  std::vector<double> x(n, nan);
  ASSERT_EQ(f().fmi3EnterContinuousTimeMode(inst), fmi3OK);
  EXPECT_EQ(f().fmi3SetContinuousStates(inst, x.data(), n), fmi3Error);
  EXPECT_EQ(f().fmi3SetTime(inst, nan), fmi3Error);
  f().fmi3FreeInstance(inst);
  // A wrong token or resource folder: no instance, and a message.
  fmi3Instance bad = f().fmi3InstantiateModelExchange("bad", "{not-this-one}", fmu->resources().c_str(), false, false,
                                                       fmu.get(), [](fmi3InstanceEnvironment e, fmi3Status s, fmi3String c, fmi3String m) {
                                                         static_cast<Fmu*>(e)->log.push_back({s, c, m});
                                                       });
  EXPECT_EQ(bad, nullptr);
  EXPECT_NE(fmu->last_error().find("instantiation token"), std::string::npos) << fmu->last_error();
  EXPECT_EQ(f().fmi3InstantiateCoSimulation("bad", fmu->token().c_str(), "/nonexistent/", false, false, false, false,
                                            nullptr, 0, nullptr, nullptr, nullptr),
            nullptr);
}

TEST_F(Misuse, ABlockRefusingAPointIsNamed) {
  // A stroke far past the damper's length empties a chamber: the damper refuses the point.
  fmi3Instance inst = initialised_me();
  ASSERT_EQ(f().fmi3EnterContinuousTimeMode(inst), fmi3OK);
  const double stroke[2] = {5.0, 0.0};
  ASSERT_EQ(f().fmi3SetFloat64(inst, inputs.data(), 2, stroke, 2), fmi3OK);
  size_t n = 0;
  f().fmi3GetNumberOfContinuousStates(inst, &n);
  std::vector<double> xdot(n);
  EXPECT_EQ(f().fmi3GetContinuousStateDerivatives(inst, xdot.data(), n), fmi3Discard);
  ASSERT_FALSE(fmu->log.empty());
  EXPECT_NE(fmu->log.back().message.find("block damper"), std::string::npos) << fmu->log.back().message;
  f().fmi3FreeInstance(inst);

  fmi3Instance cs = fmu->instantiate_cs();
  ASSERT_EQ(f().fmi3EnterInitializationMode(cs, false, 0.0, 0.0, false, 0.0), fmi3OK);
  ASSERT_EQ(f().fmi3ExitInitializationMode(cs), fmi3OK);
  ASSERT_EQ(f().fmi3SetFloat64(cs, inputs.data(), 2, stroke, 2), fmi3OK);
  fmi3Boolean b = false;
  fmi3Float64 last = -1.0;
  EXPECT_EQ(f().fmi3DoStep(cs, 0.0, 0.01, false, &b, &b, &b, &last), fmi3Error);
  EXPECT_NE(fmu->last_error().find("damper"), std::string::npos) << fmu->last_error();
  EXPECT_NE(fmu->last_error().find("t = "), std::string::npos) << fmu->last_error();
  f().fmi3FreeInstance(cs);
}

TEST_F(Misuse, ResetStartsTheInstanceAgain) {
  // A run, a reset, the same run: the same outputs as at first.
  fmi3Instance cs = fmu->instantiate_cs();
  auto steps = [&] {
    EXPECT_EQ(f().fmi3EnterInitializationMode(cs, false, 0.0, 0.0, false, 0.0), fmi3OK);
    EXPECT_EQ(f().fmi3ExitInitializationMode(cs), fmi3OK);
    std::vector<double> y(outputs.size());
    for (int k = 0; k < 4; ++k) {
      const double u[2] = {rig_stroke(k * 0.01), rig_stroke_rate(k * 0.01)};
      EXPECT_EQ(f().fmi3SetFloat64(cs, inputs.data(), 2, u, 2), fmi3OK);
      fmi3Boolean b = false;
      fmi3Float64 last = 0.0;
      EXPECT_EQ(f().fmi3DoStep(cs, k * 0.01, 0.01, false, &b, &b, &b, &last), fmi3OK) << fmu->last_error();
    }
    EXPECT_EQ(f().fmi3GetFloat64(cs, outputs.data(), y.size(), y.data(), y.size()), fmi3OK);
    return y;
  };
  const std::vector<double> first = steps();
  const fmi3ValueReference current = fmu->description().vr("valve_current");
  const double soft = 1.4;
  ASSERT_EQ(f().fmi3SetFloat64(cs, &current, 1, &soft, 1), fmi3OK);  // tuned in Step Mode
  ASSERT_EQ(f().fmi3Reset(cs), fmi3OK);
  double value = 0.0;
  ASSERT_EQ(f().fmi3SetFloat64(cs, &current, 1, &value, 0), fmi3Error);  // nValues != nValueReferences
  EXPECT_EQ(steps(), first);
  ASSERT_EQ(f().fmi3GetFloat64(cs, &current, 1, &value, 1), fmi3OK);
  EXPECT_EQ(value, 0.8);  // the scene's value again
  EXPECT_EQ(f().fmi3Terminate(cs), fmi3OK);
  EXPECT_EQ(f().fmi3GetFloat64(cs, &current, 1, &value, 1), fmi3OK);
  fmi3Boolean b = false;
  fmi3Float64 last = 0.0;
  EXPECT_EQ(f().fmi3DoStep(cs, 0.04, 0.01, false, &b, &b, &b, &last), fmi3Error);
  f().fmi3FreeInstance(cs);
}

TEST(FmuOutputs, TheCornerSubsystemGivesTheNativeForcesAtTheStart) {
  auto fmu = load_fmu(kCornerRig, "corner_rig", "start");
  const Fmi3Functions& f = fmu->f();
  fmi3Instance inst = fmu->instantiate_cs();
  ASSERT_EQ(f.fmi3EnterInitializationMode(inst, false, 0.0, 0.0, false, 0.0), fmi3OK);
  ASSERT_EQ(f.fmi3ExitInitializationMode(inst), fmi3OK);
  // Inputs away from their start values, the same on both sides.
  const auto inputs = fmu->description().of("input"), outputs = fmu->description().of("output");
  std::vector<double> u = {0.012, 0.008, -0.1, 0.004, 0.05, -0.006, 0.2};
  ASSERT_EQ(u.size(), inputs.size());
  ASSERT_EQ(f.fmi3SetFloat64(inst, inputs.data(), u.size(), u.data(), u.size()), fmi3OK);
  std::vector<double> y(outputs.size());
  ASSERT_EQ(f.fmi3GetFloat64(inst, outputs.data(), y.size(), y.data(), y.size()), fmi3OK);
  engine::Diagram d = engine::load_scene(std::string(DYDP_SOURCE_DIR) + "/scenarios/fmu/corner_rig_scene.yaml");
  engine::Evaluator ev(d, false);
  std::vector<std::pair<int, double>> held;
  for (size_t j = 0; j < inputs.size(); ++j)
    held.emplace_back(engine::signal_offsets(d, fmu->description().variables[inputs[j]].name, "test").at(0), u[j]);
  ev.hold_signals(held);
  std::vector<double> x0(std::max(d.num_states, 1));
  ev.initial_state(0.0, x0.data());
  ev.outputs(0.0, x0.data());
  for (size_t j = 0; j < outputs.size(); ++j) {
    const int offset = engine::signal_offsets(d, fmu->description().variables[outputs[j]].name, "test").at(0);
    EXPECT_DOUBLE_EQ(y[j], ev.signals()[offset]) << fmu->description().variables[outputs[j]].name;
    EXPECT_NE(y[j], 0.0);
  }
  fmi3Boolean b = false;
  fmi3Float64 last = 0.0;
  EXPECT_EQ(f.fmi3DoStep(inst, 0.0, 0.005, false, &b, &b, &b, &last), fmi3OK) << fmu->last_error();
  f.fmi3FreeInstance(inst);
}

TEST(FmuExport, TheFilesASceneReadsTravelInTheFmu) {
  // A scene reading a recording through a relative path (data/curve.csv): the FMU carries the
  // file at its place beside the scene, and the FMU, unpacked elsewhere, reads it there.
  const fs::path folder = FmuFolder::path() / "table_scene";
  fs::create_directories(folder / "data");
  std::ofstream(folder / "data" / "curve.csv") << "t,y\n0.0,1.0\n1.0,3.0\n2.0,2.0\n";
  const std::string scene = R"(scene: table_scene
time: {stop: 2.0, output_step: 0.1}
blocks:
  curve: {type: source.table, file: data/curve.csv, column: y}
outputs: [curve.y]
)";
  std::ofstream(folder / "table.yaml") << scene;
  auto fmu = load_fmu((folder / "table.yaml").string(), "table_scene", "files");
  const auto entries = fmi::archive_entries((FmuFolder::path() / "table_scene.fmu").string());
  EXPECT_TRUE(has(entries, "resources/model/table.yaml"));
  EXPECT_TRUE(has(entries, "resources/model/data/curve.csv"));
  fs::remove_all(folder);  // the FMU reads its own copy
  const Fmi3Functions& f = fmu->f();
  fmi3Instance inst = fmu->instantiate_cs();
  ASSERT_NE(inst, nullptr) << fmu->last_error();
  ASSERT_EQ(f.fmi3EnterInitializationMode(inst, false, 0.0, 0.0, false, 0.0), fmi3OK) << fmu->last_error();
  ASSERT_EQ(f.fmi3ExitInitializationMode(inst), fmi3OK) << fmu->last_error();
  const auto outputs = fmu->description().of("output");
  ASSERT_EQ(outputs.size(), 1u);
  fmi3Boolean b = false;
  fmi3Float64 last = 0.0;
  ASSERT_EQ(f.fmi3DoStep(inst, 0.0, 0.5, false, &b, &b, &b, &last), fmi3OK) << fmu->last_error();
  double y = 0.0;
  ASSERT_EQ(f.fmi3GetFloat64(inst, outputs.data(), 1, &y, 1), fmi3OK);
  EXPECT_NEAR(y, 2.0, 1e-12);  // halfway between the rows at 0 and 1 s
  ASSERT_EQ(f.fmi3DoStep(inst, 0.5, 1.0, false, &b, &b, &b, &last), fmi3OK) << fmu->last_error();
  ASSERT_EQ(f.fmi3GetFloat64(inst, outputs.data(), 1, &y, 1), fmi3OK);
  EXPECT_NEAR(y, 2.5, 1e-12);
  f.fmi3FreeInstance(inst);
}

TEST(FmuExport, AnAbsolutePathToARecordingIsRefusedAtItsLine) {
  const fs::path csv = FmuFolder::path() / "absolute_curve.csv";
  std::ofstream(csv) << "t,y\n0.0,1.0\n1.0,3.0\n";
  const std::string message = export_error("absolute_path", "scene: absolute_path\ntime: {stop: 1.0, output_step: 0.1}\n"
                                                            "blocks:\n  curve:\n    type: source.table\n    file: " +
                                                                csv.string() + "\n    column: y\noutputs: [curve.y]\n");
  EXPECT_NE(message.find(":6: curve.file: "), std::string::npos) << message;
  EXPECT_NE(message.find("write this path relative to the scene"), std::string::npos) << message;
}

}  // namespace
}  // namespace dydp::test
