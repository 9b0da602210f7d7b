#include "grainlink/lab/LabBed.hpp"

#include "grainlink/dem/ScenarioRun.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <stdexcept>

namespace grainlink::lab {

LabBed prepareLabBed(const dem::DemScenario &soil, double progress_interval_s) {
    const auto start = std::chrono::steady_clock::now();
    LabBed bed;
    bed.system = dem::prepareSoil(soil, progress_interval_s, &bed.from_cache);
    bed.preparation_wall_s = secondsSince(start);
    bed.particles = bed.system->particles().size();
    bed.largest_radius_m = soil.deposition.radius.largest();
    bed.time_step_s = bed.system->settings().time_step_s;
    bed.surface_m = dem::bedSurface(bed.system->particles());
    return bed;
}

double secondsSince(std::chrono::steady_clock::time_point since) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

std::optional<Eigen::Vector2d> parseCentre(const config::ConfigNode &section) {
    const auto c = section.optional("centre_m");
    if (!c)
        return std::nullopt;
    const auto xy = c->numbers();
    if (xy.size() != 2)
        c->fail("expected [x, y]");
    return Eigen::Vector2d(xy[0], xy[1]);
}

Eigen::Vector2d testCentre(const dem::DemScenario &soil,
                           const std::optional<Eigen::Vector2d> &centre) {
    const auto &d = soil.deposition;
    return centre.value_or(Eigen::Vector2d(0.5 * (d.region_lower_m.x() + d.region_upper_m.x()),
                                           0.5 * (d.region_lower_m.y() + d.region_upper_m.y())));
}

double highestGrainUnder(const dem::ParticleStore &grains, const Eigen::Vector2d &centre,
                         double radius_m, double floor_m) {
    double highest = floor_m;
    for (std::size_t i = 0; i < grains.size(); ++i) {
        const dem::Vec3 &x = grains.position[i];
        if (std::hypot(x.x() - centre.x(), x.y() - centre.y()) < radius_m + grains.radius[i])
            highest = std::max(highest, x.z() + grains.radius[i]);
    }
    return highest;
}

std::ofstream openCsv(const std::filesystem::path &directory, const std::string &name,
                      const std::string &header) {
    const std::filesystem::path file = directory / name;
    std::ofstream csv(file);
    if (!csv)
        throw std::runtime_error("cannot write " + file.string() + "; check the output directory");
    csv << header << '\n' << std::setprecision(10);
    return csv;
}

void writeBedLine(std::ostream &out, std::size_t particles, double largest_radius_m,
                  double time_step_s, bool from_cache, double preparation_wall_s) {
    out << "  bed: " << particles << " grains, largest radius " << largest_radius_m * 1e3
        << " mm, time step " << time_step_s << " s, packing "
        << (from_cache ? "from the cache" : "deposited") << " in " << preparation_wall_s << " s\n";
}

} // namespace grainlink::lab
