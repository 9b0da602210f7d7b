#include "grainlink/dem/Deposition.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

namespace grainlink::dem {

double RadiusDistribution::largest() const {
    switch (kind) {
    case Kind::Constant:
        return min_m;
    case Kind::Uniform:
        return max_m;
    case Kind::Discrete:
        return *std::max_element(radii_m.begin(), radii_m.end());
    }
    return 0.0;
}

double RadiusDistribution::smallest() const {
    if (kind != Kind::Discrete)
        return min_m;
    double r = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < radii_m.size(); ++k)
        if (fractions[k] > 0.0)
            r = std::min(r, radii_m[k]);
    return r;
}

double RadiusDistribution::meanCubedRadius() const {
    switch (kind) {
    case Kind::Constant:
        return min_m * min_m * min_m;
    case Kind::Uniform: // (b^4 - a^4) / (4 (b - a)), written without the division by b - a
        return (min_m + max_m) * (min_m * min_m + max_m * max_m) / 4.0;
    case Kind::Discrete: {
        double sum = 0.0, weight = 0.0;
        for (std::size_t k = 0; k < radii_m.size(); ++k) {
            sum += fractions[k] * radii_m[k] * radii_m[k] * radii_m[k];
            weight += fractions[k];
        }
        return sum / weight;
    }
    }
    return 0.0;
}

void RadiusDistribution::validate() const {
    if (kind == Kind::Constant && !(min_m > 0.0))
        throw std::invalid_argument("radius: value_m must be > 0");
    if (kind == Kind::Uniform && !(min_m > 0.0 && max_m >= min_m))
        throw std::invalid_argument("radius: need 0 < min_m <= max_m");
    if (kind == Kind::Discrete) {
        if (radii_m.empty() || radii_m.size() != fractions.size())
            throw std::invalid_argument(
                "radius: radii_m and fractions must be non-empty and of equal length");
        for (std::size_t k = 0; k < radii_m.size(); ++k)
            if (!(radii_m[k] > 0.0) || !(fractions[k] >= 0.0))
                throw std::invalid_argument("radius: radii must be > 0 and fractions >= 0");
        if (!(std::accumulate(fractions.begin(), fractions.end(), 0.0) > 0.0))
            throw std::invalid_argument("radius: fractions sum to zero");
    }
}

std::uint64_t Random::next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

double Random::uniform() {
    return double(next() >> 11) * 0x1.0p-53;
}

std::string DepositionSpec::describe() const {
    std::ostringstream s;
    s.precision(17);
    s << "method=" << int(method) << " lower=" << region_lower_m.transpose()
      << " upper=" << region_upper_m.transpose() << " count=" << count
      << " radius=" << int(radius.kind) << ',' << radius.min_m << ',' << radius.max_m;
    for (std::size_t k = 0; k < radius.radii_m.size(); ++k)
        s << ',' << radius.radii_m[k] << ':' << radius.fractions[k];
    s << " material=" << material << " seed=" << seed << " layers=" << layers
      << " interval=" << layer_interval_s << " settle=" << settle_kinetic_energy_J << ','
      << max_settle_time_s;
    // Only what is set: a bed that is only settled keeps the key it had before these existed.
    if (strike_off_height_m)
        s << " strike_off=" << *strike_off_height_m;
    if (compaction)
        s << " compaction=" << compaction->pressure_Pa << ',' << compaction->hold_time_s << ','
          << compaction->speed_m_s;
    if (crust)
        s << " crust=" << crust->thickness_m << ',' << crust->youngs_modulus_factor << ','
          << crust->material;
    return s.str();
}

std::string DepositionReport::preparationSummary() const {
    std::ostringstream s;
    s.precision(4);
    if (struck_off > 0)
        s << "struck off " << struck_off << " grains; ";
    if (compaction)
        s << "compacted: plate " << compaction->hold_force_N << " N at hold (target "
          << compaction->target_force_N << " N, press step " << compaction->time_step_s << " s); ";
    if (crust_grains > 0)
        s << "crust of " << crust_grains << " grains; ";
    if (s.tellp() == 0)
        return "";
    s << "packing fraction " << packing_fraction_settled << " settled, " << packing_fraction
      << " prepared";
    return s.str();
}

