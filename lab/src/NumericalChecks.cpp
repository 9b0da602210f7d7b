#include "grainlink/lab/NumericalChecks.hpp"
#include "grainlink/config/Number.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace grainlink::lab {

namespace fs = std::filesystem;
using dem::Vec3;

namespace {

std::size_t scaledCount(std::size_t count, double scale) {
    return std::size_t(std::llround(double(count) * scale));
}

std::string number(double x, int digits = 4) {
    return config::significant(x, digits);
}

/// Linear interpolation of y(x) in samples sorted by x; clamped to the ends.
double interpolate(const std::vector<double> &x, const std::vector<double> &y, double at) {
    if (x.empty())
        return std::numeric_limits<double>::quiet_NaN();
    if (at <= x.front())
        return y.front();
    for (std::size_t i = 1; i < x.size(); ++i)
        if (at <= x[i]) {
            const double w = (at - x[i - 1]) / (x[i] - x[i - 1]);
            return y[i - 1] + w * (y[i] - y[i - 1]);
        }
    return y.back();
}

} // namespace

std::string checkName(CheckKind kind) {
    return kind == CheckKind::Walls ? "walls" : "resolution";
}

dem::DemScenario widenedSoil(const dem::DemScenario &soil, double factor,
                             const std::optional<Eigen::Vector2d> &about_m) {
    if (!(factor > 1.0))
        throw std::invalid_argument("widening factor " + number(factor) + " must be > 1");
    dem::DemScenario s = soil;
    auto &d = s.deposition;
    const double cx = about_m ? about_m->x() : 0.5 * (d.region_lower_m.x() + d.region_upper_m.x());
    const double cy = about_m ? about_m->y() : 0.5 * (d.region_lower_m.y() + d.region_upper_m.y());
    // x -> c + F (x - c) in x and y: points map directly, plane normals by the inverse
    // transpose (n_x / F, n_y / F, n_z), renormalised.
    const auto map = [&](Vec3 p) {
        p.x() = cx + factor * (p.x() - cx);
        p.y() = cy + factor * (p.y() - cy);
        return p;
    };
    d.region_lower_m = map(d.region_lower_m);
    d.region_upper_m = map(d.region_upper_m);
    d.count = scaledCount(d.count, factor * factor);
    for (dem::PlaneWall &w : s.planes) {
        w.point_m = map(w.point_m);
        w.normal = Vec3(w.normal.x() / factor, w.normal.y() / factor, w.normal.z()).normalized();
        if (w.track) {
            w.track->lower_m = map(w.track->lower_m);
            w.track->upper_m = map(w.track->upper_m);
        }
    }
    return s;
}

dem::DemScenario refinedSoil(const dem::DemScenario &soil, double factor) {
    if (!(factor > 0.0 && factor < 1.0))
        throw std::invalid_argument("grain radius factor " + number(factor) + " must be in (0, 1)");
    dem::DemScenario s = soil;
    auto &r = s.deposition.radius;
    r.min_m *= factor;
    r.max_m *= factor;
    for (double &x : r.radii_m)
        x *= factor;
    // Same solid volume in the same region: count / f^3 (physics.md §12.14).
    s.deposition.count = scaledCount(s.deposition.count, 1.0 / (factor * factor * factor));
    s.deposition.settle_kinetic_energy_J *= factor * factor * factor; // per grain, ~ mass
    // At a fixed overlap ratio the Hertz secant stiffness goes as E r: a linear tangential spring
    // keeps its ratio to it with c_T ~ r; critical damping 2 sqrt(m k) ~ r^2 keeps the damping
    // fractions with c ~ r^2. Rayleigh time ~ r and the dashpot limit m / c ~ r: dt ~ r.
    if (auto *v = std::get_if<dem::DampingViscous>(&s.law.damping))
        v->coefficient_N_s_m *= factor * factor;
    if (auto *t = std::get_if<dem::TangentialLinear>(&s.law.tangential)) {
        t->stiffness_N_m *= factor;
        t->damping_N_s_m *= factor * factor;
    }
    s.settings.time_step_s *= factor;
    s.settings.skin_m *= factor; // 0 stays "automatic"
    return s;
}

dem::DemScenario checkedSoil(const dem::DemScenario &soil, CheckKind kind, double factor) {
    return kind == CheckKind::Walls ? widenedSoil(soil, factor) : refinedSoil(soil, factor);
}

double CheckComparison::relativeDifference() const {
    if (baseline == 0.0)
        return std::numeric_limits<double>::quiet_NaN();
    return difference() / std::abs(baseline);
}

