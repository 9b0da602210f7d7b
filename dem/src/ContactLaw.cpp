#include "grainlink/dem/ContactLaw.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace grainlink::dem {

namespace {
[[noreturn]] void badParameter(const std::string &model, const std::string &parameter, double value,
                               const std::string &rule) {
    std::ostringstream msg;
    msg << "contact model '" << model << "': parameter '" << parameter << "' = " << value
        << " is invalid (" << rule << ")";
    throw std::invalid_argument(msg.str());
}
double tanDeg(double degrees) {
    return std::tan(degrees * M_PI / 180.0);
}
} // namespace

void Material::validate() const {
    if (!(youngs_modulus_Pa > 0.0))
        badParameter("material " + name, "youngs_modulus_Pa", youngs_modulus_Pa, "must be > 0");
    if (!(poisson_ratio > -1.0 && poisson_ratio < 0.5))
        badParameter("material " + name, "poisson_ratio", poisson_ratio, "must be in (-1, 0.5)");
    if (density_kg_m3 < 0.0)
        badParameter("material " + name, "density_kg_m3", density_kg_m3, "must be >= 0");
}

void DampingViscous::validate() const {
    if (!(coefficient_N_s_m >= 0.0))
        badParameter("damping viscous", "coefficient_N_s_m", coefficient_N_s_m, "must be >= 0");
}

void DampingRestitution::validate() const {
    if (!(restitution > 0.0 && restitution <= 1.0))
        badParameter("damping restitution", "restitution", restitution, "must be in (0, 1]");
}

void DampingRestitution::derive() {
    const double log_e = std::log(restitution);
    beta = log_e / std::sqrt(log_e * log_e + M_PI * M_PI);
}

void TangentialLinear::validate() const {
    if (!(stiffness_N_m > 0.0))
        badParameter("tangential linear", "stiffness_N_m", stiffness_N_m, "must be > 0");
    if (!(damping_N_s_m >= 0.0))
        badParameter("tangential linear", "damping_N_s_m", damping_N_s_m, "must be >= 0");
    if (!(stick_angle_deg >= 0.0 && stick_angle_deg < 90.0))
        badParameter("tangential linear", "stick_angle_deg", stick_angle_deg, "must be in [0, 90)");
    if (!(slip_angle_deg >= 0.0 && slip_angle_deg <= stick_angle_deg))
        badParameter("tangential linear", "slip_angle_deg", slip_angle_deg,
                     "must be in [0, stick_angle_deg]");
}

void TangentialMindlin::validate() const {
    if (!(friction_coefficient >= 0.0))
        badParameter("tangential mindlin", "friction_coefficient", friction_coefficient,
                     "must be >= 0");
}

void RollingEpsd::validate() const {
    if (!(coefficient >= 0.0))
        badParameter("rolling epsd", "coefficient", coefficient, "must be >= 0");
}

void RollingGrainShape::validate() const {
    static const char *const names[3] = {"aspect_ratio_angle_deg[0]", "aspect_ratio_angle_deg[1]",
                                         "aspect_ratio_angle_deg[2]"};
    for (int k = 0; k < 3; ++k)
        if (!(aspect_ratio_angle_deg[k] > 0.0 && aspect_ratio_angle_deg[k] < 90.0))
            badParameter("rolling grain_shape", names[k], aspect_ratio_angle_deg[k],
                         "must be in (0, 90): gamma = arctan(A), seed eq. 7");
}

void RollingGrainShape::derive() {
    for (int k = 0; k < 3; ++k) {
        gamma_rad[k] = aspect_ratio_angle_deg[k] * M_PI / 180.0;
        tan_gamma[k] = std::tan(gamma_rad[k]);
        elastic_slope[k] = 0.5 * tan_gamma[k] * tan_gamma[k];
    }
}

Vec3 grainShapeInertia(const RollingGrainShape &model, double radius_m, double density_kg_m3) {
    // Seed eq. 12: J_k = (1/9) pi rho r^3 (r / A_k)^2, A_k = tan(gamma_k).
    Vec3 inertia;
    for (int k = 0; k < 3; ++k) {
        const double aspect = std::tan(model.aspect_ratio_angle_deg[k] * M_PI / 180.0);
        const double length = radius_m / aspect;
        inertia[k] = M_PI / 9.0 * density_kg_m3 * radius_m * radius_m * radius_m * length * length;
    }
    return inertia;
}

void CohesionLinear::validate() const {
    if (!(energy_density_J_m3 >= 0.0))
        badParameter("cohesion linear", "energy_density_J_m3", energy_density_J_m3, "must be >= 0");
}

void ContactLaw::finalize() {
    auto check = [](const auto &slot) { std::visit([](const auto &m) { m.validate(); }, slot); };
    check(normal);
    check(damping);
    check(tangential);
    check(rolling);
    check(cohesion);
    if (!(background_damping_1_s >= 0.0))
        badParameter("background damping", "background_damping_1_s", background_damping_1_s,
                     "must be >= 0");
    double beta = 0.0;
    if (auto *restitution = std::get_if<DampingRestitution>(&damping)) {
        restitution->derive();
        beta = restitution->beta;
    }
    if (auto *shape = std::get_if<RollingGrainShape>(&rolling))
        shape->derive();
    // Cross-slot rule: Mindlin's tangential dashpot takes the normal restitution (LIGGGHTS).
    if (auto *mindlin = std::get_if<TangentialMindlin>(&tangential))
        mindlin->beta = beta;
}

