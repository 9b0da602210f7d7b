// Per-contact-type laws (grain-grain, grain-wall, grain-tool): each effect acts on the contact
// type it is given for, checked against closed forms (docs/physics.md §2.10).
#include "Fixtures.hpp"

#include "grainlink/dem/Scenario.hpp"

#include <catch2/catch.hpp>

using namespace grainlink::dem;
using namespace grainlink::dem::testing;

namespace {

/// Linear cohesion against Hertz (§2.7): net attraction f(d) = a d - b d^1.5 with a = k_c pi R*,
/// b = 4/3 E* sqrt(R*). Zero at d0 = (a/b)^2, largest at d* = (a / 1.5 b)^2, where it is the
/// pull-off force P = a d* / 3.
struct Adhesion {
    double a, b;
    Adhesion(double k_c, double radius_eff_m)
        : a(k_c * M_PI * radius_eff_m),
          b(4.0 / 3.0 * effectiveModulus(kMaterial) * std::sqrt(radius_eff_m)) {}
    double zeroForceOverlap() const { return std::pow(a / b, 2); }
    double peakOverlap() const { return std::pow(a / (1.5 * b), 2); }
    double pullOff() const { return a * peakOverlap() / 3.0; }
    double attraction(double overlap) const { return a * overlap - b * std::pow(overlap, 1.5); }
};

/// A grain hanging under a ceiling plane (normal -z) held by adhesion alone against a downward
/// pull m g (gravity); started at rest at `overlap`. Returns the overlap after 0.1 s (negative:
/// it came off).
double hang(const ContactLaws &laws, double g, double overlap) {
    DemSettings settings = quietSettings(1e-5);
    settings.gravity_m_s2 = Vec3(0, 0, -g);
    DemSystem sys(laws, {kMaterial}, settings);
    PlaneWall ceiling;
    ceiling.name = "ceiling";
    ceiling.normal = -Vec3::UnitZ();
    sys.addPlane(ceiling);
    sys.particles().add(sphere(Vec3(0, 0, -(kRadius - overlap)), kRadius, 2500.0));
    sys.run(10000);
    return kRadius + sys.particles().position[0].z();
}

ContactLaw cohesive(double k_c) {
    ContactLaw law = hertzRestitution(0.3, 0.5);
    law.cohesion = CohesionLinear{k_c};
    return law;
}

} // namespace

TEST_CASE("grain-wall cohesion: a grain comes off a wall at the analytic pull-off force",
          "[dem][contact][contact_type]") {
    // The wall's cohesion k_c = 1e5 J/m^3, the grains' a tenth of it: the grain hangs below 0.97
    // of P = a d*/3 (R* = r at a wall) and comes off above 1.03 of it. It starts at the stable
    // equilibrium overlap (f(d) = m g on the falling branch d > d*) or, pulled beyond P, at d*.
    ContactLaws laws(cohesive(1e4));
    laws.grain_wall = cohesive(1e5);
    const Adhesion wall(1e5, kRadius);
    const double m = sphereMass(kRadius, 2500.0);
    const double g_hold = 0.97 * wall.pullOff() / m, g_drop = 1.03 * wall.pullOff() / m;
    double lo = wall.peakOverlap(), hi = wall.zeroForceOverlap(); // f falls from P to 0
    for (int k = 0; k < 100; ++k)
        (wall.attraction(0.5 * (lo + hi)) > m * g_hold ? lo : hi) = 0.5 * (lo + hi);
    const double held = hang(laws, g_hold, lo);
    CHECK(held == Approx(lo).epsilon(1e-3)); // at rest where cohesion balances the pull
    CHECK(hang(laws, g_drop, wall.peakOverlap()) < 0.0);
    // Under the grain-grain cohesion alone the same pull tears it off at once: the wall's own
    // parameter, not the grains', holds it.
    CHECK(hang(ContactLaws(cohesive(1e4)), g_hold, lo) < 0.0);
}

