#pragma once
// Grain-grain contacts: the neighbour list (candidates and their histories), the material-pair
// properties, the list's reference positions and the split of the particles between the
// threads of the contact pass (docs/physics.md §2, §4, §5).
#include "grainlink/dem/ContactKernel.hpp"
#include "grainlink/dem/ContactPass.hpp"
#include "grainlink/dem/NeighbourList.hpp"
#include "grainlink/dem/ParticleStore.hpp"

#include <omp.h>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace grainlink::dem {

/// One grain-grain contact of the contact network.
struct PairForce {
    std::size_t i = 0, j = 0;
    double normal_force_N = 0.0;
};

class PairContacts {
public:
    /// Material-pair properties under `law` and per-thread buffers; `law` decides whether the
    /// list keeps rolling histories (set before the first build).
    void prepare(const std::vector<Material> &materials, const ContactLaw &law, int threads);
    const PairProperties &properties(int material_i, int material_j) const {
        return properties_[std::size_t(material_i) * materials_ + std::size_t(material_j)];
    }

    NeighbourList &list() { return list_; }
    const NeighbourList &list() const { return list_; }
    /// Positions at the last list build: the list holds while no particle moved skin/2 away.
    const std::vector<Vec3> &referencePositions() const { return reference_position_; }
    bool hasReference(std::size_t particles) const {
        return reference_position_.size() == particles;
    }

    /// Rebuilds the list at the current positions; `old_to_new` maps a re-sort (empty: none).
    void rebuild(const ParticleStore &p, double skin_m, const std::vector<std::size_t> &old_to_new,
                 int threads);
    /// Recreates the list at the reference positions of a restored state, so that the rebuild
    /// schedule and the storage order continue as in the run that saved it (not counted as a
    /// build: the build count schedules re-sorts).
    void rebuildAtReference(const ParticleStore &p, double skin_m, int threads);
    /// Installs a saved state: its active contacts (merged into the next build), reference
    /// positions, build count and thread split.
    void restore(std::vector<NeighbourList::StoredContact> contacts, std::vector<Vec3> reference,
                 std::uint64_t builds, std::vector<std::size_t> split);

    /// Adds each particle's estimated contact work (listed pairs, those touching) to `work`.
    void estimateWork(std::vector<std::uint64_t> &work) const;
    /// Splits the particles into thread ranges of about equal `work`.
    void splitThreads(const std::vector<std::uint64_t> &work, int threads);
    bool splitFits(int threads, std::size_t particles) const {
        return split_.size() == std::size_t(threads) + 1 && split_.back() == particles;
    }
    const std::vector<std::size_t> &split() const { return split_; }
    std::size_t begin(int thread) const { return split_[std::size_t(thread)]; }
    std::size_t end(int thread) const { return split_[std::size_t(thread) + 1]; }

    /// The contacts of thread t's particles [begin(t), end(t)), called inside a parallel region.
    /// Forces on the thread's own particles are written directly, reactions on later threads'
    /// particles go to a side list (addSideContributions). `rows_done(limit, worst)` is called
    /// whenever the rows of all the thread's particles below `limit` are complete, and at the
    /// end with end(t): another pass can handle those particles while their data are in cache.
    template <class Law, class RowsDone>
    void threadPass(int t, ParticleStore &p, const Law &law, double dt_s, WorstOverlap &worst,
                    RowsDone &&rows_done);
    /// After threadPass in every thread: adds earlier threads' side lists to thread t's own
    /// particles, in thread order (deterministic). Contains a barrier.
    void addSideContributions(int t, int threads, ParticleStore &p) const;

    /// Everything that changes while the system runs (DemSystem::saveState).
    struct State {
        NeighbourList::Saved list;
        std::vector<Vec3> reference_position;
        std::vector<std::size_t> split;
    };
    State state() const { return {list_.save(), reference_position_, split_}; }
    void restore(const State &s) {
        list_.restore(s.list);
        reference_position_ = s.reference_position;
        split_ = s.split;
    }

    std::size_t contactCount(const ParticleStore &p) const;
    /// Adds the stored elastic energy of the contacts to `energy_J`.
    void addElasticEnergy(const ParticleStore &p, const ContactLaw &law, double &energy_J) const;
    /// Every touching pair (i < j by storage index) with its Hertz elastic normal force
    /// 4/3 E* sqrt(R*) delta^(3/2): the force chains of a snapshot.
    std::vector<PairForce> touchingPairs(const ParticleStore &p) const;

private:
    /// visit(i, j, entry, R*, overlap) for every listed pair that overlaps now.
    template <class Visit> void forEachTouching(const ParticleStore &p, Visit &&visit) const;
    /// Reaction on a particle owned by a later thread, added after the pair loop.
    struct SideContribution {
        std::size_t particle;
        Vec3 force_N;
        Vec3 torque_N_m;
    };

    std::vector<PairProperties> properties_; ///< materials x materials
    std::size_t materials_ = 0;
    NeighbourList list_;
    std::vector<Vec3> reference_position_;
    std::vector<std::size_t> split_; ///< thread t owns particles [split[t], split[t+1])
    std::vector<std::vector<SideContribution>> side_; ///< [thread]
};

