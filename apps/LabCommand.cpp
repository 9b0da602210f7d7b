// `grainlink lab TEST SCENARIO.yaml --out DIR`: the virtual soil laboratory (docs/lab.md).
#include "LabCommands.hpp"

#include "grainlink/lab/LabPlot.hpp"
#include "grainlink/lab/LabTest.hpp"

#include <cstdio>
#include <stdexcept>

namespace grainlink::apps {

int runLab(const LabOptions &options) {
    lab::CheckRequest check;
    if (!options.check.empty())
        check = lab::parseCheckRequest(options.check, options.check_factor);
    else if (options.check_factor != 0.0)
        throw std::invalid_argument("--check-factor needs --check walls or --check resolution");
    const lab::LabScenario scenario = lab::loadLabScenario(options.test, options.scenario_path);
    for (const config::KeyWarning &warning : lab::labWarnings(scenario))
        std::fprintf(stderr, "%s\n", warning.text().c_str());
    lab::LabRunOptions run_options;
    run_options.output_directory = options.output_directory.empty()
                                       ? "out/" + lab::labScenarioName(scenario)
                                       : options.output_directory;
    run_options.progress_interval_s = options.progress_interval_s;
    const lab::LabRun run = lab::runLabTest(scenario, run_options, check);

    const std::string &directory = run_options.output_directory;
    std::printf("%s", run.report.c_str());
    if (!run.checks.empty())
        std::printf("%s", lab::describeNumericalChecks(run.checks).c_str());
    std::string files;
    for (const std::string &f : run.files)
        files += (files.empty() ? "" : ",") + f;
    std::printf("written: %s/{%s}%s\n", directory.c_str(), files.c_str(),
                run.checks.empty() ? "" : ", reruns in check_*/");
    // The plot is a view of the results: without python3 or matplotlib the run still succeeded.
    if (!options.no_plot)
        std::printf("%s\n", lab::plotLabRun(directory, run.summary.test).message.c_str());
    return 0;
}

} // namespace grainlink::apps
