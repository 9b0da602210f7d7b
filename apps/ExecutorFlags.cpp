#include "ExecutorFlags.hpp"

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <vector>

namespace grainlink::apps {

std::string thisExecutable() {
    return std::filesystem::read_symlink("/proc/self/exe").string();
}

std::string shipped(const std::string &relative) {
    namespace fs = std::filesystem;
    const fs::path exe = fs::path(thisExecutable()).parent_path();
    std::vector<fs::path> places;
    if (const char *share = std::getenv("GRAINLINK_SHARE"))
        places.push_back(fs::path(share) / relative);
    for (const fs::path &p : {exe / ".." / "share" / "grainlink" / relative,
                              exe / ".." / ".." / relative, fs::path(relative)})
        places.push_back(p);
    std::string looked;
    for (const fs::path &p : places) {
        if (fs::exists(p))
            return fs::canonical(p).string();
        looked += (looked.empty() ? "" : ", ") + p.lexically_normal().string();
    }
    throw std::runtime_error("cannot find the shipped file " + relative + " (looked in: " +
                             looked + "); set GRAINLINK_SHARE to the folder that holds it");
}

void ExecutorFlags::addTo(CLI::App &command) {
    command.add_option("--executor", executor, "local (a process pool) or slurm (a job array)")
        ->check(CLI::IsMember({"local", "slurm"}));
    command.add_option("--jobs", jobs, "local: runs at once (jobs x threads <= cores)");
    command.add_flag("--oversubscribe", oversubscribe, "local: allow jobs x threads > cores");
    command.add_flag("--retry-failed", retry_failed, "rerun the runs that failed before");
    command.add_option("--partition", partition, "slurm: sbatch --partition");
    command.add_option("--account", account, "slurm: sbatch --account");
    command.add_option("--time", time_limit, "slurm: time limit per run (sbatch --time)");
    command.add_option("--max-running", max_running, "slurm: array tasks at once (%M)");
    command.add_option("--sbatch-arg", sbatch_args, "slurm: one more sbatch argument");
    command.add_option("--progress-interval", progress_interval_s, "seconds between progress lines");
}

study::ExecutorOptions ExecutorFlags::options() const {
    study::ExecutorOptions o;
    o.executor = executor == "slurm" ? study::ExecutorOptions::Executor::Slurm
                                     : study::ExecutorOptions::Executor::Local;
    o.grainlink = thisExecutable();
    o.jobs = jobs;
    o.oversubscribe = oversubscribe;
    o.retry_failed = retry_failed;
    o.slurm.partition = partition;
    o.slurm.account = account;
    o.slurm.time_limit = time_limit;
    o.slurm.max_running = max_running;
    o.slurm.extra = sbatch_args;
    o.progress_interval_s = progress_interval_s;
    return o;
}

} // namespace grainlink::apps
