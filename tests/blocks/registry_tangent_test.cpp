// Every block type in the registry passes the generic tangent check (tangent_check.hpp): a table
// of cases per type, and a test per registered type name, so that a type without a case (a new
// block) fails until it has one; cases naming no registered type fail too.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <map>
#include <string>
#include <vector>

#include "tests/blocks/registry_cases.hpp"

namespace dydp::test {
namespace {

const std::map<std::string, std::vector<BlockCase>>& cases() { return registry_cases(); }

class RegisteredType : public ::testing::TestWithParam<std::string> {};

TEST_P(RegisteredType, PassesTheTangentCheck) {
  const auto it = cases().find(GetParam());
  ASSERT_NE(it, cases().end()) << "block type " << GetParam()
                               << " has no tangent case: add one to tests/blocks/registry_cases.hpp";
  ASSERT_FALSE(it->second.empty());
  for (const BlockCase& c : it->second) check_tangents(c);
}

INSTANTIATE_TEST_SUITE_P(Registry, RegisteredType, ::testing::ValuesIn(registered_types()), [](const auto& info) {
  std::string name = info.param;
  std::replace_if(name.begin(), name.end(), [](char ch) { return !std::isalnum(static_cast<unsigned char>(ch)); }, '_');
  return name;
});

TEST(RegistryTangentCases, NameRegisteredTypes) {
  const std::vector<std::string> names = registered_types();
  EXPECT_FALSE(names.empty()) << "the block library is not linked";
  for (const auto& [type, list] : cases())
    EXPECT_NE(std::find(names.begin(), names.end(), type), names.end()) << "a case for unregistered type " << type;
}

}  // namespace
}  // namespace dydp::test
