#pragma once
// Contact law composed of slots (normal, damping, tangential, rolling, cohesion), each a small
// value-type sub-model held in a std::variant. The variants are visited once per batch of
// contacts so the per-contact code inlines (docs/physics.md §2).
#include "grainlink/dem/Types.hpp"

#include <string>
#include <variant>
#include <vector>

namespace grainlink::dem {

/// Elastic solid the grains (or a wall) are made of.
struct Material {
    std::string name = "soil";
    double youngs_modulus_Pa = 0.0;
    double poisson_ratio = 0.0;
    double density_kg_m3 = 0.0; ///< grain density; walls may leave it 0
    void validate() const;
};

/// Quantities of one material pair, computed once at setup.
struct PairProperties {
    double effective_modulus_Pa = 0.0;       ///< E* : 1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2
    double effective_shear_modulus_Pa = 0.0; ///< G* : 1/G* = 2(2-nu1)(1+nu1)/E1 + ...
    double tan_stick = 0.0;                  ///< tan(phi_h), Coulomb limit while sticking
    double tan_slip = 0.0;                   ///< tan(phi_g), friction while sliding
    double root_shear_ratio = 0.0; ///< sqrt(4 G*/E*): Mindlin's k_t over Hertz's S_n, rooted
};

// ---- normal elastic slot ---------------------------------------------------------------------
/// Hertz normal force F = 4/3 E* sqrt(R*) delta^(3/2) (seed eq. 3), docs/physics.md §2.1.
struct NormalHertz {
    void validate() const {}
};
using NormalModel = std::variant<NormalHertz>;

// ---- normal damping slot ---------------------------------------------------------------------
/// Linear viscous damping F = -k_n u_n (seed eq. 4), docs/physics.md §2.2.
struct DampingViscous {
    double coefficient_N_s_m = 0.0; ///< k_n [N s/m]
    void validate() const;
};
/// Hertz-Mindlin damping from a coefficient of restitution (Tsuji; LIGGGHTS/EDEM), §2.3.
struct DampingRestitution {
    double restitution = 0.5;
    double beta = 0.0; ///< derived: ln e / sqrt(ln^2 e + pi^2)
    void validate() const;
    void derive();
};
using DampingModel = std::variant<DampingViscous, DampingRestitution>;

// ---- tangential slot -------------------------------------------------------------------------
/// Seed eq. 5: linear spring c_T on the accumulated tangential displacement with dashpot k_T;
/// sticks while |F_T| <= F_N tan(phi_h), slides at F_N tan(phi_g) once exceeded. §2.4.
struct TangentialLinear {
    double stiffness_N_m = 0.0;    ///< c_T [N/m]
    double damping_N_s_m = 0.0;    ///< k_T [N s/m]
    double stick_angle_deg = 30.0; ///< phi_h
    double slip_angle_deg = 30.0;  ///< phi_g
    void validate() const;
};
/// Mindlin no-slip tangential spring k_t = 8 G* sqrt(R* delta) with restitution damping and a
/// Coulomb limit (LIGGGHTS "tangential history"), §2.5. Uses the normal damping's restitution.
struct TangentialMindlin {
    double friction_coefficient = 0.5; ///< mu
    double beta = 0.0;                 ///< derived from the damping slot's restitution (0: none)
    void validate() const;
};
using TangentialModel = std::variant<TangentialLinear, TangentialMindlin>;

// ---- rolling slot ----------------------------------------------------------------------------
struct RollingNone {
    void validate() const {}
};
/// Elastic-plastic spring rolling resistance (EPSD type, Ai et al. 2011): k_r = 2.25 mu_r^2 R*^2
/// k_n, |M_r| <= mu_r R* F_N, §2.6.
struct RollingEpsd {
    double coefficient = 0.1; ///< mu_r (rolling friction coefficient, dimensionless)
    void validate() const;
};
/// The seed's grain-shape law (eqs. 6-8), §2.6.1: for each local axis k of the grain a virtual
/// rectangle of aspect-ratio angle gamma_k (A_k = tan gamma_k = half base / half height) rests
/// on the contact with a face and tilts over its corner as the grain rolls; the contact force
/// acts at the pivot corner. Per-contact history: the relative rolling angle [rad].
struct RollingGrainShape {
    enum class Inertia {
        Sphere,  ///< the store's moments (solid sphere unless set)
        SeedEq12 ///< J_k = (1/9) pi rho r^3 (r / A_k)^2, seed eq. 12
    };
    Vec3 aspect_ratio_angle_deg = Vec3::Constant(30.0); ///< gamma_k per local axis, in (0, 90)
    Inertia inertia = Inertia::Sphere;
    // Derived by derive(): per local axis.
    Vec3 gamma_rad = Vec3::Zero();
    Vec3 tan_gamma = Vec3::Zero();
    Vec3 elastic_slope = Vec3::Zero(); ///< tan^2(gamma_k) / 2: face-regime slope times delta/a
    void validate() const;
    void derive();
};
using RollingModel = std::variant<RollingNone, RollingEpsd, RollingGrainShape>;

/// Principal moments of seed eq. 12 for a grain of radius r and density rho [kg m^2].
Vec3 grainShapeInertia(const RollingGrainShape &model, double radius_m, double density_kg_m3);

// ---- cohesion slot ---------------------------------------------------------------------------
struct CohesionNone {
    void validate() const {}
};
/// Linear cohesion: attractive F = k_c A with the Hertz contact area A = pi R* delta, §2.7.
struct CohesionLinear {
    double energy_density_J_m3 = 0.0; ///< k_c [J/m^3 = Pa]
    void validate() const;
};
using CohesionModel = std::variant<CohesionNone, CohesionLinear>;

/// The five slots plus the non-contact background damping. Validated once at setup.
struct ContactLaw {
    NormalModel normal = NormalHertz{};
    DampingModel damping = DampingRestitution{};
    TangentialModel tangential = TangentialMindlin{};
    RollingModel rolling = RollingNone{};
    CohesionModel cohesion = CohesionNone{};
    /// k_h: viscous drag on every particle, F = -k_h m v and M = -k_h J w [1/s], §2.8.
    double background_damping_1_s = 0.0;

