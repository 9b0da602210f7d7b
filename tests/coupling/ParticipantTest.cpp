// The participant lifecycle is enforced with messages that say what to do, and outputs are
// checked before they leave; CURVE keys admit exactly the participants that hold them.
#include "CouplingFixtures.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <future>
#include <unistd.h>

using namespace grainlink::coupling;
using grainlink::examples::runTwoMassSide;
using grainlink::examples::twoMassConfig;

using grainlink::testing::scratch;

namespace {

CoordinatorConfig smallRun(double end_s = 0.05) {
    return grainlink::testing::twoMassRun(SchemeKind::ExplicitSerial, "tcp://127.0.0.1:*", 0.01,
                                          end_s);
}

} // namespace

TEST_CASE("Calls out of lifecycle order say what to do", "[coupling][participant]") {
    Participant p(twoMassConfig(Role::Soil, "soil", "tcp://127.0.0.1:1"));
    CHECK(p.state() == Participant::State::Created);
    CHECK_THROWS_WITH(p.waitForCommand(), "participant 'soil': waitForCommand() called in state "
                                          "'created'; call initialize() first");
    CHECK_THROWS_WITH(p.advance(), "participant 'soil': advance() called in state 'created'; "
                                   "call initialize() first");
    CHECK_THROWS_AS(p.inputs(), LifecycleError);
    CHECK_THROWS_WITH(p.finalize(), Catch::Contains("finalize once waitForCommand() returned "
                                                    "Command::Finish"));
}

TEST_CASE("Inside a window: outputs before advance, only for the participant's bodies",
          "[coupling][participant]") {
    Coordinator coordinator(smallRun());
    auto run = std::async(std::launch::async, [&] { return coordinator.run(); });
    auto mbs = grainlink::testing::startSide(Role::Multibody, coordinator.boundEndpoint());
    Participant soil(twoMassConfig(Role::Soil, "soil", coordinator.boundEndpoint()));
    const auto &info = soil.initialize();
    CHECK(info.bodies.size() == 1);
    CHECK(info.bodies[0].name == "mass1");
    CHECK(info.end_tick == 50'000'000);
    REQUIRE(soil.waitForCommand() == Command::Advance);
    CHECK(soil.inputs().end_states.at(0).body == "mass1");
    CHECK_THROWS_WITH(soil.waitForCommand(),
                      Catch::EndsWith("write this window's outputs with writeOutputs(), then "
                                      "call advance()"));
    CHECK_THROWS_WITH(soil.advance(), Catch::Contains("write this window's outputs"));
    WindowOutputs wrong;
    wrong.wrenches = {Wrench{"wheel", Vec3::Zero(), Vec3::Zero(), {}}};
    CHECK_THROWS_WITH(soil.writeOutputs(wrong),
                      "participant 'soil': writeOutputs() got wrenches for { wheel } but must "
                      "give exactly one for each of { mass1 }");
    WindowOutputs nan;
    nan.wrenches = {Wrench{"mass1", Vec3(NAN, 0, 0), Vec3::Zero(), {}}};
    CHECK_THROWS_WITH(soil.writeOutputs(nan), "participant 'soil': non-finite wrench on body "
                                              "'mass1' in window 0");
    // Then behave: zero force for every window until the end.
    for (Command c = Command::Advance; c != Command::Finish; c = soil.waitForCommand()) {
        WindowOutputs out;
        out.wrenches = {Wrench{"mass1", Vec3::Zero(), Vec3::Zero(), {}}};
        soil.writeOutputs(out);
        CHECK_THROWS_AS(soil.writeOutputs(out), LifecycleError);
        soil.advance();
    }
    soil.finalize();
    CHECK(soil.state() == Participant::State::Finalized);
    CHECK(run.get().windows == 5);
    mbs.get();
}

