#pragma once
// The seed's single-wheel procedure on the rig (DIGEST §5): drop the wheel with its rotation
// locked until the sinkage is steady, then drive at constant ω, free to translate, until the
// slip is steady — detected by a trend test, not a fixed time — and report the steady values
// with their fluctuation and standard error. A phase that outlasts its maximum ends the run as
// not steady, saying what was still changing.
#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/mbs/SingleWheelRig.hpp"

#include <deque>
#include <string>

namespace grainlink::mbs {

struct WheelTestSettings {
    double drop_min_s = 0.2;               ///< [s] shortest drop phase
    double drop_settle_distance_m = 0.001; ///< [m] sinkage is steady when the wheel moved less
    double drop_settle_time_s = 0.1;       ///< [s] than this vertically over this long
    double drop_max_s = 5.0;               ///< [s] a drop still settling after this fails
    double drive_min_s = 0.5;              ///< [s] shortest drive phase before steady is judged
    double drive_max_s = 20.0;             ///< [s] a drive not steady after this fails
    /// [s] the trend of slip and height is fitted over the last two such spans and expressed
    /// as a change per span
    double steady_window_s = 0.5;
    double steady_slip_tolerance = 0.02;   ///< steady when the slip's change per span is below
    double steady_height_tolerance_m = 0.002; ///< [m] this, the height's below this, and both
                                              ///< are consistent with zero (95 %)
    /// `run_until: end_time`: the procedure never ends the run and ending unsteady at
    /// coupling.end_time_s is no failure (a check of the rig, not a measurement); the default
    /// `steady` ends the run when steady and fails it when it ends unsteady.
    bool until_end_time = false;
    /// With the DEM soil, `grainlink run` refuses a steady state in which the bin's end wall the
    /// wheel pushes towards took more than this share of its push (dem::endWallShare).
    double end_wall_limit = 0.5;
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

/// A quantity over the judged span: its mean, fluctuation (sd of the samples) and the standard
/// error of the mean from batch means (dem/SteadySignal.hpp).
struct SteadyValue {
    double mean = 0.0, sd = 0.0, standard_error = 0.0;
};

/// A quantity's linear trend over the judged span, as its change per steady_window_s.
struct Drift {
    double per_span = 0.0, standard_error = 0.0;
    bool consistent_with_zero = true; ///< the 95 % interval contains zero
};

/// The drive's last two spans judged: the report when steady, what was still changing when not.
struct SteadyState {
    bool reached = false;
    double time_s = 0.0;       ///< [s] when it was judged
    double span_start_s = 0.0; ///< [s] the samples judged are from here to time_s
    double revolutions = 0.0;  ///< wheel turns since driving began
    SteadyValue slip, motor_torque_N_m, drawbar_pull_N, vertical_force_N, wheel_z_m;
    Drift slip_drift, height_drift_m;
};

class WheelTest {
public:
    enum class Phase { Drop, Drive, Steady };
    explicit WheelTest(const WheelTestSettings &settings) : settings_(settings) {}

    /// After each window: records the sample, switches phases on the rig. Returns true once
    /// the experiment is complete: the steady state reached, or a phase past its maximum.
    bool afterWindow(SingleWheelRig &rig, const Wrench &soil);
    Phase phase() const { return phase_; }
    const SteadyState &steady() const { return steady_; }
    std::string phaseName() const;
    /// The closing report: the steady values, or why there are none (a phase past its maximum,
    /// or the run ended at `run_end_s` before the procedure did) and what was still changing.
    std::string summary(double run_end_s) const;
    /// The same as JSON (rig_summary.json: docs/scenario.md), for studies and scripts, with
    /// the rig's normal load (its weight) for comparison with the vertical force.
    void writeSummaryJson(const std::string &path, double run_end_s, double normal_load_N) const;
    bool failed() const { return !failure_.empty(); }
    /// Whether the run that ended at `run_end_s` did what the procedure asks (the node's exit
    /// status follows it).
    bool succeeded() const { return steady_.reached || settings_.until_end_time; }

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
    std::string failure_; ///< why the procedure stopped without a steady state

    /// Judges the drive's samples (the last two spans): statistics and trends into steady_.
    void judge(double t);
    std::string stillChanging() const;
};

WheelTestSettings parseWheelTest(const config::ConfigNode &node);
SingleWheelRigSettings parseSingleWheelRig(const config::ConfigNode &node);
/// The `wheel:` block shared by every model with parametric wheels (docs/scenario.md).
using body::parseWheelShape;

} // namespace grainlink::mbs
