#include "grainlink/mbs/WheelTest.hpp"

#include "CheckpointText.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace grainlink::mbs {

namespace {

struct MeanStd {
    double mean = 0.0, std = 0.0;
};

template <typename Get>
MeanStd meanStd(const std::deque<WheelSample> &samples, std::size_t first, std::size_t end,
                Get get) {
    MeanStd m;
    const double n = double(end - first);
    if (n <= 0)
        return m;
    for (std::size_t i = first; i < end; ++i)
        m.mean += get(samples[i]) / n;
    for (std::size_t i = first; i < end; ++i)
        m.std += (get(samples[i]) - m.mean) * (get(samples[i]) - m.mean) / n;
    m.std = std::sqrt(m.std);
    return m;
}

} // namespace

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
        }
        return false;
    }
    if (phase_ == Phase::Steady)
        return true;
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
    if (t - drive_start_s_ < std::max(settings_.drive_min_s, 2.0 * span))
        return false;
    // Two consecutive spans of steady_window_s: steady when their mean slips agree.
    std::size_t middle = 0;
    while (middle < drive_samples_.size() && drive_samples_[middle].time_s <= t - span)
        ++middle;
    const auto slip = [](const WheelSample &w) { return w.slip; };
    const MeanStd older = meanStd(drive_samples_, 0, middle, slip);
    const MeanStd newer = meanStd(drive_samples_, middle, drive_samples_.size(), slip);
    const auto height = [](const WheelSample &w) { return w.wheel_z_m; };
    const double sinking = meanStd(drive_samples_, middle, drive_samples_.size(), height).mean -
                           meanStd(drive_samples_, 0, middle, height).mean;
    if (std::abs(newer.mean - older.mean) >= settings_.steady_slip_tolerance ||
        std::abs(sinking) >= settings_.steady_height_tolerance_m)
        return false;
    phase_ = Phase::Steady;
    steady_.reached = true;
    steady_.time_s = t;
    steady_.slip_mean = newer.mean;
    steady_.slip_std = newer.std;
    const auto torque = meanStd(drive_samples_, middle, drive_samples_.size(),
                                [](const WheelSample &w) { return w.motor_torque_N_m; });
    const auto pull = meanStd(drive_samples_, middle, drive_samples_.size(),
                              [](const WheelSample &w) { return w.soil_force_x_N; });
    steady_.torque_mean_N_m = torque.mean;
    steady_.torque_std_N_m = torque.std;
    steady_.drawbar_pull_mean_N = pull.mean;
    steady_.drawbar_pull_std_N = pull.std;
    steady_.revolutions =
        (t - drive_start_s_) * rig.settings().angular_velocity_rad_s / (2.0 * M_PI);
    return true;
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

std::string WheelTest::summary() const {
    char text[512];
    if (!steady_.reached)
        return "wheel test: no steady state reached (phase " + phaseName() + ")";
    std::snprintf(text, sizeof text,
                  "wheel test: steady after %.3f s of driving (%.2f revolutions): slip %.3f +- "
                  "%.3f, drawbar pull %.2f +- %.2f N, motor torque %.3f +- %.3f N m",
                  steady_.time_s - drive_start_s_, steady_.revolutions, steady_.slip_mean,
                  steady_.slip_std, steady_.drawbar_pull_mean_N, steady_.drawbar_pull_std_N,
                  steady_.torque_mean_N_m, steady_.torque_std_N_m);
    return text;
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
    const auto &r = steady_;
    os << "\nsteady " << (r.reached ? 1 : 0) << ' ' << r.time_s << ' ' << r.slip_mean << ' '
       << r.slip_std << ' ' << r.torque_mean_N_m << ' ' << r.torque_std_N_m << ' '
       << r.drawbar_pull_mean_N << ' ' << r.drawbar_pull_std_N << ' ' << r.revolutions << '\n';
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
    const auto report = checkpointNumbers(in, path, 5, kind, "steady", 9, "the steady report");
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
    steady_ = {report[0] != 0.0, report[1], report[2], report[3], report[4],
               report[5],        report[6], report[7], report[8]};
}

WheelTestSettings parseWheelTest(const config::ConfigNode &node) {
    WheelTestSettings s;
    s.drop_min_s = node.number("drop_min_s", s.drop_min_s);
    s.drop_settle_distance_m = node.number("drop_settle_distance_m", s.drop_settle_distance_m);
    s.drop_settle_time_s = node.number("drop_settle_time_s", s.drop_settle_time_s);
    s.drive_min_s = node.number("drive_min_s", s.drive_min_s);
    s.steady_window_s = node.number("steady_window_s", s.steady_window_s);
    s.steady_slip_tolerance = node.number("steady_slip_tolerance", s.steady_slip_tolerance);
    s.steady_height_tolerance_m =
        node.number("steady_height_tolerance_m", s.steady_height_tolerance_m);
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
    s.angular_velocity_rad_s = node.number("angular_velocity_rad_s", s.angular_velocity_rad_s);
    s.drawbar_force_N = node.number("drawbar_force_N", 0.0);
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
