// Sphere-on-plane and sphere-on-mesh contacts: Hertz impact with R* = r, m* = m, and a flat mesh
// that must act exactly like the plane it lies in (docs/physics.md §2.1, §5).
#include "Fixtures.hpp"

#include <catch2/catch.hpp>

using namespace grainlink::dem;
using namespace grainlink::dem::testing;

namespace {

/// The same boundary twice: the plane z = 0 or a flat mesh in z = 0 (nx x ny cells of 2 triangles).
enum class Floor { Plane, Mesh };

DemSystem makeFloor(Floor floor, const ContactLaw& law, const DemSettings& settings,
                    double size_m = 0.2, int cells = 10) {
    DemSystem sys(law, {kMaterial}, settings);
    if (floor == Floor::Plane) {
        PlaneWall plane;
        plane.name = "floor";
        sys.addPlane(plane);
    } else {
        sys.addBody(MeshBody("floor", makeRectangle(size_m, size_m, cells, cells), {}));
    }
    return sys;
}

Vec3 floorForce(const DemSystem& sys) {
    return sys.planes().empty() ? sys.body(0).force_N : sys.planeForce(0);
}

/// Overlap of a grain resting on a wall of its own material under its weight.
double restingWallOverlap(double weight_N) {
    return std::pow(weight_N / (4.0 / 3.0 * effectiveModulus(kMaterial) * std::sqrt(kRadius)),
                    2.0 / 3.0);
}

struct Impact {
    double duration_s = 0.0, max_overlap_m = 0.0, restitution = 0.0;
};

Impact dropOn(Floor floor, double restitution, const Vec3& at, double speed, double dt) {
    DemSystem sys = makeFloor(floor, hertzRestitution(restitution, 0.0), quietSettings(dt));
    const double gap = 0.01 * kRadius;
    sys.particles().add(
        sphere(at + Vec3(0, 0, kRadius + gap), kRadius, kMaterial.density_kg_m3, {0, 0, -speed}));
    Impact out;
    bool touching = false;
    double start = 0.0;
    for (int k = 0; k < 1000000; ++k) {
        sys.step();
        const double overlap = kRadius - sys.particles().position[0].z();
        out.max_overlap_m = std::max(out.max_overlap_m, overlap);
        if (!touching && overlap > 0.0) {
            touching = true;
            start = sys.time();
        } else if (touching && overlap <= 0.0) {
            out.duration_s = sys.time() - start;
            out.restitution = sys.particles().velocity[0].z() / speed;
            return out;
        }
    }
    return out;
}

} // namespace

TEST_CASE("Sphere on plane and on flat mesh: Hertz impact with R* = r, m* = m",
          "[dem][contact][walls]") {
    const double speed = 0.5;
    const double m = sphereMass(kRadius, kMaterial.density_kg_m3);
    const double e_star = effectiveModulus(kMaterial); // wall of the grains' own material
    const HertzImpact theory{e_star, kRadius, m, speed};
    const double dt = theory.duration() / 2000.0;

    // Impact points on the mesh: inside a triangle, on an edge, on a vertex shared by 6 triangles.
    const std::vector<std::pair<Floor, Vec3>> cases = {{Floor::Plane, Vec3(0.003, 0.001, 0)},
                                                       {Floor::Mesh, Vec3(0.003, 0.001, 0)},
                                                       {Floor::Mesh, Vec3(0.005, 0.0, 0)},
                                                       {Floor::Mesh, Vec3(0.0, 0.0, 0)}};
    for (const auto& [floor, at] : cases) {
        INFO((floor == Floor::Plane ? "plane" : "mesh") << ", impact at " << at.transpose());
        const Impact elastic = dropOn(floor, 1.0, at, speed, dt);
        // Duration: 2000 steps per contact, the start and end are found to one step (5e-4), the
        // closed form is exact: 0.2 %. Peak overlap and rebound are smooth: 1e-3.
        CHECK(elastic.duration_s == Approx(theory.duration()).epsilon(2e-3));
        CHECK(elastic.max_overlap_m == Approx(theory.maxOverlap()).epsilon(1e-3));
        CHECK(elastic.restitution == Approx(1.0).margin(1e-4));
        // Damped: the entered restitution with R* = r, m* = m (RestitutionTest: within 2e-4).
        CHECK(dropOn(floor, 0.5, at, speed, dt).restitution == Approx(0.5).margin(2e-4));
    }
}

