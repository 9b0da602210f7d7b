#include "grainlink/mbs/WheelTest.hpp"

#include <cmath>
#include <cstdio>

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
