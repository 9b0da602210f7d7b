#pragma once
// Small builders shared by the DEM tests.
#include "grainlink/dem/DemSystem.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>

namespace grainlink::dem::testing {

inline Material soil(double youngs_modulus_Pa = 1e7, double poisson = 0.3,
                     double density = 2500.0) {
    Material m;
    m.name = "test";
    m.youngs_modulus_Pa = youngs_modulus_Pa;
    m.poisson_ratio = poisson;
    m.density_kg_m3 = density;
    return m;
}

/// The elastic grain material and radius most contact tests share.
inline const Material kMaterial = soil(1e7, 0.3, 2500.0);
inline constexpr double kRadius = 0.005;
inline constexpr double kG = 9.81;

inline double deg(double degrees) {
    return degrees * M_PI / 180.0;
}

inline ContactLaw hertzRestitution(double restitution, double friction) {
    ContactLaw law;
    law.damping = DampingRestitution{restitution};
    law.tangential = TangentialMindlin{friction};
    return law;
}

inline ContactLaw hertzViscous(double damping_N_s_m, double c_t, double stick_deg,
                               double slip_deg) {
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

/// Normal impact reduced to one degree of freedom, the overlap delta(t), with the force law of
/// ContactKernel.hpp written out again independently:
///   m* delta'' = -F,  F = max(4/3 E* sqrt(R*) delta^1.5 + c(delta) delta', 0)      (seed eq. 3)
/// c = k_n (DampingViscous, seed eq. 4) or c = -2 sqrt(5/6) beta sqrt(2 E* sqrt(R* delta) m*)
/// (DampingRestitution, Tsuji), beta = ln e / sqrt(ln^2 e + pi^2). The max(., 0) is the clamp the
/// kernel applies: a separating dashpot never pulls. Integrated with classical RK4 at a step far
/// below the DEM one, it is the reference the DEM impacts are compared with.
struct NormalImpactOde {
    double effective_modulus_Pa, radius_eff_m, mass_eff_kg;
    double viscous_N_s_m = 0.0;   ///< k_n; used when restitution_set is 0
    double restitution_set = 0.0; ///< e of DampingRestitution; 0 selects the viscous dashpot
    bool clamp = true;            ///< F >= 0 as in the kernel; false lets the dashpot pull

    double force(double delta, double rate) const {
        if (delta <= 0.0)
            return 0.0;
        const double elastic =
            4.0 / 3.0 * effective_modulus_Pa * std::sqrt(radius_eff_m) * std::pow(delta, 1.5);
        double c = viscous_N_s_m;
        if (restitution_set > 0.0) {
            const double log_e = std::log(restitution_set);
            const double beta = log_e / std::sqrt(log_e * log_e + M_PI * M_PI);
            const double stiffness = 2.0 * effective_modulus_Pa * std::sqrt(radius_eff_m * delta);
            c = -2.0 * std::sqrt(5.0 / 6.0) * beta * std::sqrt(stiffness * mass_eff_kg);
        }
        return clamp ? std::max(elastic + c * rate, 0.0) : elastic + c * rate;
    }

    struct Result {
        double restitution; ///< exit speed / impact speed
        double duration_s;  ///< time with delta > 0
        double max_overlap_m;
    };

    /// RK4 from delta = 0, delta' = speed until delta returns to 0; `steps` per elastic duration.
    Result impact(double speed_m_s, int steps = 200000) const {
        const HertzImpact elastic{effective_modulus_Pa, radius_eff_m, mass_eff_kg, speed_m_s};
        const double h = elastic.duration() / steps;
        double x = 0.0, u = speed_m_s, t = 0.0, x_max = 0.0;
        auto acc = [&](double d, double r) { return -force(d, r) / mass_eff_kg; };
        for (long k = 0; k < 100L * steps; ++k) {
            const double k1x = u, k1u = acc(x, u);
            const double k2x = u + 0.5 * h * k1u, k2u = acc(x + 0.5 * h * k1x, k2x);
            const double k3x = u + 0.5 * h * k2u, k3u = acc(x + 0.5 * h * k2x, k3x);
            const double k4x = u + h * k3u, k4u = acc(x + h * k3x, k4x);
            const double x_new = x + h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
            const double u_new = u + h / 6.0 * (k1u + 2.0 * k2u + 2.0 * k3u + k4u);
            if (x_new <= 0.0 && k > 0) {
                // Crossing inside this step: interpolate time and rate linearly.
                const double s = x / (x - x_new);
                return {-(u + s * (u_new - u)) / speed_m_s, t + s * h, x_max};
            }
            x = x_new;
            u = u_new;
            t += h;
            x_max = std::max(x_max, x);
        }
        return {std::nan(""), std::nan(""), x_max};
    }
};

/// Effective modulus of two grains (or a grain and a wall) of the same material.
inline double effectiveModulus(const Material& m) {
    return m.youngs_modulus_Pa / (2.0 * (1.0 - m.poisson_ratio * m.poisson_ratio));
}

inline double sphereMass(double r, double rho) {
    return 4.0 / 3.0 * M_PI * r * r * r * rho;
}

/// Six planes enclosing [lower, upper], normals pointing inwards.
inline void addBoxPlanes(DemSystem& sys, const Vec3& lower, const Vec3& upper) {
    for (int d = 0; d < 3; ++d) {
        PlaneWall low, high;
        low.name = "low" + std::to_string(d);
        high.name = "high" + std::to_string(d);
        low.point_m = lower;
        high.point_m = upper;
        low.normal = Vec3::Unit(d);
        high.normal = -Vec3::Unit(d);
        sys.addPlane(low);
        sys.addPlane(high);
    }
}

/// Grains on a jittered cubic lattice filling [lower, upper] (radius r_min..r_max, random
/// velocity of each component in +-speed); deterministic for a given seed.
inline void addLattice(DemSystem& sys, const Vec3& lower, const Vec3& upper, double spacing_m,
                       double r_min, double r_max, double rho, double speed_m_s,
                       std::size_t max_count, unsigned seed = 7) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    const Eigen::Vector3i cells =
        ((upper - lower) / spacing_m + Vec3::Constant(1e-9)).array().floor().cast<int>();
    for (int iz = 0; iz < cells.z(); ++iz)
        for (int iy = 0; iy < cells.y(); ++iy)
            for (int ix = 0; ix < cells.x(); ++ix) {
                if (sys.particles().size() >= max_count)
                    return;
                const double x = lower.x() + (ix + 0.5) * spacing_m;
                const double y = lower.y() + (iy + 0.5) * spacing_m;
                const double z = lower.z() + (iz + 0.5) * spacing_m;
                const double r = r_min + 0.5 * (unit(rng) + 1.0) * (r_max - r_min);
                const double jitter = 0.5 * (0.5 * spacing_m - r_max);
                const Vec3 x0 = Vec3(x, y, z) + jitter * Vec3(unit(rng), unit(rng), unit(rng));
                const Vec3 v0 = speed_m_s * Vec3(unit(rng), unit(rng), unit(rng));
                sys.particles().add(sphere(x0, r, rho, v0));
            }
}

/// Copies the particle arrays and every contact history of `from` into `to`, which must have the
/// same materials, planes and bodies; `to` keeps its own settings (time step, integrator, skin,
/// re-sort schedule). Its lists are built at the current positions, so no contact is missed.
inline void copyState(const DemSystem& from, DemSystem& to) {
    to.particles() = from.particles();
    DemSystem::Internals state = from.saveInternals();
    state.reference_position = to.particles().position;
    to.restoreInternals(state);
}

/// Open box (floor and four walls, no lid) of side `width_m` and `height_m`, floor at z = 0,
/// centred on the z axis; each face split into cells x cells rectangles of two triangles.
inline TriangleMesh makeOpenBox(double width_m, double height_m, int cells) {
    TriangleMesh box;
    auto append = [&box](const TriangleMesh& face, const Mat3& rotation, const Vec3& offset) {
        const int base = int(box.vertices_m.size());
        for (const Vec3& v : face.vertices_m)
            box.vertices_m.push_back(rotation * v + offset);
        for (const auto& t : face.triangles)
            box.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
    };
    const TriangleMesh floor = makeRectangle(width_m, width_m, cells, cells);
    const TriangleMesh wall = makeRectangle(width_m, height_m, cells, cells);
    const Mat3 upright = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()).toRotationMatrix();
    const Mat3 turned = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()).toRotationMatrix() * upright;
    const double h = 0.5 * width_m, z = 0.5 * height_m;
    append(floor, Mat3::Identity(), Vec3::Zero());
    append(wall, upright, Vec3(0, -h, z));
    append(wall, upright, Vec3(0, h, z));
    append(wall, turned, Vec3(-h, 0, z));
    append(wall, turned, Vec3(h, 0, z));
    return box;
}

/// Translational plus rotational kinetic energy [J] (isotropic grains).
inline double kineticEnergy(const DemSystem& sys) {
    const ParticleStore& p = sys.particles();
    double e = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i)
        e += 0.5 * p.mass[i] * p.velocity[i].squaredNorm() +
             0.5 * p.inertia[i].x() * p.angular_velocity[i].squaredNorm();
    return e;
}

/// A fresh folder for one test, removed afterwards. Per process: two test runs at once (two
/// build trees) must not share files.
struct Scratch {
    explicit Scratch(const std::string &name)
        : dir(std::filesystem::temp_directory_path() /
              ("grainlink-test-" + name + "-" + std::to_string(::getpid()))) {
        std::filesystem::remove_all(dir);
        std::filesystem::create_directories(dir);
    }
    ~Scratch() { std::filesystem::remove_all(dir); }
    Scratch(const Scratch &) = delete;
    Scratch &operator=(const Scratch &) = delete;
    std::filesystem::path dir;
};

} // namespace grainlink::dem::testing
