#include "grainlink/lab/ParameterEstimation.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace grainlink::lab {

namespace {

/// Throws naming the quantity if v is outside (lo, hi) (or [lo, hi] where `closed`).
void requireRange(const std::string &what, double v, double lo, double hi, bool lo_closed,
                  bool hi_closed) {
    const bool ok =
        std::isfinite(v) && (lo_closed ? v >= lo : v > lo) && (hi_closed ? v <= hi : v < hi);
    if (!ok) {
        std::ostringstream msg;
        msg << what << " = " << v << " must be in " << (lo_closed ? "[" : "(") << lo << ", " << hi
            << (hi_closed ? "]" : ")");
        throw std::invalid_argument(msg.str());
    }
}

/// Reads a number and checks its range, failing with the key and line.
double rangedNumber(const config::ConfigNode &node, double lo, double hi, bool lo_closed,
                    bool hi_closed) {
    const double v = node.number();
    try {
        requireRange("value", v, lo, hi, lo_closed, hi_closed);
    } catch (const std::invalid_argument &e) {
        node.fail(e.what());
    }
    return v;
}

double rangedOptional(const config::ConfigNode &parent, const std::string &key, double fallback,
                      double lo, double hi, bool lo_closed, bool hi_closed) {
    if (!parent.has(key))
        return fallback;
    return rangedNumber(parent[key], lo, hi, lo_closed, hi_closed);
}

constexpr double kInf = std::numeric_limits<double>::infinity();

/// Overlap ratio delta / r at which two equal Hertz grains carry force F (inverse of eq. 3).
double overlapRatioEqualGrains(double youngs_modulus_Pa, double poisson_ratio, double radius_m,
                               double force_N) {
    // F = (sqrt(2) / 3) E / (1 - nu^2) r^2 a^(3/2)
    const double c = std::sqrt(2.0) / 3.0 * youngs_modulus_Pa /
                     (1.0 - poisson_ratio * poisson_ratio) * radius_m * radius_m;
    return std::pow(force_N / c, 2.0 / 3.0);
}

} // namespace

void SoilTestDescription::validate() const {
    requireRange("grain_density_kg_m3", grain_density_kg_m3, 0.0, kInf, false, false);
    requireRange("poisson_ratio", poisson_ratio, -1.0, 0.5, false, false);
    requireRange("stick_angle_deg", stick_angle_deg, 0.0, 90.0, true, false);
    requireRange("slip_angle_deg", slip_angle_deg, 0.0, stick_angle_deg, true, true);
    for (int i = 0; i < 3; ++i)
        requireRange("aspect_ratios[" + std::to_string(i) + "]", aspect_ratios[i], 0.0, kInf, false,
                     false);
    requireRange("expected_pressure_Pa", expected_pressure_Pa, 0.0, kInf, true, false);
    requireRange("tool_size_m", tool_size_m, 0.0, kInf, false, false);
    requireRange("plate_radius_m", plate_radius_m, 0.0, kInf, false, false);
    requireRange("bed_height_m", bed_height_m, 0.0, kInf, false, false);
    requireRange("expected_sinkage_m", expected_sinkage_m, 0.0, bed_height_m, true, false);
    requireRange("gravity_m_s2", gravity_m_s2, 0.0, kInf, true, false);
    requireRange("resolution", resolution, 0.0, kInf, false, false);
    requireRange("max_overlap_ratio", max_overlap_ratio, 0.0, 1.0, false, false);
    requireRange("damping_fraction", damping_fraction, 0.0, 1.0, true, true);
    requireRange("tangential_stiffness_ratio", tangential_stiffness_ratio, 0.0, kInf, false, false);
    requireRange("radius_ratio_min_max", radius_ratio_min_max, 0.0, 1.0, false, true);
    requireRange("time_step_safety_factor", time_step_safety_factor, 0.0, 1.0, false, true);
    if (youngs_modulus_Pa)
        requireRange("youngs_modulus_Pa", *youngs_modulus_Pa, 0.0, kInf, false, false);
    if (expected_pressure_Pa == 0.0 && gravity_m_s2 == 0.0)
        throw std::invalid_argument("expected_pressure_Pa and gravity_m_s2 are both 0: nothing "
                                    "loads the contacts, eq. 10 gives no stiffness");
}

