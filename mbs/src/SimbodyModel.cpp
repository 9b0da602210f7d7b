#include "grainlink/mbs/SimbodyModel.hpp"

#include "CheckpointText.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace grainlink::mbs {

SimbodyModel::SimbodyModel(const Vec3 &gravity_m_s2, const IntegratorSettings &integrator)
    : matter_(system_), forces_(system_), discrete_(forces_, matter_),
      integrator_settings_(integrator) {
    SimTK::Force::UniformGravity(forces_, matter_, toSimTK(gravity_m_s2));
}

void SimbodyModel::addCoupled(const BodyDescription &body, const SimTK::MobilizedBody &mobod) {
    coupled_.push_back(body);
    coupled_bodies_.push_back(mobod);
    applied_.emplace_back();
}

void SimbodyModel::finishBuilding() {
    system_.realizeTopology();
    state_ = system_.getDefaultState();
    system_.realize(state_, SimTK::Stage::Position);
    saved_ = state_;
    saved_applied_ = applied_;
}

void SimbodyModel::applyWrenches(const std::vector<Wrench> &wrenches) {
    if (wrenches.size() != coupled_.size())
        throw ModelError("applyWrenches: " + std::to_string(wrenches.size()) + " wrenches for " +
                         std::to_string(coupled_.size()) + " coupled bodies");
    for (std::size_t b = 0; b < wrenches.size(); ++b) {
        // Spatial force = (torque about the body origin, force), both in Ground.
        discrete_.setOneBodyForce(
            state_, coupled_bodies_[b],
            SimTK::SpatialVec(toSimTK(wrenches[b].torque_N_m), toSimTK(wrenches[b].force_N)));
    }
    applied_ = wrenches;
}

std::vector<double> SimbodyModel::advanceTo(double time_s) {
    std::vector<double> work(coupled_.size(), 0.0);
    if (time_s <= state_.getTime())
        return work;
    // A fresh integrator per call: the State changed outside it (wrenches, controllers), and
    // starting from the State alone keeps save/restore and checkpoints exact.
    SimTK::RungeKuttaMersonIntegrator integrator(system_);
    integrator.setAccuracy(integrator_settings_.accuracy);
    integrator.setMaximumStepSize(integrator_settings_.max_step_s);
    integrator.setReturnEveryInternalStep(true);
    integrator.setFinalTime(time_s);
    integrator.initialize(state_);
    // Power of the constant wrench, F·v + T·ω, integrated by the trapezoid rule per step.
    auto power = [&](const SimTK::State &s, std::size_t b) {
        const auto &mobod = coupled_bodies_[b];
        const Vec3 v = fromSimTK(mobod.getBodyOriginVelocity(s));
        const Vec3 w = fromSimTK(mobod.getBodyAngularVelocity(s));
        return applied_[b].force_N.dot(v) + applied_[b].torque_N_m.dot(w);
    };
    std::vector<double> previous(coupled_.size());
    double t_previous = integrator.getTime();
    for (std::size_t b = 0; b < coupled_.size(); ++b)
        previous[b] = power(integrator.getState(), b);
    while (integrator.getTime() < time_s) {
        const auto status = integrator.stepTo(time_s);
        if (status == SimTK::Integrator::EndOfSimulation || integrator.isSimulationOver())
            if (integrator.getTerminationReason() != SimTK::Integrator::ReachedFinalTime)
                throw ModelError("Simbody integration stopped at t = " +
                                 std::to_string(integrator.getTime()) + " s: " +
                                 SimTK::Integrator::getTerminationReasonString(
                                     integrator.getTerminationReason()));
        const double t = integrator.getTime();
        system_.realize(integrator.getState(), SimTK::Stage::Velocity);
        for (std::size_t b = 0; b < coupled_.size(); ++b) {
            const double p = power(integrator.getState(), b);
            work[b] += 0.5 * (p + previous[b]) * (t - t_previous);
            previous[b] = p;
        }
        t_previous = t;
    }
    state_ = integrator.getState();
    return work;
}

