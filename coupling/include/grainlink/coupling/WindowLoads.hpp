#pragma once
// The soil's load on the consumed bodies through one window, summed where a soil participant
// steps through it, and the window average the coupling transfers (docs/physics.md §7.1, §7.4):
//   impulse J = Σ F dt,  angular impulse L = Σ T dt,  work W = Σ (F·v + T·ω) dt,
//   wrench F̄ = J / H, T̄ = L / H  (H the window), so that H F̄ is the impulse the soil gave.
#include "grainlink/coupling/Participant.hpp"

#include <string>
#include <vector>

namespace grainlink::coupling {

class WindowLoads {
public:
    /// Zero load on each of `bodies` (a soil participant's consumed bodies, in their order).
    explicit WindowLoads(const std::vector<std::string> &bodies);

    /// One sub-step of `dt_s`: the force and the torque (about the body origin, world frame)
    /// held over it, and the body's velocities in it (they weigh the work).
    void add(std::size_t body, const Vec3 &force_N, const Vec3 &torque_N_m,
             const Vec3 &linear_velocity_m_s, const Vec3 &angular_velocity_rad_s, double dt_s);
    /// A whole window's totals, for a model that integrates them itself (an ODE with the impulse
    /// among its states, as the two-mass example's soil side).
    void addTotals(std::size_t body, const Vec3 &impulse_N_s, const Vec3 &angular_impulse_N_m_s,
                   double work_J);

    /// The window's outputs: per body the wrench J / H, L / H and the work W.
    WindowOutputs outputs(double duration_s) const;

private:
    struct Load {
        std::string body;
        Vec3 impulse_N_s = Vec3::Zero();           ///< [N s]
        Vec3 angular_impulse_N_m_s = Vec3::Zero(); ///< [N m s] about the body origin
        double work_J = 0.0;                       ///< [J]
    };
    std::vector<Load> loads_;
};

} // namespace grainlink::coupling