template <class Law, class RowsDone>
void PairContacts::threadPass(int t, ParticleStore &p, const Law &law, double dt_s,
                              WorstOverlap &worst_out, RowsDone &&rows_done) {
    const std::size_t begin = split_[std::size_t(t)];
    const std::size_t end = split_[std::size_t(t) + 1];
    auto &side = side_[std::size_t(t)];
    side.clear();
    // Raw, non-aliasing pointers: the stores to forces then cannot force reloads of the
    // arrays' addresses from the store object inside the loop.
    Vec3 *__restrict force = p.force.data();
    Vec3 *__restrict torque = p.torque.data();
    const Vec3 *__restrict position = p.position.data();
    const Vec3 *__restrict velocity = p.velocity.data();
    const Vec3 *__restrict spin = p.angular_velocity.data();
    const double *__restrict radius = p.radius.data();
    const double *__restrict inv_mass = p.inv_mass.data();
    const int *__restrict material = p.material.data();
    const int *__restrict neighbour = list_.neighbour.data();
    std::uint8_t *__restrict state = list_.state.data();
    Vec3 *__restrict tangential_history = list_.tangential_m.data();
    Vec3 *__restrict rolling_history = list_.rolling_N_m.data();
    const int *__restrict owner = list_.owner.data();
    const PairProperties *__restrict properties = properties_.data();
    const std::size_t materials = materials_;
    WorstOverlap worst = worst_out;
    // Entries are walked in order, in batches, not row by row: rows are short (4 pairs) and of
    // varying length, and each row's end would be a mispredicted branch.
    std::size_t overlapping[kContactBatch], lost[kContactBatch];
    const std::size_t k_end = list_.first[end];
    for (std::size_t k0 = list_.first[begin]; k0 < k_end; k0 += kContactBatch) {
        const std::size_t k1 = std::min(k0 + kContactBatch, k_end);
        // 1. Which listed pairs overlap, and which contacts were just lost, without a branch on
        //    either answer: about half the pairs overlap, unpredictably.
        std::size_t count = 0, lost_count = 0;
        for (std::size_t k = k0; k < k1; ++k) {
            const std::size_t i = std::size_t(owner[k]);
            const std::size_t j = std::size_t(neighbour[k]);
            const double r_sum = radius[i] + radius[j];
            const unsigned overlaps = (position[i] - position[j]).squaredNorm() < r_sum * r_sum;
            overlapping[count] = k;
            count += overlaps;
            lost[lost_count] = k;
            lost_count += unsigned(state[k] != 0) & (overlaps ^ 1u);
        }
        // A contact just lost drops its history.
        for (std::size_t c = 0; c < lost_count; ++c) {
            state[lost[c]] = 0;
            tangential_history[lost[c]].setZero();
            if constexpr (Law::kRollingHistory)
                rolling_history[lost[c]].setZero();
        }
        // 2. The contacts, in entry order: forces on i and j are summed in that order.
        for (std::size_t c = 0; c < count; ++c) {
            const std::size_t k = overlapping[c];
            const std::size_t i = std::size_t(owner[k]);
            const std::size_t j = std::size_t(neighbour[k]);
            const double ri = radius[i], rj = radius[j];
            const ContactGeometry g = pairGeometry(
                position[i], position[j], ri, rj, inv_mass[i], inv_mass[j], velocity[i],
                velocity[j], spin[i], spin[j], Law::kGrainShape ? &p.orientation[i] : nullptr,
                Law::kGrainShape ? &p.orientation[j] : nullptr);
            ContactHistory h;
            h.tangential_m = tangential_history[k];
            if constexpr (Law::kRollingHistory)
                h.rolling_N_m = rolling_history[k];
            h.sliding = (state[k] & NeighbourList::kSliding) != 0;
            ContactResult r;
            law.evaluate(
                properties[std::size_t(material[i]) * materials + std::size_t(material[j])], g,
                dt_s, h, r);
            tangential_history[k] = h.tangential_m;
            if constexpr (Law::kRollingHistory)
                rolling_history[k] = h.rolling_N_m;
            state[k] =
                std::uint8_t(NeighbourList::kTouching | (h.sliding ? NeighbourList::kSliding : 0));
            force[i] += r.force_on_i_N;
            torque[i] += r.torque_on_i_N_m;
            if (j < end) {
                force[j] -= r.force_on_i_N;
                torque[j] += r.torque_on_j_N_m;
            } else {
                side.push_back({j, -r.force_on_i_N, r.torque_on_j_N_m});
            }
            worst.offer(g.overlap_m, std::min(ri, rj), p.id[i], p.id[j]);
        }
        // Rows before the one the next batch starts in are complete.
        if (k1 < k_end)
            rows_done(std::size_t(owner[k1]), worst);
    }
    rows_done(end, worst);
    worst_out = worst;
}

} // namespace grainlink::dem
