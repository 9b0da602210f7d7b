#pragma once
// Grain-plane contacts: the planes, their material-pair properties (with the friction track's),
// the candidates (planes within reach of each particle at the last list rebuild), one history
// per (particle, plane) and the reaction of the grains on each plane (docs/physics.md §2.9).
#include "grainlink/dem/ContactKernel.hpp"
#include "grainlink/dem/ContactPass.hpp"
#include "grainlink/dem/ParticleStore.hpp"
#include "grainlink/dem/Walls.hpp"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace grainlink::dem {

class PlaneContacts {
public:
    /// Adds a plane (normal normalized); its material must be set. Returns its index.
    int add(PlaneWall wall);
    std::vector<PlaneWall> &planes() { return planes_; }
    const std::vector<PlaneWall> &planes() const { return planes_; }
    std::size_t size() const { return planes_.size(); }
    /// Reaction force of the particles on plane k during the last step [N].
    const Vec3 &force(int k) const { return force_[std::size_t(k)]; }
    const std::vector<Vec3> &forces() const { return force_; }
    void setForces(std::vector<Vec3> forces) { force_ = std::move(forces); }

private:
    struct Candidate {
        std::size_t particle, plane;
    };

public:
    /// Properties under `law` and per-thread sums; histories laid out for `particles` (a changed
    /// plane count changes the layout, and those histories start afresh).
    void prepare(const std::vector<Material> &materials, const ContactLaw &law,
                 std::size_t particles, int threads);
    /// Reorders the histories with the particles (new index k holds old index order[k]).
    void permuteHistories(const std::vector<std::size_t> &order);
    /// Planes within reach (radius + skin) of each particle at `positions`; the others cannot
    /// touch it before the next list rebuild, so their history lapses now.
    void updateCandidates(const std::vector<Vec3> &positions, const std::vector<double> &radii,
                          double skin_m, int threads);
    /// Adds each particle's estimated contact work to `work` (12 per candidate plane).
    void estimateWork(std::vector<std::uint64_t> &work) const;

    /// One thread's plane contacts, fused into its pair pass (PairContacts::threadPass calls
    /// it as its `rows_done`): a particle's are handled right after its row of pairs, while its
    /// data are in cache; its force then sums pairs, then planes.
    template <class Law> class ThreadPass;
    template <class Law>
    ThreadPass<Law> threadPass(int t, std::size_t begin, std::size_t end, ParticleStore &p,
                               const Law &law, double dt_s) {
        return ThreadPass<Law>(*this, t, begin, end, p, law, dt_s);
    }
    /// After the pass: the threads' plane forces summed in thread order.
    void sumForces(int threads);

    /// Everything that changes while the system runs (DemSystem::saveState).
    struct State {
        std::vector<ContactHistory> history;
        std::size_t history_planes = 0;
        std::vector<Candidate> candidates;
        std::vector<Vec3> force;
    };
    State state() const { return {history_, history_planes_, candidates_, force_}; }
    void restore(const State &s);

    const std::vector<ContactHistory> &histories() const { return history_; }
    void setHistories(std::vector<ContactHistory> histories);
    void clearRollingHistories();
    std::size_t activeContacts() const;
    /// Adds the stored elastic energy of the contacts to `energy_J`.
    void addElasticEnergy(const ParticleStore &p, const ContactLaw &law, double &energy_J) const;

private:
    double distance(const Vec3 &x, std::size_t plane) const {
        return (x - planes_[plane].point_m).dot(planes_[plane].normal);
    }

    std::vector<PlaneWall> planes_;
    std::size_t materials_ = 0;
    /// [plane][material], then [plane][materials + material] on the plane's friction track
    std::vector<std::vector<PairProperties>> properties_;
    std::vector<ContactHistory> history_; ///< [particle * planes + plane]
    std::size_t history_planes_ = 0;      ///< plane count history_ is laid out for
    std::vector<std::uint64_t> mask_;     ///< planes within reach, bit per plane
    std::vector<Candidate> candidates_;   ///< the masks as a list, in particle order
    std::vector<Vec3> force_;
    std::vector<std::vector<Vec3>> thread_force_; ///< [thread][plane]
};

