// `grainlink study`: many runs of one base scenario through a local pool or Slurm, collected
// into tables (docs/study.md). The machinery is the study library; this is its command line.
#include "StudyCommand.hpp"

#include "grainlink/study/Design.hpp"
#include "grainlink/study/ResultTable.hpp"
#include "grainlink/study/StudyFolder.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace grainlink::apps {

namespace {

namespace fs = std::filesystem;
using study::PointResult;
using study::PointStatus;

std::string duration(double s) {
    char text[32];
    if (s < 0.0)
        return "?";
    if (s < 120.0)
        std::snprintf(text, sizeof text, "%.0f s", s);
    else
        std::snprintf(text, sizeof text, "%.0f min %02.0f s", std::floor(s / 60.0),
                      std::fmod(s, 60.0));
    return text;
}

void printProgress(const study::StudyProgress &p) {
    std::fprintf(stderr, "[study] %zu/%zu done, %zu running, %zu failed; %s elapsed, ETA %s\n",
                 p.done, p.total, p.running, p.failed, duration(p.elapsed_s).c_str(),
                 duration(p.eta_s).c_str());
}

/// The closing report: counts, every failed or unfinished point, the tables; exit code.
int report(const study::Study &s, const std::vector<PointResult> &results) {
    std::size_t done = 0, failed = 0, unfinished = 0, ran = 0;
    for (const PointResult &r : results) {
        done += r.status == PointStatus::Done;
        failed += r.status == PointStatus::Failed;
        unfinished += r.status == PointStatus::Unfinished;
        ran += r.ran_now && r.status != PointStatus::Unfinished;
    }
    for (const PointResult &r : results) {
        if (r.status == PointStatus::Failed)
            std::printf("failed: %s (%s): %s; log %s\n", r.point.id.c_str(), r.point.label.c_str(),
                        r.error.c_str(), r.log.c_str());
        else if (r.status == PointStatus::Unfinished)
            std::printf("unfinished: %s (%s): %s\n", r.point.id.c_str(), r.point.label.c_str(),
                        r.error.c_str());
    }
    const study::TableFiles files = study::writeTables(s, results);
    for (const std::string &w : files.warnings)
        std::printf("warning: %s\n", w.c_str());
    std::printf("study '%s': %zu points: %zu done (%zu run now), %zu failed, %zu unfinished\n",
                s.name.c_str(), results.size(), done, ran, failed, unfinished);
    std::printf("written: %s, %s, %s; plot with tools/plot_study.py %s\n", files.points_csv.c_str(),
                files.table_csv.c_str(), files.table_md.c_str(), s.directory.c_str());
    return failed ? 1 : 0;
}

} // namespace

StudyCommand::StudyCommand(CLI::App &app) {
    command_ = app.add_subcommand(
        "study", "run a study: a base scenario over a design of keys, replicates and "
                 "observables, locally or through Slurm (docs/study.md)");
    command_->add_option("study", study_path_, "study YAML file");
    command_->add_option("--out", directory_, "the study folder");
    executor_.addTo(*command_);
    command_->add_option("--threads", threads_,
                         "threads per run (sets each point's simulation.threads)");
    command_->add_flag("--submit-only", submit_only_,
                       "slurm: submit and return; `grainlink study collect DIR` later");
    command_->add_flag("--dry-run", dry_run_,
                       "check every point's scenario and count what would run; run nothing");
    collect_ = command_->add_subcommand(
        "collect", "tables of a study folder as it stands (after --submit-only)");
    collect_->add_option("directory", directory_, "the study folder")->required();
    run_point_ = command_->add_subcommand("run-point", "run one point (a Slurm array task)");
    run_point_->group(""); // not for people: the generated job script calls it
    run_point_->add_option("directory", directory_, "the study folder")->required();
    run_point_->add_option("id", point_id_, "the point's id")->required();
    run_point_->add_flag("--retry-failed", executor_.retry_failed, "rerun it if it failed before");
}

int StudyCommand::run() const {
    if (collect_->parsed())
        return collect();
    if (run_point_->parsed())
        return runPoint();
    return runStudy();
}

