#pragma once
// Shared machinery of the Simbody models: the system, gravity, the soil wrenches held in
// Force::DiscreteForces (so they live in the State and roll back with it), integration to a
// time with the work of those wrenches, save/restore and checkpoints of the whole State.
#include "grainlink/mbs/MultibodyModel.hpp"

#include <Simbody.h>

#include <memory>

namespace grainlink::mbs {

struct IntegratorSettings {
    double accuracy = 1e-8;   ///< Simbody's relative accuracy (RK-Merson, error controlled)
    double max_step_s = 1e-3; ///< [s] cap on the internal step
};

class SimbodyModel : public MultibodyModel {
public:
    std::vector<BodyDescription> coupledBodies() const override { return coupled_; }
    void applyWrenches(const std::vector<Wrench> &wrenches) override;
    std::vector<double> advanceTo(double time_s) override;
    double time() const override { return state_.getTime(); }
    std::vector<RigidState> bodyStates() const override;

    void saveState() override { saved_ = state_; }
    void restoreState() override;
    void writeCheckpoint(const std::string &path) const override;
    void readCheckpoint(const std::string &path) override;

protected:
    SimbodyModel(const Vec3 &gravity_m_s2, const IntegratorSettings &integrator);
    /// Registers a body that touches the soil (in the order wrenches and states use).
    void addCoupled(const BodyDescription &body, const SimTK::MobilizedBody &mobod);
    /// Call once every body, force and constraint exists: builds the initial State.
    void finishBuilding();
    /// A derived model's own state beyond Q and U (its controller), one line, for checkpoints.
    virtual std::string checkpointExtras() const { return "-"; }
    virtual void readCheckpointExtras(const std::string &) {}
    /// The State, for derived models that change it between windows (their controllers).
    SimTK::State &state() { return state_; }
    const SimTK::State &state() const { return state_; }

    SimTK::MultibodySystem system_;
    SimTK::SimbodyMatterSubsystem matter_;
    SimTK::GeneralForceSubsystem forces_;
    SimTK::Force::DiscreteForces discrete_;

private:
    IntegratorSettings integrator_settings_;
    std::vector<BodyDescription> coupled_;
    std::vector<SimTK::MobilizedBody> coupled_bodies_;
    std::vector<Wrench> applied_;
    SimTK::State state_, saved_;
    std::vector<Wrench> saved_applied_;
};

/// Simbody's and Eigen's vectors and rotations.
inline SimTK::Vec3 toSimTK(const Vec3 &v) {
    return SimTK::Vec3(v.x(), v.y(), v.z());
}
inline Vec3 fromSimTK(const SimTK::Vec3 &v) {
    return Vec3(v[0], v[1], v[2]);
}

} // namespace grainlink::mbs
