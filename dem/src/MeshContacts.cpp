#include "grainlink/dem/MeshContacts.hpp"

#include <cmath>

namespace grainlink::dem {

int MeshContacts::add(MeshBody body, BodyMotion motion, double time_s) {
    body.material.validate();
    bodies_.push_back(std::move(body));
    motions_.emplace_back();
    setMotion(int(bodies_.size() - 1), std::move(motion), time_s);
    stale_ = true;
    restored_ = false;
    return int(bodies_.size() - 1);
}

void MeshContacts::setMotion(int k, BodyMotion motion, double time_s) {
    motions_[std::size_t(k)] = std::move(motion);
    moveBody(std::size_t(k), time_s);
}

void MeshContacts::move(double time_s) {
    for (std::size_t b = 0; b < bodies_.size(); ++b)
        moveBody(b, time_s);
}

void MeshContacts::moveBody(std::size_t k, double time_s) {
    if (const auto *segmented = std::get_if<SegmentedMotion>(&motions_[k]))
        bodies_[k].setState(segmented->at(time_s));
    else if (const auto *window = std::get_if<WindowMotion>(&motions_[k]))
        bodies_[k].setState(window->at(time_s));
}

void MeshContacts::prepare(const std::vector<Material> &materials, const ContactLaw &law,
                           std::size_t particles, int threads) {
    properties_.assign(bodies_.size(), {});
    for (std::size_t b = 0; b < bodies_.size(); ++b)
        for (const Material &m : materials)
            properties_[b].push_back(
                bodies_[b].friction_coefficient
                    ? pairProperties(m, bodies_[b].material, law, *bodies_[b].friction_coefficient)
                    : pairProperties(m, bodies_[b].material, law));
    thread_force_.resize(std::size_t(threads));
    thread_torque_.resize(std::size_t(threads));
    for (std::size_t t = 0; t < std::size_t(threads); ++t) {
        thread_force_[t] = perThreadSums(bodies_.size());
        thread_torque_[t] = perThreadSums(bodies_.size());
    }
    thread_triangle_force_.assign(std::size_t(threads), {});
    for (auto &per_thread : thread_triangle_force_)
        for (const MeshBody &b : bodies_)
            per_thread.emplace_back(b.record_triangle_loads ? b.mesh().triangleCount() : 0,
                                    Vec3::Zero());
    slots_.resize(particles * kSlots);
    if (reference_position_.size() != particles || body_reference_.size() != bodies_.size())
        restored_ = false; // particles or bodies added since: rebuilt afresh
    body_reference_.resize(bodies_.size());
}

void MeshContacts::permuteHistories(const std::vector<std::size_t> &order) {
    std::vector<MeshContactSlot> permuted(slots_.size());
    for (std::size_t k = 0; k < order.size(); ++k)
        for (int s = 0; s < kSlots; ++s)
            permuted[k * kSlots + s] = slots_[order[k] * kSlots + s];
    slots_.swap(permuted);
    stale_ = true;
    restored_ = false;
}

void MeshContacts::update(const ParticleStore &p, double max_displacement_sq_m2, double skin_m,
                          int threads) {
    if (bodies_.empty())
        return;
    if (restored_) {
        // The candidates of the saved reference: the bodies' vertices where they were then.
        std::vector<std::vector<Vec3>> placed(bodies_.size());
        std::vector<const std::vector<Vec3> *> vertices;
        for (std::size_t b = 0; b < bodies_.size(); ++b) {
            bodies_[b].worldVerticesAt(body_reference_[b], placed[b]);
            vertices.push_back(&placed[b]);
        }
        build(p, reference_position_, vertices, skin_m, threads);
        restored_ = false;
        stale_ = false;
    }
    // A particle-triangle pair may approach by the particle's and the mesh's displacement.
    double body_move = 0.0;
    for (std::size_t b = 0; b < bodies_.size() && !stale_; ++b) {
        const RigidBodyState &now = bodies_[b].state(), &ref = body_reference_[b];
        const double angle =
            2.0 *
            std::acos(std::min(1.0, std::abs((now.orientation * ref.orientation.conjugate()).w())));
        body_move = std::max(body_move, (now.position_m - ref.position_m).norm() +
                                            angle * bodies_[b].boundingRadius());
    }
    if (stale_ || std::sqrt(max_displacement_sq_m2) + body_move > skin_m) {
        std::vector<const std::vector<Vec3> *> vertices;
        for (const MeshBody &body : bodies_)
            vertices.push_back(&body.worldVertices());
        build(p, p.position, vertices, skin_m, threads);
        reference_position_ = p.position;
        for (std::size_t b = 0; b < bodies_.size(); ++b)
            body_reference_[b] = bodies_[b].state();
        stale_ = false;
    }
}

void MeshContacts::build(const ParticleStore &p, const std::vector<Vec3> &positions,
                         const std::vector<const std::vector<Vec3> *> &vertices, double skin_m,
                         int threads) {
    const std::size_t n = p.size();
    const double r_max = p.maxRadius();
    grid_.bin(positions, 2.0 * r_max + skin_m);
    const auto &start = grid_.cellStart();
    const auto &members = grid_.cellParticles();
    // Triangles are shared out among threads; the sort below makes the result independent of
    // the thread count.
    std::vector<std::pair<int, int>> triangles;
    for (std::size_t b = 0; b < bodies_.size(); ++b)
        for (std::size_t t = 0; t < bodies_[b].mesh().triangles.size(); ++t)
            triangles.push_back({int(b), int(t)});
    using Found = std::vector<std::pair<std::size_t, std::pair<int, int>>>;
    std::vector<Found> found_by(static_cast<std::size_t>(threads));
#pragma omp parallel for schedule(static) num_threads(threads)
    for (std::size_t k = 0; k < triangles.size(); ++k) {
        auto &found = found_by[std::size_t(omp_get_thread_num())];
        const auto [b, t] = triangles[k];
        const auto &v = *vertices[std::size_t(b)];
        const auto &tri = bodies_[std::size_t(b)].mesh().triangles[std::size_t(t)];
        const Vec3 &a = v[tri[0]], &bb = v[tri[1]], &c = v[tri[2]];
        const Vec3 pad = Vec3::Constant(r_max + skin_m);
        const Eigen::Vector3i lo = grid_.cellCoords(a.cwiseMin(bb).cwiseMin(c) - pad);
        const Eigen::Vector3i hi = grid_.cellCoords(a.cwiseMax(bb).cwiseMax(c) + pad);
        const Vec3 normal = (bb - a).cross(c - a).normalized();
        for (int z = lo.z(); z <= hi.z(); ++z)
            for (int y = lo.y(); y <= hi.y(); ++y)
                for (int x = lo.x(); x <= hi.x(); ++x) {
                    const int cell = grid_.cellIndex({x, y, z});
                    for (int m = start[cell]; m < start[cell + 1]; ++m) {
                        const std::size_t i = std::size_t(members[m]);
                        const Vec3 &x_i = positions[i];
                        const double reach = p.radius[i] + skin_m;
                        // Cheap plane test first: most cell members are far off the plane.
                        if (std::abs((x_i - a).dot(normal)) >= reach)
                            continue;
                        if ((closestPointOnTriangle(x_i, a, bb, c) - x_i).squaredNorm() <
                            reach * reach)
                            found.push_back({i, {b, t}});
                    }
                }
    }
    Found found;
    for (const Found &part : found_by)
        found.insert(found.end(), part.begin(), part.end());
    std::sort(found.begin(), found.end());
    std::vector<std::size_t> first(n + 1, 0);
    candidates_.clear();
    for (const auto &f : found) {
        ++first[f.first + 1];
        candidates_.push_back(f.second);
    }
    for (std::size_t i = 0; i < n; ++i)
        first[i + 1] += first[i];
    // Particles out of every mesh's reach drop their mesh histories (they cannot touch).
    for (std::size_t i = 0; i < n; ++i)
        if (first[i] == first[i + 1] && slots_[i * kSlots].body >= 0)
            for (int s = 0; s < kSlots; ++s)
                slots_[i * kSlots + s] = MeshContactSlot{};
    particles_.clear();
    first_.clear();
    for (std::size_t i = 0; i < n; ++i)
        if (first[i] < first[i + 1]) {
            particles_.push_back(i);
            first_.push_back(first[i]);
        }
    first_.push_back(first[n]);
}

void MeshContacts::sumLoads(double dt_s, int threads) {
    for (std::size_t b = 0; b < bodies_.size(); ++b) {
        MeshBody &body = bodies_[b];
        body.force_N.setZero();
        body.torque_N_m.setZero();
        for (int t = 0; t < threads; ++t) {
            body.force_N += thread_force_[std::size_t(t)][b];
            body.torque_N_m += thread_torque_[std::size_t(t)][b];
        }
        if (body.record_triangle_loads) {
            std::fill(body.triangle_force_N.begin(), body.triangle_force_N.end(), Vec3::Zero());
            for (int t = 0; t < threads; ++t)
                for (std::size_t k = 0; k < body.triangle_force_N.size(); ++k)
                    body.triangle_force_N[k] += thread_triangle_force_[std::size_t(t)][b][k];
        }
        body.impulse_N_s += dt_s * body.force_N;
        body.angular_impulse_N_m_s += dt_s * body.torque_N_m;
        body.accumulated_time_s += dt_s;
    }
}

void MeshContacts::restore(std::vector<MeshContactSlot> slots, std::vector<Vec3> reference,
                           std::vector<RigidBodyState> body_reference) {
    slots_ = std::move(slots);
    reference_position_ = std::move(reference);
    body_reference_ = std::move(body_reference);
    stale_ = true;
    restored_ = true;
}

MeshContacts::State MeshContacts::state() const {
    State s{slots_, particles_, first_, candidates_, reference_position_, body_reference_, {},
            {},     {},         stale_, restored_};
    for (const MeshBody &b : bodies_) {
        s.body_state.push_back(b.state());
        s.body_loads.push_back(b.loads());
        s.triangle_force.push_back(b.triangle_force_N);
    }
    return s;
}

void MeshContacts::restore(const State &s) {
    slots_ = s.slots;
    particles_ = s.particles;
    first_ = s.first;
    candidates_ = s.candidates;
    reference_position_ = s.reference_position;
    body_reference_ = s.body_reference;
    stale_ = s.stale;
    restored_ = s.restored;
    for (std::size_t b = 0; b < bodies_.size(); ++b) {
        bodies_[b].restoreState(s.body_state[b]);
        bodies_[b].setLoads(s.body_loads[b]);
        bodies_[b].triangle_force_N = s.triangle_force[b];
    }
}

void MeshContacts::clearRollingHistories() {
    for (MeshContactSlot &slot : slots_)
        slot.history.rolling_N_m.setZero();
}

std::size_t MeshContacts::activeContacts() const {
    std::size_t count = 0;
    for (const MeshContactSlot &s : slots_)
        count += s.body >= 0 ? 1 : 0;
    return count;
}

} // namespace grainlink::dem
