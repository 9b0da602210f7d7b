#include "grainlink/dem/Progress.hpp"

#include <cmath>

namespace grainlink::dem {

Progress::Progress(std::string label, double interval_s, std::FILE *stream)
    : label_(std::move(label)), interval_s_(interval_s), stream_(stream),
      start_(std::chrono::steady_clock::now()), last_(start_) {}

double Progress::wallSeconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

double Progress::rate(std::uint64_t particle_steps) const {
    const double wall = wallSeconds();
    return wall > 0.0 ? double(particle_steps) / wall : 0.0;
}

bool Progress::due() const {
    return interval_s_ > 0.0 &&
           std::chrono::duration<double>(std::chrono::steady_clock::now() - last_).count() >=
               interval_s_;
}

void Progress::update(double sim_time_s, double fraction, std::uint64_t particle_steps,
                      const std::string &extra) {
    if (!due())
        return;
    const auto now = std::chrono::steady_clock::now();
    last_ = now;
    const double wall = wallSeconds();
    const double eta = fraction > 1e-9 ? wall * (1.0 - fraction) / fraction : NAN;
    char rate_text[48] = ""; // none for a process without grains (a multibody node)
    if (particle_steps > 0)
        std::snprintf(rate_text, sizeof rate_text, "  %.2f M particle-steps/s",
                      rate(particle_steps) / 1e6);
    std::fprintf(stream_, "[%s] t = %.4f s (%5.1f %%)  wall %s  ETA %s%s%s%s\n", label_.c_str(),
                 sim_time_s, 100.0 * fraction, formatDuration(wall).c_str(),
                 std::isfinite(eta) ? formatDuration(eta).c_str() : "?", rate_text,
                 extra.empty() ? "" : "  ", extra.c_str());
    std::fflush(stream_);
}

std::string formatDuration(double seconds) {
    char out[32];
    const long s = long(std::lround(seconds));
    if (s >= 3600)
        std::snprintf(out, sizeof out, "%ldh%02ldm", s / 3600, (s / 60) % 60);
    else if (s >= 60)
        std::snprintf(out, sizeof out, "%ldm%02lds", s / 60, s % 60);
    else
        std::snprintf(out, sizeof out, "%.1fs", seconds);
    return out;
}

} // namespace grainlink::dem