TEST_CASE("CURVE: keyed participants run, a wrong key is refused and named",
          "[coupling][security]") {
    if (!curveAvailable()) {
        WARN("libzmq without CURVE: skipped");
        return;
    }
    const std::string keys = scratch("keys");
    writeKeyPair(keys, "coordinator", generateKeyPair());
    writeKeyPair(keys, "mbs", generateKeyPair());
    writeKeyPair(keys, "soil", generateKeyPair());
    CHECK_THROWS_WITH(writeKeyPair(keys, "mbs", generateKeyPair()),
                      Catch::EndsWith("mbs.key exists; remove it first to make a new key"));
    auto config = smallRun();
    config.curve = loadServerKeys(keys);
    CHECK(config.curve->allowed_participants.size() == 2);

    auto side = [](Role role, const char *name, const std::string &endpoint,
                   const std::string &key_directory) {
        return std::async(std::launch::async, [=] {
            auto c = twoMassConfig(role, name, endpoint);
            c.curve = loadClientKeys(key_directory, name);
            c.handshake_timeout_s = 4.0;
            Participant p(c);
            return runTwoMassSide(p);
        });
    };
    SECTION("both hold the right keys") {
        Coordinator coordinator(config);
        auto mbs = side(Role::Multibody, "mbs", coordinator.boundEndpoint(), keys);
        auto soil = side(Role::Soil, "soil", coordinator.boundEndpoint(), keys);
        CHECK(coordinator.run().windows == 5);
        mbs.get();
        soil.get();
    }
    SECTION("the soil side holds a key the coordinator does not know") {
        const std::string other = scratch("other-keys");
        std::filesystem::copy(keys + "/coordinator.pub", other + "/coordinator.pub");
        writeKeyPair(other, "soil", generateKeyPair());
        config.handshake_timeout_s = 2.0;
        Coordinator coordinator(config);
        auto mbs = side(Role::Multibody, "mbs", coordinator.boundEndpoint(), keys);
        auto soil = side(Role::Soil, "soil", coordinator.boundEndpoint(), other);
        std::string failure;
        try {
            coordinator.run();
        } catch (const CouplingError &e) {
            failure = e.what();
        }
        CHECK_THAT(failure, Catch::Matches("participant 'soil' failed during the handshake: did "
                                           "not join within handshake_timeout_s = 2 s \\([0-9]+ "
                                           "connection\\(s\\) refused by CURVE authentication.*"));
        CHECK_THROWS_AS(soil.get(), CouplingError);
        CHECK_THROWS_AS(mbs.get(), CouplingError);
    }
}

TEST_CASE("Only loopback without keys, unless --insecure", "[coupling][security]") {
    auto config = smallRun();
    config.endpoint = "tcp://0.0.0.0:*";
    CHECK_THROWS_WITH(Coordinator(config),
                      "endpoint tcp://0.0.0.0:* is reachable from other machines: give CURVE "
                      "keys (`grainlink keygen`, key `keys_directory`) or pass --insecure");
    config.insecure = true;
    CHECK_NOTHROW(Coordinator(config));
    CHECK(isLocalEndpoint("ipc:///tmp/x"));
    CHECK(isLocalEndpoint("tcp://127.0.0.1:5555"));
    CHECK_FALSE(isLocalEndpoint("tcp://192.168.1.4:5555"));
}

