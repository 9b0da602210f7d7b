#include "grainlink/coupling/Coordinator.hpp"

#include "Codec.hpp"
#include "CouplingSeries.hpp"
#include "Sockets.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <random>
#include <set>
#include <sstream>
#include <thread>

namespace grainlink::coupling {

namespace pb = codec::pb;
namespace fs = std::filesystem;
using sockets::Clock;

namespace {

/// A participant as the coordinator knows it.
struct Peer {
    ParticipantSpec spec;
    std::string who; ///< "participant '<name>'", for messages
    bool joined = false;
    std::string routing_id;
    std::string heartbeat_id; ///< routing id of its heartbeat connection
    std::vector<BodyDescription> provides;
    std::vector<BodyState> initial_states;
    std::vector<std::string> consumes;
    Capabilities capabilities;
    // Set once the bodies are known (collectBodies), so a window builds no name lists:
    std::vector<std::size_t> inputs;  ///< the bodies (indices, body order) whose inputs it gets
    std::vector<std::string> outputs; ///< the bodies it must answer for (what it provides or
                                      ///< consumes, in that order)
    std::uint64_t sent_sequence = 0;
    std::uint64_t received_sequence = 0;
    Clock::time_point last_seen;
};

/// Which participants the coordinator waits for; a plain flag per participant, so that waiting
/// allocates nothing per window.
class PeerSet {
public:
    explicit PeerSet(std::size_t peers) : member_(peers, 0) {}
    void insert(std::size_t p) {
        count_ += !member_[p];
        member_[p] = 1;
    }
    void erase(std::size_t p) {
        count_ -= member_[p];
        member_[p] = 0;
    }
    bool contains(std::size_t p) const { return member_[p] != 0; }
    bool empty() const { return count_ == 0; }
    std::size_t first() const {
        return static_cast<std::size_t>(std::find(member_.begin(), member_.end(), 1) -
                                        member_.begin());
    }

private:
    std::vector<char> member_;
    std::size_t count_ = 0;
};

/// A message from a joined participant's main connection.
struct Incoming {
    std::size_t peer;
    const pb::Envelope &envelope; ///< valid until the next message is received
};

std::string makeRunId() {
    std::random_device device;
    std::ostringstream os;
    os << std::hex << device() << device();
    return os.str();
}

std::string formatSeconds(double s) {
    char text[32];
    std::snprintf(text, sizeof text, "%.6g", s);
    return text;
}

} // namespace

struct Coordinator::Impl {
    explicit Impl(CoordinatorConfig c) : config(std::move(c)) {}

    CoordinatorConfig config;
    sockets::ContextFor own_context{config.endpoint};
    zmq::context_t &context = own_context.get();
    zmq::socket_t router;
    std::string bound_endpoint;
    std::thread zap_thread;
    std::atomic<bool> stop_zap{false};
    std::atomic<int> refused_connections{0};
    std::string last_refused_key;
    std::atomic<bool> stop_requested{false};
    std::mutex reported_mutex;
    std::optional<std::pair<std::string, std::string>> reported_failure;

    std::vector<Peer> peers;
    std::vector<std::string> body_names;
    std::vector<BodyDescription> bodies;
    std::string run_id = makeRunId();
    std::unique_ptr<CouplingScheme> scheme;
    // Reused every window (no allocation once warm):
    codec::ScratchEnvelope incoming; ///< the last message received from a joined participant
    codec::ScratchEnvelope outgoing; ///< a window's AdvanceTo
    std::vector<Task> tasks;
    PeerSet pending_peers{0};
    std::vector<BodyState> received_states, got_states;
    std::vector<Wrench> received_wrenches, got_wrenches;

    std::uint64_t window = 0;
    Ticks tick = 0, end_tick = 0, macro_step_ticks = 0;
    Ticks nominal_step_ticks = 0, min_step_ticks = 0, max_step_ticks = 0;
    bool handshake_done = false;
    double cumulative_mismatch_J = 0.0;
    Ticks hint_ticks = std::numeric_limits<Ticks>::max(); ///< smallest step hint this window
    std::vector<BodyState> resumed_states;                ///< from the checkpoint, if resuming
    std::vector<Wrench> resumed_wrenches;
    std::unique_ptr<CouplingSeries> series;
    std::string completed_by; ///< the participant that declared the experiment complete
    const std::string heartbeat_bytes = [] {
        pb::Envelope e;
        e.set_version(kProtocolMajor);
        e.set_sender("coordinator");
        e.mutable_heartbeat();
        return codec::encode(e);
    }();

    // ---------------------------------------------------------------- failures

    std::string where() const {
        if (!handshake_done)
            return "during the handshake";
        return "in window " + std::to_string(window) +
               " (t = " + formatSeconds(tick * config.tick_s) + " s)";
    }

    /// Stops every participant, then throws the one line that names who failed and why.
    [[noreturn]] void fail(const std::string &who, const std::string &why) {
        const std::string message = who + " failed " + where() + ": " + why;
        shutdownAll(true, message);
        if (series)
            series->flush();
        throw CouplingError(message);
    }

