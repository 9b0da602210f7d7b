// Numerical checks of the lab tests (docs/lab.md, physics.md §12.14): the widened and refined
// scenarios, the stability margin of the refined step, and the baseline-vs-rerun report.
#include "grainlink/lab/NumericalChecks.hpp"

#include <catch2/catch.hpp>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

using namespace grainlink;
using Catch::Matchers::Contains;

namespace {

/// A tiny soil (never run here): a 40 x 60 mm box, a floor plane with a friction track.
const char *kSoil = R"(simulation: {time_step_s: 4.0e-5, threads: 1, skin_m: 0.0004}
material: {youngs_modulus_Pa: 1.0e7, poisson_ratio: 0.2, density_kg_m3: 2400}
contact:
  damping: {model: viscous, coefficient_N_s_m: 0.1}
  tangential: {model: linear, stiffness_N_m: 200, damping_N_s_m: 0.02, stick_angle_deg: 32, slip_angle_deg: 30}
walls:
  - {name: bin, type: box, lower_m: [0, 0, 0], upper_m: [0.04, 0.06, 0.2]}
  - name: floor
    type: plane
    point_m: [0.01, 0.02, 0]
    normal: [0, 0, 1]
    track: {lower_m: [0.01, 0.02, 0], upper_m: [0.03, 0.04, 0.01], friction_coefficient: 0.5}
deposition:
  region: {lower_m: [0, 0, 0], upper_m: [0.04, 0.06, 0.05]}
  count: 1000
  radius: {distribution: uniform, min_m: 0.001, max_m: 0.0015}
  seed: 3
  settle_kinetic_energy_J: 1.0e-8
  max_settle_time_s: 0.4
packing_cache_directory: ""
)";

dem::DemScenario soil() {
    return dem::parseScenario(config::ConfigNode::loadString(kSoil, "soil.yaml"), true);
}

const dem::PlaneWall &plane(const dem::DemScenario &s, const std::string &name) {
    for (const auto &w : s.planes)
        if (w.name == name)
            return w;
    FAIL("no plane " << name);
    return s.planes.front();
}

/// The system's stability estimate with one grain of radius r (the smallest one sets it).
double stabilityEstimate(const dem::DemScenario &s, double radius_m) {
    auto sys = dem::makeSystem(s);
    dem::ParticleSpec grain;
    grain.radius_m = radius_m;
    grain.density_kg_m3 = s.material.density_kg_m3;
    sys->particles().add(grain);
    return sys->stableTimeStepEstimate();
}

} // namespace

TEST_CASE("Widened soil: region and side walls x F about the centre, grains x F^2",
          "[lab][checks]") {
    const auto base = soil();
    const auto w = lab::widenedSoil(base, 2.0);
    // Exact arithmetic on binary fractions up to rounding: 1e-15 m.
    const double eps = 1e-15;
    // Centre (0.02, 0.03): x in [-0.02, 0.06], y in [-0.03, 0.09], heights unchanged.
    CHECK(w.deposition.region_lower_m.isApprox(dem::Vec3(-0.02, -0.03, 0.0), eps));
    CHECK(w.deposition.region_upper_m.isApprox(dem::Vec3(0.06, 0.09, 0.05), eps));
    CHECK(w.deposition.count == 4000);
    CHECK(plane(w, "bin.xmin").point_m.x() == Approx(-0.02).margin(eps));
    CHECK(plane(w, "bin.xmax").point_m.x() == Approx(0.06).margin(eps));
    CHECK(plane(w, "bin.ymin").point_m.y() == Approx(-0.03).margin(eps));
    CHECK(plane(w, "bin.ymax").point_m.y() == Approx(0.09).margin(eps));
    CHECK(plane(w, "bin.xmax").normal.isApprox(dem::Vec3(-1, 0, 0), eps));
    CHECK(plane(w, "bin.zmin").point_m.z() == 0.0);
    CHECK(plane(w, "bin.zmin").normal.isApprox(dem::Vec3(0, 0, 1), eps));
    // The floor's friction track widens with it.
    const auto &track = *plane(w, "floor").track;
    CHECK(track.lower_m.isApprox(dem::Vec3(0.0, 0.01, 0.0), eps));
    CHECK(track.upper_m.isApprox(dem::Vec3(0.04, 0.05, 0.01), eps));
    // Grains, law and step are those of the baseline.
    CHECK(w.deposition.radius.max_m == base.deposition.radius.max_m);
    CHECK(w.settings.time_step_s == base.settings.time_step_s);
    CHECK(lab::widenedSoil(base, 1.5).deposition.count == 2250);
    // About a given point (the direct shear box's corner at the origin).
    const auto corner = lab::widenedSoil(base, 2.0, Eigen::Vector2d::Zero());
    CHECK(corner.deposition.region_lower_m.isApprox(dem::Vec3(0.0, 0.0, 0.0), eps));
    CHECK(corner.deposition.region_upper_m.isApprox(dem::Vec3(0.08, 0.12, 0.05), eps));
    CHECK(plane(corner, "bin.ymax").point_m.y() == Approx(0.12).margin(eps));
    CHECK_THROWS_WITH(lab::widenedSoil(base, 0.9), Contains("must be > 1"));
}

