#pragma once
// `grainlink params` (parameter estimation) and `grainlink lab TEST` (virtual soil laboratory).
#include <string>

namespace grainlink::apps {

struct ParamsOptions {
    std::string input_path;  ///< soil and test description (docs/lab.md)
    std::string output_path; ///< .yaml or .csv; empty: out/params/<input stem>.yaml
};
/// Prints Lambda_P and a `soil:` block, writes the matrix; returns the exit code.
int runParams(const ParamsOptions &options);

struct LabOptions {
    std::string test; ///< "bevameter" or "repose"
    std::string scenario_path;
    std::string output_directory; ///< empty: out/<scenario name>
    double progress_interval_s = 5.0;
    std::string check;         ///< "", "walls", "resolution" or "both" (lab/NumericalChecks.hpp)
    double check_factor = 0.0; ///< 0: the check's default (width x 2, radii x 0.75)
};
int runLab(const LabOptions &options);

} // namespace grainlink::apps
