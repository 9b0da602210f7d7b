// Fuzz target: one message off the network, read as the coordinator and the participants read
// it — the lobby (a stranger's or a joining participant's bytes), the envelope codec with the
// coordinator's part budget, the header check, a Hello's admission and a window's reply
// (coupling/src/Admission.hpp, Codec.hpp, WindowReplies.hpp). A refusal is a ProtocolError or
// a PeerError naming the peer; anything else escaping, or a reply accepted with a non-finite
// value, is a finding.
#include "Admission.hpp"
#include "Codec.hpp"
#include "FuzzTarget.hpp"
#include "RunState.hpp"
#include "WindowReplies.hpp"

#include <cmath>

using namespace grainlink::coupling;
namespace pb = codec::pb;
namespace fz = grainlink::fuzz;

namespace {

const CoordinatorLimits kLimits{};
const ParticipantSpec kSpecs[] = {{"mbs", Role::Multibody, {}, false},
                                  {"soil", Role::Soil, {}, false}};

std::vector<Peer> runPeers() {
    std::vector<Peer> peers;
    for (const auto &spec : kSpecs) {
        Peer p;
        p.spec = spec;
        p.who = "participant '" + spec.name + "'";
        peers.push_back(p);
    }
    return peers;
}

void lobby(std::string_view bytes) {
    std::vector<Peer> peers = runPeers();
    Lobby lobby(peers, kLimits);
    const Lobby::Clock::time_point now{};
    // During the handshake, then after it: the lobby never throws, whatever arrives.
    lobby.receive("stranger", bytes, 1, std::nullopt, true, now);
    lobby.receive("stranger", bytes, 2, std::string("soil"), false, now);
}

/// A window's reply from each participant, as the coordinator checks it.
void windowDone(const pb::Envelope &e) {
    const auto &done = e.window_done();
    WindowReplies replies({{"participant 'mbs'", Role::Multibody, {"wheel"}},
                           {"participant 'soil'", Role::Soil, {"wheel"}}});
    for (std::size_t p = 0; p < 2; ++p) {
        replies.begin(e.window(), done.end_tick(), done.iteration());
        try {
            const WindowReplies::Reply reply = replies.read(p, e);
            if (!std::isfinite(reply.work_J))
                fz::finding("a WindowDone accepted with non-finite work");
        } catch (const PeerError &error) {
            if (error.who != "participant 'mbs'" && error.who != "participant 'soil'")
                fz::finding("a refusal that blames '" + error.who + "'");
        }
    }
}

/// What a participant converts of the coordinator's messages.
void coordinatorMessage(const pb::Envelope &e) {
    if (e.has_welcome()) {
        codec::fromWire(e.welcome().scheme());
        for (const auto &b : e.welcome().bodies())
            codec::fromWire(b);
    } else if (e.has_advance_to()) {
        const auto &a = e.advance_to();
        std::vector<Wrench> wrenches;
        std::vector<BodyState> states;
        codec::fromWire(a.wrenches(), wrenches);
        codec::fromWire(a.start_states(), states);
        codec::fromWire(a.end_states(), states);
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
    const std::string_view bytes(reinterpret_cast<const char *>(data), size);
    try {
        lobby(bytes);
    } catch (const std::exception &e) {
        fz::finding(std::string("the lobby threw: ") + e.what());
    }
    try {
        const pb::Envelope e = codec::decode(data, size, "participant 'soil'", kLimits.maxParts());
        codec::describe(e);
        codec::printable(e.sender());
        try {
            codec::checkHeader(e, e.sender(), e.sequence() > 0 ? e.sequence() - 1 : 0);
        } catch (const codec::ProtocolError &) {
        }
        if (e.has_hello()) {
            for (const auto &spec : kSpecs)
                try {
                    admitHello(e, spec, kLimits, std::nullopt);
                } catch (const codec::ProtocolError &) {
                }
        }
        if (e.has_window_done())
            windowDone(e);
        coordinatorMessage(e);
    } catch (const codec::ProtocolError &) {
    } catch (const std::exception &e) {
        fz::finding(std::string("a message refused without a protocol error (") +
                    typeid(e).name() + "): " + e.what());
    }
    return 0;
}