void CheckRequest::validate() const {
    if (!(widen_factor > 1.0))
        throw std::invalid_argument("--check-factor " + number(widen_factor) +
                                    " for walls must be > 1 (the box width is multiplied by it)");
    if (!(radius_factor > 0.0 && radius_factor < 1.0))
        throw std::invalid_argument("--check-factor " + number(radius_factor) +
                                    " for resolution must be in (0, 1) (the grain radii are "
                                    "multiplied by it)");
}

CheckRequest parseCheckRequest(const std::string &check, double factor) {
    CheckRequest request;
    if (check == "walls" || check == "both")
        request.walls = true;
    if (check == "resolution" || check == "both")
        request.resolution = true;
    if (!request.any())
        throw std::invalid_argument("--check '" + check +
                                    "' is not a check; use walls, resolution or both");
    if (factor != 0.0) {
        if (check == "both")
            throw std::invalid_argument(
                "--check-factor goes with --check walls or --check resolution; --check both "
                "uses the defaults (width x 2, radii x 0.75)");
        (request.walls ? request.widen_factor : request.radius_factor) = factor;
    }
    request.validate();
    return request;
}

LabRunOptions checkRunOptions(const LabRunOptions &options, const std::string &name) {
    LabRunOptions o = options;
    if (!o.output_directory.empty())
        o.output_directory = (fs::path(o.output_directory) / ("check_" + name)).string();
    return o;
}

std::vector<NumericalCheck>
runNumericalChecks(const CheckRequest &request, const Quantities &baseline,
                   const std::function<Quantities(CheckKind, double, const std::string &)> &rerun) {
    request.validate();
    std::vector<NumericalCheck> checks;
    std::vector<std::pair<CheckKind, double>> todo;
    if (request.walls)
        todo.emplace_back(CheckKind::Walls, request.widen_factor);
    if (request.resolution)
        todo.emplace_back(CheckKind::Resolution, request.radius_factor);
    for (const auto &[kind, factor] : todo) {
        const auto start = std::chrono::steady_clock::now();
        NumericalCheck check;
        check.kind = kind;
        check.factor = factor;
        check.change = kind == CheckKind::Walls
                           ? "box width x " + number(factor) + " in x and y, grains x " +
                                 number(factor * factor)
                           : "grain radii x " + number(factor) + ", grains x " +
                                 number(1.0 / (factor * factor * factor)) + ", time step x " +
                                 number(factor);
        std::fprintf(stderr, "[check %s] rerun: %s\n", checkName(kind).c_str(),
                     check.change.c_str());
        const Quantities again = rerun(kind, factor, checkName(kind));
        for (const CheckedQuantity &q : baseline) {
            const auto it = std::find_if(again.begin(), again.end(), [&](const CheckedQuantity &a) {
                return a.name == q.name;
            });
            if (it == again.end())
                throw std::runtime_error("numerical check " + checkName(kind) +
                                         ": the rerun has no '" + q.name + "'");
            check.comparisons.push_back({q.name, q.unit, q.value, it->value});
        }
        check.wall_s =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        checks.push_back(std::move(check));
    }
    return checks;
}

std::string describeNumericalChecks(const std::vector<NumericalCheck> &checks) {
    std::ostringstream out;
    out << "Numerical checks (baseline vs rerun; the differences are numerical uncertainty)\n";
    for (const NumericalCheck &c : checks) {
        out << "  " << checkName(c.kind) << ": " << c.change << " (rerun " << number(c.wall_s, 3)
            << " s wall)\n";
        std::size_t width = 8;
        for (const auto &q : c.comparisons)
            width = std::max(width, q.name.size() + q.unit.size() + 3);
        out << "    " << std::left << std::setw(int(width)) << "quantity" << std::right
            << std::setw(13) << "baseline" << std::setw(13) << "rerun" << std::setw(13)
            << "difference" << std::setw(11) << "relative" << '\n';
        for (const auto &q : c.comparisons) {
            const double rel = q.relativeDifference();
            out << "    " << std::left << std::setw(int(width)) << q.name + " [" + q.unit + "]"
                << std::right << std::setw(13) << number(q.baseline, 5) << std::setw(13)
                << number(q.rerun, 5) << std::setw(13) << number(q.difference(), 4) << std::setw(11)
                << (std::isfinite(rel) ? number(100.0 * rel, 3) + " %" : std::string("-")) << '\n';
        }
    }
    return out.str();
}

