// Conservation laws of the whole step: energy without dissipation, linear and angular momentum
// with friction, damping and rolling resistance (docs/physics.md §2-3).
#include "Fixtures.hpp"

#include <catch2/catch.hpp>

using namespace grainlink::dem;
using namespace grainlink::dem::testing;

namespace {

struct Momenta {
    Vec3 linear = Vec3::Zero();
    Vec3 angular = Vec3::Zero(); ///< about the origin: sum m x × v + I w
    double linear_scale = 0.0;   ///< sum m |v|
    double angular_scale = 0.0;  ///< sum m |x||v| + I |w|
};

Momenta momenta(const ParticleStore& p) {
    Momenta out;
    for (std::size_t i = 0; i < p.size(); ++i) {
        const double inertia = p.inertia[i].x(); // solid spheres: isotropic
        out.linear += p.mass[i] * p.velocity[i];
        out.angular +=
            p.mass[i] * p.position[i].cross(p.velocity[i]) + inertia * p.angular_velocity[i];
        out.linear_scale += p.mass[i] * p.velocity[i].norm();
        out.angular_scale += p.mass[i] * p.position[i].norm() * p.velocity[i].norm() +
                             inertia * p.angular_velocity[i].norm();
    }
    return out;
}

} // namespace

TEST_CASE("Energy is conserved by elastic frictionless collisions in a box",
          "[dem][conservation][energy]") {
    // 200 grains, r = 3.5..4.5 mm, in a 60 mm box of six planes under gravity, restitution 1
    // (no dashpot), friction 0, no background damping: the only energy error is the integrator's.
    // Velocity Verlet with Hertz contacts resolved in ~50 steps has a bounded O(dt^2) error in
    // each contact and no secular drift in a smooth system; the kink in force at touch-down
    // (delta^1.5) leaves a small error per collision. Bound: 1e-3 of the initial kinetic energy
    // over ~2.5e4 collisions (measured 2.7e-4).
    DemSettings settings;
    settings.time_step_s = 2e-5;
    settings.gravity_m_s2 = Vec3(0, 0, -9.81);
    DemSystem sys(hertzRestitution(1.0, 0.0), {kMaterial}, settings);
    const Vec3 lower(0, 0, 0), upper(0.06, 0.06, 0.06);
    addBoxPlanes(sys, lower, upper);
    addLattice(sys, lower, upper, 0.01, 0.0035, 0.0045, kMaterial.density_kg_m3, 0.8, 200);
    REQUIRE(sys.particles().size() == 200);
    const double e0 = sys.energies().total();
    const double kinetic0 = kineticEnergy(sys);
    double worst = 0.0, contacts = 0.0;
    const int steps = 25000;
    for (int k = 0; k < steps; ++k) {
        sys.step();
        if (k % 10 == 0) {
            worst = std::max(worst, std::abs(sys.energies().total() - e0));
            contacts += double(sys.contactCount() + sys.wallContactCount());
        }
    }
    // Collisions counted as contact-steps / steps per contact (~50).
    const double collisions = 10.0 * contacts / 50.0;
    INFO("max |E - E0| / KE0 = " << worst / kinetic0 << ", ~" << collisions << " collisions");
    CHECK(collisions > 2000);
    CHECK(worst < 1e-3 * kinetic0);
}

TEST_CASE("Free granular gas conserves linear and angular momentum to round-off",
          "[dem][conservation][momentum]") {
    // No gravity, no walls, no background damping; Mindlin friction, restitution damping and EPSD
    // rolling resistance all act in pairs of equal and opposite forces with torques that balance
    // the moment of the force pair (arms r_i - delta/2 and r_j - delta/2 add up to the centre
    // distance), so velocity Verlet conserves P and L = sum m x × v + I w exactly up to
    // round-off: 1e-12 of sum m|v| and of sum (m |x||v| + I |w|) after 1e4 steps (measured
    // P 1e-16, L 8e-15). Two threads: the threaded force accumulation must lose nothing either.
    DemSettings settings = quietSettings(2e-5);
    settings.threads = 2;
    ContactLaw law = hertzRestitution(0.5, 0.5);
    law.rolling = RollingEpsd{0.1};
    DemSystem sys(law, {kMaterial}, settings);
    const Vec3 half(0.03, 0.03, 0.03);
    addLattice(sys, -half, half, 0.01, 0.0035, 0.0045, kMaterial.density_kg_m3, 0.3, 200, 11);
    auto& p = sys.particles();
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (std::size_t i = 0; i < p.size(); ++i) {
        p.velocity[i] -= 10.0 * p.position[i]; // converge: many collisions in a dense cluster
        p.angular_velocity[i] = 100.0 * Vec3(unit(rng), unit(rng), unit(rng));
    }
    const Momenta before = momenta(p);
    const double kinetic0 = kineticEnergy(sys);
    sys.run(10000);
    const Momenta after = momenta(p);
    const double dp = (after.linear - before.linear).norm() / before.linear_scale;
    const double dl = (after.angular - before.angular).norm() / before.angular_scale;
    INFO("relative change: P " << dp << ", L " << dl);
    CHECK(dp < 1e-12);
    CHECK(dl < 1e-12);
    // Not a free flight: collisions with friction and damping took out most of the energy.
    CHECK(kineticEnergy(sys) < 0.5 * kinetic0);
}
