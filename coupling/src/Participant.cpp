#include "grainlink/coupling/Participant.hpp"

#include "Codec.hpp"
#include "HandshakeWatch.hpp"
#include "OutputCheck.hpp"
#include "Sockets.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

namespace grainlink::coupling {

namespace pb = codec::pb;
using sockets::Clock;

const char *stateName(Participant::State state) {
    switch (state) {
    case Participant::State::Created:
        return "created";
    case Participant::State::Ready:
        return "ready";
    case Participant::State::WindowOpen:
        return "window open";
    case Participant::State::OutputsWritten:
        return "outputs written";
    case Participant::State::CheckpointRequested:
        return "checkpoint requested";
    case Participant::State::Finished:
        return "finished";
    case Participant::State::Finalized:
        return "finalized";
    }
    return "?";
}

struct Participant::Impl {
    explicit Impl(ParticipantConfig c)
        : config(std::move(c)), who_text("participant '" + config.name + "'") {
        if (config.role == Role::Multibody)
            for (const auto &b : config.provides)
                expected_bodies.push_back(b.name);
        else
            expected_bodies = config.consumes;
    }

    ParticipantConfig config;
    const std::string who_text;               ///< "participant '<name>'", for messages
    std::vector<std::string> expected_bodies; ///< what writeOutputs() must answer for, in order
    codec::ScratchEnvelope incoming;          ///< the last message from the coordinator
    codec::ScratchEnvelope outgoing; ///< WindowDone, built anew each window in the same memory
    sockets::ContextFor own_context{config.endpoint};
    zmq::context_t &context = own_context.get();
    zmq::socket_t socket; ///< main connection, used by the calling thread only
    std::optional<HandshakeWatch> handshake_watch; ///< on `socket` until the Welcome
    State state = State::Created;
    RunInfo run;
    WindowInputs inputs;
    WindowOutputs outputs;
    std::uint64_t sent_sequence = 0;
    std::uint64_t received_sequence = 0;
    std::uint64_t expected_window = 0;
    std::string checkpoint_directory;
    std::uint64_t checkpoint_window = 0;
    bool run_stopped = false;      ///< the coordinator stopped the run, refused us or is gone
    bool failure_reported = false; ///< fail() told the coordinator already

    // Heartbeats travel on their own connection from their own thread, so a participant busy
    // in a long window still proves it is alive, and notices when the coordinator is gone.
    std::thread heartbeat_thread;
    std::atomic<bool> stop_heartbeat{false};
    std::atomic<Clock::rep> coordinator_seen{0};
    std::atomic<bool> coordinator_heard{false};
    std::atomic<bool> shutdown_heard{false}; ///< a Shutdown came on the heartbeat connection
    std::mutex shutdown_mutex;
    std::string shutdown_reason;
    std::atomic<double> heartbeat_interval_s{0.2};
    double peer_timeout_s = 5.0;

    const std::string &who() const { return who_text; }

    pb::Envelope envelope(std::uint64_t window) {
        pb::Envelope e;
        address(window, e);
        return e;
    }

    /// Fills in the envelope's header for the next message to the coordinator.
    void address(std::uint64_t window, pb::Envelope &e) {
        e.set_version(kProtocolMajor);
        e.set_sender(config.name);
        e.set_sequence(++sent_sequence);
        e.set_window(window);
    }

    void noteCoordinatorAlive() {
        coordinator_seen = Clock::now().time_since_epoch().count();
        coordinator_heard = true;
    }

    double coordinatorSilence() const {
        const Clock::time_point seen{Clock::duration{coordinator_seen.load()}};
        return sockets::secondsSince(seen);
    }

    void expect(State wanted, const char *call, const char *what_to_do) const {
        if (state != wanted)
            throw LifecycleError(who() + ": " + call + " called in state '" + stateName(state) +
                                 "'; " + what_to_do);
    }

