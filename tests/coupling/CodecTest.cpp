// The checks every received message goes through, without sockets: the envelope (codec), its
// header, the states, wrenches and meshes inside it, and a WindowDone against its window. Each
// expected message is the full line the coordinator stops the run with, naming the participant
// and the window where the check knows them.
#include "Codec.hpp"
#include "OutputCheck.hpp"
#include "RunState.hpp"
#include "WindowReplies.hpp"

#include <catch2/catch.hpp>

#include <limits>

#include <array>
#include <cmath>

using namespace grainlink::coupling;
namespace pb = grainlink::v1;

namespace {

/// The ProtocolError `f` throws (fails the test when it throws none).
template <typename F> codec::ProtocolError protocolError(F f) {
    try {
        f();
    } catch (const codec::ProtocolError &e) {
        return e;
    }
    FAIL("no ProtocolError");
    throw;
}

pb::BodyState wireState(const std::string &body) {
    pb::BodyState s;
    s.set_body(body);
    s.mutable_position_m()->set_z(0.1);
    s.mutable_orientation()->set_w(1.0);
    s.set_frame(pb::FRAME_WORLD);
    return s;
}

pb::BodyWrench wireWrench(const std::string &body) {
    pb::BodyWrench w;
    w.set_body(body);
    w.mutable_force_n()->set_z(9.81);
    w.mutable_torque_n_m();
    w.set_frame(pb::FRAME_WORLD);
    return w;
}

} // namespace

TEST_CASE("Codec: an envelope must parse, speak our major version and carry a body",
          "[coupling][codec]") {
    pb::Envelope e;
    e.set_version(kProtocolMajor);
    e.set_sender("soil");
    e.set_sequence(2);
    SECTION("missing body") {
        const std::string bytes = e.SerializeAsString();
        const auto error =
            protocolError([&] { codec::decode(bytes.data(), bytes.size(), "participant 'soil'"); });
        CHECK(error.code == pb::Error::CODE_MALFORMED);
        CHECK(std::string(error.what()) ==
              "message from participant 'soil' has no body (an unset body is an error)");
        CHECK(error.sender == "soil");
    }
    SECTION("another major version") {
        e.set_version(kProtocolMajor + 1);
        e.mutable_heartbeat();
        const std::string bytes = e.SerializeAsString();
        const auto error =
            protocolError([&] { codec::decode(bytes.data(), bytes.size(), "participant 'soil'"); });
        CHECK(error.code == pb::Error::CODE_VERSION_MISMATCH);
        CHECK(error.version == kProtocolMajor + 1);
        CHECK(error.sender == "soil");
        CHECK(std::string(error.what()) == "participant 'soil' speaks protocol major version 2, "
                                           "this side speaks 1");
    }
    SECTION("bytes that are no Envelope") {
        const std::string bytes = "\xff\xff\xff garbage";
        const auto error =
            protocolError([&] { codec::decode(bytes.data(), bytes.size(), "participant 'soil'"); });
        CHECK(error.code == pb::Error::CODE_MALFORMED);
        CHECK(std::string(error.what()) == "malformed message from participant 'soil' (11 bytes "
                                           "that are not a grainlink.v1.Envelope)");
    }
}

