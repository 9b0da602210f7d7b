#include "grainlink/lab/DirectShear.hpp"
#include "grainlink/config/Number.hpp"

#include "grainlink/dem/Progress.hpp"
#include "grainlink/dem/ScenarioRun.hpp"
#include "grainlink/lab/BekkerFit.hpp"
#include "grainlink/lab/LabBed.hpp"
#include "grainlink/lab/LabConfig.hpp"

#include <Eigen/Dense>

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

constexpr double kDeg = 180.0 / M_PI;
/// ASTM D3080's least box width over the largest grain's diameter.
constexpr double kMinGrainsAcross = 10.0;

/// Open rectangular frame [0, L] x [0, W] x [0, h] (four side walls, no floor or lid) plus a
/// horizontal lip y in [0, W], x in [lip_x0, lip_x1] at z = lip_z: the lip stands in for the wall
/// thickness of a real box, so grains at the shear plane do not fall out of the gap the shear
/// opens. Mesh contacts are two-sided, so the grains inside touch the walls.
dem::TriangleMesh frameMesh(double L, double W, double h, double lip_x0, double lip_x1,
                            double lip_z) {
    dem::TriangleMesh mesh;
    const double cx[4] = {0.0, L, L, 0.0}, cy[4] = {0.0, 0.0, W, W};
    for (int k = 0; k < 4; ++k) {
        mesh.vertices_m.emplace_back(cx[k], cy[k], 0.0);
        mesh.vertices_m.emplace_back(cx[k], cy[k], h);
    }
    for (int k = 0; k < 4; ++k) {
        const int b0 = 2 * k, t0 = b0 + 1, b1 = 2 * ((k + 1) % 4), t1 = b1 + 1;
        mesh.triangles.push_back({b0, b1, t1});
        mesh.triangles.push_back({b0, t1, t0});
    }
    const int v = int(mesh.vertices_m.size());
    mesh.vertices_m.emplace_back(lip_x0, 0.0, lip_z);
    mesh.vertices_m.emplace_back(lip_x1, 0.0, lip_z);
    mesh.vertices_m.emplace_back(lip_x1, W, lip_z);
    mesh.vertices_m.emplace_back(lip_x0, W, lip_z);
    mesh.triangles.push_back({v, v + 1, v + 2});
    mesh.triangles.push_back({v, v + 2, v + 3});
    return mesh;
}

std::string kPa(double pa) {
    return config::significant(pa * 1e-3, 4) + " kPa";
}

/// Top plate's vertical motion, set by the servo between control intervals, and the shear
/// start shared by the upper frame and the plate.
struct BoxMotion {
    double shear_speed_m_s = 0.0;
    double shear_start_s = std::numeric_limits<double>::infinity();
    double plate_t_ref_s = 0.0, plate_z_ref_m = 0.0, plate_vz_m_s = 0.0;
    dem::RigidBodyState upper_start, plate_start; ///< before the shear
    double shift(double t) const {
        return t > shear_start_s ? shear_speed_m_s * (t - shear_start_s) : 0.0;
    }
    double plateZ(double t) const { return plate_z_ref_m + plate_vz_m_s * (t - plate_t_ref_s); }
    /// Hands the DEM both moving bodies' motions from time t on (after a change of speed).
    void apply(dem::DemSystem &sys, int upper_id, int plate_id, double t) const {
        const double shear_speed = t >= shear_start_s ? shear_speed_m_s : 0.0;
        dem::RigidBodyState upper = upper_start, plate = plate_start;
        upper.position_m.x() = shift(t);
        upper.linear_velocity_m_s.x() = shear_speed;
        plate.position_m.x() += shift(t);
        plate.position_m.z() = plateZ(t);
        plate.linear_velocity_m_s = Vec3(shear_speed, 0.0, plate_vz_m_s);
        sys.setBodyMotion(upper_id, dem::constantVelocity(upper, t));
        sys.setBodyMotion(plate_id, dem::constantVelocity(plate, t));
    }
};

} // namespace

