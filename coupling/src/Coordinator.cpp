// The coordinator's transport and phases: it receives on its ROUTER socket, tells joined
// participants from strangers, and drives the handshake, the windows and the checkpoints. What
// can be decided without sockets lives beside it: RunState (lifecycle, failure lines), Admission
// (the lobby: Hellos, heartbeats, strangers, floods), RunBodies (the bodies), WindowReplies
// (WindowDone checks), CheckpointFiles, Authenticator (CURVE).
#include "grainlink/coupling/Coordinator.hpp"

#include "Admission.hpp"
#include "Authenticator.hpp"
#include "CheckpointFiles.hpp"
#include "Codec.hpp"
#include "CouplingSeries.hpp"
#include "RunBodies.hpp"
#include "RunState.hpp"
#include "Sockets.hpp"
#include "WindowReplies.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <mutex>
#include <random>
#include <set>
#include <sstream>

namespace grainlink::coupling {

namespace pb = codec::pb;
namespace fs = std::filesystem;
using codec::printable;
using sockets::Clock;
using State = Coordinator::State;

namespace {

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
    std::unique_ptr<Authenticator> authenticator; ///< with CURVE; destroyed before `router` closes
    std::string bound_endpoint;
    std::atomic<bool> stop_requested{false};
    std::mutex reported_mutex;
    std::optional<std::pair<std::string, std::string>> reported_failure;

    std::vector<Peer> peers;
    RunState run{config.tick_s};
    RunBodies bodies;
    std::string run_id = makeRunId();
    std::unique_ptr<CouplingScheme> scheme;
    Lobby lobby{peers, config.limits};
    // Reused every window (no allocation once warm):
    codec::ScratchEnvelope incoming; ///< the last message received from a joined participant
    codec::ScratchEnvelope outgoing; ///< a window's AdvanceTo
    std::vector<Task> tasks;
    PeerSet pending_peers{0};
    std::optional<WindowReplies> replies;

    Ticks end_tick = 0, macro_step_ticks = 0;
    Ticks nominal_step_ticks = 0, min_step_ticks = 0, max_step_ticks = 0;
    CouplingGuard guard{GuardSettings{}};
    double cumulative_mismatch_J = 0.0;
    Ticks hint_ticks = std::numeric_limits<Ticks>::max(); ///< smallest step hint this window
    std::optional<CoordinatorSnapshot> resumed;           ///< the checkpoint, if resuming
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

    /// Stops every participant, then throws the one line that names who failed and why.
    [[noreturn]] void fail(const std::string &who, const std::string &why) {
        const std::string message = run.failure(who, why);
        shutdownAll(true, message);
        if (series)
            series->flush();
        throw CouplingError(message);
    }

    [[noreturn]] void fail(const PeerError &error) { fail(error.who, error.why); }

