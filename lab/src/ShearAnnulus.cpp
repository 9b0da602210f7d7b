#include "grainlink/lab/ShearAnnulus.hpp"

#include "grainlink/body/WheelShape.hpp"
#include "grainlink/dem/Progress.hpp"
#include "grainlink/dem/ScenarioRun.hpp"
#include "grainlink/lab/BekkerFit.hpp"
#include "grainlink/lab/LabBed.hpp"
#include "grainlink/lab/LabConfig.hpp"
#include "grainlink/lab/LoadServo.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace grainlink::lab {

namespace fs = std::filesystem;
using dem::Vec3;

namespace {

/// Appends the quad (a, b, c, d) as two triangles whose normals point along `outward`.
void appendQuad(dem::TriangleMesh &mesh, int a, int b, int c, int d, const Vec3 &outward) {
    for (std::array<int, 3> t : {std::array<int, 3>{a, b, c}, std::array<int, 3>{a, c, d}}) {
        const Vec3 &p0 = mesh.vertices_m[t[0]], &p1 = mesh.vertices_m[t[1]],
                   &p2 = mesh.vertices_m[t[2]];
        if ((p1 - p0).cross(p2 - p0).dot(outward) < 0.0)
            std::swap(t[1], t[2]);
        mesh.triangles.push_back(t);
    }
}

/// Appends a box with half-axes a, b, c about `centre`. The box is dem::makeCylinder's square
/// prism (4 facets around its y axis, corners on the x and z axes) turned 45 degrees about y
/// onto [-1, 1]^3 and then mapped linearly; a mirroring map has its windings flipped.
void appendBox(dem::TriangleMesh &mesh, const Vec3 &centre, const Vec3 &a, const Vec3 &b,
               const Vec3 &c) {
    const dem::TriangleMesh prism = dem::makeCylinder(std::sqrt(2.0), 2.0, 4);
    dem::Mat3 axes;
    axes << a, b, c;
    const int first = int(mesh.vertices_m.size());
    for (const Vec3 &v : prism.vertices_m) {
        const Vec3 unit((v.x() + v.z()) / std::sqrt(2.0), v.y(), (v.z() - v.x()) / std::sqrt(2.0));
        mesh.vertices_m.push_back(centre + axes * unit);
    }
    const bool flip = axes.determinant() < 0.0;
    for (const auto &t : prism.triangles)
        mesh.triangles.push_back(
            flip ? std::array<int, 3>{first + t[0], first + t[2], first + t[1]}
                 : std::array<int, 3>{first + t[0], first + t[1], first + t[2]});
}

/// Prescribed motion of the annulus (mesh body 0): piecewise-constant vertical and angular
/// speed, changed between sample intervals by retarget(), which hands the DEM the new motion.
struct AnnulusDrive {
    dem::RigidBodyState initial;
    double t_ref = 0.0, z_ref = 0.0, theta_ref = 0.0; ///< [s], [m], [rad] at the last change
    double v_z = 0.0, omega = 0.0;                    ///< [m/s], [rad/s] since then
    double z(double t) const { return z_ref + v_z * (t - t_ref); }
    double theta(double t) const { return theta_ref + omega * (t - t_ref); }
    dem::RigidBodyState at(double t) const {
        dem::RigidBodyState s = initial;
        s.position_m.z() = z(t);
        s.orientation = dem::Quat(Eigen::AngleAxisd(theta(t), Vec3::UnitZ()));
        s.linear_velocity_m_s = Vec3(0.0, 0.0, v_z);
        s.angular_velocity_rad_s = Vec3(0.0, 0.0, omega);
        return s;
    }
    dem::SegmentedMotion motion() const { return dem::constantVelocity(at(t_ref), t_ref); }
    void retarget(dem::DemSystem &sys, double t, double new_v_z, double new_omega) {
        z_ref = z(t);
        theta_ref = theta(t);
        t_ref = t;
        v_z = new_v_z;
        omega = new_omega;
        sys.setBodyMotion(0, motion());
    }
};

} // namespace

double AnnulusGeometry::area_m2() const {
    return M_PI * (outer_radius_m * outer_radius_m - inner_radius_m * inner_radius_m);
}

