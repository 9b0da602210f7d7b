#include "grainlink/coupling/CouplingGuard.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace grainlink::coupling {

double lagOneAutocorrelation(const std::vector<double> &values) {
    const double n = double(values.size());
    if (values.size() < 3)
        return 0.0;
    double mean = 0.0;
    for (double v : values)
        mean += v / n;
    double variance = 0.0, lagged = 0.0;
    for (std::size_t k = 0; k < values.size(); ++k) {
        variance += (values[k] - mean) * (values[k] - mean);
        if (k > 0)
            lagged += (values[k] - mean) * (values[k - 1] - mean);
    }
    // Below round-off of the mean the signal is constant: no oscillation to speak of.
    if (variance <= 1e-24 * (mean * mean * n + 1e-300))
        return 0.0;
    return lagged / variance;
}

void CouplingGuard::restart() {
    span_.clear();
    energy_warned_ = oscillation_warned_ = false;
}

std::optional<GuardWarning> CouplingGuard::afterWindow(double work_multibody_J, double work_soil_J,
                                                       const std::vector<Wrench> &wrenches,
                                                       double macro_step_s) {
    if (!settings_.enabled)
        return std::nullopt;
    Window w{work_multibody_J - work_soil_J, work_soil_J, {}};
    for (const Wrench &wrench : wrenches)
        for (int i = 0; i < 3; ++i)
            w.forces.push_back(wrench.force_N[i]);
    exchanged_J_ += std::abs(work_soil_J);
    ++windows_;
    span_.push_back(std::move(w));
    if (span_.size() > settings_.span_windows)
        span_.pop_front();
    if (span_.size() < settings_.span_windows)
        return std::nullopt;

    char text[512];
    if (!energy_warned_) {
        double mismatch = 0.0, exchanged = 0.0;
        for (const Window &s : span_) {
            mismatch += s.mismatch_J;
            exchanged += std::abs(s.soil_work_J);
        }
        // A quiet span (a body at rest) is judged against the run's usual exchange, not its
        // own near-zero one, where round-off would look like a large share.
        const double typical = exchanged_J_ / double(windows_) * double(span_.size());
        const double scale = std::max(exchanged, typical);
        const double ratio = scale > 0.0 ? std::abs(mismatch) / scale : 0.0;
        if (ratio > settings_.energy_ratio) {
            energy_warned_ = true;
            // An explicit coupling's mismatch is first order in the macro step (§7.6): scale
            // it down to the threshold, with a margin.
            const double step = 0.8 * macro_step_s * settings_.energy_ratio / ratio;
            std::snprintf(text, sizeof text,
                          "the energy mismatch over the last %u windows, %.3g J, is "
                          "%.1f %% of the %.3g J the soil exchanged with the bodies (threshold "
                          "%.3g %%, coupling.guard.energy_ratio): the macro step %.3g s is too "
                          "long for these contacts; about %.2g s should bring it under the "
                          "threshold",
                          settings_.span_windows, mismatch, 100.0 * ratio, exchanged,
                          100.0 * settings_.energy_ratio, macro_step_s, step);
            return GuardWarning{GuardWarning::Kind::Energy, ratio, step, text};
        }
    }
    if (!oscillation_warned_ && !span_.front().forces.empty()) {
        double lowest = 1.0;
        std::size_t component = 0;
        for (std::size_t c = 0; c < span_.front().forces.size(); ++c) {
            component_.clear(); // reused: this runs after every window
            for (const Window &s : span_)
                if (c < s.forces.size())
                    component_.push_back(s.forces[c]);
            const double r = lagOneAutocorrelation(component_);
            if (r < lowest) {
                lowest = r;
                component = c;
            }
        }
        if (lowest < settings_.oscillation_autocorrelation) {
            oscillation_warned_ = true;
            const double step = 0.5 * macro_step_s;
            std::snprintf(text, sizeof text,
                          "the soil's force on body '%s' (%c) flips from window to "
                          "window: lag-1 autocorrelation %.2f over the last %u windows (threshold "
                          "%.2f, coupling.guard.oscillation_autocorrelation), the mark of an "
                          "unstable explicit coupling; try a macro step of %.2g s or implicit "
                          "coupling",
                          component / 3 < wrenches.size() ? wrenches[component / 3].body.c_str()
                                                           : "?",
                          "xyz"[component % 3], lowest, settings_.span_windows,
                          settings_.oscillation_autocorrelation, step);
            return GuardWarning{GuardWarning::Kind::Oscillation, lowest, step, text};
        }
    }
    return std::nullopt;
}

} // namespace grainlink::coupling
