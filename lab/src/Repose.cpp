#include "grainlink/lab/Repose.hpp"

#include "grainlink/dem/Deposition.hpp"
#include "grainlink/dem/Progress.hpp"
#include "grainlink/dem/SteadySignal.hpp"
#include "grainlink/dem/TriangleMesh.hpp"
#include "grainlink/lab/BekkerFit.hpp"
#include "grainlink/lab/LabBed.hpp"
#include "grainlink/lab/LabConfig.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace grainlink::lab {

namespace fs = std::filesystem;
using dem::Vec3;

namespace {

/// Open tube (side wall only) of radius R and height H about the body z axis, bottom at z = 0.
/// Mesh contacts are two-sided, so grains inside touch it.
dem::TriangleMesh tubeMesh(double radius_m, double height_m, int segments) {
    dem::TriangleMesh mesh;
    for (int k = 0; k < segments; ++k) {
        const double a = 2.0 * M_PI * k / segments;
        mesh.vertices_m.emplace_back(radius_m * std::cos(a), radius_m * std::sin(a), 0.0);
        mesh.vertices_m.emplace_back(radius_m * std::cos(a), radius_m * std::sin(a), height_m);
    }
    for (int k = 0; k < segments; ++k) {
        const int b0 = 2 * k, t0 = b0 + 1, b1 = 2 * ((k + 1) % segments), t1 = b1 + 1;
        mesh.triangles.push_back({b0, t1, b1}); // normals towards the axis, where the grains are
        mesh.triangles.push_back({b0, t0, t1});
    }
    return mesh;
}

double meanKineticEnergy(const dem::DemSystem &sys) {
    const auto e = sys.energies();
    return (e.translational_J + e.rotational_J) /
           double(std::max<std::size_t>(1, sys.particles().size()));
}

} // namespace

ReposeScenario parseRepose(const config::ConfigNode &root) {
    ReposeScenario s;
    s.name = root["name"].text();
    s.soil = parseLabSoil(root, {"the repose test adds its own tube",
                                 {},
                                 "the fill is never cached (the tube stands in it)",
                                 "the fill is poured into the standing tube, which a "
                                 "compaction plate cannot enter"});
    const auto r = root["repose"];
    ReposeSpec &t = s.test;
    t.tube_radius_m = r["tube_radius_m"].positive();
    t.tube_height_m = r["tube_height_m"].positive();
    t.tube_segments = int(r.integer("tube_segments", 8, dem::kMaxMeshSegments, t.tube_segments));
    t.lift_speed_m_s = r["lift_speed_m_s"].positive();
    if (r.has("settle_kinetic_energy_J"))
        t.settle_kinetic_energy_J = r["settle_kinetic_energy_J"].positive();
    if (r.has("max_settle_time_s"))
        t.max_settle_time_s = r["max_settle_time_s"].positive();
    if (r.has("bin_width_m"))
        t.bin_width_m = r["bin_width_m"].positive();
    t.centre_m = parseCentre(r);
    r.finish();

    // The grains are inserted inside the tube: every corner of the region must be.
    const auto &d = s.soil.deposition;
    const Eigen::Vector2d centre = testCentre(s.soil, t.centre_m);
    double far = 0.0;
    for (double x : {d.region_lower_m.x(), d.region_upper_m.x()})
        for (double y : {d.region_lower_m.y(), d.region_upper_m.y()})
            far = std::max(far, std::hypot(x - centre.x(), y - centre.y()));
    if (far > t.tube_radius_m || d.region_upper_m.z() - d.region_lower_m.z() > t.tube_height_m) {
        std::ostringstream msg;
        msg << "the deposition region reaches " << far << " m from the tube axis and "
            << d.region_upper_m.z() - d.region_lower_m.z()
            << " m high: it must lie inside the tube (radius " << t.tube_radius_m << " m, height "
            << t.tube_height_m << " m)";
        r["tube_radius_m"].fail(msg.str());
    }
    root.finish();
    return s;
}

ReposeScenario loadRepose(const std::string &path) {
    return parseRepose(config::ConfigNode::loadFile(path));
}

