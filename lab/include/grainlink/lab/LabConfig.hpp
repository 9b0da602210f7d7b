#pragma once
// What the lab tests' scenario readers share (docs/lab.md): the `soil:` section without what a
// test builds itself, the tool's axis `centre_m`, and the load servo's keys in one spelling for
// every test, with the old spellings still read and a deprecation warning for each.
#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/dem/Scenario.hpp"
#include "grainlink/lab/LoadServo.hpp"

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace grainlink::lab {

/// What a lab test builds itself, so that its `soil:` section must not give it.
struct LabSoilRules {
    std::string adds_bodies;                 ///< e.g. "the bevameter adds its own plate"
    std::optional<std::string> builds_walls; ///< set: `soil.walls` is refused, this says why
    std::optional<std::string> never_cached; ///< set: `soil.packing_cache_directory` refused
    std::optional<std::string> no_compaction; ///< set: `soil.deposition.compaction` refused
};

/// Reads `root["soil"]`: the DEM soil keys of docs/scenario.md, refusing what the lab does not
/// use (`name`: the scenario's name is the top-level `name`; `output`: the test writes its own)
/// and what `rules` say the test builds itself. Errors name the file, key and line.
dem::DemScenario parseLabSoil(const config::ConfigNode &root, const LabSoilRules &rules);

/// The optional `centre_m: [x, y]` [m] of a test section; fails naming the key unless two numbers.
std::optional<Eigen::Vector2d> parseCentre(const config::ConfigNode &section);

/// The `servo:` block of a test whose tool a force servo holds at a load (LoadServo,
/// physics.md §12.11): the direct shear box's top plate, the bevameter shear annulus.
struct ServoSpec {
    double gain_m_s_per_N = 0.0;           ///< [m/(s N)] approach speed per newton of error
    double max_speed_m_s = 0.0;            ///< [m/s] clamp on the servo's speed
    double deadband_N = 0.0;               ///< [N]
    double integral_gain_m_s2_per_N = 0.0; ///< [m/(s^2 N)] 0: proportional only
    double hold_s = 0.02;                  ///< [s] servo alone at the load before the drive
    double max_load_time_s = 0.0;          ///< [s] the load must be reached within this
    /// The controller holding `target_force_N`, validated (throws naming the member).
    LoadServo loadServo(double target_force_N) const;
};

/// The key names a servo is read under; the defaults are the `servo:` block's.
struct ServoKeys {
    std::string gain = "gain_m_s_per_N";
    std::string max_speed = "max_speed_m_s";
    std::string deadband = "deadband_N";
    std::string integral_gain = "integral_gain_m_s2_per_N";
    std::string hold = "hold_s";
    std::string max_load_time = "max_load_time_s";
};

/// Reads a servo from `node`: the `servo:` block of a test section, leaving the block open for a
/// test's own servo keys (read those, then finish() it). The gain is required, and so is the
/// maximum speed unless `defaults` gives one (> 0); the rest default to `defaults`. With `old`,
/// `node` is a test section holding the servo under those older names: each key read adds a
/// deprecation warning to `warnings` naming its `servo:` spelling.
ServoSpec parseServo(const config::ConfigNode &node, const ServoSpec &defaults,
                     std::vector<config::KeyWarning> &warnings,
                     const std::optional<ServoKeys> &old = std::nullopt);

/// `file:line: warning: 'path': deprecated; write 'spelling' instead` for a key read under an
/// old spelling.
config::KeyWarning deprecationWarning(const config::ConfigNode &node, const std::string &spelling);

} // namespace grainlink::lab
