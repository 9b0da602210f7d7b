#pragma once
// The parametric wheel (seed Fig. 8) as the numbers that describe it. The multibody model reads
// it from the scenario, the handshake carries it, and the soil builds its mesh from it
// (dem/WheelMesh.hpp): one value, never copied field by field.
#include "grainlink/config/ConfigNode.hpp"

namespace grainlink::body {

enum class GrouserShape {
    Straight, ///< one bar across the width
    Chevron,  ///< a V of two swept-back arms, apex at the mid-plane y = 0
};

/// The most grousers a wheel or a shear annulus may carry (a bound against typos, far above the
/// seed's 28).
constexpr long long kMaxGrousers = 1000;

/// A wheel about the body y axis, centred on the body origin.
struct WheelShape {
    double diameter_m = 0.25; ///< [m] rim outer diameter, grousers excluded
    double width_m = 0.1;     ///< [m]
    /// [m] radial thickness of an open wheel's rim (its inner surface at radius r - thickness);
    /// 0: a rim of no thickness. A closed wheel is solid to the grains and takes none.
    double rim_thickness_m = 0.0;
    unsigned grouser_count = 0;
    double grouser_height_m = 0.0;    ///< [m] radially outward from the rim
    double grouser_thickness_m = 0.0; ///< [m] in the rolling direction
    GrouserShape grouser_shape = GrouserShape::Straight;
    double chevron_angle_deg = 30.0; ///< [deg] sweep of each chevron arm from the axial direction
    bool closed_sides = true;        ///< side discs; false: a rim only, open at both ends
};

/// The `wheel:` block of every scenario with a parametric wheel (the rig, the rover, a URDF
/// link, the lab's wheel test; docs/scenario.md). Every key changes the mesh the grains touch;
/// one that would not (a grouser's height without grousers) is an error.
WheelShape parseWheelShape(const config::ConfigNode &node);

} // namespace grainlink::body
