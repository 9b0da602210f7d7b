#include "grainlink/lab/SoilTable.hpp"

#include "grainlink/lab/DirectShear.hpp"
#include "grainlink/lab/Repose.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>
#include <stdexcept>

namespace grainlink::lab {

namespace fs = std::filesystem;

namespace {

constexpr const char *kColumns =
    "friction_angle_deg,aspect_ratio_angle_deg,psi_deg,psi_half_width_95_deg,cohesion_Pa,"
    "cohesion_half_width_95_Pa,repose_deg,repose_half_width_95_deg,bulk_density_kg_m3,"
    "packing_fraction";

std::vector<double> ascendingAngles(const config::ConfigNode &node, double upper) {
    std::vector<double> v = node.numbers();
    if (v.empty())
        node.fail("give at least one angle");
    for (std::size_t i = 0; i < v.size(); ++i) {
        if (!(v[i] >= 0.0 && v[i] < upper))
            node.fail("every angle must be in [0, " + std::to_string(int(upper)) + ") deg");
        if (i > 0 && !(v[i] > v[i - 1]))
            node.fail("angles must be strictly ascending");
    }
    return v;
}

std::string relativeTo(const std::string &spec_file, const std::string &path) {
    if (path.empty() || fs::path(path).is_absolute())
        return path;
    return (fs::path(spec_file).parent_path() / path).lexically_normal().string();
}

/// Index i of the grid interval [axis[i], axis[i+1]] holding x (axis ascending, x inside).
std::size_t interval(const std::vector<double> &axis, double x) {
    if (axis.size() < 2)
        return 0;
    const auto it = std::upper_bound(axis.begin(), axis.end(), x);
    const auto i = std::size_t(std::max<std::ptrdiff_t>(0, it - axis.begin() - 1));
    return std::min(i, axis.size() - 2);
}

/// Smallest and largest finite entry (cells without a heap hold NaN).
std::pair<double, double> finiteRange(const Eigen::MatrixXd &q) {
    double lo = INFINITY, hi = -INFINITY;
    for (Eigen::Index k = 0; k < q.size(); ++k)
        if (std::isfinite(q.data()[k])) {
            lo = std::min(lo, q.data()[k]);
            hi = std::max(hi, q.data()[k]);
        }
    return {lo, hi};
}

std::string rangeText(const std::vector<double> &axis) {
    std::ostringstream out;
    out << "[" << axis.front() << ", " << axis.back() << "]";
    return out.str();
}

} // namespace

SoilTableSpec parseSoilTableSpec(const config::ConfigNode &root) {
    SoilTableSpec s;
    s.file = root.file();
    s.direct_shear_path = relativeTo(s.file, root["direct_shear"].text());
    if (root.has("repose"))
        s.repose_path = relativeTo(s.file, root["repose"].text());
    s.friction_angles_deg = ascendingAngles(root["friction_angles_deg"], 90.0);
    s.aspect_ratio_angles_deg = ascendingAngles(root["aspect_ratio_angles_deg"], 90.0);
    if (root.has("fit_cohesion"))
        s.fit_cohesion = root["fit_cohesion"].boolean();
    root.finish();
    return s;
}

SoilTableSpec loadSoilTableSpec(const std::string &path) {
    return parseSoilTableSpec(config::ConfigNode::loadFile(path));
}

dem::DemScenario soilWithGrainParameters(const dem::DemScenario &soil, double phi_deg,
                                         double gamma_deg) {
    dem::DemScenario s = soil;
    if (auto *linear = std::get_if<dem::TangentialLinear>(&s.law.tangential)) {
        linear->stick_angle_deg = phi_deg;
        linear->slip_angle_deg = phi_deg;
    } else if (auto *mindlin = std::get_if<dem::TangentialMindlin>(&s.law.tangential)) {
        mindlin->friction_coefficient = std::tan(phi_deg * M_PI / 180.0);
    }
    if (gamma_deg > 0.0) {
        dem::RollingGrainShape shape;
        if (const auto *old = std::get_if<dem::RollingGrainShape>(&soil.law.rolling))
            shape.inertia = old->inertia;
        shape.aspect_ratio_angle_deg = dem::Vec3::Constant(gamma_deg);
        s.law.rolling = shape;
    } else {
        s.law.rolling = dem::RollingNone{};
    }
    s.law.finalize();
    return s;
}

std::vector<SoilTableRow> generateSoilTable(const SoilTableSpec &spec,
                                            const SoilTableOptions &options) {
    auto shear = loadDirectShear(spec.direct_shear_path);
    if (spec.fit_cohesion)
        shear.test.fit_cohesion = *spec.fit_cohesion;
    std::optional<ReposeScenario> repose;
    if (!spec.repose_path.empty())
        repose = loadRepose(spec.repose_path);
    for (const config::KeyWarning &warning : shear.warnings) // old spellings, a box too narrow
        std::fprintf(stderr, "%s\n", warning.text().c_str());
    if (repose)
        for (const config::KeyWarning &warning : repose->warnings)
            std::fprintf(stderr, "%s\n", warning.text().c_str());
    const auto start = std::chrono::steady_clock::now();
    std::vector<SoilTableRow> rows;
    const fs::path out(options.output_csv);
    if (out.has_parent_path())
        fs::create_directories(out.parent_path());
    auto write = [&]() {
        std::ofstream csv(out);
        if (!csv)
            throw std::runtime_error("cannot write " + out.string());
        csv << "# grainlink soil table (docs/lab.md): direct shear " << spec.direct_shear_path
            << (spec.repose_path.empty() ? "" : ", repose " + spec.repose_path) << "\n";
        csv << "# phi: interparticle stick = slip angle; gamma: grain_shape aspect-ratio angle "
               "(0: no rolling resistance); psi: peak Mohr-Coulomb angle; half widths 95 %\n";
        if (!options.command_line.empty())
            csv << "# regenerate: " << options.command_line << "\n";
        csv << kColumns << "\n" << std::setprecision(8);
        for (const auto &r : rows)
            csv << r.phi_deg << ',' << r.gamma_deg << ',' << r.psi_deg << ','
                << r.psi_half_width_95_deg << ',' << r.cohesion_Pa << ','
                << r.cohesion_half_width_95_Pa << ',' << r.repose_deg << ','
                << r.repose_half_width_95_deg << ',' << r.bulk_density_kg_m3 << ','
                << r.packing_fraction << '\n';
    };
    const std::size_t total = spec.friction_angles_deg.size() * spec.aspect_ratio_angles_deg.size();
    for (double phi : spec.friction_angles_deg)
        for (double gamma : spec.aspect_ratio_angles_deg) {
            std::ostringstream tag;
            tag << "phi" << phi << "_gamma" << gamma;
            std::fprintf(stderr, "[soil-table] %zu/%zu: phi = %g deg, gamma = %g deg\n",
                         rows.size() + 1, total, phi, gamma);
            SoilTableRow row;
            row.phi_deg = phi;
            row.gamma_deg = gamma;
            DirectShearScenario s = shear;
            s.soil = soilWithGrainParameters(shear.soil, phi, gamma);
            LabRunOptions so;
            so.progress_interval_s = options.progress_interval_s;
            if (!options.runs_directory.empty())
                so.output_directory =
                    (fs::path(options.runs_directory) / ("direct_shear_" + tag.str())).string();
            const auto result = runDirectShear(s, so);
            if (!result.peak_fit)
                throw std::runtime_error("soil table at " + tag.str() +
                                         ": no Mohr-Coulomb fit: " + result.fit_note);
            row.psi_deg = result.peak_fit->friction_angle_deg;
            row.psi_half_width_95_deg = result.peak_fit->friction_angle_half_width_95_deg;
            row.cohesion_Pa = result.peak_fit->cohesion_Pa;
            row.cohesion_half_width_95_Pa = result.peak_fit->cohesion_half_width_95_Pa;
            row.bulk_density_kg_m3 = result.bed.bulk_density_kg_m3;
            row.packing_fraction = result.bed.packing_fraction;
            if (repose) {
                ReposeScenario r = *repose;
                r.soil = soilWithGrainParameters(repose->soil, phi, gamma);
                LabRunOptions ro;
                ro.progress_interval_s = options.progress_interval_s;
                if (!options.runs_directory.empty())
                    ro.output_directory =
                        (fs::path(options.runs_directory) / ("repose_" + tag.str())).string();
                const auto heap = runRepose(r, ro);
                row.repose_deg = heap.angle_deg;
                row.repose_half_width_95_deg = heap.angle_half_width_95_deg;
                if (!heap.heapFormed()) // grains that roll freely spread out
                    std::fprintf(stderr, "[soil-table] %s: no heap, no angle of repose (NaN)\n",
                                 tag.str().c_str());
            }
            rows.push_back(row);
            write();
            std::fprintf(
                stderr,
                "[soil-table] phi %g, gamma %g: psi %.2f +- %.2f deg, repose %.2f +- %.2f deg, "
                "packing %.3f (%.0f s so far)\n",
                phi, gamma, row.psi_deg, row.psi_half_width_95_deg, row.repose_deg,
                row.repose_half_width_95_deg, row.packing_fraction,
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        }
    return rows;
}

double SoilTable::at(const Eigen::MatrixXd &q, double phi, double gamma) const {
    // Bilinear interpolation on the (phi, gamma) grid, docs/physics.md §12.16.
    const std::size_t i = interval(phi_deg, phi), j = interval(gamma_deg, gamma);
    const std::size_t i1 = std::min(i + 1, phi_deg.size() - 1);
    const std::size_t j1 = std::min(j + 1, gamma_deg.size() - 1);
    const double u = i1 == i ? 0.0 : (phi - phi_deg[i]) / (phi_deg[i1] - phi_deg[i]);
    const double v = j1 == j ? 0.0 : (gamma - gamma_deg[j]) / (gamma_deg[j1] - gamma_deg[j]);
    const auto a = Eigen::Index(i), a1 = Eigen::Index(i1), b = Eigen::Index(j),
               b1 = Eigen::Index(j1);
    return (1 - u) * (1 - v) * q(a, b) + u * (1 - v) * q(a1, b) + (1 - u) * v * q(a, b1) +
           u * v * q(a1, b1);
}

SoilTable soilTableFromRows(const std::vector<SoilTableRow> &rows, const std::string &file) {
    SoilTable t;
    t.file = file;
    for (const auto &r : rows) {
        t.phi_deg.push_back(r.phi_deg);
        t.gamma_deg.push_back(r.gamma_deg);
    }
    for (auto *axis : {&t.phi_deg, &t.gamma_deg}) {
        std::sort(axis->begin(), axis->end());
        axis->erase(std::unique(axis->begin(), axis->end()), axis->end());
    }
    const auto n = Eigen::Index(t.phi_deg.size()), m = Eigen::Index(t.gamma_deg.size());
    if (n < 2)
        throw std::invalid_argument(file + ": the table needs at least two friction angles, has " +
                                    std::to_string(n));
    for (auto *q : {&t.psi, &t.psi_hw, &t.repose, &t.repose_hw, &t.bulk_density, &t.packing})
        q->setConstant(n, m, NAN);
    t.has_repose = false;
    for (const auto &r : rows) {
        const auto i = Eigen::Index(
            std::lower_bound(t.phi_deg.begin(), t.phi_deg.end(), r.phi_deg) - t.phi_deg.begin());
        const auto j =
            Eigen::Index(std::lower_bound(t.gamma_deg.begin(), t.gamma_deg.end(), r.gamma_deg) -
                         t.gamma_deg.begin());
        t.psi(i, j) = r.psi_deg;
        t.psi_hw(i, j) = r.psi_half_width_95_deg;
        t.repose(i, j) = r.repose_deg;
        t.repose_hw(i, j) = r.repose_half_width_95_deg;
        t.bulk_density(i, j) = r.bulk_density_kg_m3;
        t.packing(i, j) = r.packing_fraction;
        t.has_repose = t.has_repose || std::isfinite(r.repose_deg);
    }
    for (Eigen::Index i = 0; i < n; ++i)
        for (Eigen::Index j = 0; j < m; ++j)
            if (!std::isfinite(t.psi(i, j))) {
                std::ostringstream msg;
                msg << file << ": the grid has no row for phi = " << t.phi_deg[std::size_t(i)]
                    << " deg, gamma = " << t.gamma_deg[std::size_t(j)]
                    << " deg (every phi x gamma pair is needed)";
                throw std::invalid_argument(msg.str());
            }
    return t;
}

SoilTable readSoilTable(const std::string &path) {
    std::ifstream in(path);
    if (!in)
        throw std::invalid_argument("cannot read the soil table " + path);
    std::vector<SoilTableRow> rows;
    std::string line;
    bool header = false;
    int number = 0;
    while (std::getline(in, line)) {
        ++number;
        if (line.empty() || line[0] == '#')
            continue;
        if (!header) {
            if (line != kColumns)
                throw std::invalid_argument(path + ":" + std::to_string(number) +
                                            ": expected the header " + kColumns);
            header = true;
            continue;
        }
        std::vector<double> v;
        std::stringstream fields(line);
        std::string field;
        while (std::getline(fields, field, ',')) {
            try {
                v.push_back(field == "nan" || field == "-nan" ? NAN : std::stod(field));
            } catch (const std::exception &) {
                throw std::invalid_argument(path + ":" + std::to_string(number) + ": '" + field +
                                            "' is not a number");
            }
        }
        if (v.size() != 10)
            throw std::invalid_argument(path + ":" + std::to_string(number) +
                                        ": expected 10 "
                                        "fields, got " +
                                        std::to_string(v.size()));
        rows.push_back({v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8], v[9]});
    }
    if (!header)
        throw std::invalid_argument(path + ": no header line " + std::string(kColumns));
    return soilTableFromRows(rows, path);
}

SoilInversion invertSoilTable(const SoilTable &table, double target_psi,
                              std::optional<double> target_repose) {
    SoilInversion inv;
    inv.target_psi_deg = target_psi;
    inv.target_repose_deg = target_repose;
    const auto &phi = table.phi_deg;
    const auto &gamma = table.gamma_deg;
    if (target_psi < table.psi.minCoeff() || target_psi > table.psi.maxCoeff()) {
        std::ostringstream msg;
        msg << "friction angle " << target_psi << " deg is outside the soil table " << table.file
            << ": it covers psi from " << table.psi.minCoeff() << " to " << table.psi.maxCoeff()
            << " deg (phi " << rangeText(phi) << " deg, gamma " << rangeText(gamma)
            << " deg); extend the grid (grainlink soil-table) to reach it";
        throw std::invalid_argument(msg.str());
    }
    if (target_repose && !table.has_repose)
        throw std::invalid_argument("the soil table " + table.file +
                                    " has no repose column; give only the friction angle");
    const auto [repose_lo, repose_hi] = finiteRange(table.repose);
    if (target_repose && (*target_repose < repose_lo || *target_repose > repose_hi)) {
        std::ostringstream msg;
        msg << "angle of repose " << *target_repose << " deg is outside the soil table "
            << table.file << ": it covers " << repose_lo << " to " << repose_hi << " deg (phi "
            << rangeText(phi) << " deg, gamma " << rangeText(gamma) << " deg)";
        throw std::invalid_argument(msg.str());
    }

    // phi with psi(phi, gamma) = target at one gamma: psi is piecewise linear in phi there.
    auto solvePhi = [&](double g) -> std::optional<double> {
        for (std::size_t i = 0; i + 1 < phi.size(); ++i) {
            const double a = table.at(table.psi, phi[i], g) - target_psi;
            const double b = table.at(table.psi, phi[i + 1], g) - target_psi;
            if (a == 0.0)
                return phi[i];
            if ((a < 0.0) != (b < 0.0) || b == 0.0)
                return phi[i] + (phi[i + 1] - phi[i]) * a / (a - b);
        }
        return std::nullopt;
    };
    auto point = [&](double g) -> std::optional<SolutionPoint> {
        const auto f = solvePhi(g);
        if (!f)
            return std::nullopt;
        SolutionPoint p{*f, g, NAN};
        if (table.has_repose)
            p.repose_deg = table.at(table.repose, *f, g);
        return p;
    };
    // The curve of solutions, sampled over the gamma range.
    const int samples = gamma.size() > 1 ? 200 : 0;
    for (int k = 0; k <= samples; ++k) {
        const double g = samples == 0
                             ? gamma.front()
                             : gamma.front() + (gamma.back() - gamma.front()) * double(k) / samples;
        if (auto p = point(g))
            inv.curve.push_back(*p);
    }
    if (inv.curve.empty()) {
        std::ostringstream msg;
        msg << "friction angle " << target_psi << " deg is reached nowhere in the soil table "
            << table.file << " (phi " << rangeText(phi) << " deg, gamma " << rangeText(gamma)
            << " deg)";
        throw std::invalid_argument(msg.str());
    }

    if (target_repose) {
        // The point of the curve whose repose angle matches: a sign change of the mismatch
        // between neighbouring samples is bisected; else the smallest mismatch.
        auto mismatch = [&](const SolutionPoint &p) { return p.repose_deg - *target_repose; };
        // Cells without a heap (NaN: the grains spread out) give NaN points, never chosen.
        std::optional<std::size_t> best;
        for (std::size_t k = 0; k < inv.curve.size(); ++k)
            if (std::isfinite(mismatch(inv.curve[k])) &&
                (!best || std::abs(mismatch(inv.curve[k])) < std::abs(mismatch(inv.curve[*best]))))
                best = k;
        if (!best)
            throw std::invalid_argument("the soil table " + table.file +
                                        " has no angle of repose along the psi curve");
        inv.chosen = inv.curve[*best];
        for (std::size_t k = 0; k + 1 < inv.curve.size(); ++k) {
            SolutionPoint lo = inv.curve[k], hi = inv.curve[k + 1];
            if (!std::isfinite(mismatch(lo)) || !std::isfinite(mismatch(hi)) ||
                (mismatch(lo) < 0.0) == (mismatch(hi) < 0.0))
                continue;
            for (int it = 0; it < 60; ++it) {
                const auto mid = point(0.5 * (lo.gamma_deg + hi.gamma_deg));
                if (!mid)
                    break;
                ((mismatch(*mid) < 0.0) == (mismatch(lo) < 0.0) ? lo : hi) = *mid;
            }
            inv.chosen = std::abs(mismatch(lo)) < std::abs(mismatch(hi)) ? lo : hi;
            break;
        }
        inv.choice = "the point of the psi curve whose angle of repose matches the target";
    } else {
        // Default: the solution at the middle of the table's gamma range (or the nearest one).
        const double middle = 0.5 * (gamma.front() + gamma.back());
        const auto exact = point(middle);
        if (exact) {
            inv.chosen = *exact;
        } else {
            inv.chosen = *std::min_element(
                inv.curve.begin(), inv.curve.end(), [&](const auto &a, const auto &b) {
                    return std::abs(a.gamma_deg - middle) < std::abs(b.gamma_deg - middle);
                });
        }
        inv.choice = "only psi given: the point of the psi curve nearest the middle of the "
                     "table's gamma range";
    }
    const double f = inv.chosen.phi_deg, g = inv.chosen.gamma_deg;
    if (target_repose)
        inv.repose_mismatch_deg = inv.chosen.repose_deg - *target_repose;

    // Uncertainty of phi, docs/physics.md §12.16: the table's psi half width through the local
    // slope, and the interpolation error from the curvature of psi(phi) between grid nodes.
    const std::size_t i = interval(phi, f);
    const double slope = (table.at(table.psi, phi[i + 1], g) - table.at(table.psi, phi[i], g)) /
                         (phi[i + 1] - phi[i]);
    inv.psi_slope_deg_per_deg = slope;
    inv.psi_half_width_95_deg = table.at(table.psi_hw, f, g);
    inv.phi_from_measurement_deg = inv.psi_half_width_95_deg / std::abs(slope);
    if (phi.size() >= 3) {
        const std::size_t c = std::clamp<std::size_t>(
            std::size_t(std::lower_bound(phi.begin(), phi.end(), f) - phi.begin()), 1,
            phi.size() - 2);
        const double h0 = phi[c] - phi[c - 1], h1 = phi[c + 1] - phi[c];
        const double p0 = table.at(table.psi, phi[c - 1], g), p1 = table.at(table.psi, phi[c], g),
                     p2 = table.at(table.psi, phi[c + 1], g);
        const double second = 2.0 * ((p2 - p1) / h1 - (p1 - p0) / h0) / (h0 + h1);
        const double h = phi[i + 1] - phi[i];
        // Linear interpolation error bound |psi''| h^2 / 8.
        inv.phi_from_resolution_deg = std::abs(second) * h * h / 8.0 / std::abs(slope);
    }
    const double res = inv.phi_from_resolution_deg.value_or(0.0);
    inv.phi_uncertainty_deg = std::hypot(inv.phi_from_measurement_deg, res);
    inv.packing_fraction = table.at(table.packing, f, g);
    inv.bulk_density_kg_m3 = table.at(table.bulk_density, f, g);
    return inv;
}

std::string SoilInversion::describe() const {
    std::ostringstream out;
    out << std::setprecision(4);
    out << "Target: psi = " << target_psi_deg << " deg";
    if (target_repose_deg)
        out << ", angle of repose " << *target_repose_deg << " deg";
    out << "\nSolutions psi(phi, gamma) = target (bilinear in the table), " << curve.size()
        << " samples:\n";
    const std::size_t stride = std::max<std::size_t>(1, curve.size() / 10);
    for (std::size_t k = 0; k < curve.size(); k += stride) {
        out << "  gamma " << std::setw(7) << curve[k].gamma_deg << " deg -> phi " << std::setw(7)
            << curve[k].phi_deg << " deg";
        if (std::isfinite(curve[k].repose_deg))
            out << ", repose " << curve[k].repose_deg << " deg";
        out << "\n";
    }
    out << "Proposed (" << choice << "):\n";
    out << "  phi = " << chosen.phi_deg << " +- " << phi_uncertainty_deg
        << " deg (interparticle friction), gamma = " << chosen.gamma_deg
        << " deg (grain_shape aspect-ratio angle)\n";
    out << "  uncertainty of phi: psi half width " << psi_half_width_95_deg << " deg / |dpsi/dphi| "
        << std::abs(psi_slope_deg_per_deg) << " = " << phi_from_measurement_deg << " deg";
    if (phi_from_resolution_deg)
        out << "; table resolution (|psi''| dphi^2 / 8 / |dpsi/dphi|) " << *phi_from_resolution_deg
            << " deg";
    else
        out << "; table resolution not estimable (two phi nodes)";
    out << "; together " << phi_uncertainty_deg << " deg\n";
    if (target_repose_deg)
        out << "  repose at the point " << chosen.repose_deg << " deg (" << std::showpos
            << repose_mismatch_deg << std::noshowpos << " deg from the target)\n";
    out << "  settled bed at the point: packing fraction " << packing_fraction << ", bulk density "
        << bulk_density_kg_m3
        << " kg/m^3 (for a soil of known bulk density: grain density = bulk density / "
        << packing_fraction << ")\n";
    return out.str();
}

std::string SoilInversion::contactBlock() const {
    std::ostringstream out;
    out << std::setprecision(4);
    out << "  contact:\n";
    out << "    # keep stiffness_N_m and damping_N_s_m from grainlink params SOIL.yaml\n";
    out << "    tangential: {model: linear, stick_angle_deg: " << chosen.phi_deg
        << ", slip_angle_deg: " << chosen.phi_deg << "}\n";
    if (chosen.gamma_deg > 0.0)
        out << "    rolling: {model: grain_shape, aspect_ratio_angle_deg: " << chosen.gamma_deg
            << "}\n";
    else
        out << "    rolling: {model: none}\n";
    return out.str();
}

} // namespace grainlink::lab