TEST_CASE("Codec: a message that would unpack into too many parts is refused unparsed",
          "[coupling][codec]") {
    // Two bytes on the wire make an empty body description of ~70 bytes in memory: the part
    // count, not the size, bounds what parsing takes. Here: the sender and the Hello's
    // participant (strings), the Hello and its ten bodies (messages): 13 parts.
    pb::Envelope e;
    e.set_version(kProtocolMajor);
    e.set_sender("soil");
    e.set_sequence(1);
    e.mutable_hello()->set_participant("soil");
    for (int i = 0; i < 10; ++i)
        e.mutable_hello()->add_provides();
    const std::string bytes = e.SerializeAsString();
    CHECK(
        codec::decode(bytes.data(), bytes.size(), "a new connection", 13).hello().provides_size() ==
        10);
    const auto error =
        protocolError([&] { codec::decode(bytes.data(), bytes.size(), "a new connection", 12); });
    CHECK(error.code == pb::Error::CODE_MALFORMED);
    CHECK(std::string(error.what()) ==
          "message from a new connection (" + std::to_string(bytes.size()) +
              " bytes) would unpack into more than 12 sub-messages and strings "
              "(limits.max_message_bytes / 16)");
    // Packed numbers are no parts: a mesh's indices cost their bytes, not objects.
    pb::Envelope mesh = e;
    mesh.mutable_hello()->clear_provides();
    auto *indices = mesh.mutable_hello()->add_provides()->mutable_mesh();
    for (std::uint32_t i = 0; i < 3000; ++i)
        indices->add_triangle_indices(i);
    const std::string mesh_bytes = mesh.SerializeAsString();
    CHECK_NOTHROW(codec::decode(mesh_bytes.data(), mesh_bytes.size(), "a new connection", 5));
}

TEST_CASE("Codec: the header names its participant and counts 1, 2, 3, ...", "[coupling][codec]") {
    pb::Envelope e;
    e.set_sender("soil");
    e.set_sequence(5);
    CHECK_NOTHROW(codec::checkHeader(e, "soil", 4));
    SECTION("spoofed sender") {
        e.set_sender("mbs");
        CHECK_THROWS_WITH(codec::checkHeader(e, "soil", 4), "sent a message signed 'mbs'");
    }
    SECTION("a repeat and a gap") {
        CHECK_THROWS_WITH(codec::checkHeader(e, "soil", 5),
                          "sent message 5 again (duplicate; last was 5)");
        CHECK_THROWS_WITH(codec::checkHeader(e, "soil", 3),
                          "sent message 5 after 3 (out of order)");
    }
}

TEST_CASE("Codec: states need a unit quaternion in the world frame", "[coupling][codec]") {
    pb::BodyState s = wireState("wheel");
    CHECK(codec::fromWire(s).position_m.z() == 0.1);
    SECTION("non-unit quaternion") {
        s.mutable_orientation()->set_x(std::sqrt(3.0)); // |q| = 2
        const auto error = protocolError([&] { codec::fromWire(s); });
        CHECK(std::string(error.what()) ==
              "orientation of body 'wheel' is not a unit quaternion (|q| = 2.000000)");
    }
    SECTION("a quaternion just inside the tolerance of 1e-6") {
        s.mutable_orientation()->set_w(1.0 + 0.9e-6);
        CHECK_NOTHROW(codec::fromWire(s));
        s.mutable_orientation()->set_w(1.0 + 1.1e-6);
        CHECK_THROWS_AS(codec::fromWire(s), codec::ProtocolError);
    }
    SECTION("no orientation") {
        s.clear_orientation();
        CHECK_THROWS_WITH(codec::fromWire(s), "state of body 'wheel' has no orientation");
    }
    SECTION("wrong frame") {
        s.set_frame(pb::FRAME_UNSPECIFIED);
        CHECK_THROWS_WITH(codec::fromWire(s), "state of body 'wheel' is not in the world frame");
        pb::BodyWrench w = wireWrench("wheel");
        w.set_frame(pb::FRAME_UNSPECIFIED);
        CHECK_THROWS_WITH(codec::fromWire(w), "wrench on body 'wheel' is not in the world frame");
    }
}

TEST_CASE("Codec: a mesh's triangles index its vertices, three at a time", "[coupling][codec]") {
    pb::BodyDescription body;
    body.set_name("plate");
    auto *mesh = body.mutable_mesh();
    for (int v = 0; v < 3; ++v)
        mesh->add_vertices_m()->set_x(v);
    for (std::uint32_t i : {0u, 1u, 2u})
        mesh->add_triangle_indices(i);
    const auto ok = codec::fromWire(body);
    const auto &triangles = std::get<MeshShape>(ok.geometry).triangles;
    REQUIRE(triangles.size() == 1);
    CHECK(triangles[0] == std::array<int, 3>{0, 1, 2});
    SECTION("an index beyond the vertices") {
        mesh->set_triangle_indices(2, 3);
        CHECK_THROWS_WITH(codec::fromWire(body),
                          "body 'plate': triangle index 3 beyond 3 vertices");
    }
    SECTION("a count that is no multiple of three") {
        mesh->add_triangle_indices(0);
        CHECK_THROWS_WITH(codec::fromWire(body),
                          "body 'plate': triangle index count 4 is not a multiple of 3");
    }
}

