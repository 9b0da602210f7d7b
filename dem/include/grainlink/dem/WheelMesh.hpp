#pragma once
// The parametric wheel (seed Fig. 8) as a triangle mesh about the body y axis: a rim cylinder
// plus grousers standing on it: straight ones as one box across the width, chevron ones as two
// swept-back arms meeting at the mid-plane, each arm a chain of short boxes that follows the
// rim's curvature. An open wheel's rim is a tube of the wheel's rim thickness. The coupled DEM
// node and `grainlink wheel-stl` build it from the body::WheelShape the multibody model
// describes, so what a user inspects in a CAD tool is what the grains touch.
#include "grainlink/body/WheelShape.hpp"
#include "grainlink/dem/TriangleMesh.hpp"

namespace grainlink::dem {

/// How finely a wheel is meshed, and which part of it: not part of the wheel's description (both
/// sides of a coupled run use the defaults, so they see the same mesh).
struct WheelMeshOptions {
    int chevron_segments = 4; ///< boxes per chevron arm
    int rim_segments = 0;     ///< facets around; 0: about one per 5 degrees, at least 24
    /// Only the half at y >= 0, open on the plane y = 0: the wheel of a mirror-symmetric half
    /// model, whose other half is the image in a frictionless symmetry plane.
    bool half = false;
};

/// Throws std::invalid_argument naming the parameter when the wheel cannot be built.
TriangleMesh makeWheel(const body::WheelShape &wheel, const WheelMeshOptions &options = {});

} // namespace grainlink::dem