TEST_CASE("Widened soil: a tilted wall stays the same plane under the map", "[lab][checks]") {
    // A plane through (0.04, 0.03, 0) with normal (1, 0, 1)/sqrt 2; the map x -> c + F (x - c)
    // sends its point p to p' and every point q of the plane to q'. The new plane must hold q'.
    auto base = soil();
    dem::PlaneWall tilted;
    tilted.name = "ramp";
    tilted.point_m = dem::Vec3(0.04, 0.03, 0.0);
    tilted.normal = dem::Vec3(1, 0, 1).normalized();
    base.planes.push_back(tilted);
    const auto w = lab::widenedSoil(base, 3.0);
    const auto &ramp = plane(w, "ramp");
    const dem::Vec3 q(0.03, 0.05, 0.01); // (q - p) . n = 0: on the ramp
    const dem::Vec3 q_mapped(0.02 + 3.0 * (q.x() - 0.02), 0.03 + 3.0 * (q.y() - 0.03), q.z());
    CHECK(std::abs((q_mapped - ramp.point_m).dot(ramp.normal)) < 1e-15);
    CHECK(ramp.normal.norm() == Approx(1.0).epsilon(1e-15));
}

TEST_CASE("Refined soil: radii x f, grains / f^3, step x f, same stability margin",
          "[lab][checks]") {
    const auto base = soil();
    const double f = 0.5;
    const auto r = lab::refinedSoil(base, f);
    CHECK(r.deposition.radius.min_m == Approx(0.0005).epsilon(1e-14));
    CHECK(r.deposition.radius.max_m == Approx(0.00075).epsilon(1e-14));
    CHECK(r.deposition.count == 8000);
    CHECK(r.settings.time_step_s == Approx(2.0e-5).epsilon(1e-14));
    CHECK(r.settings.skin_m == Approx(0.0002).epsilon(1e-14));
    CHECK(r.deposition.settle_kinetic_energy_J == Approx(1.25e-9).epsilon(1e-14));
    const auto &t = std::get<dem::TangentialLinear>(r.law.tangential);
    CHECK(t.stiffness_N_m == Approx(100.0).epsilon(1e-14));
    CHECK(t.damping_N_s_m == Approx(0.005).epsilon(1e-14));
    CHECK(std::get<dem::DampingViscous>(r.law.damping).coefficient_N_s_m ==
          Approx(0.025).epsilon(1e-14));
    // Region, walls and angles stay.
    CHECK(r.deposition.region_upper_m == base.deposition.region_upper_m);
    CHECK(r.planes.size() == base.planes.size());
    CHECK(t.stick_angle_deg == 32.0);
    // The step keeps its margin to grainlink's stability estimate (physics.md §3.3): every limit
    // (half the Rayleigh time, the dashpot limit m_min / c) scales with r when c scales with r^2.
    // Set the damping so that the dashpot limit is the binding one in both runs, then also with
    // the Rayleigh limit binding. The ratio is exact up to rounding (1e-12).
    for (double c : {0.1, 5.0}) {
        auto b = base;
        std::get<dem::DampingViscous>(b.law.damping).coefficient_N_s_m = c;
        const auto rb = lab::refinedSoil(b, 0.6);
        const double margin = b.settings.time_step_s / stabilityEstimate(b, 0.001);
        const double refined_margin = rb.settings.time_step_s / stabilityEstimate(rb, 0.0006);
        INFO("viscous coefficient " << c << " N s/m: margins " << margin << ", " << refined_margin);
        CHECK(refined_margin == Approx(margin).epsilon(1e-12));
    }
    CHECK_THROWS_WITH(lab::refinedSoil(base, 1.0), Contains("must be in (0, 1)"));
}

TEST_CASE("Check requests from the command line", "[lab][checks]") {
    const auto both = lab::parseCheckRequest("both", 0.0);
    CHECK(both.walls);
    CHECK(both.resolution);
    CHECK(both.widen_factor == 2.0);
    CHECK(both.radius_factor == 0.75);
    const auto walls = lab::parseCheckRequest("walls", 3.0);
    CHECK(walls.walls);
    CHECK_FALSE(walls.resolution);
    CHECK(walls.widen_factor == 3.0);
    CHECK(lab::parseCheckRequest("resolution", 0.5).radius_factor == 0.5);
    CHECK_THROWS_WITH(lab::parseCheckRequest("resolution", 2.0), Contains("in (0, 1)"));
    CHECK_THROWS_WITH(lab::parseCheckRequest("walls", 0.5), Contains("must be > 1"));
    CHECK_THROWS_WITH(lab::parseCheckRequest("both", 2.0), Contains("--check both"));
    CHECK_THROWS_WITH(lab::parseCheckRequest("width", 0.0), Contains("walls, resolution or both"));
}

