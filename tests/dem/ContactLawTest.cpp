// Two-body impacts against Hertz theory, between grains of one material and of two (docs/physics.md
// §2.1), and the EPSD rolling spring against a harmonic oscillator (§2.6).
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

TEST_CASE("Hertz impact of two materials: E*, R* and m* of the pair set the duration",
          "[dem][contact][materials]") {
    // A small stiff dense grain meets a large soft light one: the impact is the one-body Hertz
    // problem with 1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2, R* = r1 r2/(r1+r2), m* = m1 m2/(m1+m2).
    // Momentum is exchanged as for two elastic balls: after the impact u1' = u1 - 2 m*/m1 du.
    const Material hard = soil(5e7, 0.15, 7800.0), soft = soil(4e6, 0.4, 1200.0);
    const double r1 = 0.003, r2 = 0.006, speed = 0.4;
    const double m1 = 4.0 / 3.0 * M_PI * std::pow(r1, 3) * 7800.0;
    const double m2 = 4.0 / 3.0 * M_PI * std::pow(r2, 3) * 1200.0;
    const double e_star = 1.0 / ((1.0 - 0.15 * 0.15) / 5e7 + (1.0 - 0.4 * 0.4) / 4e6);
    const HertzImpact theory{e_star, r1 * r2 / (r1 + r2), m1 * m2 / (m1 + m2), speed};
    const double dt = theory.duration() / 2000.0;
    DemSystem sys(hertzRestitution(1.0, 0.0), {hard, soft}, quietSettings(dt));
    const double gap = 0.05 * r1;
    ParticleSpec a = sphere({-r1 - gap, 0, 0}, r1, 7800.0, {speed, 0, 0});
    ParticleSpec b = sphere({r2 + gap, 0, 0}, r2, 1200.0);
    a.material = 0;
    b.material = 1;
    sys.particles().add(a);
    sys.particles().add(b);
    double start = -1.0, end = -1.0, max_overlap = 0.0;
    for (int k = 0; k < 100000 && end < 0.0; ++k) {
        sys.step();
        const auto &x = sys.particles().position;
        const double overlap = r1 + r2 - (x[1] - x[0]).norm();
        max_overlap = std::max(max_overlap, overlap);
        if (start < 0.0 && overlap > 0.0)
            start = sys.time();
        else if (start >= 0.0 && overlap <= 0.0)
            end = sys.time();
    }
    CHECK(end - start == Approx(theory.duration()).epsilon(0.02));
    CHECK(max_overlap == Approx(theory.maxOverlap()).epsilon(0.01));
    const auto &v = sys.particles().velocity;
    const double m_star = theory.mass_eff_kg;
    CHECK(v[0].x() == Approx(speed - 2.0 * m_star / m1 * speed).epsilon(1e-3));
    CHECK(v[1].x() == Approx(2.0 * m_star / m2 * speed).epsilon(1e-3));
    // Either grain's own material pair would give another duration (checked to differ by > 10 %).
    const double e_hard = 5e7 / (2.0 * (1.0 - 0.15 * 0.15)), e_soft = 4e6 / (2.0 * (1.0 - 0.16));
    for (double other : {e_hard, e_soft}) {
        const HertzImpact wrong{other, theory.radius_eff_m, m_star, speed};
        CHECK(std::abs(wrong.duration() / theory.duration() - 1.0) > 0.1);
    }
}

TEST_CASE("EPSD rolling: a small spin on a wall rocks at sqrt(k_r / J), elastically",
          "[dem][contact][rolling]") {
    // A grain resting on a frictionless floor (mu = 0: no tangential force, so its centre stays
    // put) is given a spin below the rolling cap. The EPSD spring k_r = 2.25 mu_r^2 R*^2 S_n
    // (Ai et al. 2011, docs/physics.md §2.6; R* = r at a wall, S_n = 2 E* sqrt(r d) at the
    // resting overlap d) is then the only moment: J theta'' = -k_r theta with J = 2/5 m r^2. The
    // spin first vanishes after a quarter period pi / (2 Omega), Omega = sqrt(k_r / J), and comes
    // back reversed with the same size (an elastic spring, no dashpot).
    const Material mat = soil(1e7, 0.3, 2500.0);
    const double r = 0.005, mu_r = 0.1, g = 9.81, w0 = 0.5, dt = 1e-5;
    ContactLaw law = hertzRestitution(0.3, 0.0);
    law.rolling = RollingEpsd{mu_r};
    DemSettings settings = quietSettings(dt);
    settings.gravity_m_s2 = Vec3(0, 0, -g);
    DemSystem sys(law, {mat}, settings);
    PlaneWall floor;
    floor.name = "floor";
    sys.addPlane(floor);
    const double m = 4.0 / 3.0 * M_PI * std::pow(r, 3) * 2500.0;
    const double e_star = 1e7 / (2.0 * (1.0 - 0.09));
    const double rest = std::pow(m * g / (4.0 / 3.0 * e_star * std::sqrt(r)), 2.0 / 3.0);
    ParticleSpec p = sphere(Vec3(0, 0, r - rest), r, 2500.0);
    p.angular_velocity_rad_s = Vec3(0, w0, 0);
    sys.particles().add(p);
    const double k_r = 2.25 * mu_r * mu_r * r * r * 2.0 * e_star * std::sqrt(r * rest);
    const double omega = std::sqrt(k_r / (0.4 * m * r * r));
    REQUIRE(k_r * w0 / omega < 0.5 * mu_r * r * m * g); // the moment stays below half the cap
    double crossing = -1.0, lowest = w0, before = w0;
    while (sys.time() < 0.75 * 2.0 * M_PI / omega) {
        sys.step();
        const double w = sys.particles().angular_velocity[0].y();
        if (crossing < 0.0 && w <= 0.0)
            crossing = sys.time() - dt * w / (w - before); // linear between the two steps
        lowest = std::min(lowest, w);
        before = w;
    }
    CHECK(crossing == Approx(0.5 * M_PI / omega).epsilon(0.01));
    CHECK(lowest == Approx(-w0).epsilon(0.01));
    CHECK(sys.particles().velocity[0].head<2>().norm() < 1e-9); // no tangential force
}
