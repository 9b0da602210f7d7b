// The parametric wheel mesh: closed, wound outward, with the volume of its parts.
#include "grainlink/dem/WheelMesh.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace grainlink::dem;

namespace {

/// Signed volume by the divergence theorem: positive when every face is wound outward.
double signedVolume(const TriangleMesh &mesh) {
    double v = 0.0;
    for (const auto &t : mesh.triangles)
        v += mesh.vertices_m[t[0]].dot(mesh.vertices_m[t[1]].cross(mesh.vertices_m[t[2]])) / 6.0;
    return v;
}

} // namespace

TEST_CASE("Wheel mesh: rim and grousers enclose their volumes, wound outward", "[dem][wheel]") {
    WheelMeshSpec spec; // the seed's wheel: 250 mm, 15 mm grousers (Table 1)
    spec.diameter_m = 0.25;
    spec.width_m = 0.1;
    spec.grouser_count = 12;
    spec.grouser_height_m = 0.015;
    spec.grouser_thickness_m = 0.004;
    spec.rim_segments = 72;
    const TriangleMesh mesh = makeWheel(spec);
    CHECK(mesh.triangleCount() == 4 * 72 + 12 * 12);
    const double r = 0.125, n = 72;
    const double rim = 0.5 * n * r * r * std::sin(2 * M_PI / n) * spec.width_m;
    const double inner = r * std::cos(M_PI / n) - 1e-6;
    const double grouser = (r + 0.015 - inner) * 0.004 * 0.1;
    // Exact up to round-off: each part is closed and outward (the parts overlap, so their
    // volumes add).
    CHECK(signedVolume(mesh) == Approx(rim + 12 * grouser).epsilon(1e-12));
    CHECK(mesh.boundingRadius() ==
          Approx(std::hypot(std::hypot(r + 0.015, 0.002), 0.05)).epsilon(1e-12));
}

TEST_CASE("Wheel mesh: chevron grousers sweep back symmetrically from the mid-plane",
          "[dem][wheel]") {
    WheelMeshSpec spec;
    spec.diameter_m = 0.25;
    spec.width_m = 0.1;
    spec.grouser_count = 12;
    spec.grouser_height_m = 0.015;
    spec.grouser_thickness_m = 0.004;
    spec.rim_segments = 72;
    spec.chevron = true;
    spec.chevron_angle_deg = 30.0;
    const TriangleMesh mesh = makeWheel(spec); // validate() inside: indices, no degenerate faces
    CHECK(mesh.triangleCount() == std::size_t(4 * 72 + 12 * 2 * spec.chevron_segments * 12));
    CHECK(signedVolume(mesh) > 0.0); // every box wound outward

    // Mirror symmetric about y = 0: every vertex has its mirror image (to round-off).
    for (const auto &v : mesh.vertices_m) {
        const Vec3 mirror(v.x(), -v.y(), v.z());
        double nearest = 1e9;
        for (const auto &w : mesh.vertices_m)
            nearest = std::min(nearest, (w - mirror).norm());
        REQUIRE(nearest < 1e-12);
    }
    // The tip of grouser 0 follows angle = |y| tan(30 deg) / r on the rim, within the half
    // thickness (plus the joint overlap) measured along the rim; and reaches the sides.
    const double r = 0.125, sweep = std::tan(M_PI / 6) / r;
    const double band = (0.002 + 0.002) / r / std::cos(M_PI / 6) + 1e-9;
    double widest = 0.0;
    for (const auto &v : mesh.vertices_m) {
        const double angle = std::atan2(v.z(), v.x());
        if (std::hypot(v.x(), v.z()) < r + 0.0075 || std::abs(angle) > M_PI / 12)
            continue; // not a tip vertex of grouser 0
        CHECK(std::abs(angle - std::abs(v.y()) * sweep) <= band);
        widest = std::max(widest, angle);
    }
    CHECK(widest >= 0.05 * sweep - 0.002 / r);
}

TEST_CASE("Wheel mesh: open sides, and what is refused", "[dem][wheel]") {
    WheelMeshSpec spec;
    spec.closed_sides = false;
    spec.rim_segments = 36;
    CHECK(makeWheel(spec).triangleCount() == 2 * 36);
    spec.chevron = true;
    spec.chevron_angle_deg = 85.0;
    CHECK_THROWS_WITH(makeWheel(spec), Catch::Contains("chevron_angle_deg"));
    spec.chevron = false;
    spec.grouser_count = 4;
    CHECK_THROWS_WITH(makeWheel(spec), Catch::Contains("positive height and thickness"));
}

TEST_CASE("Wheel mesh: the half wheel of a mirror-symmetric model is the y >= 0 half",
          "[dem][wheel]") {
    WheelMeshSpec spec;
    spec.grouser_count = 12;
    spec.grouser_height_m = 0.015;
    spec.grouser_thickness_m = 0.004;
    spec.rim_segments = 72;
    const TriangleMesh full = makeWheel(spec);
    spec.half = true;
    const TriangleMesh half = makeWheel(spec);
    // The rim loses one cap, each grouser half its length: the volume halves, to round-off
    // (the open side is the plane y = 0, which adds nothing to the divergence-theorem sum).
    CHECK(signedVolume(half) == Approx(0.5 * signedVolume(full)).epsilon(1e-12));
    for (const auto &v : half.vertices_m)
        REQUIRE(v.y() >= -1e-15);
    CHECK(half.triangleCount() == std::size_t(3 * 72 + 12 * 12));

    spec.chevron = true; // one arm per grouser, stopping at the plane
    for (const auto &v : makeWheel(spec).vertices_m)
        REQUIRE(v.y() >= -1e-15);
}
