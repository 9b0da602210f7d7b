#pragma once
// Grain-mesh contacts: the mesh bodies and their motions, their material-pair properties, the
// candidates ((particle, triangle) pairs within reach, rebuilt when particles and meshes have
// moved a skin), a few history slots per particle, and the grains' reaction on each body
// (docs/physics.md §2.9).
#include "grainlink/dem/ContactKernel.hpp"
#include "grainlink/dem/ContactPass.hpp"
#include "grainlink/dem/NeighbourList.hpp"
#include "grainlink/dem/ParticleStore.hpp"
#include "grainlink/dem/Walls.hpp"

#include <omp.h>

#include <algorithm>
#include <utility>
#include <vector>

namespace grainlink::dem {

/// History of one of a particle's contacts with a mesh.
struct MeshContactSlot {
    int body = -1; ///< -1: free
    int triangle = -1;
    Vec3 normal = Vec3::Zero();
    ContactHistory history;
};

class MeshContacts {
public:
    static constexpr int kSlots = 4; ///< mesh contacts remembered per particle

    /// Adds a body (its material must be set) moving by `motion`; returns its index.
    int add(MeshBody body, BodyMotion motion, double time_s);
    /// The body takes the motion's state at `time_s` now and follows it every step.
    void setMotion(int k, BodyMotion motion, double time_s);
    /// Moves every body that is not held to its motion's state at `time_s`.
    void move(double time_s);
    MeshBody &body(int k) { return bodies_[std::size_t(k)]; }
    const MeshBody &body(int k) const { return bodies_[std::size_t(k)]; }
    int size() const { return int(bodies_.size()); }
    bool empty() const { return bodies_.empty(); }

    /// Properties under `law`, per-thread sums, history slots for `particles`.
    void prepare(const std::vector<Material> &materials, const ContactLaw &law,
                 std::size_t particles, int threads);
    /// Reorders the history slots with the particles; the candidates are rebuilt.
    void permuteHistories(const std::vector<std::size_t> &order);
    /// The candidates are rebuilt before the next contact pass.
    void markStale() { stale_ = true; }
    /// Whether particle displacements are measured against referencePositions().
    bool tracksDisplacement() const { return !bodies_.empty() && (!stale_ || restored_); }
    const std::vector<Vec3> &referencePositions() const { return reference_position_; }
    /// Rebuilds the candidates if stale or if a particle (moved at most
    /// sqrt(max_displacement_sq_m2) since the last build) and a mesh may have closed the skin.
    void update(const ParticleStore &p, double max_displacement_sq_m2, double skin_m, int threads);

    /// The contacts of every particle with a candidate, in one parallel region; each thread
    /// continues its own worst overlap.
    template <class Law>
    void compute(ParticleStore &p, const Law &law, double dt_s, std::vector<WorstOverlap> &worst,
                 int threads);
    /// After compute: each body's force, torque (and triangle loads) summed in thread order,
    /// and its impulse accumulated over `dt_s`.
    void sumLoads(double dt_s, int threads);

    /// Everything that changes while the system runs (DemSystem::saveState); the motions are
    /// inputs, set again by the driver.
    struct State {
        std::vector<MeshContactSlot> slots;
        std::vector<std::size_t> particles, first;
        std::vector<std::pair<int, int>> candidates;
        std::vector<Vec3> reference_position;
        std::vector<RigidBodyState> body_reference, body_state;
        std::vector<BodyLoads> body_loads;
        std::vector<std::vector<Vec3>> triangle_force; ///< per body, where recorded
        bool stale = true, restored = false;
    };
    State state() const;
    void restore(const State &s);

