// The multibody sections of a coupled scenario accept no key that would change nothing: each
// refused key is named with its file and line, with what to do.
#include "grainlink/mbs/RockerBogie.hpp"
#include "grainlink/mbs/WheelTest.hpp"

#include <catch2/catch.hpp>

using namespace grainlink::mbs;
using grainlink::config::ConfigNode;

namespace {

/// The error of parsing the `wheel:` block of `text` (a rig-style YAML file "w.yaml").
std::string wheelError(const std::string &text) {
    try {
        parseWheelShape(ConfigNode::loadString(text, "w.yaml")["wheel"]);
    } catch (const std::exception &e) {
        return e.what();
    }
    return "(accepted)";
}

} // namespace

TEST_CASE("Wheel block: every key shapes the mesh, and one that would not is refused",
          "[mbs][keys]") {
    SECTION("an open wheel's rim thickness is read") {
        const auto root = ConfigNode::loadString(
            "wheel: {diameter_m: 0.2, width_m: 0.1, closed_sides: false, rim_thickness_m: 0.01}",
            "w.yaml");
        const WheelShape w = parseWheelShape(root["wheel"]);
        CHECK(w.rim_thickness_m == 0.01);
        CHECK_FALSE(w.closed_sides);
    }
    SECTION("a closed wheel's rim thickness: solid to the grains") {
        CHECK_THAT(wheelError("wheel:\n  diameter_m: 0.2\n  width_m: 0.1\n"
                              "  rim_thickness_m: 0.005\n"),
                   Catch::StartsWith("w.yaml:4: key 'wheel.rim_thickness_m': a closed wheel is "
                                     "solid to the grains"));
    }
    SECTION("a rim as thick as the radius") {
        CHECK_THAT(wheelError("wheel: {diameter_m: 0.2, width_m: 0.1, closed_sides: false,\n"
                              "        rim_thickness_m: 0.1}\n"),
                   Catch::StartsWith("w.yaml:2: key 'wheel.rim_thickness_m': must be less than "
                                     "the rim radius"));
    }
    SECTION("a grouser's height without grousers") {
        CHECK_THAT(wheelError("wheel:\n  diameter_m: 0.2\n  width_m: 0.1\n"
                              "  grouser_height_m: 0.01\n"),
                   Catch::StartsWith("w.yaml:4: key 'wheel.grouser_height_m': a wheel without "
                                     "grousers"));
    }
    SECTION("grousers without a height") {
        CHECK_THAT(wheelError("wheel:\n  diameter_m: 0.2\n  width_m: 0.1\n  grouser_count: 8\n"
                              "  grouser_thickness_m: 0.004\n"),
                   Catch::Contains("missing key 'wheel.grouser_height_m'"));
    }
    SECTION("a sweep angle for straight grousers") {
        CHECK_THAT(wheelError("wheel:\n  diameter_m: 0.2\n  width_m: 0.1\n  grouser_count: 8\n"
                              "  grouser_height_m: 0.01\n  grouser_thickness_m: 0.004\n"
                              "  chevron_angle_deg: 20\n"),
                   Catch::StartsWith("w.yaml:7: key 'wheel.chevron_angle_deg': straight "
                                     "grousers have no sweep angle"));
    }
    SECTION("a chevron swept too far") {
        CHECK_THAT(wheelError("wheel:\n  diameter_m: 0.2\n  width_m: 0.1\n  grouser_count: 8\n"
                              "  grouser_height_m: 0.01\n  grouser_thickness_m: 0.004\n"
                              "  grouser_shape: chevron\n  chevron_angle_deg: 85\n"),
                   Catch::StartsWith("w.yaml:8: key 'wheel.chevron_angle_deg': must lie in"));
    }
}

TEST_CASE("Rig and rover: one drive, and none for wheels that are never driven", "[mbs][keys]") {
    const std::string rig = "rig:\n  wheel: {diameter_m: 0.2, width_m: 0.1}\n"
                            "  wheel_mass_kg: 1.0\n  normal_load_kg: 3.0\n"
                            "  start_position_m: [0, 0, 0.2]\n";
    CHECK_THROWS_WITH(
        parseSingleWheelRig(ConfigNode::loadString(
            rig + "  drive_torque_N_m: 0.5\n  angular_velocity_rad_s: 2.0\n", "r.yaml")["rig"]),
        Catch::StartsWith("r.yaml:7: key 'rig.angular_velocity_rad_s': a torque drive"));
    CHECK_THROWS_WITH(parseSingleWheelRig(ConfigNode::loadString(
                          rig + "  drive_torque_N_m: 0.5\n  slip: 0.2\n", "r.yaml")["rig"]),
                      Catch::StartsWith("r.yaml:7: key 'rig.slip': slip control imposes"));
    CHECK(
        parseSingleWheelRig(ConfigNode::loadString(rig + "  slip: 0.2\n", "r.yaml")["rig"]).slip ==
        0.2);

    const std::string rover = "rover:\n  start_position_m: [0, 0, 1]\n";
    CHECK_THROWS_WITH(
        parseRockerBogie(ConfigNode::loadString(
            rover + "  wheel_speed_rad_s: 1.0\n  drive_torque_N_m: 2.0\n", "v.yaml")["rover"]),
        Catch::StartsWith("v.yaml:3: key 'rover.wheel_speed_rad_s': give one drive"));
    CHECK_THROWS_WITH(
        parseRockerBogie(ConfigNode::loadString(
            rover + "  rotation_locked: true\n  drive_torque_N_m: 2.0\n", "v.yaml")["rover"]),
        Catch::StartsWith("v.yaml:4: key 'rover.drive_torque_N_m': the wheels are locked"));
    CHECK(parseRockerBogie(
              ConfigNode::loadString(rover + "  rotation_locked: true\n", "v.yaml")["rover"])
              .rotation_locked);
}
