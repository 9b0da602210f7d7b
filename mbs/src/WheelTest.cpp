#include "grainlink/mbs/WheelTest.hpp"

#include "CheckpointText.hpp"
#include "grainlink/dem/SteadySignal.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace grainlink::mbs {

namespace {

SteadyValue steadyValue(const std::vector<double> &values) {
    const auto s = dem::summarizeSignal(values, 10);
    return {s.mean, s.sd, s.standard_error};
}

Drift drift(const std::vector<double> &times, const std::vector<double> &values, double span_s) {
    const auto trend = dem::signalTrend(times, values, 20);
    return {trend.slope_per_s * span_s, trend.slope_se_per_s * span_s,
            trend.consistentWithZero()};
}

} // namespace

void WheelTest::judge(double t) {
    std::vector<double> time, slip, torque, pull, vertical, height;
    for (const auto &w : drive_samples_) {
        time.push_back(w.time_s);
        slip.push_back(w.slip);
        torque.push_back(w.motor_torque_N_m);
        pull.push_back(w.soil_force_x_N);
        vertical.push_back(w.soil_force_z_N);
        height.push_back(w.wheel_z_m);
    }
    const double span = settings_.steady_window_s;
    steady_.time_s = t;
    steady_.span_start_s = time.empty() ? t : time.front();
    steady_.slip = steadyValue(slip);
    steady_.motor_torque_N_m = steadyValue(torque);
    steady_.drawbar_pull_N = steadyValue(pull);
    steady_.vertical_force_N = steadyValue(vertical);
    steady_.wheel_z_m = steadyValue(height);
    steady_.slip_drift = drift(time, slip, span);
    steady_.height_drift_m = drift(time, height, span);
}

bool WheelTest::afterWindow(SingleWheelRig &rig, const Wrench &soil) {
    const auto o = rig.observables();
    const double t = rig.time();
    if (phase_ == Phase::Drop) {
        // Steady sinkage: over the last drop_settle_time_s the wheel's height stayed within
        // drop_settle_distance_m (robust to the contact chatter of single windows).
        drop_heights_.emplace_back(t, o.at("carriage_z_m"));
        while (drop_heights_.front().first < t - settings_.drop_settle_time_s)
            drop_heights_.pop_front();
        double low = 1e300, high = -1e300;
        for (const auto &[time, z] : drop_heights_) {
            low = std::min(low, z);
            high = std::max(high, z);
        }
        const bool covered = t - drop_heights_.front().first >= 0.9 * settings_.drop_settle_time_s;
        if (t >= settings_.drop_min_s && covered && high - low < settings_.drop_settle_distance_m) {
            rig.setRotationLocked(false);
            phase_ = Phase::Drive;
            drive_start_s_ = t;
            std::fprintf(stderr,
                         "wheel test: sinkage steady at t = %.3f s; driving at %.3g rad/s\n", t,
                         rig.settings().angular_velocity_rad_s);
        } else if (t > settings_.drop_max_s && !settings_.until_end_time) {
            char text[256];
            std::snprintf(text, sizeof text,
                          "the drop phase ran %.3g s (wheel_test.drop_max_s = %.3g s) and the "
                          "wheel still moved %.3g mm over the last %.3g s (drop_settle_distance_m "
                          "= %.3g mm)",
                          t, settings_.drop_max_s, 1e3 * (high - low),
                          t - drop_heights_.front().first, 1e3 * settings_.drop_settle_distance_m);
            failure_ = text;
            return true;
        }
        return false;
    }
    if (phase_ == Phase::Steady)
        return !settings_.until_end_time;
    WheelSample s;
    s.time_s = t;
    s.slip = o.at("slip");
    s.motor_torque_N_m = o.at("motor_torque_N_m");
    s.soil_force_x_N = soil.force_N.x();
    s.soil_force_z_N = soil.force_N.z();
    s.wheel_z_m = o.at("carriage_z_m");
    drive_samples_.push_back(s);
    const double span = settings_.steady_window_s;
    while (!drive_samples_.empty() && drive_samples_.front().time_s < t - 2.0 * span)
        drive_samples_.pop_front();
    const double driven = t - drive_start_s_;
    if (driven < std::max(settings_.drive_min_s, 2.0 * span))
        return false;
    // The trend test over the last two spans: slip and height each change by less than their
    // tolerance per span, and by an amount consistent with zero. Two spans' means alone missed
    // a slow drift hidden in the fluctuation and judged a noisy flat signal unsteady.
    judge(t);
    steady_.revolutions = driven * rig.settings().angular_velocity_rad_s / (2.0 * M_PI);
    const auto within = [](const Drift &d, double tolerance) {
        return std::abs(d.per_span) < tolerance && d.consistent_with_zero;
    };
    if (within(steady_.slip_drift, settings_.steady_slip_tolerance) &&
        within(steady_.height_drift_m, settings_.steady_height_tolerance_m)) {
        phase_ = Phase::Steady;
        steady_.reached = true;
        return !settings_.until_end_time;
    }
    if (driven > settings_.drive_max_s && !settings_.until_end_time) {
        char text[160];
        std::snprintf(text, sizeof text,
                      "the drive phase ran %.3g s (wheel_test.drive_max_s = %.3g s) without a "
                      "steady state",
                      driven, settings_.drive_max_s);
        failure_ = text + std::string("; still changing: ") + stillChanging();
        return true;
    }
    return false;
}

