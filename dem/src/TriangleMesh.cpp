#include "grainlink/dem/TriangleMesh.hpp"

#include <cstdio>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

namespace grainlink::dem {

double TriangleMesh::boundingRadius() const {
    double r = 0.0;
    for (const Vec3 &v : vertices_m)
        r = std::max(r, v.norm());
    return r;
}

Vec3 TriangleMesh::extent() const {
    if (vertices_m.empty())
        return Vec3::Zero();
    Vec3 low = vertices_m.front(), high = vertices_m.front();
    for (const Vec3 &v : vertices_m) {
        low = low.cwiseMin(v);
        high = high.cwiseMax(v);
    }
    return high - low;
}

std::string describeMesh(const std::string &name, const TriangleMesh &mesh,
                         const Vec3 &position_m, double grain_diameter_m) {
    const Vec3 e = mesh.extent();
    char text[320];
    std::snprintf(text, sizeof text,
                  "mesh '%s': %zu triangles, %.4g x %.4g x %.4g m (body frame), placed at (%.4g, "
                  "%.4g, %.4g) m, %.3g grain diameters across",
                  name.c_str(), mesh.triangleCount(), e.x(), e.y(), e.z(), position_m.x(),
                  position_m.y(), position_m.z(), e.maxCoeff() / grain_diameter_m);
    return text;
}

std::string implausibleMeshSize(const TriangleMesh &mesh, double grain_diameter_m,
                                double bed_size_m) {
    const double size = mesh.extent().maxCoeff();
    char text[320];
    if (size < grain_diameter_m) {
        std::snprintf(text, sizeof text,
                      "the mesh is %.3g m across, less than one grain (%.3g m): a mesh in "
                      "metres scaled as if in millimetres?",
                      size, grain_diameter_m);
        return text;
    }
    if (size > 10.0 * bed_size_m || size > 5000.0 * grain_diameter_m) {
        std::snprintf(text, sizeof text,
                      "the mesh is %.3g m across, %.3g times the bed's largest side (%.3g m) and "
                      "%.3g grain diameters: a mesh in millimetres read as metres? (scale it: "
                      "0.001)",
                      size, size / bed_size_m, bed_size_m, size / grain_diameter_m);
        return text;
    }
    return "";
}

void TriangleMesh::transform(double scale, const Vec3 &offset_m) {
    for (Vec3 &v : vertices_m)
        v = scale * v + offset_m;
}

void TriangleMesh::validate(const std::string &what) const {
    const int n = static_cast<int>(vertices_m.size());
    for (const Vec3 &v : vertices_m)
        if (!v.allFinite())
            throw std::runtime_error(what + ": non-finite vertex coordinate");
    for (std::size_t t = 0; t < triangles.size(); ++t) {
        for (int k : triangles[t])
            if (k < 0 || k >= n)
                throw std::runtime_error(what + ": triangle " + std::to_string(t) +
                                         " refers to missing vertex " + std::to_string(k));
        const auto &tri = triangles[t];
        const Vec3 area2 = (vertices_m[tri[1]] - vertices_m[tri[0]])
                               .cross(vertices_m[tri[2]] - vertices_m[tri[0]]);
        if (area2.norm() == 0.0)
            throw std::runtime_error(what + ": triangle " + std::to_string(t) + " is degenerate");
    }
    if (triangles.empty())
        throw std::runtime_error(what + ": mesh has no triangles");
}

namespace {

/// Shares identical vertices so the mesh is indexed rather than a triangle soup.
class VertexWelder {
public:
    explicit VertexWelder(TriangleMesh &mesh) : mesh_(mesh) {}
    int index(const Vec3 &v) {
        const auto key = std::make_tuple(v.x(), v.y(), v.z());
        auto [it, inserted] = lookup_.emplace(key, static_cast<int>(mesh_.vertices_m.size()));
        if (inserted)
            mesh_.vertices_m.push_back(v);
        return it->second;
    }
    void addTriangle(const Vec3 &a, const Vec3 &b, const Vec3 &c) {
        mesh_.triangles.push_back({index(a), index(b), index(c)});
    }

private:
    TriangleMesh &mesh_;
    std::map<std::tuple<double, double, double>, int> lookup_;
};

TriangleMesh readStlBinary(const std::string &path, const std::string &bytes) {
    std::uint32_t count = 0;
    std::memcpy(&count, bytes.data() + 80, 4);
    TriangleMesh mesh;
    VertexWelder weld(mesh);
    for (std::uint32_t t = 0; t < count; ++t) {
        const char *rec = bytes.data() + 84 + 50 * std::size_t(t);
        float f[12];
        std::memcpy(f, rec, sizeof f);
        Vec3 v[3];
        for (int k = 0; k < 3; ++k)
            v[k] = Vec3(f[3 + 3 * k], f[4 + 3 * k], f[5 + 3 * k]);
        weld.addTriangle(v[0], v[1], v[2]);
    }
    mesh.validate("STL file '" + path + "'");
    return mesh;
}

TriangleMesh readStlAscii(const std::string &path, const std::string &text) {
    TriangleMesh mesh;
    VertexWelder weld(mesh);
    std::istringstream in(text);
    std::string line;
    int line_no = 0;
    std::vector<Vec3> facet;
    bool ended = false;
    while (std::getline(in, line)) {
        ++line_no;
        std::istringstream words(line);
        std::string word;
        if (!(words >> word))
            continue;
        if (ended)
            throw std::runtime_error("STL file '" + path + "', line " + std::to_string(line_no) +
                                     ": text after 'endsolid'");
        if (word == "endsolid") {
            ended = true;
        } else if (word == "vertex") {
            Vec3 v;
            if (!(words >> v.x() >> v.y() >> v.z()))
                throw std::runtime_error("STL file '" + path + "', line " +
                                         std::to_string(line_no) + ": malformed vertex");
            facet.push_back(v);
        } else if (word == "endloop") {
            if (facet.size() != 3)
                throw std::runtime_error("STL file '" + path + "', line " +
                                         std::to_string(line_no) + ": facet has " +
                                         std::to_string(facet.size()) + " vertices, expected 3");
            weld.addTriangle(facet[0], facet[1], facet[2]);
            facet.clear();
        }
    }
    // A file cut off mid-way (a copy that failed, a full disk) would otherwise give a part.
    if (!ended)
        throw std::runtime_error("STL file '" + path + "' ends at line " +
                                 std::to_string(line_no) + " without 'endsolid' after " +
                                 std::to_string(mesh.triangles.size()) +
                                 " complete facets: the file is cut off");
    return mesh;
}

} // namespace

TriangleMesh readStl(const std::string &path) {
    std::ifstream file(path, std::ios::binary);
    if (!file)
        throw std::runtime_error("cannot open STL file '" + path + "'");
    std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    if (bytes.size() >= 84) {
        std::uint32_t count = 0;
        std::memcpy(&count, bytes.data() + 80, 4);
        // Binary STL has an exact size; ASCII files may also start with "solid", so test size.
        if (bytes.size() == 84 + 50 * std::size_t(count))
            return readStlBinary(path, bytes);
    }
    if (bytes.compare(0, 5, "solid") != 0)
        throw std::runtime_error("STL file '" + path +
                                 "' is neither binary (size mismatch) nor ASCII (no 'solid')");
    return readStlAscii(path, bytes);
}

void writeStlAscii(const TriangleMesh &mesh, const std::string &path, const std::string &name) {
    std::ofstream out(path);
    if (!out)
        throw std::runtime_error("cannot write STL file '" + path + "'");
    out.precision(9);
    out << "solid " << name << "\n";
    for (const auto &tri : mesh.triangles) {
        const Vec3 &a = mesh.vertices_m[tri[0]], &b = mesh.vertices_m[tri[1]],
                   &c = mesh.vertices_m[tri[2]];
        const Vec3 n = (b - a).cross(c - a).normalized();
        out << " facet normal " << n.x() << ' ' << n.y() << ' ' << n.z() << "\n  outer loop\n";
        for (const Vec3 *v : {&a, &b, &c})
            out << "   vertex " << v->x() << ' ' << v->y() << ' ' << v->z() << "\n";
        out << "  endloop\n endfacet\n";
    }
    out << "endsolid " << name << "\n";
}

void writeStlBinary(const TriangleMesh &mesh, const std::string &path) {
    std::ofstream out(path, std::ios::binary);
    if (!out)
        throw std::runtime_error("cannot write STL file '" + path + "'");
    char header[80] = "grainlink binary STL";
    out.write(header, 80);
    const std::uint32_t count = static_cast<std::uint32_t>(mesh.triangles.size());
    out.write(reinterpret_cast<const char *>(&count), 4);
    for (const auto &tri : mesh.triangles) {
        const Vec3 &a = mesh.vertices_m[tri[0]], &b = mesh.vertices_m[tri[1]],
                   &c = mesh.vertices_m[tri[2]];
        const Vec3 n = (b - a).cross(c - a).normalized();
        float f[12];
        for (int k = 0; k < 3; ++k) {
            f[k] = float(n[k]);
            f[3 + k] = float(a[k]);
            f[6 + k] = float(b[k]);
            f[9 + k] = float(c[k]);
        }
        out.write(reinterpret_cast<const char *>(f), sizeof f);
        const std::uint16_t attribute = 0;
        out.write(reinterpret_cast<const char *>(&attribute), 2);
    }
}

namespace {
/// The placed mesh's axis-aligned box, and whether a grain at x of radius r lies beyond it.
struct Box {
    Vec3 lo, hi;
    explicit Box(const std::vector<Vec3> &vertices) : lo(vertices.front()), hi(lo) {
        for (const Vec3 &v : vertices) {
            lo = lo.cwiseMin(v);
            hi = hi.cwiseMax(v);
        }
    }
    bool outOfReach(const Vec3 &x, double r) const {
        return (x.array() < lo.array() - r).any() || (x.array() > hi.array() + r).any();
    }
};

/// The squared distance from x to the placed mesh's surface.
double squaredDistance(const Vec3 &x, const std::vector<Vec3> &vertices, const TriangleMesh &mesh) {
    double d2 = std::numeric_limits<double>::infinity();
    for (const auto &t : mesh.triangles)
        d2 = std::min(
            d2, (closestPointOnTriangle(x, vertices[std::size_t(t[0])], vertices[std::size_t(t[1])],
                                        vertices[std::size_t(t[2])]) -
                 x)
                    .squaredNorm());
    return d2;
}

/// Whether a ray from p along `direction` crosses triangle (a, b, c) (Moeller-Trumbore).
bool rayCrosses(const Vec3 &p, const Vec3 &direction, const Vec3 &a, const Vec3 &b, const Vec3 &c) {
    const Vec3 e1 = b - a, e2 = c - a, h = direction.cross(e2);
    const double det = e1.dot(h);
    if (std::abs(det) < 1e-300)
        return false; // parallel
    const Vec3 s = p - a;
    const double u = s.dot(h) / det;
    if (u < 0.0 || u > 1.0)
        return false;
    const Vec3 q = s.cross(e1);
    const double v = direction.dot(q) / det;
    return v >= 0.0 && u + v <= 1.0 && e2.dot(q) / det > 0.0;
}
} // namespace

std::vector<std::size_t> grainsInMesh(const std::vector<Vec3> &centres_m,
                                      const std::vector<double> &radii_m,
                                      const std::vector<Vec3> &world_vertices_m,
                                      const TriangleMesh &mesh) {
    std::vector<std::size_t> in;
    if (world_vertices_m.empty())
        return in;
    const Box box(world_vertices_m);
    // A direction no facet of a parametric body lies along, so that a ray meets no edge
    // exactly.
    const Vec3 direction = Vec3(0.1234, 0.3141, 0.9412).normalized();
    for (std::size_t i = 0; i < centres_m.size(); ++i) {
        const Vec3 &x = centres_m[i];
        const double r = radii_m[i];
        if (box.outOfReach(x, r))
            continue;
        if (squaredDistance(x, world_vertices_m, mesh) < r * r) {
            in.push_back(i);
            continue;
        }
        int crossings = 0;
        for (const auto &t : mesh.triangles)
            crossings += rayCrosses(x, direction, world_vertices_m[std::size_t(t[0])],
                                    world_vertices_m[std::size_t(t[1])],
                                    world_vertices_m[std::size_t(t[2])]);
        if (crossings % 2 == 1)
            in.push_back(i);
    }
    return in;
}

GrainOverlap deepestGrainOverlap(const std::vector<Vec3> &centres_m,
                                 const std::vector<double> &radii_m,
                                 const std::vector<Vec3> &world_vertices_m,
                                 const TriangleMesh &mesh) {
    GrainOverlap deepest;
    if (world_vertices_m.empty())
        return deepest;
    const Box box(world_vertices_m);
    for (std::size_t i = 0; i < centres_m.size(); ++i) {
        const Vec3 &x = centres_m[i];
        const double r = radii_m[i];
        if (box.outOfReach(x, r))
            continue; // cannot reach the mesh
        const double d2 = std::min(r * r, squaredDistance(x, world_vertices_m, mesh));
        const double ratio = (r - std::sqrt(d2)) / r;
        if (ratio > deepest.ratio)
            deepest = {i, ratio};
    }
    return deepest;
}

Vec3 closestPointOnTriangle(const Vec3 &p, const Vec3 &a, const Vec3 &b, const Vec3 &c) {
    const Vec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0.0 && d2 <= 0.0)
        return a;
    const Vec3 bp = p - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0.0 && d4 <= d3)
        return b;
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0)
        return a + (d1 / (d1 - d3)) * ab;
    const Vec3 cp = p - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0.0 && d5 <= d6)
        return c;
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0)
        return a + (d2 / (d2 - d6)) * ac;
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
        return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
    const double denom = 1.0 / (va + vb + vc);
    return a + ab * (vb * denom) + ac * (vc * denom);
}

