#pragma once
// The flags of every command whose simulations run through the study runner (`grainlink
// study`, `grainlink gap`): one spelling and one meaning for the executor, the local pool and
// the Slurm job array (docs/study.md).
#include "grainlink/study/Study.hpp"

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace grainlink::apps {

/// The running grainlink program (the study runner starts its points with it).
std::string thisExecutable();

/// A file the program ships (data/..., tools/..., scenarios/gap/...), found where it is, not
/// where the user stands: under $GRAINLINK_SHARE when set, beside the installed program
/// (<prefix>/share/grainlink), in the source tree of a build (build/apps/grainlink), or under
/// the current directory. Throws naming every place it looked.
std::string shipped(const std::string &relative);

struct ExecutorFlags {
    std::string executor = "local";
    int jobs = 1;
    bool oversubscribe = false, retry_failed = false;
    std::string partition, account, time_limit;
    int max_running = 0;
    std::vector<std::string> sbatch_args;
    double progress_interval_s = 10.0;

    /// Adds the flags to `command` (each help text says which executor it is for).
    void addTo(CLI::App &command);
    /// The runner's options for these flags, running this grainlink.
    study::ExecutorOptions options() const;
};

} // namespace grainlink::apps
