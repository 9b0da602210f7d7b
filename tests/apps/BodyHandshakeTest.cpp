// A model's coupled bodies reach the soil as the model describes them: from the scenario's
// reader through the multibody node's participant configuration, the handshake and the soil
// node's mesh builder, the mesh the grains touch is the model's, vertex for vertex, and the
// mass properties arrive unchanged (the copies of a wheel once dropped the centre of mass and
// the rim thickness on the way).
#include "MultibodySide.hpp"
#include "SoilSide.hpp"
#include "grainlink/coupling/Coordinator.hpp"
#include "grainlink/mbs/Mole.hpp"
#include "grainlink/mbs/UrdfModel.hpp"
#include "grainlink/mbs/WheelTest.hpp"

#include <catch2/catch.hpp>

#include <future>

using namespace grainlink;

namespace {

/// The bodies the soil participant receives in the handshake of a one-window run whose
/// multibody participant is `model`, configured as `grainlink mbs-node` configures it.
std::vector<coupling::BodyDescription> bodiesAtTheSoil(const mbs::MultibodyModel &model) {
    coupling::CoordinatorConfig c;
    c.endpoint = "tcp://127.0.0.1:*";
    c.participants = {{"mbs", coupling::Role::Multibody, {}, false},
                      {"soil", coupling::Role::Soil, {}, false}};
    c.macro_step_s = 0.01;
    c.end_time_s = 0.01;
    c.handshake_timeout_s = 10.0;
    coupling::Coordinator coordinator(c);
    auto run = std::async(std::launch::async, [&] { return coordinator.run(); });

    apps::NodeOptions options;
    options.name = "mbs";
    options.endpoint = coordinator.boundEndpoint();
    const auto config = apps::multibodyParticipantConfig(
        options, config::ConfigNode::loadString("{}", "test"), model);
    auto mbs = std::async(std::launch::async, [&config] {
        coupling::Participant p(config);
        p.initialize();
        while (p.waitForCommand() == coupling::Command::Advance) {
            coupling::WindowOutputs out;
            out.states = config.initial_states; // standing still
            p.writeOutputs(out);
            p.advance();
        }
        p.finalize();
    });

    coupling::ParticipantConfig soil_config;
    soil_config.name = "soil";
    soil_config.role = coupling::Role::Soil;
    soil_config.endpoint = coordinator.boundEndpoint();
    for (const auto &body : model.coupledBodies())
        soil_config.consumes.push_back(body.name);
    coupling::Participant soil(soil_config);
    const auto bodies = soil.initialize().bodies;
    while (soil.waitForCommand() == coupling::Command::Advance) {
        coupling::WindowOutputs out;
        out.wrenches.resize(soil_config.consumes.size());
        for (std::size_t b = 0; b < out.wrenches.size(); ++b)
            out.wrenches[b].body = soil_config.consumes[b];
        soil.writeOutputs(out);
        soil.advance();
    }
    soil.finalize();
    run.get();
    mbs.get();
    return bodies;
}

void checkSameMesh(const dem::TriangleMesh &got, const dem::TriangleMesh &expected) {
    REQUIRE(got.vertices_m.size() == expected.vertices_m.size());
    REQUIRE(got.triangles.size() == expected.triangles.size());
    for (std::size_t v = 0; v < got.vertices_m.size(); ++v)
        REQUIRE(got.vertices_m[v] == expected.vertices_m[v]); // bit for bit
    CHECK(got.triangles == expected.triangles);
}

} // namespace