SoilTestDescription parseSoilTestDescription(const config::ConfigNode &root) {
    SoilTestDescription d;
    const auto soil = root["soil"];
    d.name = soil.text("name", d.name);
    d.grain_density_kg_m3 = rangedNumber(soil["grain_density_kg_m3"], 0.0, kInf, false, false);
    d.poisson_ratio = rangedNumber(soil["poisson_ratio"], -1.0, 0.5, false, false);
    d.stick_angle_deg = rangedNumber(soil["stick_angle_deg"], 0.0, 90.0, true, false);
    d.slip_angle_deg = rangedOptional(soil, "slip_angle_deg", d.stick_angle_deg, 0.0,
                                      d.stick_angle_deg, true, true);
    if (auto a = soil.optional("aspect_ratios")) {
        d.aspect_ratios = a->vec3();
        if ((d.aspect_ratios.array() <= 0.0).any())
            a->fail("every aspect ratio A_i must be > 0");
    }
    soil.finish();

    const auto test = root["test"];
    d.expected_pressure_Pa = rangedNumber(test["expected_pressure_Pa"], 0.0, kInf, true, false);
    d.tool_size_m = rangedNumber(test["tool_size_m"], 0.0, kInf, false, false);
    d.plate_radius_m =
        rangedOptional(test, "plate_radius_m", 0.5 * d.tool_size_m, 0.0, kInf, false, false);
    d.bed_height_m = rangedNumber(test["bed_height_m"], 0.0, kInf, false, false);
    d.expected_sinkage_m =
        rangedNumber(test["expected_sinkage_m"], 0.0, d.bed_height_m, true, false);
    d.gravity_m_s2 = rangedOptional(test, "gravity_m_s2", d.gravity_m_s2, 0.0, kInf, true, false);
    test.finish();

    const auto model = root["model"];
    d.resolution = rangedNumber(model["resolution"], 0.0, kInf, false, false);
    d.max_overlap_ratio = rangedNumber(model["max_overlap_ratio"], 0.0, 1.0, false, false);
    d.damping_fraction = rangedNumber(model["damping_fraction"], 0.0, 1.0, true, true);
    d.tangential_stiffness_ratio = rangedOptional(
        model, "tangential_stiffness_ratio", d.tangential_stiffness_ratio, 0.0, kInf, false, false);
    d.radius_ratio_min_max = rangedOptional(model, "radius_ratio_min_max", d.radius_ratio_min_max,
                                            0.0, 1.0, false, true);
    d.time_step_safety_factor = rangedOptional(model, "time_step_safety_factor",
                                               d.time_step_safety_factor, 0.0, 1.0, false, true);
    if (model.has("youngs_modulus_Pa"))
        d.youngs_modulus_Pa = rangedNumber(model["youngs_modulus_Pa"], 0.0, kInf, false, false);
    model.finish();
    root.finish();
    try {
        d.validate();
    } catch (const std::invalid_argument &e) {
        root.fail(e.what());
    }
    return d;
}

SoilTestDescription loadSoilTestDescription(const std::string &path) {
    return parseSoilTestDescription(config::ConfigNode::loadFile(path));
}

double worstContactForce(const SoilTestDescription &d, double radius_m) {
    // Reading of seed eq. 10, docs/physics.md §12.2: plate share plus the cubic column's weight.
    const double z_h = d.bed_height_m - d.expected_sinkage_m;
    return 2.0 * M_PI / 3.0 * radius_m * radius_m *
           (d.expected_pressure_Pa * d.plate_radius_m / radius_m +
            z_h * d.grain_density_kg_m3 * d.gravity_m_s2);
}

double hertzForceEqualGrains(double youngs_modulus_Pa, double poisson_ratio, double radius_m,
                             double overlap_ratio) {
    // Seed eq. 3 with E* = E / (2 (1 - nu^2)), R* = r / 2, delta = a r (docs/physics.md §2.1).
    const double e_star = youngs_modulus_Pa / (2.0 * (1.0 - poisson_ratio * poisson_ratio));
    const double delta = overlap_ratio * radius_m;
    return 4.0 / 3.0 * e_star * std::sqrt(0.5 * radius_m) * std::pow(delta, 1.5);
}

double rayleighTime(double youngs_modulus_Pa, double poisson_ratio, double density_kg_m3,
                    double radius_m) {
    // docs/physics.md §3.3, the same estimate DemSystem::stableTimeStepEstimate uses.
    const double shear = youngs_modulus_Pa / (2.0 * (1.0 + poisson_ratio));
    return M_PI * radius_m * std::sqrt(density_kg_m3 / shear) / (0.1631 * poisson_ratio + 0.8766);
}

