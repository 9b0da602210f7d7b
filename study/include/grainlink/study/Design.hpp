#pragma once
// A study file (docs/study.md): a base scenario, the keys to vary (full factorial or zipped),
// replicates over deposition seeds, and the observables; turned into the study's points.
#include "grainlink/study/Study.hpp"

#include <optional>
#include <string>

namespace grainlink::study {

struct DesignOptions {
    std::optional<int> threads; ///< `--threads`: every point's thread count (kind.threads_key)
};

/// Reads the study file and makes its points (not validated yet: `run` does that first).
/// Errors name the study file, the key and the line.
Study loadStudy(const std::string &path, const std::string &directory,
                const DesignOptions &options = {});

} // namespace grainlink::study
