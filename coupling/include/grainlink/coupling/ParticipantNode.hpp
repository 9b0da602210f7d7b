#pragma once
// The one participant loop. runParticipant() owns a participant's lifecycle — handshake, resume,
// windows, the implicit scheme's rollback, checkpoints, the end — and reports a node's failure
// to the coordinator, which stops the run printing the node's own message. A node implements
// only the physics hooks, the way Chrono's co-simulation nodes keep communication `final` in
// their base class:
//
//   class MyModel : public coupling::ParticipantNode {
//       coupling::WindowOutputs advance(const coupling::WindowInputs &in) override;
//       void saveState() override;    void restoreState() override;   // implicit coupling
//       void writeCheckpoint(const std::string &directory) override;  // checkpoints, resume
//       void readCheckpoint(const std::string &directory) override;
//   };
//   coupling::Participant participant(config);   // capabilities: what the node implements
//   MyModel model;
//   coupling::runParticipant(participant, model);
//
// A soil node sums the soil's load through its window in a WindowLoads and returns its
// outputs(): the window average and the work are computed there and nowhere else.
#include "grainlink/coupling/Participant.hpp"

#include <string>

namespace grainlink::coupling {

class ParticipantNode {
public:
    virtual ~ParticipantNode() = default;

    /// The run as the handshake set it (its bodies, times, restore point): called once, before
    /// readCheckpoint() and the first window.
    virtual void start(const RunInfo &run) { (void)run; }
    /// One window. A multibody node applies in.wrenches over it and returns its bodies' states
    /// at in.end_s (and the work the wrenches did); a soil node moves the consumed bodies from
    /// in.start_states to in.end_states and returns the window's loads (WindowLoads::outputs).
    virtual WindowOutputs advance(const WindowInputs &in) = 0;
    /// Implicit coupling: keep the state as it is now, or go back to the state kept. Only for
    /// a participant whose capabilities include rollback.
    virtual void saveState();
    virtual void restoreState();
    /// Checkpoints: write this node's files into `directory` (it exists), or read them back
    /// when the run resumes. Only for a participant whose capabilities include checkpoint.
    virtual void writeCheckpoint(const std::string &directory);
    virtual void readCheckpoint(const std::string &directory);
    /// The run ended normally (after the coordinator's Finish): close files, print a summary.
    virtual void finish() {}
};

/// Runs `node` as `participant` (not yet initialized) until the run ends. An exception from a
/// hook, or from the participant's checks of what a hook returned, is reported to the
/// coordinator through Participant::fail — it stops the run and prints "participant '<name>'
/// failed in window <k> ...: reported: <the exception's message>" — and then rethrown.
void runParticipant(Participant &participant, ParticipantNode &node);

} // namespace grainlink::coupling
