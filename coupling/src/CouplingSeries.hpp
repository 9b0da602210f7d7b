#pragma once
// coupling.csv: one row per accepted window with the coupling's health (iterations, residual,
// energy mismatch) and every body's state and wrench. append() only queues the numbers; a writer
// thread formats and writes them every 0.1 s, off the window's critical path (formatting ~125
// numbers costs ~10 us, a tenth of a window's coupling latency). flush() writes everything queued
// before it returns (checkpoints, failures, the end); a resumed run drops the rows after its
// checkpoint.
#include "grainlink/coupling/Types.hpp"

#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
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
    /// Throws, naming the file and the reason, when a row could not be written (a full disk):
    /// a run must not go on, and end "complete", with its series cut short.
    void check() const;

private:
    struct Entry {
        Row row;
        std::vector<BodyState> states;
        std::vector<Wrench> wrenches;
    };
    void writeQueued();
    void writerLoop();

    std::string path_;
    std::FILE *file_ = nullptr;
    std::mutex queue_mutex_;            ///< guards queued_, spare_, stop_
    std::vector<Entry> queued_, spare_; ///< spare_: written entries, storage kept for reuse
    bool stop_ = false;
    std::condition_variable wake_;
    mutable std::mutex write_mutex_; ///< one writer at a time: rows stay in order
    std::vector<Entry> writing_; ///< under write_mutex_
    std::string line_;           ///< reused row buffer, under write_mutex_
    std::string error_;          ///< the first failed write, under write_mutex_
    std::thread writer_;
};

} // namespace grainlink::coupling