dem::DemScenario boxedSoil(const dem::DemScenario &soil, const DirectShearSpec &box) {
    dem::DemScenario s = soil;
    s.planes.clear();
    const char *side[5] = {"floor", "xmin", "xmax", "ymin", "ymax"};
    const Vec3 hi(box.length_m, box.width_m, 0.0);
    for (int k = 0; k < 5; ++k) {
        dem::PlaneWall wall;
        wall.name = std::string("shear_box.") + side[k];
        wall.normal = Vec3::Zero();
        if (k == 0) {
            wall.normal.z() = 1.0;
        } else {
            const int axis = (k - 1) / 2;
            const bool low = (k - 1) % 2 == 0;
            wall.point_m = low ? Vec3::Zero() : hi;
            wall.normal[axis] = low ? 1.0 : -1.0;
        }
        wall.friction_coefficient = box.wall_friction_coefficient;
        wall.material = soil.material;
        s.planes.push_back(wall);
    }
    return s;
}

DirectShearScenario parseDirectShear(const config::ConfigNode &root) {
    DirectShearScenario s;
    s.name = root["name"].text();
    s.soil = parseLabSoil(root, {"the direct shear test adds its own frames",
                                 "the direct shear test builds its own box",
                                 {},
                                 {}});
    const auto b = root["direct_shear"];
    DirectShearSpec &t = s.test;
    t.length_m = b["length_m"].positive();
    t.width_m = b["width_m"].positive();
    t.lower_height_m = b["lower_height_m"].positive();
    t.upper_height_m = b["upper_height_m"].positive();
    t.normal_stresses_Pa = b["normal_stresses_Pa"].positives();
    t.shear_speed_m_s = b["shear_speed_m_s"].positive();
    t.max_displacement_m = b["max_displacement_m"].positive();
    if (t.max_displacement_m >= 0.5 * t.length_m)
        b["max_displacement_m"].fail("must be below half the box length (the shear plane's "
                                     "overlap W (L - d) shrinks with d)");
    if (b.has("sample_interval_s"))
        t.sample_interval_s = b["sample_interval_s"].positive();
    if (b.has("residual_fraction")) {
        t.residual_fraction = b["residual_fraction"].positive();
        if (t.residual_fraction > 1.0)
            b["residual_fraction"].fail("must be in (0, 1]");
    }
    if (b.has("wall_friction_coefficient"))
        t.wall_friction_coefficient = b["wall_friction_coefficient"].nonNegative();
    if (b.has("plate_clearance_m"))
        t.plate_clearance_m = b["plate_clearance_m"].positive();
    if (b.has("start_clearance_m"))
        t.start_clearance_m = b["start_clearance_m"].nonNegative();
    const auto servo = b["servo"];
    t.servo = parseServo(servo, t.servo, s.warnings);
    if (const auto old = servo.optional("max_consolidation_time_s")) {
        if (servo.has("max_load_time_s"))
            old->fail("give max_load_time_s only (max_consolidation_time_s is its old name)");
        s.warnings.push_back(deprecationWarning(*old, "direct_shear.servo.max_load_time_s"));
        t.servo.max_load_time_s = old->positive();
    }
    // Shearing starts only after the load was held this long: 0 would shear an unloaded box.
    if (!(t.servo.hold_s > 0.0))
        servo["hold_s"].fail("must be > 0");
    if (servo.has("control_interval_s"))
        t.control_interval_s = servo["control_interval_s"].positive();
    if (servo.has("tolerance"))
        t.consolidation_tolerance = servo["tolerance"].positive();
    servo.finish();
    if (t.sample_interval_s < t.control_interval_s)
        b["sample_interval_s"].fail("must be >= servo.control_interval_s");
    t.fit_cohesion = b.boolean("fit_cohesion", true);
    b.finish();

    const auto &d = s.soil.deposition;
    if (d.region_lower_m.x() < 0.0 || d.region_lower_m.y() < 0.0 || d.region_lower_m.z() < 0.0 ||
        d.region_upper_m.x() > t.length_m || d.region_upper_m.y() > t.width_m) {
        std::ostringstream msg;
        msg << "the deposition region must lie inside the box [0, " << t.length_m << "] x [0, "
            << t.width_m << "] m above its floor z = 0";
        root["soil"]["deposition"].fail(msg.str());
    }
    const double r_max = d.radius.largest();
    if (t.plate_clearance_m >= r_max)
        b["plate_clearance_m"].fail("must be below the largest grain radius (grains would pass "
                                    "between the plate and the frame)");
    // ASTM D3080 asks for a box at least ten largest grains wide: in a narrower one the
    // grains jam between the frames and the box's strength is measured as much as the soil's.
    const double grains_across = std::min(t.length_m, t.width_m) / (2.0 * r_max);
    if (grains_across < kMinGrainsAcross) {
        const auto key = t.width_m <= t.length_m ? b["width_m"] : b["length_m"];
        std::ostringstream msg;
        msg << std::setprecision(3) << "the box is " << grains_across
            << " largest grain diameters across (" << std::min(t.length_m, t.width_m) * 1e3
            << " mm for grains up to " << 2e3 * r_max << " mm); ASTM D3080 asks for at least "
            << kMinGrainsAcross
            << ", and below it the friction measured grows as the box narrows (docs/lab.md)";
        s.warnings.push_back(key.warning(msg.str()));
    }
    root.finish();
    return s;
}

