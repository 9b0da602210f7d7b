#pragma once
// The direct shear tests' tiny box (DirectShearTest.cpp, SoilTableTest.cpp).

/// ~420 grains of 2-2.25 mm in a 30 x 30 mm box (L / d = 7), the shear plane 12 mm up,
/// sheared 3 mm at 20 mm/s under 4 and 12 kPa (smooth frames and plate).
inline const char *kTinyShearBox = R"(name: tiny-shear
soil:
  simulation: {time_step_s: 5.0e-5, threads: 1}
  material: {youngs_modulus_Pa: 2.7e7, poisson_ratio: 0.2, density_kg_m3: 2400}
  contact:
    damping: {model: viscous, coefficient_N_s_m: 0.2}
    tangential: {model: linear, stiffness_N_m: 300, damping_N_s_m: 0.03, stick_angle_deg: 30, slip_angle_deg: 30}
    rolling: {model: grain_shape, aspect_ratio_angle_deg: 20}
  deposition:
    region: {lower_m: [0, 0, 0], upper_m: [0.03, 0.03, 0.1]}
    count: 420
    radius: {distribution: uniform, min_m: 0.002, max_m: 0.00225}
    seed: 3
    settle_kinetic_energy_J: 1.0e-8
    max_settle_time_s: 0.4
  packing_cache_directory: ""
direct_shear:
  length_m: 0.03
  width_m: 0.03
  lower_height_m: 0.012
  upper_height_m: 0.03
  normal_stresses_Pa: [4000, 12000]
  shear_speed_m_s: 0.02
  max_displacement_m: 0.003
  sample_interval_s: 0.002
  fit_cohesion: false
  wall_friction_coefficient: 0
  servo: {gain_m_s_per_N: 1.0e-2, max_speed_m_s: 0.05, control_interval_s: 0.00025}
)";
