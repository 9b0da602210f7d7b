#include "grainlink/dem/NeighbourList.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace grainlink::dem {

void CellGrid::bin(const std::vector<Vec3> &positions, double min_cell_size_m) {
    if (!(min_cell_size_m > 0.0 && std::isfinite(min_cell_size_m)))
        throw std::logic_error("CellGrid: cell size " + std::to_string(min_cell_size_m));
    const std::size_t n = positions.size();
    // The box of the finite positions. A grain whose position overflowed in this step's drift
    // goes to an edge cell, and the step's end reports it (SimulationError, "not finite").
    Vec3 lo = Vec3::Constant(0.0), hi = Vec3::Constant(0.0);
    bool first = true;
    for (const Vec3 &p : positions) {
        if (!p.allFinite())
            continue;
        lo = first ? p : lo.cwiseMin(p);
        hi = first ? p : hi.cwiseMax(p);
        first = false;
    }
    cell_size_ = min_cell_size_m;
    // A stray particle must not blow up the grid: cap the cell count near 2 per particle. The
    // counts stay doubles until they fit: a grain 1e200 m away (a damaged state) would overflow
    // an int, and a span past the largest double is taken as that.
    const double max_cells = std::max<double>(64.0, 2.0 * double(n));
    const Vec3 span = (hi - lo).cwiseMin(std::numeric_limits<double>::max());
    for (;;) {
        const Eigen::Array3d cells = (span / cell_size_).array().floor() + 1.0;
        if (cells.prod() <= max_cells) {
            dims_ = cells.cast<int>().matrix();
            break;
        }
        cell_size_ *= 1.25;
    }
    origin_ = lo;
    const int cells = dims_.x() * dims_.y() * dims_.z();
    cell_start_.assign(cells + 1, 0);
    particle_cell_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        particle_cell_[i] = cellIndex(cellCoords(positions[i]));
        ++cell_start_[particle_cell_[i] + 1];
    }
    for (int c = 0; c < cells; ++c)
        cell_start_[c + 1] += cell_start_[c];
    cell_particles_.resize(n);
    std::vector<int> fill(cell_start_.begin(), cell_start_.end() - 1);
    for (std::size_t i = 0; i < n; ++i)
        cell_particles_[fill[particle_cell_[i]]++] = int(i);
}

Eigen::Vector3i CellGrid::cellCoords(const Vec3 &p) const {
    Eigen::Vector3i c;
    for (int d = 0; d < 3; ++d)
        // fmin/fmax, not clamp: a NaN coordinate goes to the last cell, not into an int cast.
        c[d] = int(std::fmax(
            0.0, std::fmin(std::floor((p[d] - origin_[d]) / cell_size_), double(dims_[d] - 1))));
    return c;
}

std::vector<NeighbourList::StoredContact> NeighbourList::activeContacts() const {
    std::vector<StoredContact> out;
    for (std::size_t i = 0; i + 1 < first.size(); ++i)
        for (std::size_t k = first[i]; k < first[i + 1]; ++k)
            if (state[k] & kTouching)
                out.push_back({i, std::size_t(neighbour[k]), history(k)});
    return out;
}

void NeighbourList::clearRollingHistory() {
    std::fill(rolling_N_m.begin(), rolling_N_m.end(), Vec3::Zero());
    for (StoredContact &c : pending_)
        c.history.rolling_N_m.setZero();
}