    void shutdownAll(bool failure, const std::string &reason) {
        for (std::size_t p = 0; p < peers.size(); ++p) {
            pb::Envelope e;
            if (peers[p].joined) {
                e = envelopeFor(p);
            } else { // not joined yet: its heartbeat connection (if any) hears the news
                e.set_version(kProtocolMajor);
                e.set_sender("coordinator");
            }
            e.mutable_shutdown()->set_failure(failure);
            e.mutable_shutdown()->set_reason(reason);
            const std::string &to = peers[p].joined ? peers[p].routing_id : peers[p].heartbeat_id;
            if (to.empty())
                continue;
            try {
                sendRaw(to, codec::encode(e), true);
            } catch (const zmq::error_t &) {
                // Already gone: nothing to tell it.
            }
        }
    }

    // ---------------------------------------------------------------- sending

    pb::Envelope envelopeFor(std::size_t p) {
        pb::Envelope e;
        address(p, e);
        return e;
    }

    /// Fills in the envelope's header for the next message to participant `p`.
    void address(std::size_t p, pb::Envelope &e) {
        e.set_version(kProtocolMajor);
        e.set_sender("coordinator");
        e.set_sequence(++peers[p].sent_sequence);
        e.set_window(window);
    }

    void sendRaw(const std::string &routing_id, const std::string &bytes, bool dontwait = false) {
        const auto flags = dontwait ? zmq::send_flags::dontwait : zmq::send_flags::none;
        router.send(zmq::buffer(routing_id), zmq::send_flags::sndmore | flags);
        router.send(zmq::buffer(bytes), flags);
    }

    void send(std::size_t p, const pb::Envelope &e) {
        try {
            router.send(zmq::buffer(peers[p].routing_id), zmq::send_flags::sndmore);
            router.send(sockets::encode(e), zmq::send_flags::none);
        } catch (const zmq::error_t &error) {
            fail("participant '" + peers[p].spec.name + "'",
                 std::string("cannot be reached (") + error.what() + "): it disconnected");
        }
    }

    void replyError(const std::string &routing_id, pb::Error::Code code, const std::string &text) {
        pb::Envelope e;
        e.set_version(kProtocolMajor);
        e.set_sender("coordinator");
        e.set_sequence(1);
        e.mutable_error()->set_code(code);
        e.mutable_error()->set_message(text);
        try {
            sendRaw(routing_id, codec::encode(e), true);
        } catch (const zmq::error_t &) {
        }
    }

    // ---------------------------------------------------------------- receiving

    std::optional<std::size_t> peerByRoutingId(const std::string &id) const {
        for (std::size_t p = 0; p < peers.size(); ++p)
            if (peers[p].joined && peers[p].routing_id == id)
                return p;
        return std::nullopt;
    }

    std::optional<std::size_t> peerByName(const std::string &name) const {
        for (std::size_t p = 0; p < peers.size(); ++p)
            if (peers[p].spec.name == name)
                return p;
        return std::nullopt;
    }

    std::string expectedNames() const {
        std::string names;
        for (const auto &p : peers)
            names += (names.empty() ? "'" : ", '") + p.spec.name + "'";
        return names;
    }

    /// Receives for up to 20 ms; answers heartbeats and strangers itself and returns
    /// the next message of a joined participant, if any. Checks liveness and Ctrl-C each call.
    std::optional<Incoming> pump() {
        zmq::message_t id, payload;
        if (!sockets::receive(router, id) || // waits at most the router's rcvtimeo (20 ms)
            !id.more()) {
            checkHealth();
            return std::nullopt;
        }
        (void)router.recv(payload, zmq::recv_flags::none);
        while (payload.more()) { // a well-behaved DEALER sends one frame; drop the rest
            zmq::message_t extra;
            (void)router.recv(extra, zmq::recv_flags::none);
        }
        auto result = handle(id.to_string(), payload);
        checkHealth();
        return result;
    }

    std::optional<Incoming> handle(const std::string &id, const zmq::message_t &payload) {
        if (const auto p = peerByRoutingId(id)) {
            Peer &peer = peers[*p];
            const auto who = [&peer]() -> const std::string & { return peer.who; };
            pb::Envelope &e = incoming.fresh();
            try {
                codec::decode(payload.data(), payload.size(), who(), e);
            } catch (const codec::ProtocolError &error) {
                fail(who(), std::string("sent a bad message: ") + error.what());
            }
            peer.last_seen = Clock::now();
            if (e.sender() != peer.spec.name)
                fail(who(), "sent a message signed '" + e.sender() + "'");
            if (e.sequence() <= peer.received_sequence)
                fail(who(), "sent message " + std::to_string(e.sequence()) + " again (duplicate; " +
                                "last was " + std::to_string(peer.received_sequence) + ")");
            if (e.sequence() != peer.received_sequence + 1)
                fail(who(), "sent message " + std::to_string(e.sequence()) + " after " +
                                std::to_string(peer.received_sequence) + " (out of order)");
            peer.received_sequence = e.sequence();
            if (e.has_heartbeat())
                return std::nullopt;
            if (e.has_error())
                fail(who(), "reported: " + e.error().message());
            return Incoming{*p, e};
        }
        return handleStranger(id, payload);
    }

