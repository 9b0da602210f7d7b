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

TEST_CASE("Coupling section: the guard's bounce keys are read, and a bad value is named with its "
          "file and line",
          "[coupling][keys]") {
    const auto config = [](const std::string &guard) {
        return coordinatorConfigFrom(ConfigNode::loadString(
            "coupling:\n  scheme: explicit-serial\n  end_time_s: 1.0\n  macro_step_s: 0.01\n"
            "  guard:\n" + guard +
                "participants: []\n",
            "c.yaml"));
    };
    const CoordinatorConfig read = config("    bounce_energy_share: 0.1\n    bounce_spans: 4\n");
    CHECK(read.guard.bounce_energy_share == 0.1);
    CHECK(read.guard.bounce_spans == 4);
    CHECK_THROWS_WITH(config("    bounce_energy_share: -0.1\n"),
                      Catch::StartsWith("c.yaml:6: key 'coupling.guard.bounce_energy_share'"));
    CHECK_THROWS_WITH(config("    bounce_spans: 0\n"),
                      Catch::StartsWith("c.yaml:6: key 'coupling.guard.bounce_spans'"));
    CHECK_THROWS_WITH(config("    bounce_energy_share: abc\n"),
                      Catch::StartsWith("c.yaml:6: key 'coupling.guard.bounce_energy_share'"));
}