namespace {

/// Every field of a body description, compared exactly.
void checkSameBody(const BodyDescription &got, const BodyDescription &sent) {
    INFO("body " << sent.name);
    CHECK(got.name == sent.name);
    CHECK(got.mass.mass_kg == sent.mass.mass_kg);
    CHECK(got.mass.center_of_mass_m == sent.mass.center_of_mass_m);
    CHECK(got.mass.inertia_diagonal_kg_m2 == sent.mass.inertia_diagonal_kg_m2);
    CHECK(got.mass.inertia_off_diagonal_kg_m2 == sent.mass.inertia_off_diagonal_kg_m2);
    REQUIRE(got.geometry.index() == sent.geometry.index());
    if (const auto *w = std::get_if<WheelShape>(&sent.geometry)) {
        const auto &g = std::get<WheelShape>(got.geometry);
        CHECK(g.diameter_m == w->diameter_m);
        CHECK(g.width_m == w->width_m);
        CHECK(g.rim_thickness_m == w->rim_thickness_m);
        CHECK(g.grouser_count == w->grouser_count);
        CHECK(g.grouser_height_m == w->grouser_height_m);
        CHECK(g.grouser_thickness_m == w->grouser_thickness_m);
        CHECK(g.grouser_shape == w->grouser_shape);
        CHECK(g.chevron_angle_deg == w->chevron_angle_deg);
        CHECK(g.closed_sides == w->closed_sides);
    }
    if (const auto *m = std::get_if<MeshShape>(&sent.geometry)) {
        const auto &g = std::get<MeshShape>(got.geometry);
        CHECK(g.vertices_m == m->vertices_m);
        CHECK(g.triangles == m->triangles);
    }
}

} // namespace

TEST_CASE("The handshake carries each body's description unchanged", "[coupling][participant]") {
    // No field at its default: a lost one (the centre of mass was, once) shows as a difference.
    BodyDescription wheel;
    wheel.name = "wheel";
    wheel.mass = {2.5, Vec3(0.001, -0.002, 0.003), Vec3(0.02, 0.04, 0.021),
                  Vec3(1e-4, -2e-4, 3e-4)};
    WheelShape shape;
    shape.diameter_m = 0.3;
    shape.width_m = 0.12;
    shape.rim_thickness_m = 0.004;
    shape.grouser_count = 14;
    shape.grouser_height_m = 0.012;
    shape.grouser_thickness_m = 0.003;
    shape.grouser_shape = GrouserShape::Chevron;
    shape.chevron_angle_deg = 25.0;
    shape.closed_sides = false;
    wheel.geometry = shape;
    BodyDescription hull;
    hull.name = "hull";
    hull.mass = {0.4, Vec3(0.0, 0.0, 0.21), Vec3(5e-3, 5e-3, 4e-5), Vec3::Zero()};
    hull.geometry = MeshShape{{Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0, 0.1, 0), Vec3(0, 0, 0.1)},
                              {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}};

    auto config = smallRun(0.01);
    config.participants = {{"mbs", Role::Multibody, {}, false}, {"soil", Role::Soil, {}, false}};
    Coordinator coordinator(config);
    auto run = std::async(std::launch::async, [&] { return coordinator.run(); });
    auto mbs = std::async(std::launch::async, [&, endpoint = coordinator.boundEndpoint()] {
        ParticipantConfig c;
        c.name = "mbs";
        c.endpoint = endpoint;
        c.provides = {wheel, hull};
        c.initial_states = {BodyState{"wheel"}, BodyState{"hull"}};
        Participant p(c);
        p.initialize();
        for (Command command = p.waitForCommand(); command != Command::Finish;
             command = p.waitForCommand()) {
            WindowOutputs out;
            out.states = {BodyState{"wheel"}, BodyState{"hull"}};
            p.writeOutputs(out);
            p.advance();
        }
        p.finalize();
    });
    ParticipantConfig c;
    c.name = "soil";
    c.role = Role::Soil;
    c.endpoint = coordinator.boundEndpoint();
    c.consumes = {"wheel", "hull"};
    Participant soil(c);
    const auto bodies = soil.initialize().bodies;
    for (Command command = soil.waitForCommand(); command != Command::Finish;
         command = soil.waitForCommand()) {
        WindowOutputs out;
        out.wrenches.resize(2);
        out.wrenches[0].body = "wheel";
        out.wrenches[1].body = "hull";
        soil.writeOutputs(out);
        soil.advance();
    }
    soil.finalize();
    run.get();
    mbs.get();
    REQUIRE(bodies.size() == 2);
    checkSameBody(bodies[0], wheel);
    checkSameBody(bodies[1], hull);
}