TEST_CASE("A flat mesh acts exactly like its plane for a sliding and rolling sphere",
          "[dem][contact][walls][mesh]") {
    // A sphere lands on the floor with a horizontal velocity and spin, slides, is brought to
    // rolling by friction and rolls on, crossing triangle edges and vertices of the mesh. Plane
    // and mesh runs step in lockstep. The contact point, normal, overlap and history must agree;
    // the only difference allowed is round-off in the closest-point arithmetic (~1e-16 relative
    // per step, accumulated over 3e4 steps of a non-chaotic motion), so the forces must agree to
    // 1e-9 of the weight and the final states to 1e-9 relative. A second, tilted force from an
    // edge of a neighbouring triangle (the error this test catches) is ~1e-2 of the weight.
    ContactLaw mindlin = hertzRestitution(0.5, 0.3);
    ContactLaw linear = hertzViscous(0.5, 1000.0, 30.0, 20.0);
    std::get<TangentialLinear>(linear.tangential).damping_N_s_m = 0.3;
    linear.rolling = RollingEpsd{0.05};
    struct Path {
        const char* what;
        Vec3 start, velocity, spin;
    };
    // Mesh of 40 x 40 cells, 5 mm = one radius each: vertices at -0.1 + 0.005 k, cell
    // diagonals along +x+y. Paths start on vertices.
    const std::vector<Path> paths = {
        {"along diagonal edges, through vertices", {-0.06, -0.06, 0}, {0.2, 0.2, 0}, {10, -10, 0}},
        {"generic direction across edges", {-0.07, -0.03, 0}, {0.25, 0.11, 0}, {0, 0, 40}},
        {"through vertices across edges", {-0.04, -0.08, 0}, {0.1, 0.2, 0}, {-15, 5, 20}},
    };
    const double m = sphereMass(kRadius, kMaterial.density_kg_m3);
    const double weight = m * 9.81;
    DemSettings settings;
    settings.time_step_s = 1e-5;
    for (const ContactLaw* law : {&mindlin, &linear}) {
        for (const Path& path : paths) {
            INFO(law->describe() << "; path " << path.what);
            DemSystem plane = makeFloor(Floor::Plane, *law, settings);
            DemSystem mesh = makeFloor(Floor::Mesh, *law, settings, 0.2, 40);
            for (DemSystem* sys : {&plane, &mesh}) {
                ParticleSpec s =
                    sphere(path.start + Vec3(0, 0, kRadius - restingWallOverlap(weight)), kRadius,
                           kMaterial.density_kg_m3, path.velocity);
                s.angular_velocity_rad_s = path.spin;
                sys->particles().add(s);
            }
            std::vector<bool> loaded(mesh.body(0).mesh().triangleCount(), false);
            double worst_force = 0.0, worst_reaction = 0.0;
            for (int k = 0; k < 30000; ++k) {
                plane.step();
                mesh.step();
                worst_force = std::max(
                    worst_force, (plane.particles().force[0] - mesh.particles().force[0]).norm());
                worst_reaction =
                    std::max(worst_reaction, (floorForce(plane) - floorForce(mesh)).norm());
                if (k % 100 != 0)
                    continue; // a 5 mm cell takes >= 2000 steps to cross
                const auto& v = mesh.body(0).worldVertices();
                const Vec3& x = mesh.particles().position[0];
                for (std::size_t t = 0; t < loaded.size(); ++t) {
                    const auto& tri = mesh.body(0).mesh().triangles[t];
                    const Vec3 q = closestPointOnTriangle(x, v[tri[0]], v[tri[1]], v[tri[2]]);
                    loaded[t] = loaded[t] || (x - q).norm() < kRadius;
                }
            }
            CHECK(worst_force < 1e-9 * weight);
            CHECK(worst_reaction < 1e-9 * weight);
            const ParticleStore &a = plane.particles(), &b = mesh.particles();
            const double travelled = (a.position[0] - path.start).norm();
            CHECK((a.position[0] - b.position[0]).norm() < 1e-9 * travelled);
            CHECK((a.velocity[0] - b.velocity[0]).norm() < 1e-9 * path.velocity.norm());
            CHECK((a.angular_velocity[0] - b.angular_velocity[0]).norm() <
                  1e-9 * path.velocity.norm() / kRadius);
            // The test is only as good as the ground it covers: several cm, tens of triangles
            // touched.
            CHECK(travelled > 0.035);
            CHECK(std::count(loaded.begin(), loaded.end(), true) >= 20);
            // And it has gone from sliding (slip ~ v) to rolling: contact point nearly at rest,
            // up to the decaying oscillation of the tangential spring (measured <= 2e-3 v).
            const Vec3 slip = a.velocity[0] + a.angular_velocity[0].cross(Vec3(0, 0, -kRadius));
            CHECK(slip.head<2>().norm() < 1e-2 * a.velocity[0].norm());
        }
    }
}

