// `grainlink soil-table SPEC.yaml --out FILE.csv` (the lookup table) and the table's inversion
// behind `grainlink params --friction-angle PSI` (docs/lab.md).
#include "ExecutorFlags.hpp"
#include "LabCommands.hpp"

#include "grainlink/lab/SoilTable.hpp"

#include <cstdio>

namespace grainlink::apps {

int runSoilTable(const SoilTableCommandOptions &options) {
    const auto spec = lab::loadSoilTableSpec(options.spec_path);
    lab::SoilTableOptions run;
    run.output_csv = options.output_path;
    run.runs_directory = options.runs_directory;
    run.progress_interval_s = options.progress_interval_s;
    run.command_line =
        "grainlink soil-table " + options.spec_path + " --out " + options.output_path;
    const auto rows = lab::generateSoilTable(spec, run);
    std::printf("%zu grid points written to %s\n", rows.size(), options.output_path.c_str());
    return 0;
}

int runTableInversion(const ParamsOptions &options) {
    const auto table = lab::readSoilTable(
        options.table_path.empty() ? shipped("data/soil_table.csv") : options.table_path);
    const auto inversion =
        lab::invertSoilTable(table, *options.friction_angle_deg, options.repose_angle_deg);
    std::printf("Soil table %s: phi %g..%g deg, gamma %g..%g deg\n", table.file.c_str(),
                table.phi_deg.front(), table.phi_deg.back(), table.gamma_deg.front(),
                table.gamma_deg.back());
    std::printf("%s\nReady to paste into a scenario's soil block (docs/scenario.md):\n\n%s",
                inversion.describe().c_str(), inversion.contactBlock().c_str());
    return 0;
}

} // namespace grainlink::apps