int StudyCommand::runStudy() const {
    if (study_path_.empty() || directory_.empty())
        throw std::invalid_argument("usage: grainlink study STUDY.yaml --out DIR "
                                    "(or grainlink study collect DIR)");
    // Locally there is nothing to return early from: the pool would run every point.
    if (submit_only_ && executor_.executor != "slurm")
        throw std::invalid_argument("--submit-only submits a Slurm job array and returns: it "
                                    "needs --executor slurm");
    const auto start = std::chrono::steady_clock::now();
    study::DesignOptions design;
    if (threads_ > 0)
        design.threads = threads_;
    const study::Study s = study::loadStudy(study_path_, directory_, design);
    if (dry_run_)
        return dryRun(s);

    study::ExecutorOptions options = executor_.options();
    options.slurm.submit_only = submit_only_;
    options.progress = printProgress;
    std::fprintf(stderr, "[study] '%s': %zu points into %s (%s)\n", s.name.c_str(), s.points.size(),
                 s.directory.c_str(), executor_.executor.c_str());
    const std::vector<PointResult> results = study::run(s, options);
    const int code = report(s, results);

    // The machinery's own cost: each point's time beyond its run (start-up, bookkeeping,
    // collection), plus validation, folder and tables shared over the points.
    double point_overhead_s = 0.0, runs_s = 0.0;
    std::size_t ran = 0;
    for (const PointResult &r : results)
        if (r.ran_now && r.status != PointStatus::Unfinished) {
            point_overhead_s += r.wall_s - r.run_wall_s;
            runs_s += r.wall_s;
            ++ran;
        }
    const double total_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (ran > 0 && options.executor == study::ExecutorOptions::Executor::Local) {
        const double shared_s = std::max(
            0.0, total_s - runs_s / double(std::min<std::size_t>(std::size_t(executor_.jobs), ran)));
        std::printf("study machinery: %.3f s per point (start-up, bookkeeping, collection) over "
                    "%zu runs; %.2f s wall in all\n",
                    point_overhead_s / double(ran) + shared_s / double(results.size()), ran,
                    total_s);
    }
    if (submit_only_)
        std::printf("submitted: follow with squeue, then grainlink study collect %s\n",
                    s.directory.c_str());
    return submit_only_ ? 0 : code;
}

int StudyCommand::dryRun(const study::Study &s) const {
    // What `run` checks before it starts, and what it would then run; nothing is written.
    study::validate(s);
    std::size_t done = 0, failed = 0, to_run = 0;
    for (const PointResult &r : study::collect(s)) {
        done += r.status == PointStatus::Done;
        failed += r.status == PointStatus::Failed;
        to_run += study::runsAgain(r, executor_.retry_failed);
    }
    std::printf("study '%s': %zu points, every scenario valid; %zu done, %zu failed, %zu to run "
                "into %s\n",
                s.name.c_str(), s.points.size(), done, failed, to_run, s.directory.c_str());
    return 0;
}

int StudyCommand::collect() const {
    const study::StudyFolder folder(directory_);
    const study::Study s = folder.read();
    return report(s, study::collect(s));
}

int StudyCommand::runPoint() const {
    const study::StudyFolder folder(directory_);
    const study::Study s = folder.read();
    for (const study::Point &p : s.points) {
        if (p.id != point_id_)
            continue;
        const PointResult r =
            folder.runPoint(p, thisExecutable(), fs::current_path().string(), executor_.retry_failed);
        std::printf("point %s (%s): %s%s%s\n", p.id.c_str(), p.label.c_str(),
                    r.status == PointStatus::Done     ? "done"
                    : r.status == PointStatus::Failed ? "failed: "
                                                      : "unfinished: ",
                    r.status == PointStatus::Done ? "" : r.error.c_str(),
                    r.ran_now ? "" : " (not run now)");
        return r.status == PointStatus::Done ? 0 : 1;
    }
    throw std::invalid_argument("no point '" + point_id_ + "' in " + folder.directory() +
                                "/study.json");
}

} // namespace grainlink::apps
