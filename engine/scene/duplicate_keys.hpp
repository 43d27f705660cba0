// Duplicate keys in a YAML document: yaml-cpp keeps every pair of a mapping but looks up the
// first, so a key written twice would silently lose its second value. The scene loader refuses
// them before reading anything, naming both lines.
#pragma once

#include <yaml-cpp/yaml.h>

#include <string>

namespace dydp::engine {

/// Throws InputError(file, line of the second key, field, "... twice (first at line N)") for the
/// first key given twice in any mapping under `root`. Fields are dotted paths of keys as the
/// loader names them: `time.stop`, `parameters.k.value`; under `blocks` the block's name leads
/// (`d_fl.current`), and a block given twice reads "block defined twice". The same holds in a
/// subsystem file and under an inline definition's `blocks:` (`subsystems.NAME.blocks`).
void refuse_duplicate_keys(const YAML::Node& root, const std::string& file);

}  // namespace dydp::engine
