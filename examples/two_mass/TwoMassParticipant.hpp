#pragma once
// One side of the two-mass example as a coupling participant: each side a ParticipantNode whose
// hooks are its model's advance, save/restore and checkpoint I/O, run by coupling's one loop —
// the template for plugging in your own model (docs/protocol.md).
#include "TwoMassModel.hpp"
#include "grainlink/coupling/ParticipantNode.hpp"
#include "grainlink/coupling/WindowLoads.hpp"

#include <csignal>
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <thread>

namespace grainlink::examples {

/// Test hooks: misbehave at a given window (the coordinator's fault tests), watch the windows,
/// or ask for another macro step (adaptive stepping).
struct SideHooks {
    long die_at_window = -1;      ///< the process kills itself (SIGKILL) when this window opens
    long hang_at_window = -1;     ///< the model never returns from this window (heartbeats go on)
    long freeze_at_window = -1;   ///< the whole process stops (SIGSTOP), heartbeats too
    long fail_at_window = -1;     ///< reports a failure to the coordinator and gives up
    long throw_at_window = -1;    ///< the model throws (the loop reports its message)
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

/// What both sides do as a window opens: the test hooks' misbehaviour and hints.
class TwoMassNode : public coupling::ParticipantNode {
public:
    TwoMassNode(coupling::Participant &participant, const SideHooks &hooks)
        : participant_(participant), hooks_(hooks), file_("/" + participant.name() + ".state") {}

    coupling::WindowOutputs advance(const coupling::WindowInputs &in) override {
        const long window = static_cast<long>(in.window);
        if (hooks_.on_window)
            hooks_.on_window(in.window);
        if (window == hooks_.die_at_window)
            std::raise(SIGKILL);
        if (window == hooks_.freeze_at_window)
            std::raise(SIGSTOP);
        while (window == hooks_.hang_at_window)
            std::this_thread::sleep_for(std::chrono::seconds(1));
        if (window == hooks_.fail_at_window) {
            // Its own report; the loop would report the exception's message otherwise.
            participant_.fail("simulated failure of the model");
            throw coupling::CouplingError("simulated failure at window " + std::to_string(window));
        }
        if (window == hooks_.throw_at_window)
            throw std::runtime_error("the model broke down at t = " + std::to_string(in.start_s) +
                                     " s (thrown at window " + std::to_string(window) + ")");
        coupling::WindowOutputs out = advanceModel(in);
        out.run_complete = window == hooks_.complete_at_window;
        if (hooks_.suggest_step_s)
            out.suggested_macro_step_s = hooks_.suggest_step_s(in.start_s);
        return out;
    }
    virtual double x() const = 0;

protected:
    virtual coupling::WindowOutputs advanceModel(const coupling::WindowInputs &in) = 0;
    const std::string &file() const { return file_; } ///< its checkpoint, in the directory

private:
    coupling::Participant &participant_;
    SideHooks hooks_;
    std::string file_;
};

/// A side's node around its model: the state handling both sides share (save/restore for
/// implicit coupling, the checkpoint file, the position the tests read).
template <class Model> class TwoMassSideNode : public TwoMassNode {
public:
    TwoMassSideNode(coupling::Participant &participant, const TwoMassParameters &p,
                    const SideHooks &hooks)
        : TwoMassNode(participant, hooks), model_(p) {}
    void saveState() override { model_.save(); }
    void restoreState() override { model_.restore(); }
    void writeCheckpoint(const std::string &directory) override {
        model_.write(directory + file());
    }
    void readCheckpoint(const std::string &directory) override { model_.read(directory + file()); }
    double x() const override { return model_.x(); }

protected:
    Model model_;
};

/// The multibody side: mass 1 under the coupling force.
class MassOneNode final : public TwoMassSideNode<MassOneSide> {
public:
    using TwoMassSideNode::TwoMassSideNode;

private:
    coupling::WindowOutputs advanceModel(const coupling::WindowInputs &in) override {
        coupling::WindowOutputs out;
        const double work = model_.advance(in.duration_s, in.wrenches.at(0).force_N.x());
        out.states = {model_.state()};
        out.work = {{"mass1", work}};
        return out;
    }
};

/// The soil side: mass 2 and the coupling spring, following mass 1's motion.
class MassTwoNode final : public TwoMassSideNode<MassTwoSide> {
public:
    using TwoMassSideNode::TwoMassSideNode;

private:
    coupling::WindowOutputs advanceModel(const coupling::WindowInputs &in) override {
        const auto &a = in.start_states.at(0), &b = in.end_states.at(0);
        const auto r = model_.advance(in.duration_s, a.position_m.x(), a.linear_velocity_m_s.x(),
                                      b.position_m.x(), b.linear_velocity_m_s.x());
        // The model integrates the impulse with its state (RK4); the loads average it.
        coupling::WindowLoads loads({"mass1"});
        loads.addTotals(0, coupling::Vec3(r.impulse_on_mass1_N_s, 0, 0), coupling::Vec3::Zero(),
                        r.work_on_mass1_J);
        return loads.outputs(in.duration_s);
    }
};

/// Runs one side until the coordinator ends the run; returns mass 1's (or mass 2's) final x.
inline double runTwoMassSide(coupling::Participant &participant, const TwoMassParameters &p = {},
                             const SideHooks &hooks = {}) {
    if (participant.role() == coupling::Role::Multibody) {
        MassOneNode node(participant, p, hooks);
        coupling::runParticipant(participant, node);
        return node.x();
    }
    MassTwoNode node(participant, p, hooks);
    coupling::runParticipant(participant, node);
    return node.x();
}

} // namespace grainlink::examples