    /// A connection that is not a joined participant's main one: a heartbeat connection, a
    /// participant saying Hello, or something that should not be here.
    std::optional<Incoming> handleStranger(const std::string &id, const zmq::message_t &payload) {
        pb::Envelope e;
        try {
            e = codec::decode(payload.data(), payload.size(), "a new connection");
        } catch (const codec::ProtocolError &error) {
            const auto p = error.sender.empty() ? std::nullopt : peerByName(error.sender);
            if (p && error.code == pb::Error::CODE_VERSION_MISMATCH) {
                const std::string why =
                    "speaks protocol major version " + std::to_string(error.version) +
                    ", the coordinator speaks " + std::to_string(kProtocolMajor);
                replyError(id, error.code, why);
                fail("participant '" + peers[*p].spec.name + "'", why);
            }
            spdlog::warn("coordinator: ignored {} bytes from an unknown connection: {}",
                         payload.size(), error.what());
            replyError(id, error.code, error.what());
            return std::nullopt;
        }
        const auto p = peerByName(e.sender());
        if (e.has_heartbeat()) {
            if (!p)
                return std::nullopt;
            // The first connection that beats for a name is its heartbeat connection; beats for
            // that name from anywhere else do not keep it alive.
            Peer &peer = peers[*p];
            if (peer.heartbeat_id.empty())
                peer.heartbeat_id = id;
            if (peer.heartbeat_id != id) {
                spdlog::warn("coordinator: ignored a heartbeat for '{}' from a second connection",
                             peer.spec.name);
                return std::nullopt;
            }
            if (peer.joined)
                peer.last_seen = Clock::now();
            try { // answered even before it joined, so it can tell when we are gone
                sendRaw(id, heartbeat_bytes, true);
            } catch (const zmq::error_t &) {
            }
            return std::nullopt;
        }
        if (e.has_hello()) {
            if (!p) {
                replyError(id, pb::Error::CODE_UNKNOWN_PARTICIPANT,
                           "this run expects participants " + expectedNames() + ", not '" +
                               e.hello().participant() + "'");
                spdlog::warn("coordinator: refused unknown participant '{}'",
                             e.hello().participant());
                return std::nullopt;
            }
            if (peers[*p].joined || handshake_done) {
                const std::string text = "participant '" + e.sender() +
                                         "' already joined this run; a participant cannot "
                                         "rejoin mid-run (resume the run from its last "
                                         "checkpoint instead)";
                replyError(id, pb::Error::CODE_ALREADY_JOINED, text);
                spdlog::warn("coordinator: {}", text);
                return std::nullopt;
            }
            admit(*p, id, e);
            return std::nullopt;
        }
        replyError(id, pb::Error::CODE_UNEXPECTED_MESSAGE,
                   "send Hello first (got " + codec::bodyName(e) + ")");
        spdlog::warn("coordinator: {} from a connection that has not joined; ignored",
                     codec::bodyName(e));
        return std::nullopt;
    }

    void admit(std::size_t p, const std::string &id, const pb::Envelope &e) {
        Peer &peer = peers[p];
        const std::string who = "participant '" + peer.spec.name + "'";
        const auto &h = e.hello();
        if (h.protocol_major() != kProtocolMajor) {
            replyError(id, pb::Error::CODE_VERSION_MISMATCH, "protocol major version mismatch");
            fail(who, "speaks protocol major version " + std::to_string(h.protocol_major()) +
                          ", the coordinator speaks " + std::to_string(kProtocolMajor));
        }
        if (h.participant() != e.sender())
            fail(who, "says Hello as '" + h.participant() + "' in an envelope from '" + e.sender() +
                          "'");
        if (e.sequence() != 1)
            fail(who,
                 "Hello must be its first message (sequence " + std::to_string(e.sequence()) + ")");
        Role role;
        try {
            role = codec::fromWire(h.role(), who);
            for (const auto &b : h.provides())
                peer.provides.push_back(codec::fromWire(b));
            peer.initial_states = codec::fromWire(h.initial_states());
        } catch (const codec::ProtocolError &error) {
            replyError(id, error.code, error.what());
            fail(who, error.what());
        }
        if (role != peer.spec.role)
            fail(who, std::string("joined as ") + roleName(role) +
                          " but the run configures it as " + roleName(peer.spec.role));
        peer.consumes.assign(h.consumes().begin(), h.consumes().end());
        peer.capabilities = Capabilities{h.capabilities().rollback(), h.capabilities().checkpoint(),
                                         h.capabilities().triangle_loads()};
        peer.routing_id = id;
        peer.joined = true;
        peer.received_sequence = 1;
        peer.last_seen = Clock::now();
        spdlog::info("coordinator: {} joined as {}", who, roleName(role));
    }

