#pragma once
// A scenario as a YAML tree that a study edits by dotted path before writing it out:
// `contact.tangential.stick_angle_deg`, `deposition.seed`, list items by index
// (`walls.0.upper_m`).
#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

namespace grainlink::study {

/// The steps of a dotted path ("walls.0.upper_m" -> walls, 0, upper_m). Throws
/// std::invalid_argument for an empty path or an empty step (a leading, doubled or trailing dot).
std::vector<std::string> pathSteps(const std::string &key);

/// Sets `key` to `value` in `root` (a clone the caller owns). Every step but the last must
/// exist; the last may be a new key of a mapping (the run's strict reader then judges it).
/// Throws std::invalid_argument saying which step of the path is missing and what is there.
void setAtPath(YAML::Node &root, const std::string &key, const YAML::Node &value);
/// The node at `key`, or an undefined node when the path does not exist.
YAML::Node findAtPath(const YAML::Node &root, const std::string &key);

/// Makes the relative file paths of a scenario (keys `file`, `model`, `keys`: meshes, user
/// models, CURVE keys) absolute against `folder`, so the scenario reads the same files from
/// wherever the study writes it. Only values naming an existing file or folder are changed.
void absolutizeFilePaths(YAML::Node &root, const std::string &folder);

/// Block-style YAML text of a tree; the same tree always gives the same text.
std::string emitYaml(const YAML::Node &root);
/// One line for tables and labels: a scalar as is, a list as `[a, b, c]`.
std::string inlineText(const YAML::Node &value);

} // namespace grainlink::study