    void shutdownAll(bool failure, const std::string &reason) {
        for (std::size_t p = 0; p < peers.size(); ++p) {
            pb::Envelope e;
            if (peers[p].joined) {
                address(p, e);
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

    /// Fills in the envelope's header for the next message to participant `p`.
    void address(std::size_t p, pb::Envelope &e) {
        e.set_version(kProtocolMajor);
        e.set_sender("coordinator");
        e.set_sequence(++peers[p].sent_sequence);
        e.set_window(run.window);
    }

    pb::Envelope envelopeFor(std::size_t p) {
        pb::Envelope e;
        address(p, e);
        return e;
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
            fail(peers[p].who,
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

    /// The participant name the connection's CURVE key is bound to; nothing without CURVE.
    std::optional<std::string> curveName(const zmq::message_t &message) const {
        if (!authenticator)
            return std::nullopt;
        const char *name = zmq_msg_gets(message.handle(), "User-Id");
        return std::string(name ? name : "");
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
        // A DEALER of ours sends one frame. The parts of a message arrive together, so reading
        // the rest never waits; each one's own `more` says whether another follows.
        std::size_t frames = 1;
        for (bool more = payload.more(); more; ++frames) {
            zmq::message_t extra;
            more = router.recv(extra, zmq::recv_flags::none) && extra.more();
        }
        auto result = handle(id.to_string(), payload, frames);
        checkHealth();
        return result;
    }

    std::optional<Incoming> handle(const std::string &id, const zmq::message_t &payload,
                                   std::size_t frames) {
        const auto p = peerByRoutingId(id);
        if (!p) {
            handleStranger(id, payload, frames);
            return std::nullopt;
        }
        Peer &peer = peers[*p];
        if (frames > 1)
            fail(peer.who, "sent a message of " + std::to_string(frames) +
                               " frames (a participant sends one)");
        pb::Envelope &e = incoming.fresh();
        try {
            codec::decode(payload.data(), payload.size(), peer.who, e, config.limits.maxParts());
        } catch (const codec::ProtocolError &error) {
            fail(peer.who, std::string("sent a bad message: ") + error.what());
        }
        peer.last_seen = Clock::now();
        try {
            codec::checkHeader(e, peer.spec.name, peer.received_sequence);
        } catch (const codec::ProtocolError &error) {
            fail(peer.who, error.what());
        }
        peer.received_sequence = e.sequence();
        if (e.has_heartbeat())
            return std::nullopt;
        if (e.has_error())
            fail(peer.who, "reported: " + printable(e.error().message(), 2000));
        return Incoming{*p, e};
    }

    /// A message from a connection that is not a joined participant's main one: the lobby
    /// decides, the coordinator answers.
    void handleStranger(const std::string &id, const zmq::message_t &payload, std::size_t frames) {
        const std::string_view bytes(static_cast<const char *>(payload.data()), payload.size());
        const auto answer = lobby.receive(id, bytes, frames, curveName(payload),
                                          run.state() == State::Handshake, Clock::now());
        if (!answer.warning.empty())
            spdlog::warn("coordinator: {}", answer.warning);
        if (answer.joined)
            spdlog::info("coordinator: {} joined as {}", peers[*answer.joined].who,
                         roleName(peers[*answer.joined].declared.role));
        if (answer.error)
            replyError(id, *answer.error, answer.text);
        if (answer.heartbeat)
            try {
                sendRaw(id, heartbeat_bytes, true);
            } catch (const zmq::error_t &) {
            }
    }

    void checkHealth() {
        if (stop_requested)
            fail("the run", "interrupted (Ctrl-C or a stop signal)");
        {
            std::unique_lock<std::mutex> lock(reported_mutex);
            if (reported_failure) {
                const auto [name, why] = *reported_failure;
                lock.unlock();
                // A process that exits after its Hello was refused exits for that reason.
                for (const auto &peer : peers)
                    if (peer.spec.name == name && !peer.refusal.empty())
                        fail(peer.who, peer.refusal + " (its Hello was refused, then " + why + ")");
                fail("participant '" + name + "'", why);
            }
        }
        if (run.state() != State::Running)
            return;
        for (auto &peer : peers) {
            const double silent = sockets::secondsSince(peer.last_seen);
            if (silent > config.peer_timeout_s)
                fail(peer.who,
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
                    fail(peers[in->peer].who, "sent " + codec::describe(in->envelope) +
                                                  " while the coordinator waited for " + what);
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
        run.enter(State::Handshake);
        const auto start = Clock::now();
        while (std::any_of(peers.begin(), peers.end(), [](const Peer &p) { return !p.joined; })) {
            if (auto in = pump())
                fail(peers[in->peer].who,
                     "sent " + codec::bodyName(in->envelope) + " before the run started");
            if (sockets::secondsSince(start) > config.handshake_timeout_s)
                failHandshake();
        }
        std::vector<Declaration> declared;
        for (const auto &peer : peers)
            declared.push_back(peer.declared);
        try {
            bodies = collectBodies(declared, {config.scheme.kind, config.checkpoint_every_windows});
        } catch (const PeerError &error) {
            fail(error);
        }
        std::vector<WindowReplies::From> from;
        for (std::size_t p = 0; p < peers.size(); ++p) {
            peers[p].inputs = bodies.inputs[p];
            from.push_back({peers[p].who, peers[p].spec.role, bodies.outputs[p]});
        }
        replies.emplace(std::move(from));
        pending_peers = PeerSet(peers.size());
        scheme = std::make_unique<CouplingScheme>(config.scheme, bodies.initial_states);
    }

    /// Names every participant that did not join, with what the coordinator saw of it.
    [[noreturn]] void failHandshake() {
        std::string missing, seen;
        const auto note = [&seen](const std::string &text) {
            seen += (seen.empty() ? " (" : "; ") + text;
        };
        if (authenticator)
            if (const std::string refused = authenticator->refusals(); !refused.empty())
                note(refused);
        for (const auto &p : peers)
            if (!p.joined) {
                missing += (missing.empty() ? "'" : ", '") + p.spec.name + "'";
                if (!p.refusal.empty())
                    note("a Hello as '" + p.spec.name + "' was refused: " + p.refusal);
            }
        fail("participant " + missing, "did not join within handshake_timeout_s = " +
                                           formatSeconds(config.handshake_timeout_s) + " s" + seen +
                                           (seen.empty() ? "" : ")"));
    }

    void welcome(const std::optional<std::string> &restore_directory) {
        for (std::size_t p = 0; p < peers.size(); ++p) {
            pb::Envelope e = envelopeFor(p);
            auto *w = e.mutable_welcome();
            w->set_run_id(run_id);
            w->set_tick_s(config.tick_s);
            w->set_start_tick(run.tick);
            w->set_end_tick(end_tick);
            w->set_macro_step_ticks(macro_step_ticks);
            w->set_scheme(codec::toWire(config.scheme.kind));
            for (const auto &b : bodies.bodies)
                codec::toWire(b, w->add_bodies());
            w->set_heartbeat_interval_ms(
                static_cast<std::uint32_t>(std::lround(config.heartbeat_interval_s * 1000)));
            w->set_peer_timeout_ms(
                static_cast<std::uint32_t>(std::lround(config.peer_timeout_s * 1000)));
            if (restore_directory) {
                auto *r = w->mutable_restore();
                r->set_window(run.window);
                r->set_tick(run.tick);
                r->set_checkpoint_directory(
                    (fs::path(*restore_directory) / peers[p].spec.name).string());
            }
            send(p, e);
            peers[p].last_seen = Clock::now();
        }
        run.enter(State::Running);
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
            replies->begin(run.window, end, tasks.front().iteration);
            double mb_work = 0.0, soil_work = 0.0;
            awaitFrom(pending, "WindowDone", [&](std::size_t p, const pb::Envelope &e) {
                WindowReplies::Reply reply;
                try {
                    reply = replies->read(p, e);
                } catch (const PeerError &error) {
                    fail(error);
                }
                (peers[p].spec.role == Role::Multibody ? mb_work : soil_work) += reply.work_J;
                if (reply.run_complete && completed_by.empty())
                    completed_by = peers[p].spec.name;
                if (reply.suggested_step_ticks > 0)
                    hint_ticks = std::min(hint_ticks, reply.suggested_step_ticks);
                return true;
            });
            try {
                bool has_multibody = false, has_soil = false;
                for (const auto &task : tasks)
                    (task.role == Role::Multibody ? has_multibody : has_soil) = true;
                if (has_multibody) {
                    scheme->completeMultibody(replies->states());
                    work_multibody = mb_work;
                }
                if (has_soil) {
                    scheme->completeSoil(replies->wrenches());
                    work_soil = soil_work;
                }
            } catch (const CouplingError &error) {
                fail("the coupling", error.what());
            }
        }
        return {work_multibody, work_soil};
    }

    /// The next window's length: the nominal step, or with adaptive stepping the smallest hint
    /// (growing back to the nominal step when there is none), clamped; never past the end.
    /// The coupling guard after a window: a warning is logged once and kept for the summary;
    /// with coupling.guard.shorten the coordinator shortens the nominal macro step itself,
    /// within coupling.adaptive's bounds.
    void watch(double work_multibody, double work_soil, Ticks step, CoordinatorSummary &summary) {
        const auto warning = guard.afterWindow(work_multibody, work_soil, scheme->wrenches(),
                                               scheme->states(), step * config.tick_s);
        if (!warning)
            return;
        std::string message = warning->message;
        if (config.guard.shorten && max_step_ticks > 0) {
            Ticks shorter = std::max<Ticks>(
                Ticks(std::llround(warning->suggested_step_s / config.tick_s)), min_step_ticks);
            shorter -= shorter % min_step_ticks;
            if (shorter < nominal_step_ticks) {
                message += "; coupling.adaptive: the macro step goes from " +
                           formatSeconds(nominal_step_ticks * config.tick_s) + " s to " +
                           formatSeconds(shorter * config.tick_s) + " s at t = " +
                           formatSeconds((run.tick + step) * config.tick_s) + " s";
                nominal_step_ticks = shorter;
                max_step_ticks = std::min(max_step_ticks, shorter);
                guard.restart();
            } else {
                message += "; coupling.adaptive cannot go lower than its min_macro_step_s";
            }
        } else {
            message += " (with coupling.guard.shorten and coupling.adaptive the coordinator "
                       "shortens it itself)";
        }
        spdlog::warn("coupling guard: {}", message);
        summary.guard_warnings.push_back(message);
    }

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
        return std::min(step, end_tick - run.tick);
    }

    void writeCheckpoint() {
        const std::string directory = checkpointDirectory(config.output_directory, run.window);
        // A run resumed from an earlier checkpoint writes this window's again: nothing of the
        // folder it left (a damaged file, a stale manifest) may mix with the new one.
        fs::remove_all(directory);
        fs::create_directories(directory);
        PeerSet all(peers.size());
        for (std::size_t p = 0; p < peers.size(); ++p) {
            pb::Envelope e = envelopeFor(p);
            auto *c = e.mutable_checkpoint();
            c->set_window(run.window);
            c->set_tick(run.tick);
            c->set_checkpoint_directory((fs::path(directory) / peers[p].spec.name).string());
            send(p, e);
            all.insert(p);
        }
        awaitFrom(all, "CheckpointDone", [&](std::size_t, const pb::Envelope &e) {
            return e.has_checkpoint_done() && e.checkpoint_done().window() == run.window;
        });
        series->flush();
        commitCheckpoint(config.output_directory, directory,
                         {run_id, run.window, run.tick, macro_step_ticks, scheme->states(),
                          scheme->wrenches(), cumulative_mismatch_J});
    }

    /// Continues where the last complete checkpoint left off; returns its directory.
    std::string resume() {
        std::string directory;
        resumed = readLatestCheckpoint(config.output_directory, directory);
        run_id = resumed->run_id;
        run.window = resumed->window;
        run.tick = resumed->tick;
        macro_step_ticks = resumed->macro_step_ticks;
        cumulative_mismatch_J = resumed->cumulative_mismatch_J;
        // Fixed windows: the checkpoint's step is the scenario's, unless the scenario changed
        // (adaptive stepping varies it on purpose).
        if (max_step_ticks == 0 && macro_step_ticks != nominal_step_ticks)
            throw CouplingError("cannot resume from " + directory + ": coupling.macro_step_s was " +
                                formatSeconds(macro_step_ticks * config.tick_s) +
                                " s when it was written, is " +
                                formatSeconds(nominal_step_ticks * config.tick_s) +
                                " s now; start the run again, or restore the scenario");
        return directory;
    }

    /// The whole run, from the first Hello to the last window.
    CoordinatorSummary drive() {
        const auto &c = config;
        const auto started = Clock::now();
        std::optional<std::string> restore_directory;
        if (c.resume)
            restore_directory = resume();
        handshake();
        if (resumed) {
            try {
                scheme->restore(resumed->states, resumed->wrenches);
            } catch (const CouplingError &error) {
                fail("the checkpoint " + *restore_directory, error.what());
            }
        }
        if (!c.output_directory.empty())
            series = std::make_unique<CouplingSeries>(c.output_directory, bodies.names,
                                                      c.resume ? std::optional(run.window)
                                                               : std::nullopt);
        welcome(restore_directory);
        spdlog::info("coordinator: run {} with {} participants, {} coupling, {} windows of {} s",
                     run_id, peers.size(), schemeName(c.scheme.kind),
                     (end_tick - run.tick + macro_step_ticks - 1) / macro_step_ticks,
                     formatSeconds(macro_step_ticks * c.tick_s));

        CoordinatorSummary summary;
        auto last_progress = Clock::now();
        const Ticks first_tick = run.tick;
        while (run.tick < end_tick) {
            const auto window_started = Clock::now();
            const Ticks step = std::min(macro_step_ticks, end_tick - run.tick);
            const auto [work_multibody, work_soil] = runWindow(run.tick, run.tick + step);
            const double mismatch = work_multibody - work_soil;
            cumulative_mismatch_J += mismatch;
            watch(work_multibody, work_soil, step, summary);
            ++summary.windows;
            summary.iterations += scheme->iterations();
            if (series) {
                CouplingSeries::Row row;
                row.window = run.window;
                row.start_s = run.tick * c.tick_s;
                row.end_s = (run.tick + step) * c.tick_s;
                row.iterations = scheme->iterations();
                row.residual = scheme->residual();
                row.work_multibody_J = work_multibody;
                row.work_soil_J = work_soil;
                row.cumulative_mismatch_J = cumulative_mismatch_J;
                row.wall_s = sockets::secondsSince(window_started);
                series->append(row, scheme->states(), scheme->wrenches()); // queued, cheap
                series->check(); // a row the writer could not write stops the run
            }
            run.tick += step;
            ++run.window;
            if (!completed_by.empty()) {
                spdlog::info("coordinator: participant '{}' completed its experiment at t = {} s",
                             completed_by, formatSeconds(run.tick * c.tick_s));
                break;
            }
            macro_step_ticks = nextStep();
            if (c.checkpoint_every_windows > 0 && run.window % c.checkpoint_every_windows == 0 &&
                run.tick < end_tick)
                writeCheckpoint();
            if (c.progress_interval_s > 0.0 &&
                sockets::secondsSince(last_progress) >= c.progress_interval_s) {
                last_progress = Clock::now();
                const double wall = sockets::secondsSince(started);
                const double done = double(run.tick - first_tick) / double(end_tick - first_tick);
                std::fprintf(stderr,
                             "coupling: t = %.4f / %.4f s  window %llu  wall %.1f s  ETA %.0f s  "
                             "%.2f passes/window  energy mismatch %.3g J\n",
                             run.tick * c.tick_s, end_tick * c.tick_s,
                             static_cast<unsigned long long>(run.window), wall,
                             done > 0 ? wall * (1.0 - done) / done : 0.0,
                             double(summary.iterations) / double(summary.windows),
                             cumulative_mismatch_J);
            }
        }
        shutdownAll(false, completed_by.empty()
                               ? "the run reached its end time"
                               : "participant '" + completed_by + "' completed its experiment");
        if (series)
            series->flush();
        summary.end_time_s = run.tick * c.tick_s;
        summary.wall_s = sockets::secondsSince(started);
        summary.cumulative_mismatch_J = cumulative_mismatch_J;
        summary.completed_by = completed_by;
        summary.final_states = scheme->states();
        summary.final_wrenches = scheme->wrenches();
        return summary;
    }
};

namespace {

void checkLimits(const CoordinatorLimits &l) {
    if (l.max_message_bytes <= 0 || l.max_bodies == 0 || l.max_name_bytes == 0 ||
        l.max_stranger_messages_per_s == 0)
        throw CouplingError("every coupling.limits value must be positive (docs/protocol.md "
                            "§Limits)");
}

} // namespace

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
        if (c.curve && !c.curve->allowed_participants.count(p.name))
            throw CouplingError("participant '" + p.name +
                                "' has no public key: the CURVE keys "
                                "directory needs its " +
                                p.name + ".pub (`grainlink keygen`)");
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
    if (!((c.end_time_s - c.start_time_s) / c.tick_s <= kMaxTicks))
        throw CouplingError("the run would be more than 1e15 ticks of tick_s long");
    const auto ticks = [&](double seconds) {
        return static_cast<Ticks>(std::llround(seconds / c.tick_s));
    };
    s.run.tick = ticks(c.start_time_s);
    s.end_tick = ticks(c.end_time_s);
    s.nominal_step_ticks = s.macro_step_ticks = ticks(c.macro_step_s);
    if ((c.min_macro_step_s > 0.0) != (c.max_macro_step_s > 0.0) ||
        (c.max_macro_step_s > 0.0 && c.min_macro_step_s > c.max_macro_step_s))
        throw CouplingError("adaptive stepping needs 0 < min_macro_step_s <= max_macro_step_s");
    s.min_step_ticks = ticks(c.min_macro_step_s);
    s.max_step_ticks = ticks(c.max_macro_step_s);
    s.guard = CouplingGuard(c.guard);
    if ((c.checkpoint_every_windows > 0 || c.resume) && c.output_directory.empty())
        throw CouplingError("checkpoints need an output directory");
    checkLimits(c.limits);

    if (!isLocalEndpoint(c.endpoint) && !c.curve && !c.insecure)
        throw CouplingError("endpoint " + c.endpoint +
                            " is reachable from other machines: give CURVE keys "
                            "(`grainlink keygen`, key `keys_directory`) or pass --insecure");
    s.router = zmq::socket_t(s.context, zmq::socket_type::router);
    s.router.set(zmq::sockopt::router_mandatory, 1);
    s.router.set(zmq::sockopt::linger, 1000);
    s.router.set(zmq::sockopt::rcvtimeo, 20); // liveness is checked between receives
    // ZeroMQ drops a connection that announces a larger frame, before buffering any of it.
    s.router.set(zmq::sockopt::maxmsgsize, c.limits.max_message_bytes);
    if (c.curve) {
        if (!curveAvailable())
            throw CouplingError("CURVE keys given, but this libzmq has no CURVE support");
        s.authenticator = std::make_unique<Authenticator>(s.context, s.router, *c.curve);
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
    impl_->authenticator.reset();
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

Coordinator::State Coordinator::state() const {
    return impl_->run.state();
}

CoordinatorSummary Coordinator::run() {
    auto &s = *impl_;
    if (s.run.state() != State::Bound)
        throw LifecycleError(std::string("coordinator: run() called in state '") +
                             stateName(s.run.state()) + "'; " + s.run.whatToDo());
    try {
        CoordinatorSummary summary = s.drive();
        s.run.enter(State::Finished);
        return summary;
    } catch (...) {
        s.run.enter(State::Failed);
        throw;
    }
}

} // namespace grainlink::coupling