DirectShearScenario loadDirectShear(const std::string &path) {
    return parseDirectShear(config::ConfigNode::loadFile(path));
}

MohrCoulombFit fitMohrCoulomb(const std::vector<double> &sigma, const std::vector<double> &tau,
                              bool with_cohesion) {
    // Mohr-Coulomb line by linear least squares, docs/physics.md §12.15.
    if (sigma.size() != tau.size())
        throw std::invalid_argument("fitMohrCoulomb: " + std::to_string(sigma.size()) +
                                    " normal stresses but " + std::to_string(tau.size()) +
                                    " shear stresses");
    const int p = with_cohesion ? 2 : 1;
    const int n = int(sigma.size());
    if (n < p + 1)
        throw std::invalid_argument("Mohr-Coulomb fit needs at least " + std::to_string(p + 1) +
                                    " normal stresses " + (with_cohesion ? "with" : "without") +
                                    " cohesion, got " + std::to_string(n));
    if (*std::max_element(sigma.begin(), sigma.end()) ==
        *std::min_element(sigma.begin(), sigma.end()))
        throw std::invalid_argument("Mohr-Coulomb fit: all normal stresses are equal");
    Eigen::MatrixXd X(n, p);
    Eigen::VectorXd y(n);
    for (int i = 0; i < n; ++i) {
        if (with_cohesion) {
            X(i, 0) = 1.0;
            X(i, 1) = sigma[std::size_t(i)];
        } else {
            X(i, 0) = sigma[std::size_t(i)];
        }
        y[i] = tau[std::size_t(i)];
    }
    const Eigen::MatrixXd XtX = X.transpose() * X;
    const Eigen::VectorXd beta = XtX.ldlt().solve(X.transpose() * y);
    const Eigen::VectorXd r = y - X * beta;
    MohrCoulombFit fit;
    fit.cohesion_fitted = with_cohesion;
    fit.degrees_of_freedom = n - p;
    const double s2 = r.squaredNorm() / fit.degrees_of_freedom;
    fit.rms_residual_Pa = std::sqrt(r.squaredNorm() / n);
    const Eigen::MatrixXd cov = s2 * XtX.inverse();
    const double slope = beta[p - 1];
    const double slope_se = std::sqrt(cov(p - 1, p - 1));
    const double t = studentT975(fit.degrees_of_freedom);
    fit.friction_angle_deg = std::atan(slope) * kDeg;
    fit.friction_angle_se_deg = slope_se / (1.0 + slope * slope) * kDeg;
    fit.friction_angle_half_width_95_deg = t * fit.friction_angle_se_deg;
    if (with_cohesion) {
        fit.cohesion_Pa = beta[0];
        fit.cohesion_se_Pa = std::sqrt(cov(0, 0));
        fit.cohesion_half_width_95_Pa = t * fit.cohesion_se_Pa;
    }
    return fit;
}

std::string MohrCoulombFit::describe(const std::string &label) const {
    std::ostringstream out;
    out << std::setprecision(4);
    out << "  Mohr-Coulomb (" << label << "): psi = " << friction_angle_deg << " +- "
        << friction_angle_half_width_95_deg << " deg";
    if (cohesion_fitted)
        out << ", c = " << cohesion_Pa << " +- " << cohesion_half_width_95_Pa << " Pa";
    else
        out << ", c = 0 (not fitted)";
    out << " (95 %, " << degrees_of_freedom << " dof; SE psi " << friction_angle_se_deg << " deg";
    if (cohesion_fitted)
        out << ", SE c " << cohesion_se_Pa << " Pa";
    out << "; rms residual " << rms_residual_Pa << " Pa)\n";
    return out.str();
}

