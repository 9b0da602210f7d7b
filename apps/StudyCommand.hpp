#pragma once
// `grainlink study STUDY.yaml --out DIR`, `grainlink study collect DIR` (docs/study.md).
#include "ExecutorFlags.hpp"

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace grainlink::study {
struct Study;
}

namespace grainlink::apps {

class StudyCommand {
public:
    /// Adds `study` (with `collect` and the Slurm tasks' `run-point`) to the command line.
    explicit StudyCommand(CLI::App &app);
    bool parsed() const { return command_->parsed(); }
    /// Runs what was parsed; returns the exit code (1 when a point failed).
    int run() const;

private:
    int runStudy() const;
    int dryRun(const study::Study &s) const;
    int collect() const;
    int runPoint() const;

    CLI::App *command_, *collect_, *run_point_;
    std::string study_path_, directory_, point_id_;
    ExecutorFlags executor_;
    int threads_ = 0; ///< 0: each scenario's own simulation.threads
    bool submit_only_ = false;
    bool dry_run_ = false;
};

} // namespace grainlink::apps
