#include "grainlink/lab/Wheel.hpp"

#include "grainlink/dem/Progress.hpp"
#include "grainlink/dem/ScenarioRun.hpp"
#include "grainlink/dem/WheelMesh.hpp"
#include "grainlink/lab/LabBed.hpp"
#include "grainlink/lab/LoadServo.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace grainlink::lab {

namespace fs = std::filesystem;
using dem::Vec3;

double rimSpeed(double carriage_speed_m_s, double slip) {
    if (!(slip >= -1.0 && slip < 1.0))
        throw std::invalid_argument("rimSpeed: slip must lie in [-1, 1), got " +
                                    std::to_string(slip));
    return slip >= 0.0 ? carriage_speed_m_s / (1.0 - slip) : carriage_speed_m_s * (1.0 + slip);
}

WheelFrame steeredFrame(double slip_angle_deg) {
    const double b = slip_angle_deg * M_PI / 180.0, c = std::cos(b), s = std::sin(b);
    return {Vec3(c, s, 0.0), Vec3(-s, c, 0.0), Vec3(s, -c, 0.0)};
}

Eigen::Vector2d steeredHalfExtent(double outer_radius_m, double width_m, double slip_angle_deg) {
    const WheelFrame f = steeredFrame(slip_angle_deg);
    return {outer_radius_m * f.heading.x() + 0.5 * width_m * f.heading.y(),
            outer_radius_m * f.heading.y() + 0.5 * width_m * f.heading.x()};
}

WheelScenario parseWheel(const config::ConfigNode &root) {
    WheelScenario s;
    s.name = root["name"].text();
    s.soil = parseLabSoil(root, {"the wheel test adds its own wheel", {}, {}, {}});
    const auto w = root["wheel"];
    WheelSpec &t = s.test;
    t.shape = body::parseWheelShape(w["shape"]);
    t.load_N = w["load_N"].positive();
    for (const config::ConfigNode &slip : w["slips"].items()) {
        const double v = slip.number();
        if (!(v >= -1.0 && v < 1.0))
            slip.fail("a slip lies in [-1, 1) (s = (v_rim - v) / max(v_rim, v); -1 a locked "
                      "wheel), got " + std::to_string(v));
        t.slips.push_back(v);
    }
    if (t.slips.empty())
        w["slips"].fail("give at least one slip");
    if (w.has("slip_angle_deg"))
        t.slip_angle_deg = w["slip_angle_deg"].number(0.0, 90.0);
    t.carriage_speed_m_s = w["carriage_speed_m_s"].positive();
    t.travel_m = w["travel_m"].positive();
    if (w.has("steady_fraction"))
        t.steady_fraction = w["steady_fraction"].number(0.05, 1.0);
    if (w.has("approach_speed_m_s"))
        t.approach_speed_m_s = w["approach_speed_m_s"].positive();
    const auto servo = w["servo"];
    t.servo = parseServo(servo, t.servo, s.warnings);
    servo.finish();
    if (w.has("start_clearance_m"))
        t.start_clearance_m = w["start_clearance_m"].nonNegative();
    if (w.has("end_margin_m"))
        t.end_margin_m = w["end_margin_m"].nonNegative();
    if (w.has("sample_interval_s"))
        t.sample_interval_s = w["sample_interval_s"].positive();
    if (w.has("friction_coefficient"))
        t.friction_coefficient = w["friction_coefficient"].nonNegative();
    if (w.has("min_resolution"))
        t.min_resolution = w["min_resolution"].positive();
    if (w.has("end_wall_limit"))
        t.end_wall_limit = w["end_wall_limit"].number(0.01, 1.0);
    w.finish();

    // The wheel drives along x from one end of the region: the travel must fit (seed eq. 11
    // for the resolution, with L_min the wheel's width).
    const double r_max = s.soil.deposition.radius.largest();
    const double gamma = t.shape.width_m / (2.0 * r_max);
    if (gamma < t.min_resolution - 1e-12) {
        std::ostringstream msg;
        msg << "the wheel's width " << t.shape.width_m << " m is " << gamma
            << " largest grain diameters; the test needs at least min_resolution = "
            << t.min_resolution << " (seed eq. 11): use smaller grains or a wider wheel";
        w["shape"]["width_m"].fail(msg.str());
    }
    if (t.end_margin_m == 0.0)
        t.end_margin_m = 4.0 * r_max;
    const Eigen::Vector2d half = steeredHalfExtent(
        0.5 * t.shape.diameter_m + t.shape.grouser_height_m, t.shape.width_m, t.slip_angle_deg);
    const double half_x = half.x(), half_y = half.y();
    const Vec3 &lo = s.soil.deposition.region_lower_m, &hi = s.soil.deposition.region_upper_m;
    const double room = hi.x() - lo.x() - 2.0 * (half_x + t.end_margin_m);
    if (t.travel_m > room) {
        std::ostringstream msg;
        msg << "the wheel (" << half_x << " m from its centre to its front along x, "
            << t.end_margin_m << " m from each end) can travel at most " << std::max(room, 0.0)
            << " m along x in the deposition region; shorten travel_m or lengthen the region";
        w["travel_m"].fail(msg.str());
    }
    // Across the travel it keeps a grain's diameter from the region's sides.
    if (2.0 * (half_y + 2.0 * r_max) > hi.y() - lo.y() + 1e-12) {
        std::ostringstream msg;
        msg << "the wheel reaches " << half_y << " m across the travel at slip angle "
            << t.slip_angle_deg << " deg; with a grain diameter to spare on each side it needs a "
            << 2.0 * (half_y + 2.0 * r_max) << " m wide region (y), not " << hi.y() - lo.y()
            << " m: widen the region or lower the slip angle";
        (w.has("slip_angle_deg") ? w["slip_angle_deg"] : w["shape"]["width_m"]).fail(msg.str());
    }
    root.finish();
    return s;
}

