#pragma once
// The mbs tests' reading of a body's pitch.
#include "grainlink/mbs/MultibodyModel.hpp"

#include <cmath>

/// The angle a rotation turns about +y (turning about +y takes x towards -z).
inline double angleAboutY(const grainlink::mbs::Quat &q) {
    const grainlink::mbs::Vec3 x = q * grainlink::mbs::Vec3::UnitX();
    return std::atan2(-x.z(), x.x());
}
