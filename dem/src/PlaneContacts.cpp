#include "grainlink/dem/PlaneContacts.hpp"

#include <stdexcept>

namespace grainlink::dem {

int PlaneContacts::add(PlaneWall wall) {
    if (!(wall.normal.norm() > 0.0))
        throw std::invalid_argument("plane '" + wall.name + "' has a zero normal");
    wall.normal.normalize();
    wall.material.validate();
    planes_.push_back(std::move(wall));
    return int(planes_.size() - 1);
}

void PlaneContacts::prepare(const std::vector<Material> &materials, const ContactLaw &law,
                            std::size_t particles, int threads) {
    if (planes_.size() > 64)
        throw std::invalid_argument("at most 64 planes are supported; use a mesh for more");
    materials_ = materials.size();
    properties_.assign(planes_.size(), {});
    for (std::size_t w = 0; w < planes_.size(); ++w) {
        const PlaneWall &p = planes_[w];
        for (const Material &m : materials)
            properties_[w].push_back(
                p.friction_coefficient ? pairProperties(m, p.material, law, *p.friction_coefficient)
                                       : pairProperties(m, p.material, law));
        for (std::size_t k = 0; k < materials.size() && p.track; ++k)
            properties_[w].push_back(
                pairProperties(materials[k], p.material, law, p.track->friction_coefficient));
    }
    force_.resize(planes_.size(), Vec3::Zero()); // a restored state keeps its last forces
    thread_force_.resize(std::size_t(threads));
    for (auto &sums : thread_force_)
        sums = perThreadSums(planes_.size());
    // New particles are appended, so per-particle blocks keep their place; histories may
    // already be restored from a checkpoint.
    if (history_planes_ != planes_.size())
        history_.clear();
    history_planes_ = planes_.size();
    history_.resize(particles * planes_.size());
}

void PlaneContacts::permuteHistories(const std::vector<std::size_t> &order) {
    const std::size_t np = planes_.size();
    std::vector<ContactHistory> permuted(history_.size());
    for (std::size_t k = 0; k < order.size(); ++k)
        for (std::size_t w = 0; w < np; ++w)
            permuted[k * np + w] = history_[order[k] * np + w];
    history_.swap(permuted);
}

void PlaneContacts::updateCandidates(const std::vector<Vec3> &positions,
                                     const std::vector<double> &radii, double skin_m, int threads) {
    const std::size_t n = positions.size(), np = planes_.size();
    mask_.assign(n, 0);
#pragma omp parallel for schedule(static) num_threads(threads)
    for (std::size_t i = 0; i < n; ++i) {
        std::uint64_t mask = 0;
        for (std::size_t w = 0; w < np; ++w) {
            if (distance(positions[i], w) < radii[i] + skin_m)
                mask |= std::uint64_t(1) << w;
            else if (history_[i * np + w].active())
                history_[i * np + w] = ContactHistory{};
        }
        mask_[i] = mask;
    }
    // The same as a list of (particle, plane) in particle order, walked by the contact loop.
    candidates_.clear();
    for (std::size_t i = 0; i < n; ++i)
        for (std::uint64_t mask = mask_[i]; mask != 0; mask &= mask - 1)
            candidates_.push_back({i, std::size_t(__builtin_ctzll(mask))});
}

void PlaneContacts::estimateWork(std::vector<std::uint64_t> &work) const {
    for (const Candidate &c : candidates_)
        work[c.particle] += 12;
}

void PlaneContacts::sumForces(int threads) {
    for (std::size_t w = 0; w < planes_.size(); ++w) {
        force_[w].setZero();
        for (int t = 0; t < threads; ++t)
            force_[w] += thread_force_[std::size_t(t)][w];
    }
}

void PlaneContacts::restore(const State &s) {
    history_ = s.history;
    history_planes_ = s.history_planes;
    candidates_ = s.candidates;
    force_ = s.force;
}

void PlaneContacts::setHistories(std::vector<ContactHistory> histories) {
    history_ = std::move(histories);
    history_planes_ = planes_.size();
}

void PlaneContacts::clearRollingHistories() {
    for (ContactHistory &h : history_)
        h.rolling_N_m.setZero();
}

std::size_t PlaneContacts::activeContacts() const {
    std::size_t count = 0;
    for (const ContactHistory &h : history_)
        count += h.active() ? 1 : 0;
    return count;
}

void PlaneContacts::addElasticEnergy(const ParticleStore &p, const ContactLaw &law,
                                     double &energy_J) const {
    if (properties_.empty())
        return;
    for (std::size_t i = 0; i < p.size(); ++i)
        for (std::size_t w = 0; w < planes_.size(); ++w) {
            const double overlap = p.radius[i] - distance(p.position[i], w);
            if (overlap <= 0.0)
                continue;
            const PairProperties &props = properties_[w][std::size_t(p.material[i])];
            energy_J += contactElasticEnergy(law, props, p.radius[i], overlap,
                                             history_[i * planes_.size() + w]);
        }
}

} // namespace grainlink::dem