    void checkHealth() {
        if (stop_requested)
            fail("the run", "interrupted (Ctrl-C or a stop signal)");
        {
            std::unique_lock<std::mutex> lock(reported_mutex);
            if (reported_failure) {
                const auto [who, why] = *reported_failure;
                lock.unlock();
                fail("participant '" + who + "'", why);
            }
        }
        if (!handshake_done)
            return;
        for (auto &peer : peers) {
            const double silent = sockets::secondsSince(peer.last_seen);
            if (silent > config.peer_timeout_s)
                fail("participant '" + peer.spec.name + "'",
                     "silent for " + formatSeconds(silent) +
                         " s (no heartbeat: the process died, froze or lost its connection)");
        }
    }

    /// Waits until each participant in `pending` sent the message `accept` takes.
    template <typename Accept> void awaitFrom(PeerSet &pending, const char *what, Accept accept) {
        const auto start = Clock::now();
        while (!pending.empty()) {
            if (auto in = pump()) {
                if (!pending.contains(in->peer) || !accept(in->peer, in->envelope))
                    fail(peers[in->peer].who, "sent " + codec::bodyName(in->envelope) +
                                                  " for window " +
                                                  std::to_string(in->envelope.window()) +
                                                  " while the coordinator "
                                                  "waited for " +
                                                  what);
                pending.erase(in->peer);
            }
            if (!pending.empty() && sockets::secondsSince(start) > config.window_timeout_s)
                fail(peers[pending.first()].who,
                     std::string("did not send ") + what + " within window_timeout_s = " +
                         formatSeconds(config.window_timeout_s) + " s (hung?)");
        }
    }

    // ---------------------------------------------------------------- phases

    void handshake() {
        const auto start = Clock::now();
        while (std::any_of(peers.begin(), peers.end(), [](const Peer &p) { return !p.joined; })) {
            if (auto in = pump())
                fail("participant '" + peers[in->peer].spec.name + "'",
                     "sent " + codec::bodyName(in->envelope) + " before the run started");
            if (sockets::secondsSince(start) > config.handshake_timeout_s) {
                std::string missing;
                for (const auto &p : peers)
                    if (!p.joined)
                        missing += (missing.empty() ? "'" : ", '") + p.spec.name + "'";
                std::string why = "did not join within handshake_timeout_s = " +
                                  formatSeconds(config.handshake_timeout_s) + " s";
                if (refused_connections > 0)
                    why += " (" + std::to_string(refused_connections.load()) +
                           " connection(s) refused by CURVE authentication, last with public "
                           "key " +
                           last_refused_key + ")";
                fail("participant " + missing, why);
            }
        }
        collectBodies();
    }

    void collectBodies() {
        std::map<std::string, std::string> provider, consumer;
        std::vector<BodyState> initial;
        for (const auto &peer : peers)
            for (std::size_t b = 0; b < peer.provides.size(); ++b) {
                const auto &body = peer.provides[b];
                if (provider.count(body.name))
                    fail("participant '" + peer.spec.name + "'",
                         "provides body '" + body.name + "', which '" + provider[body.name] +
                             "' provides already");
                provider[body.name] = peer.spec.name;
                bodies.push_back(body);
                body_names.push_back(body.name);
                if (b >= peer.initial_states.size() || peer.initial_states[b].body != body.name)
                    fail("participant '" + peer.spec.name + "'",
                         "gave no initial state for body '" + body.name + "'");
                initial.push_back(peer.initial_states[b]);
            }
        for (const auto &peer : peers)
            for (const auto &name : peer.consumes) {
                if (!provider.count(name))
                    fail("participant '" + peer.spec.name + "'",
                         "consumes body '" + name + "', which no multibody participant provides");
                if (consumer.count(name))
                    fail("participant '" + peer.spec.name + "'", "consumes body '" + name +
                                                                     "', which '" + consumer[name] +
                                                                     "' consumes already");
                consumer[name] = peer.spec.name;
            }
        for (const auto &[name, who] : provider)
            if (!consumer.count(name))
                fail("participant '" + who + "'",
                     "provides body '" + name + "', which no soil participant consumes");
        if (config.scheme.kind == SchemeKind::Implicit)
            for (const auto &peer : peers)
                if (!peer.capabilities.rollback)
                    fail("participant '" + peer.spec.name + "'",
                         "cannot roll back its state, which implicit coupling needs");
        if (config.checkpoint_every_windows > 0)
            for (const auto &peer : peers)
                if (!peer.capabilities.checkpoint)
                    fail("participant '" + peer.spec.name + "'",
                         "cannot write checkpoints, but checkpoint_every_windows = " +
                             std::to_string(config.checkpoint_every_windows));
        for (auto &peer : peers) {
            if (peer.spec.role == Role::Multibody)
                for (const auto &b : peer.provides)
                    peer.outputs.push_back(b.name);
            else
                peer.outputs = peer.consumes;
            for (std::size_t b = 0; b < body_names.size(); ++b)
                if (std::find(peer.outputs.begin(), peer.outputs.end(), body_names[b]) !=
                    peer.outputs.end())
                    peer.inputs.push_back(b);
        }
        pending_peers = PeerSet(peers.size());
        scheme = std::make_unique<CouplingScheme>(config.scheme, std::move(initial));
    }

