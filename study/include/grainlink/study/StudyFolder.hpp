#pragma once
// The study folder on disk, which every executor and `grainlink study collect` share:
//   study.json            the study: its points (id, label, kind, settings), observables, keys
//   scenarios/ID.yaml     each point's resolved scenario
//   points/ID/            a finished point: the run's outputs, log.txt, point.json
//   points/ID.failed/     a failed point: log.txt, error.txt (rerun only with --retry-failed)
//   points/ID.tmp-PID/    a point being run by process PID (renamed to points/ID on success)
//   points/ID.lock        held (flock) by the process running the point
//   slurm/                job scripts, array lists, task logs, submitted job ids
// A point's folder is complete or absent: readers never see a half-written one.
#include "grainlink/study/Study.hpp"

#include <string>

namespace grainlink::study {

class StudyFolder {
public:
    explicit StudyFolder(std::string directory);
    const std::string &directory() const { return directory_; }

    std::string scenarioPath(const Point &point) const;
    std::string pointPath(const Point &point) const;
    std::string failedPath(const Point &point) const;
    std::string slurmPath() const;

    /// Writes study.json and the points' scenarios (each file replaced atomically).
    void write(const Study &study) const;
    /// The study as study.json and scenarios/ hold it (kinds without their validators).
    Study read() const;

    /// What is on disk for a point: Done (summary parsed), Failed (error and log) or Unfinished.
    PointResult state(const Point &point) const;
    /// Runs the point unless it is finished, failed (and not `retry_failed`) or being run by
    /// another process; `grainlink` is the executable, `directory` the run's working folder.
    PointResult runPoint(const Point &point, const std::string &grainlink,
                         const std::string &directory, bool retry_failed) const;

private:
    std::string directory_;
};

/// Writes `text` to `path` through a temporary file and a rename.
void writeFileAtomically(const std::string &path, const std::string &text);

} // namespace grainlink::study
