#include "grainlink/lab/LabExperiment.hpp"

namespace grainlink::lab {

std::vector<MeanLoad> observeInterval(dem::DemSystem &system, std::uint64_t steps,
                                      std::initializer_list<int> bodies) {
    for (int b : bodies)
        system.body(b).resetAccumulatedImpulse();
    system.run(steps);
    std::vector<MeanLoad> loads;
    for (int b : bodies) {
        const dem::MeshBody &body = system.body(b);
        loads.push_back({body.impulse_N_s / body.accumulated_time_s,
                         body.angular_impulse_N_m_s / body.accumulated_time_s});
    }
    return loads;
}

} // namespace grainlink::lab