    std::string checkpointDirectory(std::uint64_t w) const {
        char name[32];
        std::snprintf(name, sizeof name, "window_%09llu", static_cast<unsigned long long>(w));
        // Absolute, so a participant started from another folder writes to the same place.
        return fs::absolute(fs::path(config.output_directory) / "checkpoints" / name).string();
    }

    void welcome(const std::optional<std::string> &restore_directory) {
        for (std::size_t p = 0; p < peers.size(); ++p) {
            pb::Envelope e = envelopeFor(p);
            auto *w = e.mutable_welcome();
            w->set_run_id(run_id);
            w->set_tick_s(config.tick_s);
            w->set_start_tick(tick);
            w->set_end_tick(end_tick);
            w->set_macro_step_ticks(macro_step_ticks);
            w->set_scheme(codec::toWire(config.scheme.kind));
            for (const auto &b : bodies)
                codec::toWire(b, w->add_bodies());
            w->set_heartbeat_interval_ms(
                static_cast<std::uint32_t>(std::lround(config.heartbeat_interval_s * 1000)));
            w->set_peer_timeout_ms(
                static_cast<std::uint32_t>(std::lround(config.peer_timeout_s * 1000)));
            if (restore_directory) {
                auto *r = w->mutable_restore();
                r->set_window(window);
                r->set_tick(tick);
                r->set_checkpoint_directory(
                    (fs::path(*restore_directory) / peers[p].spec.name).string());
            }
            send(p, e);
            peers[p].last_seen = Clock::now();
        }
        handshake_done = true;
    }

    /// One window: the scheme's tasks until it accepts. Returns the work each side reported.
    std::pair<double, double> runWindow(Ticks start, Ticks end) {
        scheme->beginWindow((end - start) * config.tick_s);
        double work_multibody = 0.0, work_soil = 0.0;
        for (scheme->tasks(tasks); !tasks.empty(); scheme->tasks(tasks)) {
            PeerSet &pending = pending_peers;
            for (const auto &task : tasks)
                for (std::size_t p = 0; p < peers.size(); ++p) {
                    if (peers[p].spec.role != task.role)
                        continue;
                    pb::Envelope &e = outgoing.fresh();
                    address(p, e);
                    auto *a = e.mutable_advance_to();
                    a->set_start_tick(start);
                    a->set_end_tick(end);
                    a->set_iteration(task.iteration);
                    a->set_save_state(task.save_state);
                    a->set_restore_state(task.restore_state);
                    // The scheme's lists are in body order; `inputs` picks this peer's bodies.
                    if (task.role == Role::Multibody) {
                        codec::toWire(task.wrenches, peers[p].inputs, start, end,
                                      a->mutable_wrenches());
                    } else {
                        codec::toWire(task.start_states, peers[p].inputs, start,
                                      a->mutable_start_states());
                        codec::toWire(task.end_states, peers[p].inputs, end,
                                      a->mutable_end_states());
                    }
                    send(p, e);
                    pending.insert(p);
                }
            received_states.clear();
            received_wrenches.clear();
            double mb_work = 0.0, soil_work = 0.0;
            const unsigned iteration = tasks.front().iteration;
            awaitFrom(pending, "WindowDone", [&](std::size_t p, const pb::Envelope &e) {
                if (!e.has_window_done() || e.window() != window)
                    return false;
                const auto &done = e.window_done();
                const std::string &who = peers[p].who;
                if (done.end_tick() != end)
                    fail(who, "reports end tick " + std::to_string(done.end_tick()) +
                                  " for a window that ends at tick " + std::to_string(end));
                if (done.iteration() != iteration)
                    fail(who, "reports iteration " + std::to_string(done.iteration()) +
                                  ", expected " + std::to_string(iteration));
                try {
                    if (peers[p].spec.role == Role::Multibody) {
                        codec::fromWire(done.states(), got_states);
                        checkNames(peers[p], "states", got_states);
                        received_states.insert(received_states.end(), got_states.begin(),
                                               got_states.end());
                    } else {
                        codec::fromWire(done.wrenches(), got_wrenches);
                        checkNames(peers[p], "wrenches", got_wrenches);
                        received_wrenches.insert(received_wrenches.end(), got_wrenches.begin(),
                                                 got_wrenches.end());
                    }
                } catch (const codec::ProtocolError &error) {
                    fail(who, error.what());
                }
                double work = 0.0;
                for (const auto &w : done.work())
                    work += w.work_j();
                (peers[p].spec.role == Role::Multibody ? mb_work : soil_work) += work;
                if (done.run_complete() && completed_by.empty())
                    completed_by = peers[p].spec.name;
                if (done.suggested_macro_step_ticks() > 0)
                    hint_ticks = std::min(hint_ticks, Ticks(done.suggested_macro_step_ticks()));
                return true;
            });
            try {
                bool has_multibody = false, has_soil = false;
                for (const auto &task : tasks)
                    (task.role == Role::Multibody ? has_multibody : has_soil) = true;
                if (has_multibody) {
                    scheme->completeMultibody(received_states);
                    work_multibody = mb_work;
                }
                if (has_soil) {
                    scheme->completeSoil(received_wrenches);
                    work_soil = soil_work;
                }
            } catch (const CouplingError &error) {
                fail("the coupling", error.what());
            }
        }
        return {work_multibody, work_soil};
    }