TEST_CASE("cohesion given to grain-grain contacts only leaves the wall non-adhesive",
          "[dem][contact][contact_type][scenario]") {
    // A scenario whose grains are cohesive and whose walls are not (contact_wall sets k_c = 0).
    // With no gravity, two grains placed at the overlap where cohesion balances Hertz stay
    // there; a grain placed at that overlap (for R* = r) on a wall is pushed off.
    const std::string text = R"(name: sticky
simulation: {time_step_s: 1.0e-5, gravity: none}
material: {youngs_modulus_Pa: 1.0e7, poisson_ratio: 0.3, density_kg_m3: 2500}
contact:
  damping: {model: restitution, restitution: 0.3}
  tangential: {model: mindlin, friction_coefficient: 0.5}
  cohesion: {model: linear, energy_density_J_m3: 1.0e5}
contact_wall:
  cohesion: {energy_density_J_m3: 0}
walls:
  - {name: floor, type: plane, point_m: [0, 0, 0], normal: [0, 0, 1]}
deposition:
  region: {lower_m: [0, 0, 0], upper_m: [0.1, 0.1, 0.1]}
  count: 10
  radius: {distribution: constant, value_m: 0.005}
run: {duration_s: 0.1}
)";
    const auto overlapsAfter = [](const DemScenario &scenario) {
        auto sys = makeSystem(scenario);
        const double pair = Adhesion(1e5, 0.5 * kRadius).zeroForceOverlap();
        const double wall = Adhesion(1e5, kRadius).zeroForceOverlap();
        auto &p = sys->particles();
        p.add(sphere(Vec3(0, 0, kRadius - wall), kRadius, 2500.0)); // on the floor
        p.add(sphere(Vec3(0.05, 0, 0.05), kRadius, 2500.0));        // a pair in mid-air
        p.add(sphere(Vec3(0.05, 0, 0.05 + 2 * kRadius - pair), kRadius, 2500.0));
        sys->run(5000);
        return std::pair<double, double>{kRadius - p.position[0].z(),
                                         2 * kRadius - (p.position[2] - p.position[1]).norm()};
    };
    const DemScenario s = parseScenario(ConfigNode::loadString(text, "sticky.yaml"));
    const double pair0 = Adhesion(1e5, 0.5 * kRadius).zeroForceOverlap();
    const double wall0 = Adhesion(1e5, kRadius).zeroForceOverlap();
    const auto [wall, pair] = overlapsAfter(s);
    CHECK(pair == Approx(pair0).epsilon(1e-3)); // the grains hold together
    CHECK(wall < 0.0);                          // the wall let go
    // Without contact_wall the wall takes the grains' cohesion (behaviour as before).
    DemScenario inherited = s;
    inherited.contact_wall = ContactOverride{};
    CHECK(overlapsAfter(inherited).first == Approx(wall0).epsilon(1e-3));
}

TEST_CASE("a grain slides on a wall at the wall's friction, not the grains'",
          "[dem][contact][contact_type][friction]") {
    // A sphere resting on a plane, launched at v0 without spin, slides while v > omega r and
    // decelerates at exactly mu g, the friction of grain-wall contacts (0.2) while the
    // grain-grain one is 0.6; a plane's own friction_coefficient (0.4) overrides both.
    // Sliding lasts 2 v0 / (7 mu g); the deceleration is measured over half of it.
    ContactLaws laws(hertzRestitution(0.3, 0.6));
    laws.grain_wall = hertzRestitution(0.3, 0.2);
    const auto deceleration = [&](std::optional<double> plane_friction, double mu) {
        DemSettings settings = quietSettings(1e-5);
        settings.gravity_m_s2 = Vec3(0, 0, -kG);
        DemSystem sys(laws, {kMaterial}, settings);
        PlaneWall floor;
        floor.name = "floor";
        floor.friction_coefficient = plane_friction;
        sys.addPlane(floor);
        const double m = sphereMass(kRadius, 2500.0);
        const double rest = std::pow(
            m * kG / (4.0 / 3.0 * effectiveModulus(kMaterial) * std::sqrt(kRadius)), 2.0 / 3.0);
        const double v0 = 0.5;
        sys.particles().add(sphere(Vec3(0, 0, kRadius - rest), kRadius, 2500.0, {v0, 0, 0}));
        const double t = 0.5 * 2.0 * v0 / (7.0 * mu * kG);
        sys.run(std::uint64_t(std::llround(t / 1e-5)));
        return (v0 - sys.particles().velocity[0].x()) / sys.time();
    };
    CHECK(deceleration(std::nullopt, 0.2) == Approx(0.2 * kG).epsilon(0.01));
    CHECK(deceleration(0.4, 0.4) == Approx(0.4 * kG).epsilon(0.01));
}

