#pragma once
// The skeleton every lab test runs (docs/lab.md, "One skeleton"): a tool pressed or driven into
// a prepared bed, observed over intervals, fitted, reported. A test supplies the steps as an
// `Experiment` and gets the rest: the bed prepared once, one run per condition, a fit that cannot
// be made kept as a note beside the runs, the wall clock, report.txt, its CSVs and summary.json.
#include "grainlink/dem/DemSystem.hpp"
#include "grainlink/lab/LabBed.hpp"
#include "grainlink/lab/LabSummary.hpp"

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <vector>

namespace grainlink::lab {

/// How a lab test runs: where it writes and how often it says how far it got.
struct LabRunOptions {
    std::string output_directory; ///< empty: nothing written
    double progress_interval_s = 5.0;
};

/// What every lab test's result holds; runLabExperiment fills it.
struct LabResult {
    std::string scenario; ///< the scenario's name
    LabBedSummary bed;
    std::string fit_note; ///< why a law could not be fitted (empty: fitted)
    double wall_s = 0.0;  ///< [s] the whole test, bed included
};

/// The soil's mean load on a tool body over an observation interval (impulse / time).
struct MeanLoad {
    dem::Vec3 force_N = dem::Vec3::Zero();
    dem::Vec3 torque_N_m = dem::Vec3::Zero(); ///< [N m] about the body's origin
};

/// One observation interval: runs `steps` steps and returns each of `bodies`' mean load; with
/// `plane_forces`, also every plane's mean reaction force over the interval (a plane keeps
/// only its last step's).
std::vector<MeanLoad> observeInterval(dem::DemSystem &system, std::uint64_t steps,
                                      std::initializer_list<int> bodies,
                                      std::vector<dem::Vec3> *plane_forces = nullptr);

/// Writes a result's report.txt, its CSVs (Result::writeCsvs) and summary.json into
/// `directory`, creating it.
template <class Result> void writeLabOutputs(const Result &result, const std::string &directory) {
    std::filesystem::create_directories(directory);
    result.writeCsvs(directory);
    const auto report = std::filesystem::path(directory) / "report.txt";
    std::ofstream out(report);
    if (!out)
        throw std::runtime_error("cannot write " + report.string());
    out << result.report();
    writeLabSummary(result.summary(), (std::filesystem::path(directory) / "summary.json").string());
}

/// Runs `experiment`, which gives the test's steps:
///
///     const Scenario &scenario;                        // its `name` names the result
///     using Result = ...;  // a LabResult with runs, report(), summary() and writeCsvs(dir)
///     Bed prepareBed(double progress_interval_s) const; // once; Bed has a LabBedSummary summary
///     Result start(const Bed &bed) const;               // what the result holds besides runs
///     std::vector<double> conditions() const;           // one run each (plate radius, stress...)
///     Run run(const Bed &bed, double condition, double progress_interval_s) const;
///     void fit(Result &result) const;                   // std::invalid_argument: no fit
///
/// `run` drives the tool into its own copy of the bed and observes it over intervals; `fit`
/// fits the runs' curves. A fit that throws std::invalid_argument leaves its message in
/// `fit_note` and the runs in the result.
template <class Experiment>
typename Experiment::Result runLabExperiment(const Experiment &experiment,
                                             const LabRunOptions &options) {
    const auto start = std::chrono::steady_clock::now();
    const auto bed = experiment.prepareBed(options.progress_interval_s);
    typename Experiment::Result result = experiment.start(bed);
    result.scenario = experiment.scenario.name;
    result.bed = bed.summary;
    for (double condition : experiment.conditions())
        result.runs.push_back(experiment.run(bed, condition, options.progress_interval_s));
    try {
        experiment.fit(result);
    } catch (const std::invalid_argument &e) {
        result.fit_note = e.what();
    }
    result.wall_s = secondsSince(start);
    if (!options.output_directory.empty())
        writeLabOutputs(result, options.output_directory);
    return result;
}

} // namespace grainlink::lab