void measureHeap(const std::vector<Eigen::Vector3d> &positions, const std::vector<double> &radii,
                 const Eigen::Vector2d &centre, double bin_width, ReposeResult &result) {
    double floor_z = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < positions.size(); ++i)
        floor_z = std::min(floor_z, positions[i].z() - radii[i]);
    std::vector<ProfileBin> bins;
    for (std::size_t i = 0; i < positions.size(); ++i) {
        const double rho = std::hypot(positions[i].x() - centre.x(), positions[i].y() - centre.y());
        const auto k = std::size_t(rho / bin_width);
        if (k >= bins.size())
            bins.resize(k + 1);
        bins[k].height_m = std::max(bins[k].height_m, positions[i].z() + radii[i] - floor_z);
        ++bins[k].grains;
    }
    for (std::size_t k = 0; k < bins.size(); ++k)
        bins[k].radius_m = (double(k) + 0.5) * bin_width;
    result.profile = bins;
    const auto top = std::max_element(bins.begin(), bins.end(), [](const auto &a, const auto &b) {
        return a.height_m < b.height_m;
    });
    const double h = top == bins.end() ? 0.0 : top->height_m;
    result.heap_height_m = h;
    // Heap flank: from the top outwards, bins between 20 % and 80 % of the top height (apex and
    // toe left out) and above one and a half grain diameters (the layer of single grains that
    // rolled out is not heap), fitted by a straight line h = a + s rho. Angle = atan(-s).
    const double r_max = radii.empty() ? 0.0 : *std::max_element(radii.begin(), radii.end());
    const double lower = std::max(0.2 * h, 3.0 * r_max);
    std::vector<double> x, y;
    for (auto it = top; it != bins.end(); ++it)
        if (it->height_m > lower && it->height_m < 0.8 * h) {
            x.push_back(it->radius_m);
            y.push_back(it->height_m);
        }
    result.flank_bins = x.size();
    if (!result.heapFormed()) {
        // A result, not a failure: the grains spread out instead of piling (report() says so).
        result.angle_deg = std::numeric_limits<double>::quiet_NaN();
        result.angle_half_width_95_deg = std::numeric_limits<double>::quiet_NaN();
        return;
    }
    const dem::LineFit line = dem::fitLine(x, y);
    const double slope = line.slope, se = line.slope_se;
    result.angle_deg = std::atan(-slope) * 180.0 / M_PI;
    // d(atan s)/ds = 1 / (1 + s^2)
    result.angle_half_width_95_deg =
        studentT975(int(x.size()) - 2) * se / (1.0 + slope * slope) * 180.0 / M_PI;
}

namespace {

/// The fill: the grains settled in the standing tube (body 0).
struct ReposeFill : LabBed {};

/// The repose test's steps of the lab skeleton (LabExperiment.hpp): the fill is the bed, the
/// lift the one run, the heap's flank line the fit.
struct ReposeExperiment {
    using Result = ReposeResult;
    const ReposeScenario &scenario;

    ReposeFill prepareBed(double progress_interval_s) const;
    Result start(const ReposeFill &) const { return {}; }
    std::vector<double> conditions() const { return {scenario.test.lift_speed_m_s}; }
    ReposeRun run(const ReposeFill &fill, double lift_speed_m_s, double progress_interval_s) const;
    void fit(Result &result) const {
        const ReposeRun &lift = result.runs.front();
        const double bin = scenario.test.bin_width_m > 0.0 ? scenario.test.bin_width_m
                                                           : 2.0 * result.bed.largest_radius_m;
        measureHeap(lift.positions_m, lift.radii_m,
                    testCentre(scenario.soil, scenario.test.centre_m), bin, result);
        if (!result.heapFormed())
            throw std::invalid_argument("no heap: the grains spread out (" +
                                        std::to_string(result.flank_bins) +
                                        " profile bins on a flank, 3 needed for an angle)");
    }
};

ReposeFill ReposeExperiment::prepareBed(double progress_interval_s) const {
    const auto start = std::chrono::steady_clock::now();
    const ReposeSpec &t = scenario.test;
    const auto &d = scenario.soil.deposition;
    const Eigen::Vector2d centre = testCentre(scenario.soil, t.centre_m);
    ReposeFill fill;
    fill.system = dem::makeSystem(scenario.soil);
    dem::DemSystem &sys = *fill.system;

    dem::RigidBodyState initial;
    initial.position_m = Vec3(centre.x(), centre.y(), d.region_lower_m.z());
    sys.addBody(dem::MeshBody("tube", tubeMesh(t.tube_radius_m, t.tube_height_m, t.tube_segments),
                              initial));

    // Fill the tube and let the column settle (the tube stands still meanwhile), under the
    // deposition's rolling law if it has its own: one fill for several laws.
    if (d.rolling)
        sys.setRolling(*d.rolling);
    dem::Progress progress("repose fill", progress_interval_s);
    const auto report = dem::deposit(sys, d, [&](const dem::DepositionReport &r) {
        progress.update(sys.time(), std::min(1.0, r.settle_time_s / d.max_settle_time_s),
                        sys.stepCount() * sys.particles().size());
    });
    std::fprintf(stderr, "[repose] %zu grains settled in the tube (%.3f s simulated)\n",
                 report.inserted, report.settle_time_s);
    if (d.rolling)
        sys.setRolling(dem::contactLaws(scenario.soil));
    fill.summary = measureBed(sys, scenario.soil,
                              {M_PI * t.tube_radius_m * t.tube_radius_m, d.region_lower_m.z()});
    fill.summary.wall_s = secondsSince(start);
    return fill;
}

ReposeRun ReposeExperiment::run(const ReposeFill &fill, double lift_speed_m_s,
                                double progress_interval_s) const {
    const auto start = std::chrono::steady_clock::now();
    const ReposeSpec &t = scenario.test;
    dem::DemSystem sys = *fill.system;
    const double dt = sys.settings().time_step_s;
    ReposeRun run;
    run.lift_speed_m_s = lift_speed_m_s;

    // Lift the tube by its own height: its bottom then clears any column it held.
    dem::RigidBodyState lifting = sys.body(0).state();
    lifting.linear_velocity_m_s = Vec3(0.0, 0.0, lift_speed_m_s);
    sys.setBodyMotion(0, dem::constantVelocity(lifting, sys.time()));
    const auto lift_steps = std::uint64_t(std::ceil(t.tube_height_m / (lift_speed_m_s * dt)));
    dem::Progress lift("repose lift", progress_interval_s);
    const std::uint64_t chunk = std::max<std::uint64_t>(1, std::llround(0.01 / dt));
    for (std::uint64_t done = 0; done < lift_steps;) {
        const std::uint64_t n = std::min(chunk, lift_steps - done);
        sys.run(n);
        done += n;
        lift.update(sys.time(), double(done) / double(lift_steps), done * sys.particles().size());
    }
    // Let the heap come to rest.
    const double settle_start = sys.time();
    while (true) {
        sys.run(chunk);
        run.final_kinetic_energy_per_grain_J = meanKineticEnergy(sys);
        run.settle_time_s = sys.time() - settle_start;
        if (run.final_kinetic_energy_per_grain_J < t.settle_kinetic_energy_J) {
            run.settled = true;
            break;
        }
        if (run.settle_time_s >= t.max_settle_time_s)
            break;
    }
    run.positions_m = sys.particles().position;
    run.radii_m = sys.particles().radius;
    run.wall_s = secondsSince(start);
    return run;
}

} // namespace