std::string ContactLaw::describe() const {
    std::ostringstream out;
    out << "normal=hertz";
    std::visit(
        [&](const auto &d) {
            using D = std::decay_t<decltype(d)>;
            if constexpr (std::is_same_v<D, DampingViscous>)
                out << " damping=viscous(k_n=" << d.coefficient_N_s_m << " N s/m)";
            else
                out << " damping=restitution(e=" << d.restitution << ")";
        },
        damping);
    std::visit(
        [&](const auto &t) {
            using T = std::decay_t<decltype(t)>;
            if constexpr (std::is_same_v<T, TangentialLinear>)
                out << " tangential=linear(c_T=" << t.stiffness_N_m
                    << " N/m, phi_h=" << t.stick_angle_deg << " deg, phi_g=" << t.slip_angle_deg
                    << " deg)";
            else
                out << " tangential=mindlin(mu=" << t.friction_coefficient << ")";
        },
        tangential);
    if (auto *r = std::get_if<RollingEpsd>(&rolling))
        out << " rolling=epsd(mu_r=" << r->coefficient << ")";
    if (auto *r = std::get_if<RollingGrainShape>(&rolling))
        out << " rolling=grain_shape(gamma=" << r->aspect_ratio_angle_deg.x() << ","
            << r->aspect_ratio_angle_deg.y() << "," << r->aspect_ratio_angle_deg.z()
            << " deg, inertia="
            << (r->inertia == RollingGrainShape::Inertia::SeedEq12 ? "seed_eq12" : "sphere") << ")";
    if (auto *c = std::get_if<CohesionLinear>(&cohesion))
        out << " cohesion=linear(k_c=" << c->energy_density_J_m3 << " J/m^3)";
    if (background_damping_1_s > 0.0)
        out << " background_damping=" << background_damping_1_s << " 1/s";
    return out.str();
}

std::string modelName(const DampingModel &slot) {
    return std::holds_alternative<DampingViscous>(slot) ? "viscous" : "restitution";
}
std::string modelName(const TangentialModel &slot) {
    return std::holds_alternative<TangentialLinear>(slot) ? "linear" : "mindlin";
}
std::string modelName(const RollingModel &slot) {
    return std::holds_alternative<RollingEpsd>(slot)         ? "epsd"
           : std::holds_alternative<RollingGrainShape>(slot) ? "grain_shape"
                                                             : "none";
}
std::string modelName(const CohesionModel &slot) {
    return std::holds_alternative<CohesionLinear>(slot) ? "linear" : "none";
}

const ContactLaw &ContactLaws::of(ContactType type) const {
    return type == ContactType::GrainGrain  ? grain_grain
           : type == ContactType::GrainWall ? grain_wall
                                            : grain_tool;
}

void ContactLaws::finalize() {
    grain_grain.finalize();
    for (ContactType type : {ContactType::GrainWall, ContactType::GrainTool}) {
        ContactLaw &law = type == ContactType::GrainWall ? grain_wall : grain_tool;
        const char *name = type == ContactType::GrainWall ? "grain-wall" : "grain-tool";
        law.finalize();
        // The contact loops are compiled once per combination of models: every type shares
        // the grain-grain models and has its own parameters.
        const auto same = [&](const std::string &slot, const std::string &own,
                              const std::string &grains) {
            if (own != grains)
                throw std::invalid_argument(
                    std::string("the ") + name + " contact law's " + slot + " model '" + own +
                    "' differs from the grain-grain law's '" + grains +
                    "': every contact type uses the grain-grain models with its own parameters");
        };
        same("damping", modelName(law.damping), modelName(grain_grain.damping));
        same("tangential", modelName(law.tangential), modelName(grain_grain.tangential));
        same("rolling", modelName(law.rolling), modelName(grain_grain.rolling));
        same("cohesion", modelName(law.cohesion), modelName(grain_grain.cohesion));
    }
}

PairProperties pairProperties(const Material &a, const Material &b, const ContactLaw &law) {
    PairProperties p;
    const double ca = (1.0 - a.poisson_ratio * a.poisson_ratio) / a.youngs_modulus_Pa;
    const double cb = (1.0 - b.poisson_ratio * b.poisson_ratio) / b.youngs_modulus_Pa;
    p.effective_modulus_Pa = 1.0 / (ca + cb);
    const double sa = 2.0 * (2.0 - a.poisson_ratio) * (1.0 + a.poisson_ratio) / a.youngs_modulus_Pa;
    const double sb = 2.0 * (2.0 - b.poisson_ratio) * (1.0 + b.poisson_ratio) / b.youngs_modulus_Pa;
    p.effective_shear_modulus_Pa = 1.0 / (sa + sb);
    p.root_shear_ratio = std::sqrt(4.0 * p.effective_shear_modulus_Pa / p.effective_modulus_Pa);
    std::visit(
        [&](const auto &t) {
            using T = std::decay_t<decltype(t)>;
            if constexpr (std::is_same_v<T, TangentialLinear>) {
                p.tan_stick = tanDeg(t.stick_angle_deg);
                p.tan_slip = tanDeg(t.slip_angle_deg);
            } else {
                p.tan_stick = p.tan_slip = t.friction_coefficient;
            }
        },
        law.tangential);
    return p;
}

PairProperties pairProperties(const Material &a, const Material &b, const ContactLaw &law,
                              double wall_friction_coefficient) {
    if (!(wall_friction_coefficient >= 0.0))
        badParameter("wall", "friction_coefficient", wall_friction_coefficient, "must be >= 0");
    PairProperties p = pairProperties(a, b, law);
    p.tan_stick = p.tan_slip = wall_friction_coefficient;
    return p;
}

} // namespace grainlink::dem
