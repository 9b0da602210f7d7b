// The parametric wheel mesh: closed, wound outward, with the volume of its parts.
#include "grainlink/dem/WheelMesh.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <map>

using namespace grainlink::dem;
using grainlink::body::GrouserShape;
using grainlink::body::WheelShape;

namespace {

/// Signed volume by the divergence theorem: positive when every face is wound outward.
double signedVolume(const TriangleMesh &mesh) {
    double v = 0.0;
    for (const auto &t : mesh.triangles)
        v += mesh.vertices_m[t[0]].dot(mesh.vertices_m[t[1]].cross(mesh.vertices_m[t[2]])) / 6.0;
    return v;
}

/// Each directed edge of a closed, consistently wound surface appears exactly once, and its
/// reverse once: the number of edges breaking that rule (0 for a closed mesh).
int openEdges(const TriangleMesh &mesh) {
    std::map<std::pair<int, int>, int> directed;
    for (const auto &t : mesh.triangles)
        for (int k = 0; k < 3; ++k)
            ++directed[{t[k], t[(k + 1) % 3]}];
    int open = 0;
    for (const auto &[edge, count] : directed) {
        const auto reverse = directed.find({edge.second, edge.first});
        open += count != 1 || reverse == directed.end() || reverse->second != 1;
    }
    return open;
}

} // namespace

TEST_CASE("Wheel mesh: rim and grousers enclose their volumes, wound outward", "[dem][wheel]") {
    WheelShape spec; // the seed's wheel: 250 mm, 15 mm grousers (Table 1)
    spec.diameter_m = 0.25;
    spec.width_m = 0.1;
    spec.grouser_count = 12;
    spec.grouser_height_m = 0.015;
    spec.grouser_thickness_m = 0.004;
    WheelMeshOptions options;
    options.rim_segments = 72;
    const TriangleMesh mesh = makeWheel(spec, options);
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
    WheelShape spec;
    spec.diameter_m = 0.25;
    spec.width_m = 0.1;
    spec.grouser_count = 12;
    spec.grouser_height_m = 0.015;
    spec.grouser_thickness_m = 0.004;
    spec.grouser_shape = GrouserShape::Chevron;
    spec.chevron_angle_deg = 30.0;
    WheelMeshOptions options;
    options.rim_segments = 72;
    // validate() inside: indices, no degenerate faces
    const TriangleMesh mesh = makeWheel(spec, options);
    CHECK(mesh.triangleCount() == std::size_t(4 * 72 + 12 * 2 * options.chevron_segments * 12));
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
    WheelShape spec;
    spec.closed_sides = false;
    WheelMeshOptions options;
    options.rim_segments = 36;
    CHECK(makeWheel(spec, options).triangleCount() == 2 * 36);
    spec.grouser_shape = GrouserShape::Chevron;
    spec.chevron_angle_deg = 85.0;
    CHECK_THROWS_WITH(makeWheel(spec, options), Catch::Contains("chevron_angle_deg"));
    spec.grouser_shape = GrouserShape::Straight;
    spec.grouser_count = 4;
    CHECK_THROWS_WITH(makeWheel(spec, options), Catch::Contains("positive height and thickness"));
    spec.grouser_count = 0;
    spec.rim_thickness_m = 0.125; // the whole radius: no rim left
    CHECK_THROWS_WITH(makeWheel(spec, options), Catch::Contains("rim_thickness_m must lie in"));
    spec.rim_thickness_m = 0.005;
    spec.closed_sides = true; // side discs: the grains never see the rim's inside
    CHECK_THROWS_WITH(makeWheel(spec, options),
                      Catch::Contains("rim_thickness_m shapes an open wheel's rim"));
}

TEST_CASE("Wheel mesh: the half wheel of a mirror-symmetric model is the y >= 0 half",
          "[dem][wheel]") {
    WheelShape spec;
    spec.grouser_count = 12;
    spec.grouser_height_m = 0.015;
    spec.grouser_thickness_m = 0.004;
    WheelMeshOptions options;
    options.rim_segments = 72;
    const TriangleMesh full = makeWheel(spec, options);
    options.half = true;
    const TriangleMesh half = makeWheel(spec, options);
    // The rim loses one cap, each grouser half its length: the volume halves, to round-off
    // (the open side is the plane y = 0, which adds nothing to the divergence-theorem sum).
    CHECK(signedVolume(half) == Approx(0.5 * signedVolume(full)).epsilon(1e-12));
    for (const auto &v : half.vertices_m)
        REQUIRE(v.y() >= -1e-15);
    CHECK(half.triangleCount() == std::size_t(3 * 72 + 12 * 12));

    spec.grouser_shape = GrouserShape::Chevron; // one arm per grouser, stopping at the plane
    for (const auto &v : makeWheel(spec, options).vertices_m)
        REQUIRE(v.y() >= -1e-15);
}

TEST_CASE("Wheel mesh: an open wheel's rim is a closed tube of its rim thickness", "[dem][wheel]") {
    WheelShape spec;
    spec.diameter_m = 0.25;
    spec.width_m = 0.1;
    spec.closed_sides = false;
    spec.rim_thickness_m = 0.01;
    WheelMeshOptions options;
    options.rim_segments = 48;
    const TriangleMesh mesh = makeWheel(spec, options);
    // Outer and inner surface, two annular edges: 2 triangles per facet each.
    CHECK(mesh.triangleCount() == 8 * 48);
    CHECK(openEdges(mesh) == 0);
    // Every corner on the outer radius or on the inner one, r - thickness.
    const double r = 0.125, inner = 0.115, n = 48;
    for (const auto &t : mesh.triangles)
        for (int k : t) {
            const double radius = std::hypot(mesh.vertices_m[k].x(), mesh.vertices_m[k].z());
            REQUIRE((std::abs(radius - r) < 1e-15 || std::abs(radius - inner) < 1e-15));
        }
    // The tube's volume: the outer polygon's area less the inner one's, times the width (exact
    // to round-off only if every face is wound outward, the inner ones towards the axis).
    const double annulus = 0.5 * n * std::sin(2 * M_PI / n) * (r * r - inner * inner);
    CHECK(signedVolume(mesh) == Approx(annulus * spec.width_m).epsilon(1e-12));

    // With grousers the tube keeps its shape: the grousers are added boxes.
    spec.grouser_count = 6;
    spec.grouser_height_m = 0.01;
    spec.grouser_thickness_m = 0.004;
    CHECK(makeWheel(spec, options).triangleCount() == 8 * 48 + 6 * 12);

    // The half wheel: no edge on the symmetry plane (its image continues the rim), half the
    // volume.
    spec.grouser_count = 0;
    options.half = true;
    const TriangleMesh half = makeWheel(spec, options);
    CHECK(half.triangleCount() == 6 * 48);
    CHECK(signedVolume(half) == Approx(0.5 * annulus * spec.width_m).epsilon(1e-12));
}