ReposeResult runRepose(const ReposeScenario &scenario, const LabRunOptions &options) {
    return runLabExperiment(ReposeExperiment{scenario}, options);
}

std::string ReposeResult::report() const {
    std::ostringstream out;
    out << std::setprecision(4);
    out << "Angle of repose (lifted cylinder)\n";
    out << "  " << bed.grains << " grains, largest radius " << bed.largest_radius_m * 1e3
        << " mm\n";
    out << "  heap " << heap_height_m * 1e3 << " mm high";
    for (const ReposeRun &lift : runs) // the one lift (none: a heap measured from positions)
        out << "; " << (lift.settled ? "settled" : "NOT settled (time limit)") << " "
            << lift.settle_time_s << " s after the lift, mean KE per grain "
            << lift.final_kinetic_energy_per_grain_J << " J";
    out << "\n";
    if (heapFormed())
        out << "  angle of repose " << angle_deg << " +- " << angle_half_width_95_deg
            << " deg (95 %, slope regression over " << flank_bins << " flank bins)\n";
    else
        out << "  no heap: the grains spread out; " << flank_bins
            << " profile bins on a flank (3 needed for an angle), see heap_profile.csv\n";
    out << "  wall time " << wall_s << " s\n";
    return out.str();
}

LabSummary ReposeResult::summary() const {
    LabSummary s{kTest, scenario, "lift_speed_m_s", bed, {}, fit_note, {}, wall_s};
    if (heapFormed())
        s.fits.push_back({"repose",
                          int(flank_bins) - 2,
                          {{"angle", "deg", angle_deg, angle_half_width_95_deg}}});
    for (const ReposeRun &lift : runs) {
        LabRunSummary r;
        r.values = {{"lift_speed_m_s", lift.lift_speed_m_s},
                    {"settle_time_s", lift.settle_time_s},
                    {"settled", lift.settled ? 1.0 : 0.0},
                    {"final_kinetic_energy_per_grain_J", lift.final_kinetic_energy_per_grain_J},
                    {"heap_height_m", heap_height_m},
                    {"flank_bins", double(flank_bins)},
                    {"wall_s", lift.wall_s}};
        std::vector<double> radius, height, grains;
        for (const auto &b : profile) {
            radius.push_back(b.radius_m);
            height.push_back(b.height_m);
            grains.push_back(double(b.grains));
        }
        r.curves = {{"radius_m", radius}, {"height_m", height}, {"grains", grains}};
        s.runs.push_back(r);
    }
    return s;
}

void ReposeResult::writeCsvs(const std::string &directory) const {
    auto csv = openCsv(directory, "heap_profile.csv", "radius_m,height_m,grains");
    for (const auto &b : profile)
        csv << b.radius_m << ',' << b.height_m << ',' << b.grains << '\n';
}

} // namespace grainlink::lab
