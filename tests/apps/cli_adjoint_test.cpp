// End-to-end `dydp run --adjoint`: objectives.json as a forward run writes it, with the gradients
// by the adjoint method for every declared parameter (equal to the forward run's), signals.csv
// without sensitivity columns, run.json's `adjoint` section; refusals with exit 2.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/apps/cli_fixture.hpp"

namespace dydp::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

TEST_F(Cli, RunAdjointWritesTheForwardRunsGradients) {
  const fs::path forward = dir_ / "forward", adjoint = dir_ / "adjoint";
  const Result f = dydp("run " + quote(msd_scene()) + " --no-estimate --out " + quote(forward.string()));
  ASSERT_EQ(f.status, 0) << f.err;
  const Result a = dydp("run " + quote(msd_scene()) + " --adjoint --out " + quote(adjoint.string()));
  ASSERT_EQ(a.status, 0) << a.err;
  const json fo = json::parse(read_text(forward / "objectives.json"));
  const json ao = json::parse(read_text(adjoint / "objectives.json"));
  const json& fs_ = fo["objectives"]["x_rms"]["sensitivity"];
  const json& as = ao["objectives"]["x_rms"]["sensitivity"];
  ASSERT_EQ(as.size(), 3u) << ao.dump();
  for (const char* p : {"mass", "stiffness", "damping"}) {
    const double g = fs_[p].get<double>();
    EXPECT_NEAR(as[p].get<double>(), g, 1e-5 * std::fabs(g)) << p;
  }
  EXPECT_NEAR(ao["objectives"]["x_rms"]["value"].get<double>(), fo["objectives"]["x_rms"]["value"].get<double>(), 1e-7);
  const std::string header = split(read_text(adjoint / "signals.csv"), '\n').at(0);
  EXPECT_EQ(header, "t,body.x,body.v,body.a") << "an adjoint run's signals carry no sensitivities";
  const json run = json::parse(read_text(adjoint / "run.json"));
  ASSERT_TRUE(run.contains("adjoint")) << run.dump();
  EXPECT_GT(run["adjoint"]["checkpoints"].get<long>(), 0);
  EXPECT_GT(run["adjoint"]["backward_steps"].get<long>(), 0);
  EXPECT_GT(run["adjoint"]["checkpoint_bytes"].get<double>(), 0.0);
  EXPECT_FALSE(json::parse(read_text(forward / "run.json")).contains("adjoint"));
}

TEST_F(Cli, RunAdjointRefusesAFixedStepSolverNamingBdf) {
  const Result r = dydp("run " + quote(msd_scene()) + " --adjoint --solver rk4 --out " + quote((dir_ / "o").string()));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("--solver bdf"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "o"));
}

TEST_F(Cli, RunAdjointRefusesNoSens) {
  const Result r = dydp("run " + quote(msd_scene()) + " --adjoint --no-sens --out " + quote((dir_ / "o").string()));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("--no-sens"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace dydp::test