TEST_CASE("A rig's wheel reaches the soil as the mesh its scenario describes, vertex for vertex",
          "[apps][bodies]") {
    // Every wheel key away from its default, as a user writes it.
    const auto root = config::ConfigNode::loadString(R"(
wheel:
  diameter_m: 0.2
  width_m: 0.08
  closed_sides: false
  rim_thickness_m: 0.006
  grouser_count: 10
  grouser_height_m: 0.01
  grouser_thickness_m: 0.004
  grouser_shape: chevron
  chevron_angle_deg: 20
wheel_mass_kg: 1.5
normal_load_kg: 4.0
start_position_m: [0.1, 0.0, 0.3]
)",
                                                     "rig.yaml");
    const mbs::SingleWheelRigSettings settings = mbs::parseSingleWheelRig(root);
    mbs::SingleWheelRig rig(settings);
    const auto bodies = bodiesAtTheSoil(rig);
    REQUIRE(bodies.size() == 1);
    CHECK(bodies[0].mass.mass_kg == 1.5);

    const dem::TriangleMesh touched = apps::meshOf(bodies[0]);
    // What the user wrote, built without the coupling: the soil's mesh is this one exactly.
    body::WheelShape written;
    written.diameter_m = 0.2;
    written.width_m = 0.08;
    written.closed_sides = false;
    written.rim_thickness_m = 0.006;
    written.grouser_count = 10;
    written.grouser_height_m = 0.01;
    written.grouser_thickness_m = 0.004;
    written.grouser_shape = body::GrouserShape::Chevron;
    written.chevron_angle_deg = 20.0;
    checkSameMesh(touched, dem::makeWheel(written));
    // And it has what the keys ask for: an inner rim surface at r - thickness (8 triangles per
    // facet for the tube, 72 facets) and two 4-box arms of 12 triangles per chevron grouser.
    CHECK(touched.triangleCount() == 8 * 72 + 10 * 2 * 4 * 12);
    bool inner = false;
    for (const auto &v : touched.vertices_m)
        inner = inner || std::abs(std::hypot(v.x(), v.z()) - 0.094) < 1e-15;
    CHECK(inner);
    // The mirror model's half wheel too.
    dem::WheelMeshOptions half;
    half.half = true;
    checkSameMesh(apps::meshOf(bodies[0], true), dem::makeWheel(written, half));
}

TEST_CASE("The mole's hull and a URDF link reach the soil with their centre of mass",
          "[apps][bodies]") {
    SECTION("the mole: its hull mesh and the centre of mass half way up the hull") {
        const auto settings = mbs::parseMole(
            config::ConfigNode::loadString("start_tip_position_m: [0, 0, 0.5]", "mole.yaml"));
        mbs::Mole mole(settings);
        const auto bodies = bodiesAtTheSoil(mole);
        REQUIRE(bodies.size() == 1);
        CHECK(bodies[0].name == "mole");
        CHECK(bodies[0].mass.mass_kg == 0.40);
        // docs/physics.md §10: the hull's mass centre at half its 0.40 m length.
        CHECK(bodies[0].mass.center_of_mass_m == coupling::Vec3(0.0, 0.0, 0.20));
        const mbs::MeshShape hull = mbs::moleHullMesh(settings);
        dem::TriangleMesh expected;
        expected.vertices_m = hull.vertices_m;
        expected.triangles = hull.triangles;
        checkSameMesh(apps::meshOf(bodies[0]), expected);
    }
    SECTION("a URDF link: its inertial origin and products of inertia") {
        mbs::UrdfModel model(mbs::parseUrdfModel(GRAINLINK_APPS_TEST_DATA "/offset_link.yaml"));
        const auto bodies = bodiesAtTheSoil(model);
        REQUIRE(bodies.size() == 1);
        const auto &mass = bodies[0].mass;
        // The numbers of tests/apps/data/offset_link.urdf.
        CHECK(mass.mass_kg == 3.0);
        CHECK(mass.center_of_mass_m == coupling::Vec3(0.01, -0.02, 0.03));
        CHECK(mass.inertia_diagonal_kg_m2 == coupling::Vec3(0.02, 0.03, 0.04));
        CHECK(mass.inertia_off_diagonal_kg_m2 == coupling::Vec3(0.001, -0.002, 0.0005));
        body::WheelShape written;
        written.diameter_m = 0.2;
        written.width_m = 0.06;
        written.grouser_count = 8;
        written.grouser_height_m = 0.01;
        written.grouser_thickness_m = 0.004;
        checkSameMesh(apps::meshOf(bodies[0]), dem::makeWheel(written));
    }
}
