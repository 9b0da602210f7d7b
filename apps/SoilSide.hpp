#pragma once
// What the soil-side participants (the DEM soil, the rigid floor) share: the mesh of a coupled
// body from its handshake description, and the body's motion through a window as the DEM's
// dem::WindowMotion (position and velocity agree with the received states at both ends).
#include "Nodes.hpp"
#include "grainlink/coupling/Participant.hpp"
#include "grainlink/coupling/Types.hpp"
#include "grainlink/dem/Walls.hpp"
#include "grainlink/dem/WheelMesh.hpp"

#include "grainlink/config/ConfigNode.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

namespace grainlink::apps {

/// A soil-side participant of the scenario `root` consuming the node's `--bodies`.
inline coupling::ParticipantConfig soilParticipantConfig(const NodeOptions &options,
                                                         const config::ConfigNode &root) {
    coupling::ParticipantConfig config;
    config.name = options.name;
    config.handshake_timeout_s = handshakeTimeout(root);
    config.role = coupling::Role::Soil;
    config.endpoint = options.endpoint;
    config.consumes = options.bodies;
    if (!options.keys_directory.empty())
        config.curve = coupling::loadClientKeys(options.keys_directory, options.name);
    return config;
}

/// The triangle mesh of a body as its provider described it (parametric wheel or mesh).
inline dem::TriangleMesh meshOf(const coupling::BodyDescription &body, bool half = false) {
    if (const auto *w = std::get_if<coupling::WheelGeometry>(&body.geometry)) {
        dem::WheelMeshSpec spec;
        spec.diameter_m = w->diameter_m;
        spec.width_m = w->width_m;
        spec.grouser_count = w->grouser_count;
        spec.grouser_height_m = w->grouser_height_m;
        spec.grouser_thickness_m = w->grouser_thickness_m;
        spec.chevron = w->grouser_shape == coupling::GrouserShape::Chevron;
        spec.chevron_angle_deg = w->chevron_angle_deg;
        spec.closed_sides = w->closed_sides;
        spec.half = half;
        return dem::makeWheel(spec);
    }
    if (half)
        throw coupling::CouplingError("body '" + body.name + "': a mirror-symmetric half model "
                                      "needs parametric wheels, not a mesh");
    if (const auto *m = std::get_if<coupling::MeshGeometry>(&body.geometry)) {
        dem::TriangleMesh mesh;
        mesh.vertices_m = m->vertices_m;
        for (std::size_t t = 0; t + 2 < m->triangles.size(); t += 3)
            mesh.triangles.push_back(
                {int(m->triangles[t]), int(m->triangles[t + 1]), int(m->triangles[t + 2])});
        return mesh;
    }
    throw coupling::CouplingError("body '" + body.name + "' has no geometry the soil can touch");
}

/// A coupled body's state as the DEM's rigid-body state.
inline dem::RigidBodyState demState(const coupling::BodyState &s) {
    dem::RigidBodyState r;
    r.position_m = s.position_m;
    r.orientation = s.orientation;
    r.linear_velocity_m_s = s.linear_velocity_m_s;
    r.angular_velocity_rad_s = s.angular_velocity_rad_s;
    return r;
}

/// Body b's motion through the window `in` (dem::WindowMotion, docs/physics.md §7.2), on a
/// clock `offset_s` ahead of the coupling's.
inline dem::WindowMotion windowMotion(const coupling::WindowInputs &in, std::size_t b,
                                      double offset_s = 0.0) {
    return {in.start_s + offset_s, in.duration_s, demState(in.start_states.at(b)),
            demState(in.end_states.at(b))};
}

/// Mirror symmetry (DIGEST §5): the soil simulates only the half of the bin at y >= plane, with
/// a frictionless wall on the plane, and each wheel's y >= 0 half; the other half is the mirror
/// image. The image's wrench about a body origin on the plane is (Fx, -Fy, Fz), (-Tx, Ty, -Tz),
/// so the full wheel's wrench is twice the half's x and z force and y torque, the rest zero.
struct MirrorSymmetry {
    double plane_y_m = 0.0;

    static std::optional<MirrorSymmetry> parse(const config::ConfigNode &root) {
        const auto node = root.optional("mirror");
        if (!node)
            return std::nullopt;
        MirrorSymmetry m;
        m.plane_y_m = (*node)["plane_y_m"].number();
        node->finish();
        return m;
    }
    /// A wheel must roll in the plane: centre on it, axis across it.
    void check(const coupling::BodyState &s) const {
        const coupling::Vec3 axis = s.orientation * coupling::Vec3::UnitY();
        if (std::abs(s.position_m.y() - plane_y_m) > 1e-9 || std::abs(axis.y()) < 1.0 - 1e-9)
            throw coupling::CouplingError(
                "body '" + s.body + "' is not on the mirror plane y = " + std::to_string(plane_y_m) +
                " m with its axis across it (centre at y = " + std::to_string(s.position_m.y()) +
                " m): start it there or remove `mirror:`");
    }
    static void complete(coupling::Vec3 &force, coupling::Vec3 &torque) {
        force = coupling::Vec3(2.0 * force.x(), 0.0, 2.0 * force.z());
        torque = coupling::Vec3(0.0, 2.0 * torque.y(), 0.0);
    }
};

} // namespace grainlink::apps