TEST_CASE("Codec: a body's mass, mesh and wheel numbers must be finite and in range",
          "[coupling][codec]") {
    // Every one of these reached the soil's mesh builder or integrator before: a NaN vertex, a
    // negative mass, four billion grousers (a mesh that exhausts memory).
    const double nan = std::numeric_limits<double>::quiet_NaN();
    pb::BodyDescription plate;
    plate.set_name("plate");
    plate.mutable_mass()->set_mass_kg(1.0);
    for (int v = 0; v < 3; ++v)
        plate.mutable_mesh()->add_vertices_m()->set_x(v);
    for (std::uint32_t i : {0u, 1u, 2u})
        plate.mutable_mesh()->add_triangle_indices(i);
    CHECK_NOTHROW(codec::fromWire(plate));
    SECTION("a non-finite vertex") {
        plate.mutable_mesh()->mutable_vertices_m(1)->set_z(nan);
        CHECK_THROWS_WITH(codec::fromWire(plate), "body 'plate': non-finite mesh vertex");
    }
    SECTION("a negative or non-finite mass, a non-finite inertia") {
        plate.mutable_mass()->set_mass_kg(-1.0);
        CHECK_THROWS_WITH(codec::fromWire(plate),
                          "body 'plate': mass_kg must be finite and not negative");
        plate.mutable_mass()->set_mass_kg(nan);
        CHECK_THROWS_WITH(codec::fromWire(plate),
                          "body 'plate': mass_kg must be finite and not negative");
        plate.mutable_mass()->set_mass_kg(1.0);
        plate.mutable_mass()->mutable_inertia_diagonal_kg_m2()->set_y(nan);
        CHECK_THROWS_WITH(codec::fromWire(plate),
                          "body 'plate': non-finite centre of mass or inertia");
    }
    pb::BodyDescription wheel;
    wheel.set_name("wheel");
    auto *w = wheel.mutable_wheel();
    w->set_diameter_m(0.25);
    w->set_width_m(0.1);
    w->set_grouser_count(12);
    w->set_grouser_height_m(0.01);
    w->set_grouser_thickness_m(0.002);
    CHECK_NOTHROW(codec::fromWire(wheel));
    SECTION("wheel sizes") {
        w->set_grouser_count(4000000000u);
        CHECK_THROWS_WITH(codec::fromWire(wheel),
                          "body 'wheel': wheel grouser_count 4000000000 above 1000");
        w->set_grouser_count(12);
        w->set_width_m(0.0);
        CHECK_THROWS_WITH(codec::fromWire(wheel), Catch::Contains("must be finite and positive"));
        w->set_width_m(0.1);
        w->set_rim_thickness_m(0.2);
        CHECK_THROWS_WITH(codec::fromWire(wheel), Catch::Contains("rim_thickness_m"));
        w->set_rim_thickness_m(0.0);
        w->set_grouser_height_m(-0.01);
        CHECK_THROWS_WITH(codec::fromWire(wheel), Catch::Contains("grouser sizes"));
    }
}

