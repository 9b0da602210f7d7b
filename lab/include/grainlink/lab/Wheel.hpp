#pragma once
// Single-wheel test at a set slip (docs/lab.md, physics.md §12.17): the slip-controlled test bed
// of terramechanics labs. A wheel is pressed onto a settled bed until a force servo holds its
// vertical load, then spun at a set angular speed while its carriage moves at a set speed and
// the servo keeps the load; the wheel may be steered (yawed) by a slip angle against its
// carriage. Per slip: the steady traction, side force, vertical load, motor torque and sinkage,
// each with its scatter over the steady stretch of travel.
#include "grainlink/body/WheelShape.hpp"
#include "grainlink/dem/Scenario.hpp"
#include "grainlink/lab/LabConfig.hpp"
#include "grainlink/lab/LabExperiment.hpp"
#include "grainlink/lab/NumericalChecks.hpp"

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace grainlink::lab {

/// The rim speed [m/s] (omega r) for carriage speed `carriage_speed_m_s` at `slip`, with the
/// test-bed convention s = (v_rim - v) / max(v_rim, v): v_rim = v / (1 - s) when driving
/// (s >= 0), v_rim = v (1 + s) when braked (s < 0; -1 is a locked wheel). Like the CMU test
/// bed, the carriage keeps its speed and the wheel's spin sets the slip. Throws
/// std::invalid_argument outside [-1, 1).
double rimSpeed(double carriage_speed_m_s, double slip);

/// The wheel's frame when steered by the slip angle beta [deg] against its carriage, which moves
/// along +x (z up): `heading` the way it rolls, (cos b, sin b, 0); `axle` its spin axis,
/// (-sin b, cos b, 0), about which it spins forward; `side` across it along the carriage's sideways
/// component, (sin b, -cos b, 0), so that soil resisting the sideways slide gives a negative side
/// force (the CMU test bed's sign).
struct WheelFrame {
    Eigen::Vector3d heading, axle, side;
};
WheelFrame steeredFrame(double slip_angle_deg);
/// A wheel's footprint seen from above when steered by the slip angle [deg]: half its extent
/// along the travel (x: its outer radius along the heading, its half-width along the axle) and
/// across it (y).
Eigen::Vector2d steeredHalfExtent(double outer_radius_m, double width_m, double slip_angle_deg);

/// The `wheel:` section.
struct WheelSpec {
    body::WheelShape shape;           ///< the `shape:` block (the rig's `wheel:` keys)
    double load_N = 0.0;              ///< [N] vertical load the servo holds
    std::vector<double> slips;        ///< [-] one run each, in [-1, 1)
    double slip_angle_deg = 0.0;      ///< [deg] the wheel's yaw against the carriage, [0, 90]
    double carriage_speed_m_s = 0.0;  ///< [m/s] while driving, every slip; the spin follows
    double travel_m = 0.0;            ///< [m] carriage travel while driving, per slip
    double steady_fraction = 0.5;     ///< [-] the last share of the travel that is averaged
    double approach_speed_m_s = 0.05; ///< [m/s] downward until the load is first reached
    /// The load servo (LabConfig.hpp): hold_s before the drive starts, max_load_time_s for the
    /// approach to first reach the load.
    ServoSpec servo{0.0, 0.0, 0.0, 0.0, 0.05, 2.0};
    double start_clearance_m = 0.001; ///< [m] lowest point above the highest grain under it
    double end_margin_m = 0.0;        ///< [m] wheel to the region's x ends; 0: two grain diameters
    double sample_interval_s = 0.002; ///< [s] servo update and CSV row
    std::optional<double> friction_coefficient; ///< wheel-grain; unset: the grain-tool law's
    double min_resolution = 3.0;      ///< [-] required width / (2 r_max) (seed eq. 11)
    /// [-] the largest share of the wheel's push along its travel that the bin's end walls may
    /// take over the steady stretch (WheelRun::end_wall_share); beyond it the run is refused
    double end_wall_limit = 0.5;
};

struct WheelScenario {
    std::string name = "wheel";
    dem::DemScenario soil;
    WheelSpec test;
    std::vector<config::KeyWarning> warnings; ///< deprecated spellings read (none yet)
};

/// Reads `name`, `soil:` (docs/scenario.md's soil keys, no walls' bodies) and `wheel:`.
WheelScenario parseWheel(const config::ConfigNode &root);
WheelScenario loadWheel(const std::string &path);

/// One sample interval while driving.
struct WheelSample {
    double time_s = 0.0;          ///< [s] since the drive started, interval middle
    double travel_m = 0.0;        ///< [m] carriage travel, interval middle
    double traction_N = 0.0;      ///< [N] soil force on the wheel along its heading (> 0: pulls)
    double side_force_N = 0.0;    ///< [N] soil force along the wheel frame's `side`
    double vertical_load_N = 0.0; ///< [N] soil force on the wheel upward
    double torque_N_m = 0.0;      ///< [N m] soil torque resisting the spin (the motor's torque)
    double sinkage_m = 0.0;       ///< [m] rim bottom (grousers excluded) below the bed surface
    /// [N] how much harder than before the drive the soil pushes on the bin's end wall ahead
    /// (along +x) and on the one behind (along -x)
    double end_wall_ahead_N = 0.0, end_wall_behind_N = 0.0;
};

/// Mean and sample standard deviation of a quantity over the steady samples.
struct SteadyValue {
    double mean = 0.0, sd = 0.0;
};

struct WheelRun {
    double slip = 0.0;            ///< [-] the set slip
    double slip_angle_deg = 0.0;  ///< [deg] the wheel's yaw against the carriage
    double carriage_speed_m_s = 0.0;
    double angular_speed_rad_s = 0.0; ///< [rad/s] the spin that gives the slip
    double surface_m = 0.0;       ///< [m] settled bed surface
    double load_time_s = 0.0;     ///< [s] approach and hold before the drive
    double sinkage_at_load_m = 0.0; ///< [m] static sinkage under the load
    std::vector<WheelSample> samples;
    std::size_t steady_samples = 0; ///< the last this many samples are the steady stretch
    SteadyValue traction_N, side_force_N, vertical_load_N, torque_N_m, sinkage_m;
    SteadyValue end_wall_ahead_N, end_wall_behind_N; ///< [N] (WheelSample)
    /// [-] the steady rise on the end wall that the wheel pushes towards, as a share of that
    /// push (the soil's steady force on the wheel along x, reversed; at least 0.1 load_N)
    double end_wall_share = 0.0;
    double max_load_error = 0.0;  ///< [-] largest |F_z - load| / load over the steady stretch
    std::uint64_t steps = 0;
    double wall_s = 0.0;
};

struct WheelResult : LabResult {
    static constexpr const char *kTest = "wheel";
    static constexpr const char *kCsvFiles = "wheel_travel.csv,wheel_slip.csv";
    body::WheelShape shape;
    double load_N = 0.0;
    double slip_angle_deg = 0.0; ///< [deg] the wheel's yaw against the carriage
    double resolution = 0.0;    ///< width / (2 r_max)
    std::vector<WheelRun> runs; ///< one per slip, in the scenario's order
    std::string report() const;
    LabSummary summary() const;
    /// wheel_travel.csv (every sample of every slip) and wheel_slip.csv (one row per slip).
    void writeCsvs(const std::string &directory) const;
};

/// Settles (or reads) the bed once and drives the wheel at every slip on a copy of it
/// (runLabExperiment); writes its outputs into options.output_directory unless empty.
WheelResult runWheel(const WheelScenario &scenario, const LabRunOptions &options);

/// Wheel answers for the numerical checks: steady traction and sinkage per slip, and the side
/// force of a steered wheel.
Quantities wheelQuantities(const WheelResult &result);
/// Reruns the wheel test on a wider box or finer grains and compares.
std::vector<NumericalCheck> checkWheel(const WheelScenario &scenario, const WheelResult &baseline,
                                       const CheckRequest &request, const LabRunOptions &options);

} // namespace grainlink::lab
