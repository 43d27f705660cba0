// The main of every FMI test program: GoogleTest with the folder of the program's FMUs
// (fmu_fixture.hpp) made before the tests and removed after them.
#include <gtest/gtest.h>

#include "tests/fmi/fmu_fixture.hpp"

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ::testing::AddGlobalTestEnvironment(new dydp::test::FmuFolder);
  return RUN_ALL_TESTS();
}
