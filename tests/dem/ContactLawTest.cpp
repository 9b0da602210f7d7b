// Two-body impacts against Hertz theory and restitution (docs/physics.md §2.1-2.3).
#include "Fixtures.hpp"

#include <catch2/catch.hpp>

using namespace grainlink::dem;
using namespace grainlink::dem::testing;

namespace {

struct ImpactResult {
    double duration_s;
    double rebound_speed_m_s;
    double max_overlap_m;
};

/// Runs a head-on collision of two equal spheres approaching at `speed` and times the contact.
ImpactResult collide(const ContactLaw &law, const Material &mat, double r, double speed,
                     double dt) {
    DemSystem sys(law, {mat}, quietSettings(dt));
    const double gap = 0.1 * r;
    sys.particles().add(sphere({-r - gap, 0, 0}, r, mat.density_kg_m3, {0.5 * speed, 0, 0}));
    sys.particles().add(sphere({r + gap, 0, 0}, r, mat.density_kg_m3, {-0.5 * speed, 0, 0}));
    bool touching = false;
    double start = 0.0, end = 0.0, max_overlap = 0.0;
    for (int k = 0; k < 10000000; ++k) {
        sys.step();
        const auto &x = sys.particles().position;
        const double overlap = 2.0 * r - (x[1] - x[0]).norm();
        max_overlap = std::max(max_overlap, overlap);
        if (!touching && overlap > 0.0) {
            touching = true;
            start = sys.time();
        } else if (touching && overlap <= 0.0) {
            end = sys.time();
            break;
        }
    }
    const auto &v = sys.particles().velocity;
    return {end - start, (v[1] - v[0]).x(), max_overlap};
}

} // namespace

TEST_CASE("Hertz head-on impact lasts as long as Hertz theory says", "[dem][contact]") {
    const Material mat = soil(1e7, 0.3, 2500.0);
    const double r = 0.005, speed = 0.5;
    const double e_star = mat.youngs_modulus_Pa / (2.0 * (1.0 - 0.09));
    const double m = 4.0 / 3.0 * M_PI * r * r * r * mat.density_kg_m3;
    const HertzImpact theory{e_star, r / 2.0, m / 2.0, speed};
    const double dt = theory.duration() / 2000.0;

    const ImpactResult elastic = collide(hertzRestitution(1.0, 0.0), mat, r, speed, dt);
    // Tolerance 2 %: the step resolves the contact in ~2000 steps, the theory is exact.
    CHECK(elastic.duration_s == Approx(theory.duration()).epsilon(0.02));
    CHECK(elastic.max_overlap_m == Approx(theory.maxOverlap()).epsilon(0.01));
    CHECK(elastic.rebound_speed_m_s == Approx(speed).epsilon(1e-3));
}