namespace {

/// One shear run on a copy of the settled bed (consolidation under the servo, then shearing).
BoxShearRun shearOnce(const dem::DemSystem &base, const DirectShearSpec &t, double sigma,
                      double progress_interval_s) {
    const auto start = std::chrono::steady_clock::now();
    BoxShearRun run;
    run.target_normal_stress_Pa = sigma;
    run.target_force_N = sigma * t.length_m * t.width_m;
    dem::DemSystem sys = base;
    // The side planes give way to the split frames; the floor (plane 0) stays.
    sys.planes().resize(1);
    const double dt = sys.settings().time_step_s;
    const double L = t.length_m, W = t.width_m, h = t.lower_height_m;
    const double lip = t.max_displacement_m + 0.01 * L;

    BoxMotion motion;
    motion.shear_speed_m_s = t.shear_speed_m_s;
    double highest = 0.0;
    const auto &grains = sys.particles();
    for (std::size_t i = 0; i < grains.size(); ++i)
        highest = std::max(highest, grains.position[i].z() + grains.radius[i]);
    if (highest > h + t.upper_height_m)
        throw std::runtime_error(
            "direct shear: the settled bed reaches z = " + std::to_string(highest) +
            " m, above the upper frame's top " + std::to_string(h + t.upper_height_m) +
            " m; raise upper_height_m or deposit fewer grains");
    motion.plate_t_ref_s = sys.time();
    motion.plate_z_ref_m = highest + t.start_clearance_m;

    dem::RigidBodyState lower_state;
    dem::MeshBody lower("lower_frame", frameMesh(L, W, h, L, L + lip, h), lower_state);
    lower.friction_coefficient = t.wall_friction_coefficient;
    sys.addBody(std::move(lower));

    motion.upper_start.position_m = Vec3(0.0, 0.0, h);
    dem::MeshBody upper("upper_frame", frameMesh(L, W, t.upper_height_m, -lip, 0.0, 0.0),
                        motion.upper_start);
    upper.friction_coefficient = t.wall_friction_coefficient;
    const int upper_id = sys.addBody(std::move(upper));

    motion.plate_start.position_m = Vec3(0.5 * L, 0.5 * W, motion.plate_z_ref_m);
    dem::MeshBody plate(
        "top_plate",
        dem::makeRectangle(L - 2.0 * t.plate_clearance_m, W - 2.0 * t.plate_clearance_m, 1, 1),
        motion.plate_start);
    plate.friction_coefficient = t.wall_friction_coefficient;
    const int plate_id = sys.addBody(std::move(plate));
    motion.apply(sys, upper_id, plate_id, sys.time());
    sys.prepare();

    LoadServo servo = t.servo.loadServo(run.target_force_N);
    const auto control_steps = std::max<std::uint64_t>(1, std::llround(t.control_interval_s / dt));
    const double control_dt = double(control_steps) * dt;
    // Runs one control interval; returns the plate's and the upper frame's mean reactions.
    struct Reaction {
        Vec3 plate_N, upper_N;
    };
    auto control = [&]() {
        const auto loads = observeInterval(sys, control_steps, {plate_id, upper_id});
        Reaction r{loads[0].force_N, loads[1].force_N};
        // Servo on the top plate's vertical speed, physics.md §12.11.
        motion.plate_z_ref_m = motion.plateZ(sys.time());
        motion.plate_t_ref_s = sys.time();
        // Until the plate touches the bed it comes down at the servo's top speed; then the
        // proportional-integral law (integral gain 0: proportional alone).
        motion.plate_vz_m_s =
            r.plate_N.z() > 0.0 ? -servo.update(r.plate_N.z(), control_dt) : -servo.max_speed_m_s;
        motion.apply(sys, upper_id, plate_id, sys.time());
        return r;
    };

    const std::string label = "direct shear " + kPa(sigma);
    // Consolidation: the plate comes down and the servo brings N to its target.
    {
        dem::Progress progress(label + " load", progress_interval_s);
        const double t0 = sys.time();
        double held = 0.0;
        while (held < t.servo.hold_s - 1e-12) {
            const Reaction r = control();
            const double error = std::abs(r.plate_N.z() - run.target_force_N) / run.target_force_N;
            held = error < t.consolidation_tolerance ? held + control_dt : 0.0;
            run.consolidation_s = sys.time() - t0;
            if (run.consolidation_s > t.servo.max_load_time_s) {
                std::ostringstream msg;
                msg << "direct shear at " << sigma << " Pa: the top plate did not hold "
                    << run.target_force_N << " N within " << t.consolidation_tolerance * 100
                    << " % for " << t.servo.hold_s << " s within " << t.servo.max_load_time_s
                    << " s (last N = " << r.plate_N.z()
                    << " N); tune servo.gain_m_s_per_N (stable for gain <= 1 / (k dt), k the "
                       "bed's stiffness) or raise servo.max_load_time_s";
                throw std::runtime_error(msg.str());
            }
            progress.update(sys.time(), run.consolidation_s / t.servo.max_load_time_s,
                            (sys.stepCount()) * sys.particles().size(),
                            "N " + std::to_string(r.plate_N.z()) + " N");
        }
    }

    // Weight of the grains above the shear plane, carried by the shear plane with N.
    const double g = sys.settings().gravity_m_s2.norm();
    for (std::size_t i = 0; i < grains.size(); ++i)
        if (grains.position[i].z() > h)
            run.grains_above_weight_N += grains.mass[i] * g;

    // Shearing at constant speed.
    motion.shear_start_s = sys.time();
    motion.apply(sys, upper_id, plate_id, sys.time());
    const double plate_z0 = motion.plateZ(sys.time());
    const auto controls_per_sample =
        std::max<std::uint64_t>(1, std::llround(t.sample_interval_s / control_dt));
    const auto total_controls =
        std::uint64_t(std::ceil(t.max_displacement_m / (t.shear_speed_m_s * control_dt) - 1e-9));
    dem::Progress progress(label + " shear", progress_interval_s);
    const std::uint64_t steps0 = sys.stepCount();
    for (std::uint64_t done = 0; done < total_controls;) {
        const std::uint64_t n = std::min(controls_per_sample, total_controls - done);
        Vec3 plate_sum = Vec3::Zero(), upper_sum = Vec3::Zero();
        for (std::uint64_t k = 0; k < n; ++k) {
            const Reaction r = control();
            plate_sum += r.plate_N;
            upper_sum += r.upper_N;
        }
        done += n;
        BoxShearSample s;
        s.time_s = (double(done) - 0.5 * double(n)) * control_dt;
        s.displacement_m = t.shear_speed_m_s * s.time_s;
        // The soil's reactions oppose the motion: the drive pushes with their negative.
        s.shear_force_N = -(plate_sum.x() + upper_sum.x()) / double(n);
        s.normal_force_N = plate_sum.z() / double(n);
        s.area_m2 = W * (L - s.displacement_m);
        s.shear_stress_Pa = s.shear_force_N / s.area_m2;
        s.normal_stress_Pa = (s.normal_force_N + run.grains_above_weight_N) / s.area_m2;
        s.plate_height_m = motion.plateZ(sys.time()) - plate_z0;
        run.samples.push_back(s);
        progress.update(sys.time(), double(done) / double(total_controls),
                        (sys.stepCount() - steps0) * sys.particles().size(),
                        "d " + std::to_string(s.displacement_m * 1e3) + " mm, tau " +
                            kPa(s.shear_stress_Pa));
    }
    run.steps = sys.stepCount() - base.stepCount();

    // Peak, residual, how well the servo held N.
    const auto peak =
        std::max_element(run.samples.begin(), run.samples.end(), [](const auto &a, const auto &b) {
            return a.shear_stress_Pa < b.shear_stress_Pa;
        });
    run.peak_shear_stress_Pa = peak->shear_stress_Pa;
    run.peak_normal_stress_Pa = peak->normal_stress_Pa;
    run.peak_displacement_m = peak->displacement_m;
    const double d_residual = (1.0 - t.residual_fraction) * t.max_displacement_m;
    int residual_n = 0;
    for (const auto &s : run.samples) {
        run.mean_normal_force_N += s.normal_force_N / double(run.samples.size());
        run.max_normal_force_error =
            std::max(run.max_normal_force_error,
                     std::abs(s.normal_force_N - run.target_force_N) / run.target_force_N);
        if (s.displacement_m >= d_residual) {
            run.residual_shear_stress_Pa += s.shear_stress_Pa;
            run.residual_normal_stress_Pa += s.normal_stress_Pa;
            ++residual_n;
        }
    }
    if (residual_n > 0) {
        run.residual_shear_stress_Pa /= residual_n;
        run.residual_normal_stress_Pa /= residual_n;
    }
    run.wall_s = secondsSince(start);
    std::fprintf(stderr,
                 "[direct shear] sigma = %s: loaded in %.3f s, peak tau %s at d = %.2f mm, "
                 "residual %s; %.1f s wall\n",
                 kPa(sigma).c_str(), run.consolidation_s, kPa(run.peak_shear_stress_Pa).c_str(),
                 run.peak_displacement_m * 1e3, kPa(run.residual_shear_stress_Pa).c_str(),
                 run.wall_s);
    return run;
}

/// The direct shear box's steps of the lab skeleton (LabExperiment.hpp): one normal stress per
/// condition.
struct DirectShearExperiment {
    using Result = DirectShearResult;
    const DirectShearScenario &scenario;