TEST_CASE("A grain under a disc's centre, in reach of every fan triangle, feels the face it "
          "presses on",
          "[dem][contact][walls][mesh]") {
    // The bevameter's plate: a closed disc whose bottom cap is a fan of 48 triangles around a
    // centre vertex. A grain pressing on the cap near the centre has every fan triangle within
    // its radius: 48 touches, more than a particle keeps (16). The nearest (the face under the
    // grain) must be among those kept, wherever the grain is around the centre: the force must be
    // the plane's. Keeping the first 16 candidates instead (fan triangles 0..15 by index) lost the
    // face under a grain in the other 32 wedges: only a far, tilted edge contact was left (in the
    // lab bevameter ~2 N where Hertz gives ~60 N), the plate sank into the grain and the run
    // stopped at overlap 0.74 r "against a wall", a grain 1.4 mm from a 20 mm plate's centre.
    const int segments = 48;
    const double disc_radius = 10.0 * kRadius, thickness = 2.0 * kRadius;
    TriangleMesh disc = makeCylinder(disc_radius, thickness, segments);
    for (Vec3& v : disc.vertices_m)
        v = Vec3(v.x(), -v.z(), v.y() + 0.5 * thickness); // axis z, bottom cap in z = 0
    const ContactLaw law = hertzViscous(0.1, 1000.0, 30.0, 20.0);
    const DemSettings settings = quietSettings(1e-7);
    const double overlap = 0.2 * kRadius, off_centre = 0.3 * kRadius;
    for (int wedge = 0; wedge < segments; ++wedge) {
        // Cap triangle k spans the angles [k, k + 1] * 2 pi / segments (measured x -> -y here).
        const double a = 2.0 * M_PI * (wedge + 0.5) / segments;
        const Vec3 at(off_centre * std::cos(a), -off_centre * std::sin(a), -(kRadius - overlap));
        INFO("wedge " << wedge);
        DemSystem plane(law, {kMaterial}, settings), mesh(law, {kMaterial}, settings);
        PlaneWall bottom;
        bottom.name = "bottom";
        bottom.normal = Vec3(0, 0, -1);
        plane.addPlane(bottom);
        mesh.addBody(MeshBody("disc", disc, {}));
        for (DemSystem* sys : {&plane, &mesh})
            sys->particles().add(sphere(at, kRadius, kMaterial.density_kg_m3));
        plane.step();
        mesh.step();
        // Every fan triangle is in reach: the grain is nearer the centre vertex than its radius.
        REQUIRE(std::hypot(off_centre, kRadius - overlap) < kRadius);
        const Vec3 expected = plane.particles().force[0];
        REQUIRE(expected.z() < -1.0); // Hertz at 0.2 r: a few N, pushing the grain down
        CHECK((mesh.particles().force[0] - expected).norm() < 1e-9 * expected.norm());
        CHECK((mesh.body(0).force_N + expected).norm() < 1e-9 * expected.norm());
        CHECK(mesh.maxOverlapRatio() == Approx(plane.maxOverlapRatio()).epsilon(1e-9));
    }
}

TEST_CASE("An overlap beyond max_overlap_ratio names the plane or the mesh body it is against",
          "[dem][contact][walls][mesh]") {
    // Both are walls to the contact law, but a box's side and a plate call for different looks:
    // the message used to say "against a wall" for either.
    const ContactLaw law = hertzViscous(0.1, 1000.0, 30.0, 20.0);
    const DemSettings settings = quietSettings(1e-7);
    const Vec3 deep(0.001, 0.002, kRadius - 0.5 * kRadius); // 0.5 r into z = 0, from above
    const auto message = [&](DemSystem& sys) {
        sys.particles().add(sphere(deep, kRadius, kMaterial.density_kg_m3));
        try {
            sys.step();
        } catch (const SimulationError& e) {
            CHECK(e.quantity == "overlap");
            return std::string(e.what());
        }
        return std::string("no error");
    };
    DemSystem plane(law, {kMaterial}, settings), mesh(law, {kMaterial}, settings);
    PlaneWall floor;
    floor.name = "bin.zmin";
    plane.addPlane(floor);
    mesh.addBody(MeshBody("plate", makeRectangle(0.1, 0.1, 4, 4), {}));
    const std::string at_plane = message(plane), at_mesh = message(mesh);
    INFO(at_plane << "\n" << at_mesh);
    CHECK(at_plane.find("= 0.5 of the radius against plane 'bin.zmin' exceeds") !=
          std::string::npos);
    CHECK(at_mesh.find("= 0.5 of the radius against body 'plate' exceeds") != std::string::npos);
}