    const std::vector<MeshContactSlot> &slots() const { return slots_; }
    const std::vector<RigidBodyState> &bodyReference() const { return body_reference_; }
    /// Installs a saved state (slots, candidate reference positions and body states): the
    /// candidates are recreated at that reference before the next pass, so that their rebuild
    /// schedule continues as in the run that saved it.
    void restore(std::vector<MeshContactSlot> slots, std::vector<Vec3> reference,
                 std::vector<RigidBodyState> body_reference);
    void clearRollingHistories();
    std::size_t activeContacts() const;

private:
    void moveBody(std::size_t k, double time_s); ///< unless it is held
    /// Candidates of the particles at `positions` and the triangles at `vertices` (per body).
    void build(const ParticleStore &p, const std::vector<Vec3> &positions,
               const std::vector<const std::vector<Vec3> *> &vertices, double skin_m, int threads);

    std::vector<MeshBody> bodies_;
    std::vector<BodyMotion> motions_;
    std::vector<std::vector<PairProperties>> properties_; ///< [body][material]
    std::vector<MeshContactSlot> slots_;                  ///< [particle * kSlots + slot]
    // Candidates, built at reference_position_ with the bodies at body_reference_.
    std::vector<std::size_t> particles_;          ///< particles with candidates
    std::vector<std::size_t> first_;              ///< per entry of particles_, + end
    std::vector<std::pair<int, int>> candidates_; ///< (body, triangle)
    std::vector<Vec3> reference_position_;
    std::vector<RigidBodyState> body_reference_;
    bool stale_ = true;
    bool restored_ = false; ///< reference and slots restored, candidates not yet recreated
    CellGrid grid_;
    std::vector<std::vector<Vec3>> thread_force_, thread_torque_;       ///< [thread][body]
    std::vector<std::vector<std::vector<Vec3>>> thread_triangle_force_; ///< [thread][body][tri]
};

template <class Law>
void MeshContacts::compute(ParticleStore &p, const Law &law, double dt_s,
                           std::vector<WorstOverlap> &worst_by_thread, int threads) {
#pragma omp parallel num_threads(threads)
    {
        const int t = omp_get_thread_num();
        auto &body_force = thread_force_[std::size_t(t)];
        auto &body_torque = thread_torque_[std::size_t(t)];
        auto &triangle_force = thread_triangle_force_[std::size_t(t)];
        std::fill(body_force.begin(), body_force.end(), Vec3::Zero());
        std::fill(body_torque.begin(), body_torque.end(), Vec3::Zero());
        for (auto &loads : triangle_force)
            std::fill(loads.begin(), loads.end(), Vec3::Zero());
        struct Touch {
            int body, triangle;
            Vec3 point;
            double dist;
        };
        constexpr int kMaxTouches = 16;
        Touch touches[kMaxTouches];
        // Nearest first, ties by (body, triangle): the order of the touches, and of which are
        // kept when more than kMaxTouches are in reach.
        const auto nearer = [](const Touch &a, const Touch &b) {
            return a.dist != b.dist
                       ? a.dist < b.dist
                       : (a.body != b.body ? a.body < b.body : a.triangle < b.triangle);
        };
        MeshContactSlot next[kSlots];
        WorstOverlap worst = worst_by_thread[std::size_t(t)]; // the pair pass's
        const std::size_t candidates = particles_.size();
#pragma omp for schedule(static)
        for (std::size_t c_index = 0; c_index < candidates; ++c_index) {
            const std::size_t i = particles_[c_index];
            MeshContactSlot *slots = &slots_[i * kSlots];
            const Vec3 xi = p.position[i];
            const double ri = p.radius[i];
            int count = 0;
            for (std::size_t c = first_[c_index]; c < first_[c_index + 1]; ++c) {
                const auto [b, tri] = candidates_[c];
                const auto &v = bodies_[std::size_t(b)].worldVertices();
                const auto &ids = bodies_[std::size_t(b)].mesh().triangles[std::size_t(tri)];
                const Vec3 q = closestPointOnTriangle(xi, v[ids[0]], v[ids[1]], v[ids[2]]);
                const double dist_sq = (xi - q).squaredNorm();
                if (dist_sq >= ri * ri)
                    continue;
                const Touch touch{b, tri, q, std::sqrt(dist_sq)};
                if (count < kMaxTouches) {
                    touches[count++] = touch;
                    continue;
                }
                // Full (a grain at a vertex many triangles share, such as a disc's centre): the
                // farthest gives way, so the nearest kMaxTouches are kept, the face the grain
                // presses on among them. Keeping the first ones in candidate order could drop it.
                int farthest = 0;
                for (int k = 1; k < count; ++k)
                    if (nearer(touches[farthest], touches[k]))
                        farthest = k;
                if (nearer(touch, touches[farthest]))
                    touches[farthest] = touch;
            }
            // Nearest first. A touch whose point lies in (or behind) the tangent plane of a
            // nearer accepted touch of the same body is that surface again, seen through a
            // neighbouring triangle's edge or vertex (a point shared by two triangles is the
            // extreme case): counting it would add a second, tilted force wherever a sphere
            // overlaps a flat mesh near an edge. Concave corners keep both faces.
            std::sort(touches, touches + count, nearer);
            int used = 0, accepted_count = 0;
            int accepted[kMaxTouches];
            Vec3 accepted_normal[kMaxTouches];
            for (int k = 0; k < count; ++k) {
                const Touch &touch = touches[k];
                bool duplicate = false;
                for (int m = 0; m < accepted_count && !duplicate; ++m) {
                    const Touch &nearer = touches[accepted[m]];
                    duplicate = nearer.body == touch.body &&
                                (touch.point - nearer.point).dot(accepted_normal[m]) <= 1e-9 * ri;
                }
                if (duplicate)
                    continue;
                const Vec3 n_c =
                    touch.dist > 0.0 ? Vec3((xi - touch.point) / touch.dist) : Vec3::UnitZ();
                accepted[accepted_count] = k;
                accepted_normal[accepted_count++] = n_c;
                // Same triangle, or a neighbour of it with the same normal, keeps history.
                ContactHistory h;
                int best = -1;
                for (int s = 0; s < kSlots; ++s)
                    if (slots[s].body == touch.body && slots[s].triangle == touch.triangle)
                        best = s;
                for (int s = 0; s < kSlots && best < 0; ++s)
                    if (slots[s].body == touch.body && slots[s].normal.dot(n_c) > 0.99)
                        best = s;
                if (best >= 0) {
                    h = slots[best].history;
                    slots[best].body = -1; // consumed
                }
                const MeshBody &body = bodies_[std::size_t(touch.body)];
                const ContactGeometry g = wallGeometry(
                    n_c, touch.dist, ri, p.mass[i], p.velocity[i], p.angular_velocity[i],
                    body.state().pointVelocity(touch.point), body.state().angular_velocity_rad_s,
                    Law::kGrainShape ? &p.orientation[i] : nullptr);
                ContactResult r;
                law.evaluate(properties_[std::size_t(touch.body)][std::size_t(p.material[i])], g,
                             dt_s, h, r);
                p.force[i] += r.force_on_i_N;
                p.torque[i] += r.torque_on_i_N_m;
                body_force[std::size_t(touch.body)] -= r.force_on_i_N;
                body_torque[std::size_t(touch.body)] +=
                    (touch.point - body.state().position_m).cross(-r.force_on_i_N) +
                    r.torque_on_j_N_m;
                auto &loads = triangle_force[std::size_t(touch.body)];
                if (!loads.empty())
                    loads[std::size_t(touch.triangle)] -= r.force_on_i_N;
                worst.offer(g.overlap_m, ri, p.id[i], p.id[i], -1, touch.body);
                if (used < kSlots)
                    next[used++] = {touch.body, touch.triangle, n_c, h};
            }
            for (int s = 0; s < kSlots; ++s)
                slots[s] = s < used ? next[s] : MeshContactSlot{};
        }
        worst_by_thread[std::size_t(t)] = worst;
    }
}

} // namespace grainlink::dem