TEST_CASE("a friction track brakes a sliding grain at its own friction, beside it none",
          "[dem][contact][contact_type][friction]") {
    // The seed's bin floor: a frictionless plane carrying a rough track (mu = 0.4) for x < 0.05.
    // A grain launched inside the track slides at a = mu_track g, as on a wall of that friction
    // (docs/physics.md §2.10: a track's coefficient takes precedence over the wall's); one
    // launched beside it keeps its speed to round-off. The track's box reaches just above the
    // floor: it holds the contact points, which lie on the floor surface.
    DemSettings settings = quietSettings(1e-5);
    settings.gravity_m_s2 = Vec3(0, 0, -kG);
    DemSystem sys(ContactLaws(hertzRestitution(0.3, 0.6)), {kMaterial}, settings);
    PlaneWall floor;
    floor.name = "floor";
    floor.friction_coefficient = 0.0;
    floor.track = FrictionTrack{Vec3(-1, -1, -0.001), Vec3(0.05, 1, 0.001), 0.4};
    sys.addPlane(floor);
    const double m = sphereMass(kRadius, 2500.0);
    const double rest = std::pow(
        m * kG / (4.0 / 3.0 * effectiveModulus(kMaterial) * std::sqrt(kRadius)), 2.0 / 3.0);
    const double v0 = 0.2;
    sys.particles().add(sphere(Vec3(0, 0, kRadius - rest), kRadius, 2500.0, {v0, 0, 0}));
    sys.particles().add(sphere(Vec3(0.2, 0.1, kRadius - rest), kRadius, 2500.0, {v0, 0, 0}));
    const double t = 0.5 * 2.0 * v0 / (7.0 * 0.4 * kG); // half the sliding time on the track
    sys.run(std::uint64_t(std::llround(t / 1e-5)));
    const auto &v = sys.particles().velocity;
    REQUIRE(sys.particles().position[0].x() < 0.05); // still on the track
    CHECK((v0 - v[0].x()) / sys.time() == Approx(0.4 * kG).epsilon(0.01));
    CHECK(v[1].x() == Approx(v0).epsilon(1e-9));
    CHECK(sys.particles().angular_velocity[1].norm() < 1e-9);
}

