#pragma once
// One side of the two-mass example as a coupling participant: the whole participant lifecycle
// in about forty lines, the template for plugging in your own model (docs/protocol.md).
#include "TwoMassModel.hpp"
#include "grainlink/coupling/Participant.hpp"

#include <csignal>
#include <filesystem>
#include <functional>
#include <thread>

namespace grainlink::examples {

/// Test hooks: misbehave at a given window (the coordinator's fault tests), watch the windows,
/// or ask for another macro step (adaptive stepping).
struct SideHooks {
    long die_at_window = -1;      ///< the process kills itself (SIGKILL) when this window opens
    long hang_at_window = -1;     ///< the model never returns from this window (heartbeats go on)
    long freeze_at_window = -1;   ///< the whole process stops (SIGSTOP), heartbeats too
    long fail_at_window = -1;     ///< reports a failure to the coordinator and gives up
    long complete_at_window = -1; ///< declares the experiment complete (run_complete) here
    std::function<void(std::uint64_t window)> on_window;  ///< called as each window opens
    std::function<double(double start_s)> suggest_step_s; ///< hint sent with each window
};

inline coupling::ParticipantConfig twoMassConfig(coupling::Role side, const std::string &name,
                                                 const std::string &endpoint,
                                                 const TwoMassParameters &p = {}) {
    coupling::ParticipantConfig c;
    c.name = name;
    c.role = side;
    c.endpoint = endpoint;
    c.capabilities.rollback = true;
    c.capabilities.checkpoint = true;
    if (side == coupling::Role::Multibody) {
        MassOneSide one(p);
        c.provides = {one.body()};
        c.initial_states = {one.state()};
    } else {
        c.consumes = {"mass1"};
    }
    return c;
}

/// Runs one side until the coordinator ends the run; returns mass 1's (or mass 2's) final x.
inline double runTwoMassSide(coupling::Participant &participant, const TwoMassParameters &p = {},
                             const SideHooks &hooks = {}) {
    using coupling::Command;
    MassOneSide one(p);
    MassTwoSide two(p);
    const auto &run = participant.initialize();
    const bool is_one = participant.role() == coupling::Role::Multibody;
    const std::string file = participant.name() + ".state";
    if (run.restore)
        is_one ? one.read(run.restore->checkpoint_directory + "/" + file)
               : two.read(run.restore->checkpoint_directory + "/" + file);
    for (;;) {
        switch (participant.waitForCommand()) {
        case Command::WriteCheckpoint:
            is_one ? one.write(participant.checkpointDirectory() + "/" + file)
                   : two.write(participant.checkpointDirectory() + "/" + file);
            participant.checkpointWritten();
            break;
        case Command::Advance: {
            const auto &in = participant.inputs();
            const long window = static_cast<long>(in.window);
            if (hooks.on_window)
                hooks.on_window(in.window);
            if (window == hooks.die_at_window)
                std::raise(SIGKILL);
            if (window == hooks.freeze_at_window)
                std::raise(SIGSTOP);
            while (window == hooks.hang_at_window)
                std::this_thread::sleep_for(std::chrono::seconds(1));
            if (window == hooks.fail_at_window) {
                participant.fail("simulated failure of the model");
                throw coupling::CouplingError("simulated failure at window " +
                                              std::to_string(window));
            }
            coupling::WindowOutputs out;
            out.run_complete = window == hooks.complete_at_window;
            if (hooks.suggest_step_s)
                out.suggested_macro_step_s = hooks.suggest_step_s(in.start_s);
            if (is_one) {
                if (in.restore_state)
                    one.restore();
                if (in.save_state)
                    one.save();
                const double work = one.advance(in.duration_s, in.wrenches.at(0).force_N.x());
                out.states = {one.state()};
                out.work = {{"mass1", work}};
            } else {
                if (in.restore_state)
                    two.restore();
                if (in.save_state)
                    two.save();
                const auto &a = in.start_states.at(0), &b = in.end_states.at(0);
                const auto r =
                    two.advance(in.duration_s, a.position_m.x(), a.linear_velocity_m_s.x(),
                                b.position_m.x(), b.linear_velocity_m_s.x());
                coupling::Wrench w;
                w.body = "mass1";
                w.force_N = coupling::Vec3(r.force_on_mass1_N, 0, 0);
                out.wrenches = {w};
                out.work = {{"mass1", r.work_on_mass1_J}};
            }
            participant.writeOutputs(std::move(out));
            participant.advance();
            break;
        }
        case Command::Finish:
            participant.finalize();
            return is_one ? one.x() : two.x();
        }
    }
}

} // namespace grainlink::examples
