// Participants that break the protocol: the coordinator stops the run with one line naming who
// and why, the well-behaved participants are told, and strangers are answered but do no harm.
#include "CouplingFixtures.hpp"
#include "LogCapture.hpp"
#include "RawPeer.hpp"

#include <catch2/catch.hpp>

#include <future>
#include <thread>

using namespace grainlink::coupling;
using grainlink::examples::runTwoMassSide;
using grainlink::examples::twoMassConfig;
using grainlink::testing::RawPeer;
namespace pb = grainlink::v1;

using grainlink::testing::failureOf;

namespace {

CoordinatorConfig faultRun(double end_s = 0.2) {
    auto c = grainlink::testing::twoMassRun(SchemeKind::ExplicitSerial, "tcp://127.0.0.1:*", 0.01,
                                            end_s);
    c.peer_timeout_s = 3.0;
    return c;
}

/// The multibody side on a thread; its future holds its outcome.
std::future<double> startMultibody(const std::string &endpoint,
                                   grainlink::examples::SideHooks hooks = {}) {
    return grainlink::testing::startSide(Role::Multibody, endpoint, hooks, 3.0);
}

} // namespace

TEST_CASE("Garbage from a joined participant stops the run naming it", "[coupling][fault]") {
    Coordinator coordinator(faultRun());
    auto mbs = startMultibody(coordinator.boundEndpoint());
    std::thread soil([endpoint = coordinator.boundEndpoint()] {
        RawPeer peer(endpoint, "soil");
        peer.helloAsSoil();
        peer.receiveUntil(pb::Envelope::kWelcome);
        peer.receiveUntil(pb::Envelope::kAdvanceTo);
        peer.sendBytes("\x08\x01garbage\xff\xfe");
        peer.receiveUntil(pb::Envelope::kShutdown);
    });
    const std::string failure = failureOf(coordinator);
    soil.join();
    CHECK_THAT(failure, Catch::StartsWith("participant 'soil' failed in window 0 (t = 0 s): sent "
                                          "a bad message: malformed message"));
    CHECK_THAT(failureOf(mbs), Catch::Contains("the coordinator stopped the run: participant "
                                               "'soil' failed in window 0"));
}

TEST_CASE("A wrong protocol major version is refused, the handshake timeout names it",
          "[coupling][fault]") {
    // A wrong-version Hello is no valid Hello: it cannot stop the run (anyone could send one),
    // so the coordinator refuses it, keeps waiting, and names it when the wait runs out.
    auto config = faultRun();
    config.handshake_timeout_s = 1.0;
    Coordinator coordinator(config);
    auto mbs = startMultibody(coordinator.boundEndpoint());
    std::optional<pb::Envelope> reply;
    std::thread soil([&, endpoint = coordinator.boundEndpoint()] {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        RawPeer peer(endpoint, "soil");
        peer.helloAsSoil("mass1", 2);
        reply = peer.receiveUntil(pb::Envelope::kError);
    });
    const std::string failure = failureOf(coordinator);
    soil.join();
    CHECK(failure == "participant 'soil' failed during the handshake: did not join within "
                     "handshake_timeout_s = 1 s (a Hello as 'soil' was refused: speaks protocol "
                     "major version 2, the coordinator speaks 1)");
    REQUIRE(reply);
    CHECK(reply->error().code() == pb::Error::CODE_VERSION_MISMATCH);
    CHECK(reply->error().message() == "speaks protocol major version 2, the coordinator speaks 1");
    // The multibody side either got the Shutdown or noticed the coordinator vanish.
    CHECK_THAT(failureOf(mbs), Catch::Contains("participant 'mbs'"));
}

