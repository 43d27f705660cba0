// End-to-end `dydp blocks`: every registered block type listed, and the parameters that can be
// sensitivity directions marked as such.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "engine/framework/registry.hpp"
#include "tests/apps/cli_fixture.hpp"

namespace dydp::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// ---------------------------------------------------------------- dydp blocks

TEST_F(Cli, BlocksListsEveryRegisteredType) {
  const Result r = dydp("blocks");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto types = dydp::engine::Registry::global().all();
  ASSERT_FALSE(types.empty()) << "the test binary must link dydp_blocks";
  for (const auto* t : types)
    EXPECT_NE(r.out.find(t->name + " "), std::string::npos) << t->name << " not listed";
  for (const char* name : {"mass_spring_damper", "source.sine", "source.table", "math.lag",
                           "objective.rms"})
    EXPECT_NE(r.out.find(name), std::string::npos) << name << " not listed";
}

TEST_F(Cli, BlocksMarksTheParametersThatCanBeDirections) {
  const Result r = dydp("blocks");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string step = r.out.substr(r.out.find("\nsource.step "));
  const std::string time = step.substr(step.find("    param   time"));
  EXPECT_NE(time.substr(0, time.find('\n')).find("(not differentiable: no direction)"), std::string::npos) << time;
  const std::string damper = r.out.substr(r.out.find("\ndamper.cdc "));
  const std::string friction = damper.substr(damper.find("    param   friction "));
  EXPECT_NE(friction.substr(0, friction.find('\n')).find("[direction]"), std::string::npos) << friction;
}

}  // namespace
}  // namespace dydp::test