    LabBed prepareBed(double progress_interval_s) const {
        const DirectShearSpec &t = scenario.test;
        LabBed bed = prepareLabBed(boxedSoil(scenario.soil, t), {t.length_m * t.width_m, 0.0},
                                   progress_interval_s);
        const double height = bed.summary.surface_m - bed.summary.floor_m;
        if (height < t.lower_height_m + 4.0 * bed.summary.largest_radius_m)
            throw std::runtime_error(
                "direct shear: the settled bed is " + std::to_string(height) +
                " m high, less than two grain diameters above the shear plane (" +
                std::to_string(t.lower_height_m) +
                " m); deposit more grains or lower lower_height_m");
        return bed;
    }
    Result start(const LabBed &) const { return {}; }
    std::vector<double> conditions() const { return scenario.test.normal_stresses_Pa; }
    BoxShearRun run(const LabBed &bed, double sigma, double progress_interval_s) const {
        return shearOnce(*bed.system, scenario.test, sigma, progress_interval_s);
    }
    void fit(Result &result) const {
        std::vector<double> s_peak, t_peak, s_res, t_res;
        for (const auto &r : result.runs) {
            s_peak.push_back(r.peak_normal_stress_Pa);
            t_peak.push_back(r.peak_shear_stress_Pa);
            s_res.push_back(r.residual_normal_stress_Pa);
            t_res.push_back(r.residual_shear_stress_Pa);
        }
        result.peak_fit = fitMohrCoulomb(s_peak, t_peak, scenario.test.fit_cohesion);
        result.residual_fit = fitMohrCoulomb(s_res, t_res, scenario.test.fit_cohesion);
    }
};

} // namespace

