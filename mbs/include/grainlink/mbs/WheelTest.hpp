#pragma once
// The seed's single-wheel procedure on the rig (DIGEST §5): drop the wheel with its rotation
// locked until the sinkage is steady, then drive at constant ω, free to translate, until the
// slip is steady — detected, not a fixed time — and report the steady values with their scatter.
#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/mbs/SingleWheelRig.hpp"

#include <deque>
#include <string>

namespace grainlink::mbs {

struct WheelTestSettings {
    double drop_min_s = 0.2;               ///< [s] shortest drop phase
    double drop_settle_distance_m = 0.001; ///< [m] sinkage is steady when the wheel moved less
    double drop_settle_time_s = 0.1;       ///< [s] than this vertically over this long
    double drive_min_s = 0.5;              ///< [s] shortest drive phase before steady is judged
    double steady_window_s = 0.5;          ///< [s] slip means over two such spans are compared
    double steady_slip_tolerance = 0.02;   ///< steady when the two means differ by less ...
    double steady_height_tolerance_m = 0.002; ///< [m] ... and the mean wheel heights too
};

/// One row of the rig's time series and the steady-state report.
struct WheelSample {
    double time_s = 0.0;
    double slip = 0.0;
    double motor_torque_N_m = 0.0;
    double soil_force_x_N = 0.0; ///< [N] the soil's traction on the wheel (drawbar pull)
    double soil_force_z_N = 0.0;
    double wheel_z_m = 0.0;
};

struct SteadyState {
    bool reached = false;
    double time_s = 0.0; ///< [s] when it was detected
    double slip_mean = 0.0, slip_std = 0.0;
    double torque_mean_N_m = 0.0, torque_std_N_m = 0.0;
    double drawbar_pull_mean_N = 0.0, drawbar_pull_std_N = 0.0;
    double revolutions = 0.0; ///< wheel turns since driving began
};

class WheelTest {
public:
    enum class Phase { Drop, Drive, Steady };
    explicit WheelTest(const WheelTestSettings &settings) : settings_(settings) {}

    /// After each window: records the sample, switches phases on the rig. Returns true once
    /// the steady state is reached (the experiment is complete).
    bool afterWindow(SingleWheelRig &rig, const Wrench &soil);
    Phase phase() const { return phase_; }
    const SteadyState &steady() const { return steady_; }
    std::string phaseName() const;
    std::string summary() const;

    /// The procedure's own state beyond the rig's (the phase, when driving began, the heights
    /// and samples its criteria look back on, the steady report) as text, for the run's
    /// checkpoints: a run resumed from one continues the procedure as if it never stopped.
    void writeCheckpoint(const std::string &path) const;
    /// Reads what writeCheckpoint wrote; a missing, truncated or damaged file is a ModelError
    /// naming the file and the line.
    void readCheckpoint(const std::string &path);

private:
    WheelTestSettings settings_;
    Phase phase_ = Phase::Drop;
    std::deque<std::pair<double, double>> drop_heights_; ///< (t, z) over the last settle time
    double drive_start_s_ = 0.0;
    std::deque<WheelSample> drive_samples_;
    SteadyState steady_;
};

WheelTestSettings parseWheelTest(const config::ConfigNode &node);
SingleWheelRigSettings parseSingleWheelRig(const config::ConfigNode &node);
/// The `wheel:` block shared by every model with parametric wheels (docs/scenario.md).
using body::parseWheelShape;

} // namespace grainlink::mbs
