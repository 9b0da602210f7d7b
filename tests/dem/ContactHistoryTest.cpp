// Contact histories (tangential spring, rolling moment, sliding flag, wall and mesh slots) must
// survive neighbour-list rebuilds and spatial re-sorts (docs/physics.md §4).
#include "Fixtures.hpp"

#include <catch2/catch.hpp>

#include <unordered_map>

using namespace grainlink::dem;
using namespace grainlink::dem::testing;

namespace {

const Vec3 kBoxVelocity(0.05, 0.03, 0.0); // m/s

ContactLaw law() {
    ContactLaw l = hertzRestitution(0.3, 0.5);
    l.rolling = RollingEpsd{0.05};
    return l;
}

DemSettings settingsWith(double skin_m, int resort_every_builds) {
    DemSettings s;
    s.time_step_s = 2e-5;
    s.skin_m = skin_m;
    s.resort_every_builds = resort_every_builds;
    return s;
}

const TriangleMesh& box() {
    static const TriangleMesh mesh = makeOpenBox(0.04, 0.06, 4);
    return mesh;
}

/// 160 grains settled under gravity in an open mesh box, friction and rolling resistance: a
/// loaded packing whose contacts all carry tangential and rolling history.
const DemSystem& settledPacking() {
    static const DemSystem packing = [] {
        DemSystem sys(law(), {kMaterial}, settingsWith(0.0, 25));
        sys.addBody(MeshBody("box", box(), {}));
        addLattice(sys, Vec3(-0.02, -0.02, 0.0), Vec3(0.02, 0.02, 0.08), 0.008, 0.0025, 0.0035,
                   kMaterial.density_kg_m3, 0.1, 160);
        sys.run(30000);
        return sys;
    }();
    return packing;
}

/// The settled packing in a box that now moves at constant velocity, grains given the same
/// velocity: by Galilean invariance the packing stays loaded and at rest relative to the box,
/// while every grain travels through the neighbour grid (rebuilds, re-sorts). A quasi-static,
/// damped state: round-off differences do not grow as they would in a flowing packing.
std::unique_ptr<DemSystem> carried(const DemSettings& settings, bool keep_history = true) {
    const DemSystem& packing = settledPacking();
    auto sys = std::make_unique<DemSystem>(law(), std::vector<Material>{kMaterial}, settings);
    const double t0 = packing.time();
    RigidBodyState start;
    start.linear_velocity_m_s = kBoxVelocity;
    sys->addBody(MeshBody("box", box(), {}), constantVelocity(start, t0));
    copyState(packing, *sys);
    if (!keep_history) {
        DemSystem::Internals bare = packing.saveInternals();
        bare.reference_position = packing.particles().position;
        bare.contacts.clear();
        for (auto& h : bare.plane_history)
            h = ContactHistory{};
        for (auto& slot : bare.mesh_slots)
            slot = MeshContactSlot{};
        sys->restoreInternals(bare);
    }
    for (Vec3& v : sys->particles().velocity)
        v += kBoxVelocity;
    return sys;
}

/// Largest force difference between runs, matched by particle id.
double maxForceDifference(const DemSystem& a, const DemSystem& b) {
    std::unordered_map<ParticleId, std::size_t> where;
    for (std::size_t i = 0; i < b.particles().size(); ++i)
        where[b.particles().id[i]] = i;
    double worst = 0.0;
    for (std::size_t i = 0; i < a.particles().size(); ++i) {
        const std::size_t j = where.at(a.particles().id[i]);
        worst = std::max(worst, (a.particles().force[i] - b.particles().force[j]).norm());
    }
    return worst;
}

} // namespace

TEST_CASE("Contact history survives neighbour-list rebuilds and spatial re-sorts",
          "[dem][history][slow]") {
    const DemSystem& packing = settledPacking();
    const double weight = sphereMass(0.0025, kMaterial.density_kg_m3) * 9.81; // smallest grain
    // The packing is loaded and its contacts carry history, or the test proves nothing.
    const DemSystem::Internals state = packing.saveInternals();
    REQUIRE(packing.contactCount() > 200);
    REQUIRE(state.contacts.size() > 200);
    REQUIRE(kineticEnergy(packing) < 1e-7); // settled (measured 5e-9 J)

    const int steps = 3000; // the box travels 0.17 mm = 70 x the small skin
    auto reference = carried(settingsWith(4e-3, 0));        // skin > travel: few rebuilds
    auto rebuilding = carried(settingsWith(2e-6, 0));       // rebuilds (nearly) every step
    auto resorting = carried(settingsWith(2e-6, 1));        // and re-sorts at each rebuild
    auto forgetful = carried(settingsWith(4e-3, 0), false); // control: histories dropped
    for (DemSystem* sys : {reference.get(), rebuilding.get(), resorting.get(), forgetful.get()})
        sys->run(steps);
    REQUIRE(reference->neighbourBuilds() - state.neighbour_builds < 10);
    REQUIRE(rebuilding->neighbourBuilds() - state.neighbour_builds > steps / 2);
    REQUIRE(resorting->neighbourBuilds() - state.neighbour_builds > steps / 2);
    REQUIRE(resorting->particles().id != reference->particles().id); // re-sorts did reorder

    SECTION("rebuilds alone change nothing, bit for bit") {
        // No re-sort: the storage order and the order of force summation (sorted neighbour
        // indices, nearest mesh touch first) do not depend on the skin, so with the histories
        // carried exactly the runs are identical.
        const ParticleStore &a = rebuilding->particles(), &b = reference->particles();
        CHECK(a.position == b.position);
        CHECK(a.velocity == b.velocity);
        CHECK(a.angular_velocity == b.angular_velocity);
        CHECK(a.force == b.force);
    }
    SECTION("re-sorts change only the summation order: forces equal to 1e-10 of a weight") {
        // Re-sorting permutes the storage, hence the order of the force sums: round-off only
        // (1e-16 relative per step), little amplified in this damped, quasi-static packing
        // (measured 4e-12 of a weight; 1e-9 if the packing is still rattling after 15000 steps).
        // Dropping the histories changes forces by 4e-2 of a weight (control).
        const double resorted = maxForceDifference(*resorting, *reference);
        const double forgotten = maxForceDifference(*forgetful, *reference);
        INFO("max |dF| / weight: re-sorted " << resorted / weight << ", histories dropped "
                                             << forgotten / weight);
        CHECK(resorted < 1e-10 * weight);
        CHECK(forgotten > 1e-2 * weight);
    }
}
