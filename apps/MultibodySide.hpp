#pragma once
// What the multibody-side participants share: a model's coupled bodies as handshake
// descriptions and its states on the wire.
#include "Series.hpp"
#include "grainlink/coupling/Types.hpp"
#include "grainlink/mbs/MultibodyModel.hpp"

#include <fstream>
#include <optional>
#include <string>
#include <vector>

namespace grainlink::apps {

inline coupling::BodyDescription describe(const mbs::CoupledBody &body) {
    coupling::BodyDescription d;
    d.name = body.name;
    d.mass.mass_kg = body.mass_kg;
    d.mass.inertia_diagonal_kg_m2 = body.inertia_diagonal_kg_m2;
    if (body.mesh) {
        coupling::MeshGeometry m;
        m.vertices_m = body.mesh->vertices_m;
        for (const auto &t : body.mesh->triangles)
            m.triangles.insert(m.triangles.end(),
                               {std::uint32_t(t[0]), std::uint32_t(t[1]), std::uint32_t(t[2])});
        d.geometry = m;
        return d;
    }
    coupling::WheelGeometry w;
    w.diameter_m = body.wheel.diameter_m;
    w.width_m = body.wheel.width_m;
    w.rim_thickness_m = body.wheel.rim_thickness_m;
    w.grouser_count = body.wheel.grouser_count;
    w.grouser_height_m = body.wheel.grouser_height_m;
    w.grouser_thickness_m = body.wheel.grouser_thickness_m;
    w.grouser_shape =
        body.wheel.chevron ? coupling::GrouserShape::Chevron : coupling::GrouserShape::Straight;
    w.chevron_angle_deg = body.wheel.chevron_angle_deg;
    w.closed_sides = body.wheel.closed_sides;
    d.geometry = w;
    return d;
}

inline coupling::BodyState toCoupling(const std::string &name, const mbs::RigidState &s) {
    coupling::BodyState out;
    out.body = name;
    out.position_m = s.position_m;
    out.orientation = s.orientation;
    out.linear_velocity_m_s = s.linear_velocity_m_s;
    out.angular_velocity_rad_s = s.angular_velocity_rad_s;
    return out;
}

} // namespace grainlink::apps
