#pragma once
// One progress line for long runs: simulated time, wall time, ETA, particle-steps per second.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>

namespace grainlink::dem {

class Progress {
public:
    /// `label` prefixes each line; lines go to `stream` at most every `interval_s` of wall time
    /// (none when it is 0).
    explicit Progress(std::string label, double interval_s = 5.0, std::FILE *stream = stderr);
    /// Reports if due. `fraction` of the phase done, `particle_steps` since construction (0: a
    /// process without grains, the line has no rate).
    void update(double sim_time_s, double fraction, std::uint64_t particle_steps,
                const std::string &extra = "");
    /// Whether the next update() prints: a caller whose line costs something asks first.
    bool due() const;
    double wallSeconds() const;
    double rate(std::uint64_t particle_steps) const; ///< particle-steps per wall second

private:
    std::string label_;
    double interval_s_;
    std::FILE *stream_;
    std::chrono::steady_clock::time_point start_, last_;
};

std::string formatDuration(double seconds);

} // namespace grainlink::dem
