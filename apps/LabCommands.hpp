#pragma once
// `grainlink params` (parameter estimation) and `grainlink lab TEST` (virtual soil laboratory).
#include <optional>
#include <string>

namespace grainlink::apps {

struct ParamsOptions {
    std::string input_path;  ///< soil and test description (docs/lab.md)
    std::string output_path; ///< .yaml or .csv; empty: out/params/<input stem>.yaml
    std::optional<double> friction_angle_deg; ///< psi: invert the soil table (docs/lab.md)
    std::optional<double> repose_angle_deg;   ///< with it, also match the angle of repose
    std::string table_path; ///< empty: the shipped data/soil_table.csv (apps::shipped)
};
/// Prints Lambda_P and a `soil:` block, writes the matrix; returns the exit code.
int runParams(const ParamsOptions &options);

struct LabOptions {
    std::string test; ///< one of lab::labTestNames()
    std::string scenario_path;
    std::string output_directory; ///< empty: out/<scenario name>
    double progress_interval_s = 5.0;
    std::string check;         ///< "", "walls", "resolution" or "both" (lab/NumericalChecks.hpp)
    double check_factor = 0.0; ///< 0: the check's default (width x 2, radii x 0.75)
    bool no_plot = false;      ///< runs that only feed a diagnosis need none
};
int runLab(const LabOptions &options);

struct SoilTableCommandOptions {
    std::string spec_path;      ///< data/soil_table.yaml
    std::string output_path;    ///< the table CSV
    std::string runs_directory; ///< each grid point's lab outputs; empty: not kept
    double progress_interval_s = 30.0;
};
/// `grainlink soil-table`: runs the grid, writes the table.
int runSoilTable(const SoilTableCommandOptions &options);
/// `grainlink params --friction-angle`: proposes (phi, gamma) from the soil table.
int runTableInversion(const ParamsOptions &options);

} // namespace grainlink::apps
