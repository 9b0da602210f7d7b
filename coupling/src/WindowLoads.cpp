#include "grainlink/coupling/WindowLoads.hpp"

namespace grainlink::coupling {

WindowLoads::WindowLoads(const std::vector<std::string> &bodies) {
    for (const auto &name : bodies)
        loads_.push_back({name});
}

void WindowLoads::add(std::size_t body, const Vec3 &force_N, const Vec3 &torque_N_m,
                      const Vec3 &linear_velocity_m_s, const Vec3 &angular_velocity_rad_s,
                      double dt_s) {
    Load &load = loads_.at(body);
    load.impulse_N_s += dt_s * force_N;
    load.angular_impulse_N_m_s += dt_s * torque_N_m;
    load.work_J +=
        (force_N.dot(linear_velocity_m_s) + torque_N_m.dot(angular_velocity_rad_s)) * dt_s;
}

void WindowLoads::addTotals(std::size_t body, const Vec3 &impulse_N_s,
                            const Vec3 &angular_impulse_N_m_s, double work_J) {
    Load &load = loads_.at(body);
    load.impulse_N_s += impulse_N_s;
    load.angular_impulse_N_m_s += angular_impulse_N_m_s;
    load.work_J += work_J;
}

WindowOutputs WindowLoads::outputs(double duration_s) const {
    if (!(duration_s > 0.0))
        throw CouplingError("the window's loads need a window of positive duration, got " +
                            std::to_string(duration_s) + " s");
    WindowOutputs out;
    for (const Load &load : loads_) {
        Wrench w;
        w.body = load.body;
        w.force_N = load.impulse_N_s / duration_s;
        w.torque_N_m = load.angular_impulse_N_m_s / duration_s;
        out.wrenches.push_back(std::move(w));
        out.work.push_back({load.body, load.work_J});
    }
    return out;
}

} // namespace grainlink::coupling
