// The local executor: a pool of `jobs` runs at once, never more threads than cores.
#include "Executors.hpp"

#include <sched.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace grainlink::study {

namespace {

int availableCores() {
    cpu_set_t set;
    if (sched_getaffinity(0, sizeof set, &set) == 0)
        return CPU_COUNT(&set);
    return int(std::max(1u, std::thread::hardware_concurrency()));
}

} // namespace

void runLocal(const Study &study, const StudyFolder &folder, const std::vector<std::size_t> &todo,
              const ExecutorOptions &options, std::vector<PointResult> &results) {
    if (options.jobs < 1)
        throw std::invalid_argument("--jobs must be at least 1");
    int threads = 1;
    for (std::size_t k : todo)
        threads = std::max(threads, study.points[k].threads);
    const int cores = availableCores();
    if (options.jobs * threads > cores && !options.oversubscribe)
        throw std::invalid_argument(
            "--jobs " + std::to_string(options.jobs) + " x " + std::to_string(threads) +
            " threads per run = " + std::to_string(options.jobs * threads) + " exceeds the " +
            std::to_string(cores) + " cores here: lower --jobs or --threads, or --oversubscribe");
    const std::string directory = options.working_directory.empty()
                                      ? std::filesystem::current_path().string()
                                      : options.working_directory;

    const auto start = std::chrono::steady_clock::now();
    std::mutex mutex;
    std::condition_variable changed;
    std::size_t running = 0, finished = 0;
    std::vector<double> ran_s;
    std::atomic<std::size_t> next{0};
    const int pool = std::min<int>(options.jobs, int(todo.size()));
    auto work = [&] {
        for (std::size_t n; (n = next++) < todo.size();) {
            const std::size_t k = todo[n];
            {
                std::lock_guard<std::mutex> hold(mutex);
                ++running;
            }
            PointResult r;
            try {
                r = folder.runPoint(study.points[k], options.grainlink, directory,
                                    options.retry_failed);
            } catch (const std::exception &e) { // the study folder itself, not the run
                r.point = study.points[k];
                r.status = PointStatus::Failed;
                r.error = e.what();
            }
            std::lock_guard<std::mutex> hold(mutex);
            --running;
            ++finished;
            if (r.ran_now && r.status != PointStatus::Unfinished)
                ran_s.push_back(r.wall_s);
            results[k] = std::move(r);
            changed.notify_all();
        }
    };
    std::vector<std::thread> workers;
    for (int w = 0; w < pool; ++w)
        workers.emplace_back(work);
    {
        const auto interval = std::chrono::duration<double>(options.progress_interval_s);
        auto last_report = start;
        std::unique_lock<std::mutex> hold(mutex);
        while (finished < todo.size()) {
            changed.wait_for(hold, interval);
            const auto now = std::chrono::steady_clock::now();
            if (options.progress && finished < todo.size() && now - last_report >= interval) {
                options.progress(progressOf(results, running, ran_s, pool, start));
                last_report = now;
            }
        }
    }
    for (auto &w : workers)
        w.join();
    if (options.progress)
        options.progress(progressOf(results, 0, ran_s, pool, start));
}

} // namespace grainlink::study