double AnnulusGeometry::torqueFactor_m3() const {
    // tau uniform over the annulus: T = int tau r dA = 2 pi / 3 (R_o^3 - R_i^3) tau, §12.12.
    return 2.0 * M_PI / 3.0 * (std::pow(outer_radius_m, 3) - std::pow(inner_radius_m, 3));
}

double AnnulusGeometry::meanRadius_m() const {
    return 0.5 * (inner_radius_m + outer_radius_m);
}

dem::TriangleMesh makeShearAnnulus(const AnnulusGeometry &g) {
    if (!(g.inner_radius_m > 0.0) || !(g.outer_radius_m > g.inner_radius_m))
        throw std::invalid_argument("makeShearAnnulus: need 0 < inner radius < outer radius");
    if (g.ring_segments < 8 || g.grouser_count < 0)
        throw std::invalid_argument("makeShearAnnulus: need >= 8 ring segments, >= 0 grousers");
    const double thickness = g.ring_thickness_m > 0.0
                                 ? g.ring_thickness_m
                                 : 0.25 * (g.outer_radius_m - g.inner_radius_m);
    const int n = g.ring_segments;
    dem::TriangleMesh mesh;
    // Per segment k: inner bottom, outer bottom, inner top, outer top.
    for (int k = 0; k < n; ++k) {
        const double a = 2.0 * M_PI * k / n, c = std::cos(a), s = std::sin(a);
        for (double z : {0.0, thickness})
            for (double r : {g.inner_radius_m, g.outer_radius_m})
                mesh.vertices_m.emplace_back(r * c, r * s, z);
    }
    for (int k = 0; k < n; ++k) {
        const int p = 4 * k, q = 4 * ((k + 1) % n);
        const double a = 2.0 * M_PI * (k + 0.5) / n;
        const Vec3 radial(std::cos(a), std::sin(a), 0.0);
        appendQuad(mesh, p + 0, p + 1, q + 1, q + 0, -Vec3::UnitZ()); // bottom face
        appendQuad(mesh, p + 2, p + 3, q + 3, q + 2, Vec3::UnitZ());  // top face
        appendQuad(mesh, p + 1, p + 3, q + 3, q + 1, radial);         // outer rim
        appendQuad(mesh, p + 0, p + 2, q + 2, q + 0, -radial);        // inner rim
    }
    if (g.grouser_count > 0 && g.grouser_height_m > 0.0) {
        const double width =
            g.grouser_thickness_m > 0.0 ? g.grouser_thickness_m : 0.5 * g.grouser_height_m;
        // Each grouser reaches half the ring's thickness up into the ring: one closed union.
        const double top = 0.5 * thickness, bottom = -g.grouser_height_m;
        for (int k = 0; k < g.grouser_count; ++k) {
            const double a = 2.0 * M_PI * k / g.grouser_count;
            const Vec3 radial(std::cos(a), std::sin(a), 0.0),
                tangential(-std::sin(a), std::cos(a), 0.0);
            appendBox(mesh, radial * g.meanRadius_m() + Vec3(0.0, 0.0, 0.5 * (top + bottom)),
                      radial * (0.5 * (g.outer_radius_m - g.inner_radius_m)),
                      tangential * (0.5 * width), Vec3(0.0, 0.0, 0.5 * (top - bottom)));
        }
    }
    mesh.validate("shear annulus");
    return mesh;
}

double JanosiParameters::shearStress(double sigma, double j) const {
    // Janosi-Hanamoto, docs/physics.md §12.13.
    const double tan_phi = std::tan(friction_angle_deg * M_PI / 180.0);
    return (cohesion_Pa + sigma * tan_phi) * (1.0 - std::exp(-j / shear_modulus_m));
}