void NeighbourList::build(const std::vector<Vec3> &positions, const std::vector<double> &radii,
                          double skin_m, const std::vector<std::size_t> &old_to_new, int threads) {
    const std::size_t n = positions.size();
    // 1. Surviving histories. Without a re-sort the old list is still indexed like the new one
    //    and sorted per particle, so it is merged entry by entry (step 3); otherwise the active
    //    contacts are re-indexed, oriented so that i < j, and sorted.
    const bool same_indexing = old_to_new.empty() && pending_.empty() && first.size() == n + 1;
    std::vector<StoredContact> carried;
    std::vector<std::size_t> carried_first(same_indexing ? 0 : n + 1, 0);
    if (same_indexing) {
        old_first_.swap(first);
        old_neighbour_.swap(neighbour);
        old_state_.swap(state);
        old_tangential_.swap(tangential_m);
        old_rolling_.swap(rolling_N_m);
    } else {
        carried = activeContacts();
        carried.insert(carried.end(), pending_.begin(), pending_.end());
        pending_.clear();
        for (StoredContact &c : carried) {
            if (!old_to_new.empty()) {
                c.i = old_to_new[c.i];
                c.j = old_to_new[c.j];
            }
            if (c.i > c.j) {
                std::swap(c.i, c.j);
                c.history = c.history.reversed();
            }
        }
        std::sort(carried.begin(), carried.end(),
                  [](const StoredContact &a, const StoredContact &b) {
                      return a.i != b.i ? a.i < b.i : a.j < b.j;
                  });
        for (const StoredContact &c : carried)
            ++carried_first[c.i + 1];
        for (std::size_t i = 0; i < n; ++i)
            carried_first[i + 1] += carried_first[i];
    }

    // 2. Bin, then visit each pair of neighbouring cells once: a cell with itself and with the
    //    13 of its 26 neighbours that come after it. Half the cells of a full 27-cell search
    //    per particle, and no candidate is looked at twice.
    double max_radius = 0.0;
    for (double r : radii)
        max_radius = std::max(max_radius, r);
    grid_.bin(positions, 2.0 * max_radius + skin_m);
    const auto &start = grid_.cellStart();
    const auto &members = grid_.cellParticles();
    const Eigen::Vector3i dims = grid_.dims();
    const int cells = dims.x() * dims.y() * dims.z();
    static constexpr int kForward[13][3] = {
        {1, 0, 0},  {-1, 1, 0}, {0, 1, 0}, {1, 1, 0},  {-1, -1, 1}, {0, -1, 1}, {1, -1, 1},
        {-1, 0, 1}, {0, 0, 1},  {1, 0, 1}, {-1, 1, 1}, {0, 1, 1},   {1, 1, 1}};
    threads = std::max(1, threads);
    chunk_pairs_.resize(std::size_t(threads));
#pragma omp parallel num_threads(threads)
    {
        auto &out = chunk_pairs_[std::size_t(omp_get_thread_num())];
        out.clear();
        // Pair (a, b) is listed in the row of the smaller index; the distance is computed as
        // the row's particle minus the neighbour, as the contact loop does.
        const auto consider = [&](int a, int b) {
            const int i = std::min(a, b), j = std::max(a, b);
            const double reach = radii[std::size_t(i)] + radii[std::size_t(j)] + skin_m;
            if ((positions[std::size_t(i)] - positions[std::size_t(j)]).squaredNorm() <
                reach * reach)
                out.push_back({i, j});
        };
        // Cells are unevenly filled (the grid spans the bounding box): dynamic chunks. The rows
        // are sorted below, so the result does not depend on which thread found a pair.
#pragma omp for schedule(dynamic, 64)
        for (int c = 0; c < cells; ++c) {
            if (start[c] == start[c + 1])
                continue;
            const int x = c % dims.x(), y = (c / dims.x()) % dims.y(),
                      z = c / (dims.x() * dims.y());
            for (int k = start[c]; k < start[c + 1]; ++k)
                for (int m = k + 1; m < start[c + 1]; ++m)
                    consider(members[k], members[m]);
            for (const auto &o : kForward) {
                const int nx = x + o[0], ny = y + o[1], nz = z + o[2];
                if (nx < 0 || nx >= dims.x() || ny < 0 || ny >= dims.y() || nz >= dims.z())
                    continue;
                const int nc = grid_.cellIndex({nx, ny, nz});
                for (int k = start[c]; k < start[c + 1]; ++k)
                    for (int m = start[nc]; m < start[nc + 1]; ++m)
                        consider(members[k], members[m]);
            }
        }
    }

    // 3. Rows by counting sort, each sorted by neighbour: the force summation order then
    //    depends only on the pair set. Then attach carried histories.
    first.assign(n + 1, 0);
    for (const auto &chunk : chunk_pairs_)
        for (const auto &pair : chunk)
            ++first[std::size_t(pair.first) + 1];
    for (std::size_t i = 0; i < n; ++i)
        first[i + 1] += first[i];
    neighbour.resize(first[n]);
    {
        std::vector<std::size_t> fill(first.begin(), first.end() - 1);
        for (const auto &chunk : chunk_pairs_)
            for (const auto &pair : chunk)
                neighbour[fill[std::size_t(pair.first)]++] = pair.second;
    }
#pragma omp parallel for schedule(static) num_threads(threads)
    for (std::size_t i = 0; i < n; ++i)
        std::sort(neighbour.begin() + std::ptrdiff_t(first[i]),
                  neighbour.begin() + std::ptrdiff_t(first[i + 1]));
    const std::size_t entries = neighbour.size();
    owner.resize(entries);
#pragma omp parallel for schedule(static) num_threads(threads)
    for (std::size_t i = 0; i < n; ++i)
        std::fill(owner.begin() + std::ptrdiff_t(first[i]),
                  owner.begin() + std::ptrdiff_t(first[i + 1]), int(i));
    state.assign(entries, 0);
    tangential_m.assign(entries, Vec3::Zero());
    rolling_N_m.assign(keep_rolling_ ? entries : 0, Vec3::Zero());
    // A pair beyond the search radius cannot be in contact: its history lapses.
    if (same_indexing) {
        const bool rolling = keep_rolling_ && old_rolling_.size() == old_state_.size();
#pragma omp parallel for schedule(static) num_threads(threads)
        for (std::size_t i = 0; i < n; ++i) {
            std::size_t k = first[i];
            for (std::size_t o = old_first_[i]; o < old_first_[i + 1]; ++o) {
                if (!(old_state_[o] & kTouching))
                    continue;
                while (k < first[i + 1] && neighbour[k] < old_neighbour_[o])
                    ++k;
                if (k < first[i + 1] && neighbour[k] == old_neighbour_[o]) {
                    state[k] = old_state_[o];
                    tangential_m[k] = old_tangential_[o];
                    if (rolling)
                        rolling_N_m[k] = old_rolling_[o];
                }
            }
        }
    } else {
        for (std::size_t i = 0; i < n; ++i)
            for (std::size_t c = carried_first[i]; c < carried_first[i + 1]; ++c) {
                const auto begin = neighbour.begin() + std::ptrdiff_t(first[i]);
                const auto end = neighbour.begin() + std::ptrdiff_t(first[i + 1]);
                const auto it = std::lower_bound(begin, end, int(carried[c].j));
                if (it != end && *it == int(carried[c].j))
                    setHistory(std::size_t(it - neighbour.begin()), carried[c].history);
            }
    }
    ++builds_;
}

} // namespace grainlink::dem
