#include "grainlink/dem/BodyMotion.hpp"

#include <algorithm>
#include <limits>

namespace grainlink::dem {

RigidBodyState SegmentedMotion::at(double t_s) const {
    RigidBodyState s = start;
    s.linear_velocity_m_s.setZero();
    s.angular_velocity_rad_s.setZero();
    double remaining = std::max(t_s - start_s, 0.0);
    for (const MotionSegment &seg : segments) {
        const double span = std::min(remaining, seg.duration_s);
        s.position_m += seg.linear_velocity_m_s * span;
        s.orientation = rotationFromVector(seg.angular_velocity_rad_s * span) * s.orientation;
        remaining -= span;
        if (remaining <= 0.0) {
            s.linear_velocity_m_s = seg.linear_velocity_m_s;
            s.angular_velocity_rad_s = seg.angular_velocity_rad_s;
            break;
        }
    }
    return s; // MeshBody::setState normalizes the orientation
}

SegmentedMotion constantVelocity(const RigidBodyState &start, double start_s) {
    return {start,
            start_s,
            {{std::numeric_limits<double>::infinity(), start.linear_velocity_m_s,
              start.angular_velocity_rad_s}}};
}

RigidBodyState WindowMotion::at(double t_s) const {
    // Cubic Hermite curve, docs/physics.md §7.2. The velocity is written so that it is exactly
    // v_a at s = 0 and v_b at s = 1 (a (H v)/H would round). A time within 1e-9 H of an end is
    // that end: the DEM's clock (steps of dt) and the coupling's (ticks) differ by round-off.
    const double H = duration_s;
    const double fraction = (t_s - start_s) / H;
    const double s = fraction < 1e-9 ? 0.0 : fraction > 1.0 - 1e-9 ? 1.0 : fraction;
    const double s2 = s * s, s3 = s2 * s;
    RigidBodyState r;
    r.position_m = (2 * s3 - 3 * s2 + 1) * a.position_m +
                   (s3 - 2 * s2 + s) * H * a.linear_velocity_m_s +
                   (-2 * s3 + 3 * s2) * b.position_m + (s3 - s2) * H * b.linear_velocity_m_s;
    r.linear_velocity_m_s = ((6 * s2 - 6 * s) / H) * (a.position_m - b.position_m) +
                            (3 * s2 - 4 * s + 1) * a.linear_velocity_m_s +
                            (3 * s2 - 2 * s) * b.linear_velocity_m_s;
    r.orientation = a.orientation.slerp(s, b.orientation); // normalized by MeshBody::setState
    r.angular_velocity_rad_s = (1 - s) * a.angular_velocity_rad_s + s * b.angular_velocity_rad_s;
    return r;
}

} // namespace grainlink::dem
