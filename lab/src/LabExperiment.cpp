#include "grainlink/lab/LabExperiment.hpp"

namespace grainlink::lab {

std::vector<MeanLoad> observeInterval(dem::DemSystem &system, std::uint64_t steps,
                                      std::initializer_list<int> bodies,
                                      std::vector<dem::Vec3> *plane_forces) {
    for (int b : bodies)
        system.body(b).resetAccumulatedImpulse();
    if (plane_forces) {
        plane_forces->assign(system.planes().size(), dem::Vec3::Zero());
        for (std::uint64_t k = 0; k < steps; ++k) {
            system.step();
            for (std::size_t p = 0; p < plane_forces->size(); ++p)
                (*plane_forces)[p] += system.planeForce(int(p)) / double(steps);
        }
    } else {
        system.run(steps);
    }
    std::vector<MeanLoad> loads;
    for (int b : bodies) {
        const dem::MeshBody &body = system.body(b);
        loads.push_back({body.impulse_N_s / body.accumulated_time_s,
                         body.angular_impulse_N_m_s / body.accumulated_time_s});
    }
    return loads;
}

} // namespace grainlink::lab