ParameterMatrix estimateParameters(const SoilTestDescription &d) {
    d.validate();
    ParameterMatrix m;
    m.input = d;
    const double nu = d.poisson_ratio, rho = d.grain_density_kg_m3, a = d.max_overlap_ratio;

    // Resolution, seed eq. 11: Gamma = L_min / (2 r_max).
    m.radius_max_m = d.tool_size_m / (2.0 * d.resolution);
    m.radius_min_m = d.radius_ratio_min_max * m.radius_max_m;
    const double r = m.radius_min_m; // F_max / r^2 is largest for the smallest grains

    // Minimum stiffness, seed eq. 10 as read in docs/physics.md §12.2.
    m.column_height_m = d.bed_height_m - d.expected_sinkage_m;
    m.plate_force_share_N = 2.0 * M_PI / 3.0 * d.expected_pressure_Pa * d.plate_radius_m * r;
    m.column_weight_N = 2.0 * M_PI / 3.0 * r * r * m.column_height_m * rho * d.gravity_m_s2;
    m.worst_contact_force_N = worstContactForce(d, r);
    m.normal_stiffness_N_m = m.worst_contact_force_N / (a * r);
    // Equivalent linear stiffness: Hertz reaches F_max at delta = a r (secant stiffness c_n).
    m.minimum_youngs_modulus_Pa = m.worst_contact_force_N / hertzForceEqualGrains(1.0, nu, r, a);
    m.youngs_modulus_Pa = d.youngs_modulus_Pa.value_or(m.minimum_youngs_modulus_Pa);
    m.overlap_ratio_at_worst_force =
        overlapRatioEqualGrains(m.youngs_modulus_Pa, nu, r, m.worst_contact_force_N);
    m.tangential_stiffness_N_m = d.tangential_stiffness_ratio * m.normal_stiffness_N_m;

    // Damping: a fraction of the critical damping of the stiffest pair, two smallest grains
    // under F_max: Hertz tangent stiffness dF/d(delta) = 3/2 F / delta.
    const double mass_min = 4.0 / 3.0 * M_PI * rho * r * r * r;
    m.stiffest_pair_mass_kg = 0.5 * mass_min;
    m.stiffest_pair_stiffness_N_m =
        1.5 * m.worst_contact_force_N / (m.overlap_ratio_at_worst_force * r);
    m.critical_damping_N_s_m =
        2.0 * std::sqrt(m.stiffest_pair_stiffness_N_m * m.stiffest_pair_mass_kg);
    m.normal_damping_N_s_m = d.damping_fraction * m.critical_damping_N_s_m;
    m.tangential_damping_N_s_m =
        d.damping_fraction * 2.0 * std::sqrt(m.tangential_stiffness_N_m * m.stiffest_pair_mass_kg);

    // Inertia, seed eq. 12, of the largest grain.
    const double R = m.radius_max_m;
    m.grain_mass_max_kg = 4.0 / 3.0 * M_PI * rho * R * R * R;
    for (int i = 0; i < 3; ++i)
        m.inertia_kg_m2[i] = M_PI * rho * R * R * R * std::pow(R / d.aspect_ratios[i], 2) / 9.0;
    m.solid_sphere_inertia_kg_m2 = 8.0 / 15.0 * M_PI * rho * std::pow(R, 5);

    // Time step (docs/physics.md §3.3 and §12.5).
    m.rayleigh_time_s = rayleighTime(m.youngs_modulus_Pa, nu, rho, r);
    const double omega = std::sqrt(m.stiffest_pair_stiffness_N_m / m.stiffest_pair_mass_kg);
    const double zeta = d.damping_fraction;
    m.oscillator_limit_s = 2.0 * (std::sqrt(1.0 + zeta * zeta) - zeta) / omega;
    m.dashpot_limit_s = m.normal_damping_N_s_m > 0.0 ? mass_min / m.normal_damping_N_s_m : kInf;
    m.grainlink_limit_s = std::min(0.5 * m.rayleigh_time_s, m.dashpot_limit_s);
    m.stable_time_step_s = std::min(m.grainlink_limit_s, m.oscillator_limit_s);
    m.recommended_time_step_s = d.time_step_safety_factor * m.stable_time_step_s;
    return m;
}

