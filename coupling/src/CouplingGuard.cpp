#include "grainlink/coupling/CouplingGuard.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace grainlink::coupling {

namespace {

/// A figure first order in the macro step (an explicit coupling's mismatch, §7.6) brought from
/// `measured` under `threshold` by scaling the step down, with a margin.
double firstOrderStep(double macro_step_s, double threshold, double measured) {
    return 0.8 * macro_step_s * threshold / measured;
}

} // namespace

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
    energy_warned_ = oscillation_warned_ = bounce_warned_ = false;
    bounce_run_ = 0;
    pending_.reset();
}

std::optional<GuardWarning> CouplingGuard::afterWindow(double work_multibody_J, double work_soil_J,
                                                       const std::vector<Wrench> &wrenches,
                                                       const std::vector<BodyState> &states,
                                                       double macro_step_s) {
    if (!settings_.enabled)
        return std::nullopt;
    Window w{work_multibody_J - work_soil_J, work_soil_J, macro_step_s, {}, {}, {}};
    for (const Wrench &wrench : wrenches) {
        for (int i = 0; i < 3; ++i)
            w.forces.push_back(wrench.force_N[i]);
        const auto state = std::find_if(states.begin(), states.end(),
                                        [&](const BodyState &s) { return s.body == wrench.body; });
        if (state == states.end())
            continue;
        for (int i = 0; i < 3; ++i) {
            w.loads.push_back(wrench.force_N[i]);
            w.motions.push_back(state->linear_velocity_m_s[i]);
            w.loads.push_back(wrench.torque_N_m[i]);
            w.motions.push_back(state->angular_velocity_rad_s[i]);
        }
    }
    exchanged_J_ += std::abs(work_soil_J);
    ++windows_;
    span_.push_back(std::move(w));
    if (span_.size() > settings_.span_windows)
        span_.pop_front();
    if (span_.size() < settings_.span_windows)
        return std::nullopt;
    std::optional<GuardWarning> warning = energy(macro_step_s);
    if (!warning)
        warning = oscillation(wrenches, macro_step_s);
    // The bounce is judged at every span's end, whatever else fired; its warning waits for a
    // window without another one.
    auto bounced = bounce(macro_step_s);
    if (warning) {
        if (bounced)
            pending_ = std::move(bounced);
        return warning;
    }
    return bounced ? bounced : std::exchange(pending_, std::nullopt);
}

std::optional<GuardWarning> CouplingGuard::energy(double macro_step_s) {
    if (energy_warned_)
        return std::nullopt;
    double mismatch = 0.0, exchanged = 0.0;
    for (const Window &s : span_) {
        mismatch += s.mismatch_J;
        exchanged += std::abs(s.soil_work_J);
    }
    // A quiet span (a body at rest) is judged against the run's usual exchange, not its own
    // near-zero one, where round-off would look like a large share.
    const double typical = exchanged_J_ / double(windows_) * double(span_.size());
    const double scale = std::max(exchanged, typical);
    const double ratio = scale > 0.0 ? std::abs(mismatch) / scale : 0.0;
    if (ratio <= settings_.energy_ratio)
        return std::nullopt;
    energy_warned_ = true;
    const double step = firstOrderStep(macro_step_s, settings_.energy_ratio, ratio);
    char text[512];
    std::snprintf(text, sizeof text,
                  "the energy mismatch over the last %u windows, %.3g J, is %.1f %% of the %.3g J "
                  "the soil exchanged with the bodies (threshold %.3g %%, "
                  "coupling.guard.energy_ratio): the macro step %.3g s is too long for these "
                  "contacts; about %.2g s should bring it under the threshold",
                  settings_.span_windows, mismatch, 100.0 * ratio, exchanged,
                  100.0 * settings_.energy_ratio, macro_step_s, step);
    return GuardWarning{GuardWarning::Kind::Energy, ratio, step, text};
}

