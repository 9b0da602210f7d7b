#pragma once
// Basic math types shared by the DEM module: Eigen vectors and quaternions, SI units throughout.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>

namespace grainlink::dem {

using Vec3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;
using Mat3 = Eigen::Matrix3d;

/// Stable particle identity; the storage index changes when particles are re-sorted.
using ParticleId = std::uint64_t;

/// Rotation by the rotation vector `rotation_rad` (axis times angle), exact for any angle.
inline Quat rotationFromVector(const Vec3 &rotation_rad) {
    const double angle = rotation_rad.norm();
    if (angle < 1e-300)
        return Quat::Identity();
    return Quat(Eigen::AngleAxisd(angle, rotation_rad / angle));
}

} // namespace grainlink::dem
