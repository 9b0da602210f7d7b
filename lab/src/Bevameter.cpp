#include "grainlink/lab/Bevameter.hpp"
#include "grainlink/config/Number.hpp"

#include "grainlink/dem/Progress.hpp"
#include "grainlink/dem/ScenarioRun.hpp"
#include "grainlink/dem/TriangleMesh.hpp"
#include "grainlink/lab/LabBed.hpp"
#include "grainlink/lab/LabConfig.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace grainlink::lab {

namespace fs = std::filesystem;
using dem::Vec3;

namespace {

/// Flat closed disc of radius R and thickness t, axis z, bottom face at z = 0.
dem::TriangleMesh plateMesh(double radius_m, double thickness_m, int segments) {
    dem::TriangleMesh mesh = dem::makeCylinder(radius_m, thickness_m, segments);
    for (Vec3 &v : mesh.vertices_m)
        v = Vec3(v.x(), -v.z(), v.y() + 0.5 * thickness_m); // cylinder axis y -> z
    return mesh;
}

} // namespace

BevameterScenario parseBevameter(const config::ConfigNode &root) {
    BevameterScenario s;
    s.name = root["name"].text();
    s.soil = parseLabSoil(root, {"the bevameter adds its own plate", {}, {}, {}});
    const auto b = root["bevameter"];
    BevameterSpec &t = s.test;
    t.plate_radii_m = b["plate_radii_m"].positives();
    if (b.has("plate_thickness_m"))
        t.plate_thickness_m = b["plate_thickness_m"].positive();
    t.plate_segments = int(b.integer("plate_segments", 8, dem::kMaxMeshSegments, t.plate_segments));
    if (b.has("plate_friction_coefficient"))
        t.plate_friction_coefficient = b["plate_friction_coefficient"].nonNegative();
    t.speed_m_s = b["speed_m_s"].positive();
    t.max_sinkage_m = b["max_sinkage_m"].positive();
    if (b.has("start_clearance_m"))
        t.start_clearance_m = b["start_clearance_m"].nonNegative();
    if (b.has("sample_interval_s"))
        t.sample_interval_s = b["sample_interval_s"].positive();
    if (b.has("min_resolution"))
        t.min_resolution = b["min_resolution"].positive();
    t.centre_m = parseCentre(b);
    if (b.has("fit_min_sinkage_m"))
        t.fit_min_sinkage_m = b["fit_min_sinkage_m"].number();
    b.finish();

    // Resolution, seed eq. 11 with L_min = 2 R: Gamma = R / r_max.
    const double r_max = s.soil.deposition.radius.largest();
    for (double r : t.plate_radii_m)
        if (r / r_max < t.min_resolution - 1e-12) {
            std::ostringstream msg;
            msg << "plate radius " << r << " m over the largest grain radius " << r_max
                << " m is Gamma = " << r / r_max << " < min_resolution " << t.min_resolution
                << " (seed: Gamma >= 10 for bevameter tests); use larger plates or finer grains";
            b["plate_radii_m"].fail(msg.str());
        }
    for (double r : t.plate_radii_m)
        refuseBeyondBed(b["plate_radii_m"], s.soil, t.centre_m, r, "plate");
    root.finish();
    return s;
}

BevameterScenario loadBevameter(const std::string &path) {
    return parseBevameter(config::ConfigNode::loadFile(path));
}

PressureSinkageCurve PlateRun::curve() const {
    PressureSinkageCurve c;
    c.plate_radius_m = plate_radius_m;
    for (const auto &s : samples) {
        c.sinkage_m.push_back(s.sinkage_m);
        c.pressure_Pa.push_back(s.pressure_Pa);
    }
    return c;
}

namespace {

/// The bevameter's steps of the lab skeleton (LabExperiment.hpp): one plate per condition.
struct BevameterExperiment {
    using Result = BevameterResult;
    const BevameterScenario &scenario;