void writeNumericalChecks(const std::vector<NumericalCheck> &checks, const std::string &directory) {
    fs::create_directories(directory);
    std::ofstream csv(fs::path(directory) / "numerical_check.csv");
    csv << "check,factor,quantity,unit,baseline,rerun,difference,relative_difference\n"
        << std::setprecision(10);
    for (const NumericalCheck &c : checks)
        for (const auto &q : c.comparisons)
            csv << checkName(c.kind) << ',' << c.factor << ",\"" << q.name << "\"," << q.unit << ','
                << q.baseline << ',' << q.rerun << ',' << q.difference() << ','
                << q.relativeDifference() << '\n';
    std::ofstream(fs::path(directory) / "report.txt", std::ios::app)
        << describeNumericalChecks(checks);
}

// ---- the checks of the lab tests ------------------------------------------------------------

Quantities bevameterQuantities(const BevameterResult &result, double max_sinkage_m) {
    Quantities q;
    for (const PlateRun &p : result.runs) {
        const PressureSinkageCurve c = p.curve();
        for (double fraction : {0.25, 0.5, 0.75, 1.0}) {
            const double z = fraction * max_sinkage_m;
            q.push_back(
                {"p(" + config::millimetres(z) + "), R = " + config::millimetres(p.plate_radius_m),
                 "Pa", interpolate(c.sinkage_m, c.pressure_Pa, z)});
        }
    }
    if (result.fit) {
        q.push_back({"Bekker k_c", "N/m^(n+1)", result.fit->parameters.k_c});
        q.push_back({"Bekker k_phi", "N/m^(n+2)", result.fit->parameters.k_phi});
        q.push_back({"Bekker n", "-", result.fit->parameters.n});
    }
    return q;
}

std::vector<NumericalCheck> checkBevameter(const BevameterScenario &scenario,
                                           const BevameterResult &baseline,
                                           const CheckRequest &request,
                                           const LabRunOptions &options) {
    const double z_max = scenario.test.max_sinkage_m;
    return runNumericalChecks(request, bevameterQuantities(baseline, z_max),
                              [&](CheckKind kind, double factor, const std::string &name) {
                                  BevameterScenario changed = scenario;
                                  changed.soil = checkedSoil(scenario.soil, kind, factor);
                                  return bevameterQuantities(
                                      runBevameter(changed, checkRunOptions(options, name)), z_max);
                              });
}

Quantities reposeQuantities(const ReposeResult &result) {
    // The heap height is left out: the widened fill makes a larger heap by design.
    return {{"angle of repose", "deg", result.angle_deg}};
}

std::vector<NumericalCheck> checkRepose(const ReposeScenario &scenario,
                                        const ReposeResult &baseline, const CheckRequest &request,
                                        const LabRunOptions &options) {
    return runNumericalChecks(request, reposeQuantities(baseline),
                              [&](CheckKind kind, double factor, const std::string &name) {
                                  ReposeScenario changed = scenario;
                                  changed.soil = checkedSoil(scenario.soil, kind, factor);
                                  if (kind == CheckKind::Walls) // the tube holds the widened fill
                                      changed.test.tube_radius_m *= factor;
                                  return reposeQuantities(
                                      runRepose(changed, checkRunOptions(options, name)));
                              });
}

Quantities directShearQuantities(const DirectShearResult &result) {
    Quantities q;
    for (const auto &[label, fit] :
         {std::pair{"peak", &result.peak_fit}, std::pair{"residual", &result.residual_fit}}) {
        if (!*fit)
            continue;
        q.push_back(
            {std::string(label) + " friction angle psi", "deg", (*fit)->friction_angle_deg});
        if ((*fit)->cohesion_fitted)
            q.push_back({std::string(label) + " cohesion c", "Pa", (*fit)->cohesion_Pa});
    }
    q.push_back({"packing fraction", "-", result.bed.packing_fraction});
    return q;
}

std::vector<NumericalCheck> checkDirectShear(const DirectShearScenario &scenario,
                                             const DirectShearResult &baseline,
                                             const CheckRequest &request,
                                             const LabRunOptions &options) {
    return runNumericalChecks(
        request, directShearQuantities(baseline),
        [&](CheckKind kind, double factor, const std::string &name) {
            DirectShearScenario changed = scenario;
            if (kind == CheckKind::Walls) {
                // The box spans [0, L] x [0, W]: widen about its corner.
                changed.soil = widenedSoil(scenario.soil, factor, Eigen::Vector2d::Zero());
                auto &t = changed.test;
                t.length_m *= factor;
                t.width_m *= factor;
                t.servo.gain_m_s_per_N /= factor * factor;
                t.servo.deadband_N *= factor * factor;
            } else {
                changed.soil = refinedSoil(scenario.soil, factor);
            }
            return directShearQuantities(runDirectShear(changed, checkRunOptions(options, name)));
        });
}

} // namespace grainlink::lab