WheelScenario loadWheel(const std::string &path) {
    return parseWheel(config::ConfigNode::loadFile(path));
}

namespace {

/// Prescribed motion of the wheel (mesh body 0): piecewise-constant carriage speed, vertical
/// speed and spin about the steered axle, changed between sample intervals by retarget().
struct WheelDrive {
    dem::RigidBodyState initial;
    dem::Quat yaw = dem::Quat::Identity();                         ///< the slip angle about z
    double t_ref = 0.0, x_ref = 0.0, z_ref = 0.0, theta_ref = 0.0; ///< at the last change
    double v_x = 0.0, v_z = 0.0, omega = 0.0;                      ///< since then
    double x(double t) const { return x_ref + v_x * (t - t_ref); }
    double z(double t) const { return z_ref + v_z * (t - t_ref); }
    double theta(double t) const { return theta_ref + omega * (t - t_ref); }
    dem::RigidBodyState at(double t) const {
        dem::RigidBodyState s = initial;
        s.position_m.x() = x(t);
        s.position_m.z() = z(t);
        s.orientation = yaw * dem::Quat(Eigen::AngleAxisd(theta(t), Vec3::UnitY()));
        s.linear_velocity_m_s = Vec3(v_x, 0.0, v_z);
        s.angular_velocity_rad_s = omega * (yaw * Vec3::UnitY()); // about the steered axle
        return s;
    }
    dem::SegmentedMotion motion() const { return dem::constantVelocity(at(t_ref), t_ref); }
    void retarget(dem::DemSystem &sys, double t, double new_v_x, double new_v_z,
                  double new_omega) {
        x_ref = x(t);
        z_ref = z(t);
        theta_ref = theta(t);
        t_ref = t;
        v_x = new_v_x;
        v_z = new_v_z;
        omega = new_omega;
        sys.setBodyMotion(0, motion());
    }
};

SteadyValue steady(const std::vector<WheelSample> &samples, std::size_t count,
                   double WheelSample::*member) {
    SteadyValue v;
    const std::size_t first = samples.size() - count;
    for (std::size_t i = first; i < samples.size(); ++i)
        v.mean += samples[i].*member / double(count);
    for (std::size_t i = first; i < samples.size(); ++i)
        v.sd += std::pow(samples[i].*member - v.mean, 2);
    v.sd = count > 1 ? std::sqrt(v.sd / double(count - 1)) : 0.0;
    return v;
}

/// The wheel test's steps of the lab skeleton (LabExperiment.hpp): one slip per condition.
struct WheelExperiment {
    using Result = WheelResult;
    const WheelScenario &scenario;