std::string WheelTest::stillChanging() const {
    const double span = settings_.steady_window_s;
    const auto describe = [span](const char *name, const Drift &d, double tolerance,
                                 double scale, const char *unit) {
        char text[200];
        std::snprintf(text, sizeof text,
                      "%s by %+.3g +- %.2g%s per %.3g s (tolerance %.3g%s%s)", name,
                      scale * d.per_span, scale * d.standard_error, unit, span, scale * tolerance,
                      unit, d.consistent_with_zero ? "" : ", a trend unlike zero");
        return std::string(text);
    };
    return describe("slip", steady_.slip_drift, settings_.steady_slip_tolerance, 1.0, "") +
           ", height " +
           describe("", steady_.height_drift_m, settings_.steady_height_tolerance_m, 1e3, " mm")
               .substr(1);
}

std::string WheelTest::phaseName() const {
    switch (phase_) {
    case Phase::Drop:
        return "drop";
    case Phase::Drive:
        return "drive";
    case Phase::Steady:
        return "steady";
    }
    return "?";
}

std::string WheelTest::summary(double run_end_s) const {
    char text[640];
    if (!steady_.reached) {
        if (!failure_.empty())
            return "wheel test: no steady state: " + failure_;
        char ended[200];
        std::snprintf(ended, sizeof ended,
                      "wheel test: no steady state: the run ended at t = %.4g s "
                      "(coupling.end_time_s) after %.3g s of the %s phase",
                      run_end_s, run_end_s - (phase_ == Phase::Drop ? 0.0 : drive_start_s_),
                      phaseName().c_str());
        std::string text = ended;
        if (phase_ == Phase::Drive && steady_.time_s > 0.0)
            text += "; still changing: " + stillChanging();
        else if (phase_ == Phase::Drive)
            text += " (shorter than the drive_min_s or two steady_window_s it needs)";
        return text;
    }
    const auto &r = steady_;
    std::snprintf(text, sizeof text,
                  "wheel test: steady after %.3f s of driving (%.2f revolutions): over the last "
                  "%.3g s slip %.3f +- %.3f (se %.3f), drawbar pull %.2f +- %.2f N (se %.2f), "
                  "motor torque %.3f +- %.3f N m (se %.3f), vertical force %.2f +- %.2f N; "
                  "drift per %.3g s: slip %+.3f +- %.3f, height %+.2f +- %.2f mm",
                  r.time_s - drive_start_s_, r.revolutions, r.time_s - r.span_start_s,
                  r.slip.mean, r.slip.sd, r.slip.standard_error, r.drawbar_pull_N.mean,
                  r.drawbar_pull_N.sd, r.drawbar_pull_N.standard_error, r.motor_torque_N_m.mean,
                  r.motor_torque_N_m.sd, r.motor_torque_N_m.standard_error,
                  r.vertical_force_N.mean, r.vertical_force_N.sd, settings_.steady_window_s,
                  r.slip_drift.per_span, r.slip_drift.standard_error,
                  1e3 * r.height_drift_m.per_span, 1e3 * r.height_drift_m.standard_error);
    return text;
}