TriangleMesh makeCylinder(double radius_m, double width_m, int segments) {
    if (segments < 3)
        throw std::invalid_argument("makeCylinder: need at least 3 segments");
    TriangleMesh mesh;
    const double half = 0.5 * width_m;
    // Ring vertices on both faces, then the two cap centres.
    for (int side = 0; side < 2; ++side)
        for (int k = 0; k < segments; ++k) {
            const double a = 2.0 * M_PI * k / segments;
            mesh.vertices_m.emplace_back(radius_m * std::cos(a), side == 0 ? -half : half,
                                         radius_m * std::sin(a));
        }
    const int centre_minus = 2 * segments, centre_plus = 2 * segments + 1;
    mesh.vertices_m.emplace_back(0.0, -half, 0.0);
    mesh.vertices_m.emplace_back(0.0, half, 0.0);
    for (int k = 0; k < segments; ++k) {
        const int k1 = (k + 1) % segments;
        const int a0 = k, a1 = k1, b0 = segments + k, b1 = segments + k1;
        // Outward normals: the angle runs x -> z, which turns about -y.
        mesh.triangles.push_back({a0, b0, b1});
        mesh.triangles.push_back({a0, b1, a1});
        mesh.triangles.push_back({centre_minus, a0, a1});
        mesh.triangles.push_back({centre_plus, b1, b0});
    }
    return mesh;
}

TriangleMesh makeRectangle(double size_x_m, double size_y_m, int nx, int ny) {
    TriangleMesh mesh;
    for (int j = 0; j <= ny; ++j)
        for (int i = 0; i <= nx; ++i)
            mesh.vertices_m.emplace_back(size_x_m * (double(i) / nx - 0.5),
                                         size_y_m * (double(j) / ny - 0.5), 0.0);
    auto at = [nx](int i, int j) { return j * (nx + 1) + i; };
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
            mesh.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
        }
    return mesh;
}

} // namespace grainlink::dem