JanosiFit fitJanosi(const std::vector<ShearCurve> &curves) {
    struct Point {
        double sigma, j, tau;
    };
    std::vector<Point> points;
    std::vector<double> pressures;
    for (const auto &c : curves) {
        if (c.shear_displacement_m.size() != c.shear_stress_Pa.size())
            throw std::invalid_argument("fitJanosi: displacement and stress differ in length");
        bool used = false;
        for (std::size_t i = 0; i < c.shear_displacement_m.size(); ++i)
            if (c.shear_displacement_m[i] > 0.0 && std::isfinite(c.shear_stress_Pa[i])) {
                points.push_back(
                    {c.normal_pressure_Pa, c.shear_displacement_m[i], c.shear_stress_Pa[i]});
                used = true;
            }
        if (used && std::none_of(pressures.begin(), pressures.end(), [&](double s) {
                return std::abs(s - c.normal_pressure_Pa) <= 1e-6 * std::abs(s);
            }))
            pressures.push_back(c.normal_pressure_Pa);
    }
    if (pressures.size() < 2)
        throw std::invalid_argument(
            "fitJanosi: needs curves at two or more normal pressures (got " +
            std::to_string(pressures.size()) + "): c and phi cannot be separated at one pressure");
    if (points.size() < 4)
        throw std::invalid_argument("fitJanosi: needs at least 4 points with j > 0, got " +
                                    std::to_string(points.size()));

    // Scaled parameters theta = (c / sigma_ref, tan phi, K / j_ref), residual
    // (tau_model - tau) / sigma_ref.
    double sigma_ref = 0.0, j_ref = 0.0;
    for (const Point &q : points) {
        sigma_ref = std::max(sigma_ref, std::abs(q.sigma));
        j_ref = std::max(j_ref, q.j);
    }
    if (!(sigma_ref > 0.0))
        throw std::invalid_argument("fitJanosi: every normal pressure is zero");
    const auto m = Eigen::Index(points.size());
    Eigen::VectorXd y(m);
    for (Eigen::Index i = 0; i < m; ++i)
        y[i] = points[std::size_t(i)].tau / sigma_ref;
    // For each K the law is linear in (c, tan phi): start from the best K on a geometric grid.
    std::vector<double> k_grid;
    for (int k = 0; k <= 60; ++k)
        k_grid.push_back(1e-3 * std::pow(10.0, 3.5 * k / 60.0)); // K / j_ref in [1e-3, 3.2]
    auto design = [&](double k_scaled) {
        Eigen::MatrixXd a(m, 2);
        for (Eigen::Index i = 0; i < m; ++i) {
            const Point &q = points[std::size_t(i)];
            const double s = 1.0 - std::exp(-q.j / (k_scaled * j_ref));
            a(i, 0) = s;
            a(i, 1) = q.sigma / sigma_ref * s;
        }
        return a;
    };
    LeastSquaresProblem problem;
    problem.parameter_count = 3;
    problem.residual_count = int(m);
    problem.residuals = [&](const Eigen::VectorXd &x, Eigen::VectorXd &f) {
        for (Eigen::Index i = 0; i < m; ++i) {
            const Point &q = points[std::size_t(i)];
            const double s = 1.0 - std::exp(-q.j / (x[2] * j_ref));
            f[i] = (x[0] + x[1] * q.sigma / sigma_ref) * s - y[i];
        }
    };
    problem.jacobian = [&](const Eigen::VectorXd &x, Eigen::MatrixXd &jac) {
        for (Eigen::Index i = 0; i < m; ++i) {
            const Point &q = points[std::size_t(i)];
            const double u = q.j / (x[2] * j_ref), e = std::exp(-u);
            const double strength = x[0] + x[1] * q.sigma / sigma_ref;
            jac(i, 0) = 1.0 - e;
            jac(i, 1) = q.sigma / sigma_ref * (1.0 - e);
            jac(i, 2) = -strength * e * u / x[2]; // d(1 - e^-u)/dx2 = -e^-u u / x2
        }
    };
    const LeastSquaresSolution solution =
        solveLeastSquares(problem, separableStart(k_grid, design, y));
    const Eigen::VectorXd &x = solution.theta;

    JanosiFit fit;
    fit.points = points.size();
    fit.degrees_of_freedom = solution.degrees_of_freedom;
    fit.iterations = solution.iterations;
    fit.rms_residual_Pa = sigma_ref * std::sqrt(solution.rss / double(m));
    fit.parameters.cohesion_Pa = sigma_ref * x[0];
    fit.parameters.friction_angle_deg = std::atan(x[1]) * 180.0 / M_PI;
    fit.parameters.shear_modulus_m = j_ref * x[2];
    // Delta method from theta to (c, phi [deg], K).
    const Eigen::Vector3d scale(sigma_ref, 180.0 / M_PI / (1.0 + x[1] * x[1]), j_ref);
    fit.covariance = scale.asDiagonal() * Eigen::Matrix3d(solution.covariance) * scale.asDiagonal();
    fit.standard_error = fit.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
    fit.half_width_95 = studentT975(std::max(1, fit.degrees_of_freedom)) * fit.standard_error;
    return fit;
}