    LabBed prepareBed(double progress_interval_s) const {
        return prepareLabBed(scenario.soil, regionFootprint(scenario.soil), progress_interval_s);
    }
    Result start(const LabBed &bed) const {
        Result result;
        result.shape = scenario.test.shape;
        result.load_N = scenario.test.load_N;
        result.slip_angle_deg = scenario.test.slip_angle_deg;
        result.resolution = scenario.test.shape.width_m / (2.0 * bed.summary.largest_radius_m);
        return result;
    }
    std::vector<double> conditions() const { return scenario.test.slips; }
    WheelRun run(const LabBed &bed, double slip, double progress_interval_s) const;
    void fit(Result &) const {} // steady values per slip; no law is fitted
};

WheelRun WheelExperiment::run(const LabBed &bed, double slip, double progress_interval_s) const {
    const auto run_start = std::chrono::steady_clock::now();
    const WheelSpec &t = scenario.test;
    const double dt = bed.summary.time_step_s;
    const double surface = bed.summary.surface_m;
    const double radius = 0.5 * t.shape.diameter_m, reach = radius + t.shape.grouser_height_m;
    const Vec3 lower = scenario.soil.deposition.region_lower_m;
    const double y = testCentre(scenario.soil, std::nullopt).y();
    const auto steps_per_sample =
        std::max<std::uint64_t>(1, std::llround(t.sample_interval_s / dt));
    const double interval_s = double(steps_per_sample) * dt; // the servo's real interval

    dem::DemSystem sys = *bed.system; // every slip drives on its own copy of the settled bed
    WheelRun run;
    run.slip = slip;
    run.slip_angle_deg = t.slip_angle_deg;
    run.carriage_speed_m_s = t.carriage_speed_m_s;
    run.angular_speed_rad_s = rimSpeed(t.carriage_speed_m_s, slip) / radius;
    run.surface_m = surface;
    const WheelFrame frame = steeredFrame(t.slip_angle_deg);
    // The wheel's footprint starts end_margin_m in from the region's end.
    const double x0 = lower.x() + t.end_margin_m +
                      steeredHalfExtent(reach, t.shape.width_m, t.slip_angle_deg).x();
    // The lowest point starts above every grain under the wheel's footprint.
    const double highest = highestGrainUnder(
        sys.particles(), Eigen::Vector2d(x0, y), std::hypot(reach, 0.5 * t.shape.width_m), surface);
    WheelDrive drive;
    drive.yaw = dem::Quat(Eigen::AngleAxisd(t.slip_angle_deg * M_PI / 180.0, Vec3::UnitZ()));
    drive.initial.position_m = Vec3(x0, y, highest + t.start_clearance_m + reach);
    drive.t_ref = sys.time();
    drive.x_ref = x0;
    drive.z_ref = drive.initial.position_m.z();
    drive.v_z = -t.approach_speed_m_s;
    dem::MeshBody wheel("wheel", dem::makeWheel(t.shape), drive.at(sys.time()));
    wheel.friction_coefficient = t.friction_coefficient;
    sys.addBody(std::move(wheel), drive.motion());
    sys.prepare();

    LoadServo servo = t.servo.loadServo(t.load_N);
    char label[48];
    std::snprintf(label, sizeof label, "wheel s=%.3g", slip);
    dem::Progress progress(label, progress_interval_s);
    const double t0 = sys.time();
    // The bin's end walls: ahead of the travel (inward normal along -x) and behind it. How much
    // harder the soil pushes on the one the wheel pushes towards than before the drive is the
    // part of the wheel's push the soil hands on to the bin's end rather than carrying itself:
    // large, and the steady values are the bin's, not the soil's (end_wall_share, refused in
    // runWheel).
    const dem::EndWalls walls = dem::endWallsAlongX(sys.planes());
    struct WallPush {
        double ahead_N = 0.0, behind_N = 0.0; ///< [N] the soil's push on them, along +x and -x
    };
    struct Interval {
        MeanLoad load;
        double t_mid_s;
        WallPush end_walls; ///< over the interval
    };
    std::vector<Vec3> plane_forces;
    const auto interval = [&]() {
        const double t_start = sys.time();
        Interval out{observeInterval(sys, steps_per_sample, {0}, &plane_forces)[0], 0.0, {}};
        out.t_mid_s = 0.5 * (t_start + sys.time());
        for (int p : walls.ahead)
            out.end_walls.ahead_N += plane_forces[std::size_t(p)].x();
        for (int p : walls.behind)
            out.end_walls.behind_N -= plane_forces[std::size_t(p)].x();
        run.steps += steps_per_sample;
        return out;
    };

    // Approach at constant speed until the load is first reached, then hold it. The end walls'
    // push at rest is the mean over the hold (without one, the approach's last interval).
    WallPush at_load;
    std::vector<WallPush> held;
    for (;;) {
        const Interval s = interval();
        progress.update(sys.time() - t0, 0.0, run.steps * sys.particles().size(),
                        "approach, F_z " + std::to_string(s.load.force_N.z()) + " N");
        if (s.load.force_N.z() >= t.load_N) {
            at_load = s.end_walls;
            drive.retarget(sys, sys.time(), 0.0, -servo.update(s.load.force_N.z(), interval_s), 0.0);
            break;
        }
        if (sys.time() - t0 > t.servo.max_load_time_s) {
            std::ostringstream msg;
            msg << "wheel: the wheel did not reach its load " << t.load_N
                << " N within servo.max_load_time_s = " << t.servo.max_load_time_s << " s (last "
                << s.load.force_N.z() << " N, rim " << surface - (drive.z(sys.time()) - radius)
                << " m below the surface); raise servo.max_load_time_s or approach_speed_m_s, "
                   "or lower load_N";
            throw std::runtime_error(msg.str());
        }
    }
    const double hold_end = sys.time() + t.servo.hold_s;
    while (sys.time() < hold_end - 0.5 * dt) {
        const Interval s = interval();
        drive.retarget(sys, sys.time(), 0.0, -servo.update(s.load.force_N.z(), interval_s), 0.0);
        held.push_back(s.end_walls);
    }
    WallPush at_rest = held.empty() ? at_load : WallPush{};
    for (const WallPush &h : held) {
        at_rest.ahead_N += h.ahead_N / double(held.size());
        at_rest.behind_N += h.behind_N / double(held.size());
    }
    run.load_time_s = sys.time() - t0;
    run.sinkage_at_load_m = surface - (drive.z(sys.time()) - radius);

    // Drive: the spin and the carriage speed set, the servo holding the load.
    const double t_drive = sys.time(), x_drive = drive.x(t_drive);
    drive.retarget(sys, t_drive, run.carriage_speed_m_s, drive.v_z, run.angular_speed_rad_s);
    for (;;) {
        const Interval s = interval();
        drive.retarget(sys, sys.time(), run.carriage_speed_m_s,
                       -servo.update(s.load.force_N.z(), interval_s), run.angular_speed_rad_s);
        WheelSample x;
        x.time_s = s.t_mid_s - t_drive;
        x.travel_m = drive.x(s.t_mid_s) - x_drive;
        x.traction_N = s.load.force_N.dot(frame.heading);
        x.side_force_N = s.load.force_N.dot(frame.side);
        x.vertical_load_N = s.load.force_N.z();
        x.torque_N_m = -s.load.torque_N_m.dot(frame.axle);
        x.sinkage_m = surface - (drive.z(s.t_mid_s) - radius);
        x.end_wall_ahead_N = s.end_walls.ahead_N - at_rest.ahead_N;
        x.end_wall_behind_N = s.end_walls.behind_N - at_rest.behind_N;
        run.samples.push_back(x);
        const double travelled = drive.x(sys.time()) - x_drive;
        progress.update(sys.time() - t0, travelled / t.travel_m, run.steps * sys.particles().size(),
                        "travel " + std::to_string(travelled * 1e3) + " mm, traction " +
                            std::to_string(x.traction_N) + " N");
        if (travelled >= t.travel_m - 1e-12)
            break;
    }
    const double steady_from = (1.0 - t.steady_fraction) * t.travel_m;
    run.steady_samples = std::size_t(std::count_if(
        run.samples.begin(), run.samples.end(),
        [&](const WheelSample &x) { return x.travel_m >= steady_from; }));
    if (run.steady_samples < 2)
        throw std::runtime_error("wheel: fewer than 2 samples in the steady stretch at slip " +
                                 std::to_string(slip) +
                                 ": lengthen travel_m or shorten sample_interval_s");
    run.traction_N = steady(run.samples, run.steady_samples, &WheelSample::traction_N);
    run.side_force_N = steady(run.samples, run.steady_samples, &WheelSample::side_force_N);
    run.vertical_load_N = steady(run.samples, run.steady_samples, &WheelSample::vertical_load_N);
    run.torque_N_m = steady(run.samples, run.steady_samples, &WheelSample::torque_N_m);
    run.sinkage_m = steady(run.samples, run.steady_samples, &WheelSample::sinkage_m);
    run.end_wall_ahead_N = steady(run.samples, run.steady_samples, &WheelSample::end_wall_ahead_N);
    run.end_wall_behind_N =
        steady(run.samples, run.steady_samples, &WheelSample::end_wall_behind_N);
    // The wheel's push on the soil along x is the soil's force on it, reversed.
    const double push_N =
        -(run.traction_N.mean * frame.heading.x() + run.side_force_N.mean * frame.side.x());
    run.end_wall_share =
        dem::endWallShare(run.end_wall_ahead_N.mean, run.end_wall_behind_N.mean, push_N, t.load_N);
    for (std::size_t i = run.samples.size() - run.steady_samples; i < run.samples.size(); ++i)
        run.max_load_error = std::max(
            run.max_load_error, std::abs(run.samples[i].vertical_load_N - t.load_N) / t.load_N);
    run.wall_s = secondsSince(run_start);
    std::fprintf(
        stderr,
        "[wheel] slip %.3g at slip angle %.3g deg: carriage %.4g m/s, spin %.4g rad/s, loaded "
        "in %.3f s (static sinkage %.2f mm); steady traction %.4g +- %.2g N, side force "
        "%.4g +- %.2g N, load %.4g +- %.2g N, torque %.4g +- %.2g N m, sinkage %.2f +- "
        "%.2f mm, end walls %+.3g +- %.2g N ahead, %+.3g +- %.2g N behind (share %.2f); %llu "
        "steps in %.1f s\n",
        slip, run.slip_angle_deg, run.carriage_speed_m_s, run.angular_speed_rad_s, run.load_time_s,
        run.sinkage_at_load_m * 1e3, run.traction_N.mean, run.traction_N.sd, run.side_force_N.mean,
        run.side_force_N.sd, run.vertical_load_N.mean, run.vertical_load_N.sd, run.torque_N_m.mean,
        run.torque_N_m.sd, run.sinkage_m.mean * 1e3, run.sinkage_m.sd * 1e3,
        run.end_wall_ahead_N.mean, run.end_wall_ahead_N.sd, run.end_wall_behind_N.mean,
        run.end_wall_behind_N.sd, run.end_wall_share, static_cast<unsigned long long>(run.steps),
        run.wall_s);
    return run;
}

} // namespace

