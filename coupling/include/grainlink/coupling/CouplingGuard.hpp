#pragma once
// The coordinator's watch on the coupling itself: an explicit coupling whose macro step is too
// long for the contacts it carries injects energy (the coupling's energy mismatch grows against
// the work the sides exchange), makes the exchanged wrench flip sign from window to window, or
// feeds a slow bounce that the soil alone would damp (the energy it creates stays a steady share
// of the work the bounce moves back and forth, span after span).
// Past a threshold it warns once, with the measured figure and a macro step that would fix it
// (docs/physics.md §7.6 says how the thresholds were chosen).
#include "grainlink/coupling/Types.hpp"

#include <deque>
#include <optional>
#include <string>
#include <vector>

namespace grainlink::coupling {

struct GuardSettings {
    bool enabled = true;
    /// Warn when |Σ mismatch| over the span exceeds this share of the work the soil exchanged
    /// with the bodies over it (or, in a quiet span, of the run's mean exchange per span).
    double energy_ratio = 0.05;
    /// Warn when a force component's lag-1 autocorrelation over the span is below this
    /// (-1: it flips sign every window; white noise: 0; smooth: near +1).
    double oscillation_autocorrelation = -0.5;
    /// Warn when, in `bounce_spans` consecutive spans, the energy the coupling created is more
    /// than this share of the work the fluctuating wrench did on the fluctuating motion, and that
    /// motion did not die down within the span (a share r cancels the damping of a mode with a
    /// damping ratio up to about r/π).
    double bounce_energy_share = 0.06;
    unsigned bounce_spans = 3;
    unsigned span_windows = 500; ///< the sliding span every check is judged over
    /// With coupling.adaptive, the coordinator shortens the macro step itself on a warning.
    bool shorten = false;
};

/// What the guard found after a window: which check fired, the figure, the advice.
struct GuardWarning {
    enum class Kind { Energy, Oscillation, Bounce } kind;
    double measured = 0.0;          ///< the energy ratio, the autocorrelation or the bounce share
    double suggested_step_s = 0.0;  ///< a macro step that should bring it within its threshold
    std::string message;
};

class CouplingGuard {
public:
    explicit CouplingGuard(const GuardSettings &settings) : settings_(settings) {}

    /// After each window of length `macro_step_s`: its work on each side, the wrenches the
    /// soil returned and the bodies' states at its end. Each kind of warning is given once per
    /// run (and again only after restart(), when the macro step was changed because of it).
    std::optional<GuardWarning> afterWindow(double work_multibody_J, double work_soil_J,
                                            const std::vector<Wrench> &wrenches,
                                            const std::vector<BodyState> &states,
                                            double macro_step_s);
    /// Forgets the span (the macro step changed): the checks start over and may warn again.
    void restart();

private:
    struct Window {
        double mismatch_J, soil_work_J, step_s;
        std::vector<double> forces;  ///< every body's force components
        std::vector<double> loads;   ///< every body's force and torque components
        std::vector<double> motions; ///< the velocity matching each of `loads`
    };
    std::optional<GuardWarning> energy(double macro_step_s);
    std::optional<GuardWarning> oscillation(const std::vector<Wrench> &wrenches,
                                            double macro_step_s);
    std::optional<GuardWarning> bounce(double macro_step_s);

    GuardSettings settings_;
    std::deque<Window> span_;
    double exchanged_J_ = 0.0; ///< Σ |soil work| over the run so far
    std::size_t windows_ = 0;
    bool energy_warned_ = false, oscillation_warned_ = false, bounce_warned_ = false;
    unsigned bounce_run_ = 0;       ///< consecutive spans past the bounce share
    std::optional<GuardWarning> pending_; ///< a bounce warning found beside another one
    std::vector<double> component_; ///< one force component over the span (reused storage)
};

/// The lag-1 autocorrelation of `values` about their mean; 0 when they do not vary.
double lagOneAutocorrelation(const std::vector<double> &values);

} // namespace grainlink::coupling