std::string JanosiFit::describe() const {
    std::ostringstream out;
    out << std::setprecision(5);
    out << "Janosi-Hanamoto fit tau = (c + sigma tan phi)(1 - exp(-j/K)) over " << points
        << " points (" << degrees_of_freedom << " dof), 95 % confidence intervals:\n";
    out << "  c   = " << parameters.cohesion_Pa << " +- " << half_width_95[0] << " Pa\n";
    out << "  phi = " << parameters.friction_angle_deg << " +- " << half_width_95[1] << " deg\n";
    out << "  K   = " << parameters.shear_modulus_m * 1e3 << " +- " << half_width_95[2] * 1e3
        << " mm\n";
    out << "  rms residual " << rms_residual_Pa << " Pa\n";
    return out.str();
}

ShearAnnulusScenario parseShearAnnulus(const config::ConfigNode &root) {
    ShearAnnulusScenario s;
    s.name = root["name"].text();
    s.soil = parseLabSoil(root, {"the shear test adds its own annulus", {}, {}, {}});
    const auto b = root["bevameter_shear"];
    ShearAnnulusSpec &t = s.test;
    AnnulusGeometry &g = t.annulus;
    g.inner_radius_m = b["inner_radius_m"].positive();
    g.outer_radius_m = b["outer_radius_m"].positive();
    if (!(g.outer_radius_m > g.inner_radius_m))
        b["outer_radius_m"].fail("must exceed inner_radius_m");
    g.grouser_count = int(b.integer("grouser_count", 0, body::kMaxGrousers, g.grouser_count));
    g.grouser_height_m = b["grouser_height_m"].nonNegative();
    if (b.has("grouser_thickness_m"))
        g.grouser_thickness_m = b["grouser_thickness_m"].positive();
    if (b.has("ring_thickness_m"))
        g.ring_thickness_m = b["ring_thickness_m"].positive();
    g.ring_segments = int(b.integer("ring_segments", 8, dem::kMaxMeshSegments, g.ring_segments));
    t.normal_pressures_Pa = b["normal_pressures_Pa"].positives();
    t.angular_speed_rad_s = b["angular_speed_rad_s"].positive();
    t.max_shear_displacement_m = b["max_shear_displacement_m"].positive();
    if (b.has("approach_speed_m_s"))
        t.approach_speed_m_s = b["approach_speed_m_s"].positive();
    if (b.has("servo")) {
        const auto servo = b["servo"];
        t.servo = parseServo(servo, t.servo, s.warnings);
        servo.finish();
    } else if (b.has("servo_gain_m_s_per_N")) {
        // The spelling before the servo: block, with its defaults (a 0.01 m/s clamp).
        ServoSpec old = t.servo;
        old.max_speed_m_s = 0.01;
        t.servo = parseServo(b, old, s.warnings,
                             ServoKeys{"servo_gain_m_s_per_N", "servo_max_speed_m_s",
                                       "servo_deadband_N", "servo_integral_gain_m_s2_per_N",
                                       "load_hold_s", "max_load_time_s"});
    } else {
        (void)b["servo"]; // throws: missing key bevameter_shear.servo
    }
    if (b.has("start_clearance_m"))
        t.start_clearance_m = b["start_clearance_m"].nonNegative();
    if (b.has("sample_interval_s"))
        t.sample_interval_s = b["sample_interval_s"].positive();
    if (b.has("friction_coefficient"))
        t.friction_coefficient = b["friction_coefficient"].nonNegative();
    if (b.has("min_resolution"))
        t.min_resolution = b["min_resolution"].positive();
    t.centre_m = parseCentre(b);
    b.finish();

    // Resolution, seed eq. 11 with L_min = R_o - R_i (the annulus width).
    const double r_max = s.soil.deposition.radius.largest();
    const double gamma = (g.outer_radius_m - g.inner_radius_m) / (2.0 * r_max);
    if (gamma < t.min_resolution - 1e-12) {
        std::ostringstream msg;
        msg << "annulus width " << g.outer_radius_m - g.inner_radius_m
            << " m over the largest grain diameter " << 2 * r_max << " m is Gamma = " << gamma
            << " < min_resolution " << t.min_resolution << "; use a wider annulus or finer grains";
        b["outer_radius_m"].fail(msg.str());
    }
    refuseBeyondBed(b["outer_radius_m"], s.soil, t.centre_m, g.outer_radius_m, "annulus");
    root.finish();
    return s;
}

