#pragma once
// Uniform cell grid and a half Verlet list with skin. Each list entry owns the history of its
// pair, so the contact loop touches no hash table; histories are carried across rebuilds and
// re-sorts by stable id (docs/physics.md §4).
#include "grainlink/dem/ContactLaw.hpp"
#include "grainlink/dem/Types.hpp"

#include <cstdint>
#include <utility>
#include <vector>

namespace grainlink::dem {

/// Bins points into cubic cells covering their bounding box (recomputed at every binning).
class CellGrid {
public:
    /// Bins `positions`; `min_cell_size_m` is the smallest admissible edge.
    void bin(const std::vector<Vec3> &positions, double min_cell_size_m);

    Eigen::Vector3i cellCoords(const Vec3 &p) const;
    int cellIndex(const Eigen::Vector3i &c) const {
        return (c.z() * dims_.y() + c.y()) * dims_.x() + c.x();
    }
    const Eigen::Vector3i &dims() const { return dims_; }
    double cellSize() const { return cell_size_; }
    /// Particles of cell c are cell_particles[cell_start[c] .. cell_start[c+1]).
    const std::vector<int> &cellStart() const { return cell_start_; }
    const std::vector<int> &cellParticles() const { return cell_particles_; }
    /// Cell index of particle i at binning time.
    const std::vector<int> &particleCell() const { return particle_cell_; }

private:
    Vec3 origin_ = Vec3::Zero();
    double cell_size_ = 1.0;
    Eigen::Vector3i dims_ = Eigen::Vector3i::Ones();
    std::vector<int> cell_start_, cell_particles_, particle_cell_;
};

/// Pairs (i, j), i < j by storage index, closer than r_i + r_j + skin at build time.
class NeighbourList {
public:
    /// Rebuilds from current positions and carries over histories of pairs that were in contact.
    /// `old_to_new` maps storage indices of the previous build to current ones (empty: identity).
    void build(const std::vector<Vec3> &positions, const std::vector<double> &radii, double skin_m,
               const std::vector<std::size_t> &old_to_new, int threads);

    std::size_t pairCount() const { return neighbour.size(); }
    const CellGrid &grid() const { return grid_; }
    std::uint64_t buildCount() const { return builds_; }
    /// Sets the build counter (it schedules re-sorts), e.g. to continue a checkpointed run.
    void restoreBuildCount(std::uint64_t count) { builds_ = count; }

    /// Keeps the rolling slot's history per entry (EPSD and grain_shape need it); set before
    /// the first build.
    void keepRollingHistory(bool keep) { keep_rolling_ = keep; }
    /// Zeroes every rolling history, listed or waiting for the next build (a new rolling law).
    void clearRollingHistory();
    bool keepsRollingHistory() const { return keep_rolling_; }

    /// Bits of `state`: the pair overlaps; its Coulomb state is sliding.
    static constexpr std::uint8_t kTouching = 1, kSliding = 2;

    // Per-entry history as parallel arrays, so that the contact loop streams only what the
    // contact law uses (docs/physics.md §4). Entries of particle i are [first[i], first[i+1]).
    std::vector<std::size_t> first;
    std::vector<int> owner; ///< i of each entry, so that a loop can walk entries, not rows
    std::vector<int> neighbour;
    std::vector<std::uint8_t> state; ///< kTouching | kSliding; 0 for pairs that do not touch
    std::vector<Vec3> tangential_m;  ///< accumulated tangential displacement of i rel. to j [m]
    std::vector<Vec3> rolling_N_m;   ///< rolling history (ContactHistory); empty unless kept

    /// History of entry k as one value, and back (sets kTouching).
    ContactHistory history(std::size_t k) const {
        ContactHistory h;
        h.tangential_m = tangential_m[k];
        if (keep_rolling_)
            h.rolling_N_m = rolling_N_m[k];
        h.sliding = (state[k] & kSliding) != 0;
        return h;
    }
    void setHistory(std::size_t k, const ContactHistory &h) {
        tangential_m[k] = h.tangential_m;
        if (keep_rolling_)
            rolling_N_m[k] = h.rolling_N_m;
        state[k] = std::uint8_t(kTouching | (h.sliding ? kSliding : 0));
    }

    /// Active contact histories with their particles, for checkpoints.
    struct StoredContact {
        std::size_t i, j;
        ContactHistory history;
    };
    std::vector<StoredContact> activeContacts() const;
    /// Installs histories (i < j) to be merged into the next build.
    void setPendingContacts(std::vector<StoredContact> contacts) { pending_ = std::move(contacts); }

    /// The list with its histories, without the buffers kept for the next build: an in-memory
    /// snapshot (DemSystem::saveState). restore() puts it back, reusing this list's memory.
    struct Saved {
        std::vector<std::size_t> first;
        std::vector<int> owner, neighbour;
        std::vector<std::uint8_t> state;
        std::vector<Vec3> tangential_m, rolling_N_m;
        std::vector<StoredContact> pending;
        std::uint64_t builds = 0;
        bool keep_rolling = false;
    };
    Saved save() const {
        return {first,       owner,    neighbour, state,        tangential_m,
                rolling_N_m, pending_, builds_,   keep_rolling_};
    }
    void restore(const Saved &saved) {
        first = saved.first;
        owner = saved.owner;
        neighbour = saved.neighbour;
        state = saved.state;
        tangential_m = saved.tangential_m;
        rolling_N_m = saved.rolling_N_m;
        pending_ = saved.pending;
        builds_ = saved.builds;
        keep_rolling_ = saved.keep_rolling;
    }

private:
    CellGrid grid_;
    std::vector<StoredContact> pending_;
    std::uint64_t builds_ = 0;
    bool keep_rolling_ = false;
    // The previous build's arrays and per-thread search output, kept to reuse their memory.
    std::vector<std::size_t> old_first_;
    std::vector<int> old_neighbour_;
    std::vector<std::uint8_t> old_state_;
    std::vector<Vec3> old_tangential_, old_rolling_;
    std::vector<std::vector<std::pair<int, int>>> chunk_pairs_; ///< found pairs, per thread
};

} // namespace grainlink::dem
