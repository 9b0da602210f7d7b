// The coupling section accepts no key that changes nothing (the audit of issue 13).
#include "grainlink/coupling/Coordinator.hpp"

#include <catch2/catch.hpp>

using namespace grainlink::coupling;
using grainlink::config::ConfigNode;

TEST_CASE("Coupling section: past windows are reused by IQN-ILS only", "[coupling][keys]") {
    const std::string head = "coupling:\n  scheme: implicit\n  end_time_s: 1.0\n"
                             "  macro_step_s: 0.01\n  implicit:\n";
    const std::string participants = "participants: []\n";
    const auto config = [&](const std::string &implicit) {
        return coordinatorConfigFrom(
            ConfigNode::loadString(head + implicit + participants, "c.yaml"));
    };
    CHECK(config("    acceleration: iqn-ils\n    reuse_windows: 3\n")
              .scheme.acceleration.reuse_windows == 3);
    CHECK_THROWS_WITH(config("    acceleration: aitken\n    reuse_windows: 3\n"),
                      Catch::StartsWith("c.yaml:7: key 'coupling.implicit.reuse_windows': only "
                                        "acceleration: iqn-ils reuses past windows"));
}