ShearAnnulusScenario loadShearAnnulus(const std::string &path) {
    return parseShearAnnulus(config::ConfigNode::loadFile(path));
}

ShearCurve ShearRun::curve() const {
    ShearCurve c;
    c.normal_pressure_Pa = mean_pressure_Pa;
    for (const auto &s : samples) {
        c.shear_displacement_m.push_back(s.shear_displacement_m);
        c.shear_stress_Pa.push_back(s.shear_stress_Pa);
    }
    return c;
}

namespace {

/// The shear annulus's steps of the lab skeleton (LabExperiment.hpp): one normal pressure per
/// condition.
struct ShearAnnulusExperiment {
    using Result = ShearAnnulusResult;
    const ShearAnnulusScenario &scenario;

    LabBed prepareBed(double progress_interval_s) const {
        return prepareLabBed(scenario.soil, regionFootprint(scenario.soil), progress_interval_s);
    }
    Result start(const LabBed &bed) const {
        const AnnulusGeometry &g = scenario.test.annulus;
        Result result;
        result.annulus = g;
        result.resolution =
            (g.outer_radius_m - g.inner_radius_m) / (2.0 * bed.summary.largest_radius_m);
        return result;
    }
    std::vector<double> conditions() const { return scenario.test.normal_pressures_Pa; }
    ShearRun run(const LabBed &bed, double pressure, double progress_interval_s) const;
    void fit(Result &result) const {
        std::vector<ShearCurve> curves;
        for (const auto &r : result.runs)
            curves.push_back(r.curve());
        result.fit = fitJanosi(curves);
    }
};

ShearRun ShearAnnulusExperiment::run(const LabBed &bed, double pressure,
                                     double progress_interval_s) const {
    const auto run_start = std::chrono::steady_clock::now();
    const ShearAnnulusSpec &t = scenario.test;
    const AnnulusGeometry &g = t.annulus;
    const double dt = bed.summary.time_step_s;
    const double surface = bed.summary.surface_m;
    const Vec3 lower = scenario.soil.deposition.region_lower_m;
    const Vec3 upper = scenario.soil.deposition.region_upper_m;
    const Eigen::Vector2d centre = testCentre(scenario.soil, t.centre_m);
    const auto steps_per_sample =
        std::max<std::uint64_t>(1, std::llround(t.sample_interval_s / dt));
    const double area = g.area_m2(), torque_factor = g.torqueFactor_m3(), r_mean = g.meanRadius_m();
    const double interval_s = double(steps_per_sample) * dt; // the servo's real interval

    dem::DemSystem sys = *bed.system; // every pressure shears its own copy of the settled bed
    ShearRun run;
    run.target_pressure_Pa = pressure;
    run.target_force_N = pressure * area;
    run.surface_m = surface;
    run.wall_gap_m = std::min(
        {centre.x() - g.outer_radius_m - lower.x(), upper.x() - centre.x() - g.outer_radius_m,
         centre.y() - g.outer_radius_m - lower.y(), upper.y() - centre.y() - g.outer_radius_m});
    // Grouser tips start above every grain under the annulus.
    const double highest = highestGrainUnder(sys.particles(), centre, g.outer_radius_m, surface);
    auto drive = std::make_shared<AnnulusDrive>();
    drive->initial.position_m =
        Vec3(centre.x(), centre.y(), highest + t.start_clearance_m + g.grouser_height_m);
    drive->t_ref = sys.time();
    drive->z_ref = drive->initial.position_m.z();
    drive->v_z = -t.approach_speed_m_s;
    dem::MeshBody annulus("annulus", makeShearAnnulus(g), drive->at(sys.time()));
    annulus.friction_coefficient = t.friction_coefficient;
    sys.addBody(std::move(annulus), drive->motion());
    sys.prepare();

    LoadServo servo = t.servo.loadServo(run.target_force_N);

    char label[64];
    std::snprintf(label, sizeof label, "bevameter_shear sigma=%.0fPa", pressure);
    dem::Progress progress(label, progress_interval_s);
    const double t0 = sys.time();
    // One sample interval: run it, return the mean vertical force and z torque of the soil on
    // the annulus, and the body height at its middle.
    struct Interval {
        double force_N, torque_N_m, z_mid_m, t_mid_s;
    };
    auto interval = [&]() {
        const double t_start = sys.time();
        const MeanLoad load = observeInterval(sys, steps_per_sample, {0})[0];
        Interval out;
        out.force_N = load.force_N.z();
        out.torque_N_m = -load.torque_N_m.z();
        out.t_mid_s = 0.5 * (t_start + sys.time());
        out.z_mid_m = drive->z(out.t_mid_s);
        run.steps += steps_per_sample;
        return out;
    };

    // Approach at constant speed until the load is first reached.
    for (;;) {
        const Interval s = interval();
        progress.update(sys.time() - t0, 0.0, run.steps * sys.particles().size(),
                        "approach, F " + std::to_string(s.force_N) + " N");
        if (s.force_N >= run.target_force_N) {
            drive->retarget(sys, sys.time(), -servo.update(s.force_N, interval_s), 0.0);
            break;
        }
        if (sys.time() - t0 > t.servo.max_load_time_s) {
            std::ostringstream msg;
            msg << "bevameter_shear: the annulus did not reach " << run.target_force_N
                << " N (sigma = " << pressure
                << " Pa) within servo.max_load_time_s = " << t.servo.max_load_time_s << " s (last "
                << s.force_N << " N, grouser tips " << surface - (s.z_mid_m - g.grouser_height_m)
                << " m below the surface); raise servo.max_load_time_s or approach_speed_m_s, "
                   "or lower the pressure";
            throw std::runtime_error(msg.str());
        }
    }
    // Hold: the servo alone.
    const double hold_end = sys.time() + t.servo.hold_s;
    while (sys.time() < hold_end - 0.5 * dt) {
        const Interval s = interval();
        drive->retarget(sys, sys.time(), -servo.update(s.force_N, interval_s), 0.0);
    }
    run.load_time_s = sys.time() - t0;
    run.sinkage_at_load_m = surface - (drive->z(sys.time()) - g.grouser_height_m);

    // Shear: constant angular speed, the servo holding the load.
    const double t_shear = sys.time();
    drive->retarget(sys, t_shear, drive->v_z, t.angular_speed_rad_s);
    double err2 = 0.0;
    for (;;) {
        const Interval s = interval();
        drive->retarget(sys, sys.time(), -servo.update(s.force_N, interval_s),
                        t.angular_speed_rad_s);
        ShearSample x;
        x.time_s = s.t_mid_s - t_shear;
        x.rotation_rad = t.angular_speed_rad_s * x.time_s;
        x.shear_displacement_m = x.rotation_rad * r_mean;
        x.normal_force_N = s.force_N;
        x.normal_pressure_Pa = s.force_N / area;
        x.torque_N_m = s.torque_N_m;
        x.shear_stress_Pa = s.torque_N_m / torque_factor;
        x.sinkage_m = surface - (s.z_mid_m - g.grouser_height_m);
        run.samples.push_back(x);
        const double err = std::abs(s.force_N - run.target_force_N) / run.target_force_N;
        run.max_load_error = std::max(run.max_load_error, err);
        err2 += err * err;
        const double j_end = t.angular_speed_rad_s * (sys.time() - t_shear) * r_mean;
        progress.update(sys.time() - t0, j_end / t.max_shear_displacement_m,
                        run.steps * sys.particles().size(),
                        "j " + std::to_string(x.shear_displacement_m * 1e3) + " mm, tau " +
                            std::to_string(x.shear_stress_Pa) + " Pa");
        if (j_end >= t.max_shear_displacement_m - 1e-12)
            break;
    }
    const double count = double(run.samples.size());
    run.rms_load_error = std::sqrt(err2 / count);
    for (const auto &x : run.samples)
        run.mean_pressure_Pa += x.normal_pressure_Pa / count;
    // tau_max: the largest mean over 5 consecutive samples (a DEM torque rattles).
    const std::size_t w = std::min<std::size_t>(5, run.samples.size());
    for (std::size_t i = 0; i + w <= run.samples.size(); ++i) {
        double sum = 0.0;
        for (std::size_t k = i; k < i + w; ++k)
            sum += run.samples[k].shear_stress_Pa;
        run.max_shear_stress_Pa = std::max(run.max_shear_stress_Pa, sum / double(w));
    }
    run.wall_s = secondsSince(run_start);
    std::fprintf(stderr,
                 "[bevameter_shear] sigma = %.4g Pa: loaded in %.3f s (grouser tips %.2f mm "
                 "deep), %llu steps in %.1f s, tau_max %.4g Pa, load held within %.1f %% "
                 "(rms %.1f %%)\n",
                 pressure, run.load_time_s, run.sinkage_at_load_m * 1e3,
                 static_cast<unsigned long long>(run.steps), run.wall_s, run.max_shear_stress_Pa,
                 100 * run.max_load_error, 100 * run.rms_load_error);
    return run;
}

} // namespace

