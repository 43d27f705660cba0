#include "engine/studies/screen_study.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "engine/analysis/cvodes_adjoint.hpp"
#include "engine/analysis/run.hpp"
#include "engine/framework/errors.hpp"
#include "engine/studies/initial_equilibrium.hpp"
#include "engine/studies/run_sharing.hpp"
#include "engine/studies/sobol_points.hpp"
#include "io/files.hpp"

namespace dydp::engine {
namespace {

namespace fs = std::filesystem;
using nlohmann::ordered_json;

std::string runs_folder(const std::string& out) { return out + "/runs"; }

/// FNV-1a of a file's bytes: a record of another scene (or subsystem) text is not resumed.
std::string file_digest(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  unsigned long long h = 1469598103934665603ull;
  for (unsigned char c : text.str()) h = (h ^ c) * 1099511628211ull;
  char buffer[17];
  std::snprintf(buffer, sizeof buffer, "%016llx", h);
  return buffer;
}

Diagram load(const ScreenSpec& spec) {
  Diagram d = load_scene(spec.scene, spec.overrides);
  apply_solver_overrides(d, spec.solver);
  return d;
}

/// What makes two invocations the same study (the number of samples aside: the first N points
/// of the Sobol' sequence do not depend on N, so a study may be resumed with more samples).
ordered_json identity(const ScreenSpec& spec, const ScreenResult& r, const Diagram& d) {
  ordered_json j;
  j["scene"] = fs::absolute(spec.scene).lexically_normal().string();
  j["scene_digest"] = file_digest(spec.scene);
  // the subsystem files the scene includes: an edited corner is another study too
  std::set<std::string> included;
  for (const Node& n : d.nodes)
    if (!n.file.empty()) included.insert(fs::absolute(n.file).lexically_normal().string());
  for (const std::string& file : included) j["subsystem_digests"][file] = file_digest(file);
  j["set"] = ordered_json::array();
  for (const auto& [name, value] : spec.overrides) j["set"].push_back(name + "=" + value);
  j["solver"] = {{"method", d.solver.method}, {"rtol", d.solver.rtol}, {"atol", d.solver.atol}, {"step", d.solver.step}};
  if (spec.adjoint) j["adjoint"] = true;
  for (const auto& range : r.ranges)
    j["parameters"].push_back({{"name", range.name}, {"lower", range.lower}, {"upper", range.upper},
                               {"nominal", range.nominal}});
  return j;
}

std::string encode(const ScreenRun& run) {
  ordered_json j = {{"index", run.index}, {"p", run.p}, {"psi", run.psi}, {"gradient", run.gradient},
                    {"cpu_seconds", run.cpu_seconds}, {"steps", run.steps}, {"warnings", run.warnings}};
  if (std::isfinite(run.error_signals))
    j["error_estimate"] = {{"signals", run.error_signals}, {"sensitivities", run.error_sensitivities}};
  return j.dump() + "\n";
}

ScreenRun decode(const std::string& text) {
  const auto j = nlohmann::json::parse(text);
  ScreenRun run;
  run.index = j.at("index");
  run.p = j.at("p").get<std::vector<double>>();
  run.psi = j.at("psi").get<std::vector<double>>();
  run.gradient = j.at("gradient").get<std::vector<std::vector<double>>>();
  run.cpu_seconds = j.at("cpu_seconds");
  run.steps = j.at("steps");
  if (j.contains("error_estimate")) {  // records written with --no-estimate have none
    run.error_signals = j["error_estimate"].at("signals");
    run.error_sensitivities = j["error_estimate"].at("sensitivities");
  }
  if (j.contains("warnings")) run.warnings = j["warnings"].get<std::vector<std::string>>();
  return run;
}

}  // namespace

std::string screen_record_path(const std::string& out, int index) {
  char name[32];
  std::snprintf(name, sizeof name, "/run_%05d.json", index);
  return runs_folder(out) + name;
}

namespace {

/// One screening study: the probe scene, the sample points and the runs the steps share.
class ScreenStudy {
 public:
  explicit ScreenStudy(const ScreenSpec& spec) : spec_(spec), probe_(load(spec)) {}

