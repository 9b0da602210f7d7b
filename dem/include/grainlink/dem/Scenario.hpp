#pragma once
// A DEM-only run described by one YAML file (every key in docs/scenario.md).
#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/dem/DemSystem.hpp"
#include "grainlink/dem/Deposition.hpp"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace grainlink::dem {

// The scenario reader and its tests use the strict YAML node under short names.
using config::ConfigError;
using config::ConfigNode;

struct BodySpec {
    std::string name;
    TriangleMesh mesh;
    RigidBodyState start;
    /// If set, the body's lowest point starts this far above the settled bed's surface.
    std::optional<double> clearance_above_bed_m;
    std::vector<MotionSegment> motion; ///< from the start of the run phase (BodyMotion.hpp)
    std::optional<double> friction_coefficient;
    bool record_triangle_loads = false;
};

struct OutputSpec {
    double series_interval_s = 0.01;
    double snapshot_interval_s = 0.0;   ///< 0: no snapshots
    double checkpoint_interval_s = 0.0; ///< 0: no periodic checkpoints
    bool contact_network = false;       ///< force chains beside every particle snapshot
};

/// The slots a contact type sets for itself in `contact_wall` or `contact_tool`; the others are
/// the grain-grain law's (`contact`). A slot given there is the grain-grain slot with the keys
/// given replaced.
struct ContactOverride {
    std::optional<DampingModel> damping;
    std::optional<TangentialModel> tangential;
    std::optional<RollingModel> rolling;
    std::optional<CohesionModel> cohesion;
    bool any() const { return damping || tangential || rolling || cohesion; }
    /// `law` with these slots in place of its own.
    ContactLaw appliedTo(ContactLaw law) const;
};

struct DemScenario {
    std::string file;
    std::string name;
    DemSettings settings;
    ContactLaw law;               ///< `contact`: grain-grain contacts
    ContactOverride contact_wall; ///< grain-wall contacts (planes, boxes)
    ContactOverride contact_tool; ///< grain-tool contacts (mesh bodies)
    Material material;
    std::vector<PlaneWall> planes;
    DepositionSpec deposition;
    std::string packing_cache_directory; ///< empty: no caching
    std::vector<BodySpec> bodies;
    double duration_s = 0.0; ///< run phase after deposition
    OutputSpec output;
    /// [m] coupled soil (`wall_clearance_m`): the run stops when a body comes this close to a
    /// wall; by default one largest grain diameter. Unused by `grainlink dem`.
    double wall_clearance_m = 0.0;
    /// Coupled soil (`bury_bodies`): bodies that start inside the bed remove the grains they
    /// touch or hold (a mole or an anchor placed in the ground before the test) instead of
    /// being refused.
    bool bury_bodies = false;
};

/// Bounds on the counts a scenario may ask for: a typo or a wrapped negative stops at its key
/// instead of exhausting memory (a grain with its contacts costs about 0.5 kB) or crashing a
/// library (libgomp segfaults at 1e5 threads).
constexpr long long kMaxGrains = 50'000'000;
constexpr long long kMaxThreads = 1024;
constexpr long long kMaxLayers = 100'000;

/// The thread count of a `simulation` block: `--threads N` (which sets GRAINLINK_THREADS, so
/// that a run's participant processes follow it too) overrides the scenario's `threads`;
/// without either, OMP_NUM_THREADS; else 1.
int threadsFor(const ConfigNode &sim);

/// The gravity of a `simulation` block: `gravity` (earth, mars, moon, none or a vector) or
/// `gravity_m_s2` (a vector), not both; earth without either.
Vec3 simulationGravity(const ConfigNode &sim);

/// A `deposition` block (the region, count, sizes, settling and preparation); errors name the key.
DepositionSpec parseDeposition(const ConfigNode &node);

/// Reads and validates a scenario; errors name the file, key and line.
DemScenario loadScenario(const std::string &path);
/// `coupled`: the soil section of a coupled run (no `run:`; bodies come from the coupling).
DemScenario parseScenario(const ConfigNode &root, bool coupled = false);

/// The law of each contact type: `contact` with the overrides of `contact_wall`, `contact_tool`.
ContactLaws contactLaws(const DemScenario &scenario);
/// The system without mesh bodies (deposition runs without them).
std::unique_ptr<DemSystem> makeSystem(const DemScenario &scenario);
/// Key of the settled packing: everything that shapes it, nothing that does not.
std::string packingKey(const DemScenario &scenario);

} // namespace grainlink::dem
