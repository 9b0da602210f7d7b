#include "grainlink/lab/LabBed.hpp"

#include "grainlink/dem/ScenarioRun.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace grainlink::lab {

BedFootprint regionFootprint(const dem::DemScenario &soil) {
    const auto &d = soil.deposition;
    return {(d.region_upper_m.x() - d.region_lower_m.x()) *
                (d.region_upper_m.y() - d.region_lower_m.y()),
            d.region_lower_m.z()};
}

LabBed prepareLabBed(const dem::DemScenario &soil, const BedFootprint &footprint,
                     double progress_interval_s) {
    const auto start = std::chrono::steady_clock::now();
    LabBed bed;
    bool from_cache = false;
    bed.system = dem::prepareSoil(soil, progress_interval_s, &from_cache);
    const double wall_s = secondsSince(start);
    bed.summary = measureBed(*bed.system, soil, footprint);
    bed.summary.from_cache = from_cache;
    bed.summary.wall_s = wall_s;
    return bed;
}

LabBedSummary measureBed(const dem::DemSystem &system, const dem::DemScenario &soil,
                         const BedFootprint &footprint) {
    const dem::ParticleStore &grains = system.particles();
    LabBedSummary bed;
    bed.grains = grains.size();
    bed.largest_radius_m = soil.deposition.radius.largest();
    bed.time_step_s = system.settings().time_step_s;
    bed.floor_m = footprint.floor_m;
    bed.surface_m = dem::bedSurface(grains);
    bed.footprint_m2 = footprint.area_m2;
    bed.seed = soil.deposition.seed;
    // Bulk density of the settled bed, docs/physics.md §12.15.
    double mass = 0.0;
    for (double m : grains.mass)
        mass += m;
    bed.bulk_density_kg_m3 = mass / (footprint.area_m2 * (bed.surface_m - bed.floor_m));
    bed.packing_fraction = bed.bulk_density_kg_m3 / soil.material.density_kg_m3;
    return bed;
}

double secondsSince(std::chrono::steady_clock::time_point since) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

Eigen::Vector2d testCentre(const dem::DemScenario &soil,
                           const std::optional<Eigen::Vector2d> &centre) {
    const auto &d = soil.deposition;
    return centre.value_or(Eigen::Vector2d(0.5 * (d.region_lower_m.x() + d.region_upper_m.x()),
                                           0.5 * (d.region_lower_m.y() + d.region_upper_m.y())));
}

void refuseBeyondBed(const config::ConfigNode &where, const dem::DemScenario &soil,
                     const std::optional<Eigen::Vector2d> &centre, double radius_m,
                     const std::string &tool) {
    const auto &d = soil.deposition;
    const Eigen::Vector2d c = testCentre(soil, centre);
    const double room = std::min({c.x() - d.region_lower_m.x(), d.region_upper_m.x() - c.x(),
                                  c.y() - d.region_lower_m.y(), d.region_upper_m.y() - c.y()});
    if (radius_m > room) {
        std::ostringstream msg;
        msg << tool << " of radius " << radius_m * 1e3 << " mm about (" << c.x() * 1e3 << ", "
            << c.y() * 1e3 << ") mm reaches past the bed, whose nearest side is " << room * 1e3
            << " mm away (soil.deposition.region): a larger bin, or a smaller " << tool;
        where.fail(msg.str());
    }
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

void writeBedLine(std::ostream &out, const LabBedSummary &bed) {
    out << "  bed: " << bed.grains << " grains, largest radius " << bed.largest_radius_m * 1e3
        << " mm, time step " << bed.time_step_s << " s, packing "
        << (bed.from_cache ? "from the cache" : "deposited") << " in " << bed.wall_s << " s\n";
}

} // namespace grainlink::lab
