// Tangential contact against Coulomb statics and rigid-body dynamics: the two-angle stick/slip
// law of seed eq. 5 and a sphere rolling or slipping down an incline (docs/physics.md §2.4-2.5).
#include "Fixtures.hpp"

#include <catch2/catch.hpp>

using namespace grainlink::dem;
using namespace grainlink::dem::testing;

namespace {

/// Overlap of a grain pressed on a wall of its own material by `load_N`.
double restingOverlap(double load_N) {
    return std::pow(load_N / (4.0 / 3.0 * effectiveModulus(kMaterial) * std::sqrt(kRadius)),
                    2.0 / 3.0);
}

} // namespace

TEST_CASE("TangentialLinear: sticks up to F_N tan(phi_h), slides at F_N tan(phi_g)",
          "[dem][contact][friction]") {
    // A sphere rests on a plane under gravity; a horizontal pull P(t) acts on it (applied as the
    // impulse P dt after each step) and its rotation is held by a huge moment of inertia, so the
    // contact sees a pure tangential load. Measured from the motion alone:
    //  - P at the onset of sliding / weight = tan(phi_h);
    //  - while sliding, m a = P - W tan(phi_g), also for phi_g < P/W < phi_h (hysteresis);
    //  - at a lower pull it stops and sticks again, the wall then carrying exactly P.
    const double phi_h = 35.0, phi_g = 25.0;
    const double c_t = 1000.0; // N/m, ~0.4 of the normal contact stiffness at rest
    ContactLaw law = hertzViscous(1.0, c_t, phi_h, phi_g);
    std::get<TangentialLinear>(law.tangential).damping_N_s_m = 1.0; // ~0.4 critical
    DemSettings settings;
    settings.time_step_s = 1e-5;
    settings.gravity_m_s2 = Vec3(0, 0, -kG);
    DemSystem sys(law, {kMaterial}, settings);
    PlaneWall floor;
    floor.name = "floor";
    sys.addPlane(floor);
    const double m = sphereMass(kRadius, kMaterial.density_kg_m3);
    const double weight = m * kG;
    ParticleSpec spec =
        sphere(Vec3(0, 0, kRadius - restingOverlap(weight)), kRadius, kMaterial.density_kg_m3);
    spec.inertia_kg_m2 = Vec3::Constant(1e3); // ~1e11 x the solid sphere's: rotation held
    sys.particles().add(spec);
    auto& p = sys.particles();
    const double dt = settings.time_step_s;
    const double stick_limit = weight * std::tan(deg(phi_h));
    const double slide_force = weight * std::tan(deg(phi_g));
    const double mid = 0.5 * (stick_limit + slide_force);
    auto pulled = [&](double pull_N) {
        sys.step();
        p.velocity[0].x() += pull_N * dt / m;
    };
    auto tangentialRatio = [&] {
        const Vec3 f = sys.planeForce(0);
        return std::abs(f.x()) / -f.z();
    };

    // 1. Ramp to the midway pull in 0.2 s and hold it 0.1 s: it must stick all along. The spring
    // alone gives way by at most P / c_T (dynamic overshoot of the damped spring: +10 %).
    const double rate = mid / 0.2; // N/s, slow against the 7 ms tangential period
    double max_shift = 0.0, max_ratio = 0.0;
    for (int k = 0; k < 30000; ++k) {
        pulled(std::min(mid, rate * dt * k));
        max_shift = std::max(max_shift, std::abs(p.position[0].x()));
        max_ratio = std::max(max_ratio, tangentialRatio());
    }
    CHECK(max_shift < 1.1 * mid / c_t);
    CHECK(max_ratio < 1.02 * mid / weight); // never near either friction limit
    // Static: the wall carries the pull and the weight (damped spring at rest: 1e-3).
    CHECK(sys.planeForce(0).x() == Approx(mid).epsilon(1e-3));
    CHECK(-sys.planeForce(0).z() == Approx(weight).epsilon(1e-3));

    // 2. Keep ramping at the same rate until the wall reaction says the contact slides (the
    // kernel then delivers exactly W tan(phi_g)). Onset pull: 1e-3, the lag of the damped spring
    // behind the ramp is k_T/c_T * rate = 1e-3 s * rate, 2e-4 of the limit (measured 3e-5).
    double pull = mid;
    int steps = 0;
    while (std::abs(tangentialRatio() - std::tan(deg(phi_g))) > 1e-9 && steps++ < 100000)
        pulled(pull += rate * dt);
    INFO("onset pull / weight = " << pull / weight << ", tan(phi_h) = " << std::tan(deg(phi_h)));
    CHECK(pull == Approx(stick_limit).epsilon(1e-3));
    CHECK(std::abs(p.position[0].x()) < 1.1 * stick_limit / c_t); // not moved before the onset

    // 3. Drop the pull back to midway: below the stick limit, yet it keeps sliding, accelerating
    // at (P - W tan phi_g) / m. Acceleration over 45 ms after a 5 ms transient: 1 %.
    for (int k = 0; k < 500; ++k)
        pulled(mid);
    const double v0 = p.velocity[0].x();
    double worst_ratio_error = 0.0;
    for (int k = 0; k < 4500; ++k) {
        pulled(mid);
        worst_ratio_error =
            std::max(worst_ratio_error, std::abs(tangentialRatio() / std::tan(deg(phi_g)) - 1.0));
    }
    CHECK(worst_ratio_error < 1e-9); // sliding every step: the kernel's exact W tan(phi_g)
    const double a_sliding = (p.velocity[0].x() - v0) / (4500 * dt);
    CHECK(a_sliding == Approx((mid - slide_force) / m).epsilon(1e-2));

    // 4. Pull at half the sliding friction: decelerates at (P - W tan phi_g) / m, stops, sticks,
    // and the wall takes the pull again (damped spring at rest: 1e-3).
    const double low = 0.5 * slide_force;
    const double v1 = p.velocity[0].x();
    for (int k = 0; k < 1000; ++k)
        pulled(low);
    CHECK((p.velocity[0].x() - v1) / (1000 * dt) == Approx((low - slide_force) / m).epsilon(1e-2));
    for (int k = 0; k < 20000; ++k)
        pulled(low);
    // At rest: the end-of-step velocity carries the pull's impulse P dt / m (2.5e-5 m/s), so
    // judge by the drift over 0.1 s; sliding at even 1 mm/s would move 1e-4 m.
    const double x_stuck = p.position[0].x();
    for (int k = 0; k < 10000; ++k)
        pulled(low);
    CHECK(std::abs(p.position[0].x() - x_stuck) < 1e-8);
    CHECK(sys.planeForce(0).x() == Approx(low).epsilon(1e-3));
}

