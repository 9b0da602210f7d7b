#include "grainlink/coupling/CouplingScheme.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace grainlink::coupling {

namespace {

/// `items` (states or wrenches) rearranged into the scheme's body order, one per body, into `out`
/// (its storage is reused; on an error it holds a partial result). `seen` is scratch space.
template <typename T>
void inBodyOrder(const std::vector<T> &items, const std::vector<std::string> &bodies,
                 const std::string &what, std::vector<T> &out, std::vector<char> &seen) {
    out.resize(bodies.size());
    seen.assign(bodies.size(), 0);
    for (std::size_t i = 0; i < items.size(); ++i) {
        const auto &item = items[i];
        // Items usually come in body order already: try that place first.
        const auto b =
            i < bodies.size() && bodies[i] == item.body
                ? i
                : static_cast<std::size_t>(std::find(bodies.begin(), bodies.end(), item.body) -
                                           bodies.begin());
        if (b == bodies.size())
            throw CouplingError(what + " for unknown body '" + item.body + "'");
        if (seen[b])
            throw CouplingError("two " + what + "s for body '" + item.body + "'");
        seen[b] = 1;
        out[b] = item;
    }
    for (std::size_t b = 0; b < bodies.size(); ++b)
        if (!seen[b])
            throw CouplingError("no " + what + " for body '" + bodies[b] + "'");
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
    std::vector<BodyState> ordered_states;
    std::vector<Wrench> ordered_wrenches;
    order(states, ordered_states);
    order(wrenches, ordered_wrenches);
    states_ = std::move(ordered_states);
    wrenches_ = std::move(ordered_wrenches);
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
    std::vector<Task> out;
    tasks(out);
    return out;
}

void CouplingScheme::tasks(std::vector<Task> &out) const {
    const bool implicit = settings_.kind == SchemeKind::Implicit;
    const bool multibody =
        stage_ == Stage::Multibody || (stage_ == Stage::Both && !multibody_done_);
    const bool soil = stage_ == Stage::Soil || (stage_ == Stage::Both && !soil_done_);
    out.resize(std::size_t(multibody) + std::size_t(soil));
    // Assigned field by field, so a reused `out` keeps its vectors' storage.
    auto set = [&](Task &task, Role role) {
        task.role = role;
        task.iteration = iteration_;
        task.save_state = implicit && iteration_ == 0;
        task.restore_state = implicit && iteration_ > 0;
        if (role == Role::Multibody) {
            task.wrenches = applied_;
            task.start_states.clear();
            task.end_states.clear();
        } else {
            task.wrenches.clear();
            task.start_states = states_;
            task.end_states = soil_inputs_;
        }
    };
    if (multibody)
        set(out.front(), Role::Multibody);
    if (soil)
        set(out.back(), Role::Soil);
}

void CouplingScheme::completeMultibody(const std::vector<BodyState> &end_states) {
    if (!(stage_ == Stage::Multibody || (stage_ == Stage::Both && !multibody_done_)))
        throw CouplingError("multibody result arrived when none was expected");
    order(end_states, scratch_states_); // end_states_ stays as it was if this throws
    std::swap(end_states_, scratch_states_);
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
    order(wrenches, scratch_wrenches_);
    std::swap(soil_result_, scratch_wrenches_);
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

void CouplingScheme::order(const std::vector<BodyState> &states, std::vector<BodyState> &out) {
    inBodyOrder(states, bodies_, "state", out, seen_);
}

void CouplingScheme::order(const std::vector<Wrench> &wrenches, std::vector<Wrench> &out) {
    inBodyOrder(wrenches, bodies_, "wrench", out, seen_);
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