    LabBed prepareBed(double progress_interval_s) const {
        return prepareLabBed(scenario.soil, regionFootprint(scenario.soil), progress_interval_s);
    }
    Result start(const LabBed &) const { return {}; }
    std::vector<double> conditions() const { return scenario.test.plate_radii_m; }
    PlateRun run(const LabBed &bed, double radius, double progress_interval_s) const;
    void fit(Result &result) const {
        std::vector<PressureSinkageCurve> curves;
        for (const auto &p : result.runs)
            curves.push_back(p.curve());
        result.fit = fitBekker(curves, scenario.test.fit_min_sinkage_m);
    }
};

PlateRun BevameterExperiment::run(const LabBed &bed, double radius,
                                  double progress_interval_s) const {
    const auto plate_start = std::chrono::steady_clock::now();
    const BevameterSpec &t = scenario.test;
    const double surface = bed.summary.surface_m;
    const Vec3 lower = scenario.soil.deposition.region_lower_m;
    const Vec3 upper = scenario.soil.deposition.region_upper_m;
    const Eigen::Vector2d centre = testCentre(scenario.soil, t.centre_m);
    const double dt = bed.summary.time_step_s;
    dem::DemSystem sys = *bed.system; // every plate presses into the same settled bed
    PlateRun run;
    run.plate_radius_m = radius;
    run.resolution = radius / bed.summary.largest_radius_m;
    run.surface_m = surface;
    run.wall_gap_m = std::min({centre.x() - radius - lower.x(), upper.x() - centre.x() - radius,
                               centre.y() - radius - lower.y(), upper.y() - centre.y() - radius});
    run.depth_below_m = surface - t.max_sinkage_m - lower.z();

    const double thickness = t.plate_thickness_m > 0.0 ? t.plate_thickness_m : 0.2 * radius;
    // Start above every grain under the plate (the surface is a percentile: a few grains stick
    // out of it), so the plate never appears inside a grain.
    const double highest = highestGrainUnder(sys.particles(), centre, radius, surface);
    dem::RigidBodyState initial;
    initial.position_m = Vec3(centre.x(), centre.y(), highest + t.start_clearance_m);
    initial.linear_velocity_m_s = Vec3(0.0, 0.0, -t.speed_m_s);
    std::fprintf(stderr,
                 "[bevameter] R = %s: bed surface %.5f m, highest grain under the plate "
                 "%.5f m, plate starts at %.5f m\n",
                 config::millimetres(radius).c_str(), surface, highest, initial.position_m.z());
    dem::MeshBody plate("plate", plateMesh(radius, thickness, t.plate_segments), initial);
    plate.friction_coefficient = t.plate_friction_coefficient;
    const double z0 = initial.position_m.z(), v = t.speed_m_s;
    sys.addBody(std::move(plate), dem::constantVelocity(initial, sys.time())); // down
    sys.prepare();

    const auto total_steps = std::uint64_t(
        std::ceil((initial.position_m.z() - surface + t.max_sinkage_m) / (t.speed_m_s * dt)));
    const auto steps_per_sample =
        std::max<std::uint64_t>(1, std::llround(t.sample_interval_s / dt));
    const double area = M_PI * radius * radius;
    dem::Progress progress("bevameter R=" + config::millimetres(radius), progress_interval_s);
    std::uint64_t done = 0;
    while (done < total_steps) {
        const std::uint64_t n = std::min(steps_per_sample, total_steps - done);
        const MeanLoad load = observeInterval(sys, n, {0})[0];
        done += n;
        BevameterSample s;
        s.time_s = (double(done) - 0.5 * double(n)) * dt;
        s.sinkage_m = surface - (z0 - v * s.time_s);
        s.force_N = load.force_N.z();
        s.pressure_Pa = s.force_N / area;
        run.samples.push_back(s);
        progress.update(sys.time(), double(done) / double(total_steps),
                        done * sys.particles().size(),
                        "sinkage " + config::millimetres(s.sinkage_m) + ", p " +
                            std::to_string(s.pressure_Pa) + " Pa");
    }
    run.steps = done;
    run.wall_s = secondsSince(plate_start);
    std::fprintf(stderr, "[bevameter] R = %s: %llu steps in %.1f s, p(%s) = %.4g Pa\n",
                 config::millimetres(radius).c_str(), static_cast<unsigned long long>(done),
                 run.wall_s, config::millimetres(run.samples.back().sinkage_m).c_str(),
                 run.samples.back().pressure_Pa);
    return run;
}

} // namespace

