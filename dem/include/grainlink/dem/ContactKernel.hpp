#pragma once
// Force of one contact, given concrete slot types so the compiler inlines the whole law.
// Every formula here is written out, with its test, in docs/physics.md §2.
#include "grainlink/dem/ContactLaw.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>

namespace grainlink::dem {

/// Geometry and kinematics of one contact. `normal` points from j (or the wall) to i.
struct ContactGeometry {
    Vec3 normal;
    double overlap_m;
    double radius_eff_m;       ///< R* = r_i r_j / (r_i + r_j); r_i for walls
    double mass_eff_kg;        ///< m* = m_i m_j / (m_i + m_j); m_i for walls
    double arm_i_m;            ///< centre of i to contact point
    double arm_j_m;            ///< centre of j to contact point (0 for walls)
    Vec3 contact_velocity_m_s; ///< velocity of i relative to j at the contact point
    Vec3 relative_spin_rad_s;  ///< omega_i - omega_j
    // Read only by the grain-shape rolling law (set only where it is the law in use):
    const Quat *orientation_i; ///< particle frame of i
    const Quat *orientation_j; ///< particle frame of j; nullptr for walls
};

/// Geometry of the pair i-j (§2): n from j to i, contact arms a = r - delta/2.
[[gnu::always_inline]] inline ContactGeometry
pairGeometry(const Vec3 &x_i, const Vec3 &x_j, double r_i, double r_j, double inv_mass_i,
             double inv_mass_j, const Vec3 &v_i, const Vec3 &v_j, const Vec3 &w_i, const Vec3 &w_j,
             const Quat *orientation_i, const Quat *orientation_j) {
    const Vec3 d = x_i - x_j;
    const double dist = std::sqrt(d.squaredNorm());
    const double r_sum = r_i + r_j;
    ContactGeometry g;
    g.normal = d * (1.0 / dist);
    g.overlap_m = r_sum - dist;
    g.radius_eff_m = r_i * r_j / r_sum;
    g.mass_eff_kg = 1.0 / (inv_mass_i + inv_mass_j);
    g.arm_i_m = r_i - 0.5 * g.overlap_m;
    g.arm_j_m = r_j - 0.5 * g.overlap_m;
    g.contact_velocity_m_s = v_i - v_j - (g.arm_i_m * w_i + g.arm_j_m * w_j).cross(g.normal);
    g.relative_spin_rad_s = w_i - w_j;
    g.orientation_i = orientation_i;
    g.orientation_j = orientation_j;
    return g;
}

/// Geometry of sphere i on a wall (plane or triangle) whose surface point nearest the centre
/// lies `dist` below it along the wall's outward normal n (§2, §2.9): R* = r_i, m* = m_i, the
/// arm is dist; the wall's surface moves at `wall_velocity` there and spins at `wall_spin`.
[[gnu::always_inline]] inline ContactGeometry
wallGeometry(const Vec3 &n, double dist, double r_i, double mass_i, const Vec3 &v_i,
             const Vec3 &w_i, const Vec3 &wall_velocity, const Vec3 &wall_spin,
             const Quat *orientation_i) {
    ContactGeometry g;
    g.normal = n;
    g.overlap_m = r_i - dist;
    g.radius_eff_m = r_i;
    g.mass_eff_kg = mass_i;
    g.arm_i_m = dist;
    g.arm_j_m = 0.0;
    g.contact_velocity_m_s = v_i - dist * w_i.cross(n) - wall_velocity;
    g.relative_spin_rad_s = w_i - wall_spin;
    g.orientation_i = orientation_i;
    g.orientation_j = nullptr;
    return g;
}

struct ContactResult {
    Vec3 force_on_i_N;
    Vec3 torque_on_i_N_m;
    Vec3 torque_on_j_N_m;
    double normal_force_N; ///< compressive normal force (elastic + damping, >= 0)
};

namespace detail {
constexpr double kSqrtFiveSixths = 0.91287092917527685576;

/// Turns a history vector into the current tangent plane, keeping its length (§2.4).
inline void rotateIntoPlane(Vec3 &history, const Vec3 &normal) {
    const double length_sq = history.squaredNorm();
    if (length_sq == 0.0)
        return;
    const double along = history.dot(normal);
    history -= along * normal;
    // Rescale by 1/sqrt(1 - x), x = along^2 / length^2. Within one step the plane turns by a
    // tiny angle, x ~ angle^2, and the series to x^2 is exact to 1e-16 for x < 1e-5.
    const double x = along * along / length_sq;
    if (x < 1e-5) {
        history *= 1.0 + x * (0.5 + 0.375 * x);
    } else if (x < 1.0) {
        history *= 1.0 / std::sqrt(1.0 - x);
    }
}

/// Moment arms of the grain-shape law in one rotation plane, as fractions of the sphere's
/// contact arm a (docs/physics.md §2.6.1): the pivot lies x = a X along T and y = a Y below the
/// centre along -N. `theta` is the grain's tilt about the plane's axis, `tan_gamma` = A and
/// `elastic` the face-regime slope (a tan^2(gamma) / 2 delta).
struct GrainShapeArms {
    double X, Y;
};
inline GrainShapeArms grainShapeArms(double theta, double gamma, double tan_gamma, double elastic) {
    // The virtual grain lands on its next face every 2 gamma: the tilt within the current face.
    const double period = 2.0 * gamma;
    const double tilt = theta - period * std::floor(theta / period + 0.5); // in [-gamma, gamma]
    const double t = std::abs(tilt);
    const double s = std::sin(t), c = std::cos(t);
    // Corner regime: x = d sin(gamma - t), y = d cos(gamma - t), d = a / cos(gamma), over a.
    const double x_corner = tan_gamma * c - s;
    const double x = std::min(elastic * t, x_corner); // face regime near t = 0
    return {std::copysign(x, tilt), c + tan_gamma * s};
}

/// Torque of the grain-shape law on one grain beyond the sphere's own -a n x F_t (§2.6.1): the
/// contact force f_n n + f_t acts, in the rotation plane of each local axis e_k, at the pivot
/// corner of that axis' rectangle. `n` points from the contact into the grain, `tilt` is the
/// grain's rolling rotation relative to the contact (world frame, in the contact plane).
/// Out of line: one copy for all slot combinations, so that the Eigen kernels it uses do not
/// multiply in every instantiation of the contact loops (which changed their inlining).
[[gnu::noinline]] inline Vec3 grainShapeTorque(const RollingGrainShape &law,
                                               const Quat &orientation, const Vec3 &n, double arm_m,
                                               double overlap_m, double normal_force_N,
                                               const Vec3 &f_tangential, const Vec3 &tilt) {
    const Mat3 frame = orientation.toRotationMatrix();
    const double arm_over_overlap = arm_m / overlap_m;
    Vec3 moments; // about the local axes
    for (int k = 0; k < 3; ++k) {
        const Vec3 e = frame.col(k);
        const Vec3 u = e.cross(n); // |u| = s_k, the share of the contact in this plane
        const GrainShapeArms arms = grainShapeArms(tilt.dot(e), law.gamma_rad[k], law.tan_gamma[k],
                                                   law.elastic_slope[k] * arm_over_overlap);
        // M_k = -a (X f_n s_k^2 + Y f_t.u_k); the sphere's part (Y = 1, X = 0) is already applied.
        moments[k] = -arm_m * (arms.X * normal_force_N * u.squaredNorm() +
                               (arms.Y - 1.0) * f_tangential.dot(u));
    }
    return frame * moments;
}
} // namespace detail

// Always inlined: a call would pass the geometry through memory, and the contact loop calls it
// from more than one place.
template <class Normal, class Damping, class Tangential, class Rolling, class Cohesion>
[[gnu::always_inline]] inline void
evaluateContact(const Damping &damping, const Tangential &tangential, const Rolling &rolling,
                const Cohesion &cohesion, const PairProperties &pair, const ContactGeometry &g,
                double dt_s, ContactHistory &history, ContactResult &out) {
    static_assert(std::is_same_v<Normal, NormalHertz>, "only Hertz normal contact exists");
    const Vec3 &n = g.normal;
    const double sqrt_r_delta = std::sqrt(g.radius_eff_m * g.overlap_m);
    // Hertz: S_n = dF/d(delta) = 2 E* sqrt(R* delta); F = 2/3 S_n delta (seed eq. 3).
    const double normal_stiffness = 2.0 * pair.effective_modulus_Pa * sqrt_r_delta;
    const double elastic = (2.0 / 3.0) * normal_stiffness * g.overlap_m;

    const double v_normal = g.contact_velocity_m_s.dot(n); // < 0 while approaching
    // sqrt(S_n m*) serves the restitution dashpot and, scaled, Mindlin's tangential one.
    constexpr bool kNeedsRoot = std::is_same_v<Damping, DampingRestitution> ||
                                std::is_same_v<Tangential, TangentialMindlin>;
    const double root_stiffness_mass =
        kNeedsRoot ? std::sqrt(normal_stiffness * g.mass_eff_kg) : 0.0;
    double damping_coefficient;
    if constexpr (std::is_same_v<Damping, DampingViscous>) {
        damping_coefficient = damping.coefficient_N_s_m; // seed eq. 4
    } else {
        damping_coefficient = -2.0 * detail::kSqrtFiveSixths * damping.beta * root_stiffness_mass;
    }
    // The seed's viscous dashpot may not pull a separating contact together (§2.2). The
    // restitution dashpot is left unclamped as in LIGGGHTS and EDEM, so that a restitution
    // entered there gives the same rebound here (§2.3); friction sees only compression.
    const double normal_total = elastic - damping_coefficient * v_normal;
    const double normal_force = std::max(normal_total, 0.0);
    const double normal_applied =
        std::is_same_v<Damping, DampingViscous> ? normal_force : normal_total;

    double cohesive = 0.0;
    if constexpr (std::is_same_v<Cohesion, CohesionLinear>) {
        cohesive = cohesion.energy_density_J_m3 * M_PI * g.radius_eff_m * g.overlap_m;
    } else {
        (void)cohesion;
    }

    // Tangential spring on the accumulated displacement, turned with the contact plane.
    const Vec3 v_tangential = g.contact_velocity_m_s - v_normal * n;
    detail::rotateIntoPlane(history.tangential_m, n);
    history.tangential_m += v_tangential * dt_s;
    double k_t, c_t;
    if constexpr (std::is_same_v<Tangential, TangentialLinear>) {
        k_t = tangential.stiffness_N_m;
        c_t = tangential.damping_N_s_m;
    } else {
        // k_t = 8 G* sqrt(R* delta) = (4 G*/E*) S_n, so sqrt(k_t m*) needs no second root.
        k_t = 8.0 * pair.effective_shear_modulus_Pa * sqrt_r_delta;
        c_t = -2.0 * detail::kSqrtFiveSixths * tangential.beta * pair.root_shear_ratio *
              root_stiffness_mass;
    }
    Vec3 f_tangential = -k_t * history.tangential_m - c_t * v_tangential;
    const double limit = (history.sliding ? pair.tan_slip : pair.tan_stick) * normal_force;
    const double trial_sq = f_tangential.squaredNorm();
    if (trial_sq > limit * limit) {
        // Slip: friction at the sliding angle; the spring keeps the matching stretch (seed eq. 5).
        f_tangential *= pair.tan_slip * normal_force / std::sqrt(trial_sq);
        history.tangential_m =
            k_t > 0.0 ? Vec3(-(f_tangential + c_t * v_tangential) / k_t) : Vec3::Zero();
        history.sliding = true;
    } else {
        history.sliding = false;
    }

    out.force_on_i_N = (normal_applied - cohesive) * n + f_tangential;
    const Vec3 n_cross_ft = n.cross(f_tangential);
    out.torque_on_i_N_m = -g.arm_i_m * n_cross_ft;
    out.torque_on_j_N_m = -g.arm_j_m * n_cross_ft;
    out.normal_force_N = normal_force;

    if constexpr (std::is_same_v<Rolling, RollingEpsd>) {
        // EPSD rolling spring on the relative rolling rotation, capped at mu_r R* F_N (§2.6).
        Vec3 spin = g.relative_spin_rad_s;
        spin -= spin.dot(n) * n; // twisting is not rolling
        detail::rotateIntoPlane(history.rolling_N_m, n);
        const double mu_r = rolling.coefficient;
        const double k_r = 2.25 * mu_r * mu_r * g.radius_eff_m * g.radius_eff_m * normal_stiffness;
        history.rolling_N_m -= k_r * dt_s * spin;
        const double max_moment = mu_r * g.radius_eff_m * normal_force;
        const double moment_sq = history.rolling_N_m.squaredNorm();
        if (moment_sq > max_moment * max_moment)
            history.rolling_N_m *= max_moment / std::sqrt(moment_sq);
        out.torque_on_i_N_m += history.rolling_N_m;
        out.torque_on_j_N_m -= history.rolling_N_m;
    } else if constexpr (std::is_same_v<Rolling, RollingGrainShape>) {
        // Seed eq. 8 with the moment arms of a rectangle tilting over its corner (§2.6.1). The
        // history is the relative rolling angle; each grain's tilt is its share of the rolling
        // displacement at the contact point: a_j / (a_i + a_j) for i (R*/r_i), 1 at a wall.
        // (Plain assignments here, not +=: see grainShapeTorque.)
        const Vec3 spin = g.relative_spin_rad_s - g.relative_spin_rad_s.dot(n) * n;
        detail::rotateIntoPlane(history.rolling_N_m, n);
        history.rolling_N_m = history.rolling_N_m + dt_s * spin;
        const double share_i = g.orientation_j ? g.arm_j_m / (g.arm_i_m + g.arm_j_m) : 1.0;
        const Vec3 tilt_i = share_i * history.rolling_N_m;
        out.torque_on_i_N_m =
            out.torque_on_i_N_m + detail::grainShapeTorque(rolling, *g.orientation_i, n, g.arm_i_m,
                                                           g.overlap_m, normal_force, f_tangential,
                                                           tilt_i);
        if (g.orientation_j) {
            const Vec3 tilt_j = (share_i - 1.0) * history.rolling_N_m;
            out.torque_on_j_N_m =
                out.torque_on_j_N_m + detail::grainShapeTorque(rolling, *g.orientation_j, -n,
                                                               g.arm_j_m, g.overlap_m, normal_force,
                                                               -f_tangential, tilt_j);
        }
    } else {
        (void)rolling;
    }
}

/// A contact law with its slot types known to the compiler: what the contact loops are
/// instantiated for, so that evaluate() inlines the whole law.
template <class Damping, class Tangential, class Rolling, class Cohesion> struct ConcreteLaw {
    Damping damping;
    Tangential tangential;
    Rolling rolling;
    Cohesion cohesion;
    /// The grain-shape law reads the grains' orientations.
    static constexpr bool kGrainShape = std::is_same_v<Rolling, RollingGrainShape>;
    /// The rolling slot keeps a per-contact history.
    static constexpr bool kRollingHistory = kGrainShape || std::is_same_v<Rolling, RollingEpsd>;

    /// The same models with the parameters of `law` (ContactLaws::finalize checked that a
    /// contact type's law has the grain-grain models).
    static ConcreteLaw of(const ContactLaw &law) {
        return {std::get<Damping>(law.damping), std::get<Tangential>(law.tangential),
                std::get<Rolling>(law.rolling), std::get<Cohesion>(law.cohesion)};
    }

    [[gnu::always_inline]] void evaluate(const PairProperties &pair, const ContactGeometry &g,
                                         double dt_s, ContactHistory &history,
                                         ContactResult &out) const {
        evaluateContact<NormalHertz>(damping, tangential, rolling, cohesion, pair, g, dt_s, history,
                                     out);
    }
};

/// Calls `body` with `law` as a ConcreteLaw (one std::visit per pass over the contacts).
template <class Body> inline void withConcreteLaw(const ContactLaw &law, Body &&body) {
    std::visit(
        [&](const NormalHertz &, const auto &damping, const auto &tangential, const auto &rolling,
            const auto &cohesion) {
            using Law =
                ConcreteLaw<std::decay_t<decltype(damping)>, std::decay_t<decltype(tangential)>,
                            std::decay_t<decltype(rolling)>, std::decay_t<decltype(cohesion)>>;
            body(Law{damping, tangential, rolling, cohesion});
        },
        law.normal, law.damping, law.tangential, law.rolling, law.cohesion);
}

/// Stored elastic energy of one contact [J]: Hertz 8/15 E* sqrt(R*) delta^(5/2) plus the
/// tangential spring's 1/2 k_t |delta_t|^2 (docs/physics.md §2.1, §2.4, §2.5).
inline double contactElasticEnergy(const ContactLaw &law, const PairProperties &pair,
                                   double radius_eff_m, double overlap_m,
                                   const ContactHistory &history) {
    double k_t = 0.0;
    if (const auto *lin = std::get_if<TangentialLinear>(&law.tangential))
        k_t = lin->stiffness_N_m;
    else
        k_t = 8.0 * pair.effective_shear_modulus_Pa * std::sqrt(radius_eff_m * overlap_m);
    return 8.0 / 15.0 * pair.effective_modulus_Pa * std::sqrt(radius_eff_m) *
               std::pow(overlap_m, 2.5) +
           0.5 * k_t * history.tangential_m.squaredNorm();
}

} // namespace grainlink::dem
