#include "grainlink/gap/Experiments.hpp"

#include "DataTable.hpp"

#include "grainlink/gap/Comparison.hpp"

#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/config/Number.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <set>
#include <sstream>
#include <stdexcept>
#include <tuple>

namespace grainlink::gap {

namespace fs = std::filesystem;
using config::ConfigNode;

namespace {

struct TypeInfo {
    ExperimentType type;
    const char *name;
    const char *x_name; ///< SI name of x; "" for a scalar
    std::vector<std::string> observables;
    ConditionNames conditions;
};

const std::vector<TypeInfo> &types() {
    // Gravity's magnitude makes every test's soil, and a bed's depth every test whose bed is the
    // soil's deposition (the shear box is the direct shear test's own, its depth too).
    static const std::vector<TypeInfo> t{
        {ExperimentType::PlateSinkage,
         "plate_sinkage",
         "sinkage_m",
         {"pressure_Pa"},
         {{"plate_diameter_m", "gravity_m_s2", "bed_depth_m"},
          "plate_diameter_m",
          {{"plate_radius_m", "plate_diameter_m", 2.0}}}},
        {ExperimentType::BevameterShear,
         "bevameter_shear",
         "shear_displacement_m",
         {"shear_stress_Pa"},
         {{"normal_pressure_Pa", "gravity_m_s2", "bed_depth_m"}, "normal_pressure_Pa", {}}},
        // The top plate's rise from the start of shearing (dilation positive), as a direct
        // shear test's vertical gauge reads it.
        {ExperimentType::DirectShear,
         "direct_shear",
         "shear_displacement_m",
         {"shear_stress_Pa", "vertical_displacement_m"},
         {{"normal_stress_Pa", "gravity_m_s2"}, "normal_stress_Pa", {}}},
        {ExperimentType::AngleOfRepose,
         "angle_of_repose",
         "",
         {"angle_deg"},
         {{"gravity_m_s2"}, "", {}}},
        {ExperimentType::WheelSteadyState,
         "wheel_steady_state",
         "slip",
         {"traction_N", "drawbar_pull_N", "vertical_load_N", "side_force_N", "sinkage_m",
          "torque_N_m"},
         // One test per geometry, load and slope, one slip per run.
         {{"wheel_radius_m", "wheel_width_m", "grouser_count", "grouser_height_m", "load_N",
           "slip_angle_deg", "slope_deg", "gravity_m_s2", "bed_depth_m"},
          "",
          {{"wheel_diameter_m", "wheel_radius_m", 0.5}}}},
        {ExperimentType::Mole,
         "mole",
         "stroke",
         {"depth_m"},
         {{"gravity_m_s2", "bed_depth_m"}, "", {}}},
    };
    return t;
}

const TypeInfo &info(ExperimentType type) {
    for (const auto &t : types())
        if (t.type == type)
            return t;
    throw std::logic_error("unknown experiment type");
}

struct Unit {
    const char *name, *dimension;
    double factor;
};

const std::vector<Unit> &units() {
    // The SI units and their multiples, the spellings of them in other tools' exports (kN/m^2,
    // g/cm3, mm/min), and the US customary ones of the older terramechanics literature (psi,
    // lbf, in). Exact by definition: 1 in = 0.0254 m, 1 lb = 0.45359237 kg, standard gravity
    // 9.80665 m/s2 (NIST SP 811).
    constexpr double g0 = 9.80665, lbf = 0.45359237 * g0, inch = 0.0254;
    static const std::vector<Unit> u{
        {"m", "length", 1.0},
        {"mm", "length", 1e-3},
        {"cm", "length", 1e-2},
        {"um", "length", 1e-6},
        {"\u00b5m", "length", 1e-6}, // the micro sign
        {"\u03bcm", "length", 1e-6}, // the Greek mu
        {"in", "length", inch},
        {"ft", "length", 12 * inch},
        {"Pa", "pressure", 1.0},
        {"kPa", "pressure", 1e3},
        {"MPa", "pressure", 1e6},
        {"N/m2", "pressure", 1.0},
        {"N/m^2", "pressure", 1.0},
        {"kN/m2", "pressure", 1e3},
        {"kN/m^2", "pressure", 1e3},
        {"bar", "pressure", 1e5},
        {"psi", "pressure", lbf / (inch * inch)},
        {"kgf/cm2", "pressure", g0 * 1e4},
        {"N", "force", 1.0},
        {"mN", "force", 1e-3},
        {"kN", "force", 1e3},
        {"kgf", "force", g0},
        {"lbf", "force", lbf},
        {"N_m", "torque", 1.0},
        {"N m", "torque", 1.0},
        {"Nm", "torque", 1.0},
        {"N*m", "torque", 1.0},
        {"N_mm", "torque", 1e-3},
        {"N mm", "torque", 1e-3},
        {"Nmm", "torque", 1e-3},
        {"lbf_in", "torque", lbf * inch},
        {"deg", "angle", 1.0},
        {"rad", "angle", 180.0 / M_PI},
        {"-", "dimensionless", 1.0},
        {"1", "dimensionless", 1.0},
        {"%", "dimensionless", 0.01},
        {"m_s", "speed", 1.0},
        {"mm_s", "speed", 1e-3},
        {"m/s", "speed", 1.0},
        {"mm/s", "speed", 1e-3},
        {"cm/s", "speed", 1e-2},
        {"mm/min", "speed", 1e-3 / 60},
        {"m/min", "speed", 1.0 / 60},
        {"in/s", "speed", inch},
        {"kg", "mass", 1.0},
        {"g", "mass", 1e-3},
        {"lb", "mass", 0.45359237},
        {"s", "time", 1.0},
        {"ms", "time", 1e-3},
        {"min", "time", 60.0},
        {"m_s2", "acceleration", 1.0},
        {"m/s2", "acceleration", 1.0},
        {"m/s^2", "acceleration", 1.0},
        {"g0", "acceleration", g0},
        {"kg_m3", "density", 1.0},
        {"kg/m3", "density", 1.0},
        {"kg/m^3", "density", 1.0},
        {"g_cm3", "density", 1e3},
        {"g/cm3", "density", 1e3},
        {"g/cm^3", "density", 1e3},
    };
    return u;
}

/// The largest size a tool or a bed may have (a plate's or wheel's diameter, a grouser's
/// height, a bed's depth): a lab's soil bin is a metre or two. Above it, the size was given in
/// mm or cm. A travel or a bin's length may be longer (a field test, a long test bed).
constexpr double kLongestLabSize_m = 2.0;
bool isToolOrBedSize(const std::string &key) {
    for (const char *size : {"diameter", "radius", "width", "height", "depth"})
        if (key.find(size) != std::string::npos)
            return true;
    return false;
}

/// Suffix -> dimension of grainlink's SI names (`plate_diameter_m`, `normal_stress_Pa`).
const std::vector<std::pair<std::string, std::string>> &suffixes() {
    static const std::vector<std::pair<std::string, std::string>> s{
        {"_N_m", "torque"}, {"_m_s2", "acceleration"}, {"_m_s", "speed"}, {"_kg_m3", "density"},
        {"_Pa", "pressure"}, {"_N", "force"},         {"_m", "length"},  {"_deg", "angle"},
        {"_kg", "mass"},     {"_s", "time"},
    };
    return s;
}

bool endsWith(const std::string &s, const std::string &tail) {
    return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

/// How the data files of `data` are written (docs/gap.md): comment mark, delimiter, decimal
/// mark and, for a file without a header line, its column names.
TableFormat parseTableFormat(const ConfigNode &data) {
    TableFormat f;
    f.comment = data.text("comment", "#");
    if (data.has("delimiter")) {
        // A tab also as the character itself ("\t").
        const std::string d = data["delimiter"].text() == "\t" ? "tab" : data["delimiter"].text();
        if (d != "," && d != ";" && d != "tab" && d != "whitespace")
            data["delimiter"].fail("'" + d +
                                   "' is no delimiter: give \",\", \";\", tab or whitespace");
        f.delimitedBy(d);
    }
    // A decimal comma beside the comma delimiter reads only quoted numbers ("0,5"); an
    // unquoted one splits its row into too many cells, which the reader refuses.
    if (data.has("decimal")) {
        const std::string d = data["decimal"].text();
        if (d != "." && d != ",")
            data["decimal"].fail("'" + d + "' is no decimal mark: give \".\" or \",\"");
        f.decimal = d[0];
    }
    f.units_row = data.boolean("units_row", false);
    f.skip_lines = int(data.integer("skip_lines", 0, 1000000, 0));
    if (data.has("columns")) {
        for (const ConfigNode &c : data["columns"].items())
            f.columns.push_back(c.text());
        if (f.columns.empty())
            data["columns"].fail("name the file's columns in order");
    }
    return f;
}

/// The column `name` of `table`; a missing one is an error at `where` listing the columns.
std::size_t columnOf(const DataTable &table, const std::string &name, const ConfigNode &where) {
    std::optional<std::size_t> c;
    try {
        c = table.find(name);
    } catch (const config::ConfigError &e) {
        where.fail(e.what());
    }
    if (!c)
        where.fail(table.missingColumn(name));
    return *c;
}

/// `{column, unit}` of one axis: the column index in `table` and the factor to SI.
std::pair<std::size_t, double> axisColumn(const ConfigNode &node, const DataTable &table,
                                          const std::string &si_name) {
    const std::size_t col = columnOf(table, node["column"].text(), node["column"]);
    const std::string unit = node["unit"].text();
    double factor = 1.0;
    try {
        factor = unitFactor(unit, dimensionOf(si_name));
    } catch (const std::invalid_argument &e) {
        node["unit"].fail(e.what());
    }
    if (const std::string why = unitsRowDisagreement(table, col, unit, dimensionOf(si_name));
        !why.empty())
        node["unit"].fail(why);
    // Another code's sign convention (z up: a sinkage and a plate force come out negative).
    const double scale = node.number("scale", 1.0);
    if (scale == 0.0 || !std::isfinite(scale))
        node["scale"].fail("a scale multiplies the column: give a finite number other than 0");
    node.finish();
    return {col, factor * scale};
}

/// How grainlink takes a type's signs, and the fix for another code's (z up, a box pulled the
/// other way): said alike wherever a column reads with the other sign.
std::string signFix(ExperimentType type) {
    const char *convention =
        type == ExperimentType::PlateSinkage
            ? "a plate's pressure as positive and its sinkage as growing into the soil"
        : type == ExperimentType::WheelSteadyState ? "a wheel's sinkage as positive into the soil"
        : type == ExperimentType::Mole             ? "a mole's depth as positive below the surface"
                                       : "the shear stress as positive and the shear displacement "
                                         "as growing";
    return std::string("; grainlink takes ") + convention +
           " (add `scale: -1` to a column whose axis points the other way, as z up does)";
}

/// Refuses a curve that reads with another code's signs: grainlink takes a plate's pressure and
/// a shear box's stress as positive, and their sinkage or displacement as growing, and a curve
/// with z up (or the box pulled the other way) would otherwise read as an enormous gap. Judged
/// at the most loaded sample, which must push (y > 0) and lie further on than the first.
void checkSigns(ExperimentType type, const Curve &curve, const ConfigNode &data,
                const std::string &file) {
    if (curve.y.size() < 2 ||
        (type != ExperimentType::PlateSinkage && type != ExperimentType::DirectShear &&
         type != ExperimentType::BevameterShear))
        return;
    const bool plate = type == ExperimentType::PlateSinkage;
    std::size_t peak = 0;
    for (std::size_t i = 1; i < curve.y.size(); ++i)
        if (std::abs(curve.y[i]) > std::abs(curve.y[peak]))
            peak = i;
    if (curve.y[peak] < 0.0)
        data["y"].fail(file + ": the largest " + (plate ? "pressure" : "shear stress") +
                       " is negative" + signFix(type));
    if (curve.x[peak] < curve.x.front())
        data["x"].fail(file +
                       (plate ? ": the sinkage falls as the plate is loaded"
                              : ": the shear displacement falls as the stress builds") +
                       signFix(type));
}

/// Refuses a file whose curve runs up its x, falls back to its start and runs up again: trials
/// written one after the other (a stacked export, or a shear box reversed and sheared again),
/// which read as one curve would bin each trial's start with the others' ends. `lines` holds
/// each sample's file line. An unloading that ends the file is not a second trial.
void refuseStackedTrials(const Experiment &e, const Curve &curve, const std::vector<int> &lines,
                         const ConfigNode &data, const std::string &file) {
    if (curve.x.size() < 4 || lines.size() != curve.x.size() ||
        (e.type != ExperimentType::PlateSinkage && e.type != ExperimentType::DirectShear &&
         e.type != ExperimentType::BevameterShear))
        return;
    const auto [lo, hi] = std::minmax_element(curve.x.begin(), curve.x.end());
    const double range = *hi - *lo;
    if (!(range > 0.0))
        return;
    // Past half the range, back within a tenth of the start, past half again: one restart.
    std::vector<int> restarts;
    bool risen = false;
    int fell_at = 0;
    for (std::size_t i = 0; i < curve.x.size(); ++i) {
        const double u = (curve.x[i] - *lo) / range;
        if (u >= 0.5) {
            if (fell_at)
                restarts.push_back(fell_at);
            risen = true, fell_at = 0;
        } else if (risen && u <= 0.1) {
            risen = false, fell_at = lines[i];
        }
    }
    if (restarts.empty())
        return;
    data["x"].fail(file + ":" + std::to_string(restarts.front()) + ": " + e.x_name +
                   " falls back to its start here and runs up again (" +
                   std::to_string(restarts.size()) +
                   " time(s) in the file): " + std::to_string(restarts.size() + 1) +
                   " trials one after the other? give data.trial: the column that tells them "
                   "apart (import csv: --trial COLUMN), or one file per trial");
}

/// Says a shear test whose shear stress stands far outside a soil's strength against its normal
/// stress (more than 50 times it, or under 1/50 of it): a stress in kPa read as Pa on one side
/// gives 1000 times too much or too little. Said, not refused. Not nearer: stiff grains jammed
/// in a narrow box reached 6 times their normal stress, and a cohesive soil under a light load
/// may reach 20.
void sayUnlikelyStressRatio(const Experiment &e, std::vector<std::string> &notes) {
    const char *normal = e.type == ExperimentType::DirectShear      ? "normal_stress_Pa"
                         : e.type == ExperimentType::BevameterShear ? "normal_pressure_Pa"
                                                                    : nullptr;
    const auto sigma = normal ? e.numbers.find(normal) : e.numbers.end();
    if (sigma == e.numbers.end() || !(sigma->second > 0.0))
        return;
    double tau = 0.0;
    for (const Trial &t : e.trials)
        if (const auto c = t.curves.find("shear_stress_Pa"); c != t.curves.end())
            for (double y : c->second.y)
                tau = std::max(tau, y);
    if (!(tau > 0.0))
        return;
    const double ratio = tau / sigma->second;
    if (ratio <= 50.0 && ratio >= 0.02)
        return;
    std::ostringstream m;
    m << std::setprecision(6) << "experiment '" << e.id << "': shear stress up to " << tau
      << " Pa under " << normal << " " << sigma->second << " (" << std::setprecision(3) << ratio
      << " times it): "
      << (ratio > 1.0 ? std::string(normal) + " given in kPa? (conditions are in Pa: " +
                            config::significant(sigma->second * 1000.0, 6) + " for " +
                            config::significant(sigma->second, 6) + " kPa)"
                      : std::string("is the shear stress column's unit right (kPa read as "
                                    "Pa?), or the normal stress 1000 times too large?"));
    notes.push_back(m.str());
}

/// Says an experiment whose largest value lies 100 times or more off the median of the others
/// of its kind (three or more): plates of other sizes or boxes differ by a few times, a column
/// in kPa read as Pa by a thousand. Only loads every test of the kind builds up: a wheel's side
/// force at no slip angle is near zero by rights.
void sayLevelsApart(ExperimentSet &set) {
    static const std::set<std::string> loads = {"pressure_Pa", "shear_stress_Pa", "vertical_load_N",
                                                "angle_deg"};
    std::map<std::string, std::vector<std::pair<std::string, double>>> levels;
    for (const Experiment &e : set.experiments)
        for (const std::string &o : e.observables) {
            if (!loads.count(o))
                continue;
            double level = 0.0;
            for (const Trial &t : e.trials)
                if (const auto c = t.curves.find(o); c != t.curves.end())
                    for (double y : c->second.y)
                        level = std::max(level, std::abs(y));
            if (level > 0.0)
                levels[e.kind(o)].emplace_back(e.id, level);
        }
    for (const auto &[kind, list] : levels) {
        if (list.size() < 3)
            continue;
        std::vector<double> values;
        for (const auto &[id, level] : list)
            values.push_back(level);
        std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
        const double median = values[values.size() / 2];
        for (const auto &[id, level] : list)
            if (level > 100.0 * median || level < 0.01 * median) {
                std::ostringstream m;
                m << std::setprecision(3) << "experiment '" << id << "': " << kind << " reaches "
                  << level << ", " << level / median << " times the median of its kind's "
                  << list.size() << " experiments (" << median
                  << "): its unit? (kPa read as Pa is 1000 times)";
                set.notes.push_back(m.str());
            }
    }
}

/// Refuses a wheel's sinkage given z up: every run's sinkage at or below zero, one below.
void checkWheelSinkage(const Experiment &e, const ConfigNode &data) {
    bool below = false, above = false;
    for (const Trial &t : e.trials)
        if (const auto c = t.curves.find("sinkage_m"); c != t.curves.end())
            for (double y : c->second.y)
                below = below || y < 0.0, above = above || y > 0.0;
    if (below && !above)
        data["y"]["sinkage_m"].fail("every run's sinkage is negative" + signFix(e.type));
}

/// Refuses an experiment that gives no feature of its own (the diagnosis' bins on it alone):
/// its curves all on the wrong side of their zero (z up without `scale: -1`), or its own bins
/// beyond its data. Said here, with its file, rather than as "not compared" after the
/// simulations have run.
void refuseUncomparable(const Experiment &e, const ConfigNode &node) {
    if (e.x_name.empty())
        return;
    ExperimentSet alone;
    alone.experiments = {e};
    if (designFeatures(alone).by_experiment.count(e.id))
        return;
    double lo = INFINITY, hi = -INFINITY;
    for (const Trial &t : e.trials)
        for (const auto &[o, curve] : t.curves)
            for (double x : applyZero(curve, e.zero).x)
                lo = std::min(lo, x), hi = std::max(hi, x);
    std::ostringstream m;
    m << "experiment '" << e.id << "' has no bin to compare: its " << e.x_name;
    if (!e.scatter)
        m << " (zeroed by its zero method)";
    m << " runs from " << lo << " to " << hi + 0.0; // + 0.0: -0 reads as 0
    if (!e.bin_edges.empty()) {
        m << ", its bins from " << e.bin_edges.front() << " to " << e.bin_edges.back()
          << (e.scatter ? " (SI), and none holds a run"
                        : " (SI), and none up to its curves' reach holds a measured sample");
        node["bins"]["edges"].fail(m.str() + (hi <= 0.0 && lo < 0.0 ? signFix(e.type) : ""));
    }
    m << " (SI), and its bins start at 0";
    node["data"]["x"].fail(m.str() + (hi <= 0.0 && lo < 0.0 ? signFix(e.type) : ""));
}

double siValue(const ConfigNode &parent, const std::string &value_key, const std::string &unit_key,
               const std::string &dimension) {
    const double v = parent[value_key].number();
    const ConfigNode u = parent[unit_key];
    try {
        return v * unitFactor(u.text(), dimension);
    } catch (const std::invalid_argument &e) {
        u.fail(e.what());
    }
}

} // namespace

const char *typeName(ExperimentType type) { return info(type).name; }

std::vector<ExperimentType> experimentTypes() {
    std::vector<ExperimentType> all;
    for (const auto &t : types())
        all.push_back(t.type);
    return all;
}

const std::vector<std::string> &observablesOf(ExperimentType type) { return info(type).observables; }

const ConditionNames &conditionsOf(ExperimentType type) {
    return info(type).conditions;
}

const std::vector<std::string> &describingConditions() {
    static const std::vector<std::string> d{"speed_m_s", "box", "preparation"};
    return d;
}

namespace {
/// The names data.y takes: the type's observables, and a plate's force, read as its pressure
/// (given with conditions.plate_diameter_m).
std::vector<std::string> observableNames(ExperimentType type) {
    std::vector<std::string> names = observablesOf(type);
    if (type == ExperimentType::PlateSinkage)
        names.push_back("force_N");
    return names;
}
} // namespace

bool isObservableOf(const std::string &name, ExperimentType type) {
    const std::vector<std::string> names = observableNames(type);
    return std::find(names.begin(), names.end(), name) != names.end();
}

std::string notAnObservable(const std::string &name, ExperimentType type) {
    const std::vector<std::string> names = observableNames(type);
    std::string list;
    for (const auto &n : names)
        list += (list.empty() ? "" : ", ") + n;
    return "'" + name + "' is not an observable of " + typeName(type) +
           " (its observables: " + list + ")";
}

const char *xNameOf(ExperimentType type) { return info(type).x_name; }

ExperimentType parseType(const std::string &name) {
    std::string known;
    for (const auto &t : types()) {
        if (name == t.name)
            return t.type;
        known += (known.empty() ? "" : ", ") + std::string(t.name);
    }
    throw std::invalid_argument("unknown experiment type '" + name + "' (known: " + known + ")");
}

double unitFactor(const std::string &unit, const std::string &dimension) {
    std::string same;
    for (const auto &u : units()) {
        if (u.dimension != dimension)
            continue;
        if (unit == u.name)
            return u.factor;
        same += (same.empty() ? "" : ", ") + std::string(u.name);
    }
    for (const auto &u : units())
        if (unit == u.name)
            throw std::invalid_argument("unit '" + unit + "' is a " + u.dimension + ", not a " +
                                        dimension + " (use one of: " + same + ")");
    throw std::invalid_argument("unknown unit '" + unit + "' for a " + dimension +
                                " (use one of: " + same + ")");
}

std::string dimensionOf(const std::string &si_name) {
    for (const auto &[tail, dim] : suffixes())
        if (endsWith(si_name, tail))
            return dim;
    return "dimensionless";
}

std::string unitOf(const std::string &si_name) {
    for (const auto &suffix : suffixes())
        if (endsWith(si_name, suffix.first))
            return suffix.first.substr(1);
    return "";
}

std::string Experiment::kind(const std::string &observable) const {
    return std::string(typeName(type)) + "/" + observable;
}

std::map<std::string, std::string> Experiment::conditionText() const {
    std::map<std::string, std::string> c = labels;
    for (const auto &[k, v] : numbers) {
        std::ostringstream s;
        s << v;
        c[k] = s.str();
    }
    return c;
}

const Experiment &ExperimentSet::find(const std::string &id) const {
    for (const auto &e : experiments)
        if (e.id == id)
            return e;
    std::string ids;
    for (const auto &e : experiments)
        ids += (ids.empty() ? "" : ", ") + e.id;
    throw std::invalid_argument("no experiment '" + id + "' in " + directory +
                                " (its experiments: " + ids + ")");
}

std::size_t loadingBranch(const Curve &curve) {
    const std::size_t n = curve.x.size();
    if (n < 3)
        return n;
    // The last sample at the largest x: a repeated x at the turn is still loading.
    const std::size_t peak =
        n - 1 - std::size_t(std::max_element(curve.x.rbegin(), curve.x.rend()) - curve.x.rbegin());
    if (peak + 1 >= n || peak < 2)
        return n;
    // Not falling, rather than rising: an encoder's or a rounded export's x repeats.
    std::size_t forward = 0;
    for (std::size_t i = 1; i <= peak; ++i)
        forward += curve.x[i] >= curve.x[i - 1];
    return 5 * forward >= 4 * peak ? peak + 1 : n;
}

Curve applyZero(const Curve &curve, const ZeroConvention &zero) {
    std::vector<std::size_t> order(curve.x.size());
    for (std::size_t i = 0; i < order.size(); ++i)
        order[i] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return curve.x[a] < curve.x[b]; });
    Curve out;
    for (std::size_t k = 0; k < order.size();) {
        std::size_t j = k;
        double sum = 0.0;
        while (j < order.size() && curve.x[order[j]] == curve.x[order[k]])
            sum += curve.y[order[j++]];
        out.x.push_back(curve.x[order[k]]);
        out.y.push_back(sum / double(j - k));
        k = j;
    }
    if (out.x.empty() || zero.method == ZeroConvention::Method::AsRecorded)
        return out;
    double x0 = out.x.front();
    if (zero.method == ZeroConvention::Method::ForceThreshold) {
        // From the shallowest sample on, the first that reaches the threshold: a loading
        // curve's first contact, whichever order its file was written in.
        const auto first =
            std::find_if(out.y.begin(), out.y.end(), [&](double y) { return y >= zero.threshold; });
        if (first == out.y.end())
            return Curve{}; // never reaches the threshold: nothing to compare
        x0 = out.x[std::size_t(first - out.y.begin())];
    }
    for (double &x : out.x)
        x -= x0;
    return out;
}