    /// Fails unless `got` is finite and names exactly the bodies `peer` answers for.
    template <typename T>
    void checkNames(const Peer &peer, const char *what, const std::vector<T> &got) {
        const std::string &who = peer.who;
        bool in_order = got.size() == peer.outputs.size();
        for (std::size_t i = 0; i < got.size(); ++i) {
            const auto &x = got[i];
            if constexpr (std::is_same_v<T, BodyState>) {
                if (!x.position_m.allFinite() || !x.linear_velocity_m_s.allFinite() ||
                    !x.angular_velocity_rad_s.allFinite())
                    fail(who, "sent a non-finite state of body '" + x.body + "'");
            } else {
                if (!x.force_N.allFinite() || !x.torque_N_m.allFinite())
                    fail(who, "sent a non-finite wrench on body '" + x.body + "'");
            }
            in_order = in_order && x.body == peer.outputs[i];
        }
        if (in_order) // the usual case: the same names in the same order
            return;
        std::vector<std::string> names, expected = peer.outputs;
        for (const auto &x : got)
            names.push_back(x.body);
        std::sort(names.begin(), names.end());
        std::sort(expected.begin(), expected.end());
        if (names != expected) {
            std::string list;
            for (const auto &n : expected)
                list += " " + n;
            fail(who,
                 std::string("sent ") + what + " for other bodies than its own {" + list + " }");
        }
    }

    /// The next window's length: the nominal step, or with adaptive stepping the smallest hint
    /// (growing back to the nominal step when there is none), clamped; never past the end.
    Ticks nextStep() {
        Ticks step = nominal_step_ticks;
        if (max_step_ticks > 0) {
            step =
                hint_ticks != std::numeric_limits<Ticks>::max() ? hint_ticks : nominal_step_ticks;
            step = std::clamp(step, min_step_ticks, max_step_ticks);
            // Whole multiples of the smallest step: a participant with a fixed internal step
            // (the DEM's, when min_macro_step_s is it) takes every window in whole steps.
            step -= step % min_step_ticks;
        }
        hint_ticks = std::numeric_limits<Ticks>::max();
        return std::min(step, end_tick - tick);
    }

    void writeCheckpoint() {
        const std::string directory = checkpointDirectory(window);
        fs::create_directories(directory);
        PeerSet all(peers.size());
        for (std::size_t p = 0; p < peers.size(); ++p) {
            pb::Envelope e = envelopeFor(p);
            auto *c = e.mutable_checkpoint();
            c->set_window(window);
            c->set_tick(tick);
            c->set_checkpoint_directory((fs::path(directory) / peers[p].spec.name).string());
            send(p, e);
            all.insert(p);
        }
        awaitFrom(all, "CheckpointDone", [&](std::size_t, const pb::Envelope &e) {
            return e.has_checkpoint_done() && e.checkpoint_done().window() == window;
        });
        pb::CoordinatorCheckpoint state;
        state.set_run_id(run_id);
        state.set_window(window);
        state.set_tick(tick);
        state.set_macro_step_ticks(macro_step_ticks);
        codec::toWire(scheme->states(), tick, state.mutable_states());
        codec::toWire(scheme->wrenches(), tick, tick, state.mutable_wrenches());
        state.set_cumulative_mismatch_j(cumulative_mismatch_J);
        series->flush();
        writeAtomically((fs::path(directory) / "coordinator.pb").string(),
                        state.SerializeAsString());
        // Only now is the checkpoint complete: `latest` moves to it.
        writeAtomically((fs::path(config.output_directory) / "checkpoints" / "latest").string(),
                        fs::path(directory).filename().string() + "\n");
    }

    static void writeAtomically(const std::string &path, const std::string &bytes) {
        const std::string temporary = path + ".tmp";
        {
            std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
            out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
            if (!out.flush())
                throw CouplingError("cannot write " + temporary);
        }
        fs::rename(temporary, path);
    }

    /// Reads the last complete checkpoint; returns its directory.
    std::string readCheckpoint() {
        const fs::path latest = fs::path(config.output_directory) / "checkpoints" / "latest";
        std::ifstream in(latest);
        std::string name;
        if (!(in >> name))
            throw CouplingError("cannot resume: no complete checkpoint (" + latest.string() +
                                " is missing)");
        const fs::path directory = fs::absolute(latest.parent_path() / name);
        std::ifstream state_file(directory / "coordinator.pb", std::ios::binary);
        pb::CoordinatorCheckpoint state;
        if (!state.ParseFromIstream(&state_file))
            throw CouplingError("cannot resume: " + (directory / "coordinator.pb").string() +
                                " is unreadable");
        run_id = state.run_id();
        window = state.window();
        tick = state.tick();
        macro_step_ticks = state.macro_step_ticks();
        cumulative_mismatch_J = state.cumulative_mismatch_j();
        resumed_states = codec::fromWire(state.states());
        resumed_wrenches = codec::fromWire(state.wrenches());
        return directory.string();
    }
    // ---------------------------------------------------------------- security

