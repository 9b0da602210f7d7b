#pragma once
// A study: many ordinary `grainlink` runs (points), each a fully resolved scenario, run through
// a local process pool or a Slurm job array into one folder, their summary.json files collected
// into tables (docs/study.md).
//
//   study::Study s;
//   s.name = "psi_vs_seed";
//   s.directory = "out/psi";
//   s.points.push_back(study::makePoint(study::standardKind("lab", "direct_shear"), yaml_text,
//                                       "seed 1"));
//   study::ExecutorOptions run_with;
//   run_with.grainlink = "build/apps/grainlink";
//   run_with.jobs = 2;
//   for (const study::PointResult &r : study::run(s, run_with))
//       if (r.status == study::PointStatus::Done)
//           use(r.summary["fit"]["psi_deg"]["value"]);
//
// A point's folder is named by a hash of its kind and resolved scenario, so the same point is
// the same folder whatever the order, executor or study: finished points are never rerun.
#include "grainlink/study/Kind.hpp"

#include <nlohmann/json.hpp>

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace grainlink::study {

struct Point {
    std::string id;     ///< hash of kind and scenario: the point's folder name
    std::string label;  ///< for people: "stick_angle_deg=32 seed=2"
    std::string origin; ///< where it came from, for errors: "study.yaml:9: key = value"
    Kind kind;
    std::string scenario_yaml; ///< fully resolved; relative file paths already absolute
    int threads = 1;           ///< the scenario's own thread count (kind.threads_key)
    /// The varied keys and their values as text (table columns); empty for code-built points.
    std::vector<std::pair<std::string, std::string>> settings;
};
/// A point of `kind` running `scenario_yaml`; its id and thread count are read from the text.
Point makePoint(const Kind &kind, const std::string &scenario_yaml, const std::string &label);

struct Study {
    std::string name;
    std::string source;    ///< the study file, when there is one (messages)
    std::string directory; ///< the study folder (points, tables, Slurm files)
    std::vector<Point> points;
    std::vector<std::string> observables; ///< dotted paths into each summary: `fit.psi_deg.value`
    std::vector<std::string> varied_keys; ///< table columns that group points
    std::string replicate_key;            ///< varies within a group (mean, sd, sem over it)
};

enum class PointStatus { Done, Failed, Unfinished };

struct PointResult {
    Point point;
    PointStatus status = PointStatus::Unfinished;
    bool ran_now = false;    ///< run in this call (false: found finished or failed before)
    std::string folder;      ///< the finished folder, or the failed one
    std::string log;         ///< the run's log (stdout and stderr)
    std::string error;       ///< why it failed or is unfinished
    nlohmann::json summary;  ///< the run's summary file, parsed (Done only)
    double wall_s = 0.0;     ///< [s] the point as the study saw it, start to collected
    double run_wall_s = 0.0; ///< [s] the run's own wall time (its summary's wall_s, else process)
};

struct StudyProgress {
    std::size_t total = 0, done = 0, failed = 0, running = 0, reused = 0;
    double elapsed_s = 0.0; ///< [s]
    double eta_s = -1.0;    ///< [s] estimate for the rest; < 0: not known yet
};

struct SlurmOptions {
    std::string partition, account; ///< empty: the cluster's defaults
    std::string time_limit;         ///< per array task, sbatch --time (e.g. "02:00:00")
    int max_running = 0;            ///< array throttle %M; 0: none
    std::vector<std::string> extra; ///< more sbatch arguments, as given
    bool submit_only = false;       ///< submit and return; `grainlink study collect` later
    double poll_interval_s = 2.0;   ///< [s] between squeue calls
};

struct ExecutorOptions {
    enum class Executor { Local, Slurm } executor = Executor::Local;
    std::string grainlink;         ///< the `grainlink` executable the points run with
    std::string working_directory; ///< the runs' working directory; empty: the current one
    int jobs = 1;                  ///< local: runs at once
    bool oversubscribe = false;    ///< local: allow jobs x threads above the cores
    bool retry_failed = false;     ///< rerun points that failed before
    SlurmOptions slurm;
    double progress_interval_s = 5.0; ///< [s] between progress calls
    std::function<void(const StudyProgress &)> progress;
};

/// Parses every point with its kind's own reader, in-process; throws naming the point's
/// origin (study file, key, value) before anything runs.
void validate(const Study &study);
/// Validates, writes the study folder, runs the unfinished points, and returns every point's
/// result in the study's order (Unfinished for points a submit-only Slurm run left queued).
std::vector<PointResult> run(const Study &study, const ExecutorOptions &options);
/// Every point's result as the study folder holds it now; runs nothing.
std::vector<PointResult> collect(const Study &study);
/// Whether a point in this state is run (again): unfinished, or failed with `retry_failed`.
bool runsAgain(const PointResult &result, bool retry_failed);

} // namespace grainlink::study
