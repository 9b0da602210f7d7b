#include "grainlink/dem/Walls.hpp"

namespace grainlink::dem {

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
    const Mat3 rotation = state_.orientation.toRotationMatrix();
    world_vertices_.resize(mesh_.vertices_m.size());
    for (std::size_t k = 0; k < world_vertices_.size(); ++k)
        world_vertices_[k] = state_.position_m + rotation * mesh_.vertices_m[k];
}

void MeshBody::resetAccumulatedImpulse() {
    impulse_N_s.setZero();
    angular_impulse_N_m_s.setZero();
    accumulated_time_s = 0.0;
}

} // namespace grainlink::dem