    /// Checks each slot's parameters and the cross-slot rules; derives dependent constants.
    void finalize();
    std::string describe() const;
};

/// Which two things a contact joins.
enum class ContactType {
    GrainGrain,
    GrainWall, ///< planes and boxes
    GrainTool, ///< mesh bodies: wheels, plates, hulls, STL meshes
};

/// The law of each contact type: one set of slot models, each type its own parameters, as
/// LIGGGHTS and EDEM give parameters per material pair (docs/physics.md §2.10). A wall's or a
/// body's own friction_coefficient still applies on top of its type's law.
struct ContactLaws {
    ContactLaw grain_grain; ///< its background damping acts on every grain (§2.8)
    ContactLaw grain_wall;  ///< its background damping is not used
    ContactLaw grain_tool;  ///< its background damping is not used

    ContactLaws() = default;
    /// Every contact type under `law` (implicit: a single law is the common case).
    ContactLaws(const ContactLaw &law) : grain_grain(law), grain_wall(law), grain_tool(law) {}
    const ContactLaw &of(ContactType type) const;
    /// Finalizes each law; a wall or tool law whose models differ from the grain-grain law's
    /// is an error naming the contact type, the slot and both models.
    void finalize();
};

/// Name of a slot's model as the scenario writes it (`restitution`, `epsd`, ...).
std::string modelName(const DampingModel &slot);
std::string modelName(const TangentialModel &slot);
std::string modelName(const RollingModel &slot);
std::string modelName(const CohesionModel &slot);

/// Pair quantities of two materials with Coulomb angles from the tangential slot.
PairProperties pairProperties(const Material &a, const Material &b, const ContactLaw &law);
/// Same, with a wall's own friction coefficient replacing both Coulomb angles.
PairProperties pairProperties(const Material &a, const Material &b, const ContactLaw &law,
                              double wall_friction_coefficient);

/// Per-contact memory that survives neighbour-list rebuilds and re-sorts.
struct ContactHistory {
    Vec3 tangential_m = Vec3::Zero(); ///< accumulated tangential displacement of i rel. to j
    /// Rolling slot's memory: EPSD's elastic rolling moment on i [N m]; grain_shape's relative
    /// rolling angle of i to j, integral of (omega_i - omega_j) in the contact plane [rad].
    Vec3 rolling_N_m = Vec3::Zero();
    bool sliding = false; ///< two-angle Coulomb state (seed eq. 5)
    bool active() const { return sliding || !tangential_m.isZero() || !rolling_N_m.isZero(); }
    /// The same contact seen from the other particle.
    ContactHistory reversed() const { return {-tangential_m, -rolling_N_m, sliding}; }
};

} // namespace grainlink::dem
