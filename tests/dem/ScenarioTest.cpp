// Scenario files: strict validation with file, key and line in every error (docs/scenario.md).
#include "grainlink/dem/Scenario.hpp"
#include "grainlink/dem/ScenarioRun.hpp"

#include <catch2/catch.hpp>

#include <string>

using namespace grainlink::dem;

namespace {

const std::string kValid = R"(name: tiny
simulation:
  time_step_s: 1.0e-4
  gravity: mars
material: {youngs_modulus_Pa: 3.0e6, poisson_ratio: 0.2, density_kg_m3: 2400}
contact:
  damping: {model: restitution, restitution: 0.3}
  tangential: {model: linear, stiffness_N_m: 300, stick_angle_deg: 32, slip_angle_deg: 30}
walls:
  - {name: bin, type: box, lower_m: [0, 0, 0], upper_m: [0.1, 0.1, 0.2], friction_coefficient: 0}
deposition:
  region: {lower_m: [0, 0, 0], upper_m: [0.1, 0.1, 0.1]}
  count: 100
  radius: {distribution: uniform, min_m: 0.004, max_m: 0.005}
run: {duration_s: 0.1}
)";

/// The message of the ConfigError that parsing `text` throws.
std::string errorOf(const std::string &text) {
    try {
        parseScenario(ConfigNode::loadString(text, "bad.yaml"));
    } catch (const ConfigError &e) {
        return e.what();
    }
    return "no error";
}

std::string replaced(std::string text, const std::string &from, const std::string &to) {
    const auto at = text.find(from);
    REQUIRE(at != std::string::npos);
    return text.replace(at, from.size(), to);
}

/// tiny.yaml's system at time step `time_step_s`, holding one of its 4 mm grains.
auto oneGrain(double time_step_s) {
    DemScenario s = parseScenario(ConfigNode::loadString(kValid, "tiny.yaml"));
    s.settings.time_step_s = time_step_s;
    auto system = makeSystem(s);
    ParticleSpec p;
    p.radius_m = 0.004;
    p.density_kg_m3 = 2400;
    p.position_m = Vec3(0.05, 0.05, 0.05);
    system->particles().add(p);
    return system;
}

} // namespace

TEST_CASE("a valid scenario parses into the documented settings", "[dem][scenario]") {
    const DemScenario s = parseScenario(ConfigNode::loadString(kValid, "tiny.yaml"));
    CHECK(s.name == "tiny");
    CHECK(s.settings.gravity_m_s2.z() == Approx(-3.71));
    CHECK(s.planes.size() == 5); // open-top box
    CHECK(std::holds_alternative<TangentialLinear>(s.law.tangential));
    CHECK(std::get<TangentialLinear>(s.law.tangential).slip_angle_deg == 30.0);
    CHECK(s.deposition.count == 100);
    CHECK(s.duration_s == 0.1);
}

