// The lab readers' shared parts (lab/LabConfig.hpp): one spelling of the servo keys with the old
// ones still read and named, the soil keys a lab test would ignore, and every shipped lab
// scenario read strictly.
#include "grainlink/lab/LabTest.hpp"

#include "TextEdit.hpp"
#include "TinyBed.hpp"
#include "TinyRepose.hpp"
#include "TinyShearBox.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <string>

using namespace grainlink;
using Catch::Matchers::Contains;

namespace {

/// The tiny annulus of ShearAnnulusTest.cpp with its servo as `servo` (YAML lines).
std::string annulus(const std::string &servo) {
    return "name: tiny-shear\n" + tinyBinSoil("0.06", "0.04", "2300") + R"(bevameter_shear:
  inner_radius_m: 0.012
  outer_radius_m: 0.022
  grouser_height_m: 0.003
  normal_pressures_Pa: [1000, 2000]
  angular_speed_rad_s: 4
  max_shear_displacement_m: 0.012
)" + servo;
}

lab::ShearAnnulusScenario parseAnnulus(const std::string &text) {
    return lab::parseShearAnnulus(config::ConfigNode::loadString(text, "shear.yaml"));
}

lab::DirectShearScenario parseBox(const std::string &text) {
    return lab::parseDirectShear(config::ConfigNode::loadString(text, "box.yaml"));
}

} // namespace

