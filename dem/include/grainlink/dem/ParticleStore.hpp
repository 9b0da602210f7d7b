#pragma once
// Structure-of-arrays particle storage (LAMMPS atom->x/v/omega idea) with stable ids.
#include "grainlink/dem/Types.hpp"

#include <cstddef>
#include <vector>

namespace grainlink::dem {

/// Everything needed to add one sphere.
struct ParticleSpec {
    Vec3 position_m = Vec3::Zero();
    Vec3 velocity_m_s = Vec3::Zero();
    Vec3 angular_velocity_rad_s = Vec3::Zero();
    double radius_m = 0.0;
    double density_kg_m3 = 0.0;
    int material = 0;
    /// Principal moments of inertia in the particle frame [kg m^2]; zero means solid sphere.
    Vec3 inertia_kg_m2 = Vec3::Zero();
};

/// Particle state as parallel arrays. The storage index is not identity: `id[i]` is.
class ParticleStore {
public:
    std::size_t size() const { return id.size(); }
    bool empty() const { return id.empty(); }

    /// Appends a particle; returns its stable id. Throws on non-physical radius or density.
    ParticleId add(const ParticleSpec &spec);
    void reserve(std::size_t n);

    /// Reorders every array so that new index k holds old index `order[k]`.
    void permute(const std::vector<std::size_t> &order);
    /// Keeps only the particles at storage indices `kept` (ascending), dropping the others.
    void keep(const std::vector<std::size_t> &kept);

    /// True when all three principal moments of particle i are equal (no frame transforms needed).
    bool isotropic(std::size_t i) const {
        return inertia[i].x() == inertia[i].y() && inertia[i].y() == inertia[i].z();
    }
    double maxRadius() const;
    double minRadius() const;
    ParticleId nextId() const { return next_id_; }
    void setNextId(ParticleId next) { next_id_ = next; }

    std::vector<ParticleId> id;
    std::vector<Vec3> position;         ///< [m]
    std::vector<Vec3> velocity;         ///< [m/s]
    std::vector<Vec3> angular_velocity; ///< [rad/s], world frame
    std::vector<Quat> orientation;      ///< particle frame -> world frame
    std::vector<Vec3> force;            ///< [N], summed over the current step
    std::vector<Vec3> torque;           ///< [N m], world frame
    std::vector<double> radius;         ///< [m]
    std::vector<double> mass;           ///< [kg]
    std::vector<double> inv_mass;       ///< [1/kg]
    std::vector<Vec3> inertia;          ///< principal moments, particle frame [kg m^2]
    std::vector<int> material;          ///< index into the material table

private:
    void select(const std::vector<std::size_t> &order); ///< new index k holds old order[k]
    ParticleId next_id_ = 0;
};

} // namespace grainlink::dem
