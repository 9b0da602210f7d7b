#include "grainlink/coupling/CouplingScheme.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace grainlink::coupling {

namespace {

/// `items` (states or wrenches) rearranged into the scheme's body order: one per body.
template <typename T>
std::vector<T> inBodyOrder(const std::vector<T> &items, const std::vector<std::string> &bodies,
                           const std::string &what) {
    std::vector<T> out(bodies.size());
    std::vector<bool> seen(bodies.size(), false);
    for (const auto &item : items) {
        const auto b = static_cast<std::size_t>(std::find(bodies.begin(), bodies.end(), item.body) -
                                                bodies.begin());
        if (b == bodies.size())
            throw CouplingError(what + " for unknown body '" + item.body + "'");
        if (seen[b])
            throw CouplingError("two " + what + "s for body '" + item.body + "'");
        seen[b] = true;
        out[b] = item;
    }
    for (std::size_t b = 0; b < bodies.size(); ++b)
        if (!seen[b])
            throw CouplingError("no " + what + " for body '" + bodies[b] + "'");
    return out;
}

} // namespace

Eigen::VectorXd stack(const std::vector<Wrench> &wrenches) {
    Eigen::VectorXd out(6 * wrenches.size());
    for (std::size_t b = 0; b < wrenches.size(); ++b) {
        out.segment<3>(6 * b) = wrenches[b].force_N;
        out.segment<3>(6 * b + 3) = wrenches[b].torque_N_m;
    }
    return out;
}

void unstack(const Eigen::VectorXd &values, std::vector<Wrench> &wrenches) {
    for (std::size_t b = 0; b < wrenches.size(); ++b) {
        wrenches[b].force_N = values.segment<3>(6 * b);
        wrenches[b].torque_N_m = values.segment<3>(6 * b + 3);
        wrenches[b].triangle_forces_N.clear(); // a blend of two iterates has no per-triangle loads
    }
}

CouplingScheme::CouplingScheme(const SchemeSettings &settings, std::vector<BodyState> initial)
    : settings_(settings), states_(std::move(initial)) {
    if (settings_.kind == SchemeKind::Implicit) // explicit schemes never iterate
        acceleration_ = makeAcceleration(settings.acceleration);
    for (const auto &s : states_) {
        bodies_.push_back(s.body);
        wrenches_.push_back(Wrench{s.body, Vec3::Zero(), Vec3::Zero(), {}});
    }
    if (settings_.kind == SchemeKind::Implicit && settings_.max_iterations == 0)
        throw CouplingError("implicit coupling needs max_iterations >= 1");
}

void CouplingScheme::restore(std::vector<BodyState> states, std::vector<Wrench> wrenches) {
    states_ = ordered(states);
    wrenches_ = ordered(wrenches);
    stage_ = Stage::Accepted;
}

void CouplingScheme::beginWindow(double window_s) {
    if (stage_ != Stage::Accepted)
        throw CouplingError("beginWindow() while the current window is not accepted yet");
    iteration_ = 0;
    residual_ = 0.0;
    multibody_done_ = soil_done_ = false;
    applied_ = wrenches_;
    if (acceleration_)
        acceleration_->beginWindow();
    switch (settings_.kind) {
    case SchemeKind::ExplicitSerial:
    case SchemeKind::Implicit:
        stage_ = Stage::Multibody;
        break;
    case SchemeKind::ExplicitParallel:
        stage_ = Stage::Both;
        soil_inputs_ = extrapolated(window_s);
        break;
    }
}

std::vector<Task> CouplingScheme::tasks() const {
    const bool implicit = settings_.kind == SchemeKind::Implicit;
    Task multibody;
    multibody.role = Role::Multibody;
    multibody.iteration = iteration_;
    multibody.save_state = implicit && iteration_ == 0;
    multibody.restore_state = implicit && iteration_ > 0;
    multibody.wrenches = applied_;
    Task soil = multibody;
    soil.role = Role::Soil;
    soil.wrenches.clear();
    soil.start_states = states_;
    soil.end_states = soil_inputs_;
    switch (stage_) {
    case Stage::Multibody:
        return {multibody};
    case Stage::Soil:
        return {soil};
    case Stage::Both: {
        std::vector<Task> out;
        if (!multibody_done_)
            out.push_back(multibody);
        if (!soil_done_)
            out.push_back(soil);
        return out;
    }
    case Stage::Accepted:
        break;
    }
    return {};
}

void CouplingScheme::completeMultibody(const std::vector<BodyState> &end_states) {
    if (!(stage_ == Stage::Multibody || (stage_ == Stage::Both && !multibody_done_)))
        throw CouplingError("multibody result arrived when none was expected");
    end_states_ = ordered(end_states);
    if (stage_ == Stage::Multibody) {
        soil_inputs_ = end_states_;
        stage_ = Stage::Soil;
        return;
    }
    multibody_done_ = true;
    if (soil_done_)
        finishIteration(soil_result_);
}

void CouplingScheme::completeSoil(const std::vector<Wrench> &wrenches) {
    if (!(stage_ == Stage::Soil || (stage_ == Stage::Both && !soil_done_)))
        throw CouplingError("soil result arrived when none was expected");
    soil_result_ = ordered(wrenches);
    if (stage_ == Stage::Both) {
        soil_done_ = true;
        if (!multibody_done_)
            return;
    }
    finishIteration(soil_result_);
}

void CouplingScheme::finishIteration(const std::vector<Wrench> &soil_wrenches) {
    if (settings_.kind != SchemeKind::Implicit) {
        states_ = end_states_;
        wrenches_ = soil_wrenches;
        stage_ = Stage::Accepted;
        return;
    }
    // Fixed point on the wrenches: x = what the multibody side applied, h = what the soil returned.
    const Eigen::VectorXd x = stack(applied_);
    const Eigen::VectorXd h = stack(soil_wrenches);
    const double difference = (h - x).norm();
    const double scale = h.norm();
    residual_ = scale > 0.0 ? difference / scale : difference;
    if (difference <= settings_.relative_tolerance * scale + settings_.absolute_tolerance) {
        states_ = end_states_;
        wrenches_ = soil_wrenches;
        stage_ = Stage::Accepted;
        return;
    }
    if (iteration_ + 1 >= settings_.max_iterations) {
        std::ostringstream os;
        os << "implicit coupling did not converge in " << settings_.max_iterations
           << " iterations: relative residual " << residual_ << " > tolerance "
           << settings_.relative_tolerance;
        throw CouplingError(os.str());
    }
    unstack(acceleration_->next(x, h), applied_);
    ++iteration_;
    stage_ = Stage::Multibody;
}

std::vector<BodyState> CouplingScheme::ordered(const std::vector<BodyState> &states) const {
    return inBodyOrder(states, bodies_, "state");
}

std::vector<Wrench> CouplingScheme::ordered(const std::vector<Wrench> &wrenches) const {
    return inBodyOrder(wrenches, bodies_, "wrench");
}

std::vector<BodyState> CouplingScheme::extrapolated(double window_s) const {
    // Constant velocities over the window: x + v H, and the rotation by ω H (world frame).
    std::vector<BodyState> out = states_;
    for (auto &s : out) {
        s.position_m += s.linear_velocity_m_s * window_s;
        const Vec3 rotation = s.angular_velocity_rad_s * window_s;
        const double angle = rotation.norm();
        if (angle > 0.0)
            s.orientation =
                (Quat(Eigen::AngleAxisd(angle, rotation / angle)) * s.orientation).normalized();
    }
    return out;
}

} // namespace grainlink::coupling