std::vector<DerivedValue> ParameterMatrix::values() const {
    const auto &d = input;
    const std::string e_source = d.youngs_modulus_Pa ? "input" : "eq. 3 secant = eq. 10";
    std::vector<DerivedValue> v = {
        // inputs that are entries of Lambda_P
        {"poisson_ratio", "normal", d.poisson_ratio, "input (material)"},
        {"grain_density_kg_m3", "normal", d.grain_density_kg_m3, "input (material)"},
        {"stick_angle_deg", "tangential", d.stick_angle_deg, "input (phi_h, eq. 5)"},
        {"slip_angle_deg", "tangential", d.slip_angle_deg, "input (phi_g, eq. 5)"},
        {"aspect_ratio_x", "rotational", d.aspect_ratios.x(), "input (A_1, eq. 6)"},
        {"aspect_ratio_y", "rotational", d.aspect_ratios.y(), "input (A_2, eq. 6)"},
        {"aspect_ratio_z", "rotational", d.aspect_ratios.z(), "input (A_3, eq. 6)"},
        {"aspect_ratio_angle_x_deg", "rotational", std::atan(d.aspect_ratios.x()) * 180.0 / M_PI,
         "eq. 7: gamma = atan(A)"},
        {"aspect_ratio_angle_y_deg", "rotational", std::atan(d.aspect_ratios.y()) * 180.0 / M_PI,
         "eq. 7: gamma = atan(A)"},
        {"aspect_ratio_angle_z_deg", "rotational", std::atan(d.aspect_ratios.z()) * 180.0 / M_PI,
         "eq. 7: gamma = atan(A)"},
        // geometry
        {"particle_radius_max_m", "normal", radius_max_m, "eq. 11: L_min / (2 Gamma)"},
        {"particle_radius_min_m", "normal", radius_min_m, "radius_ratio_min_max * r_max"},
        // stiffness
        {"column_height_m", "-", column_height_m, "eq. 10: z_h = bed height - sinkage"},
        {"plate_force_share_N", "-", plate_force_share_N, "eq. 10: (2 pi/3) p R r_min"},
        {"column_weight_N", "-", column_weight_N, "eq. 10: (2 pi/3) r_min^2 z_h rho g"},
        {"worst_contact_force_N", "-", worst_contact_force_N, "eq. 10: F_max, the sum"},
        {"normal_stiffness_min_N_m", "normal", normal_stiffness_N_m,
         "eq. 10: c_n = F_max / (a_max r_min)"},
        {"youngs_modulus_min_Pa", "normal", minimum_youngs_modulus_Pa,
         "eq. 3 secant stiffness at a_max = c_n"},
        {"youngs_modulus_Pa", "normal", youngs_modulus_Pa, e_source},
        {"overlap_ratio_at_worst_force", "-", overlap_ratio_at_worst_force,
         "eq. 3 inverted at F_max"},
        {"tangential_stiffness_N_m", "tangential", tangential_stiffness_N_m,
         "sec. 2.3: c_T = ratio * c_n"},
        // damping
        {"stiffest_pair_stiffness_N_m", "-", stiffest_pair_stiffness_N_m,
         "eq. 3 tangent: 3 F_max / (2 delta), two r_min grains"},
        {"stiffest_pair_mass_kg", "-", stiffest_pair_mass_kg, "m* = m_min / 2"},
        {"critical_damping_N_s_m", "-", critical_damping_N_s_m, "2 sqrt(k m*)"},
        {"normal_damping_N_s_m", "normal", normal_damping_N_s_m,
         "eq. 4: k_N = fraction * critical"},
        {"tangential_damping_N_s_m", "tangential", tangential_damping_N_s_m,
         "k_T = fraction * 2 sqrt(c_T m*)"},
        // inertia
        {"grain_mass_max_kg", "-", grain_mass_max_kg, "(4/3) pi rho r_max^3"},
        {"inertia_x_kg_m2", "rotational", inertia_kg_m2.x(), "eq. 12: (1/9) pi rho r^3 (r/A_1)^2"},
        {"inertia_y_kg_m2", "rotational", inertia_kg_m2.y(), "eq. 12: (1/9) pi rho r^3 (r/A_2)^2"},
        {"inertia_z_kg_m2", "rotational", inertia_kg_m2.z(), "eq. 12: (1/9) pi rho r^3 (r/A_3)^2"},
        {"solid_sphere_inertia_kg_m2", "-", solid_sphere_inertia_kg_m2,
         "(8/15) pi rho r_max^5, for comparison"},
        // time step
        {"rayleigh_time_s", "-", rayleigh_time_s, "physics.md 3.3: T_R of r_min"},
        {"oscillator_limit_s", "-", oscillator_limit_s,
         "2 (sqrt(1 + zeta^2) - zeta) / omega, stiffest pair"},
        {"dashpot_limit_s", "-", dashpot_limit_s, "m_min / k_N (physics.md 3.3)"},
        {"grainlink_limit_s", "-", grainlink_limit_s,
         "min(T_R / 2, m_min / k_N): dem refuses above"},
        {"stable_time_step_s", "-", stable_time_step_s, "min of the limits"},
        {"time_step_safety_factor", "-", d.time_step_safety_factor, "input"},
        {"time_step_s", "-", recommended_time_step_s, "safety factor * stable"},
    };
    return v;
}