  ScreenResult run() {
    validate();
    unit_points_ = sobol_points(P_, N_);

    // Rank 0 owns the folder: it reads earlier records and writes every new one.
    const bool writer = world_rank() == 0;
    runs_.resize(N_ + 1);
    have_.assign(N_ + 1, false);
    const ordered_json id = identity(spec_, r_, probe_);
    if (writer) open_folder(id);
    run_missing();
    if (!writer) return std::move(r_);
    estimate();
    return std::move(r_);
  }

 private:
  // The study's settings and parameters checked, their ranges, units and the objectives noted.
  void validate() {
    // Validate on every rank (the same scene gives the same verdict), before any run starts.
    if (spec_.parameters.empty()) throw InputError("--params", 0, "", "name at least one parameter");
    if (spec_.samples < 2) throw InputError("--samples", 0, std::to_string(spec_.samples), "needs at least 2 samples");
    if (probe_.objectives.empty())
      throw InputError(spec_.scene, 0, "outputs", "a screening study needs at least one objective among the outputs");
    if (static_cast<int>(spec_.parameters.size()) > sobol_max_dimension())
      throw InputError("--params", 0, "", "at most " + std::to_string(sobol_max_dimension()) + " parameters");
    for (const std::string& name : spec_.parameters) add_parameter(name);
    {
      Diagram check = load(spec_);
      check.set_sensitivities(indices_);
      if (spec_.adjoint) check_adjoint_possible(check);
    }
    for (int o : probe_.objectives) {
      r_.objectives.push_back(probe_.nodes[o].name);
      r_.objective_units.push_back(probe_.objective_unit(probe_.nodes[o]));
    }
    P_ = static_cast<int>(indices_.size()), N_ = spec_.samples, O_ = static_cast<int>(r_.objectives.size());
  }

  // One screened parameter checked, and its index, range and unit noted.
  void add_parameter(const std::string& name) {
    const int i = probe_.find_parameter(name);
    if (i < 0)
      throw InputError("--params", 0, name, "no scene parameter or declared direction of that name in " + spec_.scene);
    if (std::find(indices_.begin(), indices_.end(), i) != indices_.end())
      throw InputError("--params", 0, name, "listed twice");
    const SceneParameter& sp = probe_.parameters[i];
    if (!std::isfinite(sp.lower) || !std::isfinite(sp.upper) || !(sp.lower < sp.upper))
      throw InputError(spec_.scene, sp.line,
                       (sp.direction_list.empty() ? "parameters." : sp.direction_list + ".") + name,
                       "a screened parameter needs a finite range [low, high] with low < high (range: [" +
                           format_number(sp.lower) + ", " + format_number(sp.upper) + "])");
    indices_.push_back(i);
    r_.ranges.push_back({name, sp.lower, sp.upper, sp.value});
    r_.units.push_back(sp.unit);
  }

  // The parameters of run `index`: the nominal point for 0, else Sobol' point index - 1 in the ranges.
  std::vector<double> point(int index) const {
    std::vector<double> p(P_);
    for (int i = 0; i < P_; ++i)
      p[i] = index == 0 ? r_.ranges[i].nominal
                        : r_.ranges[i].lower + (r_.ranges[i].upper - r_.ranges[i].lower) * unit_points_[index - 1][i];
    return p;
  }

  // The runs folder with the study's record: an earlier one's runs read when resumed, else emptied.
  void open_folder(const ordered_json& id) {
    const std::string folder = runs_folder(spec_.out);
    const std::string id_path = folder + "/study.json";
    if (spec_.resume && fs::exists(id_path)) {
      read_records(id_path, id);
    } else {
      // A fresh study: records of an earlier one would be mistaken for this one's.
      fs::remove_all(folder);
    }
    fs::create_directories(folder);
    io::write_file_atomically(id_path, id.dump(2) + "\n");
  }

