// The Slurm executor: one job array through sbatch, one array task per unfinished point, each
// task `grainlink study run-point DIR ID`; followed with squeue, final states from sacct.
#include "Executors.hpp"

#include "grainlink/study/ChildProcess.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace grainlink::study {

namespace fs = std::filesystem;

namespace {

/// Quotes a word for the generated bash script.
std::string shellWord(const std::string &word) {
    std::string quoted = "'";
    for (char c : word)
        quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return quoted + "'";
}

std::string batchScript(const Study &study, const StudyFolder &folder, const std::string &list,
                        std::size_t tasks, int threads, const ExecutorOptions &options,
                        const std::string &directory) {
    const SlurmOptions &slurm = options.slurm;
    std::ostringstream s;
    s << "#!/bin/bash\n"
      << "# Written by grainlink study: one array task per point of " << list << "\n"
      << "#SBATCH --job-name=grainlink-" << study.name << "\n"
      << "#SBATCH --array=0-" << tasks - 1;
    if (slurm.max_running > 0)
        s << '%' << slurm.max_running;
    s << "\n#SBATCH --ntasks=1\n#SBATCH --cpus-per-task=" << threads << "\n"
      << "#SBATCH --output=" << folder.slurmPath() << "/task-%A_%a.out\n"
      << "#SBATCH --chdir=" << directory << "\n";
    if (!slurm.partition.empty())
        s << "#SBATCH --partition=" << slurm.partition << "\n";
    if (!slurm.account.empty())
        s << "#SBATCH --account=" << slurm.account << "\n";
    if (!slurm.time_limit.empty())
        s << "#SBATCH --time=" << slurm.time_limit << "\n";
    s << "export OMP_WAIT_POLICY=PASSIVE\n"
      << "id=$(sed -n \"$((SLURM_ARRAY_TASK_ID + 1))p\" " << shellWord(list) << ")\n"
      << "exec " << shellWord(options.grainlink) << " study run-point "
      << shellWord(folder.directory()) << " \"$id\""
      << (options.retry_failed ? " --retry-failed" : "") << "\n";
    return s.str();
}

/// Array tasks of `job` still in the queue (pending or running), from squeue.
std::map<std::string, std::size_t> queued(const std::string &job) {
    const Captured c = capture({"squeue", "-h", "-r", "-j", job, "-o", "%T"});
    std::map<std::string, std::size_t> states;
    if (!c.status.ok()) {
        // A job that has left the queue: squeue says "Invalid job id" once it is purged.
        if (c.output.find("Invalid job id") != std::string::npos)
            return states;
        throw std::runtime_error("squeue failed (" + c.status.describe() + "): " + c.output);
    }
    std::istringstream lines(c.output);
    for (std::string state; lines >> state;)
        ++states[state];
    return states;
}

/// Final state and exit code of each array task ("FAILED 1:0"), when accounting is on.
std::map<std::string, std::string> accounted(const std::string &job) {
    const Captured c =
        capture({"sacct", "-n", "-X", "-P", "-j", job, "-o", "JobID,State,ExitCode"});
    std::map<std::string, std::string> states;
    if (!c.status.ok())
        return states; // accounting disabled: the folders alone tell
    std::istringstream lines(c.output);
    for (std::string line; std::getline(lines, line);) {
        const auto bar = line.find('|');
        if (bar == std::string::npos)
            continue;
        std::string rest = line.substr(bar + 1);
        std::replace(rest.begin(), rest.end(), '|', ' ');
        states[line.substr(0, bar)] = rest;
    }
    return states;
}

} // namespace

void runSlurm(const Study &study, const StudyFolder &folder, const std::vector<std::size_t> &todo,
              const ExecutorOptions &options, std::vector<PointResult> &results) {
    const std::string directory =
        options.working_directory.empty() ? fs::current_path().string() : options.working_directory;
    fs::create_directories(folder.slurmPath());
    int array = 0;
    while (fs::exists(folder.slurmPath() + "/array-" + std::to_string(array) + ".txt"))
        ++array;
    const std::string stem = folder.slurmPath() + "/array-" + std::to_string(array);
    std::string ids;
    int threads = 1;
    for (std::size_t k : todo) {
        ids += study.points[k].id + "\n";
        threads = std::max(threads, study.points[k].threads);
    }
    writeFileAtomically(stem + ".txt", ids);
    writeFileAtomically(stem + ".sbatch", batchScript(study, folder, stem + ".txt", todo.size(),
                                                      threads, options, directory));
    std::vector<std::string> sbatch{"sbatch", "--parsable"};
    sbatch.insert(sbatch.end(), options.slurm.extra.begin(), options.slurm.extra.end());
    sbatch.push_back(stem + ".sbatch");
    const Captured submitted = capture(sbatch);
    if (!submitted.status.ok())
        throw std::runtime_error("sbatch " + stem + ".sbatch failed (" +
                                 submitted.status.describe() + "): " + submitted.output);
    std::string job = submitted.output.substr(0, submitted.output.find_first_of(";\n"));
    {
        std::ofstream jobs(folder.slurmPath() + "/jobs.txt", std::ios::app);
        jobs << job << ' ' << stem << ".txt\n";
    }
    for (std::size_t k : todo)
        results[k].error = "queued in Slurm job " + job;
    if (options.slurm.submit_only)
        return;

    const auto start = std::chrono::steady_clock::now();
    std::vector<double> ran_s;
    while (true) {
        const auto states = queued(job);
        std::size_t running = states.count("RUNNING") ? states.at("RUNNING") : 0;
        std::size_t waiting = 0;
        for (const auto &[state, n] : states)
            waiting += n;
        ran_s.clear();
        for (std::size_t k : todo) {
            results[k] = folder.state(study.points[k]);
            results[k].ran_now = results[k].status != PointStatus::Unfinished;
            if (results[k].ran_now)
                ran_s.push_back(results[k].wall_s);
        }
        if (waiting == 0)
            break;
        if (options.progress)
            options.progress(
                progressOf(results, running, ran_s, int(std::max<std::size_t>(running, 1)), start));
        std::this_thread::sleep_for(std::chrono::duration<double>(options.slurm.poll_interval_s));
    }
    const auto final_states = accounted(job);
    for (std::size_t n = 0; n < todo.size(); ++n) {
        PointResult &r = results[todo[n]];
        if (r.status != PointStatus::Unfinished)
            continue;
        const std::string task = job + "_" + std::to_string(n);
        const auto state = final_states.find(task);
        r.log = folder.slurmPath() + "/task-" + task + ".out";
        r.error = "Slurm task " + task + " left no result" +
                  (state != final_states.end() ? " (" + state->second + ")" : "") +
                  "; rerun the study to run it again";
    }
    if (options.progress)
        options.progress(progressOf(results, 0, ran_s, 1, start));
}

} // namespace grainlink::study