WheelResult runWheel(const WheelScenario &scenario, const LabRunOptions &options) {
    WheelResult result = runLabExperiment(WheelExperiment{scenario}, options);
    // Refused after its outputs are written: they stay readable, the steady values flagged.
    std::ostringstream bound;
    for (const WheelRun &r : result.runs)
        if (r.end_wall_share > scenario.test.end_wall_limit)
            bound << (bound.tellp() > 0 ? "; " : "wheel: ") << "at slip " << r.slip
                  << " the bin's end walls took " << std::lround(100.0 * r.end_wall_share)
                  << " % of the wheel's push along its travel over the steady stretch";
    if (bound.tellp() > 0) {
        bound << ", more than wheel.end_wall_limit = " << scenario.test.end_wall_limit
              << ": the soil pushed ahead of the wheel reached the bin's end, and the steady "
                 "values are the bin's, not the soil's. Lengthen the bin (its walls and the "
                 "deposition region along x) or shorten wheel.travel_m";
        if (!options.output_directory.empty())
            bound << "; the results are written to " << options.output_directory;
        throw std::runtime_error(bound.str());
    }
    return result;
}

std::string WheelResult::report() const {
    std::ostringstream out;
    out << std::setprecision(5);
    out << "Single-wheel test at set slips\n";
    writeBedLine(out, bed);
    out << "  wheel D = " << shape.diameter_m * 1e3 << " mm, b = " << shape.width_m * 1e3 << " mm, "
        << shape.grouser_count << " grousers of " << shape.grouser_height_m * 1e3 << " mm; load "
        << load_N << " N; slip angle " << slip_angle_deg
        << " deg; Gamma = b / (2 r_max) = " << resolution << "\n";
    out << "  steady means +- sd over the last stretch of travel (s = (v_rim - v) / max(v_rim, "
           "v); traction along the wheel's heading, side force across it):\n";
    for (const auto &r : runs)
        out << "  s = " << r.slip << ": traction " << r.traction_N.mean << " +- " << r.traction_N.sd
            << " N, side force " << r.side_force_N.mean << " +- " << r.side_force_N.sd
            << " N, vertical load " << r.vertical_load_N.mean << " +- " << r.vertical_load_N.sd
            << " N (within " << 100 * r.max_load_error << " %), torque " << r.torque_N_m.mean
            << " +- " << r.torque_N_m.sd << " N m, sinkage " << r.sinkage_m.mean * 1e3 << " +- "
            << r.sinkage_m.sd * 1e3 << " mm (static " << r.sinkage_at_load_m * 1e3
            << " mm), end walls " << r.end_wall_ahead_N.mean << " +- " << r.end_wall_ahead_N.sd
            << " N ahead, " << r.end_wall_behind_N.mean << " +- " << r.end_wall_behind_N.sd
            << " N behind (share " << r.end_wall_share << "); " << r.steady_samples << " of "
            << r.samples.size() << " samples; " << r.steps << " steps, " << r.wall_s << " s wall\n";
    out << "  total wall time " << wall_s << " s\n";
    return out.str();
}

