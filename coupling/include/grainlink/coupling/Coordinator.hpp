#pragma once
// The coordinator: binds a ROUTER socket, admits the expected participants, and drives the
// windows of the coupling scheme until the end time. Any failure stops the run everywhere and
// is thrown as one CouplingError naming who failed, in which window, and why.
#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/coupling/CouplingGuard.hpp"
#include "grainlink/coupling/CouplingScheme.hpp"
#include "grainlink/coupling/Security.hpp"
#include "grainlink/coupling/Types.hpp"

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace grainlink::coupling {

struct ParticipantSpec {
    std::string name;
    Role role = Role::Multibody;
    std::vector<std::string> command; ///< `grainlink run` starts it with this command line
    bool external = false;            ///< `grainlink run` waits for it to connect instead
};

/// What the coordinator accepts from its peers, so that no peer (a participant gone wrong, or any
/// process that can reach the endpoint) can exhaust its memory or its log. docs/protocol.md
/// §Limits; keys `coupling.limits.*`.
struct CoordinatorLimits {
    /// The largest message (frame) the coordinator receives: ZeroMQ's ZMQ_MAXMSGSIZE on its
    /// socket, which disconnects a sender before it buffers a larger one.
    std::int64_t max_message_bytes = 16 * 1024 * 1024;
    /// The most sub-messages and strings one message may unpack into, counted before parsing
    /// makes any: parsing makes ~70 bytes of each (a few on the wire), so this bounds a message's
    /// memory to ~5 times max_message_bytes.
    std::size_t maxParts() const { return static_cast<std::size_t>(max_message_bytes / 16); }
    std::size_t max_bodies = 1000;    ///< bodies one Hello may provide or consume
    std::size_t max_name_bytes = 128; ///< a body's name (participant names come from the file)
    /// A connection that is not a joined participant's main one (a heartbeat connection, or a
    /// stranger) and sends more in one second is dropped: ignored from then on, logged once.
    unsigned max_stranger_messages_per_s = 100;
};

struct CoordinatorConfig {
    std::string endpoint =
        "tcp://127.0.0.1:5555"; ///< tcp://host:port, tcp://127.0.0.1:* , ipc://, inproc://
    bool insecure = false;      ///< allow a non-loopback endpoint without CURVE (explicit opt-in)
    std::optional<CurveServerKeys> curve;
    std::vector<ParticipantSpec> participants;
    SchemeSettings scheme;

    double tick_s = 1e-9;          ///< [s] the time quantum on the wire
    double start_time_s = 0.0;     ///< [s]
    double end_time_s = 1.0;       ///< [s]
    double macro_step_s = 1e-3;    ///< [s] window length
    double min_macro_step_s = 0.0; ///< [s] adaptive stepping: lower bound (0 = fixed windows)
    double max_macro_step_s = 0.0; ///< [s] adaptive stepping: upper bound
    GuardSettings guard;           ///< the energy and oscillation watch (CouplingGuard.hpp)

    double heartbeat_interval_s = 0.2;  ///< [s]
    double peer_timeout_s = 5.0;        ///< [s] silence after which a participant counts as dead
    double window_timeout_s = 600.0;    ///< [s] wall time a participant may spend on one window
    double handshake_timeout_s = 120.0; ///< [s] wait for every participant's Hello

    unsigned checkpoint_every_windows = 0; ///< 0: never
    std::string output_directory;          ///< coupling.csv and checkpoints/; empty: no files
    bool resume = false;                   ///< continue from output_directory/checkpoints/latest
    double progress_interval_s = 0.0;      ///< [s] wall time between progress lines; 0: none
    CoordinatorLimits limits;
};

struct CoordinatorSummary {
    std::uint64_t windows = 0;    ///< windows run by this process (not counting resumed ones)
    std::uint64_t iterations = 0; ///< passes over windows (= windows unless implicit)
    double end_time_s = 0.0;
    double wall_s = 0.0;
    double cumulative_mismatch_J = 0.0; ///< Σ (multibody work - soil work) over all windows
    std::vector<BodyState> final_states;
    std::vector<Wrench> final_wrenches;
    std::string completed_by; ///< the participant that ended the run early (run_complete), if any
    std::vector<std::string> guard_warnings; ///< what the coupling guard warned, in order
};

class Coordinator {
public:
    /// The run's lifecycle; run() enforces it, and a call out of turn says what to do instead.
    enum class State {
        Bound,     ///< the socket is bound: call run()
        Handshake, ///< run() waits for every participant's Hello
        Running,   ///< run() drives the windows
        Finished,  ///< run() returned: the run is over
        Failed,    ///< run() threw: the run stopped everywhere
    };

    /// Validates the configuration and binds the socket (so boundEndpoint() is known at once).
    explicit Coordinator(CoordinatorConfig config);
    ~Coordinator();
    Coordinator(const Coordinator &) = delete;
    Coordinator &operator=(const Coordinator &) = delete;

    /// The endpoint participants connect to (a tcp port chosen by the system is filled in).
    const std::string &boundEndpoint() const;
    /// Runs the whole coupled run. Throws CouplingError on any failure, after telling every
    /// participant to stop and keeping coupling.csv readable.
    CoordinatorSummary run();
    /// Asks a running coordinator to stop (signal handler safe); run() then throws.
    void requestStop();
    /// Reports, from another thread, that a participant failed outside the protocol (its
    /// process exited); run() stops everything and throws naming it.
    void reportFailure(const std::string &participant, const std::string &why);
    /// Where the run is (safe to call from another thread).
    State state() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

const char *stateName(Coordinator::State state);

/// Reads a YAML file with `coupling:` and `participants:` and nothing else (docs/protocol.md).
CoordinatorConfig loadCoordinatorConfig(const std::string &path);
/// The same sections inside a larger document (a scenario); other keys are the caller's.
CoordinatorConfig coordinatorConfigFrom(const config::ConfigNode &root);

} // namespace grainlink::coupling
