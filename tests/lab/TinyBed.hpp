#pragma once
// The lab tests' tiny beds (BevameterTest.cpp, ShearAnnulusTest.cpp, ReposeTest.cpp): the same
// grains and contacts, and the same bin of 1.5 mm grains in two sizes.
#include <string>

/// The tiny beds' grains and contacts, as `soil:` lines: soft (E = 10 MPa) grains of 2400 kg/m^3,
/// linear tangential springs (stick 32 deg, slip 30 deg). Rolling resistance stands in for grain
/// shape: frictional spheres without it have too little bulk friction for a lab test.
inline const std::string kTinyGrainContacts =
    R"(  material: {youngs_modulus_Pa: 1.0e7, poisson_ratio: 0.2, density_kg_m3: 2400}
  contact:
    damping: {model: viscous, coefficient_N_s_m: 0.1}
    rolling: {model: epsd, coefficient: 0.3}
    tangential: {model: linear, stiffness_N_m: 200, stick_angle_deg: 32, slip_angle_deg: 30}
)";

/// The `soil:` section of a tiny bed: `count` grains of 1.5 mm radius deposited over the full
/// width of a square bin `side_m` wide, in a region `fill_height_m` high, and settled without the
/// packing cache. The numbers are YAML text, written into the scenario as given.
inline std::string tinyBinSoil(const std::string &side_m, const std::string &fill_height_m,
                               const std::string &count) {
    return "soil:\n  simulation: {time_step_s: 4.5e-5, threads: 1}\n" + kTinyGrainContacts +
           "  walls:\n    - {name: bin, type: box, lower_m: [0, 0, 0], upper_m: [" + side_m + ", " +
           side_m + ", 0.2]}\n  deposition:\n    region: {lower_m: [0, 0, 0], upper_m: [" + side_m +
           ", " + side_m + ", " + fill_height_m + "]}\n    count: " + count +
           "\n    radius: {distribution: constant, value_m: 0.0015}\n    seed: 3\n"
           "    settle_kinetic_energy_J: 1.0e-8\n    max_settle_time_s: 0.4\n"
           "  packing_cache_directory: \"\"\n";
}
