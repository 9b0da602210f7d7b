#include "grainlink/dem/WheelMesh.hpp"

#include <cmath>
#include <stdexcept>

namespace grainlink::dem {

namespace {

/// Appends a box given by its centre and three half-axes; faces wound outward.
void appendBox(TriangleMesh &mesh, const Vec3 &centre, const Vec3 &a, const Vec3 &b,
               const Vec3 &c) {
    const int first = static_cast<int>(mesh.vertices_m.size());
    for (int k = 0; k < 8; ++k)
        mesh.vertices_m.push_back(centre + ((k & 1) ? a : Vec3(-a)) + ((k & 2) ? b : Vec3(-b)) +
                                  ((k & 4) ? c : Vec3(-c)));
    // Each face: four corners sharing one coordinate sign, as two triangles.
    const int faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                             {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
    for (const auto &f : faces)
        for (const auto &tri :
             {std::array<int, 3>{f[0], f[1], f[2]}, std::array<int, 3>{f[0], f[2], f[3]}}) {
            std::array<int, 3> t{first + tri[0], first + tri[1], first + tri[2]};
            const Vec3 &p0 = mesh.vertices_m[t[0]], &p1 = mesh.vertices_m[t[1]],
                       &p2 = mesh.vertices_m[t[2]];
            const Vec3 normal = (p1 - p0).cross(p2 - p0);
            if (normal.dot((p0 + p1 + p2) / 3.0 - centre) < 0.0)
                std::swap(t[1], t[2]); // wind it outward
            mesh.triangles.push_back(t);
        }
}

} // namespace

TriangleMesh makeWheel(const WheelMeshSpec &spec) {
    const double r = 0.5 * spec.diameter_m;
    if (!(r > 0.0) || !(spec.width_m > 0.0))
        throw std::invalid_argument("wheel: diameter_m and width_m must be positive");
    if (spec.chevron)
        throw std::invalid_argument("wheel: chevron grousers are not implemented yet; use "
                                    "straight grousers");
    if (spec.grouser_count > 0 &&
        (!(spec.grouser_height_m > 0.0) || !(spec.grouser_thickness_m > 0.0)))
        throw std::invalid_argument("wheel: grousers need a positive height and thickness");
    const int segments = spec.rim_segments > 0
                             ? spec.rim_segments
                             : std::max(24, static_cast<int>(std::lround(360.0 / 5.0)));
    TriangleMesh mesh = makeCylinder(r, spec.width_m, segments);
    if (!spec.closed_sides) { // keep the rim: drop the cap triangles (they touch a centre)
        const int centre_minus = 2 * segments, centre_plus = centre_minus + 1;
        std::vector<std::array<int, 3>> rim;
        for (const auto &t : mesh.triangles)
            if (t[0] != centre_minus && t[0] != centre_plus)
                rim.push_back(t);
        mesh.triangles = rim;
    }
    // Grousers stand on the rim: from just inside the facetted rim to r + height.
    const double inner = r * std::cos(M_PI / segments) - 1e-6;
    for (unsigned g = 0; g < spec.grouser_count; ++g) {
        const double angle = 2.0 * M_PI * g / spec.grouser_count;
        const Vec3 radial(std::cos(angle), 0.0, std::sin(angle));
        const Vec3 tangential(-std::sin(angle), 0.0, std::cos(angle));
        const double half_height = 0.5 * (r + spec.grouser_height_m - inner);
        appendBox(mesh, radial * (inner + half_height), radial * half_height,
                  tangential * (0.5 * spec.grouser_thickness_m),
                  Vec3(0.0, 0.5 * spec.width_m, 0.0));
    }
    mesh.validate("wheel");
    return mesh;
}

} // namespace grainlink::dem
