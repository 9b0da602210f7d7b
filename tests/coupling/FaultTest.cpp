// Participants that break the protocol: the coordinator stops the run with one line naming who
// and why, the well-behaved participants are told, and strangers are answered but do no harm.
#include "CouplingFixtures.hpp"
#include "RawPeer.hpp"

#include <catch2/catch.hpp>

#include <future>
#include <thread>

using namespace grainlink::coupling;
using grainlink::examples::runTwoMassSide;
using grainlink::examples::twoMassConfig;
using grainlink::testing::RawPeer;
namespace pb = grainlink::v1;

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

std::string failureOf(Coordinator &coordinator) {
    try {
        coordinator.run();
    } catch (const CouplingError &e) {
        return e.what();
    }
    return "(the run did not fail)";
}

std::string failureOf(std::future<double> &side) {
    try {
        side.get();
    } catch (const CouplingError &e) {
        return e.what();
    }
    return "(the participant did not fail)";
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

TEST_CASE("A wrong protocol major version is refused and stops the run", "[coupling][fault]") {
    Coordinator coordinator(faultRun());
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
    CHECK_THAT(failure, Catch::Matches("participant 'soil' failed during the handshake: .*speaks "
                                       "protocol major version 2, the coordinator speaks 1"));
    REQUIRE(reply);
    CHECK(reply->error().code() == pb::Error::CODE_VERSION_MISMATCH);
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

TEST_CASE("Strangers and a mid-run reconnect get an error; the run goes on", "[coupling][fault]") {
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
    std::thread strangers([&] {
        running.get_future().wait();
        RawPeer garbage(endpoint, "?");
        garbage.sendBytes("not a protobuf message at all");
        RawPeer intruder(endpoint, "intruder");
        intruder.helloAsSoil();
        RawPeer again(endpoint, "soil"); // the real soil is mid-run
        again.helloAsSoil();
        for (RawPeer *peer : {&garbage, &intruder, &again})
            if (auto e = peer->receiveUntil(pb::Envelope::kError))
                codes.push_back(e->error().code());
    });
    const auto summary = coordinator.run();
    strangers.join();
    CHECK(summary.windows == 200);
    CHECK(mbs.get() != 0.0);
    soil.get();
    CHECK(codes == std::vector<pb::Error::Code>{pb::Error::CODE_MALFORMED,
                                                pb::Error::CODE_UNKNOWN_PARTICIPANT,
                                                pb::Error::CODE_ALREADY_JOINED});
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
    Coordinator coordinator(faultRun());
    auto mbs = startMultibody(coordinator.boundEndpoint());
    std::thread soil([endpoint = coordinator.boundEndpoint()] {
        RawPeer peer(endpoint, "soil");
        pb::Envelope e = peer.envelope();
        auto *h = e.mutable_hello();
        h->set_protocol_major(grainlink::coupling::kProtocolMajor);
        h->set_participant("somebody-else");
        h->set_role(pb::ROLE_SOIL);
        h->add_consumes("mass1");
        peer.send(e);
        peer.receiveUntil(pb::Envelope::kShutdown, 3000);
    });
    const std::string failure = failureOf(coordinator);
    soil.join();
    CHECK(failure == "participant 'soil' failed during the handshake: says Hello as "
                     "'somebody-else' in an envelope from 'soil'");
    CHECK_THAT(failureOf(mbs), Catch::Contains("participant 'mbs'"));
}
