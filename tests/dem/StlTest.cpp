// STL import and export: ASCII and binary round trips and error messages (docs/physics.md §5).
#include "Fixtures.hpp"

#include <catch2/catch.hpp>

#include <cstdio>
#include <fstream>
#include <unistd.h>

using namespace grainlink::dem;

namespace {

/// A file name in the temporary directory, removed again when the test ends.
struct TempFile {
    std::string path;
    explicit TempFile(const std::string& name)
        : path((std::getenv("TMPDIR") ? std::string(std::getenv("TMPDIR")) : "/tmp") +
               "/grainlink_" + std::to_string(::getpid()) + "_" + name) {}
    ~TempFile() { std::remove(path.c_str()); }
};

/// Largest vertex distance between two meshes triangle by triangle, corner by corner.
double maxCornerDistance(const TriangleMesh& a, const TriangleMesh& b) {
    double worst = 0.0;
    for (std::size_t t = 0; t < a.triangleCount(); ++t)
        for (int k = 0; k < 3; ++k)
            worst = std::max(
                worst, (a.vertices_m[a.triangles[t][k]] - b.vertices_m[b.triangles[t][k]]).norm());
    return worst;
}

/// Sum of outward-facing area vectors: zero for a closed surface; and the enclosed volume.
std::pair<double, double> closureAndVolume(const TriangleMesh& m) {
    Vec3 area = Vec3::Zero();
    double volume = 0.0;
    for (const auto& t : m.triangles) {
        const Vec3 &a = m.vertices_m[t[0]], &b = m.vertices_m[t[1]], &c = m.vertices_m[t[2]];
        area += 0.5 * (b - a).cross(c - a);
        volume += a.dot(b.cross(c)) / 6.0;
    }
    return {area.norm(), volume};
}

} // namespace

TEST_CASE("STL round trip of the wheel cylinder, ASCII and binary", "[dem][stl]") {
    const TriangleMesh wheel = makeCylinder(0.125, 0.1, 360);
    REQUIRE(wheel.triangleCount() == 1440);
    REQUIRE(wheel.vertices_m.size() == 722); // two rings of 360 and two cap centres
    const auto [closure, volume] = closureAndVolume(wheel);
    // Closed, outward-facing surface; a 360-gon cylinder holds pi r^2 w sin(2pi/n) n / (2pi).
    CHECK(closure < 1e-12);
    CHECK(volume ==
          Approx(0.5 * 360 * std::sin(2 * M_PI / 360) * 0.125 * 0.125 * 0.1).epsilon(1e-12));

    TempFile ascii("wheel_ascii.stl"), binary("wheel_binary.stl");
    writeStlAscii(wheel, ascii.path, "wheel");
    writeStlBinary(wheel, binary.path);
    for (const std::string& path : {ascii.path, binary.path}) {
        INFO(path);
        const TriangleMesh read = readStl(path);
        // Same facets in the same order, same corner order (orientation), vertices shared again.
        CHECK(read.triangleCount() == 1440);
        CHECK(read.vertices_m.size() == 722);
        // ASCII is written with 9 significant digits (<= 5e-10 relative), binary as float32
        // (<= 6e-8 relative): 1e-8 m on a 0.125 m wheel covers both.
        CHECK(maxCornerDistance(wheel, read) < 1e-8);
        const auto [read_closure, read_volume] = closureAndVolume(read);
        CHECK(read_closure < 1e-9);
        CHECK(read_volume == Approx(volume).epsilon(1e-6));
    }
    // Both files describe the same vertices to float precision (1e-8 m as above).
    CHECK(maxCornerDistance(readStl(ascii.path), readStl(binary.path)) < 1e-8);
}

TEST_CASE("A malformed STL names the file and the line", "[dem][stl]") {
    TempFile file("broken.stl");
    auto write = [&](const std::string& text) { std::ofstream(file.path) << text; };
    const std::string head = "solid broken\n facet normal 0 0 1\n  outer loop\n";

    write(head + "   vertex 0 0 0\n   vertex 1 zero 0\n   vertex 0 1 0\n  endloop\n endfacet\n"
                 "endsolid broken\n");
    CHECK_THROWS_WITH(readStl(file.path), Catch::Contains(file.path) && Catch::Contains("line 5") &&
                                              Catch::Contains("malformed vertex"));

    write(head + "   vertex 0 0 0\n   vertex 1 0 0\n  endloop\n endfacet\nendsolid broken\n");
    CHECK_THROWS_WITH(readStl(file.path), Catch::Contains(file.path) && Catch::Contains("line 6") &&
                                              Catch::Contains("2 vertices"));

    // Cut off after the first of two facets: refused, not read as one triangle.
    const std::string facet = " facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n"
                              "   vertex 0 1 0\n  endloop\n endfacet\n";
    write("solid cut\n" + facet + " facet normal 0 0 1\n  outer loop\n   vertex 0 0 1\n");
    CHECK_THROWS_WITH(readStl(file.path), Catch::Contains(file.path) &&
                                              Catch::Contains("without 'endsolid' after 1 complete") &&
                                              Catch::Contains("cut off"));
    write("solid two\n" + facet + "endsolid two\nsolid three\n" + facet + "endsolid three\n");
    CHECK_THROWS_WITH(readStl(file.path), Catch::Contains("line 10") &&
                                              Catch::Contains("text after 'endsolid'"));

    write("neither ascii nor binary");
    CHECK_THROWS_WITH(readStl(file.path), Catch::Contains(file.path));
    CHECK_THROWS_WITH(readStl(file.path + ".missing"), Catch::Contains("cannot open"));
}

TEST_CASE("the grain cutting deepest into a placed mesh is found with its overlap") {
    // A 40 mm square in the plane z = 0.1 m; grains of radius 2 mm below and beside it.
    const TriangleMesh square = makeRectangle(0.04, 0.04, 4, 4);
    std::vector<Vec3> world;
    for (const Vec3 &v : square.vertices_m)
        world.push_back(v + Vec3(0.0, 0.0, 0.1));
    const std::vector<double> radii(4, 0.002);
    std::vector<Vec3> centres{
        {0.0, 0.0, 0.099},    // 1 mm below the face: overlap (2 - 1) / 2 = 0.5
        {0.005, 0.0, 0.0985}, // 1.5 mm below: 0.25
        {0.0215, 0.0, 0.1},   // 1.5 mm beyond the edge, in its plane: 0.25
        {0.0, 0.0, 0.095},    // 5 mm below: untouched
    };
    const GrainOverlap deepest = deepestGrainOverlap(centres, radii, world, square);
    CHECK(deepest.particle == 0);
    CHECK(deepest.ratio == Approx(0.5).margin(1e-12));
    centres.erase(centres.begin());
    CHECK(deepestGrainOverlap(centres, {0.002, 0.002, 0.002}, world, square).ratio ==
          Approx(0.25).margin(1e-12));
    CHECK(deepestGrainOverlap({{0.0, 0.0, 0.095}}, {0.002}, world, square).ratio == 0.0);
}
