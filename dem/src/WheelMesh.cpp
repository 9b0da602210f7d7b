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

/// Appends one straight piece of grouser: a box on the rim whose centre line runs from
/// (angle0, y0) to (angle1, y1) on the rim surface, from radius `inner` to r + height, lengthened
/// by `extend0` / `extend1` past its ends (so that the pieces of a chevron arm overlap at their
/// joints). The piece is sunk by the sagitta of its chord so that it stays closed onto the rim.
void appendGrouserPiece(TriangleMesh &mesh, double r, double inner, double height, double thickness,
                        double angle0, double angle1, double y0, double y1, double extend0 = 0.0,
                        double extend1 = 0.0) {
    const double mid = 0.5 * (angle0 + angle1);
    const Vec3 radial(std::cos(mid), 0.0, std::sin(mid));
    const Vec3 tangential(-std::sin(mid), 0.0, std::cos(mid));
    const Vec3 run = tangential * (r * (angle1 - angle0)) + Vec3(0.0, y1 - y0, 0.0);
    const Vec3 along = run.normalized();
    const Vec3 across = radial.cross(along); // in the rim's tangent plane
    const double sagitta = r * (1.0 - std::cos(0.5 * (angle1 - angle0)));
    const double bottom = inner - sagitta;
    const double half_height = 0.5 * (r + height - bottom);
    appendBox(mesh,
              radial * (bottom + half_height) + Vec3(0.0, 0.5 * (y0 + y1), 0.0) +
                  along * (0.5 * (extend1 - extend0)),
              radial * half_height, across * (0.5 * thickness),
              along * (0.5 * (run.norm() + extend0 + extend1)));
}

/// An open rim's inner surface at `inner_radius` (facing the axis) and its annular edge at each
/// open end, joined to the outer rim's vertex rings (makeCylinder's first 2 x `segments`
/// vertices, at y_from then y_to). A half wheel has no edge on its symmetry plane (y_from).
void appendRimThickness(TriangleMesh &mesh, double inner_radius, double y_from, double y_to,
                        int segments, bool edge_at_from) {
    const int outer_from = 0, outer_to = segments;
    const int inner_from = static_cast<int>(mesh.vertices_m.size()),
              inner_to = inner_from + segments;
    for (const double y : {y_from, y_to})
        for (int k = 0; k < segments; ++k) {
            const double a = 2.0 * M_PI * k / segments; // the outer rim's angles
            mesh.vertices_m.emplace_back(inner_radius * std::cos(a), y, inner_radius * std::sin(a));
        }
    for (int k = 0; k < segments; ++k) {
        const int k1 = (k + 1) % segments;
        const int c0 = inner_from + k, c1 = inner_from + k1, d0 = inner_to + k, d1 = inner_to + k1;
        // The outer rim's winding reversed: the inner surface faces the axis.
        mesh.triangles.push_back({c0, d1, d0});
        mesh.triangles.push_back({c0, c1, d1});
        // The edges, wound as a closed wheel's caps (normal -y at y_from, +y at y_to).
        const int b0 = outer_to + k, b1 = outer_to + k1;
        mesh.triangles.push_back({d0, b1, b0});
        mesh.triangles.push_back({d0, d1, b1});
        if (edge_at_from) {
            const int a0 = outer_from + k, a1 = outer_from + k1;
            mesh.triangles.push_back({c0, a0, a1});
            mesh.triangles.push_back({c0, a1, c1});
        }
    }
}

} // namespace

