// `grainlink run` checks a coupled scenario's participant sections against the nodes its
// commands run, before any process starts: a section no node reads, a key the node ignores, or a
// second multibody model is an error naming the file, the key and the line.
#include "CouplingCommands.hpp"

#include <catch2/catch.hpp>

using namespace grainlink;

namespace {

const std::string kParticipants = R"(participants:
  - name: rig
    role: multibody
    command: [grainlink, mbs-node, "{scenario}", --name, "{name}"]
  - name: ground
    role: soil
    command: [grainlink, floor-node, "{scenario}", --name, "{name}", --bodies, wheel]
)";
const std::string kRig = R"(rig:
  wheel: {diameter_m: 0.2, width_m: 0.1}
  wheel_mass_kg: 1.0
  normal_load_kg: 3.0
  start_position_m: [0, 0, 0.2]
)";

/// The error checkParticipantSections gives for `text` ("s.yaml"), or "(accepted)".
std::string errorOf(const std::string &text) {
    try {
        apps::checkParticipantSections(config::ConfigNode::loadString(text, "s.yaml"), "s.yaml");
    } catch (const std::exception &e) {
        return e.what();
    }
    return "(accepted)";
}

} // namespace

TEST_CASE("Coupled scenario: every participant section is read by a node the run starts",
          "[apps][keys]") {
    const std::string floor = "floor: {height_m: 0.0}\n";
    CHECK(errorOf(kParticipants + kRig + floor) == "(accepted)");
    // Lines: the participants take 7, the rig 5, the floor 1; a block section is named at its
    // first line inside.
    CHECK_THAT(errorOf(kParticipants + kRig + floor + "mirror: {plane_y_m: 0.0}\n"),
               Catch::StartsWith("s.yaml:14: key 'mirror': mirror symmetry is the DEM soil's"));
    CHECK_THAT(errorOf(kParticipants + kRig + floor +
                       "wheel_test: {drop_min_s: 0.1}\nmole:\n"
                       "  start_tip_position_m: [0, 0, 0.5]\n"),
               Catch::StartsWith("s.yaml:16: key 'mole': a second multibody model (`rig:` is "
                                 "the first)"));
    const std::string rover = "rover: {start_position_m: [0, 0, 0.5]}\n";
    CHECK_THAT(errorOf(kParticipants + rover + floor + "wheel_test: {drop_min_s: 0.1}\n"),
               Catch::StartsWith("s.yaml:10: key 'wheel_test': the wheel test is the "
                                 "single-wheel rig's procedure"));
    // An external multibody participant (user code) reads no section of ours.
    const std::string external = R"(participants:
  - name: rig
    role: multibody
    external: true
  - name: ground
    role: soil
    command: [grainlink, floor-node, "{scenario}", --name, "{name}", --bodies, wheel]
)";
    CHECK_THAT(errorOf(external + floor + kRig),
               Catch::StartsWith("s.yaml:10: key 'rig': no participant runs `grainlink "
                                 "mbs-node`"));
    CHECK_THAT(errorOf(external + "floor: {height_m: 0.0}\nmole: {start_tip_position_m: [0, 0, "
                                  "1]}\n"),
               Catch::StartsWith("s.yaml:9: key 'mole': no participant runs `grainlink "
                                 "mbs-node`"));
    CHECK_THAT(errorOf(kParticipants + kRig),
               Catch::Contains("missing key 'floor'")); // the floor node needs its section
}

TEST_CASE("Coupled scenario: a soil section has no key the coupling decides", "[apps][keys]") {
    const std::string soil_node = R"(participants:
  - name: soil
    role: soil
    command: [grainlink, dem-node, "{scenario}", --name, "{name}", --bodies, wheel]
)";
    CHECK_THAT(errorOf(soil_node + "soil:\n  bodies: []\n"),
               Catch::StartsWith("s.yaml:6: key 'soil.bodies': a coupled soil's bodies come "
                                 "from the multibody participant"));
    CHECK_THAT(errorOf(soil_node + "soil:\n  name: bed\n"),
               Catch::StartsWith("s.yaml:6: key 'soil.name': a soil node's files are named "
                                 "after its section"));
    CHECK_THAT(errorOf(soil_node + "soil:\n  output: {snapshot_interval_s: 0.1, "
                                   "series_interval_s: 0.01}\n"),
               Catch::StartsWith("s.yaml:6: key 'soil.output.series_interval_s': the soil node "
                                 "writes a row every window"));
    CHECK_THAT(errorOf(soil_node + "soil:\n  run: {duration_s: 1.0}\n"),
               Catch::StartsWith("s.yaml:6: key 'soil.run': a coupled soil runs as long as"));
}