TEST_CASE("scenario errors name the file, the key and the line", "[dem][scenario]") {
    SECTION("unknown key") {
        const std::string msg =
            errorOf(replaced(kValid, "gravity: mars", "gravity: mars\n  gravty: 3"));
        // ... with the key it may be a typo of, one letter off one read beside it.
        CHECK(msg == "bad.yaml:5: unknown key 'simulation.gravty' (misspelt? a key read here is "
                     "'gravity')");
    }
    SECTION("wrong unit is recognised as such") {
        const std::string msg = errorOf(replaced(kValid, "time_step_s", "time_step_ms"));
        CHECK(msg.find("bad.yaml:3: unknown key 'simulation.time_step_ms'") == 0);
        CHECK(msg.find("wrong unit? this key is 'time_step_s'") != std::string::npos);
    }
    SECTION("missing key") {
        const std::string msg = errorOf(replaced(kValid, "  count: 100\n", ""));
        CHECK(msg.find("missing key 'deposition.count'") != std::string::npos);
        CHECK(msg.find("bad.yaml:12:") == 0); // the deposition mapping
    }
    SECTION("not a number") {
        const std::string msg = errorOf(replaced(kValid, "count: 100", "count: many"));
        CHECK(msg == "bad.yaml:13: key 'deposition.count': expected a number, got 'many'");
    }
    SECTION("unknown model") {
        const std::string msg = errorOf(replaced(kValid, "model: restitution", "model: hooke"));
        CHECK(
            msg.find("key 'contact.damping.model': 'hooke' is not one of: restitution, viscous") !=
            std::string::npos);
    }
    SECTION("non-physical parameter") {
        const std::string msg =
            errorOf(replaced(kValid, "slip_angle_deg: 30", "slip_angle_deg: 40"));
        CHECK(msg.find("bad.yaml:8:") == 0);
        CHECK(msg.find("slip_angle_deg") != std::string::npos);
    }
    SECTION("counts out of range stop at their key, before any memory is taken") {
        CHECK(errorOf(replaced(kValid, "count: 100", "count: -5")) ==
              "bad.yaml:13: key 'deposition.count': must be a whole number in [1, 50000000], got -5");
        CHECK(errorOf(replaced(kValid, "count: 100", "count: 1e9")).find("in [1, 50000000], got 1e9") !=
              std::string::npos);
        CHECK(errorOf(replaced(kValid, "gravity: mars", "gravity: mars\n  threads: 100000")) ==
              "bad.yaml:5: key 'simulation.threads': must be a whole number in [1, 1024], got 100000");
    }
    SECTION("gravity given twice, by name and as a vector") {
        CHECK(errorOf(
                  replaced(kValid, "gravity: mars", "gravity: mars\n  gravity_m_s2: [0, 0, -1]")) ==
              "bad.yaml:5: key 'simulation.gravity_m_s2': give gravity or gravity_m_s2, not both "
              "(gravity also takes a vector)");
    }
    SECTION("a key given twice") {
        CHECK(errorOf(replaced(kValid, "  count: 100\n", "  count: 100\n  count: 200\n")) ==
              "bad.yaml:14: key 'deposition.count' given twice (first at line 13)");
    }
    SECTION("YAML syntax error") {
        const std::string msg =
            errorOf(replaced(kValid, "run: {duration_s: 0.1}", "run: {duration_s: 0.1"));
        CHECK(msg.find("bad.yaml:") == 0);
        CHECK(msg.find("YAML syntax error") != std::string::npos);
    }
}

TEST_CASE("a time step above the stability estimate is refused with both numbers",
          "[dem][scenario]") {
    auto system = oneGrain(1e-2);
    try {
        system->step();
        FAIL("expected an error");
    } catch (const std::invalid_argument &e) {
        const std::string msg = e.what();
        CHECK(msg.find("time_step_s = 0.01 s is above the stability estimate") == 0);
    }
}

TEST_CASE("the stability estimate is half the Rayleigh time: just above it refused, just below "
          "it runs",
          "[dem][scenario]") {
    // physics.md §3.3 by hand for tiny.yaml's grain (r 4 mm, 2400 kg/m^3, E 3 MPa, nu 0.2):
    // G = E / (2 (1 + nu)) = 1.25 MPa; T_R = pi r sqrt(rho / G) / (0.1631 nu + 0.8766)
    // = 6.05608e-4 s; the estimate T_R / 2 = 3.02804e-4 s.
    const double estimate = 3.02804e-4;
    for (const double factor : {1.01, 0.99}) {
        auto system = oneGrain(factor * estimate);
        INFO("time step " << factor << " x the estimate");
        if (factor > 1.0)
            CHECK_THROWS_WITH(system->step(), Catch::Contains("above the stability estimate 0.000302804 s"));
        else
            CHECK_NOTHROW(system->step());
    }
}