std::optional<GuardWarning> CouplingGuard::oscillation(const std::vector<Wrench> &wrenches,
                                                       double macro_step_s) {
    if (oscillation_warned_ || span_.front().forces.empty())
        return std::nullopt;
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
    if (lowest >= settings_.oscillation_autocorrelation)
        return std::nullopt;
    oscillation_warned_ = true;
    const double step = 0.5 * macro_step_s;
    char text[512];
    std::snprintf(text, sizeof text,
                  "the soil's force on body '%s' (%c) flips from window to window: lag-1 "
                  "autocorrelation %.2f over the last %u windows (threshold %.2f, "
                  "coupling.guard.oscillation_autocorrelation), the mark of an unstable explicit "
                  "coupling; try a macro step of %.2g s or implicit coupling",
                  component / 3 < wrenches.size() ? wrenches[component / 3].body.c_str() : "?",
                  "xyz"[component % 3], lowest, settings_.span_windows,
                  settings_.oscillation_autocorrelation, step);
    return GuardWarning{GuardWarning::Kind::Oscillation, lowest, step, text};
}

std::optional<GuardWarning> CouplingGuard::bounce(double macro_step_s) {
    // Judged once per span (consecutive spans do not overlap), on the loads matched to a state.
    if (bounce_warned_ || windows_ % settings_.span_windows != 0 || span_.front().loads.empty())
        return std::nullopt;
    const std::size_t components = span_.front().loads.size();
    std::vector<double> load_mean(components, 0.0), motion_mean(components, 0.0);
    for (const Window &s : span_)
        for (std::size_t c = 0; c < components && c < s.loads.size(); ++c) {
            load_mean[c] += s.loads[c] / double(span_.size());
            motion_mean[c] += s.motions[c] / double(span_.size());
        }
    // The work the fluctuating loads do on the fluctuating motion, over the span and its thirds.
    double work = 0.0, mismatch = 0.0, first_third = 0.0, last_third = 0.0;
    const std::size_t third = span_.size() / 3;
    for (std::size_t k = 0; k < span_.size(); ++k) {
        const Window &s = span_[k];
        double w = 0.0;
        for (std::size_t c = 0; c < components && c < s.loads.size(); ++c)
            w += std::abs((s.loads[c] - load_mean[c]) * (s.motions[c] - motion_mean[c])) * s.step_s;
        work += w;
        mismatch += s.mismatch_J;
        if (k < third)
            first_third += w;
        else if (k >= span_.size() - third)
            last_third += w;
    }
    const double share = work > 0.0 ? mismatch / work : 0.0;
    // Created energy (not lost) at a steady share, in a motion that is not dying down.
    const bool feeding = share > settings_.bounce_energy_share && last_third >= 0.5 * first_third;
    bounce_run_ = feeding ? bounce_run_ + 1 : 0;
    if (bounce_run_ < settings_.bounce_spans)
        return std::nullopt;
    bounce_warned_ = true;
    // The share is about (π/2) ω H for a bounce of angular frequency ω: first order in H too.
    const double step = firstOrderStep(macro_step_s, settings_.bounce_energy_share, share);
    char text[512];
    std::snprintf(text, sizeof text,
                  "the coupling feeds a bounce: for %u spans of %u windows it created %.1f %% of "
                  "the work the fluctuating soil load did on the bodies' fluctuating motion "
                  "(%.3g J of %.3g J in the last), and the motion did not die down (threshold "
                  "%.3g %%, coupling.guard.bounce_energy_share): the macro step %.3g s is too "
                  "long for this motion; about %.2g s or implicit coupling should damp it",
                  bounce_run_, settings_.span_windows, 100.0 * share, mismatch, work,
                  100.0 * settings_.bounce_energy_share, macro_step_s, step);
    return GuardWarning{GuardWarning::Kind::Bounce, share, step, text};
}

} // namespace grainlink::coupling
