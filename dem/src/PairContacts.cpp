#include "grainlink/dem/PairContacts.hpp"

#include <cmath>

namespace grainlink::dem {

void PairContacts::prepare(const std::vector<Material> &materials, const ContactLaw &law,
                           int threads) {
    materials_ = materials.size();
    properties_.resize(materials_ * materials_);
    for (std::size_t a = 0; a < materials_; ++a)
        for (std::size_t b = 0; b < materials_; ++b)
            properties_[a * materials_ + b] = pairProperties(materials[a], materials[b], law);
    side_.assign(std::size_t(threads), {});
    list_.keepRollingHistory(std::holds_alternative<RollingEpsd>(law.rolling) ||
                             std::holds_alternative<RollingGrainShape>(law.rolling));
}

void PairContacts::rebuild(const ParticleStore &p, double skin_m,
                           const std::vector<std::size_t> &old_to_new, int threads) {
    list_.build(p.position, p.radius, skin_m, old_to_new, threads);
    reference_position_ = p.position;
}

void PairContacts::rebuildAtReference(const ParticleStore &p, double skin_m, int threads) {
    const std::uint64_t builds = list_.buildCount();
    list_.build(reference_position_, p.radius, skin_m, {}, threads);
    list_.restoreBuildCount(builds);
}

void PairContacts::restore(std::vector<NeighbourList::StoredContact> contacts,
                           std::vector<Vec3> reference, std::uint64_t builds,
                           std::vector<std::size_t> split) {
    const bool keep_rolling = list_.keepsRollingHistory();
    list_ = NeighbourList{};
    list_.keepRollingHistory(keep_rolling);
    list_.setPendingContacts(std::move(contacts));
    list_.restoreBuildCount(builds);
    reference_position_ = std::move(reference);
    split_ = std::move(split); // empty from version-1 checkpoints: re-estimated
}

void PairContacts::estimateWork(std::vector<std::uint64_t> &work) const {
    // A contact costs about 12 times a listed pair that does not touch, and contacts crowd at
    // the floor and walls of a bed: a particle's work counts its listed pairs and, 12 times
    // more, those of them in contact at the rebuild.
    const auto &first = list_.first;
    for (std::size_t i = 0; i + 1 < first.size(); ++i)
        for (std::size_t k = first[i]; k < first[i + 1]; ++k)
            work[i] += (list_.state[k] & NeighbourList::kTouching) ? 13 : 1;
}

void PairContacts::splitThreads(const std::vector<std::uint64_t> &work, int threads) {
    // Thread ranges of about equal work. The split depends only on the lists, so a run stays
    // deterministic for a given thread count.
    const std::size_t n = work.size();
    std::uint64_t total = 0;
    for (std::uint64_t w : work)
        total += w;
    split_.assign(std::size_t(threads) + 1, n);
    split_[0] = 0;
    std::uint64_t sum = 0;
    int t = 1;
    for (std::size_t i = 0; i < n && t < threads; ++i) {
        sum += work[i];
        while (t < threads && sum * std::uint64_t(threads) >= total * std::uint64_t(t))
            split_[std::size_t(t++)] = i + 1;
    }
}

void PairContacts::addSideContributions(int t, int threads, ParticleStore &p) const {
    if (threads == 1)
        return;
#pragma omp barrier
    const std::size_t begin = split_[std::size_t(t)], end = split_[std::size_t(t) + 1];
    for (int s = 0; s < t; ++s)
        for (const SideContribution &c : side_[std::size_t(s)])
            if (c.particle >= begin && c.particle < end) {
                p.force[c.particle] += c.force_N;
                p.torque[c.particle] += c.torque_N_m;
            }
}

std::size_t PairContacts::contactCount(const ParticleStore &p) const {
    std::size_t count = 0;
    for (std::size_t i = 0; i + 1 < list_.first.size(); ++i)
        for (std::size_t k = list_.first[i]; k < list_.first[i + 1]; ++k) {
            const std::size_t j = std::size_t(list_.neighbour[k]);
            const double r = p.radius[i] + p.radius[j];
            if ((p.position[i] - p.position[j]).squaredNorm() < r * r)
                ++count;
        }
    return count;
}

template <class Visit>
void PairContacts::forEachTouching(const ParticleStore &p, Visit &&visit) const {
    for (std::size_t i = 0; i + 1 < list_.first.size(); ++i)
        for (std::size_t k = list_.first[i]; k < list_.first[i + 1]; ++k) {
            const std::size_t j = std::size_t(list_.neighbour[k]);
            const double r_sum = p.radius[i] + p.radius[j];
            const double overlap = r_sum - (p.position[i] - p.position[j]).norm();
            if (overlap > 0.0)
                visit(i, j, k, p.radius[i] * p.radius[j] / r_sum, overlap);
        }
}

void PairContacts::addElasticEnergy(const ParticleStore &p, const ContactLaw &law,
                                    double &energy_J) const {
    forEachTouching(
        p, [&](std::size_t i, std::size_t j, std::size_t k, double r_eff, double overlap) {
            energy_J += contactElasticEnergy(law, properties(p.material[i], p.material[j]), r_eff,
                                             overlap, list_.history(k));
        });
}

std::vector<PairForce> PairContacts::touchingPairs(const ParticleStore &p) const {
    std::vector<PairForce> out;
    forEachTouching(
        p, [&](std::size_t i, std::size_t j, std::size_t, double r_eff, double overlap) {
            const double e_star = properties(p.material[i], p.material[j]).effective_modulus_Pa;
            out.push_back({i, j, 4.0 / 3.0 * e_star * std::sqrt(r_eff) * std::pow(overlap, 1.5)});
        });
    return out;
}

} // namespace grainlink::dem