    void startAuthenticator(const CurveServerKeys &keys) {
        // ZeroMQ asks a handler bound here (ZAP, RFC 27) whether to admit each CURVE client.
        zmq::socket_t handler(context, zmq::socket_type::rep);
        handler.bind("inproc://zeromq.zap.01");
        zap_thread = std::thread([this, allowed = keys.allowed_participants,
                                  socket = std::move(handler)]() mutable {
            while (!stop_zap) {
                if (!sockets::poll(socket, 100))
                    continue;
                std::vector<zmq::message_t> frames;
                do {
                    frames.emplace_back();
                    (void)socket.recv(frames.back(), zmq::recv_flags::none);
                } while (frames.back().more());
                std::string key_text = "?";
                bool ok = false;
                if (frames.size() >= 7 && frames[6].size() == 32) {
                    char z85[41];
                    zmq_z85_encode(z85, static_cast<const std::uint8_t *>(frames[6].data()), 32);
                    key_text = z85;
                    ok = std::find(allowed.begin(), allowed.end(), key_text) != allowed.end();
                }
                if (!ok) {
                    ++refused_connections;
                    last_refused_key = key_text;
                    spdlog::warn("coordinator: refused a CURVE connection from {} with public key "
                                 "{} (not among the participants' keys)",
                                 frames.size() > 3 ? frames[3].to_string() : "?", key_text);
                }
                const std::string request_id = frames.size() > 1 ? frames[1].to_string() : "";
                socket.send(zmq::str_buffer("1.0"), zmq::send_flags::sndmore);
                socket.send(zmq::buffer(request_id), zmq::send_flags::sndmore);
                socket.send(zmq::buffer(std::string(ok ? "200" : "400")), zmq::send_flags::sndmore);
                socket.send(zmq::buffer(std::string(ok ? "OK" : "unknown key")),
                            zmq::send_flags::sndmore);
                socket.send(zmq::str_buffer(""), zmq::send_flags::sndmore);
                socket.send(zmq::str_buffer(""), zmq::send_flags::none);
            }
        });
    }
};

Coordinator::Coordinator(CoordinatorConfig config)
    : impl_(std::make_unique<Impl>(std::move(config))) {
    auto &s = *impl_;
    if (s.config.endpoint.empty())
        s.config.endpoint = "tcp://127.0.0.1:5555";
    const auto &c = s.config;
    if (c.participants.empty())
        throw CouplingError("the coordinator needs at least one participant of each role");
    bool has_multibody = false, has_soil = false;
    std::set<std::string> names;
    for (const auto &p : c.participants) {
        if (!names.insert(p.name).second)
            throw CouplingError("two participants are named '" + p.name + "'");
        (p.role == Role::Multibody ? has_multibody : has_soil) = true;
        Peer peer;
        peer.spec = p;
        peer.who = "participant '" + p.name + "'";
        s.peers.push_back(std::move(peer));
    }
    if (!has_multibody || !has_soil)
        throw CouplingError("a run needs a multibody and a soil participant");
    if (!(c.tick_s > 0.0) || !(c.macro_step_s >= c.tick_s) || !(c.end_time_s > c.start_time_s))
        throw CouplingError(
            "need tick_s > 0, macro_step_s >= tick_s and end_time_s > start_time_s");
    const auto ticks = [&](double seconds) {
        return static_cast<Ticks>(std::llround(seconds / c.tick_s));
    };
    s.tick = ticks(c.start_time_s);
    s.end_tick = ticks(c.end_time_s);
    s.nominal_step_ticks = s.macro_step_ticks = ticks(c.macro_step_s);
    if ((c.min_macro_step_s > 0.0) != (c.max_macro_step_s > 0.0) ||
        (c.max_macro_step_s > 0.0 && c.min_macro_step_s > c.max_macro_step_s))
        throw CouplingError("adaptive stepping needs 0 < min_macro_step_s <= max_macro_step_s");
    s.min_step_ticks = ticks(c.min_macro_step_s);
    s.max_step_ticks = ticks(c.max_macro_step_s);
    if ((c.checkpoint_every_windows > 0 || c.resume) && c.output_directory.empty())
        throw CouplingError("checkpoints need an output directory");

    if (!isLocalEndpoint(c.endpoint) && !c.curve && !c.insecure)
        throw CouplingError("endpoint " + c.endpoint +
                            " is reachable from other machines: give CURVE keys "
                            "(`grainlink keygen`, key `keys_directory`) or pass --insecure");
    s.router = zmq::socket_t(s.context, zmq::socket_type::router);
    s.router.set(zmq::sockopt::router_mandatory, 1);
    s.router.set(zmq::sockopt::linger, 1000);
    s.router.set(zmq::sockopt::rcvtimeo, 20); // liveness is checked between receives
    if (c.curve) {
        if (!curveAvailable())
            throw CouplingError("CURVE keys given, but this libzmq has no CURVE support");
        s.startAuthenticator(*c.curve);
        s.router.set(zmq::sockopt::zap_domain, "grainlink");
        s.router.set(zmq::sockopt::curve_server, 1);
        s.router.set(zmq::sockopt::curve_secretkey, c.curve->coordinator.secret_key);
    }
    try {
        s.router.bind(c.endpoint);
    } catch (const zmq::error_t &error) {
        throw CouplingError("cannot bind " + c.endpoint + ": " + error.what());
    }
    s.bound_endpoint = s.router.get(zmq::sockopt::last_endpoint);
}

Coordinator::~Coordinator() {
    impl_->stop_zap = true;
    if (impl_->zap_thread.joinable())
        impl_->zap_thread.join();
    impl_->router.close();
}

const std::string &Coordinator::boundEndpoint() const {
    return impl_->bound_endpoint;
}

void Coordinator::requestStop() {
    impl_->stop_requested = true;
}

void Coordinator::reportFailure(const std::string &participant, const std::string &why) {
    std::lock_guard<std::mutex> lock(impl_->reported_mutex);
    if (!impl_->reported_failure)
        impl_->reported_failure.emplace(participant, why);
}

CoordinatorSummary Coordinator::run() {
    auto &s = *impl_;
    const auto &c = s.config;
    const auto started = Clock::now();
    std::optional<std::string> restore_directory;
    if (c.resume)
        restore_directory = s.readCheckpoint();
    s.handshake();
    if (restore_directory) {
        try {
            s.scheme->restore(s.resumed_states, s.resumed_wrenches);
        } catch (const CouplingError &error) {
            s.fail("the checkpoint", error.what());
        }
    }
    if (!c.output_directory.empty())
        s.series = std::make_unique<CouplingSeries>(
            c.output_directory, s.body_names, c.resume ? std::optional(s.window) : std::nullopt);
    s.welcome(restore_directory);
    spdlog::info("coordinator: run {} with {} participants, {} coupling, {} windows of {} s",
                 s.run_id, s.peers.size(), schemeName(c.scheme.kind),
                 (s.end_tick - s.tick + s.macro_step_ticks - 1) / s.macro_step_ticks,
                 formatSeconds(s.macro_step_ticks * c.tick_s));

    CoordinatorSummary summary;
    auto last_progress = Clock::now();
    const Ticks first_tick = s.tick;
    while (s.tick < s.end_tick) {
        const auto window_started = Clock::now();
        const Ticks step = std::min(s.macro_step_ticks, s.end_tick - s.tick);
        const auto [work_multibody, work_soil] = s.runWindow(s.tick, s.tick + step);
        const double mismatch = work_multibody - work_soil;
        s.cumulative_mismatch_J += mismatch;
        ++summary.windows;
        summary.iterations += s.scheme->iterations();
        if (s.series) {
            CouplingSeries::Row row;
            row.window = s.window;
            row.start_s = s.tick * c.tick_s;
            row.end_s = (s.tick + step) * c.tick_s;
            row.iterations = s.scheme->iterations();
            row.residual = s.scheme->residual();
            row.work_multibody_J = work_multibody;
            row.work_soil_J = work_soil;
            row.cumulative_mismatch_J = s.cumulative_mismatch_J;
            row.wall_s = sockets::secondsSince(window_started);
            s.series->append(row, s.scheme->states(), s.scheme->wrenches()); // queued, cheap
        }
        s.tick += step;
        ++s.window;
        if (!s.completed_by.empty()) {
            spdlog::info("coordinator: participant '{}' completed its experiment at t = {} s",
                         s.completed_by, formatSeconds(s.tick * c.tick_s));
            break;
        }
        s.macro_step_ticks = s.nextStep();
        if (c.checkpoint_every_windows > 0 && s.window % c.checkpoint_every_windows == 0 &&
            s.tick < s.end_tick)
            s.writeCheckpoint();
        if (c.progress_interval_s > 0.0 &&
            sockets::secondsSince(last_progress) >= c.progress_interval_s) {
            last_progress = Clock::now();
            const double wall = sockets::secondsSince(started);
            const double done = double(s.tick - first_tick) / double(s.end_tick - first_tick);
            std::fprintf(
                stderr,
                "coupling: t = %.4f / %.4f s  window %llu  wall %.1f s  ETA %.0f s  "
                "%.2f passes/window  energy mismatch %.3g J\n",
                s.tick * c.tick_s, s.end_tick * c.tick_s, static_cast<unsigned long long>(s.window),
                wall, done > 0 ? wall * (1.0 - done) / done : 0.0,
                double(summary.iterations) / double(summary.windows), s.cumulative_mismatch_J);
        }
    }
    s.shutdownAll(false, s.completed_by.empty()
                             ? "the run reached its end time"
                             : "participant '" + s.completed_by + "' completed its experiment");
    if (s.series)
        s.series->flush();
    summary.end_time_s = s.tick * c.tick_s;
    summary.wall_s = sockets::secondsSince(started);
    summary.cumulative_mismatch_J = s.cumulative_mismatch_J;
    summary.completed_by = s.completed_by;
    summary.final_states = s.scheme->states();
    summary.final_wrenches = s.scheme->wrenches();
    return summary;
}

} // namespace grainlink::coupling
