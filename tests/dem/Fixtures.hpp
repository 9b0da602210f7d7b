#pragma once
// Small builders shared by the DEM tests.
#include "grainlink/dem/DemSystem.hpp"

namespace grainlink::dem::testing {

inline Material soil(double youngs_modulus_Pa = 1e7, double poisson = 0.3, double density = 2500.0) {
    Material m;
    m.name = "test";
    m.youngs_modulus_Pa = youngs_modulus_Pa;
    m.poisson_ratio = poisson;
    m.density_kg_m3 = density;
    return m;
}

inline ContactLaw hertzRestitution(double restitution, double friction) {
    ContactLaw law;
    law.damping = DampingRestitution{restitution};
    law.tangential = TangentialMindlin{friction};
    return law;
}

inline ContactLaw hertzViscous(double damping_N_s_m, double c_t, double stick_deg, double slip_deg) {
    ContactLaw law;
    law.damping = DampingViscous{damping_N_s_m};
    TangentialLinear t;
    t.stiffness_N_m = c_t;
    t.stick_angle_deg = stick_deg;
    t.slip_angle_deg = slip_deg;
    law.tangential = t;
    return law;
}

inline DemSettings quietSettings(double dt_s) {
    DemSettings s;
    s.time_step_s = dt_s;
    s.gravity_m_s2 = Vec3::Zero();
    return s;
}

inline ParticleSpec sphere(const Vec3& x, double r, double rho, const Vec3& v = Vec3::Zero()) {
    ParticleSpec p;
    p.position_m = x;
    p.radius_m = r;
    p.density_kg_m3 = rho;
    p.velocity_m_s = v;
    return p;
}

/// Hertz impact of a sphere pair (or sphere-wall) from the closed-form elastic solution.
struct HertzImpact {
    double effective_modulus_Pa, radius_eff_m, mass_eff_kg, speed_m_s;
    double maxOverlap() const {
        return std::pow(15.0 * mass_eff_kg * speed_m_s * speed_m_s /
                            (16.0 * effective_modulus_Pa * std::sqrt(radius_eff_m)),
                        0.4);
    }
    /// t_c = 2.94328 delta_max / v0 (integral of the Hertz energy equation).
    double duration() const { return 2.9432 * maxOverlap() / speed_m_s; }
};

} // namespace grainlink::dem::testing
