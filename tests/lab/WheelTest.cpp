// Single-wheel test at set slips (docs/lab.md, physics.md §12.17): the slip convention by hand,
// a driven and a braked wheel on a tiny bed against the laws every such test obeys, and the
// input checks.
#include "grainlink/lab/Wheel.hpp"
#include "grainlink/lab/LabSummary.hpp"
#include "grainlink/lab/LabTest.hpp"

#include "TextEdit.hpp"
#include "TinyBed.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <string>

#include <unistd.h>

using namespace grainlink;
using Catch::Matchers::Contains;

namespace {

/// A tiny bin 200 x 50 mm, ~30 mm of 2.5 mm grains (the tiny beds' contacts); a smooth wheel
/// 60 mm across and 30 mm wide (Gamma = 6) under 2 N, its carriage at 0.12 m/s over 60 mm.
const std::string kTinyWheel =
    "name: tiny-wheel\nsoil:\n  simulation: {time_step_s: 5.0e-5, threads: 1}\n" +
    kTinyGrainContacts + R"(  walls:
    - {name: bin, type: box, lower_m: [0, 0, 0], upper_m: [0.2, 0.05, 0.2]}
  deposition:
    region: {lower_m: [0, 0, 0], upper_m: [0.2, 0.05, 0.07]}
    count: 2700
    radius: {distribution: constant, value_m: 0.0025}
    seed: 3
    settle_kinetic_energy_J: 1.0e-8
    max_settle_time_s: 0.4
  packing_cache_directory: ""
wheel:
  shape: {diameter_m: 0.06, width_m: 0.03}
  load_N: 2
  slips: [-0.4, 0.0, 0.5]
  carriage_speed_m_s: 0.12
  travel_m: 0.06
  servo: {gain_m_s_per_N: 0.01, integral_gain_m_s2_per_N: 0.5, max_speed_m_s: 0.05}
  sample_interval_s: 0.001
)";

lab::WheelScenario parseWheelText(const std::string &text) {
    return lab::parseWheel(config::ConfigNode::loadString(text, "wheel.yaml"));
}

/// The tiny bed 90 mm wide (the wheel across the travel reaches 30 mm to each side) in a bin
/// `length` long (grains in proportion), the wheel steered by 90 deg (the carriage drags it
/// along its axle) at `slips` over 60 mm.
std::string steeredAcross(const std::string &slips, const std::string &length, int grains) {
    std::string text = replacedOnce(kTinyWheel, "upper_m: [0.2, 0.05, 0.2]",
                                    "upper_m: [" + length + ", 0.09, 0.2]");
    text =
        replacedOnce(text, "upper_m: [0.2, 0.05, 0.07]", "upper_m: [" + length + ", 0.09, 0.07]");
    text = replacedOnce(text, "count: 2700", "count: " + std::to_string(grains));
    return replacedOnce(text, "slips: [-0.4, 0.0, 0.5]", slips + "\n  slip_angle_deg: 90");
}

} // namespace

TEST_CASE("wheel: the rim speed of a slip, driven, braked and locked, by hand", "[lab][wheel]") {
    // s = (v_rim - v) / max(v_rim, v) with the carriage at v = 0.1 m/s.
    CHECK(lab::rimSpeed(0.1, 0.0) == Approx(0.1));
    CHECK(lab::rimSpeed(0.1, 0.5) == Approx(0.2));   // (0.2 - 0.1) / 0.2
    CHECK(lab::rimSpeed(0.1, 0.9) == Approx(1.0));   // (1 - 0.1) / 1
    CHECK(lab::rimSpeed(0.1, -0.25) == Approx(0.075)); // (0.075 - 0.1) / 0.1
    CHECK(lab::rimSpeed(0.1, -1.0) == 0.0);          // locked
    CHECK_THROWS_WITH(lab::rimSpeed(0.1, 1.0), Contains("[-1, 1)"));
}

