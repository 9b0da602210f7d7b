// `grainlink lab TEST SCENARIO.yaml --out DIR`: the virtual soil laboratory (docs/lab.md).
#include "LabCommands.hpp"

#include "grainlink/lab/Bevameter.hpp"
#include "grainlink/lab/DirectShear.hpp"
#include "grainlink/lab/NumericalChecks.hpp"
#include "grainlink/lab/Repose.hpp"
#include "grainlink/lab/ShearAnnulus.hpp"

#include <cstdio>
#include <stdexcept>

namespace grainlink::apps {

namespace {

/// Prints and writes the checks (numerical_check.csv, report.txt) when --check asked for them.
void reportChecks(const std::vector<lab::NumericalCheck> &checks, const std::string &directory) {
    if (checks.empty())
        return;
    std::printf("%s", lab::describeNumericalChecks(checks).c_str());
    lab::writeNumericalChecks(checks, directory);
    std::printf("written: %s/numerical_check.csv, reruns in %s/check_*\n", directory.c_str(),
                directory.c_str());
}

} // namespace

int runLab(const LabOptions &options) {
    lab::CheckRequest check;
    if (!options.check.empty())
        check = lab::parseCheckRequest(options.check, options.check_factor);
    else if (options.check_factor != 0.0)
        throw std::invalid_argument("--check-factor needs --check walls or --check resolution");
    if (options.test == "bevameter") {
        const auto scenario = lab::loadBevameter(options.scenario_path);
        lab::BevameterOptions run;
        run.output_directory =
            options.output_directory.empty() ? "out/" + scenario.name : options.output_directory;
        run.progress_interval_s = options.progress_interval_s;
        const auto result = lab::runBevameter(scenario, run);
        std::printf("%s", result.report().c_str());
        std::printf("written: %s/{pressure_sinkage.csv,bekker_fit.csv,report.txt}; plot with "
                    "tools/plot_lab.py %s\n",
                    run.output_directory.c_str(), run.output_directory.c_str());
        if (check.any())
            reportChecks(lab::checkBevameter(scenario, result, check, run), run.output_directory);
        return 0;
    }
    if (options.test == "repose") {
        const auto scenario = lab::loadRepose(options.scenario_path);
        lab::ReposeOptions run;
        run.output_directory =
            options.output_directory.empty() ? "out/" + scenario.name : options.output_directory;
        run.progress_interval_s = options.progress_interval_s;
        const auto result = lab::runRepose(scenario, run);
        std::printf("%s", result.report().c_str());
        std::printf("written: %s/{heap_profile.csv,report.txt}; plot with tools/plot_lab.py %s\n",
                    run.output_directory.c_str(), run.output_directory.c_str());
        if (check.any())
            reportChecks(lab::checkRepose(scenario, result, check, run), run.output_directory);
        return 0;
    }
    if (options.test == "direct_shear") {
        const auto scenario = lab::loadDirectShear(options.scenario_path);
        lab::DirectShearOptions run;
        run.output_directory =
            options.output_directory.empty() ? "out/" + scenario.name : options.output_directory;
        run.progress_interval_s = options.progress_interval_s;
        const auto result = lab::runDirectShear(scenario, run);
        std::printf("%s", result.report().c_str());
        std::printf("written: %s/{shear_curves.csv,mohr_coulomb.csv,report.txt}; plot with "
                    "tools/plot_lab.py %s\n",
                    run.output_directory.c_str(), run.output_directory.c_str());
        if (check.any())
            reportChecks(lab::checkDirectShear(scenario, result, check, run),
                         run.output_directory);
        return 0;
    }
    if (options.test == "bevameter_shear") {
        const auto scenario = lab::loadShearAnnulus(options.scenario_path);
        lab::ShearAnnulusOptions run;
        run.output_directory =
            options.output_directory.empty() ? "out/" + scenario.name : options.output_directory;
        run.progress_interval_s = options.progress_interval_s;
        const auto result = lab::runShearAnnulus(scenario, run);
        std::printf("%s", result.report().c_str());
        std::printf("written: %s/{shear_displacement.csv,janosi_fit.csv,report.txt}; plot with "
                    "tools/plot_lab.py %s\n",
                    run.output_directory.c_str(), run.output_directory.c_str());
        if (check.any())
            reportChecks(lab::checkShearAnnulus(scenario, result, check, run),
                         run.output_directory);
        return 0;
    }
    throw std::invalid_argument("lab test '" + options.test +
                                "' is not implemented; available: bevameter, repose, direct_shear, "
                                "bevameter_shear");
}

} // namespace grainlink::apps