void WheelTest::writeSummaryJson(const std::string &path, double run_end_s,
                                 double normal_load_N) const {
    using nlohmann::json;
    const auto value = [](const SteadyValue &v) {
        return json{{"mean", v.mean}, {"sd", v.sd}, {"standard_error", v.standard_error}};
    };
    const auto trend = [](const Drift &d) {
        return json{{"per_span", d.per_span},
                    {"standard_error", d.standard_error},
                    {"consistent_with_zero", d.consistent_with_zero}};
    };
    const auto &r = steady_;
    json j{{"steady", r.reached},
           {"phase", phaseName()},
           {"message", summary(run_end_s)},
           {"run_end_s", run_end_s},
           {"normal_load_N", normal_load_N}};
    if (phase_ != Phase::Drop) {
        j["drive_start_s"] = drive_start_s_;
        j["span_s"] = {r.span_start_s, r.time_s};
        j["span_length_s"] = settings_.steady_window_s;
        j["revolutions"] = r.revolutions;
        j["slip"] = value(r.slip);
        j["motor_torque_N_m"] = value(r.motor_torque_N_m);
        j["drawbar_pull_N"] = value(r.drawbar_pull_N);
        j["vertical_force_N"] = value(r.vertical_force_N);
        j["wheel_z_m"] = value(r.wheel_z_m);
        j["drift"] = {{"slip", trend(r.slip_drift)}, {"wheel_z_m", trend(r.height_drift_m)}};
    }
    // Written aside and renamed: a reader (a study collecting it) sees the whole file or none.
    const std::string partial = path + ".partial";
    std::ofstream(partial) << j.dump(2) << '\n';
    std::error_code error;
    std::filesystem::rename(partial, path, error);
    if (error)
        throw ModelError("cannot write the wheel test's summary " + path + ": " +
                         error.message());
}

void WheelTest::writeCheckpoint(const std::string &path) const {
    std::ostringstream os;
    os.precision(17); // round trip: the resumed criteria see the very same numbers
    os << "phase " << phaseName() << "\ndrive_start_s " << drive_start_s_ << "\ndrop_heights";
    for (const auto &[t, z] : drop_heights_)
        os << ' ' << t << ' ' << z;
    os << "\ndrive_samples";
    for (const auto &w : drive_samples_)
        os << ' ' << w.time_s << ' ' << w.slip << ' ' << w.motor_torque_N_m << ' '
           << w.soil_force_x_N << ' ' << w.soil_force_z_N << ' ' << w.wheel_z_m;
    // The steady report is judged again from the samples when read.
    os << "\nsteady " << (steady_.reached ? 1 : 0) << ' ' << steady_.time_s << ' '
       << steady_.revolutions << '\n';
    std::ofstream out(path);
    out << os.str();
    if (!out)
        throw ModelError("cannot write the wheel test's checkpoint " + path);
}

void WheelTest::readCheckpoint(const std::string &path) {
    std::ifstream in(path);
    if (!in)
        throw ModelError("cannot open the wheel test's checkpoint " + path +
                         " (a checkpoint written before the wheel test's state was saved cannot "
                         "be resumed: start the run again)");
    const std::string kind = "wheel test";
    std::string line, tag, name;
    std::getline(in, line);
    std::istringstream words(line);
    words >> tag >> name;
    Phase phase = Phase::Drop;
    if (tag != "phase")
        throw ModelError(path + ":1: expected 'phase drop|drive|steady', got '" +
                         line.substr(0, 40) + "': not a wheel test checkpoint");
    if (name == "drive")
        phase = Phase::Drive;
    else if (name == "steady")
        phase = Phase::Steady;
    else if (name != "drop")
        throw ModelError(path + ":1: unknown phase '" + name.substr(0, 40) +
                         "' (drop, drive or steady)");
    const double drive_start_s =
        checkpointNumbers(in, path, 2, kind, "drive_start_s", 1, "when driving began [s]")[0];
    const auto heights =
        checkpointNumbers(in, path, 3, kind, "drop_heights", "the drop's (time [s], height [m])");
    const auto samples = checkpointNumbers(in, path, 4, kind, "drive_samples",
                                           "the drive's samples (time [s], slip, torque [N m], "
                                           "force x [N], force z [N], height [m])");
    const auto report = checkpointNumbers(in, path, 5, kind, "steady", 3,
                                          "the steady report (reached, time [s], revolutions)");
    if (heights.size() % 2 != 0)
        throw ModelError(path + ":3: " + std::to_string(heights.size()) +
                         " values of the drop's (time, height) pairs: an odd number");
    if (samples.size() % 6 != 0)
        throw ModelError(path + ":4: " + std::to_string(samples.size()) +
                         " values of the drive's samples: not 6 per sample");
    phase_ = phase;
    drive_start_s_ = drive_start_s;
    drop_heights_.clear();
    for (std::size_t k = 0; k < heights.size(); k += 2)
        drop_heights_.emplace_back(heights[k], heights[k + 1]);
    drive_samples_.clear();
    for (std::size_t k = 0; k < samples.size(); k += 6)
        drive_samples_.push_back({samples[k], samples[k + 1], samples[k + 2], samples[k + 3],
                                  samples[k + 4], samples[k + 5]});
    steady_ = {};
    if (report[1] > 0.0)
        judge(report[1]);
    steady_.reached = report[0] != 0.0;
    steady_.revolutions = report[2];
}