TEST_CASE("Rerun report: every quantity, baseline, rerun, difference, relative difference",
          "[lab][checks]") {
    const lab::Quantities baseline = {{"angle of repose", "deg", 30.0}, {"zero", "Pa", 0.0}};
    lab::CheckRequest request;
    request.walls = request.resolution = true;
    std::vector<std::string> seen;
    const auto checks = lab::runNumericalChecks(
        request, baseline, [&](lab::CheckKind kind, double factor, const std::string &name) {
            seen.push_back(name + " " + std::to_string(factor));
            const double angle = kind == lab::CheckKind::Walls ? 33.0 : 28.5;
            return lab::Quantities{{"zero", "Pa", 1.0}, {"angle of repose", "deg", angle}};
        });
    REQUIRE(seen == std::vector<std::string>{"walls 2.000000", "resolution 0.750000"});
    REQUIRE(checks.size() == 2);
    const auto &a = checks[0].comparisons[0];
    CHECK(a.name == "angle of repose");
    CHECK(a.baseline == 30.0);
    CHECK(a.rerun == 33.0);
    CHECK(a.difference() == Approx(3.0).epsilon(1e-15));
    CHECK(a.relativeDifference() == Approx(0.1).epsilon(1e-15));
    CHECK(checks[1].comparisons[0].relativeDifference() == Approx(-0.05).epsilon(1e-14));
    CHECK(std::isnan(checks[0].comparisons[1].relativeDifference()));

    const std::string text = lab::describeNumericalChecks(checks);
    CHECK_THAT(text, Contains("walls: box width x 2 in x and y, grains x 4"));
    CHECK_THAT(text, Contains("resolution: grain radii x 0.75, grains x 2.37"));
    CHECK_THAT(text, Contains("angle of repose [deg]"));
    CHECK_THAT(text, Contains("10 %"));
    CHECK_THAT(text, Contains("-5 %"));

    const auto dir = std::filesystem::temp_directory_path() /
                     ("grainlink_numerical_checks_test-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "report.txt") << "the test's own report\n";
    lab::writeNumericalChecks(checks, dir.string());
    std::ifstream csv(dir / "numerical_check.csv");
    std::stringstream all;
    all << csv.rdbuf();
    CHECK_THAT(all.str(), Contains("check,factor,quantity,unit,baseline,rerun,difference,"
                                   "relative_difference\n"));
    CHECK_THAT(all.str(), Contains("walls,2,\"angle of repose\",deg,30,33,3,0.1\n"));
    CHECK_THAT(all.str(), Contains("resolution,0.75,\"angle of repose\",deg,30,28.5,-1.5,-0.05\n"));
    std::ifstream report(dir / "report.txt");
    std::stringstream r;
    r << report.rdbuf();
    CHECK_THAT(r.str(), Contains("the test's own report\nNumerical checks"));

    // A rerun that lost a quantity is an error naming it.
    CHECK_THROWS_WITH(lab::runNumericalChecks(request, baseline,
                                              [](lab::CheckKind, double, const std::string &) {
                                                  return lab::Quantities{{"zero", "Pa", 1.0}};
                                              }),
                      Contains("no 'angle of repose'"));
    std::filesystem::remove_all(dir);
}

TEST_CASE("Bevameter quantities: p at quarter sinkages per plate and the Bekker fit",
          "[lab][checks]") {
    // A synthetic result: p = 1e6 z (Pa) for one plate, linear so interpolation is exact.
    lab::BevameterResult result;
    lab::PlateRun plate;
    plate.plate_radius_m = 0.025;
    for (int k = -1; k <= 21; ++k) {
        lab::BevameterSample s;
        s.sinkage_m = 0.001 * k;
        s.pressure_Pa = 1e6 * s.sinkage_m;
        plate.samples.push_back(s);
    }
    result.runs.push_back(plate);
    const auto q = lab::bevameterQuantities(result, 0.02);
    REQUIRE(q.size() == 4); // no fit: no Bekker quantities
    CHECK(q[0].name == "p(5 mm), R = 25 mm");
    CHECK(q[0].value == Approx(5000.0).epsilon(1e-12));
    CHECK(q[3].name == "p(20 mm), R = 25 mm");
    CHECK(q[3].value == Approx(20000.0).epsilon(1e-12));
    lab::BekkerFit fit;
    fit.parameters.n = 0.7;
    fit.standard_error.setZero();
    fit.half_width_95.setZero();
    fit.covariance.setZero();
    result.fit = fit;
    const auto with_fit = lab::bevameterQuantities(result, 0.02);
    REQUIRE(with_fit.size() == 7);
    CHECK(with_fit.back().name == "Bekker n");
    CHECK(with_fit.back().value == 0.7);
}