TEST_CASE("Codec: a Hello needs its role and a Welcome its scheme", "[coupling][codec]") {
    for (const auto scheme :
         {SchemeKind::ExplicitSerial, SchemeKind::ExplicitParallel, SchemeKind::Implicit})
        CHECK(codec::fromWire(codec::toWire(scheme)) == scheme);
    CHECK(codec::fromWire(pb::ROLE_SOIL, "participant 'soil'") == Role::Soil);
    CHECK(codec::fromWire(pb::ROLE_MULTIBODY, "participant 'mbs'") == Role::Multibody);
    const auto no_scheme = protocolError([] { codec::fromWire(pb::SCHEME_UNSPECIFIED); });
    CHECK(no_scheme.code == pb::Error::CODE_MALFORMED);
    CHECK(std::string(no_scheme.what()) == "Welcome names no coupling scheme");
    const auto no_role =
        protocolError([] { codec::fromWire(pb::ROLE_UNSPECIFIED, "participant 'soil'"); });
    CHECK(no_role.code == pb::Error::CODE_MALFORMED);
    CHECK(std::string(no_role.what()) ==
          "participant 'soil': Hello has no role (expected multibody or soil)");
}

TEST_CASE("Codec: text from a peer is printable and short in messages", "[coupling][codec]") {
    CHECK(codec::printable("mass1") == "mass1");
    CHECK(codec::printable("a\nb\\c") == "a\\x0ab\\x5cc"); // no new log line, no fake escapes
    CHECK(codec::printable(std::string("\0\x7f\xc3", 3)) == "\\x00\\x7f\\xc3");
    const std::string long_name(1'000'000, 'x');
    CHECK(codec::printable(long_name) == std::string(64, 'x') + "... (1000000 bytes)");
    CHECK(codec::printable(long_name, 10) == std::string(10, 'x') + "... (1000000 bytes)");
}

TEST_CASE("Output check: finite values, each expected body exactly once, in any order",
          "[coupling][codec]") {
    const std::vector<std::string> expected{"a", "b"};
    const auto state = [](const char *body) {
        BodyState s;
        s.body = body;
        return s;
    };
    CHECK_FALSE(checkOutputs(std::vector<BodyState>{state("a"), state("b")}, expected));
    CHECK_FALSE(checkOutputs(std::vector<BodyState>{state("b"), state("a")}, expected));
    const auto twice = checkOutputs(std::vector<BodyState>{state("a"), state("a")}, expected);
    REQUIRE(twice);
    CHECK(twice->kind == OutputProblem::Kind::WrongBodies);
    CHECK(twice->text == "states for { a a } but must give exactly one for each of { a b }");
    CHECK(checkOutputs(std::vector<BodyState>{state("a")}, expected)->text ==
          "states for { a } but must give exactly one for each of { a b }");
    auto bad = state("b");
    bad.orientation.x() = NAN;
    const auto nan = checkOutputs(std::vector<BodyState>{state("a"), bad}, expected);
    REQUIRE(nan);
    CHECK(nan->kind == OutputProblem::Kind::NonFinite);
    CHECK(nan->text == "non-finite state of body 'b'");
    Wrench w;
    w.body = "a\nforged";
    w.torque_N_m.y() = INFINITY;
    CHECK(checkOutputs(std::vector<Wrench>{w}, {"a"})->text ==
          "non-finite wrench on body 'a\\x0aforged'");
}