namespace {

double drawRadius(const RadiusDistribution &d, Random &random) {
    switch (d.kind) {
    case RadiusDistribution::Kind::Constant:
        return d.min_m;
    case RadiusDistribution::Kind::Uniform:
        return random.uniform(d.min_m, d.max_m);
    case RadiusDistribution::Kind::Discrete: {
        const double total = std::accumulate(d.fractions.begin(), d.fractions.end(), 0.0);
        double pick = random.uniform() * total;
        for (std::size_t k = 0; k < d.radii_m.size(); ++k) {
            pick -= d.fractions[k];
            if (pick < 0.0)
                return d.radii_m[k];
        }
        return d.radii_m.back();
    }
    }
    return d.min_m;
}

/// Hash grid of placed spheres for overlap tests during insertion.
class PlacementGrid {
public:
    explicit PlacementGrid(double cell) : cell_(cell) {}
    void add(const Vec3 &x, double r) {
        spheres_.push_back({x, r});
        cells_[key(x)].push_back(int(spheres_.size() - 1));
    }
    bool free(const Vec3 &x, double r, double reach) const {
        const Eigen::Vector3i c = coords(x);
        const int span = int(std::ceil(reach / cell_));
        for (int dz = -span; dz <= span; ++dz)
            for (int dy = -span; dy <= span; ++dy)
                for (int dx = -span; dx <= span; ++dx) {
                    auto it = cells_.find(pack(c + Eigen::Vector3i(dx, dy, dz)));
                    if (it == cells_.end())
                        continue;
                    for (int k : it->second) {
                        const double d = spheres_[k].second + r;
                        if ((spheres_[k].first - x).squaredNorm() < d * d)
                            return false;
                    }
                }
        return true;
    }

private:
    Eigen::Vector3i coords(const Vec3 &x) const {
        return Eigen::Vector3i(int(std::floor(x.x() / cell_)), int(std::floor(x.y() / cell_)),
                               int(std::floor(x.z() / cell_)));
    }
    static std::int64_t pack(const Eigen::Vector3i &c) {
        return (std::int64_t(c.x() & 0x1FFFFF) << 42) | (std::int64_t(c.y() & 0x1FFFFF) << 21) |
               std::int64_t(c.z() & 0x1FFFFF);
    }
    std::int64_t key(const Vec3 &x) const { return pack(coords(x)); }
    double cell_;
    std::vector<std::pair<Vec3, double>> spheres_;
    std::unordered_map<std::int64_t, std::vector<int>> cells_;
};

} // namespace

std::size_t insertRandom(DemSystem &system, const DepositionSpec &spec, Random &random,
                         std::size_t count, const Vec3 &lower_m, const Vec3 &upper_m) {
    const double r_max = spec.radius.largest();
    PlacementGrid grid(2.0 * r_max);
    ParticleStore &p = system.particles();
    for (std::size_t i = 0; i < p.size(); ++i)
        grid.add(p.position[i], p.radius[i]);
    const double density = system.materials().at(std::size_t(spec.material)).density_kg_m3;
    std::size_t placed = 0;
    // Each grain keeps its drawn radius until it finds room: redrawing after a rejection would
    // favour small grains and distort the size distribution in a crowded region.
    constexpr int kTriesPerGrain = 200;
    for (std::size_t k = 0; k < count; ++k) {
        const double r = drawRadius(spec.radius, random);
        for (int attempt = 0; attempt < kTriesPerGrain; ++attempt) {
            Vec3 x;
            for (int d = 0; d < 3; ++d)
                x[d] = random.uniform(lower_m[d] + r, upper_m[d] - r);
            if (!grid.free(x, r, r + r_max))
                continue;
            ParticleSpec s;
            s.position_m = x;
            s.radius_m = r;
            s.density_kg_m3 = density;
            s.material = spec.material;
            system.particles().add(s);
            grid.add(x, r);
            ++placed;
            break;
        }
    }
    return placed;
}

namespace {

/// Steps until the mean kinetic energy per grain is below the spec's threshold (checked every
/// 0.01 s) with report.settle_time_s at least not_before_s, or until it reaches until_s.
void settle(DemSystem &system, const DepositionSpec &spec, DepositionReport &report,
            const std::function<void(const DepositionReport &)> &progress, double until_s,
            double not_before_s = 0.0) {
    const double dt = system.settings().time_step_s;
    const std::uint64_t check_every = std::max<std::uint64_t>(1, std::uint64_t(0.01 / dt));
    for (;;) {
        for (std::uint64_t k = 0; k < check_every; ++k)
            system.step();
        report.settle_time_s += double(check_every) * dt;
        const Energies e = system.energies();
        report.final_kinetic_energy_per_particle_J =
            (e.translational_J + e.rotational_J) /
            double(std::max<std::size_t>(1, system.particles().size()));
        report.settled =
            report.final_kinetic_energy_per_particle_J < spec.settle_kinetic_energy_J &&
            report.settle_time_s >= not_before_s;
        if (progress)
            progress(report);
        if (report.settled || report.settle_time_s >= until_s)
            break;
    }
}

} // namespace