TEST_CASE("wheel: a braked wheel is pushed back, a driven one pulls, the servo holds the load and "
          "the motor's power covers the drawbar's",
          "[lab][wheel][slow]") {
    const lab::WheelScenario s = parseWheelText(kTinyWheel);
    const lab::WheelResult r = lab::runWheel(s, {});
    REQUIRE(r.runs.size() == 3);
    const lab::WheelRun &braked = r.runs[0], &rolling = r.runs[1], &driven = r.runs[2];
    for (const lab::WheelRun &run : r.runs) {
        INFO("slip " << run.slip << ": traction " << run.traction_N.mean << " +- "
                     << run.traction_N.sd << " N, load " << run.vertical_load_N.mean << " +- "
                     << run.vertical_load_N.sd << " N, torque " << run.torque_N_m.mean
                     << " N m, sinkage " << run.sinkage_m.mean * 1e3 << " mm");
        // The servo: the steady vertical load within 10 % of the set load on average.
        CHECK(run.vertical_load_N.mean == Approx(2.0).epsilon(0.10));
        // Steady state: the power the motor puts in, T omega, covers the drawbar's, F_x v
        // (what the soil dissipates is never negative), within the steady scatter.
        const double omega = run.angular_speed_rad_s;
        const double motor = run.torque_N_m.mean * omega,
                     drawbar = run.traction_N.mean * run.carriage_speed_m_s;
        const double scatter = omega * run.torque_N_m.sd / std::sqrt(double(run.steady_samples)) +
                               run.carriage_speed_m_s * 2.0 * run.traction_N.sd /
                                   std::sqrt(double(run.steady_samples));
        CHECK(motor - drawbar > -scatter);
        CHECK(run.sinkage_m.mean > 0.0);
    }
    // Traction grows with slip: the soil resists a braked wheel and pushes a driven one on.
    CHECK(braked.traction_N.mean < 0.0);
    CHECK(braked.traction_N.mean < rolling.traction_N.mean);
    CHECK(rolling.traction_N.mean < driven.traction_N.mean);
    CHECK(driven.traction_N.mean > 0.0);
    // So does the motor torque.
    CHECK(braked.torque_N_m.mean < driven.torque_N_m.mean);
    // The summary holds each slip's steady values, as the diagnosis reads them.
    const lab::LabSummary sum = r.summary();
    CHECK(sum.test == "wheel");
    CHECK(sum.runs[2].value("slip") == 0.5);
    CHECK(sum.runs[2].value("traction_N") == driven.traction_N.mean);
    CHECK(sum.runs[2].curve("travel_m").size() == driven.samples.size());
}

TEST_CASE("wheel: a steered wheel's frame by hand: it rolls along its heading, the side is the "
          "carriage's sideways part",
          "[lab][wheel]") {
    const lab::WheelFrame straight = lab::steeredFrame(0.0), across = lab::steeredFrame(90.0);
    CHECK(straight.heading.isApprox(Eigen::Vector3d(1, 0, 0)));
    CHECK(straight.axle.isApprox(Eigen::Vector3d(0, 1, 0)));
    CHECK(across.heading.isApprox(Eigen::Vector3d(0, 1, 0)));
    CHECK(across.side.isApprox(Eigen::Vector3d(1, 0, 0))); // the carriage pushes it along its axle
    for (double beta : {0.0, 15.0, 30.0, 60.0, 90.0}) {
        INFO("slip angle " << beta << " deg");
        const lab::WheelFrame f = lab::steeredFrame(beta);
        // Spinning forward about its axle, the rim's lowest point moves backward along the
        // heading: omega x (-r z) = -omega r heading (rigid-body kinematics).
        CHECK(f.axle.cross(-Eigen::Vector3d::UnitZ()).isApprox(-f.heading));
        // The carriage's velocity splits into the heading and the side: cos b and sin b.
        const Eigen::Vector3d x = Eigen::Vector3d::UnitX();
        CHECK(x.dot(f.heading) == Approx(std::cos(beta * M_PI / 180)));
        CHECK(x.dot(f.side) == Approx(std::sin(beta * M_PI / 180)).margin(1e-12));
        CHECK(f.side.dot(f.heading) == Approx(0.0).margin(1e-12));
        CHECK(f.side.isApprox(-f.axle));
    }
}

TEST_CASE("wheel: steered across its travel, a locked wheel meets the soil along its axle only "
          "(mirror symmetry), a spinning one is pushed along its heading, and the soil "
          "dissipates",
          "[lab][wheel][slow]") {
    // The tiny bed in a 160 x 90 mm bin, the wheel steered by 90 deg: the carriage drags it
    // along its axle over 60 mm, which leaves 60 mm of soil ahead of it (40 mm less, and the
    // end wall takes the drag: next test).
    const lab::WheelResult r =
        lab::runWheel(parseWheelText(steeredAcross("slips: [-1.0, 0.5]", "0.16", 3870)), {});
    REQUIRE(r.runs.size() == 2);
    const lab::WheelRun &locked = r.runs[0], &spinning = r.runs[1];
    for (const lab::WheelRun &run : r.runs) {
        INFO("slip " << run.slip << ": traction " << run.traction_N.mean << " +- "
                     << run.traction_N.sd << " N, side " << run.side_force_N.mean << " +- "
                     << run.side_force_N.sd << " N, load " << run.vertical_load_N.mean
                     << " N, torque " << run.torque_N_m.mean << " N m");
        CHECK(run.slip_angle_deg == 90.0);
        // The servo lags a wheel that digs in while dragged sideways (2.2 N measured at s = 0.5,
        // its sinkage still growing): 15 %, not the straight wheel's 10 %.
        CHECK(run.vertical_load_N.mean == Approx(2.0).epsilon(0.15));
        // The soil resists the sideways drag: a negative side force (the CMU sign), of the
        // order of the load times a friction.
        CHECK(run.side_force_N.mean < -0.2 * run.vertical_load_N.mean);
        // Dissipation: the motor's power T omega and the carriage's, -F_side v (the carriage
        // moves along the side direction), are both spent in the soil.
        const double n = std::sqrt(double(run.steady_samples));
        CHECK(run.torque_N_m.mean * run.angular_speed_rad_s -
                  run.side_force_N.mean * run.carriage_speed_m_s >
              -2.0 *
                  (run.angular_speed_rad_s * run.torque_N_m.sd +
                   run.carriage_speed_m_s * run.side_force_N.sd) /
                  n);
    }
    // Locked, the wheel and its drag are mirror-symmetric about the travel's vertical plane:
    // the soil's force along the heading averages to zero; 20 % of the drag bounds what one bed
    // and a 30 mm stretch leave of it.
    CHECK(std::abs(locked.traction_N.mean) < 0.2 * std::abs(locked.side_force_N.mean));
    // Spinning, the rim throws soil back and the wheel is pushed along its heading.
    CHECK(spinning.traction_N.mean > locked.traction_N.mean + locked.traction_N.sd);
    CHECK(spinning.traction_N.mean > 0.0);
    for (const lab::WheelRun &run : r.runs)
        CHECK(run.end_wall_share < 0.5);
}