TEST_CASE("the packing key changes with the soil and not with the run", "[dem][scenario]") {
    const DemScenario a = parseScenario(ConfigNode::loadString(kValid, "tiny.yaml"));
    DemScenario b = a;
    b.duration_s = 5.0;
    b.bodies.push_back(BodySpec{});
    CHECK(packingKey(a) == packingKey(b));
    DemScenario c = a;
    c.material.youngs_modulus_Pa = 4e6;
    CHECK(packingKey(a) != packingKey(c));
    DemScenario d = a;
    d.deposition.seed = 99;
    CHECK(packingKey(a) != packingKey(d));
}

TEST_CASE("a mesh whose size cannot fit the grains is refused", "[dem][scenario]") {
    // tiny.yaml: grains of at most 10 mm diameter in a 0.1 m region. A 150 mm wheel given in
    // millimetres (radius 75 "m") is 150 m across: 1500 times the region and 15,000 grains;
    // one scaled twice (radius 7.5e-5 m, width 8e-5 m) is 0.15 mm, under one grain. A 150 mm
    // wheel is fine
    // and the load report gives its size: 0.15 x 0.08 x 0.15 m (72 facets reach ±r on x and z).
    const auto withBody = [](const std::string &radius, const std::string &width = "0.08") {
        return replaced(kValid, "run: {duration_s: 0.1}",
                        "bodies:\n  - name: wheel\n    position_m: [0.05, 0.05, 0.2]\n"
                        "    mesh: {type: cylinder, radius_m: " +
                            radius + ", width_m: " + width + "}\nrun: {duration_s: 0.1}");
    };
    CHECK(errorOf(withBody("75")) ==
          "bad.yaml:18: key 'bodies[0].mesh': body 'wheel': the mesh is 150 m across, 1.5e+03 times "
          "the bed's largest side (0.1 m) and 1.5e+04 grain diameters: a mesh in millimetres "
          "read as metres? (scale it: 0.001)");
    CHECK(errorOf(withBody("7.5e-5", "8e-5")) ==
          "bad.yaml:18: key 'bodies[0].mesh': body 'wheel': the mesh is 0.00015 m across, less "
          "than one grain (0.01 m): a mesh in metres scaled as if in millimetres?");
    const DemScenario ok = parseScenario(ConfigNode::loadString(withBody("0.075"), "ok.yaml"));
    REQUIRE(ok.bodies.size() == 1);
    CHECK(describeMesh("wheel", ok.bodies[0].mesh, Vec3(0.05, 0.05, 0.2), 0.01) ==
          "mesh 'wheel': 288 triangles, 0.15 x 0.08 x 0.15 m (body frame), placed at (0.05, "
          "0.05, 0.2) m, 15 grain diameters across");
}

TEST_CASE("wall clearance and burying the bodies are a coupled soil's keys", "[dem][scenario]") {
    // A coupled soil watches its bodies' distance to the walls: one largest grain diameter by
    // default (tiny.yaml: 2 x 5 mm), or what the key says; `grainlink dem` refuses the key.
    const std::string coupled = replaced(kValid, "run: {duration_s: 0.1}\n", "");
    CHECK(parseScenario(ConfigNode::loadString(coupled, "c.yaml"), true).wall_clearance_m ==
          Approx(0.01));
    CHECK(parseScenario(ConfigNode::loadString(coupled + "wall_clearance_m: 0.03\n", "c.yaml"),
                        true)
              .wall_clearance_m == Approx(0.03));
    CHECK(errorOf(kValid + "wall_clearance_m: 0.03\n") ==
          "bad.yaml:16: key 'wall_clearance_m': only a coupled soil (grainlink dem-node) watches "
          "its bodies' clearance to the walls: remove the key");
    // Burying the bodies likewise: off by default, a coupled soil's alone.
    CHECK_FALSE(parseScenario(ConfigNode::loadString(coupled, "c.yaml"), true).bury_bodies);
    CHECK(parseScenario(ConfigNode::loadString(coupled + "bury_bodies: true\n", "c.yaml"), true)
              .bury_bodies);
    CHECK(errorOf(kValid + "bury_bodies: true\n") ==
          "bad.yaml:16: key 'bury_bodies': only a coupled soil (grainlink dem-node) has bodies to "
          "bury: remove the key");
}

