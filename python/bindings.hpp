// The parts of the Python module `dydp`, each adding its classes and functions to the module:
// scenes and runs, sweeps, screening studies, the block library's metadata.
#pragma once

#include <pybind11/pybind11.h>

#include <string>
#include <utility>
#include <vector>

namespace dydp::python {

void add_scene_bindings(pybind11::module_& m);
void add_sweep_bindings(pybind11::module_& m);
void add_screen_bindings(pybind11::module_& m);
void add_block_bindings(pybind11::module_& m);

/// {NAME: VALUE} as the scene loader's overrides; numbers are written with 17 significant
/// digits, so the scene sees exactly the double given in Python.
std::vector<std::pair<std::string, std::string>> overrides_from(const pybind11::dict& overrides);

}  // namespace dydp::python
