// The coordinator's parts that need no sockets: its lifecycle, the body collection, who may join
// (Hellos, floods, CURVE keys) and its limits' configuration.
#include "Admission.hpp"
#include "Authenticator.hpp"
#include "CouplingSeries.hpp"
#include "Peer.hpp"
#include "RunBodies.hpp"
#include "RunState.hpp"

#include "grainlink/config/ConfigNode.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>

using namespace grainlink::coupling;
namespace pb = grainlink::v1;
using State = Coordinator::State;

TEST_CASE("Run state: the lifecycle in order, and what to do out of turn",
          "[coupling][coordinator]") {
    RunState run(1e-9);
    CHECK(run.state() == State::Bound);
    CHECK(run.where() == "during the handshake");
    CHECK_THROWS_WITH(run.enter(State::Running),
                      "coordinator: cannot go from state 'bound' to 'running'; call run()");
    run.enter(State::Handshake);
    CHECK(run.failure("participant 'soil'", "did not join") ==
          "participant 'soil' failed during the handshake: did not join");
    run.enter(State::Running);
    run.window = 2761;
    run.tick = 2'761'000'000;
    CHECK(run.failure("the run", "interrupted") ==
          "the run failed in window 2761 (t = 2.761 s): interrupted");
    run.enter(State::Finished);
    CHECK_THROWS_WITH(run.enter(State::Handshake),
                      "coordinator: cannot go from state 'finished' to 'handshake'; the run is "
                      "over and a coordinator runs once: construct a new Coordinator for another "
                      "run");
    RunState failed(1e-9);
    failed.enter(State::Failed); // from any state
    CHECK(std::string(failed.whatToDo()) ==
          "the run failed and a coordinator runs once: construct a new Coordinator (with "
          "resume = true to continue from the last checkpoint)");
}

namespace {

Declaration multibody(const std::string &name, const std::vector<std::string> &bodies) {
    Declaration d;
    d.name = name;
    d.role = Role::Multibody;
    for (const auto &b : bodies) {
        d.provides.push_back(BodyDescription{b, {}, {}});
        BodyState s;
        s.body = b;
        d.initial_states.push_back(s);
    }
    d.capabilities.rollback = true;
    return d;
}

Declaration soil(const std::string &name, const std::vector<std::string> &bodies) {
    Declaration d;
    d.name = name;
    d.role = Role::Soil;
    d.consumes = bodies;
    d.capabilities.rollback = true;
    return d;
}

/// The PeerError collectBodies throws, as "<who>: <why>".
std::string collectError(const std::vector<Declaration> &ds, RunNeeds needs = {}) {
    try {
        collectBodies(ds, needs);
    } catch (const PeerError &e) {
        return e.what();
    }
    return "(no error)";
}

} // namespace