ShearAnnulusResult runShearAnnulus(const ShearAnnulusScenario &scenario,
                                   const LabRunOptions &options) {
    return runLabExperiment(ShearAnnulusExperiment{scenario}, options);
}

std::string ShearAnnulusResult::report() const {
    std::ostringstream out;
    out << std::setprecision(5);
    out << "Virtual bevameter (shear annulus)\n";
    writeBedLine(out, bed);
    out << "  annulus R_i = " << annulus.inner_radius_m * 1e3
        << " mm, R_o = " << annulus.outer_radius_m * 1e3 << " mm, " << annulus.grouser_count
        << " grousers of " << annulus.grouser_height_m * 1e3
        << " mm; Gamma = (R_o - R_i) / (2 r_max) = " << resolution
        << "; j = theta R_mean, R_mean = " << annulus.meanRadius_m() * 1e3 << " mm\n";
    for (const auto &r : runs) {
        out << "  sigma = " << r.target_pressure_Pa << " Pa (F = " << r.target_force_N
            << " N): loaded in " << r.load_time_s << " s, grouser tips "
            << r.sinkage_at_load_m * 1e3 << " mm deep; mean sigma while shearing "
            << r.mean_pressure_Pa << " Pa, load within " << 100 * r.max_load_error << " % (rms "
            << 100 * r.rms_load_error << " %); tau_max " << r.max_shear_stress_Pa
            << " Pa; final sinkage " << r.samples.back().sinkage_m * 1e3
            << " mm; rim to region side " << r.wall_gap_m * 1e3 << " mm; " << r.steps << " steps, "
            << r.wall_s << " s wall\n";
    }
    if (fit)
        out << fit->describe();
    else
        out << "  no Janosi fit: " << fit_note << "\n";
    out << "  total wall time " << wall_s << " s\n";
    return out.str();
}

