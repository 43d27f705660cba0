// `dydp screen` end to end: a study killed midway (SIGKILL once some runs are recorded) and
// resumed gives exactly the numbers of an uninterrupted one; the measures in screen.json follow
// from the recorded samples (recomputed here from samples.csv); a sample's gradient is the one
// `dydp run --set` gives at that point; bad options and foreign records are refused.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <numbers>
#include <thread>

#include "tests/apps/dydp_process.hpp"

extern char** environ;

namespace dydp::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

class Screen : public DydpProcessTest {
 protected:
  Screen() : DydpProcessTest("dydp_screen_") {}

  /// The mass-spring-damper scene integrated by RK4 at a small step: about 0.2 s a run, so a
  /// study of a few runs can be interrupted between two of them.
  static std::string slow_args() {
    return quote(source_path("scenarios/msd_sensitivity.yaml").string()) +
           " --params mass,stiffness,damping --solver rk4 --step 5e-5 --threads 1";
  }

  static int records(const fs::path& out) {
    int n = 0;
    for (const std::string& name : entries(out / "runs"))
      if (name.rfind("run_", 0) == 0 && name.size() == 14 && name.ends_with(".json")) ++n;
    return n;
  }

  /// Starts `dydp screen ARGS` as a child process and kills it (SIGKILL) once `after` runs are
  /// recorded; returns the number recorded when it died.
  int kill_after(const std::vector<std::string>& args, const fs::path& out, int after) const {
    std::vector<std::string> argv_text = {DYDP_EXE, "screen"};
    argv_text.insert(argv_text.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : argv_text) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
    pid_t pid = 0;
    EXPECT_EQ(posix_spawn(&pid, DYDP_EXE, &actions, nullptr, argv.data(), environ), 0);
    posix_spawn_file_actions_destroy(&actions);
    // The child at the lowest priority: on a loaded machine this poller still runs between two of
    // its runs (each about 0.2 s), so the study cannot finish between the count and the kill.
    setpriority(PRIO_PROCESS, static_cast<id_t>(pid), 19);
    // How long to wait for the records, not a bound on the result: at nice 19 beside two builds
    // and a test suite (a load of 5) the child recorded only 2 runs in 60 s.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(300);
    while (records(out) < after && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    kill(pid, SIGKILL);
    int status = 0;
    waitpid(pid, &status, 0);
    EXPECT_TRUE(WIFSIGNALED(status)) << "the study ended before it was killed";
    return records(out);
  }

  /// screen.json without the "runs" section (CPU seconds differ from one invocation to another).
  static json results(const fs::path& out) {
    json j = json::parse(read_text(out / "screen.json"));
    j.erase("runs");
    return j;
  }
};

TEST_F(Screen, AStudyKilledMidwayAndResumedGivesTheNumbersOfAnUninterruptedOne) {
  const fs::path whole = dir_ / "whole", broken = dir_ / "broken";
  const ProcessResult w = dydp("screen " + slow_args() + " --samples 8 --out " + quote(whole.string()));
  ASSERT_EQ(w.status, 0) << w.err;
  EXPECT_EQ(records(whole), 9);

  const std::string scene = source_path("scenarios/msd_sensitivity.yaml").string();
  const int recorded = kill_after({scene, "--params", "mass,stiffness,damping", "--solver", "rk4", "--step", "5e-5",
                                   "--threads", "1", "--samples", "8", "--out", broken.string()},
                                  broken, 3);
  ASSERT_GE(recorded, 3);
  ASSERT_LT(recorded, 9);
  EXPECT_FALSE(fs::exists(broken / "screen.json"));

  const ProcessResult r = dydp("screen " + slow_args() + " --samples 8 --resume --out " + quote(broken.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find(std::to_string(recorded) + " runs taken from the records, " + std::to_string(9 - recorded) +
                       " run now"), std::string::npos) << r.err;
  EXPECT_EQ(results(broken), results(whole));
  EXPECT_EQ(read_text(broken / "screen.csv"), read_text(whole / "screen.csv"));
  for (int k = 0; k <= 8; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "runs/run_%05d.json", k);
    json a = json::parse(read_text(whole / name)), b = json::parse(read_text(broken / name));
    EXPECT_EQ(a["p"], b["p"]) << name;
    EXPECT_EQ(a["psi"], b["psi"]) << name;
    EXPECT_EQ(a["gradient"], b["gradient"]) << name;
  }

  // A resumed study with more samples keeps all nine records: the first points do not depend on N.
  const ProcessResult more = dydp("screen " + slow_args() + " --samples 10 --resume --out " + quote(broken.string()));
  ASSERT_EQ(more.status, 0) << more.err;
  EXPECT_NE(more.err.find("9 runs taken from the records, 2 run now"), std::string::npos) << more.err;
  // Records of another study (another --set) are not resumed.
  const ProcessResult other =
      dydp("screen " + slow_args() + " --samples 8 --resume --set damping=2.0 --out " + quote(broken.string()));
  EXPECT_EQ(other.status, 2);
  EXPECT_NE(other.err.find("study.json: set: the recorded study differs"), std::string::npos) << other.err;
}

TEST_F(Screen, RecordsOfAStudyWhoseSubsystemFileChangedAreNotResumed) {
  // The oscillator of msd_sensitivity.yaml as a subsystem in a file of its own.
  fs::create_directories(dir_ / "sub");
  write("sub/oscillator.yaml", R"(subsystem: oscillator
parameters:
  stiffness: {value: 40.0, unit: N/m}
  damping: {value: 1.2, unit: N s/m}
outputs:
  position: body.x
blocks:
  force: {type: source.sine, amplitude: 2.0, frequency: 0.8}
  body: {type: mass_spring_damper, m: 1.5, k: $stiffness, c: $damping, x0: 0.05, v0: 0.1}
connections:
  - force.y -> body.f
)");
  const std::string scene = write("s.yaml", R"(scene: s
time: {start: 0.0, stop: 4.0, output_step: 0.01}
solver: {method: bdf, rtol: 1.0e-8, atol: 1.0e-10}
parameters:
  stiffness: {value: 40.0, unit: N/m, range: [30.0, 50.0]}
  damping: {value: 1.2, unit: N s/m, range: [0.8, 1.6]}
subsystems:
  oscillator: {file: sub/oscillator.yaml}
blocks:
  osc: {type: subsystem.oscillator, stiffness: $stiffness, damping: $damping}
  x_rms: {type: objective.rms, window: [1.0, 4.0]}
connections:
  - osc.position -> x_rms.in
outputs: [x_rms]
)");
  const fs::path out = dir_ / "out";
  const std::string args = quote(scene) + " --params stiffness,damping --samples 2 --out " + quote(out.string());
  const ProcessResult first = dydp("screen " + args);
  ASSERT_EQ(first.status, 0) << first.err;
  // Unchanged, the study resumes from its records.
  const ProcessResult same = dydp("screen " + args + " --resume");
  ASSERT_EQ(same.status, 0) << same.err;
  EXPECT_NE(same.err.find("3 runs taken from the records, 0 run now"), std::string::npos) << same.err;
  // The subsystem's mass edited: its records belong to another study.
  write("sub/oscillator.yaml", replaced(read_text(dir_ / "sub/oscillator.yaml"), "m: 1.5", "m: 1.6"));
  const ProcessResult edited = dydp("screen " + args + " --resume");
  EXPECT_EQ(edited.status, 2);
  EXPECT_NE(edited.err.find("study.json: subsystem_digests: the recorded study differs"), std::string::npos)
      << edited.err;
}

TEST_F(Screen, MeasuresFollowFromTheSamplesAndGradientsFromSingleRuns) {
  const fs::path out = dir_ / "out";
  const std::string scene = source_path("scenarios/msd_sensitivity.yaml").string();
  const ProcessResult r =
      dydp("screen " + quote(scene) + " --params stiffness,damping --samples 16 --out " + quote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const io::CsvFile samples = io::read_csv((out / "samples.csv").string());
  const json j = json::parse(read_text(out / "screen.json"));
  const json& x = j["objectives"]["x_rms"];
  const std::vector<double>& k = column(samples, "stiffness");
  const std::vector<double>& psi = column(samples, "x_rms");
  const std::vector<double>& dk = column(samples, "d(x_rms)/d(stiffness)");
  const std::vector<double>& dc = column(samples, "d(x_rms)/d(damping)");
  ASSERT_EQ(psi.size(), 17u);  // the nominal row first
  EXPECT_EQ(k[0], 40.0);
  double mean = 0, var = 0, nu_k = 0, nu_c = 0;
  for (size_t s = 1; s < psi.size(); ++s) mean += psi[s] / 16;
  for (size_t s = 1; s < psi.size(); ++s) {
    var += (psi[s] - mean) * (psi[s] - mean) / 15;
    nu_k += dk[s] * dk[s] / 16;
    nu_c += dc[s] * dc[s] / 16;
    EXPECT_GE(k[s], 1.0);
    EXPECT_LE(k[s], 1000.0);
  }
  EXPECT_NEAR(x["mean"].get<double>(), mean, 1e-14 * std::fabs(mean));
  EXPECT_NEAR(x["variance"].get<double>(), var, 1e-12 * var);
  const json& pk = x["parameters"]["stiffness"];
  EXPECT_NEAR(pk["nu"].get<double>(), nu_k, 1e-12 * nu_k);
  const double pi2 = std::numbers::pi * std::numbers::pi;
  EXPECT_NEAR(pk["total_index_bound"].get<double>(), 999.0 * 999.0 * nu_k / (pi2 * var), 1e-10 * nu_k / var * 1e6);
  EXPECT_NEAR(x["parameters"]["damping"]["total_index_bound"].get<double>(), 50.0 * 50.0 * nu_c / (pi2 * var),
              1e-10 * 2500 * nu_c / var);
  EXPECT_EQ(x["ranking"].size(), 2u);
  const bool k_first = 999.0 * 999.0 * nu_k >= 2500 * nu_c;
  EXPECT_EQ(x["ranking"][0], k_first ? "stiffness" : "damping");
  // The nominal row's local normalised sensitivity: (p / psi) dpsi/dp.
  EXPECT_NEAR(pk["local_normalised"].get<double>(), 40.0 / psi[0] * dk[0], 1e-12);

  // Sample 5 again as a single run at that point with the same two directions: the same
  // numbers, bit for bit (samples.csv prints 17 digits).
  const fs::path single = dir_ / "single";
  const std::string two = write("two.yaml", replaced(read_text(scene), "sensitivities: [mass, stiffness, damping]",
                                                      "sensitivities: [stiffness, damping]"));
  char set_k[64], set_c[64];
  std::snprintf(set_k, sizeof set_k, "stiffness=%.17g", k[5]);
  std::snprintf(set_c, sizeof set_c, "damping=%.17g", column(samples, "damping")[5]);
  const ProcessResult one = dydp("run " + quote(two) + " --set " + set_k + " --set " + set_c + " --out " +
                                 quote(single.string()));
  ASSERT_EQ(one.status, 0) << one.err;
  const json o = json::parse(read_text(single / "objectives.json"))["objectives"]["x_rms"];
  EXPECT_EQ(o["value"].get<double>(), psi[5]);
  EXPECT_EQ(o["sensitivity"]["stiffness"].get<double>(), dk[5]);
  EXPECT_EQ(o["sensitivity"]["damping"].get<double>(), dc[5]);
  // Each run estimated its own error as that run does (its shadow run beside it).
  const json est = json::parse(read_text(single / "run.json"))["error_estimate"];
  ASSERT_TRUE(est.is_object());
  EXPECT_NEAR(column(samples, "error_estimate_signals")[5], est["signals"].get<double>(), 1e-15);
  EXPECT_NEAR(column(samples, "error_estimate_sensitivities")[5], est["sensitivities"].get<double>(), 1e-15);
  const json& worst = j["runs"]["error_estimate"];
  ASSERT_TRUE(worst.is_object());
  EXPECT_EQ(worst["estimated_runs"].get<int>(), 17);
  const auto& es = column(samples, "error_estimate_signals");
  EXPECT_EQ(worst["signals"].get<double>(), *std::max_element(es.begin(), es.end()));
  EXPECT_GT(worst["signals"].get<double>(), 0.0);
}

TEST_F(Screen, ReportShowsTheRankingAsATornadoAndTheSamplesOfEachParameter) {
  const fs::path out = dir_ / "out";
  const ProcessResult r = dydp("screen " + quote(source_path("scenarios/msd_sensitivity.yaml").string()) +
                               " --params mass,stiffness,damping --samples 8 --report --out " + quote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string md = read_text(out / "report.md");
  ASSERT_NE(md.find("# Screening of 3 parameters"), std::string::npos) << md;
  if (md.find("gnuplot was not found") != std::string::npos) GTEST_SKIP() << "gnuplot not on the PATH";
  for (const char* png : {"plots/tornado_x_rms.png", "plots/samples_x_rms.png"}) {
    EXPECT_NE(md.find(std::string("](") + png + ")"), std::string::npos) << png;
    ASSERT_TRUE(fs::exists(out / png)) << png;
    EXPECT_GT(fs::file_size(out / png), 1000u) << png;
  }
  // The tornado's bars, top (y = 3) to bottom, are the ranking of screen.json.
  const json ranking = json::parse(read_text(out / "screen.json"))["objectives"]["x_rms"]["ranking"];
  std::istringstream bars(read_text(out / "plots/tornado_x_rms.dat"));
  std::string line;
  for (int rank = 0; std::getline(bars, line); ++rank) {
    EXPECT_EQ(line.substr(0, 2), std::to_string(3 - rank) + " ") << line;
    EXPECT_NE(line.find("\"" + ranking[rank].get<std::string>() + " (S_T <= "), std::string::npos) << line;
  }
}

TEST_F(Screen, BadParametersAndSampleCountsAreRefusedWithoutOutput) {
  const std::string scene = write("s.yaml", R"(scene: s
time: {stop: 1.0, output_step: 0.1}
parameters:
  mass: {value: 1.0, unit: kg, range: [0.5, 2.0]}
  stiffness: {value: 40.0, unit: N/m}
blocks:
  body: {type: mass_spring_damper, m: $mass, k: $stiffness}
  zero: {type: source.constant, value: 0.0}
  x_rms: {type: objective.rms, window: [0.0, 1.0]}
connections:
  - zero.y -> body.f
  - body.x -> x_rms.in
outputs: [x_rms]
)");
  const fs::path out = dir_ / "out";
  const std::string tail = " --out " + quote(out.string());
  ProcessResult r = dydp("screen " + quote(scene) + " --params mass,stifness" + tail);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--params: stifness: no scene parameter or declared direction"), std::string::npos) << r.err;
  r = dydp("screen " + quote(scene) + " --params mass,stiffness" + tail);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find(scene + ":5: parameters.stiffness: a screened parameter needs a finite range"), std::string::npos)
      << r.err;
  r = dydp("screen " + quote(scene) + " --params mass,mass" + tail);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--params: mass: listed twice"), std::string::npos) << r.err;
  r = dydp("screen " + quote(scene) + " --params mass --samples 1" + tail);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--samples: 1: needs at least 2 samples"), std::string::npos) << r.err;
  EXPECT_TRUE(entries(out).empty()) << "written: " << entries(out).size();
}

}  // namespace
}  // namespace dydp::test