TEST_CASE("Body collection: every body provided once, consumed once, and its inputs routed",
          "[coupling][coordinator]") {
    // Two rigs (two wheels and one), one soil for the three: the soil answers for its own order.
    const auto run = collectBodies({multibody("rig", {"w1", "w2"}), multibody("arm", {"tool"}),
                                    soil("soil", {"tool", "w1", "w2"})},
                                   {});
    CHECK(run.names == std::vector<std::string>{"w1", "w2", "tool"});
    CHECK(run.initial_states[2].body == "tool");
    CHECK(run.inputs == std::vector<std::vector<std::size_t>>{{0, 1}, {2}, {0, 1, 2}});
    CHECK(run.outputs[2] == std::vector<std::string>{"tool", "w1", "w2"});

    CHECK(collectError({multibody("a", {"w"}), multibody("b", {"w"}), soil("s", {"w"})}) ==
          "participant 'b': provides body 'w', which 'a' provides already");
    auto no_state = multibody("a", {"w"});
    no_state.initial_states.clear();
    CHECK(collectError({no_state, soil("s", {"w"})}) ==
          "participant 'a': gave no initial state for body 'w'");
    auto nan_state = multibody("a", {"w"});
    nan_state.initial_states[0].linear_velocity_m_s.z() = NAN;
    CHECK(collectError({nan_state, soil("s", {"w"})}) ==
          "participant 'a': gave a non-finite state of body 'w' in its Hello");
    nan_state.initial_states[0].linear_velocity_m_s.z() = 0.0;
    nan_state.initial_states[0].position_m.x() = -INFINITY;
    CHECK(collectError({nan_state, soil("s", {"w"})}) ==
          "participant 'a': gave a non-finite state of body 'w' in its Hello");
    CHECK(collectError({multibody("a", {"w"}), soil("s", {"x"})}) ==
          "participant 's': consumes body 'x', which no multibody participant provides");
    CHECK(collectError({multibody("a", {"w"}), soil("s", {"w"}), soil("t", {"w"})}) ==
          "participant 't': consumes body 'w', which 's' consumes already");
    CHECK(collectError({multibody("a", {"w", "v"}), soil("s", {"w"})}) ==
          "participant 'a': provides body 'v', which no soil participant consumes");
    auto rigid = soil("s", {"w"});
    rigid.capabilities.rollback = false;
    CHECK(collectError({multibody("a", {"w"}), rigid}, {SchemeKind::Implicit, 0}) ==
          "participant 's': cannot roll back its state, which implicit coupling needs");
    CHECK(
        collectError({multibody("a", {"w"}), soil("s", {"w"})}, {SchemeKind::ExplicitSerial, 10}) ==
        "participant 'a': cannot write checkpoints, but checkpoint_every_windows = 10");
}

namespace {

pb::Envelope soilHello() {
    pb::Envelope e;
    e.set_version(kProtocolMajor);
    e.set_sender("soil");
    e.set_sequence(1);
    auto *h = e.mutable_hello();
    h->set_protocol_major(kProtocolMajor);
    h->set_participant("soil");
    h->set_role(pb::ROLE_SOIL);
    h->add_consumes("wheel");
    h->mutable_capabilities()->set_checkpoint(true);
    return e;
}

const ParticipantSpec soil_spec{"soil", Role::Soil, {}, false};

/// The refusal admitHello gives, as "<code>: <reason>".
std::string refusal(const pb::Envelope &e, const CoordinatorLimits &limits = {},
                    const std::optional<std::string> &curve_name = std::nullopt) {
    try {
        admitHello(e, soil_spec, limits, curve_name);
    } catch (const codec::ProtocolError &error) {
        return pb::Error::Code_Name(error.code) + ": " + error.what();
    }
    return "(admitted)";
}

} // namespace