LabSummary ShearAnnulusResult::summary() const {
    LabSummary s{kTest, scenario, "target_pressure_Pa", bed, {}, fit_note, {}, wall_s};
    if (fit) {
        const auto &f = *fit;
        s.fits.push_back({"janosi",
                          f.degrees_of_freedom,
                          {{"c", "Pa", f.parameters.cohesion_Pa, f.half_width_95[0]},
                           {"phi", "deg", f.parameters.friction_angle_deg, f.half_width_95[1]},
                           {"K", "m", f.parameters.shear_modulus_m, f.half_width_95[2]}}});
    }
    for (const auto &r : runs) {
        LabRunSummary x;
        x.values = {{"target_pressure_Pa", r.target_pressure_Pa},
                    {"target_force_N", r.target_force_N},
                    {"mean_pressure_Pa", r.mean_pressure_Pa},
                    {"max_shear_stress_Pa", r.max_shear_stress_Pa},
                    {"load_time_s", r.load_time_s},
                    {"sinkage_at_load_m", r.sinkage_at_load_m},
                    {"max_load_error", r.max_load_error},
                    {"rms_load_error", r.rms_load_error},
                    {"surface_m", r.surface_m},
                    {"wall_gap_m", r.wall_gap_m},
                    {"steps", double(r.steps)},
                    {"wall_s", r.wall_s}};
        std::vector<double> time, rotation, j, force, sigma, torque, tau, sinkage;
        for (const auto &p : r.samples) {
            time.push_back(p.time_s);
            rotation.push_back(p.rotation_rad);
            j.push_back(p.shear_displacement_m);
            force.push_back(p.normal_force_N);
            sigma.push_back(p.normal_pressure_Pa);
            torque.push_back(p.torque_N_m);
            tau.push_back(p.shear_stress_Pa);
            sinkage.push_back(p.sinkage_m);
        }
        x.curves = {
            {"time_s", time},          {"rotation_rad", rotation},    {"shear_displacement_m", j},
            {"normal_force_N", force}, {"normal_pressure_Pa", sigma}, {"torque_N_m", torque},
            {"shear_stress_Pa", tau},  {"sinkage_m", sinkage}};
        s.runs.push_back(x);
    }
    return s;
}