template <class Law> class PlaneContacts::ThreadPass {
public:
    ThreadPass(PlaneContacts &planes, int t, std::size_t begin, std::size_t end, ParticleStore &p,
               const Law &law, double dt_s)
        : planes_(planes), p_(p), law_(law), dt_s_(dt_s),
          force_sum_(planes.thread_force_[std::size_t(t)]) {
        std::fill(force_sum_.begin(), force_sum_.end(), Vec3::Zero());
        const auto by_particle = [](const Candidate &c, std::size_t i) { return c.particle < i; };
        const auto &all = planes.candidates_;
        const auto first = std::lower_bound(all.begin(), all.end(), begin, by_particle);
        next_ = std::size_t(first - all.begin());
        end_ = std::size_t(std::lower_bound(first, all.end(), end, by_particle) - all.begin());
    }

    /// The contacts of the thread's particles below `limit` not handled yet.
    void operator()(std::size_t limit, WorstOverlap &worst) {
        const Candidate *__restrict candidate = planes_.candidates_.data();
        std::size_t stop = next_;
        while (stop < end_ && candidate[stop].particle < limit)
            ++stop;
        Vec3 *__restrict force = p_.force.data();
        Vec3 *__restrict torque = p_.torque.data();
        const Vec3 *__restrict position = p_.position.data();
        const Vec3 *__restrict velocity = p_.velocity.data();
        const Vec3 *__restrict spin = p_.angular_velocity.data();
        const double *__restrict radius = p_.radius.data();
        const int *__restrict material = p_.material.data();
        ContactHistory *__restrict history = planes_.history_.data();
        const std::size_t np = planes_.planes_.size(), nm = planes_.materials_;
        std::size_t overlapping[kContactBatch], apart[kContactBatch];
        for (std::size_t c0 = next_; c0 < stop; c0 += kContactBatch) {
            const std::size_t c1 = std::min(c0 + kContactBatch, stop);
            std::size_t count = 0, apart_count = 0;
            for (std::size_t c = c0; c < c1; ++c) {
                // Histories of the few particles at walls are scattered over a large array:
                // fetch them now, for the contacts below.
                const std::size_t i = candidate[c].particle;
                const ContactHistory *h = &history[i * np + candidate[c].plane];
                __builtin_prefetch(h, 1);
                __builtin_prefetch(reinterpret_cast<const char *>(h + 1) - 1, 1);
                __builtin_prefetch(&p_.mass[i]);
                const unsigned touches =
                    planes_.distance(position[i], candidate[c].plane) < radius[i];
                overlapping[count] = c;
                count += touches;
                apart[apart_count] = c;
                apart_count += touches ^ 1u;
            }
            // Candidates apart from their plane: an active history lapses.
            for (std::size_t k = 0; k < apart_count; ++k) {
                ContactHistory &h =
                    history[candidate[apart[k]].particle * np + candidate[apart[k]].plane];
                if (h.active())
                    h = ContactHistory{};
            }
            for (std::size_t k = 0; k < count; ++k) {
                const std::size_t i = candidate[overlapping[k]].particle;
                const std::size_t w = candidate[overlapping[k]].plane;
                const PlaneWall &wall = planes_.planes_[w];
                ContactHistory &h = history[i * np + w];
                const double ri = radius[i];
                const double dist = planes_.distance(position[i], w);
                const ContactGeometry g = wallGeometry(
                    wall.normal, dist, ri, p_.mass[i], velocity[i], spin[i], Vec3::Zero(),
                    Vec3::Zero(), Law::kGrainShape ? &p_.orientation[i] : nullptr);
                const Vec3 contact_point = position[i] - dist * wall.normal;
                std::size_t slot = std::size_t(material[i]);
                if (wall.track && wall.track->contains(contact_point))
                    slot += nm;
                ContactResult r;
                law_.evaluate(planes_.properties_[w][slot], g, dt_s_, h, r);
                force[i] += r.force_on_i_N;
                torque[i] += r.torque_on_i_N_m;
                force_sum_[w] -= r.force_on_i_N;
                worst.offer(g.overlap_m, ri, p_.id[i], p_.id[i], int(w));
            }
        }
        next_ = stop;
    }

private:
    PlaneContacts &planes_;
    ParticleStore &p_;
    const Law &law_;
    double dt_s_;
    std::vector<Vec3> &force_sum_; ///< this thread's reaction on each plane
    std::size_t next_ = 0, end_ = 0;
};

} // namespace grainlink::dem
