#include "grainlink/dem/Walls.hpp"

#include <algorithm>
#include <cmath>

namespace grainlink::dem {

EndWalls endWallsAlongX(const std::vector<PlaneWall> &planes) {
    EndWalls walls;
    for (std::size_t p = 0; p < planes.size(); ++p) {
        const double n_x = planes[p].normal.normalized().x();
        if (n_x < -0.5)
            walls.ahead.push_back(int(p));
        else if (n_x > 0.5)
            walls.behind.push_back(int(p));
    }
    return walls;
}

double endWallShare(double ahead_rise_N, double behind_rise_N, double push_N, double load_N) {
    return (push_N >= 0.0 ? ahead_rise_N : behind_rise_N) /
           std::max(std::abs(push_N), 0.1 * load_N);
}

MeshBody::MeshBody(std::string name, TriangleMesh mesh_body_frame, RigidBodyState initial)
    : name_(std::move(name)), mesh_(std::move(mesh_body_frame)) {
    mesh_.validate("mesh of body '" + name_ + "'");
    bounding_radius_ = mesh_.boundingRadius();
    triangle_force_N.assign(mesh_.triangleCount(), Vec3::Zero());
    setState(initial);
}

void MeshBody::setState(const RigidBodyState &state) {
    state_ = state;
    state_.orientation.normalize();
    placeVertices();
}

void MeshBody::restoreState(const RigidBodyState &saved) {
    state_ = saved;
    placeVertices();
}

void MeshBody::placeVertices() {
    worldVerticesAt(state_, world_vertices_);
}

void MeshBody::worldVerticesAt(const RigidBodyState &state, std::vector<Vec3> &out) const {
    const Mat3 rotation = state.orientation.toRotationMatrix();
    out.resize(mesh_.vertices_m.size());
    for (std::size_t k = 0; k < out.size(); ++k)
        out[k] = state.position_m + rotation * mesh_.vertices_m[k];
}

void MeshBody::setLoads(const BodyLoads &loads) {
    force_N = loads.force_N;
    torque_N_m = loads.torque_N_m;
    impulse_N_s = loads.impulse_N_s;
    angular_impulse_N_m_s = loads.angular_impulse_N_m_s;
    accumulated_time_s = loads.accumulated_time_s;
}

void MeshBody::resetAccumulatedImpulse() {
    impulse_N_s.setZero();
    angular_impulse_N_m_s.setZero();
    accumulated_time_s = 0.0;
}

} // namespace grainlink::dem