TEST_CASE("Servo keys: the servo: block, and the annulus's old flat keys read the same",
          "[lab][config]") {
    const auto block = parseAnnulus(annulus(R"(  servo:
    gain_m_s_per_N: 0.1
    max_speed_m_s: 0.05
    integral_gain_m_s2_per_N: 5
    deadband_N: 0.01
    hold_s: 0.03
    max_load_time_s: 0.5
)"));
    CHECK(block.warnings.empty());
    const auto old = parseAnnulus(annulus(R"(  servo_gain_m_s_per_N: 0.1
  servo_max_speed_m_s: 0.05
  servo_integral_gain_m_s2_per_N: 5
  servo_deadband_N: 0.01
  load_hold_s: 0.03
  max_load_time_s: 0.5
)"));
    for (const lab::ServoSpec *s : {&block.test.servo, &old.test.servo}) {
        CHECK(s->gain_m_s_per_N == 0.1); // exact: the numbers as written
        CHECK(s->max_speed_m_s == 0.05);
        CHECK(s->integral_gain_m_s2_per_N == 5.0);
        CHECK(s->deadband_N == 0.01);
        CHECK(s->hold_s == 0.03);
        CHECK(s->max_load_time_s == 0.5);
    }
    // Each old key read is one warning naming its file, line and new spelling.
    REQUIRE(old.warnings.size() == 6);
    CHECK_THAT(old.warnings[0].text(),
               Contains("shear.yaml:26: warning: 'bevameter_shear.servo_gain_m_s_per_N': "
                        "deprecated; write 'bevameter_shear.servo.gain_m_s_per_N'"));
    CHECK(old.warnings[4].key == "bevameter_shear.load_hold_s");
    CHECK_THAT(old.warnings[4].message, Contains("'bevameter_shear.servo.hold_s'"));

    // The old spelling keeps its old defaults (a 0.01 m/s clamp, 0.02 s hold, 1 s to load);
    // the block asks for the clamp.
    const auto old_defaults = parseAnnulus(annulus("  servo_gain_m_s_per_N: 0.1\n"));
    CHECK(old_defaults.test.servo.max_speed_m_s == 0.01);
    CHECK(old_defaults.test.servo.hold_s == 0.02);
    CHECK(old_defaults.test.servo.max_load_time_s == 1.0);
    CHECK_THROWS_WITH(parseAnnulus(annulus("  servo: {gain_m_s_per_N: 0.1}\n")),
                      Contains("missing key 'bevameter_shear.servo.max_speed_m_s'"));
    CHECK_THROWS_WITH(parseAnnulus(annulus("")), Contains("missing key 'bevameter_shear.servo'"));
    // Both spellings at once: the old key is unknown next to the block.
    CHECK_THROWS_WITH(parseAnnulus(annulus("  servo: {gain_m_s_per_N: 0.1, max_speed_m_s: 0.05}\n"
                                           "  servo_deadband_N: 0.1\n")),
                      Contains("unknown key 'bevameter_shear.servo_deadband_N'"));
    CHECK_THROWS_WITH(parseAnnulus(annulus(
                          "  servo: {gain_m_s_per_N: 0.1, max_speed_m_s: 0.05, deadband_N: -1}\n")),
                      Contains("bevameter_shear.servo.deadband_N") && Contains("must be >= 0"));
}

TEST_CASE("Servo keys: the box's max_consolidation_time_s is max_load_time_s", "[lab][config]") {
    CHECK(parseBox(kTinyShearBox).test.servo.max_load_time_s == 0.3); // the box's default
    const std::string from = "control_interval_s: 0.00025}";
    const auto old = parseBox(replacedOnce(kTinyShearBox, from,
                                           "control_interval_s: 0.00025, "
                                           "max_consolidation_time_s: 0.7}"));
    CHECK(old.test.servo.max_load_time_s == 0.7);
    REQUIRE(old.warnings.size() == 2); // and the tiny box's width (the next test)
    CHECK_THAT(old.warnings[0].text(),
               Contains("box.yaml:28: warning: 'direct_shear.servo.max_consolidation_time_s': "
                        "deprecated; write 'direct_shear.servo.max_load_time_s'"));
    const auto block = parseBox(
        replacedOnce(kTinyShearBox, from, "control_interval_s: 0.00025, max_load_time_s: 0.7}"));
    CHECK(block.test.servo.max_load_time_s == 0.7);
    CHECK(block.warnings.size() == 1);
    CHECK_THROWS_WITH(parseBox(replacedOnce(kTinyShearBox, from,
                                            "control_interval_s: 0.00025, max_load_time_s: 0.7, "
                                            "max_consolidation_time_s: 0.7}")),
                      Contains("give max_load_time_s only"));
    // The box shears only after the load was held: a zero hold would shear an unloaded box;
    // the annulus may start turning at once.
    CHECK_THROWS_WITH(
        parseBox(replacedOnce(kTinyShearBox, from, "control_interval_s: 0.00025, hold_s: 0}")),
        Contains("direct_shear.servo.hold_s") && Contains("must be > 0"));
    CHECK(parseAnnulus(annulus("  servo: {gain_m_s_per_N: 0.1, max_speed_m_s: 0.05, hold_s: 0}\n"))
              .test.servo.hold_s == 0.0);
}

TEST_CASE("Direct shear: a box narrower than ten grain diameters is warned about with its key "
          "and line (ASTM D3080)",
          "[lab][config]") {
    // The tiny box: 30 mm across, grains up to 2 x 2.25 mm: 6.67 diameters, under D3080's 10.
    const auto tiny = parseBox(kTinyShearBox);
    REQUIRE(tiny.warnings.size() == 1);
    CHECK_THAT(tiny.warnings[0].text(),
               Contains("box.yaml:19: warning: 'direct_shear.width_m': ") &&
                   Contains("6.67 largest grain diameters across") &&
                   Contains("30 mm for grains up to 4.5 mm") &&
                   Contains("ASTM D3080 asks for at least 10"));
    // 45 mm is ten diameters: no warning.
    const auto wide =
        parseBox(replacedOnce(replacedOnce(kTinyShearBox, "length_m: 0.03", "length_m: 0.045"),
                              "width_m: 0.03", "width_m: 0.045"));
    CHECK(wide.warnings.empty());
    // The narrower side is the one named: a box 60 mm wide but 30 mm long in the shear direction.
    const auto long_narrow =
        parseBox(replacedOnce(kTinyShearBox, "width_m: 0.03", "width_m: 0.06"));
    REQUIRE(long_narrow.warnings.size() == 1);
    CHECK(long_narrow.warnings[0].key == "direct_shear.length_m");
    CHECK(long_narrow.warnings[0].line == 18);
}

TEST_CASE("Lab soil: keys a lab test would read and ignore are errors with their line",
          "[lab][config]") {
    const std::string cache = "    max_settle_time_s: 0.4\n";
    CHECK_THROWS_WITH(
        lab::parseRepose(config::ConfigNode::loadString(
            replacedOnce(kTinyRepose, cache, cache + "  packing_cache_directory: \"\"\n"),
            "repose.yaml")),
        Contains("repose.yaml:18:") && Contains("soil.packing_cache_directory") &&
            Contains("never cached"));
    // The fill is poured into the standing tube: a compaction plate cannot enter it (it failed
    // after settling, "the bed must have no mesh bodies yet").
    CHECK_THROWS_WITH(
        lab::parseRepose(config::ConfigNode::loadString(
            replacedOnce(kTinyRepose, cache, cache + "    compaction: {pressure_Pa: 4000}\n"),
            "repose.yaml")),
        Contains("repose.yaml:18:") && Contains("soil.deposition.compaction") &&
            Contains("poured into the standing tube"));
    CHECK_THROWS_WITH(parseBox(replacedOnce(kTinyShearBox, "soil:\n", "soil:\n  name: other\n")),
                      Contains("box.yaml:3:") && Contains("soil.name") &&
                          Contains("top-level 'name'"));
    CHECK_THROWS_WITH(parseBox(replacedOnce(kTinyShearBox, "soil:\n",
                                            "soil:\n  output: {series_interval_s: 0.01}\n")),
                      Contains("soil.output") && Contains("writes its own outputs"));
    CHECK_THROWS_WITH(
        parseAnnulus(replacedOnce(annulus("  servo: {gain_m_s_per_N: 0.1, max_speed_m_s: 0.05}\n"),
                                  "soil:\n", "soil:\n  bodies: []\n")),
        Contains("the shear test adds its own annulus; remove soil.bodies"));
}

TEST_CASE("Every shipped lab scenario reads strictly, in the current spelling", "[lab][config]") {
    // scenarios/lab/**.yaml but the `grainlink params` inputs: the test named by the file's
    // section key, no error and no deprecation warning.
    const std::filesystem::path root = std::filesystem::path(GRAINLINK_SOURCE_DIR) / "scenarios";
    std::size_t read = 0;
    for (const auto &entry : std::filesystem::recursive_directory_iterator(root / "lab")) {
        const std::string file = entry.path().string();
        if (entry.path().extension() != ".yaml" || file.find("_params") != std::string::npos)
            continue;
        const auto yaml = config::ConfigNode::loadFile(file);
        std::string test;
        for (const std::string &name : lab::labTestNames())
            if (yaml.has(name))
                test = name;
        INFO(file);
        REQUIRE_FALSE(test.empty());
        const lab::LabScenario scenario = lab::loadLabScenario(test, file);
        CHECK(lab::labTestName(scenario) == test);
        CHECK(lab::labWarnings(scenario).empty());
        ++read;
    }
    CHECK(read >= 18); // 6 in scenarios/lab, 12 in compare/
    CHECK_THROWS_WITH(lab::loadLabScenario("triaxial", "x.yaml"),
                      Contains("'triaxial' is not implemented") &&
                          Contains("bevameter, bevameter_shear, direct_shear, repose"));
}
