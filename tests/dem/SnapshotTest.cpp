// The in-memory full-state snapshot (DemSystem::saveState / restoreState) that implicit coupling
// needs to repeat a window: after a restore the same steps give bit-identical results
// (docs/physics.md §6).
#include "Fixtures.hpp"

#include "grainlink/dem/Deposition.hpp"

#include <catch2/catch.hpp>

using namespace grainlink::dem;
using namespace grainlink::dem::testing;

namespace {

/// 300 grains with the grain-shape rolling law (anisotropic, seed eq. 12 inertia) in a box of
/// planes, a re-sort every 3 list builds, settled for 0.1 s; a wheel above them.
std::unique_ptr<DemSystem> shapedBox(int threads) {
    DemSettings settings;
    settings.time_step_s = 5e-5;
    settings.threads = threads;
    settings.resort_every_builds = 3;
    ContactLaw law = hertzRestitution(0.3, 0.5);
    RollingGrainShape shape;
    shape.aspect_ratio_angle_deg = Vec3(30.0, 20.0, 40.0);
    shape.inertia = RollingGrainShape::Inertia::SeedEq12;
    law.rolling = shape;
    auto sys =
        std::make_unique<DemSystem>(law, std::vector<Material>{soil(3e6, 0.2, 2400)}, settings);
    addBoxPlanes(*sys, Vec3::Zero(), Vec3(0.08, 0.05, 0.3));
    DepositionSpec spec;
    spec.region_lower_m = Vec3::Zero();
    spec.region_upper_m = Vec3(0.08, 0.05, 0.06);
    spec.count = 300;
    spec.radius.kind = RadiusDistribution::Kind::Uniform;
    spec.radius.min_m = 0.0025;
    spec.radius.max_m = 0.0035;
    spec.seed = 4;
    Random random(spec.seed);
    insertRandom(*sys, spec, random, spec.count, spec.region_lower_m, spec.region_upper_m);
    RigidBodyState above;
    above.position_m = Vec3(0.04, 0.025, 0.1);
    sys->addBody(MeshBody("wheel", makeCylinder(0.02, 0.03, 24), above));
    sys->run(2000);
    return sys;
}

/// A coupling window taking the wheel `depth_m` lower from where it is, turning and rolling on.
WindowMotion press(const DemSystem &sys, double depth_m) {
    WindowMotion m;
    m.start_s = sys.time();
    m.duration_s = 0.04;
    m.a = sys.body(0).state();
    m.b = m.a;
    m.b.position_m += Vec3(0.005, 0.0, -depth_m);
    m.a.angular_velocity_rad_s = m.b.angular_velocity_rad_s = Vec3(0, 5, 0);
    m.b.linear_velocity_m_s = Vec3(0.1, 0, -0.3);
    m.b.orientation = rotationFromVector(m.duration_s * Vec3(0, 5, 0)) * m.a.orientation;
    return m;
}

struct Outcome {
    ParticleStore particles;
    BodyLoads wheel;
    double time_s;
    std::uint64_t steps, builds;
    std::size_t contacts, wall_contacts;
    std::vector<Vec3> plane_force;
};

Outcome outcome(const DemSystem &sys) {
    Outcome o{sys.particles(),       sys.body(0).loads(),   sys.time(),
              sys.stepCount(),       sys.neighbourBuilds(), sys.contactCount(),
              sys.wallContactCount(), {}};
    for (int k = 0; k < int(sys.planes().size()); ++k)
        o.plane_force.push_back(sys.planeForce(k));
    return o;
}

bool identical(const ParticleStore &a, const ParticleStore &b) {
    return a.id == b.id && a.position == b.position && a.velocity == b.velocity &&
           a.angular_velocity == b.angular_velocity && a.force == b.force && a.torque == b.torque &&
           std::equal(a.orientation.begin(), a.orientation.end(), b.orientation.begin(),
                      [](const Quat &p, const Quat &q) { return p.coeffs() == q.coeffs(); });
}

} // namespace

