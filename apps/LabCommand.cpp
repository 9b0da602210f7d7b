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

/// One lab test: reads its scenario, runs it into the output directory (default out/NAME),
/// prints the report and what was written (`files`), then the numerical checks if asked.
template <class Options, class Load, class Run, class Check>
int runTest(const LabOptions &options, const lab::CheckRequest &check, Load load, Run run,
            Check numericalChecks, const char *files) {
    const auto scenario = load(options.scenario_path);
    Options run_options;
    run_options.output_directory =
        options.output_directory.empty() ? "out/" + scenario.name : options.output_directory;
    run_options.progress_interval_s = options.progress_interval_s;
    const auto result = run(scenario, run_options);
    const char *directory = run_options.output_directory.c_str();
    std::printf("%s", result.report().c_str());
    std::printf("written: %s/{%s}; plot with tools/plot_lab.py %s\n", directory, files, directory);
    if (check.any())
        reportChecks(numericalChecks(scenario, result, check, run_options),
                     run_options.output_directory);
    return 0;
}

} // namespace

int runLab(const LabOptions &options) {
    lab::CheckRequest check;
    if (!options.check.empty())
        check = lab::parseCheckRequest(options.check, options.check_factor);
    else if (options.check_factor != 0.0)
        throw std::invalid_argument("--check-factor needs --check walls or --check resolution");
    if (options.test == "bevameter")
        return runTest<lab::BevameterOptions>(options, check, lab::loadBevameter,
                                              lab::runBevameter, lab::checkBevameter,
                                              "pressure_sinkage.csv,bekker_fit.csv,report.txt");
    if (options.test == "repose")
        return runTest<lab::ReposeOptions>(options, check, lab::loadRepose, lab::runRepose,
                                           lab::checkRepose, "heap_profile.csv,report.txt");
    if (options.test == "direct_shear")
        return runTest<lab::DirectShearOptions>(options, check, lab::loadDirectShear,
                                                lab::runDirectShear, lab::checkDirectShear,
                                                "shear_curves.csv,mohr_coulomb.csv,report.txt");
    if (options.test == "bevameter_shear")
        return runTest<lab::ShearAnnulusOptions>(
            options, check, lab::loadShearAnnulus, lab::runShearAnnulus, lab::checkShearAnnulus,
            "shear_displacement.csv,janosi_fit.csv,report.txt");
    throw std::invalid_argument("lab test '" + options.test +
                                "' is not implemented; available: bevameter, repose, direct_shear, "
                                "bevameter_shear");
}

} // namespace grainlink::apps
