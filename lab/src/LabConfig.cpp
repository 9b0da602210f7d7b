#include "grainlink/lab/LabConfig.hpp"

namespace grainlink::lab {

dem::DemScenario parseLabSoil(const config::ConfigNode &root, const LabSoilRules &rules) {
    const config::ConfigNode soil = root["soil"];
    auto refuse = [&](const std::string &key, const std::string &why) {
        if (soil.has(key))
            soil[key].fail(why + "; remove soil." + key);
    };
    refuse("bodies", rules.adds_bodies);
    if (rules.builds_walls)
        refuse("walls", *rules.builds_walls);
    if (rules.never_cached)
        refuse("packing_cache_directory", *rules.never_cached);
    if (const auto deposition = soil.optional("deposition");
        rules.no_compaction && deposition && deposition->has("compaction"))
        (*deposition)["compaction"].fail(*rules.no_compaction +
                                         "; remove soil.deposition.compaction");
    // Keys of a DEM run that a lab test would read and then ignore.
    refuse("name", "a lab scenario is named by its top-level 'name'");
    refuse("output", "a lab test writes its own outputs (docs/lab.md)");
    return dem::parseScenario(soil, true);
}

std::optional<Eigen::Vector2d> parseCentre(const config::ConfigNode &section) {
    const auto c = section.optional("centre_m");
    if (!c)
        return std::nullopt;
    const auto xy = c->numbers();
    if (xy.size() != 2)
        c->fail("expected [x, y]");
    return Eigen::Vector2d(xy[0], xy[1]);
}

LoadServo ServoSpec::loadServo(double target_force_N) const {
    LoadServo servo;
    servo.target_force_N = target_force_N;
    servo.gain_m_s_per_N = gain_m_s_per_N;
    servo.max_speed_m_s = max_speed_m_s;
    servo.deadband_N = deadband_N;
    servo.integral_gain_m_s2_per_N = integral_gain_m_s2_per_N;
    servo.validate();
    return servo;
}

config::KeyWarning deprecationWarning(const config::ConfigNode &node, const std::string &spelling) {
    return node.warning("deprecated; write '" + spelling + "' instead (docs/lab.md)");
}

ServoSpec parseServo(const config::ConfigNode &node, const ServoSpec &defaults,
                     std::vector<config::KeyWarning> &warnings,
                     const std::optional<ServoKeys> &old) {
    const ServoKeys block;
    const ServoKeys &names = old ? *old : block;
    // The key `key` (in `names`), whose `servo:` spelling is `block_key`.
    auto read = [&](const std::string &key, const std::string &block_key, bool required) {
        std::optional<config::ConfigNode> value = required ? node[key] : node.optional(key);
        if (value && old)
            warnings.push_back(deprecationWarning(*value, node.path() + ".servo." + block_key));
        return value;
    };
    ServoSpec s = defaults;
    s.gain_m_s_per_N = read(names.gain, block.gain, true)->positive();
    if (const auto v = read(names.max_speed, block.max_speed, !(defaults.max_speed_m_s > 0.0)))
        s.max_speed_m_s = v->positive();
    if (const auto v = read(names.deadband, block.deadband, false))
        s.deadband_N = v->nonNegative();
    if (const auto v = read(names.integral_gain, block.integral_gain, false))
        s.integral_gain_m_s2_per_N = v->nonNegative();
    if (const auto v = read(names.hold, block.hold, false))
        s.hold_s = v->nonNegative();
    if (const auto v = read(names.max_load_time, block.max_load_time, false))
        s.max_load_time_s = v->positive();
    return s;
}

} // namespace grainlink::lab