TEST_CASE("Admission: a valid Hello from the expected participant, or a refusal saying why",
          "[coupling][coordinator]") {
    pb::Envelope e = soilHello();
    const Declaration d = admitHello(e, soil_spec, {}, std::nullopt);
    CHECK(d.name == "soil");
    CHECK(d.consumes == std::vector<std::string>{"wheel"});
    CHECK(d.capabilities.checkpoint);
    CHECK(admitHello(e, soil_spec, {}, std::string("soil")).name == "soil");

    SECTION("another protocol version") {
        e.mutable_hello()->set_protocol_major(2);
        CHECK(refusal(e) == "CODE_VERSION_MISMATCH: speaks protocol major version 2, the "
                            "coordinator speaks 1");
    }
    SECTION("a Hello for someone else") {
        e.mutable_hello()->set_participant("mbs\nforged log line");
        CHECK(refusal(e) == "CODE_MALFORMED: says Hello as 'mbs\\x0aforged log line' in an "
                            "envelope from 'soil'");
    }
    SECTION("the CURVE key of another participant, or of none") {
        CHECK(refusal(e, {}, std::string("mbs")) ==
              "CODE_UNKNOWN_PARTICIPANT: says Hello as 'soil' with the CURVE key of 'mbs' (each "
              "participant joins with its own <name>.key)");
        CHECK_THAT(refusal(e, {}, std::string()),
                   Catch::Contains("the CURVE key of no participant"));
    }
    SECTION("not the first message") {
        e.set_sequence(3);
        CHECK(refusal(e) == "CODE_MALFORMED: Hello must be its first message (sequence 3)");
    }
    SECTION("another role") {
        e.mutable_hello()->set_role(pb::ROLE_MULTIBODY);
        CHECK(refusal(e) == "CODE_UNKNOWN_PARTICIPANT: joined as multibody but the run configures "
                            "it as soil");
        e.mutable_hello()->set_role(pb::ROLE_UNSPECIFIED);
        CHECK(refusal(e) == "CODE_MALFORMED: participant 'soil': Hello has no role (expected "
                            "multibody or soil)");
    }
    SECTION("more bodies than limits.max_bodies") {
        CoordinatorLimits limits;
        limits.max_bodies = 3;
        for (int i = 0; i < 3; ++i)
            e.mutable_hello()->add_consumes("w" + std::to_string(i));
        CHECK(refusal(e, limits) == "CODE_MALFORMED: Hello consumes 4 bodies, more than "
                                    "limits.max_bodies = 3");
    }
    SECTION("body names: not empty, not too long, no control characters") {
        CoordinatorLimits limits;
        limits.max_name_bytes = 8;
        e.mutable_hello()->set_consumes(0, "wheel\r\n");
        CHECK(refusal(e, limits) == "CODE_MALFORMED: body name 'wheel\\x0d\\x0a' is not 1 to 8 "
                                    "bytes without control characters (limits.max_name_bytes)");
        e.mutable_hello()->set_consumes(0, "123456789");
        CHECK_THAT(refusal(e, limits), Catch::Contains("body name '123456789' is not 1 to 8"));
        e.mutable_hello()->set_consumes(0, "");
        CHECK_THAT(refusal(e, limits), Catch::Contains("body name '' is not 1 to 8"));
        e.mutable_hello()->set_consumes(0, "12345678");
        CHECK(refusal(e, limits) == "(admitted)");
    }
    SECTION("a bad mesh") {
        e.mutable_hello()->set_role(pb::ROLE_MULTIBODY);
        const ParticipantSpec mbs_spec{"soil", Role::Multibody, {}, false};
        auto *body = e.mutable_hello()->add_provides();
        body->set_name("plate");
        body->mutable_mesh()->add_triangle_indices(0);
        CHECK_THROWS_WITH(admitHello(e, mbs_spec, {}, std::nullopt),
                          "body 'plate': triangle index count 1 is not a multiple of 3");
    }
}

namespace {

/// The run's two participants, as the coordinator starts with them.
std::vector<Peer> twoPeers() {
    std::vector<Peer> peers(2);
    peers[0].spec = {"mbs", Role::Multibody, {}, false};
    peers[1].spec = soil_spec;
    for (auto &p : peers)
        p.who = "participant '" + p.spec.name + "'";
    return peers;
}

pb::Envelope beat(const std::string &name) {
    pb::Envelope e;
    e.set_version(kProtocolMajor);
    e.set_sender(name);
    e.mutable_heartbeat();
    return e;
}

} // namespace