namespace {
std::string sixFigures(double v) {
    std::ostringstream out;
    out << std::setprecision(6) << v;
    return out.str();
}
} // namespace

std::string formatTable(const ParameterMatrix &m) {
    std::ostringstream out;
    out << "Parameter matrix Lambda_P (seed eq. 9) for '" << m.input.name << "'\n";
    out << "  rows: normal [E, nu | k_N | r | 0 | rho], tangential [c_T | k_T | 0 | phi | 0], "
           "rotational [0 | 0 | r | gamma | J]\n\n";
    for (const auto &v : m.values())
        out << "  " << std::left << std::setw(30) << v.key << std::right << std::setw(14)
            << sixFigures(v.value) << "  " << std::left << std::setw(11) << v.row << v.source
            << "\n";
    if (m.input.youngs_modulus_Pa && *m.input.youngs_modulus_Pa < m.minimum_youngs_modulus_Pa)
        out << "\n  warning: the given E is below eq. 10's minimum: the worst-case overlap is "
            << sixFigures(m.overlap_ratio_at_worst_force) << " r, above max_overlap_ratio "
            << sixFigures(m.input.max_overlap_ratio) << "\n";
    return out.str();
}

std::string formatYaml(const ParameterMatrix &m) {
    std::ostringstream out;
    out << "# grainlink params: parameter matrix Lambda_P (seed eq. 9) for '" << m.input.name
        << "'\n";
    for (const auto &v : m.values())
        out << v.key << ": " << std::setprecision(10) << v.value << "  # " << v.row << "; "
            << v.source << "\n";
    return out.str();
}

std::string formatCsv(const ParameterMatrix &m) {
    std::ostringstream out;
    out << "key,row,value,source\n";
    for (const auto &v : m.values())
        out << v.key << ',' << v.row << ',' << std::setprecision(10) << v.value << ",\"" << v.source
            << "\"\n";
    return out.str();
}

std::string soilBlock(const ParameterMatrix &m) {
    const auto &d = m.input;
    std::ostringstream out;
    out << std::setprecision(6);
    out << "# from grainlink params (" << d.name << "): grains of radius "
        << sixFigures(m.radius_min_m) << " .. " << sixFigures(m.radius_max_m) << " m (eq. 11)\n";
    out << "soil:\n";
    out << "  simulation:\n";
    out << "    time_step_s: " << m.recommended_time_step_s << "\n";
    out << "  material:\n";
    out << "    name: " << d.name << "\n";
    out << "    youngs_modulus_Pa: " << m.youngs_modulus_Pa << "\n";
    out << "    poisson_ratio: " << d.poisson_ratio << "\n";
    out << "    density_kg_m3: " << d.grain_density_kg_m3 << "\n";
    out << "  contact:\n";
    out << "    damping: {model: viscous, coefficient_N_s_m: " << m.normal_damping_N_s_m << "}\n";
    out << "    tangential: {model: linear, stiffness_N_m: " << m.tangential_stiffness_N_m
        << ", damping_N_s_m: " << m.tangential_damping_N_s_m
        << ", stick_angle_deg: " << d.stick_angle_deg << ", slip_angle_deg: " << d.slip_angle_deg
        << "}\n";
    return out.str();
}

} // namespace grainlink::lab