    std::string whatToDoNow() const {
        switch (state) {
        case State::Created:
            return "call initialize() first";
        case State::Ready:
            return "call waitForCommand()";
        case State::WindowOpen:
            return "write this window's outputs with writeOutputs(), then call advance()";
        case State::OutputsWritten:
            return "call advance() to send this window's outputs";
        case State::CheckpointRequested:
            return "write the checkpoint into checkpointDirectory(), then call checkpointWritten()";
        case State::Finished:
            return "the run is over: call finalize()";
        case State::Finalized:
            return "the participant is finalized";
        }
        return "";
    }

    /// Throws why a wait for the coordinator must stop (a refused handshake, a stopped run,
    /// its silence, the timeout); returns when it may go on.
    void checkWait(Clock::time_point start, double timeout_s, const char *waiting_for) {
        // Keys the coordinator refuses, or CURVE on one side only: fail at once, saying so.
        if (handshake_watch)
            if (auto why = handshake_watch->failure())
                throw CouplingError(who() + ": " + *why);
        if (shutdown_heard) {
            std::lock_guard<std::mutex> lock(shutdown_mutex);
            run_stopped = true;
            throw CouplingError(who() + ": the coordinator stopped the run: " + shutdown_reason);
        }
        // Silence counts only once the coordinator answered: it may start after us.
        if (coordinator_heard && coordinatorSilence() > peer_timeout_s) {
            std::ostringstream os;
            os.precision(3);
            os << who() << ": the coordinator has been silent for " << coordinatorSilence()
               << " s while waiting for " << waiting_for
               << " (it stopped, or the connection is down)";
            run_stopped = true;
            throw CouplingError(os.str());
        }
        if (sockets::secondsSince(start) > timeout_s) {
            std::ostringstream os;
            os << who() << ": no " << waiting_for << " from the coordinator at " << config.endpoint
               << " within " << timeout_s << " s";
            run_stopped = true;
            throw CouplingError(os.str());
        }
    }

    /// Receives the next message from the coordinator, checking order and liveness. The envelope
    /// stays valid until the next call.
    const pb::Envelope &receive(double timeout_s, const char *waiting_for) {
        const auto start = Clock::now();
        for (;;) {
            zmq::message_t message;
            if (sockets::receive(socket, message)) { // waits at most 50 ms (rcvtimeo)
                noteCoordinatorAlive();
                pb::Envelope &e = incoming.fresh();
                codec::decode(message.data(), message.size(), "the coordinator", e);
                if (e.sequence() != received_sequence + 1)
                    throw CouplingError(who() + ": message " + std::to_string(e.sequence()) +
                                        " from the coordinator arrived after " +
                                        std::to_string(received_sequence) + " (out of order)");
                received_sequence = e.sequence();
                return e;
            }
            checkWait(start, timeout_s, waiting_for);
        }
    }

    [[noreturn]] void stopped(const pb::Envelope &e) {
        run_stopped = true;
        if (e.has_shutdown())
            throw CouplingError(who() +
                                ": the coordinator stopped the run: " + e.shutdown().reason());
        if (e.has_error())
            throw CouplingError(who() + ": the coordinator refused: " + e.error().message());
        throw CouplingError(who() + ": unexpected " + codec::bodyName(e) + " from the coordinator");
    }

    void startHeartbeats() {
        heartbeat_thread = std::thread([this] {
            try {
                zmq::socket_t beat =
                    sockets::connectDealer(context, config.endpoint, config.curve, 0);
                pb::Envelope e;
                e.set_version(kProtocolMajor);
                e.set_sender(config.name);
                e.mutable_heartbeat();
                const std::string bytes = codec::encode(e);
                while (!stop_heartbeat) {
                    const long interval_ms = std::lround(heartbeat_interval_s * 1000.0);
                    (void)beat.send(zmq::buffer(bytes), zmq::send_flags::dontwait);
                    const auto sent = Clock::now();
                    while (!stop_heartbeat && sockets::secondsSince(sent) < heartbeat_interval_s) {
                        if (sockets::poll(beat, std::min(interval_ms, 50L))) {
                            zmq::message_t reply;
                            (void)beat.recv(reply, zmq::recv_flags::none);
                            noteCoordinatorAlive();
                            // A run that fails before we joined is announced here.
                            pb::Envelope news;
                            if (news.ParseFromArray(reply.data(), int(reply.size())) &&
                                news.has_shutdown()) {
                                std::lock_guard<std::mutex> lock(shutdown_mutex);
                                shutdown_reason = news.shutdown().reason();
                                shutdown_heard = true;
                            }
                        }
                    }
                }
            } catch (const zmq::error_t &) {
                // The context is closing; the main thread reports what went wrong.
            }
        });
    }