DirectShearResult runDirectShear(const DirectShearScenario &scenario,
                                 const LabRunOptions &options) {
    return runLabExperiment(DirectShearExperiment{scenario}, options);
}

std::string DirectShearResult::report() const {
    std::ostringstream out;
    out << std::setprecision(4);
    out << "Direct shear box\n";
    writeBedLine(out, bed);
    out << "  settled bed " << (bed.surface_m - bed.floor_m) * 1e3 << " mm high: bulk density "
        << bed.bulk_density_kg_m3 << " kg/m^3, packing fraction " << bed.packing_fraction << "\n";
    for (const auto &r : runs)
        out << "  sigma " << kPa(r.target_normal_stress_Pa) << " (N " << r.target_force_N
            << " N, held to " << r.max_normal_force_error * 100 << " % while shearing; grains "
            << "above the shear plane " << r.grains_above_weight_N << " N): peak tau "
            << kPa(r.peak_shear_stress_Pa) << " at sigma " << kPa(r.peak_normal_stress_Pa) << ", d "
            << r.peak_displacement_m * 1e3 << " mm; residual tau "
            << kPa(r.residual_shear_stress_Pa) << " at sigma " << kPa(r.residual_normal_stress_Pa)
            << "; " << r.steps << " steps, " << r.wall_s << " s wall\n";
    if (peak_fit)
        out << peak_fit->describe("peak");
    if (residual_fit)
        out << residual_fit->describe("residual");
    if (!peak_fit)
        out << "  no Mohr-Coulomb fit: " << fit_note << "\n";
    out << "  total wall time " << wall_s << " s\n";
    return out.str();
}

