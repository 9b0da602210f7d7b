#pragma once
// A body that touches the soil: its name, mass properties and geometry. Multibody models
// describe their coupled bodies with it (mbs/MultibodyModel.hpp), the handshake carries it
// unchanged (coupling/Types.hpp), and the soil builds the mesh its grains touch from it.
#include "grainlink/body/WheelShape.hpp"

#include <Eigen/Core>

#include <array>
#include <string>
#include <variant>
#include <vector>

namespace grainlink::body {

using Vec3 = Eigen::Vector3d;

struct MassProperties {
    double mass_kg = 0.0;                           ///< [kg]
    Vec3 center_of_mass_m = Vec3::Zero();           ///< [m] in the body frame
    Vec3 inertia_diagonal_kg_m2 = Vec3::Zero();     ///< [kg m^2] about the centre of mass
    Vec3 inertia_off_diagonal_kg_m2 = Vec3::Zero(); ///< [kg m^2] (xy, xz, yz)
};

/// A closed triangle mesh in the body frame (the mole's hull, a user's STL).
struct MeshShape {
    std::vector<Vec3> vertices_m;              ///< [m] body frame
    std::vector<std::array<int, 3>> triangles; ///< vertex indices, counter-clockwise from outside
};

struct BodyDescription {
    std::string name;
    MassProperties mass;
    /// What the grains touch; none: a body the soil cannot load (the two-mass example's mass).
    std::variant<std::monostate, MeshShape, WheelShape> geometry;
};

} // namespace grainlink::body