    void stopHeartbeats() {
        stop_heartbeat = true;
        if (heartbeat_thread.joinable())
            heartbeat_thread.join();
    }
};

Participant::Participant(ParticipantConfig config)
    : impl_(std::make_unique<Impl>(std::move(config))) {
    const auto &c = impl_->config;
    if (c.name.empty() || c.name == "coordinator")
        throw CouplingError("a participant needs a name other than 'coordinator'");
    if (c.role == Role::Multibody && c.provides.empty())
        throw CouplingError(impl_->who() + ": a multibody participant must provide a body");
    if (c.role == Role::Multibody && c.initial_states.size() != c.provides.size())
        throw CouplingError(impl_->who() + ": give one initial state per provided body");
    if (c.role == Role::Soil && c.consumes.empty())
        throw CouplingError(impl_->who() + ": a soil participant must consume a body");
}

Participant::~Participant() {
    impl_->stopHeartbeats();
    if (impl_->socket)
        impl_->socket.close();
}

const RunInfo &Participant::initialize() {
    auto &s = *impl_;
    s.expect(State::Created, "initialize()", "it can be called once");
    // The handshake watch attaches before the connection, so that it misses no attempt.
    s.socket = sockets::makeDealer(s.context, s.config.curve, 2000);
    s.handshake_watch.emplace(s.context, s.socket, s.config.curve, s.config.endpoint);
    s.socket.connect(s.config.endpoint);
    s.heartbeat_interval_s = s.config.heartbeat_interval_s;
    s.peer_timeout_s = s.config.peer_timeout_s;
    s.startHeartbeats();

    pb::Envelope hello = s.envelope(0);
    auto *h = hello.mutable_hello();
    h->set_protocol_major(kProtocolMajor);
    h->set_protocol_minor(kProtocolMinor);
    h->set_participant(s.config.name);
    h->set_role(codec::toWire(s.config.role));
    for (const auto &b : s.config.provides)
        codec::toWire(b, h->add_provides());
    for (const auto &b : s.config.consumes)
        h->add_consumes(b);
    h->mutable_capabilities()->set_rollback(s.config.capabilities.rollback);
    h->mutable_capabilities()->set_checkpoint(s.config.capabilities.checkpoint);
    h->mutable_capabilities()->set_triangle_loads(s.config.capabilities.triangle_loads);
    if (s.config.role == Role::Multibody)
        codec::toWire(s.config.initial_states, 0, h->mutable_initial_states());
    // Queued once the DEALER has a connection to queue it on. A handshake that failed before
    // (CURVE on one side only, under load) can leave it none, and a blocking send then waited
    // for ever: try without waiting, and stop as the wait for the Welcome would.
    zmq::message_t message = sockets::encode(hello);
    const auto start = Clock::now();
    while (!s.socket.send(message, zmq::send_flags::dontwait)) {
        s.checkWait(start, s.config.handshake_timeout_s, "Welcome");
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }

    const pb::Envelope &reply = s.receive(s.config.handshake_timeout_s, "Welcome");
    s.handshake_watch.reset(); // the connection is up
    if (!reply.has_welcome())
        s.stopped(reply);
    const auto &w = reply.welcome();
    s.run.run_id = w.run_id();
    s.run.tick_s = w.tick_s();
    s.run.start_tick = w.start_tick();
    s.run.end_tick = w.end_tick();
    s.run.macro_step_ticks = w.macro_step_ticks();
    s.run.scheme = codec::fromWire(w.scheme());
    for (const auto &b : w.bodies())
        s.run.bodies.push_back(codec::fromWire(b));
    s.expected_window = 0;
    if (w.has_restore()) {
        s.run.restore = RestorePoint{w.restore().window(), w.restore().tick(),
                                     w.restore().checkpoint_directory()};
        s.expected_window = w.restore().window();
    }
    if (s.run.scheme == SchemeKind::Implicit && !s.config.capabilities.rollback)
        throw CouplingError(s.who() + ": the run uses implicit coupling, which needs rollback");
    s.heartbeat_interval_s = w.heartbeat_interval_ms() / 1000.0;
    s.peer_timeout_s = w.peer_timeout_ms() / 1000.0;
    s.noteCoordinatorAlive();
    s.state = State::Ready;
    return s.run;
}

Command Participant::waitForCommand() {
    auto &s = *impl_;
    if (s.state != State::Ready)
        throw LifecycleError(s.who() + ": waitForCommand() called in state '" + stateName(s.state) +
                             "'; " + s.whatToDoNow());
    // No bound: a window of the other side may take long; liveness is the heartbeats' job.
    const pb::Envelope &e = s.receive(1e300, "the next command");
    if (e.has_advance_to()) {
        const auto &a = e.advance_to();
        if (e.window() != s.expected_window &&
            !(a.iteration() > 0 && e.window() + 1 == s.expected_window))
            throw CouplingError(s.who() + ": AdvanceTo for window " + std::to_string(e.window()) +
                                " while window " + std::to_string(s.expected_window) +
                                " was expected");
        WindowInputs &in = s.inputs; // filled in place: its vectors keep their storage
        in.window = e.window();
        in.start_tick = a.start_tick();
        in.end_tick = a.end_tick();
        in.start_s = a.start_tick() * s.run.tick_s;
        in.end_s = a.end_tick() * s.run.tick_s;
        in.duration_s = (a.end_tick() - a.start_tick()) * s.run.tick_s;
        in.iteration = a.iteration();
        in.save_state = a.save_state();
        in.restore_state = a.restore_state();
        codec::fromWire(a.wrenches(), in.wrenches);
        codec::fromWire(a.start_states(), in.start_states);
        codec::fromWire(a.end_states(), in.end_states);
        s.outputs = WindowOutputs{};
        s.expected_window = e.window() + 1;
        s.state = State::WindowOpen;
        return Command::Advance;
    }
    if (e.has_checkpoint()) {
        s.checkpoint_directory = e.checkpoint().checkpoint_directory();
        s.checkpoint_window = e.checkpoint().window();
        std::filesystem::create_directories(s.checkpoint_directory);
        s.state = State::CheckpointRequested;
        return Command::WriteCheckpoint;
    }
    if (e.has_shutdown() && !e.shutdown().failure()) {
        s.state = State::Finished;
        return Command::Finish;
    }
    s.stopped(e);
}

const WindowInputs &Participant::inputs() const {
    if (impl_->state != State::WindowOpen)
        throw LifecycleError(impl_->who() + ": inputs() read in state '" + stateName(impl_->state) +
                             "'; inputs exist between waitForCommand() "
                             "returning Command::Advance and writeOutputs()");
    return impl_->inputs;
}

const std::string &Participant::checkpointDirectory() const {
    impl_->expect(State::CheckpointRequested, "checkpointDirectory()",
                  "it is valid after waitForCommand() returned Command::WriteCheckpoint");
    return impl_->checkpoint_directory;
}

void Participant::checkpointWritten() {
    auto &s = *impl_;
    s.expect(State::CheckpointRequested, "checkpointWritten()",
             "call it after waitForCommand() returned Command::WriteCheckpoint");
    pb::Envelope e = s.envelope(s.checkpoint_window);
    e.mutable_checkpoint_done()->set_window(s.checkpoint_window);
    sockets::send(s.socket, e);
    s.state = State::Ready;
}

void Participant::writeOutputs(WindowOutputs outputs) {
    auto &s = *impl_;
    if (s.state != State::WindowOpen)
        throw LifecycleError(s.who() + ": writeOutputs() called in state '" + stateName(s.state) +
                             "'; " + s.whatToDoNow());
    // The same check the coordinator runs on arrival (OutputCheck), worded for this call.
    const auto problem = s.config.role == Role::Multibody
                             ? checkOutputs(outputs.states, s.expected_bodies)
                             : checkOutputs(outputs.wrenches, s.expected_bodies);
    if (problem)
        throw CouplingError(s.who() + ": " +
                            (problem->kind == OutputProblem::Kind::NonFinite
                                 ? problem->text + " in window " + std::to_string(s.inputs.window)
                                 : "writeOutputs() got " + problem->text));
    s.outputs = std::move(outputs);
    s.state = State::OutputsWritten;
}

void Participant::advance() {
    auto &s = *impl_;
    if (s.state != State::OutputsWritten)
        throw LifecycleError(s.who() + ": advance() called in state '" + stateName(s.state) +
                             "'; " + s.whatToDoNow());
    pb::Envelope &e = s.outgoing.fresh();
    s.address(s.inputs.window, e);
    auto *done = e.mutable_window_done();
    done->set_end_tick(s.inputs.end_tick);
    done->set_iteration(s.inputs.iteration);
    if (s.config.role == Role::Multibody)
        codec::toWire(s.outputs.states, s.inputs.end_tick, done->mutable_states());
    else
        codec::toWire(s.outputs.wrenches, s.inputs.start_tick, s.inputs.end_tick,
                      done->mutable_wrenches());
    for (const auto &w : s.outputs.work) {
        auto *work = done->add_work();
        work->set_body(w.body);
        work->set_work_j(w.work_J);
    }
    if (s.outputs.suggested_macro_step_s > 0.0)
        done->set_suggested_macro_step_ticks(static_cast<Ticks>(
            std::max(1.0, std::floor(s.outputs.suggested_macro_step_s / s.run.tick_s))));
    done->set_run_complete(s.outputs.run_complete);
    sockets::send(s.socket, e);
    s.state = State::Ready;
}

void Participant::finalize() {
    auto &s = *impl_;
    s.expect(State::Finished, "finalize()",
             "finalize once waitForCommand() returned Command::Finish");
    s.stopHeartbeats();
    s.state = State::Finalized;
}

void Participant::fail(const std::string &reason) noexcept {
    auto &s = *impl_;
    // Nothing to tell a coordinator that is not there, that stopped the run itself (it knows
    // why), or that heard it already; and a finished run cannot fail.
    if (!s.socket || s.run_stopped || s.failure_reported || s.state == State::Finished ||
        s.state == State::Finalized)
        return;
    s.failure_reported = true;
    try {
        pb::Envelope e = s.envelope(s.inputs.window);
        e.mutable_error()->set_code(pb::Error::CODE_PARTICIPANT_FAILED);
        e.mutable_error()->set_message(reason);
        const std::string bytes = codec::encode(e);
        (void)s.socket.send(zmq::buffer(bytes), zmq::send_flags::dontwait);
        // Wait (briefly) until the coordinator stops the run: it has then read this report and
        // prints it, rather than the exit status of a process that left before it read it.
        const auto sent = Clock::now();
        const double wait_s = std::min(2.0, s.peer_timeout_s);
        while (!s.shutdown_heard && sockets::secondsSince(sent) < wait_s) {
            zmq::message_t message;
            if (!sockets::receive(s.socket, message)) // waits at most 50 ms
                continue;
            pb::Envelope reply;
            if (reply.ParseFromArray(message.data(), int(message.size())) &&
                (reply.has_shutdown() || reply.has_error()))
                break;
        }
    } catch (...) {
        // Best effort: the coordinator also notices the process exit or the missing heartbeats.
    }
    s.run_stopped = true;
}

Participant::State Participant::state() const {
    return impl_->state;
}
const std::string &Participant::name() const {
    return impl_->config.name;
}
Role Participant::role() const {
    return impl_->config.role;
}
const RunInfo &Participant::runInfo() const {
    return impl_->run;
}

} // namespace grainlink::coupling
