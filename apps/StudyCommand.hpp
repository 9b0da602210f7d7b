#pragma once
// `grainlink study STUDY.yaml --out DIR`, `grainlink study collect DIR` (docs/study.md).
#include <CLI/CLI.hpp>

#include <string>
#include <vector>

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
    int collect() const;
    int runPoint() const;

    CLI::App *command_, *collect_, *run_point_;
    std::string study_path_, directory_, point_id_;
    std::string executor_ = "local";
    int jobs_ = 1;
    int threads_ = 0; ///< 0: each scenario's own simulation.threads
    bool oversubscribe_ = false, retry_failed_ = false, submit_only_ = false;
    std::string partition_, account_, time_limit_;
    int max_running_ = 0;
    std::vector<std::string> sbatch_args_;
    double progress_interval_s_ = 10.0;
};

} // namespace grainlink::apps
