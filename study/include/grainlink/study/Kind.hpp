#pragma once
// What kind of run a study point is: the `grainlink` subcommand that runs it, the summary file
// it leaves, where its thread count and deposition seed live, its checkpoint, and the parser that
// checks it.
#include "grainlink/config/ConfigNode.hpp"

#include <functional>
#include <string>
#include <vector>

namespace YAML {
class Node;
}

namespace grainlink::study {

struct Kind {
    std::string name;                 ///< "dem", "run", "lab direct_shear", ...
    std::vector<std::string> command; ///< words after `grainlink`: {"lab", "direct_shear"}
    std::string summary_file;         ///< machine-readable result in the run's output folder
    /// Where the summary file depends on the scenario (a coupled run: the rig's or any other
    /// model's), the file for this base scenario; none: `summary_file` always.
    std::function<std::string(const YAML::Node &scenario)> summary_file_of;
    std::string threads_key;          ///< dotted path of the scenario's thread count
    std::string seed_key;             ///< dotted path replicates vary by default
    /// The run's latest checkpoint in its output folder: an interrupted point that left one
    /// continues from it (`--resume`) instead of starting again; empty for runs without one.
    std::string checkpoint_file;
    /// The run's own scenario reader, called in-process; throws config::ConfigError.
    std::function<void(const config::ConfigNode &root)> validate;
};

/// `dem`, `run` or `lab` with its `test` (bevameter, repose, direct_shear, bevameter_shear).
/// `run` is checked by the reader `setRunScenarioCheck` registered (none: unchecked).
Kind standardKind(const std::string &kind, const std::string &test = "");

/// The coupled run's scenario reader (the coupling and every model's section) lives in the
/// `grainlink` command, above this library: the command registers it once at start, and every
/// `run` kind made after carries it (a study's points, a diagnosis' mole runs).
void setRunScenarioCheck(std::function<void(const config::ConfigNode &root)> check);

} // namespace grainlink::study
