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

TEST_CASE("Wheel mesh: open sides, and what is not built yet is refused", "[dem][wheel]") {
    WheelMeshSpec spec;
    spec.closed_sides = false;
    spec.rim_segments = 36;
    CHECK(makeWheel(spec).triangleCount() == 2 * 36);
    spec.chevron = true;
    CHECK_THROWS_WITH(makeWheel(spec), Catch::Contains("chevron grousers are not implemented"));
    spec.chevron = false;
    spec.grouser_count = 4;
    CHECK_THROWS_WITH(makeWheel(spec), Catch::Contains("positive height and thickness"));
}
