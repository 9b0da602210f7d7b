// Coordinator and participants in one test binary, talking over inproc:// and tcp://127.0.0.1:*.
#include "grainlink/coupling/Coordinator.hpp"
#include "TwoMassDriver.hpp"
#include "TwoMassParticipant.hpp"

#include <catch2/catch.hpp>

#include <future>
#include <thread>

using namespace grainlink::coupling;
using grainlink::examples::runTwoMassSide;
using grainlink::examples::twoMassConfig;

namespace {

CoordinatorConfig twoMassRun(SchemeKind kind, const std::string &endpoint, double window_s,
                             double end_s) {
    CoordinatorConfig c;
    c.endpoint = endpoint;
    c.participants = {{"mbs", Role::Multibody, {}, false}, {"soil", Role::Soil, {}, false}};
    c.scheme.kind = kind;
    c.macro_step_s = window_s;
    c.end_time_s = end_s;
    c.handshake_timeout_s = 10;
    return c;
}

struct Outcome {
    CoordinatorSummary summary;
    double x1 = 0.0;
};

/// Runs the coordinator here and the two sides on threads.
Outcome runTwoMassNetworked(const CoordinatorConfig &config) {
    Coordinator coordinator(config);
    const std::string endpoint = coordinator.boundEndpoint();
    auto side = [endpoint](Role role, const char *name) {
        return std::async(std::launch::async, [=] {
            Participant p(twoMassConfig(role, name, endpoint));
            return runTwoMassSide(p);
        });
    };
    auto mbs = side(Role::Multibody, "mbs");
    auto soil = side(Role::Soil, "soil");
    Outcome out;
    out.summary = coordinator.run();
    out.x1 = mbs.get();
    soil.get();
    return out;
}

} // namespace

TEST_CASE("Networked two-mass runs equal the in-process scheme bit for bit",
          "[coupling][coordinator]") {
    // The transport must not change a single bit: same scheme, same participants' arithmetic.
    for (auto kind :
         {SchemeKind::ExplicitSerial, SchemeKind::ExplicitParallel, SchemeKind::Implicit}) {
        for (const char *endpoint : {"inproc://two-mass", "tcp://127.0.0.1:*"}) {
            auto config = twoMassRun(kind, endpoint, 0.01, 0.5);
            const auto networked = runTwoMassNetworked(config);
            // The window as the participants see it: a whole number of ticks.
            const double window_s = static_cast<double>(Ticks(10'000'000)) * config.tick_s;
            const auto reference = grainlink::testing::runTwoMass(config.scheme, window_s, 0.5);
            INFO(schemeName(kind) << " over " << endpoint);
            CHECK(networked.summary.windows == 50);
            CHECK(networked.x1 == reference.final_x1_m);
            CHECK(networked.summary.final_states[0].position_m.x() == reference.final_x1_m);
            CHECK(networked.summary.cumulative_mismatch_J ==
                  Approx(reference.work_mismatch_J).margin(1e-15));
            if (kind == SchemeKind::Implicit)
                CHECK(networked.summary.iterations == reference.total_iterations);
        }
    }
}
