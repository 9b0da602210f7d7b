#pragma once
// The two ways a study runs its unfinished points (private to the study library).
#include "grainlink/study/StudyFolder.hpp"

#include <chrono>

namespace grainlink::study {

/// Results of `todo` (indices into study.points) go into `results`, which holds every point's
/// state on disk when called.
void runLocal(const Study &study, const StudyFolder &folder, const std::vector<std::size_t> &todo,
              const ExecutorOptions &options, std::vector<PointResult> &results);
void runSlurm(const Study &study, const StudyFolder &folder, const std::vector<std::size_t> &todo,
              const ExecutorOptions &options, std::vector<PointResult> &results);

/// Progress counts over all points; `ran` are the point wall times of this call so far.
StudyProgress progressOf(const std::vector<PointResult> &results, std::size_t running,
                         const std::vector<double> &ran_s, int parallel,
                         std::chrono::steady_clock::time_point start);

} // namespace grainlink::study
