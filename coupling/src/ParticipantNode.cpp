#include "grainlink/coupling/ParticipantNode.hpp"

namespace grainlink::coupling {

namespace {

[[noreturn]] void noRollback() {
    throw CouplingError("this node cannot save and restore its state (implicit coupling): "
                        "do not declare the rollback capability");
}

} // namespace

void ParticipantNode::saveState() {
    noRollback();
}

void ParticipantNode::restoreState() {
    noRollback();
}

void ParticipantNode::writeCheckpoint(const std::string &) {
    throw CouplingError("this node does not write checkpoints: do not declare the checkpoint "
                        "capability, or remove coupling.checkpoint_every_windows");
}

void ParticipantNode::readCheckpoint(const std::string &) {
    throw CouplingError("this node cannot resume from a checkpoint");
}

void runParticipant(Participant &participant, ParticipantNode &node) {
    try {
        const RunInfo &run = participant.initialize();
        node.start(run);
        if (run.restore)
            node.readCheckpoint(run.restore->checkpoint_directory);
        for (;;) {
            switch (participant.waitForCommand()) {
            case Command::WriteCheckpoint:
                node.writeCheckpoint(participant.checkpointDirectory());
                participant.checkpointWritten();
                break;
            case Command::Advance: {
                const WindowInputs &in = participant.inputs();
                if (in.restore_state)
                    node.restoreState();
                if (in.save_state)
                    node.saveState();
                participant.writeOutputs(node.advance(in));
                participant.advance();
                break;
            }
            case Command::Finish:
                participant.finalize();
                node.finish();
                return;
            }
        }
    } catch (const std::exception &e) {
        participant.fail(e.what()); // nothing is sent when the coordinator stopped the run
        throw;
    }
}

} // namespace grainlink::coupling
