#include "grainlink/lab/LabSummary.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace grainlink::lab {

namespace {

// Insertion order kept: the file reads in the order docs/lab.md describes it.
using Json = nlohmann::ordered_json;

constexpr const char *kFormat = "grainlink-lab-summary";
constexpr int kVersion = 1;

/// JSON has no NaN: null stands for it, both ways.
Json number(double x) {
    return std::isnan(x) ? Json(nullptr) : Json(x);
}

double number(const Json &j, const std::string &what) {
    if (j.is_null())
        return std::numeric_limits<double>::quiet_NaN();
    if (!j.is_number())
        throw std::invalid_argument(what + " is not a number");
    return j.get<double>();
}

const Json &member(const Json &object, const std::string &key, const std::string &where) {
    if (!object.is_object() || !object.contains(key))
        throw std::invalid_argument(where + " has no '" + key + "'");
    return object.at(key);
}

} // namespace

double LabRunSummary::value(const std::string &name) const {
    for (const auto &[key, x] : values)
        if (key == name)
            return x;
    throw std::out_of_range("lab run has no value '" + name + "'");
}

const std::vector<double> &LabRunSummary::curve(const std::string &name) const {
    for (const auto &[key, column] : curves)
        if (key == name)
            return column;
    throw std::out_of_range("lab run has no curve '" + name + "'");
}

const FittedValue &LabSummary::fitted(const std::string &law, const std::string &name) const {
    for (const LabFit &fit : fits)
        if (fit.law == law)
            for (const FittedValue &p : fit.parameters)
                if (p.name == name)
                    return p;
    throw std::out_of_range("lab summary has no fitted '" + name + "' of '" + law + "'" +
                            (fit_note.empty() ? "" : " (" + fit_note + ")"));
}

std::string toJson(const LabSummary &s) {
    Json j;
    j["format"] = kFormat;
    j["version"] = kVersion;
    j["test"] = s.test;
    j["scenario"] = s.scenario;
    j["wall_s"] = s.wall_s;
    const LabBedSummary &b = s.bed;
    j["bed"] = Json{{"grains", b.grains},
                    {"largest_radius_m", b.largest_radius_m},
                    {"time_step_s", b.time_step_s},
                    {"floor_m", b.floor_m},
                    {"surface_m", b.surface_m},
                    {"footprint_m2", b.footprint_m2},
                    {"bulk_density_kg_m3", b.bulk_density_kg_m3},
                    {"packing_fraction", b.packing_fraction},
                    {"seed", b.seed},
                    {"from_cache", b.from_cache},
                    {"wall_s", b.wall_s}};
    Json fits = Json::object();
    for (const LabFit &fit : s.fits) {
        Json parameters = Json::object();
        for (const FittedValue &p : fit.parameters)
            parameters[p.name] = Json{{"value", number(p.value)},
                                      {"half_width_95", number(p.half_width_95)},
                                      {"unit", p.unit}};
        fits[fit.law] =
            Json{{"degrees_of_freedom", fit.degrees_of_freedom}, {"parameters", parameters}};
    }
    j["fits"] = fits;
    j["fit_note"] = s.fit_note;
    j["condition"] = s.condition;
    Json runs = Json::array();
    for (const LabRunSummary &run : s.runs) {
        Json r = Json::object();
        auto unique = [&](const std::string &key) {
            if (r.contains(key))
                throw std::logic_error("lab summary: run key '" + key + "' given twice");
            return key;
        };
        for (const auto &[key, x] : run.values)
            r[unique(key)] = number(x);
        for (const auto &[key, column] : run.curves) {
            Json c = Json::array();
            for (double x : column)
                c.push_back(number(x));
            r[unique(key)] = c;
        }
        runs.push_back(r);
    }
    j["runs"] = runs;
    return j.dump(1) + "\n";
}

LabSummary labSummaryFromJson(const std::string &text, const std::string &source) {
    Json j;
    try {
        j = Json::parse(text);
    } catch (const Json::parse_error &e) {
        throw std::invalid_argument(source + ": not JSON: " + e.what());
    }
    try {
        if (member(j, "format", "the file") != kFormat)
            throw std::invalid_argument("'format' is not " + std::string(kFormat));
        if (member(j, "version", "the file") != kVersion)
            throw std::invalid_argument("'version' is not " + std::to_string(kVersion));
        LabSummary s;
        s.test = member(j, "test", "the file").get<std::string>();
        s.scenario = member(j, "scenario", "the file").get<std::string>();
        s.wall_s = number(member(j, "wall_s", "the file"), "wall_s");
        const Json &b = member(j, "bed", "the file");
        auto bed = [&](const char *key) { return number(member(b, key, "'bed'"), key); };
        s.bed.grains = member(b, "grains", "'bed'").get<std::size_t>();
        s.bed.largest_radius_m = bed("largest_radius_m");
        s.bed.time_step_s = bed("time_step_s");
        s.bed.floor_m = bed("floor_m");
        s.bed.surface_m = bed("surface_m");
        s.bed.footprint_m2 = bed("footprint_m2");
        s.bed.bulk_density_kg_m3 = bed("bulk_density_kg_m3");
        s.bed.packing_fraction = bed("packing_fraction");
        s.bed.seed = member(b, "seed", "'bed'").get<std::uint64_t>();
        s.bed.from_cache = member(b, "from_cache", "'bed'").get<bool>();
        s.bed.wall_s = bed("wall_s");
        for (const auto &[law, fit] : member(j, "fits", "the file").items()) {
            LabFit f;
            f.law = law;
            const std::string where = "fit '" + law + "'";
            f.degrees_of_freedom = member(fit, "degrees_of_freedom", where).get<int>();
            for (const auto &[name, p] : member(fit, "parameters", where).items()) {
                const std::string what = where + " parameter '" + name + "'";
                f.parameters.push_back({name, member(p, "unit", what).get<std::string>(),
                                        number(member(p, "value", what), what),
                                        number(member(p, "half_width_95", what), what)});
            }
            s.fits.push_back(f);
        }
        s.fit_note = member(j, "fit_note", "the file").get<std::string>();
        s.condition = member(j, "condition", "the file").get<std::string>();
        for (const Json &r : member(j, "runs", "the file")) {
            LabRunSummary run;
            for (const auto &[key, x] : r.items()) {
                if (x.is_array()) {
                    std::vector<double> column;
                    for (const Json &e : x)
                        column.push_back(number(e, "curve '" + key + "'"));
                    run.curves.emplace_back(key, column);
                } else {
                    run.values.emplace_back(key, number(x, "run value '" + key + "'"));
                }
            }
            s.runs.push_back(run);
        }
        return s;
    } catch (const Json::exception &e) {
        throw std::invalid_argument(source + ": " + e.what());
    } catch (const std::invalid_argument &e) {
        throw std::invalid_argument(source + ": " + e.what());
    }
}

void writeLabSummary(const LabSummary &summary, const std::string &path) {
    std::ofstream out(path);
    if (!out)
        throw std::runtime_error("cannot write " + path + "; check the output directory");
    out << toJson(summary);
}

LabSummary readLabSummary(const std::string &path) {
    std::ifstream in(path);
    if (!in)
        throw std::invalid_argument("cannot read the lab summary " + path);
    std::ostringstream text;
    text << in.rdbuf();
    return labSummaryFromJson(text.str(), path);
}

} // namespace grainlink::lab