void ShearAnnulusResult::writeCsvs(const std::string &directory) const {
    const fs::path dir(directory);
    {
        auto csv =
            openCsv(dir, "shear_displacement.csv",
                    "target_pressure_Pa,time_s,rotation_rad,shear_displacement_m,normal_force_N,"
                    "normal_pressure_Pa,torque_N_m,shear_stress_Pa,sinkage_m");
        for (const auto &r : runs)
            for (const auto &s : r.samples)
                csv << r.target_pressure_Pa << ',' << s.time_s << ',' << s.rotation_rad << ','
                    << s.shear_displacement_m << ',' << s.normal_force_N << ','
                    << s.normal_pressure_Pa << ',' << s.torque_N_m << ',' << s.shear_stress_Pa
                    << ',' << s.sinkage_m << '\n';
    }
    auto csv = openCsv(dir, "janosi_fit.csv", "parameter,value,standard_error,half_width_95,unit");
    if (fit) {
        const auto &f = *fit;
        csv << "c," << f.parameters.cohesion_Pa << ',' << f.standard_error[0] << ','
            << f.half_width_95[0] << ",Pa\n";
        csv << "phi," << f.parameters.friction_angle_deg << ',' << f.standard_error[1] << ','
            << f.half_width_95[1] << ",deg\n";
        csv << "K," << f.parameters.shear_modulus_m << ',' << f.standard_error[2] << ','
            << f.half_width_95[2] << ",m\n";
        for (const auto &r : runs)
            csv << "sigma_mean," << r.mean_pressure_Pa << ",,,Pa\n";
    }
}

Quantities shearAnnulusQuantities(const ShearAnnulusResult &result) {
    Quantities q;
    for (const auto &r : result.runs) {
        std::ostringstream name;
        name << "tau_max, sigma = " << r.target_pressure_Pa << " Pa";
        q.push_back({name.str(), "Pa", r.max_shear_stress_Pa});
    }
    if (result.fit) {
        q.push_back({"Janosi c", "Pa", result.fit->parameters.cohesion_Pa});
        q.push_back({"Janosi phi", "deg", result.fit->parameters.friction_angle_deg});
        q.push_back({"Janosi K", "m", result.fit->parameters.shear_modulus_m});
    }
    return q;
}

std::vector<NumericalCheck> checkShearAnnulus(const ShearAnnulusScenario &scenario,
                                              const ShearAnnulusResult &baseline,
                                              const CheckRequest &request,
                                              const LabRunOptions &options) {
    return runNumericalChecks(
        request, shearAnnulusQuantities(baseline),
        [&](CheckKind kind, double factor, const std::string &name) {
            ShearAnnulusScenario changed = scenario;
            // Widened about the annulus's axis, so that it stays centred in the wider box.
            changed.soil = kind == CheckKind::Walls
                               ? widenedSoil(scenario.soil, factor, scenario.test.centre_m)
                               : refinedSoil(scenario.soil, factor);
            return shearAnnulusQuantities(runShearAnnulus(changed, checkRunOptions(options, name)));
        });
}

} // namespace grainlink::lab