TEST_CASE("Lobby: strangers are answered, never joined, and never stop anything",
          "[coupling][coordinator]") {
    std::vector<Peer> peers = twoPeers();
    Lobby lobby(peers, CoordinatorLimits{});
    const Lobby::Clock::time_point now{};
    const auto receive = [&](const std::string &id, const std::string &bytes, bool open = true,
                             std::size_t frames = 1) {
        return lobby.receive(id, bytes, frames, std::nullopt, open, now);
    };

    SECTION("a valid Hello joins; a second one for the name is refused to its sender only") {
        const auto joined = receive("A", soilHello().SerializeAsString());
        REQUIRE(joined.joined == std::size_t(1));
        CHECK_FALSE(joined.error);
        CHECK(peers[1].joined);
        CHECK(peers[1].routing_id == "A");
        const auto again = receive("B", soilHello().SerializeAsString());
        CHECK(again.error == pb::Error::CODE_ALREADY_JOINED);
        CHECK(peers[1].routing_id == "A");
        CHECK(peers[1].refusal.empty());
    }
    SECTION("an invalid Hello claims nothing: the real participant joins after it") {
        pb::Envelope old_version = soilHello();
        old_version.set_version(2);
        const auto refused = receive("S", old_version.SerializeAsString());
        CHECK(refused.error == pb::Error::CODE_VERSION_MISMATCH);
        CHECK(refused.text == "speaks protocol major version 2, the coordinator speaks 1");
        CHECK(refused.warning ==
              "refused a message from 'soil': speaks protocol major version 2, the coordinator "
              "speaks 1");
        CHECK_FALSE(peers[1].joined);
        CHECK(peers[1].refusal == refused.text); // for the handshake timeout's message
        CHECK(receive("A", soilHello().SerializeAsString()).joined == std::size_t(1));
        CHECK(peers[1].refusal.empty());
        // The same stranger after the soil joined: refused again, the soil untouched.
        CHECK(receive("S", old_version.SerializeAsString()).error ==
              pb::Error::CODE_VERSION_MISMATCH);
        CHECK(peers[1].routing_id == "A");
        CHECK(peers[1].refusal.empty());
    }
    SECTION("no Hello once the run started") {
        CHECK(receive("A", soilHello().SerializeAsString(), false).error ==
              pb::Error::CODE_ALREADY_JOINED);
        CHECK_FALSE(peers[1].joined);
    }
    SECTION("an unknown name is neither echoed nor logged in full") {
        pb::Envelope e = soilHello();
        const std::string name = "x\ncoordinator: forged line" + std::string(1'000'000, 'y');
        e.set_sender(name);
        e.mutable_hello()->set_participant(name);
        const auto a = receive("S", e.SerializeAsString());
        CHECK(a.error == pb::Error::CODE_UNKNOWN_PARTICIPANT);
        CHECK(a.text.size() < 200);
        CHECK(a.text.find('\n') == std::string::npos);
        CHECK_THAT(a.text, Catch::StartsWith("this run expects participants 'mbs', 'soil', not "
                                             "'x\\x0acoordinator: forged line"));
        CHECK_THAT(a.warning, Catch::EndsWith("... (1000026 bytes)'"));
    }
    SECTION("a message of two frames, garbage, and a message before Hello are refused") {
        const auto two = receive("S", soilHello().SerializeAsString(), true, 2);
        CHECK(two.error == pb::Error::CODE_MALFORMED);
        CHECK(two.text == "a message is one frame, not 2; ignored");
        CHECK_FALSE(peers[1].joined);
        CHECK(receive("S", "\xff\xff garbage").error == pb::Error::CODE_MALFORMED);
        pb::Envelope done = soilHello();
        done.mutable_window_done();
        CHECK(receive("S", done.SerializeAsString()).text == "send Hello first (got window_done)");
    }
    SECTION("heartbeats: the first connection for a name is its heartbeat connection") {
        CHECK(
            receive("H", beat("soil").SerializeAsString()).heartbeat); // answered before it joined
        CHECK(peers[1].heartbeat_id == "H");
        const auto other = receive("X", beat("soil").SerializeAsString());
        CHECK_FALSE(other.heartbeat);
        CHECK(other.warning == "ignored a heartbeat for 'soil' from a second connection");
        CHECK_FALSE(receive("X", beat("nobody").SerializeAsString()).heartbeat);
        // With CURVE, a key beats only for its own name.
        CHECK_FALSE(
            lobby.receive("M", beat("mbs").SerializeAsString(), 1, std::string("soil"), true, now)
                .heartbeat);
        CHECK(peers[0].heartbeat_id.empty());
        CHECK(lobby.receive("M", beat("mbs").SerializeAsString(), 1, std::string("mbs"), true, now)
                  .heartbeat);
    }
    SECTION("a connection that floods is dropped with a logged reason, then ignored") {
        for (unsigned i = 0; i < CoordinatorLimits{}.max_stranger_messages_per_s; ++i)
            REQUIRE(receive("F", "garbage").error);
        const auto dropped = receive("F", "garbage");
        CHECK_FALSE(dropped.error);
        CHECK(dropped.warning == "dropped connection 0x46: more than "
                                 "limits.max_stranger_messages_per_s = 100 messages within a "
                                 "second; it is ignored from now on");
        const auto after = receive("F", soilHello().SerializeAsString());
        CHECK_FALSE(after.error);
        CHECK(after.warning.empty());
        CHECK_FALSE(peers[1].joined);
    }
}

