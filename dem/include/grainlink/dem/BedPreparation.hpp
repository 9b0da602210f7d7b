#pragma once
// A settled bed prepared the way test beds are: struck off level at a height, compacted by a
// plate held at a pressure, topped by a stiffer crust; and the bed's surface and packing
// fraction (docs/physics.md §6.1). deposit() runs these steps in that order.
#include "grainlink/dem/DemSystem.hpp"

#include <cstddef>

namespace grainlink::dem {

/// `deposition.compaction`: a rigid plate over the region's footprint comes down at speed_m_s,
/// is held by a force servo at pressure_Pa x footprint area for hold_time_s, and is lifted off.
struct CompactionSpec {
    double pressure_Pa = 0.0; ///< [Pa] on the footprint; > 0
    double hold_time_s = 0.1; ///< [s] at the pressure
    double speed_m_s = 0.05;  ///< [m/s] approach and lift speed (the servo's clamp)
    void validate() const;    ///< throws std::invalid_argument naming the member
};

/// `deposition.crust`: the grains whose tops lie within thickness_m of the bed surface get a
/// stiffer copy of their material (crustMaterial()).
struct CrustSpec {
    double thickness_m = 0.0;           ///< [m] below the surface; > 0
    double youngs_modulus_factor = 1.0; ///< E_crust / E; > 0 and not 1
    int material = 1;                   ///< the crust's index in the system's material table
    void validate() const;              ///< throws std::invalid_argument naming the member
};

/// The crust's material: the soil's, Young's modulus times the factor (density and Poisson
/// ratio unchanged).
Material crustMaterial(const Material &soil, const CrustSpec &crust);

/// Height of a settled bed's surface: 98th percentile of grain tops (robust to stray grains).
double bedSurface(const ParticleStore &particles);
/// Why body `body` of `system`, as placed, cannot start, or "" when it can: it cuts a grain by
/// more than half of `max_overlap_ratio` of the grain's radius. Grains stand up to a radius and more above
/// the 98th-percentile surface, so a body placed above that surface can still cut one deep; its
/// first step would push the grain out at once, or stop at the overlap limit with a message
/// about the time step. The message names the body, the grain and the height to add.
std::string startingOverlapError(const DemSystem &system, int body, double max_overlap_ratio);
/// Solid fraction of the bed below its surface: grain volume / (footprint area x (surface -
/// floor)), the floor being the lowest grain bottom.
double packingFraction(const ParticleStore &particles, double footprint_area_m2);

/// Removes every grain whose centre lies above height_m (a blade there carries those off and
/// presses the others down); keeps every other grain's contact histories. Returns how many
/// went; throws if none would be left. Does not settle.
std::size_t strikeOff(DemSystem &system, double height_m);

/// Buries mesh body `body` where it is placed: removes every grain it touches or holds
/// (grainsInMesh), keeping the others' contact histories, as a tool pushed in before the test
/// leaves the grains around it. Returns how many went. Does not settle.
std::size_t bury(DemSystem &system, int body);

struct CompactionReport {
    double target_force_N = 0.0; ///< [N] pressure x footprint area
    double hold_force_N = 0.0;   ///< [N] plate's mean reaction over the second half of the hold
    double time_s = 0.0;         ///< [s] simulated from the plate's approach to its lift-off
    double time_step_s = 0.0;    ///< [s] the press's step: the bed's, or shorter under load
};

/// Compacts the bed under a plate spanning the x-y footprint [lower_m, upper_m] (docs/physics.md
/// §6.1). The system must have no mesh bodies; it has none afterwards. Does not settle.
CompactionReport compact(DemSystem &system, const CompactionSpec &spec, const Vec3 &lower_m,
                         const Vec3 &upper_m);

/// Gives the crust's grains material crust.material, which the system's table must hold as
/// crustMaterial() of their own; returns how many. Throws if the stiffer crust needs a smaller
/// time step (docs/physics.md §3.3). Does not settle.
std::size_t applyCrust(DemSystem &system, const CrustSpec &crust);

} // namespace grainlink::dem