TriangleMesh makeWheel(const body::WheelShape &wheel, const WheelMeshOptions &options) {
    const double r = 0.5 * wheel.diameter_m;
    const bool chevron = wheel.grouser_shape == body::GrouserShape::Chevron;
    if (!(r > 0.0) || !(wheel.width_m > 0.0))
        throw std::invalid_argument("wheel: diameter_m and width_m must be positive");
    if (chevron && !(std::abs(wheel.chevron_angle_deg) < 80.0 && options.chevron_segments > 0))
        throw std::invalid_argument("wheel: chevron_angle_deg must lie in (-80, 80) degrees and "
                                    "chevron_segments be positive");
    if (wheel.grouser_count > 0 &&
        (!(wheel.grouser_height_m > 0.0) || !(wheel.grouser_thickness_m > 0.0)))
        throw std::invalid_argument("wheel: grousers need a positive height and thickness");
    if (!(wheel.rim_thickness_m >= 0.0 && wheel.rim_thickness_m < r))
        throw std::invalid_argument("wheel: rim_thickness_m must lie in [0, diameter_m / 2)");
    if (wheel.closed_sides && wheel.rim_thickness_m != 0.0)
        throw std::invalid_argument("wheel: rim_thickness_m shapes an open wheel's rim "
                                    "(closed_sides false); a closed wheel is solid to the grains");
    const int segments = options.rim_segments > 0
                             ? options.rim_segments
                             : std::max(24, static_cast<int>(std::lround(360.0 / 5.0)));
    // The rim from y = -w/2 (or 0 for the half wheel) to w/2.
    const double y_from = options.half ? 0.0 : -0.5 * wheel.width_m, y_to = 0.5 * wheel.width_m;
    TriangleMesh mesh = makeCylinder(r, y_to - y_from, segments);
    for (auto &v : mesh.vertices_m)
        v.y() += 0.5 * (y_from + y_to);
    // Drop the cap triangles (they touch a cap centre) that are not wanted: both for an open
    // wheel, the one on the symmetry plane for a half wheel.
    const int centre_minus = 2 * segments, centre_plus = centre_minus + 1;
    std::vector<std::array<int, 3>> kept;
    for (const auto &t : mesh.triangles)
        if (!(t[0] == centre_minus && (options.half || !wheel.closed_sides)) &&
            !(t[0] == centre_plus && !wheel.closed_sides))
            kept.push_back(t);
    mesh.triangles = kept;
    if (wheel.rim_thickness_m > 0.0) // an open rim with a thickness; the half's edge at y = 0 is
                                     // its image's, not an edge
        appendRimThickness(mesh, r - wheel.rim_thickness_m, y_from, y_to, segments, !options.half);
    // Grousers stand on the rim: from just inside the facetted rim to r + height.
    const double inner = r * std::cos(M_PI / segments) - 1e-6;
    for (unsigned g = 0; g < wheel.grouser_count; ++g) {
        const double angle = 2.0 * M_PI * g / wheel.grouser_count;
        if (!chevron) {
            appendGrouserPiece(mesh, r, inner, wheel.grouser_height_m, wheel.grouser_thickness_m,
                               angle, angle, y_from, y_to);
            continue;
        }
        // Each arm runs from the apex (y = 0) to a side, its angle growing as |y| tan(sweep)/r:
        // a straight line on the unrolled rim.
        const double sweep = std::tan(wheel.chevron_angle_deg * M_PI / 180.0) / r;
        const int n = options.chevron_segments;
        for (const double side : {-1.0, 1.0}) {
            if (options.half && side < 0.0)
                continue;
            for (int k = 0; k < n; ++k) {
                const double y0 = side * 0.5 * wheel.width_m * k / n;
                const double y1 = side * 0.5 * wheel.width_m * (k + 1) / n;
                const double overlap = 0.5 * wheel.grouser_thickness_m; // closes the joints
                // A half wheel's arm stops where its slanted end face touches the symmetry
                // plane (its image continues it), leaving a notch smaller than the thickness.
                const double start =
                    k > 0 || !options.half
                        ? overlap
                        : -0.5 * wheel.grouser_thickness_m *
                              std::abs(std::tan(wheel.chevron_angle_deg * M_PI / 180.0));
                appendGrouserPiece(mesh, r, inner, wheel.grouser_height_m,
                                   wheel.grouser_thickness_m, angle + std::abs(y0) * sweep,
                                   angle + std::abs(y1) * sweep, y0, y1, start,
                                   k + 1 < n ? overlap : 0.0);
            }
        }
    }
    mesh.validate("wheel");
    return mesh;
}

} // namespace grainlink::dem