std::vector<double> scatterBinMeans(const std::vector<std::pair<double, double>> &points,
                                    const std::vector<double> &edges, std::vector<int> &counts) {
    const std::size_t bins = edges.size() < 2 ? 0 : edges.size() - 1;
    std::vector<double> sum(bins, 0.0);
    counts.assign(bins, 0);
    for (const auto &[x, y] : points)
        for (std::size_t b = 0; b < bins; ++b)
            if (x >= edges[b] && (x < edges[b + 1] || (b + 1 == bins && x == edges[b + 1]))) {
                sum[b] += y;
                ++counts[b];
                break;
            }
    for (std::size_t b = 0; b < bins; ++b)
        sum[b] = counts[b] > 0 ? sum[b] / counts[b] : std::nan("");
    return sum;
}

std::string folderName(const std::string &directory) {
    fs::path p = fs::absolute(directory).lexically_normal();
    if (!p.has_filename())
        p = p.parent_path(); // "meas/"
    return p.filename().string();
}

ExperimentSet loadExperiments(const std::string &directory) {
    const fs::path dir(directory);
    const fs::path file = dir / "experiments.yaml";
    if (!fs::is_regular_file(file))
        throw config::ConfigError(file.string() + ": no such file (a measurements folder holds "
                                                  "experiments.yaml; docs/gap.md)");
    const ConfigNode root = ConfigNode::loadFile(file.string());
    ExperimentSet set;
    set.directory = directory;
    set.name = root.text("name", folderName(directory));
    if (set.name.empty() || set.name.find_first_of("/\\") != std::string::npos)
        root["name"].fail("a name is a word without slashes (it names the default output "
                          "folder out/gap/NAME)");
    const ConfigNode list = root["experiments"];
    if (!list.isSequence())
        list.fail("must be a list of experiments");
    std::set<std::string> ids;
    for (const ConfigNode &node : list.items()) {
        Experiment e;
        e.source = file.string() + ":" + std::to_string(node.line());
        e.id = node["id"].text();
        if (e.id.empty() || e.id.find_first_of(" /\\\t\n") != std::string::npos)
            node["id"].fail("an id is one word without spaces or slashes");
        if (!ids.insert(e.id).second)
            node["id"].fail("experiment id '" + e.id + "' is used twice");
        try {
            e.type = parseType(node["type"].text());
        } catch (const std::invalid_argument &ex) {
            node["type"].fail(ex.what());
        }
        const TypeInfo &ti = info(e.type);
        e.x_name = ti.x_name;

        if (const auto cond = node.optional("conditions")) {
            for (const auto &key : cond->keys()) {
                const ConfigNode c = (*cond)[key];
                // A box or a preparation is a name even when it reads as a number (`box: 1`).
                const bool label = key == "box" || key == "preparation";
                if (label || (dimensionOf(key) == "dimensionless" && !c.isNumber()))
                    e.labels[key] = c.text();
                else
                    e.numbers[key] = c.number();
                // A size in mm or cm under an SI name (80 for 80 mm) is said here, with its
                // experiment, not as the test it would break or the group it would join.
                if (const auto v = e.numbers.find(key);
                    v != e.numbers.end() && dimensionOf(key) == "length") {
                    std::ostringstream m;
                    m << "experiment '" << e.id << "': " << key << " " << v->second;
                    if (v->second < 0.0)
                        c.fail(m.str() + ": a length, >= 0");
                    if (v->second > kLongestLabSize_m && isToolOrBedSize(key)) {
                        m << " m is larger than a lab test's " << kLongestLabSize_m
                          << " m: given in mm? (conditions are in SI: " << v->second / 1000.0
                          << " m for mm)";
                        c.fail(m.str());
                    }
                }
            }
            // A radius where grainlink takes a diameter, or the other way round: read as the
            // condition it is, so the test is not set up from the base's size in its place.
            for (const auto &[other, name, factor] : conditionsOf(e.type).aliases) {
                const auto given = e.numbers.find(other);
                if (given == e.numbers.end())
                    continue;
                const double value = factor * given->second;
                const auto named = e.numbers.find(name);
                if (named != e.numbers.end() &&
                    std::abs(named->second - value) > 1e-9 * std::abs(value)) {
                    std::ostringstream m;
                    m << other << " " << given->second << " and " << name << " " << named->second
                      << " disagree: give one of them";
                    (*cond)[other].fail(m.str());
                }
                e.numbers[name] = value;
                e.numbers.erase(given);
            }
            cond->finish();
        }

        const ConfigNode data = node["data"];
        double plate_area = 0.0; // > 0: the data give the plate's force (force_N)
        if (e.x_name.empty()) {
            // A scalar: values (repeats) with a unit.
            const std::string &obs = ti.observables.front();
            const ConfigNode values = data["values"];
            double factor = 1.0;
            try {
                factor = unitFactor(data["unit"].text(), dimensionOf(obs));
            } catch (const std::invalid_argument &ex) {
                data["unit"].fail(ex.what());
            }
            int row = 0;
            for (double v : values.numbers()) {
                Trial t;
                t.source = e.source + " value " + std::to_string(++row);
                t.curves[obs] = Curve{{0.0}, {v * factor}};
                e.trials.push_back(std::move(t));
            }
            if (e.trials.empty())
                values.fail("give at least one value");
            // An angle of repose lies between 0 and 90 deg (angle_deg's unit): outside, the
            // unit is wrong (rad for deg, or 1690 deg for 29.5 rad).
            for (const Trial &t : e.trials)
                if (const double a = t.curves.at(obs).y[0];
                    obs == "angle_deg" && !(a > 0.0 && a < 90.0))
                    values.fail("an angle of repose lies between 0 and 90 deg; in " +
                                data["unit"].text() + " this value is " + std::to_string(a) +
                                " deg (is the unit right?)");
            e.observables = {obs};
            data.finish();
        } else {
            e.scatter = data.boolean("scatter", false);
            const ConfigNode files = data["files"];
            const ConfigNode y = data["y"];
            std::vector<std::string> obs_names = y.keys();
            // A plate's force, as most codes and load cells give it, read as the pressure under
            // the plate (the simulation's observable).
            if (e.type == ExperimentType::PlateSinkage && y.has("force_N")) {
                if (y.has("pressure_Pa"))
                    y["force_N"].fail("give a plate's force or its pressure, not both");
                const auto d = e.numbers.find("plate_diameter_m");
                if (d == e.numbers.end() || !(d->second > 0.0))
                    y["force_N"].fail("a plate's force needs conditions.plate_diameter_m to "
                                      "become its pressure");
                plate_area = M_PI * d->second * d->second / 4.0;
            }
            for (const auto &o : obs_names)
                if (!isObservableOf(o, e.type) || (o == "force_N" && !(plate_area > 0.0)))
                    y[o].fail(notAnObservable(o, e.type));
            if (obs_names.empty())
                y.fail("name at least one observable");
            e.observables = obs_names;
            std::replace(e.observables.begin(), e.observables.end(), std::string("force_N"),
                         std::string("pressure_Pa"));
            const auto filter = data.optional("filter");
            // A file holding several trials one after the other, told apart by a column.
            const auto trial_column = data.optional("trial");
            if (trial_column && e.scatter)
                trial_column->fail("a scatter's rows are its trials already: no trial column");
            const TableFormat format = parseTableFormat(data);
            const ConfigNode x_node = data["x"];
            // Every key of data: read by now: a misspelt one is said before a file that it
            // would have read (`skip_line`) fails to read.
            data.finish();
            for (const ConfigNode &f : files.items()) {
                const fs::path path = dir / f.text();
                const DataTable table = [&] {
                    try {
                        return readDataTable(path.string(), format);
                    } catch (const config::ConfigError &e) {
                        f.fail(e.what());
                    }
                }();
                const auto [xcol, xfac] = axisColumn(x_node, table, e.x_name);
                std::vector<std::tuple<std::string, std::size_t, double>> ycols;
                for (const auto &o : obs_names) {
                    const auto [c, fac] = axisColumn(y[o], table, o);
                    if (o == "force_N")
                        ycols.emplace_back("pressure_Pa", c, fac / plate_area);
                    else
                        ycols.emplace_back(o, c, fac);
                }
                std::vector<std::pair<std::size_t, double>> keep;
                if (filter)
                    for (const auto &key : filter->keys())
                        keep.emplace_back(columnOf(table, key, (*filter)[key]),
                                          (*filter)[key].number());
                const std::optional<std::size_t> tcol =
                    trial_column ? std::optional<std::size_t>(
                                       columnOf(table, trial_column->text(), *trial_column))
                                 : std::nullopt;
                // The file's trials: one, or one per value of the trial column, in file order;
                // each with the line of every sample (its first observable's).
                std::vector<std::pair<std::string, Trial>> wholes;
                std::vector<std::vector<int>> sample_lines;
                const auto trialOf = [&](const std::string &value) -> std::size_t {
                    for (std::size_t i = 0; i < wholes.size(); ++i)
                        if (wholes[i].first == value)
                            return i;
                    Trial t;
                    t.source = path.string() +
                               (tcol ? " (" + table.header[*tcol] + " " + value + ")" : "");
                    wholes.emplace_back(value, std::move(t));
                    sample_lines.emplace_back();
                    return wholes.size() - 1;
                };
                if (!tcol)
                    trialOf("");
                // A value missing (empty, NaN) leaves that sample out, and is said: a sensor's
                // dropout is no reason to refuse the file; a word where a number belongs is.
                std::vector<int> gaps;
                for (std::size_t r = 0; r < table.rows.size(); ++r) {
                    bool selected = true;
                    for (const auto &[c, v] : keep)
                        selected = selected && !table.missing(r, c) &&
                                   std::abs(table.number(r, c) - v) <= 1e-9 * (1 + std::abs(v));
                    if (!selected)
                        continue;
                    if (tcol && table.missing(r, *tcol)) {
                        gaps.push_back(table.lines[r]);
                        continue;
                    }
                    const std::size_t into = tcol ? trialOf(table.rows[r][*tcol]) : 0;
                    // No x: the row gives nothing; no y: that observable's sample is left out.
                    const bool no_x = table.missing(r, xcol);
                    bool gap = no_x;
                    const double x = no_x ? 0.0 : table.number(r, xcol) * xfac;
                    // A slip lies in [-1, 1): given in % under `unit: "-"` (11.3 for 0.113) it
                    // would drop out of every bin, or reach the wheel test as a slip of 11.
                    if (e.x_name == "slip" && !no_x && !(x >= -1.0 && x < 1.0)) {
                        std::ostringstream m;
                        m << path.string() << ":" << table.lines[r] << ": column '"
                          << table.header[xcol] << "': slip " << x << " lies outside [-1, 1)"
                          << (x_node["unit"].text() == "%" ? ""
                                                           : ": a slip in %? give unit: \"%\"");
                        x_node["unit"].fail(m.str());
                    }
                    Trial t;
                    t.source = path.string() + ":" + std::to_string(table.lines[r]);
                    for (const auto &[o, c, fac] : ycols) {
                        if (no_x || table.missing(r, c)) {
                            gap = true;
                            continue;
                        }
                        Curve &curve = e.scatter ? t.curves[o] : wholes[into].second.curves[o];
                        curve.x.push_back(x);
                        curve.y.push_back(table.number(r, c) * fac);
                        if (o == std::get<0>(ycols.front()))
                            sample_lines[into].push_back(table.lines[r]);
                    }
                    if (gap)
                        gaps.push_back(table.lines[r]);
                    if (e.scatter && !t.curves.empty())
                        e.trials.push_back(std::move(t));
                }
                if (!gaps.empty())
                    set.notes.push_back(path.string() + ": " + std::to_string(gaps.size()) +
                                        " of " + std::to_string(table.rows.size()) +
                                        " rows miss a value (empty or NaN) in a column read; "
                                        "those samples are left out (lines " +
                                        lineList(gaps) + ")");
                if (wholes.empty() && !e.scatter)
                    f.fail("no rows of " + path.string() + " pass the filter");
                for (std::size_t w = 0; w < wholes.size() && !e.scatter; ++w) {
                    Trial &whole = wholes[w].second;
                    // No row passed the filter: no curve was started at all.
                    if (whole.curves.empty() || whole.curves.begin()->second.empty())
                        f.fail("no rows of " + path.string() + " pass the filter");
                    // One sample covers no bin: the experiment would drop out of the diagnosis.
                    for (const auto &[o, curve] : whole.curves)
                        if (curve.x.size() < 2)
                            f.fail(path.string() + ": '" + o + "' has " +
                                   std::to_string(curve.x.size()) + " sample(s) with " + e.x_name +
                                   " and a value" +
                                   (tcol ? " in " + table.header[*tcol] + " " + wholes[w].first
                                         : std::string()) +
                                   "; a curve needs two or more");
                    // Every sample at one x: the wrong column, or the x of a constant.
                    for (const auto &[o, curve] : whole.curves) {
                        const double first = curve.x.front();
                        if (std::all_of(curve.x.begin(), curve.x.end(),
                                        [first](double x) { return x == first; }))
                            data["x"].fail(path.string() + ": every sample of '" + o + "' is at " +
                                           e.x_name + " = " + std::to_string(first) +
                                           ": the x column does not vary (is it the right one?)");
                    }
                    // A length beyond any lab test's (10 m of sinkage under a 20 mm plate): a
                    // column in mm read in m.
                    if (dimensionOf(e.x_name) == "length")
                        for (const auto &[o, curve] : whole.curves) {
                            double far = 0.0;
                            for (double x : curve.x)
                                far = std::max(far, std::abs(x));
                            if (far > kLongestLabSize_m) {
                                std::ostringstream m;
                                m << path.string() << ": " << e.x_name << " reaches " << far
                                  << " m, beyond a lab test's " << kLongestLabSize_m
                                  << " m: is the column in mm? (read in '" << x_node["unit"].text()
                                  << "')";
                                x_node["unit"].fail(m.str());
                            }
                        }
                    if (!tcol)
                        refuseStackedTrials(e, whole.curves.begin()->second, sample_lines[w], data,
                                            path.string());
                    // A plate or shear curve recorded in time order that runs back after its
                    // largest x (unloaded, reversed) keeps its loading branch: binned with it,
                    // the other branch would read low against a loading-only simulation.
                    if (e.type == ExperimentType::PlateSinkage ||
                        e.type == ExperimentType::DirectShear ||
                        e.type == ExperimentType::BevameterShear)
                        for (auto &[o, curve] : whole.curves)
                            if (const std::size_t keep = loadingBranch(curve);
                                keep < curve.x.size()) {
                                set.notes.push_back(path.string() + ": " + o + ": the " +
                                                    std::to_string(curve.x.size() - keep) +
                                                    " samples after the largest " + e.x_name +
                                                    " (an unloading) are left out");
                                curve.x.resize(keep);
                                curve.y.resize(keep);
                            }
                    checkSigns(e.type, whole.curves.begin()->second, data, path.string());
                    e.trials.push_back(std::move(whole));
                }
            }
            if (e.trials.empty())
                files.fail("no data: give at least one file (and rows that pass the filter)");
            if (y.has("sinkage_m"))
                checkWheelSinkage(e, data);
            sayUnlikelyStressRatio(e, set.notes);
            if (filter)
                filter->finish();
        }

        // A value of y with its `unit` (a threshold, a sigma), in the data's own terms: a force
        // where the data give a plate's force.
        const auto yValue = [&](const ConfigNode &parent, const std::string &key) {
            return plate_area > 0.0
                       ? siValue(parent, key, "unit", "force") / plate_area
                       : siValue(parent, key, "unit", dimensionOf(e.observables.front()));
        };
        if (const auto zero = node.optional("zero")) {
            const std::string method =
                (*zero)["method"].choice({"as_recorded", "first_sample", "force_threshold"});
            if (method == "first_sample")
                e.zero.method = ZeroConvention::Method::FirstSample;
            if (method == "force_threshold") {
                e.zero.method = ZeroConvention::Method::ForceThreshold;
                e.zero.threshold = yValue(*zero, "threshold");
            }
            zero->finish();
        }
        if (const auto u = node.optional("uncertainty")) {
            // One sigma has one unit (the first observable's): it cannot serve an observable of
            // another dimension, which would read it in that unit.
            const std::string &first = e.observables.front();
            const auto other = std::find_if(
                e.observables.begin(), e.observables.end(),
                [&](const std::string &o) { return dimensionOf(o) != dimensionOf(first); });
            for (const char *key : {"y_sigma", "y_systematic"})
                if (u->has(key) && plate_area <= 0.0 && other != e.observables.end())
                    (*u)[key].fail("one " + std::string(key) + " in the unit of '" + first +
                                   "' (" + dimensionOf(first) + ") cannot serve '" + *other +
                                   "' (" + dimensionOf(*other) +
                                   "): give y_relative, or one experiment per observable");
            if (u->has("y_sigma"))
                e.uncertainty.y_sigma = yValue(*u, "y_sigma");
            if (u->has("y_systematic"))
                e.uncertainty.y_systematic = yValue(*u, "y_systematic");
            e.uncertainty.y_relative = u->number("y_relative", 0.0);
            if (u->has("x_zero_sigma"))
                e.uncertainty.x_zero_sigma =
                    siValue(*u, "x_zero_sigma", "x_unit", dimensionOf(e.x_name));
            if (u->has("repeats"))
                e.uncertainty.rebuilt_bed =
                    (*u)["repeats"].choice({"rebuilt_bed", "same_bed"}) == "rebuilt_bed";
            if (u->has("beds"))
                e.uncertainty.own_beds = (*u)["beds"].choice({"shared", "own"}) == "own";
            if (e.uncertainty.y_sigma < 0 || e.uncertainty.y_relative < 0 ||
                e.uncertainty.y_systematic < 0 || e.uncertainty.x_zero_sigma < 0)
                u->fail("uncertainties must be >= 0");
            // A fraction: 5 would be a 500 % error, most likely 5 % meant.
            if (e.uncertainty.y_relative >= 1.0)
                (*u)["y_relative"].fail("a fraction of the value (0.05 for 5 %), below 1");
            u->finish();
        }
        if (const auto bins = node.optional("bins")) {
            const double f = [&] {
                try {
                    return unitFactor((*bins)["unit"].text(), dimensionOf(e.x_name));
                } catch (const std::invalid_argument &ex) {
                    (*bins)["unit"].fail(ex.what());
                }
            }();
            for (double v : (*bins)["edges"].numbers())
                e.bin_edges.push_back(v * f);
            if (e.bin_edges.size() < 2 ||
                std::adjacent_find(e.bin_edges.begin(), e.bin_edges.end(),
                                   std::greater_equal<double>()) != e.bin_edges.end())
                (*bins)["edges"].fail("give at least two increasing edges");
            bins->finish();
        }
        refuseUncomparable(e, node);
        node.finish();
        set.experiments.push_back(std::move(e));
    }
    root.finish();
    if (set.experiments.empty())
        list.fail("no experiments");
    sayLevelsApart(set);
    return set;
}

} // namespace grainlink::gap
