#pragma once
// The parametric wheel (seed Fig. 8) as a closed triangle mesh about the body y axis: a rim
// cylinder plus grousers standing on it: straight ones as one box across the width, chevron
// ones as two swept-back arms meeting at the mid-plane, each arm a chain of short boxes that
// follows the rim's curvature. The coupled DEM node and `grainlink`'s
// STL export build it from the same numbers the multibody side sends in its handshake.
#include "grainlink/dem/TriangleMesh.hpp"

namespace grainlink::dem {

struct WheelMeshSpec {
    double diameter_m = 0.25; ///< [m] rim outer diameter (grousers excluded)
    double width_m = 0.1;     ///< [m]
    unsigned grouser_count = 0;
    double grouser_height_m = 0.0;    ///< [m] radially outward from the rim
    double grouser_thickness_m = 0.0; ///< [m] in the rolling direction
    bool chevron = false;             ///< V-shaped grousers, apex at y = 0
    double chevron_angle_deg = 30.0;  ///< [deg] sweep of each arm from the axial direction
    int chevron_segments = 4;         ///< boxes per arm
    bool closed_sides = true;         ///< side discs (an open wheel is a rim only)
    int rim_segments = 0;             ///< facets around; 0: about one per 5 degrees, at least 24
    /// Only the half at y >= 0, open on the plane y = 0: the wheel of a mirror-symmetric half
    /// model, whose other half is the image in a frictionless symmetry plane.
    bool half = false;
};

TriangleMesh makeWheel(const WheelMeshSpec &spec);

} // namespace grainlink::dem
