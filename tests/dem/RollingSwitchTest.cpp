// One settled packing for several rolling laws (docs/scenario.md, deposition.rolling): the bed
// settles under the deposition's law, is cached under that law's key, and the run goes on with
// its own law from fresh rolling histories.
#include "grainlink/dem/ScenarioRun.hpp"

#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <string>

using namespace grainlink::dem;
namespace fs = std::filesystem;

namespace {

// 150 grains poured into a 6 cm box; settles in about 0.4 s simulated.
std::string rollingScenarioText(const std::string &contact_rolling,
                                const std::string &settling_rolling, const std::string &cache) {
    std::string text = R"(name: switch
simulation: {time_step_s: 5.0e-5}
material: {youngs_modulus_Pa: 3.0e6, poisson_ratio: 0.2, density_kg_m3: 2400}
contact:
  damping: {model: restitution, restitution: 0.3}
  tangential: {model: linear, stiffness_N_m: 300, stick_angle_deg: 32, slip_angle_deg: 30}
  rolling: )" + contact_rolling + R"(
walls:
  - {name: bin, type: box, lower_m: [0, 0, 0], upper_m: [0.06, 0.06, 0.2]}
deposition:
  region: {lower_m: [0, 0, 0], upper_m: [0.06, 0.06, 0.08]}
  count: 150
  radius: {distribution: uniform, min_m: 0.003, max_m: 0.004}
  seed: 3
  settle_kinetic_energy_J: 1.0e-8
  max_settle_time_s: 1.0
)";
    if (!settling_rolling.empty())
        text += "  rolling: " + settling_rolling + "\n";
    return text + "packing_cache_directory: " + cache + "\nrun: {duration_s: 0.01}\n";
}

DemScenario parsedRolling(const std::string &text) {
    return parseScenario(ConfigNode::loadString(text, "switch.yaml"));
}

const std::string kNone = "{model: none}";
const std::string kEpsd = "{model: epsd, coefficient: 0.3}";
const std::string kShape = "{model: grain_shape, aspect_ratio_angle_deg: 20, inertia: seed_eq12}";

bool samePositions(const ParticleStore &a, const ParticleStore &b) {
    if (a.size() != b.size())
        return false;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (a.id[i] != b.id[i] || a.position[i] != b.position[i])
            return false;
    return true;
}

/// Contacts of `sys` (prepared now) that carry a rolling history.
std::size_t contactsWithRollingHistory(DemSystem &sys) {
    sys.prepare();
    std::size_t contacts = 0, loaded = 0;
    for (const auto &c : sys.saveInternals().contacts) {
        ++contacts;
        loaded += !c.history.rolling_N_m.isZero();
    }
    REQUIRE(contacts > 150);
    return loaded;
}

} // namespace

TEST_CASE("deposition.rolling: the packing key is the settling law's", "[dem][scenario]") {
    const std::string cache = "/tmp/unused";
    // Rolling laws that settle alike share a packing; the run's own law decides otherwise.
    CHECK(packingKey(parsedRolling(rollingScenarioText(kEpsd, kNone, cache))) ==
          packingKey(parsedRolling(rollingScenarioText(kShape, kNone, cache))));
    CHECK(packingKey(parsedRolling(rollingScenarioText(kEpsd, kNone, cache))) ==
          packingKey(parsedRolling(rollingScenarioText(kNone, "", cache))));
    CHECK(packingKey(parsedRolling(rollingScenarioText(kEpsd, "", cache))) !=
          packingKey(parsedRolling(rollingScenarioText(kNone, "", cache))));
    CHECK(packingKey(parsedRolling(rollingScenarioText(kNone, kEpsd, cache))) ==
          packingKey(parsedRolling(rollingScenarioText(kEpsd, "", cache))));
    // A bad law there is reported at its key and line, like contact.rolling.
    try {
        parsedRolling(rollingScenarioText(kNone, "{model: spheroid}", cache));
        FAIL("expected an error");
    } catch (const ConfigError &e) {
        const std::string msg = e.what();
        INFO(msg);
        CHECK(msg.find("switch.yaml:17") != std::string::npos);
        CHECK(msg.find("deposition.rolling.model") != std::string::npos);
    }
}

TEST_CASE("deposition.rolling: several rolling laws run on one settled packing",
          "[dem][scenario][deposition]") {
    const fs::path cache =
        fs::temp_directory_path() / ("grainlink-test-switch-" + std::to_string(::getpid()));
    fs::remove_all(cache);

    // Settled under EPSD (its rolling springs loaded), run under grain shape with seed eq. 12.
    bool from_cache = true;
    auto shaped = prepareSoil(parsedRolling(rollingScenarioText(kShape, kEpsd, cache.string())),
                              0.0, &from_cache);
    CHECK_FALSE(from_cache);
    REQUIRE(std::holds_alternative<RollingGrainShape>(shaped->law().rolling));
    // The settled EPSD contacts carried rolling moments; the new law starts from none of them.
    CHECK(contactsWithRollingHistory(*shaped) == 0);
    // Seed eq. 12's moments (gamma 20 deg: 1.57 times the solid sphere's).
    const auto sphereMoment = [](const DemSystem &sys) {
        const double r = sys.particles().radius[0];
        return 0.4 * sys.particles().mass[0] * r * r;
    };
    const double r0 = shaped->particles().radius[0];
    CHECK(shaped->particles().inertia[0] ==
          grainShapeInertia(std::get<RollingGrainShape>(shaped->law().rolling), r0, 2400.0));
    CHECK(shaped->particles().inertia[0].x() > 1.5 * sphereMoment(*shaped));

    // The same packing from the cache, for EPSD and for no rolling resistance: positions bit
    // for bit, each system with its own law, spheres' moments back where eq. 12 is not the law.
    auto epsd = prepareSoil(parsedRolling(rollingScenarioText(kEpsd, kEpsd, cache.string())), 0.0,
                            &from_cache);
    CHECK(from_cache);
    CHECK(samePositions(shaped->particles(), epsd->particles()));
    CHECK(std::holds_alternative<RollingEpsd>(epsd->law().rolling));
    auto none = prepareSoil(parsedRolling(rollingScenarioText(kNone, kEpsd, cache.string())), 0.0,
                            &from_cache);
    CHECK(from_cache);
    CHECK(samePositions(shaped->particles(), none->particles()));
    CHECK(none->particles().inertia[0].x() == sphereMoment(*none));

    // The cached packing does carry them: read without a switch, under EPSD (the same key).
    auto settled = prepareSoil(parsedRolling(rollingScenarioText(kEpsd, "", cache.string())), 0.0,
                               &from_cache);
    CHECK(from_cache);
    CHECK(contactsWithRollingHistory(*settled) > 100);

    // A cached grain-shape bed continues exactly as the freshly settled one.
    auto shaped_cached = prepareSoil(
        parsedRolling(rollingScenarioText(kShape, kEpsd, cache.string())), 0.0, &from_cache);
    CHECK(from_cache);
    CHECK(contactsWithRollingHistory(*shaped_cached) == 0);
    shaped->run(400);
    shaped_cached->run(400);
    CHECK(samePositions(shaped->particles(), shaped_cached->particles()));
    // ... and the laws do part ways from the shared packing (the switch is not a no-op).
    epsd->run(400);
    none->run(400);
    CHECK_FALSE(samePositions(epsd->particles(), none->particles()));
    fs::remove_all(cache);
}