LabSummary WheelResult::summary() const {
    LabSummary s{kTest, scenario, "slip", bed, {}, fit_note, {}, wall_s};
    for (const auto &r : runs) {
        LabRunSummary x;
        x.values = {{"slip", r.slip},
                    {"slip_angle_deg", r.slip_angle_deg},
                    {"carriage_speed_m_s", r.carriage_speed_m_s},
                    {"angular_speed_rad_s", r.angular_speed_rad_s},
                    {"traction_N", r.traction_N.mean},
                    {"traction_sd_N", r.traction_N.sd},
                    {"side_force_N", r.side_force_N.mean},
                    {"side_force_sd_N", r.side_force_N.sd},
                    {"vertical_load_N", r.vertical_load_N.mean},
                    {"vertical_load_sd_N", r.vertical_load_N.sd},
                    {"torque_N_m", r.torque_N_m.mean},
                    {"torque_sd_N_m", r.torque_N_m.sd},
                    {"sinkage_m", r.sinkage_m.mean},
                    {"sinkage_sd_m", r.sinkage_m.sd},
                    {"end_wall_ahead_N", r.end_wall_ahead_N.mean},
                    {"end_wall_ahead_sd_N", r.end_wall_ahead_N.sd},
                    {"end_wall_behind_N", r.end_wall_behind_N.mean},
                    {"end_wall_behind_sd_N", r.end_wall_behind_N.sd},
                    {"end_wall_share", r.end_wall_share},
                    {"steady_samples", double(r.steady_samples)},
                    {"sinkage_at_load_m", r.sinkage_at_load_m},
                    {"load_time_s", r.load_time_s},
                    {"max_load_error", r.max_load_error},
                    {"surface_m", r.surface_m},
                    {"steps", double(r.steps)},
                    {"wall_s", r.wall_s}};
        std::vector<double> time, travel, traction, side, load, torque, sinkage, ahead, behind;
        for (const auto &p : r.samples) {
            time.push_back(p.time_s);
            travel.push_back(p.travel_m);
            traction.push_back(p.traction_N);
            side.push_back(p.side_force_N);
            load.push_back(p.vertical_load_N);
            torque.push_back(p.torque_N_m);
            sinkage.push_back(p.sinkage_m);
            ahead.push_back(p.end_wall_ahead_N);
            behind.push_back(p.end_wall_behind_N);
        }
        // The series over travel; the plain names are the steady values above.
        x.curves = {{"time_s", time},
                    {"travel_m", travel},
                    {"traction_series_N", traction},
                    {"side_force_series_N", side},
                    {"vertical_load_series_N", load},
                    {"torque_series_N_m", torque},
                    {"sinkage_series_m", sinkage},
                    {"end_wall_ahead_series_N", ahead},
                    {"end_wall_behind_series_N", behind}};
        s.runs.push_back(x);
    }
    return s;
}