TEST_CASE("Out-of-order, duplicate and wrong-tick replies stop the run", "[coupling][fault]") {
    std::uint64_t skip = 0, offset = 0;
    std::string expected;
    SECTION("a skipped sequence number") {
        skip = 1;
        expected = "sent message 4 after 2 (out of order)";
    }
    SECTION("a repeated sequence number") {
        skip = std::uint64_t(-1);
        expected = "sent message 2 again (duplicate; last was 2)";
    }
    SECTION("a different end tick") {
        offset = 7;
        expected = "reports end tick 20000007 for a window that ends at tick 20000000";
    }
    Coordinator coordinator(faultRun());
    auto mbs = startMultibody(coordinator.boundEndpoint());
    std::thread soil([&, endpoint = coordinator.boundEndpoint()] {
        RawPeer peer(endpoint, "soil");
        peer.helloAsSoil();
        peer.receiveUntil(pb::Envelope::kWelcome);
        auto first = peer.receiveUntil(pb::Envelope::kAdvanceTo);
        peer.answerWindow(*first); // message 2: fine
        auto second = peer.receiveUntil(pb::Envelope::kAdvanceTo);
        peer.answerWindow(*second, skip, offset);
        peer.receiveUntil(pb::Envelope::kShutdown);
    });
    const std::string failure = failureOf(coordinator);
    soil.join();
    CHECK_THAT(failure, Catch::StartsWith("participant 'soil' failed in window 1"));
    CHECK_THAT(failure, Catch::Contains(expected));
    CHECK_THAT(failureOf(mbs), Catch::Contains("the coordinator stopped the run"));
}

TEST_CASE("Strangers and a mid-run reconnect get an error, the run goes on", "[coupling][fault]") {
    Coordinator coordinator(faultRun(2.0));
    const std::string endpoint = coordinator.boundEndpoint();
    std::promise<void> running;
    grainlink::examples::SideHooks hooks;
    hooks.on_window = [&running](std::uint64_t window) {
        if (window == 5)
            running.set_value();
    };
    auto mbs = startMultibody(endpoint, hooks);
    auto soil = grainlink::testing::startSide(Role::Soil, endpoint);
    std::vector<pb::Error::Code> codes;
    std::string forged_reply;
    grainlink::testing::LogCapture log;
    std::thread strangers([&] {
        running.get_future().wait();
        RawPeer garbage(endpoint, "?");
        garbage.sendBytes("not a protobuf message at all");
        RawPeer intruder(endpoint, "intruder");
        intruder.helloAsSoil();
        RawPeer again(endpoint, "soil"); // the real soil is mid-run
        again.helloAsSoil();
        RawPeer old(endpoint, "soil"); // ... and this once stopped the run, blaming the soil
        old.helloAsSoil("mass1", 2);
        RawPeer frames(endpoint, "soil"); // ... and this wedged the coordinator for good
        frames.sendFrames({"\x08\x01", "second frame"});
        RawPeer forger(endpoint, "x\ncoordinator: participant 'soil' failed");
        forger.helloAsSoil();
        for (RawPeer *peer : {&garbage, &intruder, &again, &old, &frames, &forger})
            if (auto e = peer->receiveUntil(pb::Envelope::kError)) {
                codes.push_back(e->error().code());
                forged_reply = e->error().message();
            }
    });
    const auto summary = coordinator.run();
    strangers.join();
    CHECK(summary.windows == 200);
    CHECK(mbs.get() != 0.0);
    soil.get();
    CHECK(codes == std::vector<pb::Error::Code>{
                       pb::Error::CODE_MALFORMED, pb::Error::CODE_UNKNOWN_PARTICIPANT,
                       pb::Error::CODE_ALREADY_JOINED, pb::Error::CODE_VERSION_MISMATCH,
                       pb::Error::CODE_MALFORMED, pb::Error::CODE_UNKNOWN_PARTICIPANT});
    CHECK_THAT(forged_reply, Catch::EndsWith("not 'x\\x0acoordinator: participant 'soil' failed'"));
    const std::string text = log.text();
    CHECK_THAT(text, Catch::Contains("refused unknown participant 'x\\x0acoordinator: "));
    CHECK_THAT(text, !Catch::Contains("\ncoordinator: participant 'soil' failed"));
}