TEST_CASE("thread count: --threads beats the scenario beats OMP_NUM_THREADS", "[dem][scenario]") {
    // tiny.yaml gives no threads key; `with` adds `threads: 1`. GRAINLINK_THREADS is what
    // `--threads N` sets for the command and the processes it starts.
    const std::string without = kValid;
    const std::string with = replaced(kValid, "  gravity: mars\n", "  gravity: mars\n  threads: 1\n");
    const auto threads = [](const std::string &text) {
        return parseScenario(ConfigNode::loadString(text, "t.yaml")).settings.threads;
    };
    ::unsetenv("GRAINLINK_THREADS");
    ::unsetenv("OMP_NUM_THREADS");
    CHECK(threads(without) == 1);
    ::setenv("OMP_NUM_THREADS", "4,2", 1); // nested levels: the first
    CHECK(threads(without) == 4);
    CHECK(threads(with) == 1); // the scenario's own count beats the environment's
    ::setenv("GRAINLINK_THREADS", "3", 1);
    CHECK(threads(with) == 3); // --threads beats both
    ::setenv("GRAINLINK_THREADS", "3x", 1);
    CHECK_THROWS_WITH(threads(with), "--threads / GRAINLINK_THREADS = '3x' is not a thread count "
                                     "(1 to 1024)");
    ::unsetenv("GRAINLINK_THREADS");
    ::unsetenv("OMP_NUM_THREADS");
}

TEST_CASE("a slope: the bed settles level and the run tilts gravity", "[dem][scenario]") {
    // tiny.yaml run on a 20° slope (gravity tilted in x), once with deposition.gravity earth:
    // its packing is the level bed's, grain for grain (deposited and settled under vertical
    // gravity), its cache key the level bed's, and the system it hands to the run pulls at
    // 20°. Without deposition.gravity the grains settle under the tilted gravity: another bed.
    const double g = 9.81, a = 20.0 * M_PI / 180.0;
    const std::string tilted = "gravity_m_s2: [" + std::to_string(-g * std::sin(a)) + ", 0, " +
                               std::to_string(-g * std::cos(a)) + "]";
    const std::string level_text = replaced(kValid, "gravity: mars", "gravity: earth");
    const std::string slope_text = replaced(kValid, "gravity: mars", tilted);
    const std::string settled_level_text =
        replaced(slope_text, "  count: 100\n", "  count: 100\n  gravity: earth\n");
    const auto scenario = [](const std::string &text) {
        DemScenario s = parseScenario(ConfigNode::loadString(text, "slope.yaml"));
        s.packing_cache_directory = ""; // each settles its own bed
        s.deposition.max_settle_time_s = 0.3;
        return s;
    };
    const DemScenario level = scenario(level_text), slope = scenario(slope_text),
                      settled_level = scenario(settled_level_text);
    CHECK(packingKey(settled_level) == packingKey(level));
    CHECK(packingKey(slope) != packingKey(level));
    const auto level_bed = prepareSoil(level, 0.0);
    const auto slope_bed = prepareSoil(settled_level, 0.0);
    const auto tilted_bed = prepareSoil(slope, 0.0);
    CHECK(slope_bed->particles().position == level_bed->particles().position);
    CHECK(tilted_bed->particles().position != level_bed->particles().position);
    CHECK(slope_bed->settings().gravity_m_s2.x() == Approx(-g * std::sin(a)).epsilon(1e-6));
    CHECK(slope_bed->settings().gravity_m_s2.z() == Approx(-g * std::cos(a)).epsilon(1e-6));
}