TEST_CASE("wheel: a drag whose pushed soil reaches the bin's end is refused, its results written",
          "[lab][wheel][slow]") {
    // The test before in a bin 120 mm long: the locked wheel's front ends 25 mm from the end
    // wall, and the soil it pushes ahead reaches it. The bed is in equilibrium: what the wheel
    // pushes along x the floor, the side walls and the end walls carry, and here the end wall
    // ahead carries most of it.
    const auto dir = std::filesystem::temp_directory_path() /
                     ("grainlink_wall_bound_wheel-" + std::to_string(::getpid()));
    const std::string out = (dir / "out").string();
    CHECK_THROWS_WITH(
        lab::runWheel(parseWheelText(steeredAcross("slips: [-1.0]", "0.12", 2900)), {out, 1e9}),
        Contains("at slip -1 the bin's end walls took") && Contains("wheel.end_wall_limit = 0.5") &&
            Contains("results are written to " + out));
    const lab::LabSummary s = lab::readLabSummary(out + "/summary.json");
    REQUIRE(s.runs.size() == 1);
    CHECK(s.runs[0].value("end_wall_share") > 0.5);
    CHECK(s.runs[0].value("end_wall_ahead_N") > 0.5 * -s.runs[0].value("side_force_N"));
    std::filesystem::remove_all(dir);
}

TEST_CASE("wheel: bad input names the file, the key and the line", "[lab][wheel]") {
    CHECK_THROWS_WITH(
        parseWheelText(replacedOnce(kTinyWheel, "slips: [-0.4, 0.0, 0.5]", "slips: [0.2, 1.0]")),
        Contains("wheel.yaml:") && Contains("wheel.slips[1]") && Contains("[-1, 1)"));
    CHECK_THROWS_WITH(parseWheelText(replacedOnce(kTinyWheel, "travel_m: 0.06", "travel_m: 0.5")),
                      Contains("wheel.travel_m") && Contains("can travel at most"));
    CHECK_THROWS_WITH(parseWheelText(replacedOnce(kTinyWheel, "width_m: 0.03", "width_m: 0.01")),
                      Contains("wheel.shape.width_m") && Contains("min_resolution"));
    CHECK_THROWS_WITH(
        parseWheelText(replacedOnce(kTinyWheel, "{diameter_m: 0.06, width_m: 0.03}",
                                    "{diameter_m: 0.06, width_m: 0.03, grouser_height_m: 0.005}")),
        Contains("grouser_count 0"));
    // Steered by 90 deg, the 60 mm wheel reaches 30 mm to each side of a 50 mm wide bin.
    CHECK_THROWS_WITH(
        parseWheelText(replacedOnce(kTinyWheel, "load_N: 2", "load_N: 2\n  slip_angle_deg: 90")),
        Contains("wheel.slip_angle_deg") && Contains("wide region"));
    CHECK_THROWS_WITH(
        parseWheelText(replacedOnce(kTinyWheel, "load_N: 2", "load_N: 2\n  slip_angle_deg: 95")),
        Contains("wheel.slip_angle_deg"));
    CHECK_THROWS_WITH(parseWheelText(replacedOnce(kTinyWheel, "load_N: 2", "load_N: 0")),
                      Contains("wheel.load_N") && Contains("must be > 0"));
    CHECK_THROWS_WITH(lab::loadLabScenario("wheels", "x.yaml"), Contains("wheel"));
}