TEST_CASE("A message of several frames wedges nothing, from a participant it stops the run",
          "[coupling][fault]") {
    SECTION("from a stranger, before anyone joined: the handshake timeout still fires") {
        auto config = faultRun();
        config.handshake_timeout_s = 1.0;
        Coordinator coordinator(config);
        std::optional<pb::Envelope> reply;
        std::thread stranger([&reply, endpoint = coordinator.boundEndpoint()] {
            RawPeer peer(endpoint, "soil");
            peer.sendFrames({"one", "two", "three"});
            reply = peer.receiveUntil(pb::Envelope::kError);
        });
        CHECK(failureOf(coordinator) == "participant 'mbs', 'soil' failed during the handshake: "
                                        "did not join within handshake_timeout_s = 1 s");
        stranger.join();
        REQUIRE(reply);
        CHECK(reply->error().message() == "a message is one frame, not 3; ignored");
    }
    SECTION("from a joined participant") {
        Coordinator coordinator(faultRun());
        auto mbs = startMultibody(coordinator.boundEndpoint());
        std::thread soil([endpoint = coordinator.boundEndpoint()] {
            RawPeer peer(endpoint, "soil");
            peer.helloAsSoil();
            peer.receiveUntil(pb::Envelope::kAdvanceTo);
            peer.sendFrames({"\x08\x01", "more"});
            peer.receiveUntil(pb::Envelope::kShutdown);
        });
        const std::string failure = failureOf(coordinator);
        soil.join();
        CHECK(failure == "participant 'soil' failed in window 0 (t = 0 s): sent a message of 2 "
                         "frames (a participant sends one)");
        CHECK_THAT(failureOf(mbs), Catch::Contains("the coordinator stopped the run"));
    }
}

TEST_CASE("Hellos that are refused before the participants join lock no one out",
          "[coupling][fault]") {
    // A stranger's wrong-version Hello as 'mbs' once stopped the coordinator; one naming 'soil'
    // in the envelope but someone else in the Hello took the name. Neither may: the real ones
    // join after them and the run completes.
    Coordinator coordinator(faultRun());
    const std::string endpoint = coordinator.boundEndpoint();
    std::vector<std::string> refusals;
    std::future<double> mbs, soil;
    std::thread strangers([&] {
        RawPeer old(endpoint, "mbs");
        pb::Envelope e = old.envelope();
        e.set_version(2);
        e.mutable_hello()->set_protocol_major(2);
        e.mutable_hello()->set_participant("mbs");
        old.send(e);
        RawPeer liar(endpoint, "soil");
        pb::Envelope h = liar.envelope();
        h.mutable_hello()->set_protocol_major(grainlink::coupling::kProtocolMajor);
        h.mutable_hello()->set_participant("somebody-else");
        h.mutable_hello()->set_role(pb::ROLE_SOIL);
        liar.send(h);
        for (RawPeer *peer : {&old, &liar})
            if (auto r = peer->receiveUntil(pb::Envelope::kError))
                refusals.push_back(r->error().message());
        // Both refused: now the real participants.
        mbs = startMultibody(endpoint);
        soil = grainlink::testing::startSide(Role::Soil, endpoint);
    });
    CHECK(coordinator.run().windows == 20);
    strangers.join();
    CHECK_NOTHROW(mbs.get());
    CHECK_NOTHROW(soil.get());
    CHECK(refusals ==
          std::vector<std::string>{"speaks protocol major version 2, the coordinator speaks 1",
                                   "says Hello as 'somebody-else' in an envelope from 'soil'"});
}

TEST_CASE("A frame above limits.max_message_bytes is dropped at the socket", "[coupling][fault]") {
    // ZMQ_MAXMSGSIZE: the sender is disconnected when its frame's header announces the size,
    // so the coordinator buffers none of it (and never answers it); a smaller frame is answered.
    auto config = faultRun();
    config.limits.max_message_bytes = 64 * 1024;
    Coordinator coordinator(config);
    const std::string endpoint = coordinator.boundEndpoint();
    int big_replies = -1, small_replies = -1;
    std::future<double> mbs, soil;
    std::thread strangers([&] {
        RawPeer big(endpoint, "?");
        big.sendBytes(std::string(1024 * 1024, '\xff'));
        big_replies = big.countUntilQuiet();
        RawPeer small(endpoint, "?");
        small.sendBytes(std::string(32 * 1024, '\xff'));
        small_replies = small.countUntilQuiet();
        mbs = startMultibody(endpoint);
        soil = grainlink::testing::startSide(Role::Soil, endpoint);
    });
    CHECK(coordinator.run().windows == 20);
    strangers.join();
    mbs.get();
    soil.get();
    CHECK(big_replies == 0);
    CHECK(small_replies == 1);
}

