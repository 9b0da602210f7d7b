#pragma once
// Particle generation, settling and the bed's preparation: the seed's step 1, run once per soil
// setup and cached.
#include "grainlink/dem/BedPreparation.hpp"
#include "grainlink/dem/DemSystem.hpp"

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace grainlink::dem {

/// Grain radius distribution.
struct RadiusDistribution {
    enum class Kind { Constant, Uniform, Discrete } kind = Kind::Constant;
    double min_m = 0.0, max_m = 0.0; ///< Constant uses min_m; Uniform draws in [min, max]
    std::vector<double> radii_m;     ///< Discrete: radii ...
    std::vector<double> fractions;   ///< ... and their number fractions (normalised)
    double largest() const;
    double smallest() const; ///< of the radii drawn with a fraction > 0
    double meanCubedRadius() const; ///< E[r^3] of a drawn grain [m^3]: its mean volume / (4/3 pi)
    void validate() const;
};

/// Deterministic random numbers (SplitMix64): the same seed gives the same packing everywhere.
class Random {
public:
    explicit Random(std::uint64_t seed) : state_(seed) {}
    std::uint64_t next();
    double uniform(); ///< in [0, 1)
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }

private:
    std::uint64_t state_;
};

struct DepositionSpec {
    enum class Method { Random, Rain } method = Method::Random;
    Vec3 region_lower_m = Vec3::Zero(); ///< insertion region (particles lie fully inside)
    Vec3 region_upper_m = Vec3::Zero();
    std::size_t count = 0;
    RadiusDistribution radius;
    int material = 0;
    std::uint64_t seed = 1;
    /// Rain: the region is filled in `layers` batches, each after `layer_interval_s` of fall.
    int layers = 1;
    double layer_interval_s = 0.1;
    /// Settling ends when the mean kinetic energy per particle is below this [J] ...
    double settle_kinetic_energy_J = 1e-9;
    double max_settle_time_s = 5.0; ///< ... or when this much time has passed (then a warning)
    /// Rolling law while the grains settle, if not the run's own: one packing for several
    /// rolling laws. deposit() does not switch laws; its callers do (prepareSoil, the repose
    /// test): DemSystem::setRolling before deposit() and back to the run's law after it.
    std::optional<RollingModel> rolling;
    /// Gravity while the grains settle and the bed is prepared, if not the run's own: a slope is
    /// run by tilting the run's gravity on a bed settled level (docs/scenario.md).
    std::optional<Vec3> gravity_m_s2;
    // The settled bed's preparation, in this order, each followed by settling again
    // (docs/physics.md §6.1): struck off, compacted, given a crust.
    std::optional<double> strike_off_height_m; ///< [m] grains with centres above it go
    std::optional<CompactionSpec> compaction;
    std::optional<CrustSpec> crust;
    std::string describe() const;
};

struct DepositionReport {
    std::size_t inserted = 0;
    double settle_time_s = 0.0; ///< [s] simulated while raining and settling
    double final_kinetic_energy_per_particle_J = 0.0;
    bool settled = false;
    double packing_fraction_settled = 0.0; ///< after the first settling
    double packing_fraction = 0.0;         ///< of the finished bed
    std::size_t struck_off = 0;            ///< grains removed by the strike-off
    std::optional<CompactionReport> compaction;
    std::size_t crust_grains = 0;
    /// One line on the preparation (empty when the bed was only settled).
    std::string preparationSummary() const;
};

/// Inserts up to `count` non-overlapping spheres in the region (also avoiding existing
/// particles); returns how many fitted. Throws if fewer than 99 % fit (region too small).
std::size_t insertRandom(DemSystem &system, const DepositionSpec &spec, Random &random,
                         std::size_t count, const Vec3 &lower_m, const Vec3 &upper_m);

/// Inserts, settles and prepares; `progress` is called every few hundred steps with the report
/// so far. The packing fraction's footprint is the region's x-y rectangle.
DepositionReport deposit(DemSystem &system, const DepositionSpec &spec,
                         const std::function<void(const DepositionReport &)> &progress = {});

/// 64-bit FNV-1a of a text, as 16 hex digits (keys of the packing cache).
std::string hashKey(const std::string &text);

} // namespace grainlink::dem