TEST_CASE("WindowDone: checked against its window, in the words the run stops with",
          "[coupling][codec]") {
    // Window 3 of 10 ms windows (tick 1 ns): t = 0.03 s, ends at tick 40'000'000, pass 1.
    RunState run(1e-9);
    run.enter(RunState::State::Handshake);
    run.enter(RunState::State::Running);
    run.window = 3;
    run.tick = 30'000'000;
    WindowReplies replies({{"participant 'mbs'", Role::Multibody, {"wheel"}},
                           {"participant 'soil'", Role::Soil, {"wheel"}}});
    replies.begin(3, 40'000'000, 1);

    pb::Envelope mbs, soil;
    mbs.set_window(3);
    soil.set_window(3);
    auto *m = mbs.mutable_window_done();
    m->set_end_tick(40'000'000);
    m->set_iteration(1);
    *m->mutable_states()->add_states() = wireState("wheel");
    m->add_work()->set_work_j(0.25);
    m->add_work()->set_work_j(0.5);
    auto *s = soil.mutable_window_done();
    s->set_end_tick(40'000'000);
    s->set_iteration(1);
    *s->mutable_wrenches()->add_wrenches() = wireWrench("wheel");
    s->set_suggested_macro_step_ticks(2'500'000);
    s->set_run_complete(true);

    const auto line = [&](std::size_t p, const pb::Envelope &e) -> std::string {
        try {
            replies.read(p, e);
        } catch (const PeerError &error) {
            return run.failure(error.who, error.why);
        }
        return "(accepted)";
    };
    const std::string soil_at = "participant 'soil' failed in window 3 (t = 0.03 s): ";
    const std::string mbs_at = "participant 'mbs' failed in window 3 (t = 0.03 s): ";

    SECTION("valid replies are kept with their work, hint and completion") {
        const auto from_mbs = replies.read(0, mbs);
        const auto from_soil = replies.read(1, soil);
        CHECK(from_mbs.work_J == 0.75);
        CHECK_FALSE(from_mbs.run_complete);
        CHECK(from_soil.suggested_step_ticks == 2'500'000);
        CHECK(from_soil.run_complete);
        REQUIRE(replies.states().size() == 1);
        CHECK(replies.states()[0].position_m.z() == 0.1);
        REQUIRE(replies.wrenches().size() == 1);
        CHECK(replies.wrenches()[0].force_N.z() == 9.81);
        replies.begin(4, 50'000'000, 0); // the next pass forgets them
        CHECK(replies.states().empty());
    }
    SECTION("wrong window") {
        soil.set_window(2);
        CHECK(line(1, soil) == soil_at + "sent window_done for window 2 while the coordinator "
                                         "waited for WindowDone");
        pb::Envelope other;
        other.set_window(3);
        other.mutable_checkpoint_done();
        CHECK(line(1, other) == soil_at + "sent checkpoint_done for window 3 while the "
                                          "coordinator waited for WindowDone");
    }
    SECTION("wrong end tick and wrong pass") {
        s->set_end_tick(40'000'007);
        CHECK(line(1, soil) == soil_at + "reports end tick 40000007 for a window that ends at "
                                         "tick 40000000");
        s->set_end_tick(40'000'000);
        s->set_iteration(0);
        CHECK(line(1, soil) == soil_at + "reports iteration 0, expected 1");
    }
    SECTION("missing body, and a body of someone else") {
        m->mutable_states()->clear_states();
        CHECK(line(0, mbs) ==
              mbs_at + "sent states for { } but must give exactly one for each of { wheel }");
        s->mutable_wrenches()->mutable_wrenches(0)->set_body("rock");
        CHECK(line(1, soil) ==
              soil_at + "sent wrenches for { rock } but must give exactly one for each of "
                        "{ wheel }");
    }
    SECTION("non-finite states and wrenches") {
        m->mutable_states()->mutable_states(0)->mutable_linear_velocity_m_s()->set_x(NAN);
        CHECK(line(0, mbs) == mbs_at + "sent a non-finite state of body 'wheel'");
        s->mutable_wrenches()->mutable_wrenches(0)->mutable_force_n()->set_y(-INFINITY);
        CHECK(line(1, soil) == soil_at + "sent a non-finite wrench on body 'wheel'");
        // The work enters the coupling's energy balance: a NaN would hide every mismatch.
        m->mutable_states()->mutable_states(0)->mutable_linear_velocity_m_s()->set_x(0.0);
        m->mutable_work(1)->set_body("wheel");
        m->mutable_work(1)->set_work_j(NAN);
        CHECK(line(0, mbs) == mbs_at + "sent a non-finite work for body 'wheel'");
    }
    SECTION("a non-unit quaternion and a wrong frame inside the reply") {
        m->mutable_states()->mutable_states(0)->mutable_orientation()->set_w(0.5);
        CHECK(line(0, mbs) == mbs_at + "orientation of body 'wheel' is not a unit quaternion "
                                       "(|q| = 0.500000)");
        s->mutable_wrenches()->mutable_wrenches(0)->set_frame(pb::FRAME_UNSPECIFIED);
        CHECK(line(1, soil) == soil_at + "wrench on body 'wheel' is not in the world frame");
    }
}