TEST_CASE("A stranger that floods is dropped with a logged reason, the run goes on",
          "[coupling][fault]") {
    Coordinator coordinator(faultRun());
    const std::string endpoint = coordinator.boundEndpoint();
    grainlink::testing::LogCapture log;
    int replies = -1;
    std::future<double> mbs, soil;
    std::thread flood([&] {
        RawPeer peer(endpoint, "?");
        for (int i = 0; i < 300; ++i)
            peer.sendBytes("garbage");
        replies = peer.countUntilQuiet();
        mbs = startMultibody(endpoint);
        soil = grainlink::testing::startSide(Role::Soil, endpoint);
    });
    CHECK(coordinator.run().windows == 20);
    flood.join();
    mbs.get();
    soil.get();
    // 300 messages arrive within far less than a second: the first 100 are answered.
    CHECK(replies == 100);
    CHECK_THAT(log.text(), Catch::Contains(": more than limits.max_stranger_messages_per_s = 100 "
                                           "messages within a second; it is ignored from now on"));
}

TEST_CASE("A participant that reports a failure stops the run at once", "[coupling][fault]") {
    Coordinator coordinator(faultRun());
    grainlink::examples::SideHooks hooks;
    hooks.fail_at_window = 3;
    auto mbs = startMultibody(coordinator.boundEndpoint(), hooks);
    auto soil = grainlink::testing::startSide(Role::Soil, coordinator.boundEndpoint());
    CHECK(failureOf(coordinator) == "participant 'mbs' failed in window 3 (t = 0.03 s): "
                                    "reported: simulated failure of the model");
    CHECK_THAT(failureOf(soil), Catch::Contains("the coordinator stopped the run"));
    CHECK_THAT(failureOf(mbs), Catch::Contains("simulated failure at window 3"));
}

TEST_CASE("A participant whose heartbeats stop is declared dead", "[coupling][fault]") {
    // A raw soil that joins and then goes silent: no heartbeat connection at all.
    auto config = faultRun();
    config.peer_timeout_s = 1.0;
    config.heartbeat_interval_s = 0.1;
    Coordinator coordinator(config);
    auto mbs = startMultibody(coordinator.boundEndpoint());
    std::thread soil([endpoint = coordinator.boundEndpoint()] {
        RawPeer peer(endpoint, "soil");
        peer.helloAsSoil();
        peer.receiveUntil(pb::Envelope::kShutdown, 8000);
    });
    const std::string failure = failureOf(coordinator);
    soil.join();
    CHECK_THAT(failure, Catch::Matches("participant 'soil' failed in window 0 \\(t = 0 s\\): "
                                       "silent for 1\\.[0-9]* s \\(no heartbeat: .*"));
}

TEST_CASE("A Hello must name the participant that sends it", "[coupling][fault]") {
    // Refused to its connection only; the handshake timeout says what became of it.
    auto config = faultRun();
    config.handshake_timeout_s = 1.0;
    Coordinator coordinator(config);
    auto mbs = startMultibody(coordinator.boundEndpoint());
    std::optional<pb::Envelope> reply;
    std::thread soil([&reply, endpoint = coordinator.boundEndpoint()] {
        RawPeer peer(endpoint, "soil");
        pb::Envelope e = peer.envelope();
        auto *h = e.mutable_hello();
        h->set_protocol_major(grainlink::coupling::kProtocolMajor);
        h->set_participant("somebody-else");
        h->set_role(pb::ROLE_SOIL);
        h->add_consumes("mass1");
        peer.send(e);
        reply = peer.receiveUntil(pb::Envelope::kError, 3000);
    });
    const std::string failure = failureOf(coordinator);
    soil.join();
    CHECK(failure == "participant 'soil' failed during the handshake: did not join within "
                     "handshake_timeout_s = 1 s (a Hello as 'soil' was refused: says Hello as "
                     "'somebody-else' in an envelope from 'soil')");
    REQUIRE(reply);
    CHECK(reply->error().message() == "says Hello as 'somebody-else' in an envelope from 'soil'");
    CHECK_THAT(failureOf(mbs), Catch::Contains("participant 'mbs'"));
}