TEST_CASE("cohesion: a grain snaps into a wall to (5/4)^2 of its resting overlap, at any step",
          "[dem][contact][contact_type][cohesion]") {
    // Soft grains (E = 5.4 MPa, r = 1.8 mm) and strong linear cohesion at a wall: released at rest
    // at first touch, without damping and gravity, the grain falls into the wall until the
    // potential of f(d) = a d - b d^1.5 is back to zero: a d^2 / 2 = 2/5 b d^2.5, at
    // d1 = (5 a / 4 b)^2 = (5/4)^2 d0. k_c = 0.331 E* puts d0 at 0.61 r and d1 at 0.95 r, the
    // overlap once seen beside a wall. The law alone takes it there: the same at the stability
    // estimate's step and at a tenth of it (docs/physics.md §2.7).
    const Material soft = soil(5.4e6, 0.2, 2400.0);
    const double r = 0.0018, e_star = 5.4e6 / (2.0 * (1.0 - 0.04));
    const double k_c = 0.331 * e_star;
    const double a = k_c * M_PI * r, b = 4.0 / 3.0 * e_star * std::sqrt(r);
    const double d0 = std::pow(a / b, 2), d1 = std::pow(1.25 * a / b, 2);
    REQUIRE(d1 / r == Approx(0.95).epsilon(0.01));
    ContactLaw law = hertzRestitution(1.0, 0.5); // e = 1: no dashpot
    law.cohesion = CohesionLinear{k_c};
    const auto deepest = [&](double step_fraction) {
        DemSettings settings = quietSettings(1e-5);
        settings.max_overlap_ratio = 2.0; // let the grain go where the law takes it
        DemSystem sys(ContactLaws(law), {soft}, settings);
        PlaneWall floor;
        floor.name = "floor";
        sys.addPlane(floor);
        sys.particles().add(sphere(Vec3(0, 0, r * (1.0 - 1e-6)), r, 2400.0));
        sys.setTimeStep(step_fraction * sys.stableTimeStepEstimate());
        double deepest = 0.0;
        for (int k = 0; k < 200000 && sys.time() < 0.01; ++k) {
            sys.step();
            deepest = std::max(deepest, r - sys.particles().position[0].z());
        }
        return deepest;
    };
    CHECK(deepest(0.1) == Approx(d1).epsilon(0.01));
    CHECK(deepest(0.99) == Approx(d1).epsilon(0.03));
    CHECK(d0 / r == Approx(0.608).epsilon(0.01));
    // Under the default max_overlap_ratio (0.4) the run stops, blaming cohesion, not the step.
    DemSystem sys(ContactLaws(law), {soft}, quietSettings(1e-5));
    PlaneWall floor;
    floor.name = "floor";
    sys.addPlane(floor);
    sys.particles().add(sphere(Vec3(0, 0, r * (1.0 - 1e-6)), r, 2400.0));
    CHECK_THROWS_WITH(sys.run(2000), Catch::Contains("against plane 'floor'") &&
                                         Catch::Contains("(cohesion alone holds this contact "
                                                         "at 0.608") &&
                                         Catch::Contains("lower the cohesion or stiffen"));
    law.cohesion = CohesionLinear{0.2 * k_c}; // resting at 0.024 r: the usual hint
    DemSystem weak(ContactLaws(law), {soft}, quietSettings(1e-5));
    weak.addPlane(floor);
    weak.particles().add(sphere(Vec3(0, 0, 0.5 * r), r, 2400.0));
    CHECK_THROWS_WITH(weak.run(1), Catch::EndsWith("(time step too large or stiffness too low)"));
}

TEST_CASE("grain-tool rolling resistance decelerates a spinning grain at 5 mu_r g / 2 r",
          "[dem][contact][contact_type][rolling]") {
    // A sphere spinning about a horizontal axis on a flat mesh (a tool), without tangential
    // friction there: the only moment is the EPSD rolling moment at its cap mu_r R* F_N with
    // R* = r, F_N = m g, so omega falls at mu_r r m g / J = 5 mu_r g / (2 r), J = 2/5 m r^2.
    // The tool's mu_r = 0.3; the grains' (0.05) would give a sixth of that deceleration.
    ContactLaw grains = hertzRestitution(0.3, 0.5);
    grains.rolling = RollingEpsd{0.05};
    ContactLaws laws(grains);
    laws.grain_tool.tangential = TangentialMindlin{0.0};
    const auto deceleration = [&](const ContactLaws &with, double mu_r) {
        DemSettings settings = quietSettings(1e-5);
        settings.gravity_m_s2 = Vec3(0, 0, -kG);
        DemSystem sys(with, {kMaterial}, settings);
        sys.addBody(MeshBody("plate", makeRectangle(0.1, 0.1, 3, 3), {}));
        const double m = sphereMass(kRadius, 2500.0);
        const double rest = std::pow(
            m * kG / (4.0 / 3.0 * effectiveModulus(kMaterial) * std::sqrt(kRadius)), 2.0 / 3.0);
        ParticleSpec s = sphere(Vec3(0, 0, kRadius - rest), kRadius, 2500.0);
        const double w0 = 20.0;
        s.angular_velocity_rad_s = Vec3(0, w0, 0);
        sys.particles().add(s);
        const double stop_s = w0 * kRadius / (2.5 * mu_r * kG);
        sys.run(std::uint64_t(std::llround(0.5 * stop_s / 1e-5)));
        CHECK(sys.particles().velocity[0].norm() < 1e-6); // no tangential force: no translation
        return (w0 - sys.particles().angular_velocity[0].y()) / sys.time();
    };
    CHECK(deceleration(laws, 0.05) == Approx(2.5 * 0.05 * kG / kRadius).epsilon(0.01));
    laws.grain_tool.rolling = RollingEpsd{0.3};
    CHECK(deceleration(laws, 0.3) == Approx(2.5 * 0.3 * kG / kRadius).epsilon(0.01));
}

