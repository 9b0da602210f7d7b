// Speed benchmark of the DEM core on the reference cases, run on exactly the bed that
// LIGGGHTS is given (bench/liggghts/): prints particle-steps per second, never asserts.
//   dem_bench prepare DIR            settle the 30,000-sphere bed (cached), write DIR/bed.data
//                                    (LIGGGHTS read_data) and DIR/cylinder.stl
//   dem_bench run DIR CASE THREADS [STEPS]   time CASE (settle | cylinder) on that bed
//   dem_bench snapshot DIR CASE THREADS [CALLS]   time DemSystem::saveState / restoreState
//                                    on CASE after the warm-up, and print the snapshot's size
#include "grainlink/dem/Checkpoint.hpp"
#include "grainlink/dem/Deposition.hpp"
#include "grainlink/dem/Progress.hpp"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

using namespace grainlink::dem;
namespace fs = std::filesystem;

namespace {

constexpr double kRadius = 0.0025, kDensity = 2400.0, kTimeStep = 5e-5;
const Vec3 kBoxUpper(0.6, 0.1, 0.4);
constexpr double kCylinderRadius = 0.125, kCylinderWidth = 0.1, kSpeed = 0.5, kSpin = 4.0;

/// Issue #2's reference case: Hertz with tangential history, e = 0.3, mu = 0.6, six walls.
std::unique_ptr<DemSystem> makeBenchSystem(int threads) {
    Material m;
    m.name = "bench";
    m.youngs_modulus_Pa = 3e6;
    m.poisson_ratio = 0.2;
    m.density_kg_m3 = kDensity;
    ContactLaw law;
    law.damping = DampingRestitution{0.3};
    law.tangential = TangentialMindlin{0.6};
    DemSettings s;
    s.time_step_s = kTimeStep;
    s.gravity_m_s2 = Vec3(0, 0, -9.81);
    s.skin_m = 0.001; // as LIGGGHTS' "neighbor 0.001 bin"
    s.threads = threads;
    auto sys = std::make_unique<DemSystem>(law, std::vector<Material>{m}, s);
    for (int k = 0; k < 6; ++k) {
        PlaneWall w;
        w.name = "box" + std::to_string(k);
        w.normal = Vec3::Zero();
        w.normal[k / 2] = (k % 2 == 0) ? 1.0 : -1.0;
        w.point_m = (k % 2 == 0) ? Vec3::Zero() : kBoxUpper;
        sys->addPlane(w);
    }
    return sys;
}

std::string bedCheckpoint(const fs::path &dir) {
    return (dir / "bed.checkpoint").string();
}

int prepare(const fs::path &dir) {
    fs::create_directories(dir);
    auto sys = makeBenchSystem(2);
    if (!fs::exists(bedCheckpoint(dir))) {
        DepositionSpec spec;
        spec.region_lower_m = Vec3::Zero();
        spec.region_upper_m = Vec3(0.6, 0.1, 0.16); // 0.12 fits only 29,489 grains (the 99 % rule)
        spec.count = 30000;
        spec.radius.kind = RadiusDistribution::Kind::Constant;
        spec.radius.min_m = spec.radius.max_m = kRadius;
        spec.seed = 2013;
        spec.settle_kinetic_energy_J = 1e-10;
        spec.max_settle_time_s = 2.0;
        Progress progress("bench bed", 10.0);
        const auto report = deposit(*sys, spec, [&](const DepositionReport &r) {
            progress.update(sys->time(), r.settle_time_s / spec.max_settle_time_s,
                            sys->stepCount() * sys->particles().size());
        });
        std::fprintf(
            stderr, "bed: %zu particles settled in %.2f s simulated (KE/particle %.2g J)\n",
            report.inserted, report.settle_time_s, report.final_kinetic_energy_per_particle_J);
        writeCheckpoint(*sys, bedCheckpoint(dir));
    } else {
        readCheckpoint(*sys, bedCheckpoint(dir));
    }
    const ParticleStore &p = sys->particles();
    std::ofstream data(dir / "bed.data");
    data.precision(17);
    data << "grainlink settled bed for the speed benchmark\n\n"
         << p.size() << " atoms\n1 atom types\n\n0 " << kBoxUpper.x() << " xlo xhi\n0 "
         << kBoxUpper.y() << " ylo yhi\n0 " << kBoxUpper.z() << " zlo zhi\n\nAtoms\n\n";
    for (std::size_t i = 0; i < p.size(); ++i)
        data << i + 1 << " 1 " << 2.0 * p.radius[i] << ' ' << kDensity << ' ' << p.position[i].x()
             << ' ' << p.position[i].y() << ' ' << p.position[i].z() << '\n';
    data << "\nVelocities\n\n";
    for (std::size_t i = 0; i < p.size(); ++i)
        data << i + 1 << ' ' << p.velocity[i].x() << ' ' << p.velocity[i].y() << ' '
             << p.velocity[i].z() << ' ' << p.angular_velocity[i].x() << ' '
             << p.angular_velocity[i].y() << ' ' << p.angular_velocity[i].z() << '\n';
    TriangleMesh cylinder = makeCylinder(kCylinderRadius, kCylinderWidth, 360);
    writeStlAscii(cylinder, (dir / "cylinder.stl").string(), "cylinder");
    std::printf("prepared %s/bed.data (%zu particles) and cylinder.stl (%zu triangles)\n",
                dir.c_str(), p.size(), cylinder.triangleCount());
    return 0;
}

/// The cylinder's start centre, computed as bench/liggghts/run.sh does: x = 0.15, bottom 3 cm
/// below the 99th percentile of grain tops; grains inside its start volume are removed.
Vec3 placeCylinder(DemSystem &sys) {
    ParticleStore &p = sys.particles();
    std::vector<double> tops;
    for (std::size_t i = 0; i < p.size(); ++i)
        tops.push_back(p.position[i].z() + p.radius[i]);
    std::sort(tops.begin(), tops.end());
    const Vec3 centre(0.15, 0.5 * kBoxUpper.y(),
                      tops[std::size_t(0.99 * double(tops.size())) - 1] - 0.03 + kCylinderRadius);
    const double reach = kCylinderRadius + kRadius;
    std::vector<std::size_t> keep;
    for (std::size_t i = 0; i < p.size(); ++i) {
        const double dx = p.position[i].x() - centre.x(), dz = p.position[i].z() - centre.z();
        if (dx * dx + dz * dz >= reach * reach)
            keep.push_back(i);
    }
    ParticleStore kept;
    kept.setNextId(p.nextId());
    for (std::size_t i : keep) {
        ParticleSpec s;
        s.position_m = p.position[i];
        s.velocity_m_s = p.velocity[i];
        s.angular_velocity_rad_s = p.angular_velocity[i];
        s.radius_m = p.radius[i];
        s.density_kg_m3 = kDensity;
        kept.add(s);
    }
    p = std::move(kept);
    return centre;
}

/// CASE on the prepared bed, warmed up; null for an unknown case.
std::unique_ptr<DemSystem> makeCase(const fs::path &dir, const std::string &which, int threads) {
    auto sys = makeBenchSystem(threads);
    {
        // Start from the exported bed at rest, as LIGGGHTS does (contact histories from zero).
        auto bed = makeBenchSystem(1);
        readCheckpoint(*bed, bedCheckpoint(dir));
        for (std::size_t i = 0; i < bed->particles().size(); ++i) {
            ParticleSpec s;
            s.position_m = bed->particles().position[i];
            s.velocity_m_s = bed->particles().velocity[i];
            s.angular_velocity_rad_s = bed->particles().angular_velocity[i];
            s.radius_m = kRadius;
            s.density_kg_m3 = kDensity;
            sys->particles().add(s);
        }
    }
    if (which == "cylinder") {
        RigidBodyState start;
        start.position_m = placeCylinder(*sys);
        start.linear_velocity_m_s = Vec3(kSpeed, 0, 0);
        start.angular_velocity_rad_s = Vec3(0, kSpin, 0);
        sys->addBody(
            MeshBody("cylinder", makeCylinder(kCylinderRadius, kCylinderWidth, 360), start),
            constantVelocity(start));
    } else if (which != "settle") {
        std::fprintf(stderr, "unknown case '%s' (settle | cylinder)\n", which.c_str());
        return nullptr;
    }
    sys->run(200); // warm-up, as in the LIGGGHTS inputs
    return sys;
}

double secondsSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

int run(const fs::path &dir, const std::string &which, int threads, std::uint64_t steps) {
    auto sys = makeCase(dir, which, threads);
    if (!sys)
        return 2;
    sys->timer().reset();
    const auto t0 = std::chrono::steady_clock::now();
    sys->run(steps);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double rate = double(sys->particles().size()) * double(steps) / seconds;
    std::fprintf(stderr, "%s", sys->timer().table().c_str());
    std::fprintf(stderr,
                 "per particle: %.2f listed pairs, %.2f contacts, %.3f wall contacts; %llu list "
                 "builds\n",
                 double(sys->neighbourPairs()) / double(sys->particles().size()),
                 double(sys->contactCount()) / double(sys->particles().size()),
                 double(sys->wallContactCount()) / double(sys->particles().size()),
                 static_cast<unsigned long long>(sys->neighbourBuilds()));
    // Digest of the final state: variants of the code that must not change the results are
    // compared by it (FNV-1a over the bytes of positions, velocities and spins).
    std::uint64_t digest = 1469598103934665603ull;
    for (const auto *array : {&sys->particles().position, &sys->particles().velocity,
                              &sys->particles().angular_velocity}) {
        const auto *bytes = reinterpret_cast<const unsigned char *>(array->data());
        for (std::size_t k = 0; k < array->size() * sizeof(Vec3); ++k)
            digest = (digest ^ bytes[k]) * 1099511628211ull;
    }
    std::fprintf(stderr, "state digest %016llx\n", static_cast<unsigned long long>(digest));
    std::printf("GRAINLINK case=%s threads=%d particles=%zu steps=%llu seconds=%.4f "
                "particle_steps_per_s=%.0f\n",
                which.c_str(), threads, sys->particles().size(),
                static_cast<unsigned long long>(steps), seconds, rate);
    return 0;
}

/// The in-memory snapshot that implicit coupling takes at every window's start and restores at
/// every further iteration: its cost per call beside a step's.
int snapshot(const fs::path &dir, const std::string &which, int threads, int calls) {
    auto sys = makeCase(dir, which, threads);
    if (!sys)
        return 2;
    const std::uint64_t steps = 50;
    auto t0 = std::chrono::steady_clock::now();
    sys->run(steps);
    const double step_s = secondsSince(t0) / double(steps);
    DemSystem::State state = sys->saveState();
    t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < calls; ++k)
        state = sys->saveState(); // a fresh value each time, as a driver would take it
    const double save_s = secondsSince(t0) / calls;
    t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < calls; ++k)
        sys->restoreState(state);
    const double restore_s = secondsSince(t0) / calls;
    sys->run(1); // the restored system steps on
    std::printf("GRAINLINK snapshot case=%s threads=%d particles=%zu contacts=%zu bytes=%zu "
                "save_ms=%.3f restore_ms=%.3f step_ms=%.3f\n",
                which.c_str(), threads, sys->particles().size(), sys->contactCount(),
                state.bytes(), 1e3 * save_s, 1e3 * restore_s, 1e3 * step_s);
    return 0;
}

} // namespace

int main(int argc, char **argv) {
    try {
        const std::string verb = argc > 1 ? argv[1] : "";
        if (verb == "prepare" && argc == 3)
            return prepare(argv[2]);
        if (verb == "run" && (argc == 5 || argc == 6))
            return run(argv[2], argv[3], std::stoi(argv[4]),
                       argc == 6 ? std::stoull(argv[5]) : 2000);
        if (verb == "snapshot" && (argc == 5 || argc == 6))
            return snapshot(argv[2], argv[3], std::stoi(argv[4]),
                            argc == 6 ? std::max(1, std::stoi(argv[5])) : 20);
        std::fprintf(stderr, "usage: dem_bench prepare DIR | dem_bench run DIR CASE THREADS "
                             "[STEPS] | dem_bench snapshot DIR CASE THREADS [CALLS]\n");
        return 2;
    } catch (const std::exception &e) {
        std::fprintf(stderr, "dem_bench: error: %s\n", e.what());
        return 1;
    }
}