void WheelResult::writeCsvs(const std::string &directory) const {
    const fs::path dir(directory);
    {
        auto csv =
            openCsv(dir, "wheel_travel.csv",
                    "slip,slip_angle_deg,time_s,travel_m,traction_N,side_force_N,vertical_load_N,"
                    "torque_N_m,sinkage_m,end_wall_ahead_N,end_wall_behind_N");
        for (const auto &r : runs)
            for (const auto &s : r.samples)
                csv << r.slip << ',' << r.slip_angle_deg << ',' << s.time_s << ',' << s.travel_m
                    << ',' << s.traction_N << ',' << s.side_force_N << ',' << s.vertical_load_N
                    << ',' << s.torque_N_m << ',' << s.sinkage_m << ',' << s.end_wall_ahead_N << ','
                    << s.end_wall_behind_N << '\n';
    }
    auto csv = openCsv(dir, "wheel_slip.csv",
                       "slip,slip_angle_deg,carriage_speed_m_s,angular_speed_rad_s,traction_N,"
                       "traction_sd_N,side_force_N,side_force_sd_N,vertical_load_N,"
                       "vertical_load_sd_N,torque_N_m,torque_sd_N_m,sinkage_m,sinkage_sd_m,"
                       "end_wall_ahead_N,end_wall_behind_N,end_wall_share,steady_samples");
    for (const auto &r : runs)
        csv << r.slip << ',' << r.slip_angle_deg << ',' << r.carriage_speed_m_s << ','
            << r.angular_speed_rad_s << ',' << r.traction_N.mean << ',' << r.traction_N.sd << ','
            << r.side_force_N.mean << ',' << r.side_force_N.sd << ',' << r.vertical_load_N.mean
            << ',' << r.vertical_load_N.sd << ',' << r.torque_N_m.mean << ',' << r.torque_N_m.sd
            << ',' << r.sinkage_m.mean << ',' << r.sinkage_m.sd << ',' << r.end_wall_ahead_N.mean
            << ',' << r.end_wall_behind_N.mean << ',' << r.end_wall_share << ',' << r.steady_samples
            << '\n';
}

Quantities wheelQuantities(const WheelResult &result) {
    Quantities q;
    for (const auto &r : result.runs) {
        std::ostringstream at;
        at << ", s = " << r.slip;
        q.push_back({"traction" + at.str(), "N", r.traction_N.mean});
        q.push_back({"sinkage" + at.str(), "m", r.sinkage_m.mean});
        if (r.slip_angle_deg != 0.0) // straight, its mean is zero by symmetry
            q.push_back({"side force" + at.str(), "N", r.side_force_N.mean});
    }
    return q;
}

std::vector<NumericalCheck> checkWheel(const WheelScenario &scenario, const WheelResult &baseline,
                                       const CheckRequest &request, const LabRunOptions &options) {
    return runNumericalChecks(
        request, wheelQuantities(baseline),
        [&](CheckKind kind, double factor, const std::string &name) {
            WheelScenario changed = scenario;
            changed.soil = checkedSoil(scenario.soil, kind, factor);
            return wheelQuantities(runWheel(changed, checkRunOptions(options, name)));
        });
}

} // namespace grainlink::lab