LabSummary DirectShearResult::summary() const {
    LabSummary s{kTest, scenario, "target_normal_stress_Pa", bed, {}, fit_note, {}, wall_s};
    for (const auto &[law, fit] : {std::pair{"mohr_coulomb_peak", &peak_fit},
                                   std::pair{"mohr_coulomb_residual", &residual_fit}}) {
        if (!*fit)
            continue;
        const MohrCoulombFit &f = **fit;
        LabFit x{law, f.degrees_of_freedom, {}};
        x.parameters.push_back(
            {"psi", "deg", f.friction_angle_deg, f.friction_angle_half_width_95_deg});
        if (f.cohesion_fitted)
            x.parameters.push_back({"c", "Pa", f.cohesion_Pa, f.cohesion_half_width_95_Pa});
        s.fits.push_back(x);
    }
    for (const auto &r : runs) {
        LabRunSummary x;
        x.values = {{"target_normal_stress_Pa", r.target_normal_stress_Pa},
                    {"target_force_N", r.target_force_N},
                    {"grains_above_weight_N", r.grains_above_weight_N},
                    {"consolidation_s", r.consolidation_s},
                    {"peak_shear_stress_Pa", r.peak_shear_stress_Pa},
                    {"peak_normal_stress_Pa", r.peak_normal_stress_Pa},
                    {"peak_displacement_m", r.peak_displacement_m},
                    {"residual_shear_stress_Pa", r.residual_shear_stress_Pa},
                    {"residual_normal_stress_Pa", r.residual_normal_stress_Pa},
                    {"mean_normal_force_N", r.mean_normal_force_N},
                    {"max_normal_force_error", r.max_normal_force_error},
                    {"steps", double(r.steps)},
                    {"wall_s", r.wall_s}};
        std::vector<double> time, d, shear, normal, area, tau, sigma, rise;
        for (const auto &p : r.samples) {
            time.push_back(p.time_s);
            d.push_back(p.displacement_m);
            shear.push_back(p.shear_force_N);
            normal.push_back(p.normal_force_N);
            area.push_back(p.area_m2);
            tau.push_back(p.shear_stress_Pa);
            sigma.push_back(p.normal_stress_Pa);
            rise.push_back(p.plate_height_m);
        }
        x.curves = {{"time_s", time},
                    {"displacement_m", d},
                    {"shear_force_N", shear},
                    {"normal_force_N", normal},
                    {"area_m2", area},
                    {"shear_stress_Pa", tau},
                    {"normal_stress_Pa", sigma},
                    {"plate_height_m", rise}};
        s.runs.push_back(x);
    }
    return s;
}

void DirectShearResult::writeCsvs(const std::string &directory) const {
    const fs::path dir(directory);
    {
        auto csv =
            openCsv(dir, "shear_curves.csv",
                    "target_normal_stress_Pa,time_s,displacement_m,shear_force_N,normal_force_N,"
                    "area_m2,shear_stress_Pa,normal_stress_Pa,plate_height_m");
        for (const auto &r : runs)
            for (const auto &s : r.samples)
                csv << r.target_normal_stress_Pa << ',' << s.time_s << ',' << s.displacement_m
                    << ',' << s.shear_force_N << ',' << s.normal_force_N << ',' << s.area_m2 << ','
                    << s.shear_stress_Pa << ',' << s.normal_stress_Pa << ',' << s.plate_height_m
                    << '\n';
    }
    {
        // One row per normal stress and kind, the kind's fitted line repeated on each row.
        auto csv = openCsv(
            dir, "mohr_coulomb.csv",
            "kind,target_normal_stress_Pa,normal_stress_Pa,shear_stress_Pa,friction_angle_deg,"
            "friction_angle_half_width_95_deg,cohesion_Pa,cohesion_half_width_95_Pa");
        auto row = [&](const char *kind, const BoxShearRun &r, double sigma, double tau,
                       const std::optional<MohrCoulombFit> &fit) {
            csv << kind << ',' << r.target_normal_stress_Pa << ',' << sigma << ',' << tau;
            if (fit)
                csv << ',' << fit->friction_angle_deg << ','
                    << fit->friction_angle_half_width_95_deg << ',' << fit->cohesion_Pa << ','
                    << fit->cohesion_half_width_95_Pa << '\n';
            else
                csv << ",,,,\n";
        };
        for (const auto &r : runs)
            row("peak", r, r.peak_normal_stress_Pa, r.peak_shear_stress_Pa, peak_fit);
        for (const auto &r : runs)
            row("residual", r, r.residual_normal_stress_Pa, r.residual_shear_stress_Pa,
                residual_fit);
    }
}

} // namespace grainlink::lab
