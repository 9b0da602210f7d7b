#pragma once
// Triangle surface in its own (body) frame, with ASCII/binary STL import and export.
#include "grainlink/dem/Types.hpp"

#include <array>
#include <string>
#include <vector>

namespace grainlink::dem {

struct TriangleMesh {
    std::vector<Vec3> vertices_m;              ///< body frame [m]
    std::vector<std::array<int, 3>> triangles; ///< counter-clockwise seen from outside

    std::size_t triangleCount() const { return triangles.size(); }
    /// Largest distance of any vertex from the body-frame origin [m].
    double boundingRadius() const;
    /// Applies a uniform scale and then a translation to every vertex.
    void transform(double scale, const Vec3 &offset_m);
    /// Throws if an index is out of range, a triangle is degenerate or a vertex is non-finite.
    void validate(const std::string &what) const;
    /// The sides of the axis-aligned box around the vertices, in the body frame [m].
    Vec3 extent() const;
};

/// One line for the log when a body's mesh is loaded: its name, triangles, size and placement,
/// and how many grain diameters it spans.
std::string describeMesh(const std::string &name, const TriangleMesh &mesh,
                         const Vec3 &position_m, double grain_diameter_m);

/// Why a mesh this size cannot be meant for grains of this diameter in a bed this size, or ""
/// when it is plausible: under one grain across (a metre STL scaled as millimetres?), or more
/// than 10 times the bed's largest side or 5000 grains across (a millimetre STL read as metres?).
std::string implausibleMeshSize(const TriangleMesh &mesh, double grain_diameter_m,
                                double bed_size_m);

/// Reads ASCII or binary STL (detected from the file); vertices are shared where identical.
TriangleMesh readStl(const std::string &path);
void writeStlAscii(const TriangleMesh &mesh, const std::string &path, const std::string &name);
void writeStlBinary(const TriangleMesh &mesh, const std::string &path);

/// Closest point of triangle (a, b, c) to p (Ericson, Real-Time Collision Detection §5.1.5).
Vec3 closestPointOnTriangle(const Vec3 &p, const Vec3 &a, const Vec3 &b, const Vec3 &c);

/// The grain that cuts deepest into a placed mesh (vertices in the world frame): its index and
/// its overlap as a share of its radius, r - d over r with d its centre's distance from the
/// surface; ratio 0 when no grain touches. A body placed this way starts with that contact.
struct GrainOverlap {
    std::size_t particle = 0;
    double ratio = 0.0;
};
GrainOverlap deepestGrainOverlap(const std::vector<Vec3> &centres_m,
                                 const std::vector<double> &radii_m,
                                 const std::vector<Vec3> &world_vertices_m,
                                 const TriangleMesh &mesh);

/// The grains a placed closed mesh (vertices in the world frame) touches or holds: every grain
/// whose centre lies within its radius of the surface, or inside it (an odd number of the
/// surface's crossings on a ray from the centre). Ascending indices.
std::vector<std::size_t> grainsInMesh(const std::vector<Vec3> &centres_m,
                                      const std::vector<double> &radii_m,
                                      const std::vector<Vec3> &world_vertices_m,
                                      const TriangleMesh &mesh);

/// The most facets around a parametric body (wheel, plate, ring, tube) a scenario may ask for:
/// far beyond any grain-resolved need, and small enough that a typo cannot exhaust memory.
constexpr int kMaxMeshSegments = 100000;

/// Closed cylinder about the body y axis (a wheel without grousers): `segments` facets around.
TriangleMesh makeCylinder(double radius_m, double width_m, int segments);
/// Flat rectangle in the z = 0 plane, normal +z, split into 2 * nx * ny triangles.
TriangleMesh makeRectangle(double size_x_m, double size_y_m, int nx, int ny);

} // namespace grainlink::dem