TEST_CASE("contact_wall and contact_tool are validated strictly",
          "[dem][contact][contact_type][scenario]") {
    const std::string head = R"(name: typed
simulation: {time_step_s: 1.0e-4}
material: {youngs_modulus_Pa: 3.0e6, poisson_ratio: 0.2, density_kg_m3: 2400}
contact:
  damping: {model: restitution, restitution: 0.3}
  tangential: {model: mindlin, friction_coefficient: 0.5}
  rolling: {model: grain_shape, aspect_ratio_angle_deg: 30}
deposition:
  region: {lower_m: [0, 0, 0], upper_m: [0.1, 0.1, 0.1]}
  count: 100
  radius: {distribution: constant, value_m: 0.004}
run: {duration_s: 0.1}
)";
    const auto errorOf = [&](const std::string &extra) {
        try {
            parseScenario(ConfigNode::loadString(head + extra, "typed.yaml"));
        } catch (const ConfigError &e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    // Valid: parameters of the grain-grain models, the model named or not.
    const DemScenario ok = parseScenario(ConfigNode::loadString(
        head + "contact_wall:\n  tangential: {model: mindlin, friction_coefficient: 0.1}\n"
               "contact_tool:\n  rolling: {aspect_ratio_angle_deg: 20}\n",
        "typed.yaml"));
    const ContactLaws laws = contactLaws(ok);
    CHECK(std::get<TangentialMindlin>(laws.grain_wall.tangential).friction_coefficient == 0.1);
    CHECK(std::get<TangentialMindlin>(laws.grain_tool.tangential).friction_coefficient == 0.5);
    CHECK(std::get<RollingGrainShape>(laws.grain_tool.rolling).aspect_ratio_angle_deg.x() == 20.0);
    CHECK(std::get<RollingGrainShape>(laws.grain_wall.rolling).aspect_ratio_angle_deg.x() == 30.0);
    // Unknown keys, with file and line.
    CHECK_THAT(errorOf("contact_wall:\n  cohesion: {energy_density_Pa: 5}\n"),
               Catch::Contains("typed.yaml:14:") && Catch::Contains("energy_density_Pa"));
    CHECK_THAT(errorOf("contact_tool:\n  background_damping_1_s: 1\n"),
               Catch::Contains("typed.yaml:14:") && Catch::Contains("background_damping_1_s"));
    // Another model than the grains': named, with both models.
    CHECK_THAT(errorOf("contact_wall:\n  rolling: {model: epsd, coefficient: 0.1}\n"),
               Catch::Contains("typed.yaml:14:") && Catch::Contains("'epsd'") &&
                   Catch::Contains("'grain_shape'"));
    CHECK_THAT(errorOf("contact_wall:\n  cohesion: {model: linear, energy_density_J_m3: 5}\n"),
               Catch::Contains("differs from the grain-grain model 'none'"));
    // The grains' moments of inertia are not a contact type's.
    CHECK_THAT(errorOf("contact_tool:\n  rolling: {inertia: seed_eq12}\n"),
               Catch::Contains("typed.yaml:14:") && Catch::Contains("inertia"));
    // A parameter out of range names the model and the parameter.
    CHECK_THAT(errorOf("contact_wall:\n  damping: {restitution: 1.5}\n"),
               Catch::Contains("typed.yaml:14:") && Catch::Contains("restitution"));
    // The API refuses other models too, naming the contact type and the slot.
    ContactLaws mixed(hertzRestitution(0.3, 0.5));
    mixed.grain_tool.cohesion = CohesionLinear{10.0};
    CHECK_THROWS_WITH(DemSystem(mixed, {kMaterial}, quietSettings(1e-5)),
                      Catch::Contains("grain-tool") && Catch::Contains("cohesion"));
    // Grain-wall parameters shape a packing, grain-tool ones do not.
    const DemScenario base = parseScenario(ConfigNode::loadString(head, "typed.yaml"));
    DemScenario wall = base, tool = base;
    wall.contact_wall.tangential = TangentialMindlin{0.1};
    tool.contact_tool.tangential = TangentialMindlin{0.1};
    CHECK(packingKey(wall) != packingKey(base));
    CHECK(packingKey(tool) == packingKey(base));
}
