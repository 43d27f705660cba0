// `mpirun -n 2 dydp sweep|screen` against one process: the runs shared between two ranks give
// the same numbers, bit for bit, and rank 0 alone writes the results and prints.
#include <cstdlib>

#include "engine/studies/run_sharing.hpp"
#include "tests/apps/dydp_process.hpp"

namespace dydp::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

class Mpi : public DydpProcessTest {
 protected:
  Mpi() : DydpProcessTest("dydp_mpi_") {}

  /// `mpirun -n 2 dydp ARGS`, as root too (CI runs in a container as root).
  ProcessResult mpirun(const std::string& args) const {
    return run_process(DYDP_MPIEXEC, "--allow-run-as-root --oversubscribe -n 2 " + quote(DYDP_EXE) + " " + args, dir_);
  }

  static std::string scene() { return quote(source_path("scenarios/msd_sensitivity.yaml").string()); }
};

TEST_F(Mpi, TheProgramIsBuiltWithMpi) { EXPECT_TRUE(engine::built_with_mpi()); }

TEST_F(Mpi, SweepOverTwoRanksGivesTheNumbersOfOneProcess) {
  const fs::path one = dir_ / "one", two = dir_ / "two";
  const std::string args = "sweep " + scene() + " --param damping --range 0.5:2.5:5 --fd 0.01 --report --out ";
  const ProcessResult a = dydp(args + quote(one.string()));
  ASSERT_EQ(a.status, 0) << a.err;
  const ProcessResult b = mpirun(args + quote(two.string()));
  ASSERT_EQ(b.status, 0) << b.err;
  // Rank 0 prints once, the same table.
  EXPECT_EQ(b.out.substr(0, b.out.find("results in")), a.out.substr(0, a.out.find("results in")));
  EXPECT_NE(a.out.find("results in"), std::string::npos);
  json ja = json::parse(read_text(one / "sweep.json")), jb = json::parse(read_text(two / "sweep.json"));
  ASSERT_EQ(ja["points"].size(), 5u);
  for (json* j : {&ja, &jb})
    for (auto& p : (*j)["points"]) p.erase("cpu_seconds");
  EXPECT_EQ(ja, jb);
  // The report's trajectories come from every run, wherever it ran.
  EXPECT_EQ(read_text(one / "plots/trajectories.dat"), read_text(two / "plots/trajectories.dat"));
}

TEST_F(Mpi, ScreenOverTwoRanksGivesTheNumbersOfOneProcess) {
  const fs::path one = dir_ / "one", two = dir_ / "two";
  const std::string args = "screen " + scene() + " --params mass,stiffness,damping --samples 16 --out ";
  const ProcessResult a = dydp(args + quote(one.string()));
  ASSERT_EQ(a.status, 0) << a.err;
  const ProcessResult b = mpirun(args + quote(two.string()));
  ASSERT_EQ(b.status, 0) << b.err;
  EXPECT_NE(b.err.find("shared among 2 MPI ranks"), std::string::npos) << b.err;
  json ja = json::parse(read_text(one / "screen.json")), jb = json::parse(read_text(two / "screen.json"));
  EXPECT_EQ(ja["runs"]["count"], 17);
  EXPECT_EQ(jb["runs"]["count"], 17);
  EXPECT_EQ(ja["runs"]["steps"], jb["runs"]["steps"]);
  ja.erase("runs"), jb.erase("runs");
  EXPECT_EQ(ja, jb);
  EXPECT_EQ(read_text(one / "screen.csv"), read_text(two / "screen.csv"));
  int records = 0;
  for (const std::string& name : entries(two / "runs")) records += name.rfind("run_", 0) == 0;
  EXPECT_EQ(records, 17);
}

TEST_F(Mpi, AFailedRunOnAnyRankEndsTheStudyWithTheSolverFailure) {
  // A step too large for the stiffest sample: RK4 goes unstable, the run's objective is not finite.
  // (omega h = 17 rad/s * 0.2 s = 3.4 at sample 3, past RK4's limit of 2.8; 1.0 at the nominal point).
  const std::string text = replaced(read_text(source_path("scenarios/msd_sensitivity.yaml")),
                                    "solver: {method: bdf, rtol: 1.0e-8, atol: 1.0e-10}", "solver: {method: rk4, step: 0.2}");
  // Over 400 s the unstable samples overflow; the window [2, 10] s stays as written.
  const std::string s = write("stiff.yaml", replaced(replaced(text, "output_step: 0.01", "output_step: 0.2"),
                                                     "stop: 10.0", "stop: 400.0"));
  const ProcessResult single = dydp("screen " + quote(s) + " --params mass,stiffness --samples 8 --out " + quote((dir_ / "a").string()));
  const ProcessResult shared = mpirun("screen " + quote(s) + " --params mass,stiffness --samples 8 --out " + quote((dir_ / "b").string()));
  EXPECT_EQ(single.status, 1) << single.err;
  EXPECT_NE(shared.status, 0) << shared.err;
  EXPECT_NE(single.err.find("solver failure: t = "), std::string::npos) << single.err;
  EXPECT_NE(shared.err.find("solver failure: t = "), std::string::npos) << shared.err;
  EXPECT_FALSE(fs::exists(dir_ / "b" / "screen.json"));
}

}  // namespace
}  // namespace dydp::test
