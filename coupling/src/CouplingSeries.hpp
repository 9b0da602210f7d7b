#pragma once
// coupling.csv: one row per accepted window with the coupling's health (iterations, residual,
// energy mismatch) and every body's state and wrench. Rows reach the disk at most 0.5 s after
// their window, and at every checkpoint; a resumed run drops the rows after its checkpoint.
#include "grainlink/coupling/Types.hpp"

#include <chrono>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

namespace grainlink::coupling {

class CouplingSeries {
public:
    struct Row {
        std::uint64_t window = 0;
        double start_s = 0.0, end_s = 0.0;
        unsigned iterations = 1;
        double residual = 0.0;
        double work_multibody_J = 0.0, work_soil_J = 0.0;
        double cumulative_mismatch_J = 0.0;
        double wall_s = 0.0;
    };

    /// Creates <directory>/coupling.csv, or with `resume_window` keeps its rows before it.
    CouplingSeries(const std::string &directory, const std::vector<std::string> &bodies,
                   std::optional<std::uint64_t> resume_window);
    ~CouplingSeries();
    CouplingSeries(const CouplingSeries &) = delete;
    CouplingSeries &operator=(const CouplingSeries &) = delete;

    void append(const Row &row, const std::vector<BodyState> &states,
                const std::vector<Wrench> &wrenches);
    void flush();

private:
    std::string path_;
    std::FILE *file_ = nullptr;
    std::string line_; ///< reused row buffer
    std::chrono::steady_clock::time_point last_flush_;
};

} // namespace grainlink::coupling