WheelTestSettings parseWheelTest(const config::ConfigNode &node) {
    WheelTestSettings s;
    s.drop_min_s = node.number("drop_min_s", s.drop_min_s);
    s.drop_settle_distance_m = node.number("drop_settle_distance_m", s.drop_settle_distance_m);
    s.drop_settle_time_s = node.number("drop_settle_time_s", s.drop_settle_time_s);
    s.drop_max_s = node.number("drop_max_s", s.drop_max_s);
    s.drive_min_s = node.number("drive_min_s", s.drive_min_s);
    s.drive_max_s = node.number("drive_max_s", s.drive_max_s);
    s.steady_window_s = node.number("steady_window_s", s.steady_window_s);
    s.steady_slip_tolerance = node.number("steady_slip_tolerance", s.steady_slip_tolerance);
    s.steady_height_tolerance_m =
        node.number("steady_height_tolerance_m", s.steady_height_tolerance_m);
    if (node.has("end_wall_limit"))
        s.end_wall_limit = node["end_wall_limit"].number(0.01, 1.0);
    if (node.has("run_until")) {
        const std::string until = node["run_until"].text();
        if (until != "steady" && until != "end_time")
            node["run_until"].fail("'" + until + "' is not steady or end_time");
        s.until_end_time = until == "end_time";
    }
    // A phase's maximum below its minimum would fail every run for the wrong reason (a run to
    // its end time has no maximum).
    const auto ordered = [&node, &s](const char *min_key, double min, const char *max_key,
                                     double max) {
        if (s.until_end_time || max > min)
            return;
        node[node.has(max_key) ? max_key : min_key].fail(
            std::string(max_key) + " = " + std::to_string(max) + " s is not above " + min_key +
            " = " + std::to_string(min) + " s");
    };
    ordered("drop_min_s", s.drop_min_s, "drop_max_s", s.drop_max_s);
    ordered("drive_min_s", s.drive_min_s, "drive_max_s", s.drive_max_s);
    node.finish();
    return s;
}

SingleWheelRigSettings parseSingleWheelRig(const config::ConfigNode &node) {
    SingleWheelRigSettings s;
    s.wheel_name = node.text("wheel_name", s.wheel_name);
    s.wheel = parseWheelShape(node["wheel"]);
    s.wheel_mass_kg = node["wheel_mass_kg"].positive();
    s.normal_load_kg = node["normal_load_kg"].positive();
    s.horizontal_mass_kg = node.number("horizontal_mass_kg", s.normal_load_kg);
    s.start_position_m = node["start_position_m"].vec3();
    if (node.has("clearance_above_bed_m")) {
        s.clearance_above_bed_m = node["clearance_above_bed_m"].number();
        if (!(*s.clearance_above_bed_m >= 0.0))
            node["clearance_above_bed_m"].fail("must be >= 0: a wheel started inside the bed "
                                               "would be pushed out by crushed grains");
    }
    s.angular_velocity_rad_s = node.number("angular_velocity_rad_s", s.angular_velocity_rad_s);
    s.drawbar_force_N = node.number("drawbar_force_N", 0.0);
    s.hold_carriage_in_drop = node.boolean("hold_carriage_in_drop", false);
    if (node.has("drive_torque_N_m")) {
        s.drive_torque_N_m = node["drive_torque_N_m"].number();
        // A torque drive sets no speed, and slip control imposes one.
        if (node.has("angular_velocity_rad_s"))
            node["angular_velocity_rad_s"].fail("a torque drive (drive_torque_N_m) sets no speed: "
                                                "remove one of the two keys");
        if (node.has("slip"))
            node["slip"].fail("slip control imposes the wheel speed; it cannot be combined with "
                              "a torque drive (drive_torque_N_m)");
    }
    if (node.has("slip"))
        s.slip = node["slip"].number();
    s.rotation_locked = true; // the procedure starts with the drop phase
    if (auto g = node.optional("gravity_m_s2"))
        s.gravity_m_s2 = g->vec3();
    node.finish();
    return s;
}

} // namespace grainlink::mbs
