#pragma once
// The participant side of a coupled run, for our DEM and Simbody nodes and for a user's own code.
// Most code runs a node through the one loop of ParticipantNode.hpp (runParticipant), which
// makes these calls. The lifecycle (preCICE-like) is enforced; a call out of order throws
// LifecycleError saying what to do:
//
//   Participant p(config);
//   const RunInfo &run = p.initialize();          // handshake; run.restore set when resuming
//   for (;;) {
//       switch (p.waitForCommand()) {
//       case Command::WriteCheckpoint: model.write(p.checkpointDirectory()); p.checkpointWritten();
//       break; case Command::Advance: {
//           const WindowInputs &in = p.inputs();
//           if (in.restore_state) model.restore();   // implicit coupling: repeat the window
//           if (in.save_state) model.save();
//           p.writeOutputs(model.advance(in));
//           p.advance();
//           break;
//       }
//       case Command::Finish: p.finalize(); return;
//       }
//   }
//   // on any exception of the model: p.fail(what) before giving up
#include "grainlink/coupling/Security.hpp"
#include "grainlink/coupling/Types.hpp"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace grainlink::coupling {

struct ParticipantConfig {
    std::string name;
    Role role = Role::Multibody;
    std::string endpoint = "tcp://127.0.0.1:5555";
    std::vector<BodyDescription> provides; ///< multibody: the bodies it integrates
    std::vector<BodyState> initial_states; ///< multibody: their states at the run start
    std::vector<std::string> consumes;     ///< soil: the bodies whose states it needs
    Capabilities capabilities;
    std::optional<CurveClientKeys> curve; ///< required when the coordinator uses CURVE
    double handshake_timeout_s = 120.0;   ///< [s] wait for the Welcome
    double heartbeat_interval_s = 0.2;    ///< [s] until the Welcome sets the run's value
    double peer_timeout_s = 5.0;          ///< [s] until the Welcome sets the run's value
};

struct RunInfo {
    std::string run_id;
    double tick_s = 0.0; ///< [s] per tick
    Ticks start_tick = 0, end_tick = 0;
    Ticks macro_step_ticks = 0;
    SchemeKind scheme = SchemeKind::ExplicitSerial;
    std::vector<BodyDescription> bodies; ///< every coupled body of the run
    std::optional<RestorePoint> restore; ///< resuming: read this checkpoint before the first window
};

struct WindowInputs {
    std::uint64_t window = 0;
    Ticks start_tick = 0, end_tick = 0;
    double start_s = 0.0, end_s = 0.0; ///< [s]
    double duration_s = 0.0; ///< [s] (end_tick - start_tick) x tick: exact, unlike end_s - start_s
    unsigned iteration = 0;
    bool save_state = false;      ///< save the state now, before advancing (implicit coupling)
    bool restore_state = false;   ///< roll back to the saved state, then advance again
    std::vector<Wrench> wrenches; ///< multibody: apply these over the window
    std::vector<BodyState> start_states; ///< soil: body states at start_s
    std::vector<BodyState> end_states;   ///< soil: body states at end_s
};

struct WindowOutputs {
    std::vector<BodyState> states;       ///< multibody: at end_s, one per provided body
    std::vector<Wrench> wrenches;        ///< soil: averaged over the window, one per consumed body
    std::vector<BodyWork> work;          ///< optional: work of the coupling wrench per body
    double suggested_macro_step_s = 0.0; ///< [s] 0: no preference (adaptive stepping hint)
    bool run_complete = false; ///< the experiment is over (e.g. steady state): end the run
};

enum class Command { Advance, WriteCheckpoint, Finish };

class Participant {
public:
    enum class State {
        Created,             ///< call initialize()
        Ready,               ///< call waitForCommand()
        WindowOpen,          ///< read inputs(), compute, then writeOutputs()
        OutputsWritten,      ///< call advance()
        CheckpointRequested, ///< write to checkpointDirectory(), then checkpointWritten()
        Finished,            ///< call finalize()
        Finalized,
    };

    explicit Participant(ParticipantConfig config);
    ~Participant();
    Participant(const Participant &) = delete;
    Participant &operator=(const Participant &) = delete;

    /// Connects, says Hello, waits for the Welcome. Throws CouplingError if refused.
    const RunInfo &initialize();
    /// Blocks until the coordinator's next command. Throws CouplingError when the run is stopped
    /// (another participant failed, the coordinator vanished or sent an error).
    Command waitForCommand();
    const WindowInputs &inputs() const;
    const std::string &checkpointDirectory() const;
    void checkpointWritten();
    void writeOutputs(WindowOutputs outputs);
    /// Sends the window's outputs; the window is done on this side.
    void advance();
    void finalize();
    /// Tells the coordinator this participant cannot go on: it stops the run everywhere and
    /// prints `reason` naming this participant and the window. Waits (at most 2 s) until the
    /// coordinator confirms, so that it reports this reason, not the process's exit. Sends
    /// nothing when the coordinator stopped the run itself, or was told already.
    void fail(const std::string &reason) noexcept;

    State state() const;
    const std::string &name() const;
    Role role() const;
    const RunInfo &runInfo() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

const char *stateName(Participant::State state);

} // namespace grainlink::coupling
