#pragma once
// The repose tests' tiny fill (ReposeTest.cpp, LabSummaryTest.cpp).
#include "TinyBed.hpp"

#include <string>

/// 600 grains of 1.8-2 mm in a tube of 21 mm radius on a rough floor, lifted at 0.1 m/s; the
/// profile in bins of r_max (the default 2 r_max leaves 3-7 bins on so small a heap's flank).
/// The insertion region fills the tube's height: 0.09 m held all 600 grains for seed 3 only of
/// seeds 1-10.
inline const std::string kTinyRepose = R"(name: tiny-repose
soil:
  simulation: {time_step_s: 6.0e-5, threads: 1}
)" + kTinyGrainContacts + R"(  walls:
    - {name: floor, type: plane, point_m: [0, 0, 0], normal: [0, 0, 1], friction_coefficient: 0.6}
  deposition:
    region: {lower_m: [-0.014, -0.014, 0], upper_m: [0.014, 0.014, 0.1]}
    count: 600
    radius: {distribution: uniform, min_m: 0.0018, max_m: 0.002}
    seed: 3
    settle_kinetic_energy_J: 1.0e-8
    max_settle_time_s: 0.4
repose:
  tube_radius_m: 0.021
  tube_height_m: 0.1
  lift_speed_m_s: 0.1
  max_settle_time_s: 0.6
  bin_width_m: 0.002
)";