  // The earlier runs' records of the same study (checked against `id`, the study's record at id_path).
  void read_records(const std::string& id_path, const ordered_json& id) {
    std::ifstream in(id_path);
    ordered_json earlier;
    try {
      earlier = ordered_json::parse(in);
    } catch (const std::exception&) {
      throw InputError(id_path, 0, "", "not a study record (resume needs the study.json of an earlier screen)");
    }
    for (const auto& [key, value] : id.items())
      if (!earlier.contains(key) || earlier[key] != value)
        throw InputError(id_path, 0, key, "the recorded study differs from this one in '" + key +
                                              "': --resume continues the same study only (choose another --out)");
    for (int k = 0; k <= N_; ++k) {
      const std::string path = screen_record_path(spec_.out, k);
      if (!fs::exists(path)) continue;
      std::ifstream record(path, std::ios::binary);
      std::ostringstream text;
      text << record.rdbuf();
      ScreenRun run;
      try {
        run = decode(text.str());
      } catch (const std::exception& e) {
        throw InputError(path, 0, "", std::string("unreadable run record: ") + e.what());
      }
      if (run.index != k || run.p != point(k) || static_cast<int>(run.psi.size()) != O_ ||
          static_cast<int>(run.gradient.size()) != O_)
        throw InputError(path, 0, "", "the record does not belong to run " + std::to_string(k) + " of this study");
      runs_[k] = std::move(run);
      have_[k] = true;
      ++r_.recorded_before;
    }
  }

  // Run k at its point: its record's text.
  std::string run_one(int k) const {
    const std::vector<double> p = point(k);
    auto at_point = [&]() {
      Diagram d = load(spec_);
      for (int i = 0; i < P_; ++i) d.set_parameter(indices_[i], p[i]);
      d.set_sensitivities(indices_);
      return d;
    };
    const RunResult result = run_study_point(at_point, spec_.estimate, spec_.adjoint);
    ScreenRun sr;
    sr.index = k;
    sr.p = p;
    for (const auto& obj : result.objectives) {
      sr.psi.push_back(obj.value);
      sr.gradient.push_back(obj.sensitivity);
    }
    sr.cpu_seconds = result.stats.cpu_seconds;
    sr.steps = result.stats.steps;
    if (result.stats.error_estimate.estimated) {
      sr.error_signals = result.stats.error_estimate.signal_error;
      sr.error_sensitivities = result.stats.error_estimate.sensitivity_error;
    }
    sr.warnings = result.stats.warnings;
    return encode(sr);
  }

  // The runs without a record shared among the threads and ranks, each recorded as it ends.
  void run_missing() {
    std::vector<int> todo;
    for (int k = 0; k <= N_; ++k)
      if (!have_[k]) todo.push_back(k);

    int done = 0;
    const int to_do = static_cast<int>(todo.size());
    auto record = [&](int k, const std::string& text) {
      io::write_file_atomically(screen_record_path(spec_.out, k), text);
      // The study's numbers come from the record as written: a resumed study reads the same.
      runs_[k] = decode(text);
      have_[k] = true;
      if (spec_.progress) spec_.progress(++done, to_do);
    };
    share_runs(todo, [this](int k) { return run_one(k); }, record,
               spec_.threads > 0 ? spec_.threads : (world_size() > 1 ? 1 : 0));
  }

  // The nominal run, the samples and each objective's screening estimates.
  void estimate() {
    r_.nominal = runs_[0];
    r_.samples.assign(runs_.begin() + 1, runs_.end());
    for (int o = 0; o < O_; ++o) {
      ScreeningData data;
      for (const ScreenRun& s : r_.samples) {
        data.psi.push_back(s.psi[o]);
        data.gradient.push_back(s.gradient[o]);
      }
      data.nominal_psi = r_.nominal.psi[o];
      data.nominal_gradient = r_.nominal.gradient[o];
      r_.estimates.push_back(estimate_screening(r_.ranges, data));
    }
    r_.complete = true;
  }

  const ScreenSpec& spec_;
  const Diagram probe_;
  ScreenResult r_;
  std::vector<int> indices_;  // the screened parameters' indices in the scene
  int P_ = 0, N_ = 0, O_ = 0;  // parameters, samples, objectives
  std::vector<std::vector<double>> unit_points_;
  std::vector<ScreenRun> runs_;
  std::vector<bool> have_;
};

}  // namespace

ScreenResult screen(const ScreenSpec& spec) { return ScreenStudy(spec).run(); }

}  // namespace dydp::engine