DepositionReport deposit(DemSystem &system, const DepositionSpec &spec,
                         const std::function<void(const DepositionReport &)> &progress) {
    spec.radius.validate();
    if (spec.count == 0)
        throw std::invalid_argument("deposition: count must be > 0");
    if ((spec.region_upper_m - spec.region_lower_m).minCoeff() <= 2.0 * spec.radius.largest())
        throw std::invalid_argument("deposition: region is thinner than a grain");
    if (spec.layers < 1)
        throw std::invalid_argument("deposition: layers must be >= 1");
    if (spec.compaction)
        spec.compaction->validate();
    if (spec.crust)
        spec.crust->validate();
    Random random(spec.seed);
    DepositionReport report;
    const double dt = system.settings().time_step_s;
    double last_inserted_s = 0.0; // when the last grains were placed, at rest
    if (spec.method == DepositionSpec::Method::Random) {
        report.inserted = insertRandom(system, spec, random, spec.count, spec.region_lower_m,
                                       spec.region_upper_m);
    } else {
        // Rain: each layer fills the top slab of the region, then falls for one interval.
        const double height = spec.region_upper_m.z() - spec.region_lower_m.z();
        const double slab = std::max(height / spec.layers, 2.2 * spec.radius.largest());
        for (int layer = 0; layer < spec.layers; ++layer) {
            const std::size_t want =
                spec.count * std::size_t(layer + 1) / std::size_t(spec.layers) - report.inserted;
            Vec3 lo = spec.region_lower_m;
            lo.z() = spec.region_upper_m.z() - slab;
            report.inserted += insertRandom(system, spec, random, want, lo, spec.region_upper_m);
            last_inserted_s = report.settle_time_s;
            const auto steps = std::uint64_t(std::ceil(spec.layer_interval_s / dt));
            for (std::uint64_t k = 0; k < steps; ++k)
                system.step();
            report.settle_time_s += double(steps) * dt;
            if (progress)
                progress(report);
        }
    }
    if (report.inserted < spec.count * 99 / 100) {
        std::ostringstream msg;
        msg << "deposition: only " << report.inserted << " of " << spec.count
            << " particles fit into the insertion region; enlarge it, use rain with more layers, "
               "or lower count";
        throw std::runtime_error(msg.str());
    }
    // Not settled before the last grains placed at the region's top could have fallen to its
    // floor, sqrt(2 h / g): a grain starts at rest, and under a weak gravity (the Moon's) the
    // first check, 0.01 s in, found the mean kinetic energy of a bed in free fall below the
    // threshold (docs/physics.md §6).
    const double g = system.settings().gravity_m_s2.norm();
    const double fall_s =
        g > 0.0 ? std::sqrt(2.0 * (spec.region_upper_m.z() - spec.region_lower_m.z()) / g) : 0.0;
    settle(system, spec, report, progress, spec.max_settle_time_s, last_inserted_s + fall_s);
    const Vec3 footprint = spec.region_upper_m - spec.region_lower_m;
    const double area_m2 = footprint.x() * footprint.y();
    report.packing_fraction_settled = packingFraction(system.particles(), area_m2);

    // Preparation (docs/physics.md §6.1): each step then settles again, as long as it may.
    const auto settleAgain = [&] {
        settle(system, spec, report, progress, report.settle_time_s + spec.max_settle_time_s);
    };
    if (spec.strike_off_height_m) {
        report.struck_off = strikeOff(system, *spec.strike_off_height_m);
        if (report.struck_off > 0)
            settleAgain();
    }
    if (spec.compaction) {
        report.compaction =
            compact(system, *spec.compaction, spec.region_lower_m, spec.region_upper_m);
        settleAgain();
    }
    if (spec.crust) {
        report.crust_grains = applyCrust(system, *spec.crust);
        settleAgain();
    }
    report.packing_fraction = packingFraction(system.particles(), area_m2);
    return report;
}

std::string hashKey(const std::string &text) {
    std::uint64_t h = 1469598103934665603ull;
    for (unsigned char c : text) {
        h ^= c;
        h *= 1099511628211ull;
    }
    char out[17];
    std::snprintf(out, sizeof out, "%016llx", static_cast<unsigned long long>(h));
    return out;
}

} // namespace grainlink::dem