TEST_CASE("Flood guard: a connection over its messages per second is dropped for good",
          "[coupling][coordinator]") {
    using Clock = FloodGuard::Clock;
    using std::chrono::milliseconds;
    FloodGuard guard(100);
    const Clock::time_point t0{};
    // A heartbeat connection at 10 beats a second for a minute: never dropped.
    for (int i = 0; i < 600; ++i)
        REQUIRE(guard.note("beats", t0 + milliseconds(100 * i)) == FloodGuard::Verdict::Handle);
    // 100 within one second are fine, the 101st is one too many.
    for (int i = 0; i < 100; ++i)
        REQUIRE(guard.note("flood", t0 + milliseconds(i)) == FloodGuard::Verdict::Handle);
    CHECK(guard.note("flood", t0 + milliseconds(999)) == FloodGuard::Verdict::DropNow);
    CHECK(guard.note("flood", t0 + milliseconds(60'000)) == FloodGuard::Verdict::Dropped);
    CHECK(guard.dropped() == 1);
    // Each connection counts for itself; a new second starts a new count.
    for (int i = 0; i < 100; ++i)
        REQUIRE(guard.note("other", t0 + milliseconds(500 + i)) == FloodGuard::Verdict::Handle);
    CHECK(guard.note("other", t0 + milliseconds(1500)) == FloodGuard::Verdict::Handle);
}

TEST_CASE("ZAP handler: a participant's key admits its name, nothing else is admitted",
          "[coupling][security]") {
    if (!curveAvailable()) {
        WARN("libzmq without CURVE: skipped");
        return;
    }
    const CurveKeyPair soil = generateKeyPair(), stranger = generateKeyPair();
    const auto raw = [](const CurveKeyPair &k) {
        std::string bytes(32, '\0');
        zmq_z85_decode(reinterpret_cast<std::uint8_t *>(bytes.data()), k.public_key.c_str());
        return bytes;
    };
    const std::map<std::string, std::string> names{{soil.public_key, "soil"}};
    std::vector<std::string> request{"1.0", "7", "grainlink", "127.0.0.1", "", "CURVE", raw(soil)};
    const ZapReply ok = answerZap(request, names);
    CHECK(ok.status_code == "200");
    CHECK(ok.user_id == "soil");
    request[6] = raw(stranger);
    const ZapReply refused = answerZap(request, names);
    CHECK(refused.status_code == "400");
    CHECK(refused.status_text == "unknown key " + stranger.public_key);
    CHECK(refused.user_id.empty());
    request[6] = raw(soil);
    request[5] = "PLAIN";
    CHECK(answerZap(request, names).status_code == "400");
    request[5] = "CURVE";
    request.pop_back();
    CHECK(answerZap(request, names).status_text == "malformed ZAP request");
}

TEST_CASE("Limits: read from coupling.limits, checked with the file and line",
          "[coupling][coordinator]") {
    const std::string head = "coupling:\n"
                             "  scheme: explicit-serial\n"
                             "  end_time_s: 1.0\n"
                             "  macro_step_s: 0.01\n";
    const std::string people = "participants:\n"
                               "  - {name: mbs, role: multibody, external: true}\n"
                               "  - {name: soil, role: soil, external: true}\n";
    const auto load = [&](const std::string &limits) {
        return coordinatorConfigFrom(
            grainlink::config::ConfigNode::loadString(head + limits + people, "run.yaml"));
    };
    const CoordinatorLimits defaults = load("").limits;
    CHECK(defaults.max_message_bytes == 16 * 1024 * 1024);
    CHECK(defaults.max_bodies == 1000);
    CHECK(defaults.max_name_bytes == 128);
    CHECK(defaults.max_stranger_messages_per_s == 100);
    const auto c = load("  limits:\n"
                        "    max_message_bytes: 65536\n"
                        "    max_bodies: 8\n"
                        "    max_name_bytes: 32\n"
                        "    max_stranger_messages_per_s: 50\n");
    CHECK(c.limits.max_message_bytes == 65536);
    CHECK(c.limits.max_bodies == 8);
    CHECK(c.limits.max_name_bytes == 32);
    CHECK(c.limits.max_stranger_messages_per_s == 50);
    CHECK_THROWS_WITH(load("  limits:\n    max_message_bytes: 100\n"),
                      Catch::Contains("run.yaml:6") && Catch::Contains("max_message_bytes") &&
                          Catch::Contains("in [1024, "));
    CHECK_THROWS_WITH(load("  limits:\n    max_bodys: 8\n"), Catch::Contains("max_bodys"));
    // A tick so fine that the run's tick count overflows: once a run 'completed' after one
    // window of 9e-12 s with exit 0.
    CHECK_THROWS_WITH(load("  tick_s: 1.0e-30\n"),
                      Catch::Contains("run.yaml:5") && Catch::Contains("tick_s") &&
                          Catch::Contains("more than 1e15 ticks"));
    // Beats every 10 ms are 100 a second: a limit of 100 would drop them.
    CHECK_THROWS_WITH(load("  heartbeat_interval_s: 0.01\n"),
                      Catch::Contains("heartbeat_interval_s") &&
                          Catch::Contains("max_stranger_messages_per_s / 3"));
    CHECK_THROWS_WITH(load("  limits:\n    max_stranger_messages_per_s: 10\n"),
                      Catch::Contains("at least three heartbeats per heartbeat_interval_s"));
}

TEST_CASE("Coupling series: a resume keeps the rows before its window, and a damaged row is "
          "named with its file and line",
          "[coupling][coordinator]") {
    const auto dir = std::filesystem::temp_directory_path() / "grainlink-coupling-series-test";
    std::filesystem::remove_all(dir);
    { CouplingSeries series(dir.string(), {}, std::nullopt); } // its header only
    const auto path = dir / "coupling.csv";
    std::ifstream in(path);
    std::string header;
    std::getline(in, header);
    in.close();
    std::ofstream(path) << header << "\n0,0,1\n1,1,2\n2,2,3\n";
    { CouplingSeries resumed(dir.string(), {}, std::uint64_t(2)); }
    std::ifstream kept(path);
    std::string line;
    int rows = -1;
    while (std::getline(kept, line))
        ++rows;
    CHECK(rows == 2); // windows 0 and 1
    kept.close();
    // A row cut into something that is no window number (a torn write, an edited file).
    std::ofstream(path) << header << "\n0,0,1\n#1,1,2\n";
    CHECK_THROWS_WITH(CouplingSeries(dir.string(), {}, std::uint64_t(2)),
                      Catch::Contains(path.string()) && Catch::Contains("line 3") &&
                          Catch::Contains("cannot resume"));
    std::filesystem::remove_all(dir);
}