BevameterResult runBevameter(const BevameterScenario &scenario, const LabRunOptions &options) {
    return runLabExperiment(BevameterExperiment{scenario}, options);
}

std::string BevameterResult::report() const {
    std::ostringstream out;
    out << std::setprecision(5);
    out << "Virtual bevameter (pressure-sinkage)\n";
    writeBedLine(out, bed);
    for (const auto &p : runs) {
        out << "  plate R = " << config::millimetres(p.plate_radius_m)
            << ": Gamma = R/r_max = " << p.resolution << ", rim to region side "
            << config::millimetres(p.wall_gap_m) << " (" << p.wall_gap_m / (2 * p.plate_radius_m)
            << " diameters), bed under the plate at the end "
            << config::millimetres(p.depth_below_m) << "; " << p.steps << " steps, " << p.wall_s
            << " s wall; final p = " << p.samples.back().pressure_Pa
            << " Pa at z = " << config::millimetres(p.samples.back().sinkage_m) << "\n";
    }
    if (fit)
        out << fit->describe();
    else
        out << "  no Bekker fit: " << fit_note << "\n";
    out << "  total wall time " << wall_s << " s\n";
    return out.str();
}

LabSummary BevameterResult::summary() const {
    LabSummary s{kTest, scenario, "plate_radius_m", bed, {}, fit_note, {}, wall_s};
    if (fit) {
        const auto &f = *fit;
        s.fits.push_back({"bekker",
                          f.degrees_of_freedom,
                          {{"k_c", "N/m^(n+1)", f.parameters.k_c, f.half_width_95[0]},
                           {"k_phi", "N/m^(n+2)", f.parameters.k_phi, f.half_width_95[1]},
                           {"n", "-", f.parameters.n, f.half_width_95[2]}}});
    }
    for (const auto &p : runs) {
        LabRunSummary r;
        r.values = {{"plate_radius_m", p.plate_radius_m},
                    {"resolution", p.resolution},
                    {"surface_m", p.surface_m},
                    {"wall_gap_m", p.wall_gap_m},
                    {"depth_below_m", p.depth_below_m},
                    {"steps", double(p.steps)},
                    {"wall_s", p.wall_s}};
        std::vector<double> time, sinkage, force, pressure;
        for (const auto &x : p.samples) {
            time.push_back(x.time_s);
            sinkage.push_back(x.sinkage_m);
            force.push_back(x.force_N);
            pressure.push_back(x.pressure_Pa);
        }
        r.curves = {{"time_s", time},
                    {"sinkage_m", sinkage},
                    {"force_N", force},
                    {"pressure_Pa", pressure}};
        s.runs.push_back(r);
    }
    return s;
}

void BevameterResult::writeCsvs(const std::string &directory) const {
    const fs::path dir(directory);
    {
        auto csv = openCsv(dir, "pressure_sinkage.csv",
                           "plate_radius_m,time_s,sinkage_m,force_N,pressure_Pa");
        for (const auto &p : runs)
            for (const auto &s : p.samples)
                csv << p.plate_radius_m << ',' << s.time_s << ',' << s.sinkage_m << ',' << s.force_N
                    << ',' << s.pressure_Pa << '\n';
    }
    auto csv = openCsv(dir, "bekker_fit.csv", "parameter,value,standard_error,half_width_95,unit");
    if (fit) {
        const auto &f = *fit;
        csv << "k_c," << f.parameters.k_c << ',' << f.standard_error[0] << ',' << f.half_width_95[0]
            << ",N/m^(n+1)\n";
        csv << "k_phi," << f.parameters.k_phi << ',' << f.standard_error[1] << ','
            << f.half_width_95[1] << ",N/m^(n+2)\n";
        csv << "n," << f.parameters.n << ',' << f.standard_error[2] << ',' << f.half_width_95[2]
            << ",-\n";
    }
}

} // namespace grainlink::lab