std::vector<RigidState> SimbodyModel::bodyStates() const {
    system_.realize(state_, SimTK::Stage::Velocity);
    std::vector<RigidState> out;
    for (const auto &mobod : coupled_bodies_) {
        RigidState s;
        const SimTK::Transform &x = mobod.getBodyTransform(state_);
        s.position_m = fromSimTK(x.p());
        const SimTK::Quaternion q = x.R().convertRotationToQuaternion();
        s.orientation = Quat(q[0], q[1], q[2], q[3]).normalized();
        s.linear_velocity_m_s = fromSimTK(mobod.getBodyOriginVelocity(state_));
        s.angular_velocity_rad_s = fromSimTK(mobod.getBodyAngularVelocity(state_));
        out.push_back(s);
    }
    return out;
}

void SimbodyModel::restoreState() {
    state_ = saved_;
    applied_ = saved_applied_;
}

void SimbodyModel::writeCheckpoint(const std::string &path) const {
    // The continuous and discrete state as text with round-trip precision.
    std::ostringstream os;
    os.precision(17);
    os << "t " << state_.getTime() << "\nq";
    for (int i = 0; i < state_.getNQ(); ++i)
        os << ' ' << state_.getQ()[i];
    os << "\nu";
    for (int i = 0; i < state_.getNU(); ++i)
        os << ' ' << state_.getU()[i];
    os << "\nwrenches";
    for (const auto &w : applied_)
        for (int k = 0; k < 3; ++k)
            os << ' ' << w.force_N[k] << ' ' << w.torque_N_m[k];
    os << '\n' << checkpointExtras() << '\n';
    std::ofstream out(path);
    out << os.str();
    if (!out)
        throw ModelError("cannot write checkpoint " + path);
}

namespace {

/// One line of a multibody checkpoint: its tag, then exactly `count` finite numbers.
std::vector<double> checkpointLine(std::istream &in, const std::string &path, int number,
                                   const std::string &tag, std::size_t count,
                                   const std::string &what) {
    return checkpointNumbers(in, path, number, "multibody", tag, count, what);
}

} // namespace

void SimbodyModel::readCheckpoint(const std::string &path) {
    std::ifstream in(path);
    if (!in)
        throw ModelError("cannot open multibody checkpoint " + path);
    SimTK::State s = state_;
    s.setTime(checkpointLine(in, path, 1, "t", 1, "the time [s]")[0]);
    const auto q =
        checkpointLine(in, path, 2, "q", std::size_t(s.getNQ()), "the generalized coordinates");
    for (int i = 0; i < s.getNQ(); ++i)
        s.updQ()[i] = q[std::size_t(i)];
    const auto u =
        checkpointLine(in, path, 3, "u", std::size_t(s.getNU()), "the generalized speeds");
    for (int i = 0; i < s.getNU(); ++i)
        s.updU()[i] = u[std::size_t(i)];
    const auto w = checkpointLine(in, path, 4, "wrenches", 6 * coupled_.size(),
                                  "the force [N] and torque [N m] on each coupled body");
    std::vector<Wrench> wrenches(coupled_.size());
    for (std::size_t b = 0; b < wrenches.size(); ++b)
        for (int k = 0; k < 3; ++k) {
            wrenches[b].force_N[k] = w[6 * b + 2 * std::size_t(k)];
            wrenches[b].torque_N_m[k] = w[6 * b + 2 * std::size_t(k) + 1];
        }
    std::string extras;
    if (!std::getline(in, extras))
        throw ModelError(path + ":5: missing the model's own line: truncated multibody checkpoint");
    state_ = s;
    applyWrenches(wrenches);
    try {
        readCheckpointExtras(extras);
    } catch (const ModelError &e) {
        throw ModelError(path + ":5: " + e.what());
    }
    system_.realize(state_, SimTK::Stage::Velocity);
}

} // namespace grainlink::mbs
