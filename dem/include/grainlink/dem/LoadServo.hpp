#pragma once
// Force servo for a body pressed onto the soil: turns the soil reaction measured over the last
// interval into the body's speed for the next one, so that the reaction stays at a target
// (bevameter shear annulus, direct-shear top plate, the compaction plate of a bed's
// preparation; docs/physics.md §12.11).
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace grainlink::dem {

/// Proportional force control of the approach speed with a deadband and a speed clamp:
///
///     e = F_target - F_measured
///     e' = sign(e) max(|e| - deadband, 0)          (continuous at the deadband's edges)
///     u = clamp(gain e', -max_speed, max_speed)     approach speed, > 0 pushes into the soil
///
/// A body pressing down moves with vertical velocity v_z = -u (verticalVelocity()).
/// Against a soil of contact stiffness k [N/m] sampled every dt [s] the loop
/// F_{n+1} = F_n + k gain dt e_n converges without overshoot for k gain dt <= 1 and is unstable
/// beyond 2; pick gain <= 1 / (k dt).
///
/// Against soil that gives way at a steady rate v (a shearing annulus digging in) the
/// proportional law lags the target by v / gain. update() adds an integral term for that:
///     I += integral_gain e' dt   (only while the sum stays inside the clamp: no wind-up)
///     u = clamp(gain e' + I, -max_speed, max_speed)
/// which removes the lag once I has grown to v.
struct LoadServo {
    double target_force_N = 0.0;           ///< [N] wanted soil reaction along the pressing axis
    double gain_m_s_per_N = 0.0;           ///< [m/(s N)] approach speed per newton of error
    double max_speed_m_s = 0.0;            ///< [m/s] clamp on the approach speed, both ways
    double deadband_N = 0.0;               ///< [N] errors this small leave the body at rest
    double integral_gain_m_s2_per_N = 0.0; ///< [m/(s^2 N)] update() only; 0: proportional
    double integral_m_s = 0.0;             ///< [m/s] update()'s integral term, starts at 0

    /// Throws std::invalid_argument naming the member that is out of range.
    void validate() const {
        auto fail = [](const char *what, double value, const char *rule) {
            std::ostringstream msg;
            msg << "LoadServo: " << what << " = " << value << " " << rule;
            throw std::invalid_argument(msg.str());
        };
        if (!std::isfinite(target_force_N))
            fail("target_force_N", target_force_N, "must be finite");
        if (!(gain_m_s_per_N > 0.0) || !std::isfinite(gain_m_s_per_N))
            fail("gain_m_s_per_N", gain_m_s_per_N, "must be > 0 and finite");
        if (!(max_speed_m_s > 0.0) || !std::isfinite(max_speed_m_s))
            fail("max_speed_m_s", max_speed_m_s, "must be > 0 and finite");
        if (!(deadband_N >= 0.0) || !std::isfinite(deadband_N))
            fail("deadband_N", deadband_N, "must be >= 0 and finite");
        if (!(integral_gain_m_s2_per_N >= 0.0) || !std::isfinite(integral_gain_m_s2_per_N))
            fail("integral_gain_m_s2_per_N", integral_gain_m_s2_per_N, "must be >= 0 and finite");
    }

    /// Approach speed [m/s] (> 0: into the soil) for the reaction measured over the last
    /// interval, docs/physics.md §12.11.
    double approachSpeed(double measured_force_N) const {
        const double u = gain_m_s_per_N * error(measured_force_N);
        return std::clamp(u, -max_speed_m_s, max_speed_m_s);
    }

    /// Proportional-integral approach speed [m/s] for the reaction measured over the interval
    /// of `interval_s` just ended; advances the integral term (physics.md §12.11).
    double update(double measured_force_N, double interval_s) {
        const double e = error(measured_force_N);
        const double integral = integral_m_s + integral_gain_m_s2_per_N * e * interval_s;
        if (std::abs(gain_m_s_per_N * e + integral) <= max_speed_m_s)
            integral_m_s = integral;
        return std::clamp(gain_m_s_per_N * e + integral_m_s, -max_speed_m_s, max_speed_m_s);
    }

    /// Vertical velocity [m/s] of a body pressing down (z up): -approachSpeed().
    double verticalVelocity(double measured_force_N) const {
        return -approachSpeed(measured_force_N);
    }

private:
    /// e' = sign(e) max(|e| - deadband, 0) with e = target - measured [N].
    double error(double measured_force_N) const {
        const double e = target_force_N - measured_force_N;
        return std::copysign(std::max(std::abs(e) - deadband_N, 0.0), e);
    }
};

} // namespace grainlink::dem
