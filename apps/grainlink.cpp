// The `grainlink` command: one binary, one subcommand per job.
#include "grainlink/dem/ScenarioRun.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>

int main(int argc, char **argv) {
    CLI::App app{"grainlink: co-simulation of planetary locomotion on granular soil"};
    app.require_subcommand(1);

    auto *dem =
        app.add_subcommand("dem", "run a DEM-only scenario (deposition, then prescribed bodies)");
    std::string scenario_path, out_dir;
    bool resume = false;
    double progress_s = 5.0;
    dem->add_option("scenario", scenario_path, "scenario YAML file (keys: docs/scenario.md)")
        ->required();
    dem->add_option("--out", out_dir, "output directory (default: out/<scenario name>)");
    dem->add_flag("--resume", resume, "continue from the last checkpoint in the output directory");
    dem->add_option("--progress-interval", progress_s, "seconds between progress lines");

    CLI11_PARSE(app, argc, argv);
    try {
        if (dem->parsed()) {
            const auto scenario = grainlink::dem::loadScenario(scenario_path);
            grainlink::dem::RunOptions options;
            options.output_directory = out_dir.empty() ? "out/" + scenario.name : out_dir;
            options.resume = resume;
            options.progress_interval_s = progress_s;
            grainlink::dem::runScenario(scenario, options);
        }
    } catch (const std::exception &e) {
        std::fprintf(stderr, "grainlink: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