TEST_CASE("saveState / restoreState: repeating the same steps gives bit-identical results",
          "[dem][snapshot]") {
    // As implicit coupling uses it: save at the window's start, run the window, roll back, run
    // it again with another motion (a second iteration), roll back, run the first motion again:
    // the last run must equal the first bit for bit, with grain-shape rolling histories, mesh
    // and plane contacts, list rebuilds and re-sorts inside the window. Two threads too: the
    // contact pass's thread split and its summation order are part of the state.
    const int threads = GENERATE(1, 2);
    CAPTURE(threads);
    auto sys = shapedBox(threads);
    // Down into the bed (about 14 mm deep), 4 mm below its top: mesh histories at the save.
    double top = 0.0;
    for (std::size_t i = 0; i < sys->particles().size(); ++i)
        top = std::max(top, sys->particles().position[i].z() + sys->particles().radius[i]);
    sys->setBodyMotion(0, press(*sys, 0.1 - (top + 0.02 - 0.004)));
    sys->run(800);
    REQUIRE(sys->body(0).force_N.norm() > 0.0);
    sys->body(0).resetAccumulatedImpulse();
    const DemSystem::State start = sys->saveState();
    const std::uint64_t builds0 = sys->neighbourBuilds();
    const std::uint64_t steps0 = sys->stepCount();
    const double time0 = sys->time();
    sys->setBodyMotion(0, press(*sys, 0.003));
    sys->run(800);
    const Outcome first = outcome(*sys);
    REQUIRE(first.builds - builds0 > 6);           // rebuilds and re-sorts within the window
    REQUIRE(first.wheel.impulse_N_s.norm() > 0.0); // the wheel ploughs on
    REQUIRE(first.wall_contacts > 0);
    REQUIRE(first.contacts > 0);

    // Not vacuous: the same steps from where the first try ended differ...
    sys->setBodyMotion(0, press(*sys, 0.003));
    sys->run(800);
    CHECK_FALSE(identical(sys->particles(), first.particles));

    // ... and so do the same 800 steps from the snapshot with another motion (a second try).
    sys->restoreState(start);
    CHECK(sys->stepCount() == steps0);
    CHECK(sys->time() == time0);
    CHECK(sys->neighbourBuilds() == builds0);
    sys->setBodyMotion(0, press(*sys, 0.006));
    sys->run(800);
    CHECK_FALSE(identical(sys->particles(), first.particles));

    // ... and so do they with the first motion when the rolling histories are lost (setRolling
    // with the same laws clears them): the comparison sees the contact state, not only the
    // particles'.
    sys->restoreState(start);
    sys->setRolling(sys->laws());
    sys->setBodyMotion(0, press(*sys, 0.003));
    sys->run(800);
    CHECK_FALSE(identical(sys->particles(), first.particles));

    // Back to the snapshot, the first motion again: bit for bit.
    sys->restoreState(start);
    sys->setBodyMotion(0, press(*sys, 0.003));
    sys->run(800);
    const Outcome again = outcome(*sys);
    CHECK(again.time_s == first.time_s);
    CHECK(again.steps == first.steps);
    CHECK(again.builds == first.builds);
    CHECK(again.contacts == first.contacts);
    CHECK(again.wall_contacts == first.wall_contacts);
    CHECK(identical(again.particles, first.particles));
    CHECK(again.wheel.force_N == first.wheel.force_N);
    CHECK(again.wheel.torque_N_m == first.wheel.torque_N_m);
    CHECK(again.wheel.impulse_N_s == first.wheel.impulse_N_s);
    CHECK(again.wheel.angular_impulse_N_m_s == first.wheel.angular_impulse_N_m_s);
    CHECK(again.wheel.accumulated_time_s == first.wheel.accumulated_time_s);
    CHECK(again.plane_force == first.plane_force);
}

TEST_CASE("restoreState refuses a state of another setup", "[dem][snapshot]") {
    DemSystem sys(hertzRestitution(0.5, 0.5), {soil()}, quietSettings(1e-4));
    sys.particles().add(sphere(Vec3(0, 0, 0.01), 0.005, 2500.0));
    const DemSystem::State bare = sys.saveState();
    sys.addBody(MeshBody("plate", makeRectangle(0.1, 0.1, 1, 1), {}));
    CHECK_THROWS_WITH(sys.restoreState(bare), Catch::Contains("0 mesh bodies") &&
                                                  Catch::Contains("the system has 0 and 1"));
}