TEST_CASE("Sphere on an incline rolls at 5/7 g sin(theta) or slips at g(sin - mu cos)",
          "[dem][contact][friction][incline]") {
    // Solid sphere released at rest on a plane tilted by theta, gravity down, Mindlin contact with
    // Coulomb coefficient mu. Rigid-body result: rolls without slipping with a = 5/7 g sin(theta)
    // while tan(theta) <= 7/2 mu, otherwise slips with a = g (sin(theta) - mu cos(theta)). The
    // acceleration is measured along the slope from the velocity between 50 ms (the tangential
    // spring has settled) and 250 ms: tolerance 1 %. Cases straddle the limit mu = 2/7 tan(theta).
    struct Case {
        double theta_deg, mu;
        bool rolls;
    };
    const std::vector<Case> cases = {
        {20.0, 0.5, true}, {30.0, 0.18, true}, {30.0, 0.15, false}, {40.0, 0.2, false}};
    for (const Case& c : cases) {
        const double theta = deg(c.theta_deg);
        INFO("theta = " << c.theta_deg << " deg, mu = " << c.mu
                        << ", 2/7 tan(theta) = " << 2.0 / 7.0 * std::tan(theta));
        REQUIRE(c.rolls == (std::tan(theta) <= 3.5 * c.mu));
        DemSettings settings;
        settings.time_step_s = 1e-5;
        settings.gravity_m_s2 = Vec3(0, 0, -kG);
        DemSystem sys(hertzRestitution(0.5, c.mu), {kMaterial}, settings);
        PlaneWall incline;
        incline.name = "incline";
        incline.normal = Vec3(std::sin(theta), 0, std::cos(theta));
        sys.addPlane(incline);
        const Vec3 downhill(std::cos(theta), 0, -std::sin(theta));
        const double m = sphereMass(kRadius, kMaterial.density_kg_m3);
        const double load = m * kG * std::cos(theta);
        sys.particles().add(sphere(incline.normal * (kRadius - restingOverlap(load)), kRadius,
                                   kMaterial.density_kg_m3));
        auto& p = sys.particles();
        sys.run(5000);
        const double v1 = p.velocity[0].dot(downhill);
        sys.run(20000);
        const double v2 = p.velocity[0].dot(downhill);
        const double a = (v2 - v1) / (20000 * settings.time_step_s);
        const double a_theory = c.rolls ? 5.0 / 7.0 * kG * std::sin(theta)
                                        : kG * (std::sin(theta) - c.mu * std::cos(theta));
        CHECK(a == Approx(a_theory).epsilon(1e-2));
        // Sharper: the kernel's rolling radius is the contact arm r - delta, not r, which lowers
        // the rolling acceleration by ~0.8 delta/r / 1.4 = 1e-3 here (measured offset 9e-4).
        // With it, rolling matches to 2e-4 and a slipping sphere (no radius involved) to 1e-4.
        const double arm = kRadius - restingOverlap(load);
        const double a_arm = kG * std::sin(theta) / (1.0 + 0.4 * kRadius * kRadius / (arm * arm));
        CHECK(a == Approx(c.rolls ? a_arm : a_theory).epsilon(c.rolls ? 2e-4 : 1e-4));
        // Rolling: contact point at rest, w (r - delta) = v (1e-3); slipping: w r clearly below v.
        const double spin_speed = p.angular_velocity[0].dot(Vec3::UnitY()) * arm;
        if (c.rolls)
            CHECK(spin_speed == Approx(v2).epsilon(1e-3));
        else
            CHECK(spin_speed < 0.9 * v2);
    }
}
