#include "grainlink/gap/StudySimulator.hpp"

#include "NotANumber.hpp"

#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/dem/Scenario.hpp"
#include "grainlink/lab/LabSummary.hpp"
#include "grainlink/lab/LabTest.hpp"
#include "grainlink/study/ScenarioEdit.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <tuple>

namespace grainlink::gap {

using config::ConfigNode;

namespace {

/// A test section's loading speeds: a plate's, a shear box's, a carriage's (in m/s, what an
/// experiment's `speed_m_s` is compared with), and with them every rate the rate check scales.
constexpr const char *kSpeedKeys[] = {"speed_m_s", "shear_speed_m_s", "carriage_speed_m_s"};
constexpr const char *kRateKeys[] = {"speed_m_s", "shear_speed_m_s", "angular_speed_rad_s",
                                     "lift_speed_m_s", "carriage_speed_m_s"};

/// v rounded up to two significant digits (0.01089 -> 0.011); 0 stays 0.
double roundUp2(double v) {
    if (!(v > 0.0))
        return v;
    const double step = std::pow(10.0, std::floor(std::log10(v)) - 1.0);
    return std::ceil(v / step * (1.0 - 1e-12)) * step;
}

/// `over` merged into `target`: mappings key by key, anything else replaced; a key set to
/// null (`walls: ~`) is removed.
void mergeInto(YAML::Node target, const YAML::Node &over) {
    if (!over || over.IsNull())
        return;
    if (!over.IsMap() || !target.IsMap()) {
        target = YAML::Clone(over);
        return;
    }
    for (auto it = over.begin(); it != over.end(); ++it) {
        const std::string key = it->first.as<std::string>();
        if (it->second.IsNull()) {
            target.remove(key);
            continue;
        }
        if (target[key] && target[key].IsMap() && it->second.IsMap())
            mergeInto(target[key], it->second);
        else
            target[key] = YAML::Clone(it->second);
    }
}

/// Whether a `box` label gives this type's test its container: a direct shear test builds its
/// own box (the lab refuses walls for it), so a box's walls, region and grain count would
/// only break it.
bool containerOf(ExperimentType type) {
    return type != ExperimentType::DirectShear;
}

std::string boxOf(const Experiment &e) {
    const auto it = e.labels.find("box");
    return it == e.labels.end() ? "" : it->second;
}

/// What a test is run for besides its type and box: its gravity, a bed's depth, a wheel's
/// geometry, load and slope; not what each of its experiments is run at (a plate's size).
std::string setupOf(const Experiment &e) {
    std::ostringstream key;
    key.precision(12);
    const ConditionNames &names = conditionsOf(e.type);
    for (const std::string &c : names.simulated)
        if (const auto it = e.numbers.find(c); it != e.numbers.end() && c != names.per_experiment)
            key << c << '=' << it->second << ';';
    return key.str();
}

/// Why the lab cannot run an experiment of a type it simulates; empty: it can.
std::string unsupported(const Experiment &e) {
    if (const auto g = e.numbers.find("gravity_m_s2");
        g != e.numbers.end() && !(g->second > 0.0 && g->second < 1e3)) {
        std::ostringstream why;
        why << "gravity_m_s2 " << g->second << ": the magnitude of a gravity, > 0";
        return why.str();
    }
    if (const auto d = e.numbers.find("bed_depth_m");
        d != e.numbers.end() && !(d->second > 0.0 && d->second < 1e3)) {
        std::ostringstream why;
        why << "bed_depth_m " << d->second << ": the bed's depth over its floor, > 0";
        return why.str();
    }
    if (const auto a = e.numbers.find("slope_deg");
        a != e.numbers.end() && !(std::abs(a->second) < 60.0)) {
        std::ostringstream why;
        why << "slope " << a->second << " deg: steeper than any soil stands (|slope| < 60 deg)";
        return why.str();
    }
    if (e.type == ExperimentType::WheelSteadyState) {
        const auto beta = e.numbers.find("slip_angle_deg");
        if (beta != e.numbers.end() && !(beta->second >= 0.0 && beta->second <= 90.0)) {
            std::ostringstream why;
            why << "slip angle " << beta->second
                << " deg: the lab's wheel is steered between 0 and 90 deg";
            return why.str();
        }
    }
    return "";
}

/// The numbers of a condition over a group, sorted and unique.
std::vector<double> conditionValues(const ExperimentSet &set, const std::vector<std::string> &ids,
                                    const std::string &key, double scale) {
    std::vector<double> v;
    for (const auto &id : ids) {
        const Experiment &e = set.find(id);
        const auto it = e.numbers.find(key);
        if (it == e.numbers.end()) {
            // A condition it gives that nothing reads is most likely this one misspelt; one that
            // a test of any type reads, or that describes the experiment, is no misspelling.
            std::set<std::string> known(describingConditions().begin(),
                                        describingConditions().end());
            for (const ExperimentType t : experimentTypes())
                for (const std::string &c : conditionsOf(t).simulated)
                    known.insert(c);
            std::string unread;
            for (const auto &[k, value] : e.numbers)
                if (!known.count(k))
                    unread += (unread.empty() ? "" : ", ") + ("'" + k + "'");
            throw std::invalid_argument(
                e.source + ": experiment '" + id + "' (" + typeName(e.type) +
                ") needs the condition '" + key + "'" +
                (unread.empty() ? std::string()
                                : " (it gives " + unread + ", which nothing reads: misspelt?)"));
        }
        v.push_back(it->second * scale);
    }
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
    return v;
}

YAML::Node flowList(const std::vector<double> &v) {
    YAML::Node n(YAML::NodeType::Sequence);
    for (double x : v)
        n.push_back(x);
    n.SetStyle(YAML::EmitterStyle::Flow);
    return n;
}

/// The deposition block of a soil as the DEM reads it (its defaults included).
dem::DepositionSpec depositionOf(YAML::Node soil) {
    return dem::parseDeposition(config::ConfigNode::loadString(YAML::Dump(soil["deposition"]),
                                                               "the base model's soil.deposition"));
}

/// The gravity of a soil's simulation as the DEM reads it (a named body's or a vector).
dem::Vec3 gravityOf(YAML::Node soil) {
    return dem::simulationGravity(config::ConfigNode::loadString(
        YAML::Dump(soil["simulation"]), "the base model's soil.simulation"));
}

/// An experiment's gravity and slope in its soil: the test runs under gravity of the
/// experiment's magnitude (`gravity_m_s2`; the base's without it) tilted about y by its slope
/// (`slope_deg`, a wheel's), (-g sin a, 0, -g cos a): a wheel driving along +x climbs. The bed
/// settles level under that magnitude, unless the base's soil names its own deposition gravity
/// (a bed prepared on Earth and tested in another gravity).
void setGravity(YAML::Node soil, const Experiment &e) {
    const auto g_it = e.numbers.find("gravity_m_s2"), a_it = e.numbers.find("slope_deg");
    if (g_it == e.numbers.end() && a_it == e.numbers.end())
        return;
    YAML::Node sim = soil["simulation"];
    const double g_base = gravityOf(soil).norm();
    const double g = g_it != e.numbers.end() ? g_it->second : g_base;
    const double a = a_it != e.numbers.end() ? a_it->second * M_PI / 180.0 : 0.0;
    sim.remove("gravity_m_s2");
    sim["gravity"] = flowList({-g * std::sin(a), 0.0, -g * std::cos(a)});
    YAML::Node deposition = soil["deposition"];
    if (!deposition["gravity"]) {
        const dem::DepositionSpec spec = depositionOf(soil);
        deposition["gravity"] = flowList({0.0, 0.0, -g});
        // A resting grain's energies scale with m g d: the base's "settled" means the same
        // fraction of them under g (an absolute threshold would pass a Mars bed 2.6 times as
        // restless, and never a bed under ten Earth gravities).
        deposition["settle_kinetic_energy_J"] = spec.settle_kinetic_energy_J * g / g_base;
        // Grains fall sqrt(g_base / g) times as long under a weaker gravity: the settling's
        // time limit with them (else the bed is cut off unsettled, "NOT (time limit)").
        if (g < g_base)
            deposition["max_settle_time_s"] = spec.max_settle_time_s * std::sqrt(g_base / g);
    }
}

/// An experiment's bed depth (`bed_depth_m`, over the deposition region's floor), made as a test
/// bed is brought to a depth: the base's grains poured 1.15 times as deep as it even at the
/// densest packing poured spheres reach, then struck off level at it. The insertion region
/// grows with the count, so that the grains go in as sparsely as the base's.
void setBedDepth(YAML::Node soil, const Experiment &e) {
    const auto it = e.numbers.find("bed_depth_m");
    const std::vector<std::string> &read = conditionsOf(e.type).simulated;
    if (it == e.numbers.end() || std::find(read.begin(), read.end(), "bed_depth_m") == read.end())
        return;
    constexpr double kDensestPour = 0.64; // random close packing of spheres
    constexpr double kOverfill = 1.15;
    YAML::Node deposition = soil["deposition"];
    const dem::DepositionSpec spec = depositionOf(soil);
    const dem::Vec3 span = spec.region_upper_m - spec.region_lower_m;
    const double grain = 4.0 / 3.0 * M_PI * spec.radius.meanCubedRadius();
    const double depth = it->second;
    // Deeper than the bin is high: most often a depth in mm. Said here, with the experiment,
    // rather than as the grain count it would become.
    for (const YAML::Node &w : soil["walls"])
        if (w["type"] && w["type"].as<std::string>() == "box" && w["upper_m"] &&
            spec.region_lower_m.z() + depth > w["upper_m"][2].as<double>())
            throw std::invalid_argument(e.source + ": experiment '" + e.id + "': bed_depth_m " +
                                        std::to_string(depth) + " is deeper than the base's bin '" +
                                        w["name"].as<std::string>("box") + "' is high (" +
                                        std::to_string(w["upper_m"][2].as<double>()) +
                                        " m): a depth in mm?");
    const double count = std::ceil(kOverfill * depth * span.x() * span.y() * kDensestPour / grain);
    const double height = std::max(span.z(), span.z() * count / double(spec.count));
    deposition["count"] = static_cast<long long>(count);
    deposition["region"]["upper_m"] = flowList(
        {spec.region_upper_m.x(), spec.region_upper_m.y(), spec.region_lower_m.z() + height});
    deposition["strike_off_height_m"] = spec.region_lower_m.z() + depth;
    // The last grains fall from a higher top: the settling's time limit grows as the fall's.
    if (height > span.z())
        deposition["max_settle_time_s"] = spec.max_settle_time_s * std::sqrt(height / span.z());
}

/// A mole experiment's coupled run (docs/gap.md, "The mole"): the Simbody mole of the base's
/// `mole:` section and the DEM column of the soil, `strokes` strokes long, to the start of the
/// next cocking (the hull at rest after the last stroke). The windows are whole DEM steps of
/// the soil as the variant left it (a stiffer grain's shorter step), the step rounded down to
/// the coupling's nanosecond tick. The tip starts `clearance` above the struck-off surface, so
/// that a deeper or shallower column meets it alike; the mole's gravity is the soil's.
void moleRun(YAML::Node root, const YAML::Node &coupling_over, int strokes,
             std::optional<double> clearance) {
    YAML::Node mole = root["mole"];
    const auto number = [](const YAML::Node &n, double fallback) {
        return n ? n.as<double>() : fallback;
    };
    YAML::Node soil = root["soil"];
    const double dt = 1e-9 * std::floor(soil["simulation"]["time_step_s"].as<double>() / 1e-9);
    soil["simulation"]["time_step_s"] = dt;
    YAML::Node c;
    c["scheme"] = "explicit-serial";
    c["handshake_timeout_s"] = 1800; // the first run of a packing settles it first
    c["checkpoint_every_windows"] = 20000;
    mergeInto(c, coupling_over);
    const double largest =
        number(c["adaptive"]["max_macro_step_s"], number(c["macro_step_s"], 1e-3));
    const double step = dt * std::max(1.0, std::floor(largest / dt + 1e-9));
    const double end =
        number(mole["first_cocking_s"], 0.0) + strokes * number(mole["stroke_period_s"], 3.6);
    c["end_time_s"] = dt * std::ceil(end / dt - 1e-9);
    c["macro_step_s"] = step;
    c["adaptive"]["min_macro_step_s"] = dt;
    c["adaptive"]["max_macro_step_s"] = step;
    root["coupling"] = c;
    root.remove("name"); // a coupled scenario is named by its folder
    const std::string hull = mole["hull_name"] ? mole["hull_name"].as<std::string>() : "mole";
    root["participants"] = YAML::Load(
        "- {name: mole, role: multibody, command: [grainlink, mbs-node, '{scenario}', --name, "
        "'{name}', --endpoint, '{endpoint}', --out, '{out}']}\n"
        "- {name: soil, role: soil, command: [grainlink, dem-node, '{scenario}', --name, '{name}', "
        "--endpoint, '{endpoint}', --out, '{out}', --bodies, '" +
        hull + "', --progress-interval, '60']}");
    // One world: the mole falls under the soil's gravity (the experiment's, set above).
    const dem::Vec3 g = gravityOf(soil);
    mole["gravity_m_s2"] = flowList({g.x(), g.y(), g.z()});
    const YAML::Node strike = soil["deposition"]["strike_off_height_m"];
    if (strike && clearance && mole["start_tip_position_m"] &&
        mole["start_tip_position_m"].size() == 3)
        mole["start_tip_position_m"][2] = strike.as<double>() + *clearance;
}

/// Every number under `node` times `f` (a radius distribution's sizes).
void scaleAll(YAML::Node node, double f) {
    if (node.IsScalar()) {
        try {
            node = node.as<double>() * f;
        } catch (const YAML::Exception &) {
        }
    } else if (node.IsSequence()) {
        for (std::size_t i = 0; i < node.size(); ++i)
            scaleAll(node[i], f);
    }
}

/// The wheel test's section for a group of wheel experiments (one wheel under one load): a run in
/// every slip bin they are compared in, at the mean slip of the measured runs in it (the bin's
/// centre when it holds none), so that a steep curve is compared where it was measured; and the
/// wheel's size, grousers and load from their conditions over the base model's `wheel:`.
void wheelSection(YAML::Node section, const ExperimentSet &design, const FeatureDesign &fd,
                  const std::vector<std::string> &group, const std::string &base_path) {
    std::set<double> slips;
    for (const auto &id : group) {
        const Experiment &e = design.find(id);
        for (const std::string &o : e.observables) {
            const auto edges = fd.edges.find(id + "/" + o);
            if (edges == fd.edges.end())
                continue;
            // The measured runs' slips binned as their values are (scatterBinMeans of x).
            std::vector<std::pair<double, double>> xx;
            for (const Trial &t : e.trials)
                if (const auto c = t.curves.find(o); e.scatter && c != t.curves.end() && !c->second.empty())
                    xx.emplace_back(c->second.x[0], c->second.x[0]);
            std::vector<int> counts;
            const std::vector<double> mean = scatterBinMeans(xx, edges->second, counts);
            for (std::size_t b = 0; b < mean.size(); ++b) {
                if (e.scatter && counts[b] == 0)
                    continue; // no measured run there: no feature to compare
                const double slip = counts[b] > 0 ? mean[b]
                                                  : 0.5 * (edges->second[b] + edges->second[b + 1]);
                slips.insert(std::round(slip * 1e6) / 1e6);
            }
        }
    }
    if (slips.empty())
        throw std::invalid_argument("wheel experiment '" + group.front() +
                                    "' has no slip bin to simulate");
    section["slips"] = flowList(std::vector<double>(slips.begin(), slips.end()));
    YAML::Node shape = section["shape"];
    if (!shape || !shape.IsMap())
        throw std::invalid_argument(base_path + ": tests.wheel_steady_state.wheel needs its shape "
                                                "(the wheel's keys; conditions override them)");
    const Experiment &e = design.find(group.front());
    const auto condition = [&](const char *key) -> std::optional<double> {
        const auto it = e.numbers.find(key);
        return it == e.numbers.end() ? std::nullopt : std::optional<double>(it->second);
    };
    const auto noGrousers = [&] {
        shape["grouser_count"] = 0;
        for (const char *k : {"grouser_height_m", "grouser_thickness_m", "grouser_shape",
                              "chevron_angle_deg"})
            shape.remove(k);
    };
    if (const auto r = condition("wheel_radius_m"))
        shape["diameter_m"] = 2.0 * *r;
    if (const auto b = condition("wheel_width_m"))
        shape["width_m"] = *b;
    if (const auto h = condition("grouser_height_m")) {
        if (*h == 0.0)
            noGrousers();
        else
            shape["grouser_height_m"] = *h;
    }
    if (const auto n = condition("grouser_count")) {
        if (*n == 0.0)
            noGrousers();
        else
            shape["grouser_count"] = std::llround(*n);
    }
    if (const auto load = condition("load_N"))
        section["load_N"] = *load;
    if (const auto beta = condition("slip_angle_deg"))
        section["slip_angle_deg"] = *beta;
}

/// A wheel experiment's observable over slip from the wheel test's runs: each run's steady
/// value at its slip.
Curve wheelCurve(const lab::LabSummary &summary, const std::string &observable) {
    static const std::set<std::string> steady{"traction_N", "side_force_N", "vertical_load_N",
                                              "sinkage_m", "torque_N_m"};
    const std::string key = observable == "drawbar_pull_N" ? "traction_N" : observable;
    if (!steady.count(key))
        throw std::invalid_argument("the lab's wheel test gives no '" + observable +
                                    "' (traction_N, drawbar_pull_N, vertical_load_N, sinkage_m, "
                                    "torque_N_m, side_force_N)");
    std::vector<std::pair<double, double>> points;
    for (const auto &run : summary.runs)
        points.emplace_back(run.value("slip"), run.value(key));
    std::sort(points.begin(), points.end());
    Curve c;
    for (const auto &[x, y] : points) {
        c.x.push_back(x);
        c.y.push_back(y);
    }
    return c;
}

/// A mole's depth below the bed surface over its strokes, from its run's mbs_summary.json
/// (`grainlink run` adds each stroke's depth from the soil's series): stroke 0 is the hull
/// resting on the grains before the first release.
Curve moleCurve(const nlohmann::json &summary) {
    Curve c;
    const auto before = summary.find("depth_before_strokes_m");
    if (before != summary.end() && before->is_number())
        c.x.push_back(0.0), c.y.push_back(before->get<double>());
    const auto strokes = summary.find("strokes");
    if (strokes == summary.end() || !strokes->is_array())
        return c;
    for (const auto &s : *strokes)
        if (s.value("complete", false) && s.contains("depth_m") && s["depth_m"].is_number())
            c.x.push_back(s["stroke"].get<double>()), c.y.push_back(s["depth_m"].get<double>());
    return c;
}

bool close(double a, double b) {
    return std::abs(a - b) <= 1e-6 * std::max(std::abs(a), std::abs(b));
}

} // namespace

ExperimentSet simulable(const ExperimentSet &set, const BaseModel &base,
                        std::vector<std::string> &left_out) {
    ExperimentSet out = set;
    out.experiments.clear();
    // A condition the simulation does not read is said, once with its experiments:
    // `wheel_load_N` for `load_N` would otherwise leave the base's load in silence.
    std::map<std::string, std::vector<std::string>> unused;
    std::map<std::pair<std::string, std::string>, std::vector<std::string>> undescribed;
    for (const Experiment &e : set.experiments)
        if (!base.tests.count(typeName(e.type)))
            left_out.push_back(e.id + " (" + typeName(e.type) + ": " + base.path + " has no tests." +
                               typeName(e.type) + ")");
        else if (const std::string why = unsupported(e); !why.empty())
            left_out.push_back(e.id + " (" + typeName(e.type) + ": " + why + ")");
        else {
            const std::vector<std::string> &used = conditionsOf(e.type).simulated;
            for (const auto &[key, value] : e.conditionText()) {
                const auto described = base.conditions.find(key);
                if (key == "box" && !containerOf(e.type)) {
                    unused[key].push_back(e.id); // the test builds its own box
                } else if (described != base.conditions.end() || key == "box") {
                    // A text condition the base gives soils for: this value among them?
                    if (described == base.conditions.end() || !described->second.count(value))
                        undescribed[{key, value}].push_back(e.id);
                } else if (std::find(used.begin(), used.end(), key) == used.end()) {
                    unused[key].push_back(e.id);
                }
            }
            out.experiments.push_back(e);
        }
    const auto listed = [](const std::vector<std::string> &ids) {
        std::string list;
        for (std::size_t i = 0; i < ids.size() && i < 4; ++i)
            list += (i ? ", " : "") + ids[i];
        return list + (ids.size() > 4 ? ", ..." : "") + " (" + std::to_string(ids.size()) +
               (ids.size() == 1 ? " experiment" : " experiments");
    };
    for (const auto &[key, ids] : unused) {
        std::set<ExperimentType> types;
        for (const std::string &id : ids)
            types.insert(set.find(id).type);
        std::string read;
        for (const ExperimentType t : types) {
            read += std::string("; a ") + typeName(t) + " test is set up from ";
            for (const std::string &c : conditionsOf(t).simulated)
                read += c + ", ";
        }
        out.notes.push_back("condition '" + key +
                            "' is not simulated (the base's own value stands) in " + listed(ids) +
                            read +
                            "and the text conditions the base's boxes: and conditions: "
                            "describe)");
    }
    for (const auto &[condition, ids] : undescribed) {
        const auto &[key, value] = condition;
        // The base's values for it, and the one this may be a typo of ('Narrow' for 'narrow').
        std::string values, typo;
        if (const auto d = base.conditions.find(key); d != base.conditions.end())
            for (const auto &[v, soil] : d->second) {
                values += (values.empty() ? "" : ", ") + v;
                if (typo.empty() && config::misspelling(value, v))
                    typo = "; '" + v + "' misspelt?";
            }
        out.notes.push_back(key + " '" + value + "' has no soil in " + base.path + " (" +
                            (key == "box" ? "boxes" : "conditions." + key) +
                            (values.empty() ? "" : ": " + values) + typo +
                            "): the base's own soil stands in " + listed(ids) + ")");
    }
    // Every one left out: said with why, as each was (a gravity of -9.81 is no missing test).
    if (out.experiments.empty()) {
        std::string why;
        for (std::size_t i = left_out.size() - set.experiments.size(); i < left_out.size(); ++i)
            why += (why.empty() ? "" : "; ") + left_out[i];
        throw std::invalid_argument(base.path + ": every experiment of " + set.directory +
                                    " is left out, none is simulated: " + why);
    }
    return out;
}

std::string addRateCheckWhereSpeedDiffers(BaseModel &base, const ExperimentSet &set) {
    if (base.checks.count("rate"))
        return "";
    std::vector<std::string> differ;
    double measured = 0.0, simulated = 0.0;
    for (const Experiment &e : set.experiments) {
        const auto speed = e.numbers.find("speed_m_s");
        const auto test = base.tests.find(typeName(e.type));
        if (speed == e.numbers.end() || test == base.tests.end())
            continue;
        const YAML::Node section = test->second[testSectionOf(e.type)];
        for (const char *key : kSpeedKeys)
            if (section && section[key]) {
                const double v = section[key].as<double>();
                if (std::abs(v - speed->second) > 0.1 * std::abs(speed->second)) {
                    if (differ.empty()) // the note's example: the first such experiment
                        measured = speed->second, simulated = v;
                    differ.push_back(e.id);
                }
            }
    }
    if (differ.empty())
        return "";
    base.checks["rate"] = 0.5;
    std::ostringstream note;
    note << differ.size() << (differ.size() == 1 ? " experiment is" : " experiments are")
         << " loaded at another speed than simulated (" << differ.front() << ": " << measured
         << " m/s measured, " << simulated
         << " m/s simulated): the loading rate check (x 0.5) is added to the base's numerical "
            "checks";
    return note.str();
}

std::string testSectionOf(ExperimentType type) {
    switch (type) {
    case ExperimentType::PlateSinkage:
        return "bevameter";
    case ExperimentType::BevameterShear:
        return "bevameter_shear";
    case ExperimentType::DirectShear:
        return "direct_shear";
    case ExperimentType::AngleOfRepose:
        return "repose";
    case ExperimentType::WheelSteadyState:
        return "wheel";
    case ExperimentType::Mole:
        return "mole";
    }
    throw std::invalid_argument(std::string("grainlink gap cannot simulate ") + typeName(type) +
                                " experiments from a base model");
}

BaseModel loadBaseModel(const std::string &path) {
    const ConfigNode root = ConfigNode::loadFile(path);
    BaseModel b;
    b.path = path;
    b.name = root.text("name", "base");
    b.soil = YAML::Clone(root["soil"].yaml());
    if (!b.soil.IsMap())
        root["soil"].fail("the soil is a mapping (docs/scenario.md)");
    const ConfigNode tests = root["tests"];
    for (const std::string &type : tests.keys()) {
        const ConfigNode t = tests[type];
        ExperimentType et;
        try {
            et = parseType(type);
        } catch (const std::invalid_argument &e) {
            t.fail(e.what());
        }
        std::string section;
        try {
            section = testSectionOf(et);
        } catch (const std::invalid_argument &e) {
            t.fail(e.what());
        }
        YAML::Node node;
        node[section] = YAML::Clone(t[section].yaml());
        if (t.has("soil"))
            node["soil"] = YAML::Clone(t["soil"].yaml());
        if (et == ExperimentType::Mole && t.has("coupling"))
            node["coupling"] = YAML::Clone(t["coupling"].yaml());
        if (t.has("probe")) {
            const ConfigNode probe = t["probe"];
            (void)probe["conditions"].items();
            (void)probe["reach"].number();
            node["probe"] = YAML::Clone(probe.yaml());
            probe.finish();
        }
        t.finish();
        b.tests[type] = node;
    }
    const auto readOverlays = [&](const ConfigNode &values, const std::string &condition) {
        for (const std::string &value : values.keys()) {
            const ConfigNode v = values[value];
            b.conditions[condition][value] = YAML::Clone(v["soil"].yaml());
            v.finish();
        }
    };
    if (const auto boxes = root.optional("boxes"))
        readOverlays(*boxes, "box");
    if (const auto conditions = root.optional("conditions"))
        for (const std::string &name : conditions->keys()) {
            if (name == "box")
                (*conditions)[name].fail("a box's container is given under `boxes:`");
            readOverlays((*conditions)[name], name);
        }
    if (const auto n = root.optional("numerics")) {
        b.seeds = int(n->integer("seeds", 2, 64, 3));
        b.signature_seeds = int(n->integer("signature_seeds", 1, 64, 2));
        b.check_seeds = int(n->integer("check_seeds", 1, 64, 3));
        b.threads = int(n->integer("threads", 1, dem::kMaxThreads, 1));
        if (const auto checks = n->optional("checks"))
            for (const std::string &c : checks->keys()) {
                static const std::set<std::string> known{"resolution", "time_step", "domain", "rate"};
                if (!known.count(c))
                    (*checks)[c].fail("unknown numerical check '" + c +
                                      "' (resolution, time_step, domain, rate)");
                const double v = (*checks)[c].number();
                if (!(v > 0.0) || v == 1.0)
                    (*checks)[c].fail("a check's factor is > 0 and not 1");
                b.checks[c] = v;
            }
        n->finish();
    } else {
        b.checks = {{"resolution", 0.8}, {"time_step", 0.5}};
    }
    root.finish();
    return b;
}

namespace {

/// A design of one experiment of `type` with one trial, nothing measured: what the base makes of
/// such a test is read before any real experiment is.
ExperimentSet standIn(ExperimentType type, const std::string &observable, Curve curve,
                      std::map<std::string, double> numbers = {}) {
    Experiment e;
    e.id = testSectionOf(type);
    e.type = type;
    e.x_name = xNameOf(type);
    e.observables = {observable};
    e.numbers = std::move(numbers);
    Trial t;
    t.curves[observable] = std::move(curve);
    e.trials.push_back(t);
    ExperimentSet set;
    set.experiments.push_back(e);
    return set;
}

} // namespace

StudySimulator::StudySimulator(BaseModel base, std::string directory,
                               study::ExecutorOptions executor)
    : base_(std::move(base)), directory_(std::move(directory)), executor_(std::move(executor)) {
    collectLabWarnings();
    // A mole's run is read by `grainlink run`'s reader when a point runs, in a file the
    // diagnosis writes: a typo in the base's mole is said now, naming the base.
    const study::Kind run = study::standardKind("run", "");
    if (!base_.tests.count("mole") || !run.validate)
        return;
    const ExperimentSet stand_in =
        standIn(ExperimentType::Mole, "depth_m", Curve{{0.0, 1.0}, {0.0, 0.0}});
    VariantRequest plain;
    plain.label = "base";
    try {
        run.validate(config::ConfigNode::loadString(
            study::emitYaml(scenarioNode(stand_in, {"mole"}, plain, 0)),
            base_.path + " (the run tests.mole makes)"));
    } catch (const std::exception &ex) {
        throw std::invalid_argument(base_.path +
                                    ": tests.mole (its mole: under tests.mole.mole, "
                                    "its column under soil and tests.mole.soil): " +
                                    ex.what());
    }
}

std::vector<std::string> StudySimulator::checks() const {
    std::vector<std::string> c;
    for (const auto &[name, f] : base_.checks)
        c.push_back(name);
    return c;
}

YAML::Node StudySimulator::referenceScenario() const {
    YAML::Node r;
    r["soil"] = YAML::Clone(base_.soil);
    for (const auto &[type, node] : base_.tests)
        for (auto it = node.begin(); it != node.end(); ++it) {
            const std::string k = it->first.as<std::string>();
            if (k != "soil" && k != "probe")
                r[k] = YAML::Clone(it->second);
        }
    return r;
}

std::vector<StudySimulator::Overlay> StudySimulator::overlaysOf(const Experiment &e) const {
    std::vector<Overlay> out;
    for (const auto &[condition, values] : base_.conditions) {
        const auto label = e.labels.find(condition);
        if (label == e.labels.end() || (condition == "box" && !containerOf(e.type)))
            continue;
        const auto soil = values.find(label->second);
        if (soil != values.end())
            out.insert(condition == "box" ? out.begin() : out.end(),
                       Overlay{condition, label->second, soil->second});
    }
    return out;
}

std::vector<std::vector<std::string>>
StudySimulator::groups(const ExperimentSet &design,
                       const std::vector<VariantRequest> &requests) const {
    if (std::any_of(requests.begin(), requests.end(),
                    [](const VariantRequest &r) { return r.own_beds; })) {
        std::vector<std::vector<std::string>> alone;
        for (const Experiment &e : design.experiments)
            alone.push_back({e.id});
        return alone;
    }
    // Experiments of one type in one box share a bed: one lab test runs them all (wheels: those
    // of one wheel under one load).
    std::map<std::tuple<ExperimentType, std::string, std::string>, std::vector<std::string>> g;
    for (const Experiment &e : design.experiments) {
        std::string key = setupOf(e);
        for (const Overlay &o : overlaysOf(e))
            key += o.condition + '=' + o.value + ';';
        g[{e.type, boxOf(e), key}].push_back(e.id);
    }
    std::vector<std::vector<std::string>> out;
    for (auto &[key, ids] : g)
        out.push_back(ids);
    return out;
}

YAML::Node StudySimulator::scenarioNode(const ExperimentSet &design,
                                        const std::vector<std::string> &group,
                                        const VariantRequest &request, int seed) const {
    const Experiment &first = design.find(group.front());
    const std::string type = typeName(first.type);
    const std::string test = testSectionOf(first.type);
    const auto t = base_.tests.find(type);
    if (t == base_.tests.end() || !t->second[test])
        throw std::invalid_argument(base_.path + ": the base model says nothing of how to simulate " +
                                    type + " experiments (add tests." + type + "." + test +
                                    ", docs/gap.md)");
    // The soil of the experiment's text conditions that the base describes, its box's first (a
    // box or preparation the base does not describe leaves the base's soil: the scenario, and
    // so the cached run, is then the same for every such value; `simulable` says so).
    YAML::Node root;
    root["name"] = base_.name + "-" + type;
    root["soil"] = YAML::Clone(base_.soil);
    mergeInto(root["soil"], t->second["soil"]);
    for (const Overlay &o : overlaysOf(first)) {
        root["name"] = root["name"].as<std::string>() + "-" + o.value;
        mergeInto(root["soil"], o.soil);
    }
    YAML::Node section = YAML::Clone(t->second[test]);
    // The mole's tip keeps its height above the struck surface of the base's column (10 mm over
    // a column the base does not strike off, when the experiment gives its depth).
    std::optional<double> clearance;
    if (test == "mole") {
        const YAML::Node strike = root["soil"]["deposition"]["strike_off_height_m"];
        const YAML::Node tip = section["start_tip_position_m"];
        if (strike && tip && tip.IsSequence() && tip.size() == 3)
            clearance = tip[2].as<double>() - strike.as<double>();
        else if (first.numbers.count("bed_depth_m"))
            clearance = 0.01;
    }
    setGravity(root["soil"], first);
    setBedDepth(root["soil"], first);
    const FeatureDesign fd = designFeatures(design);
    double reach = 0.0;
    for (const auto &id : group)
        for (const auto &o : design.find(id).observables) {
            const auto r = fd.x_reach.find(id + "/" + o);
            if (r != fd.x_reach.end() && std::isfinite(r->second))
                reach = std::max(reach, r->second);
        }
    // Conditions of the experiments, and a reach beyond the measured one: room for a zero
    // offset (the catalogue's prior: +-2 mm) and a compliant rig's extra travel. Rounded up to
    // two significant digits, so that data sets reaching nearly as far share their runs.
    const double beyond = roundUp2(1.1 * reach);
    if (test == "bevameter") {
        section["plate_radii_m"] = flowList(conditionValues(design, group, "plate_diameter_m", 0.5));
        section["max_sinkage_m"] = beyond + 0.002;
    } else if (test == "direct_shear") {
        section["normal_stresses_Pa"] = flowList(conditionValues(design, group, "normal_stress_Pa", 1.0));
        section["max_displacement_m"] = beyond;
    } else if (test == "bevameter_shear") {
        section["normal_pressures_Pa"] = flowList(conditionValues(design, group, "normal_pressure_Pa", 1.0));
        section["max_shear_displacement_m"] = beyond;
    } else if (test == "wheel") {
        wheelSection(section, design, fd, group, base_.path);
    }
    // A mole run hammers as many strokes as the measured depth curve reaches (its x).
    const int strokes = std::max(1, int(std::ceil(reach - 1e-6)));
    root[test] = section;
    YAML::Node soil = root["soil"];
    const long long seed0 = soil["deposition"]["seed"] ? soil["deposition"]["seed"].as<long long>() : 1;
    soil["deposition"]["seed"] = seed0 + seed;
    soil["simulation"]["threads"] = base_.threads;

    for (auto [effect, strength] : {std::pair{request.effect, request.strength},
                                    std::pair{request.second, request.second_strength}})
        if (effect && effect->kind != Effect::Kind::Measurement)
            root = applyEffect(*effect, strength, root, first.type);

    if (!request.check.empty()) {
        const double f = base_.checks.at(request.check);
        YAML::Node s = root["soil"];
        if (request.check == "resolution") {
            // Grains f times the size, the same solid volume, a time step f times as long.
            YAML::Node r = s["deposition"]["radius"];
            for (const char *k : {"value_m", "min_m", "max_m", "radii_m"})
                if (r[k])
                    scaleAll(r[k], f);
            s["deposition"]["count"] = std::llround(s["deposition"]["count"].as<double>() / (f * f * f));
            s["simulation"]["time_step_s"] = s["simulation"]["time_step_s"].as<double>() * f;
        } else if (request.check == "time_step") {
            s["simulation"]["time_step_s"] = s["simulation"]["time_step_s"].as<double>() * f;
        } else if (request.check == "domain") {
            Effect domain;
            domain.kind = Effect::Kind::Builtin;
            domain.builtin = "domain_size";
            root = applyEffect(domain, f, root, first.type);
        } else if (request.check == "rate") {
            YAML::Node sec = root[test];
            for (const char *k : kRateKeys)
                if (sec[k])
                    sec[k] = sec[k].as<double>() * f;
            if (sec["sample_interval_s"])
                sec["sample_interval_s"] = sec["sample_interval_s"].as<double>() / f;
            // The mole's loading rate is its strokes' rate (each stroke's impact is the
            // mechanism's own): the period is compressed from the flight model's 3.6 s.
            if (test == "mole")
                sec["stroke_period_s"] =
                    (sec["stroke_period_s"] ? sec["stroke_period_s"].as<double>() : 3.6) / f;
        }
    }
    if (test == "mole")
        moleRun(root, t->second["coupling"], strokes, clearance);
    return root;
}

std::string StudySimulator::scenarioText(const ExperimentSet &design,
                                         const std::vector<std::string> &group,
                                         const VariantRequest &request, int seed) const {
    return study::emitYaml(scenarioNode(design, group, request, seed));
}

study::Study StudySimulator::studyOf(const ExperimentSet &design,
                                     const std::vector<std::vector<std::string>> &gs,
                                     const std::vector<VariantRequest> &requests,
                                     std::vector<Slot> &slots) const {
    study::Study st;
    st.name = "gap";
    st.directory = directory_;
    std::map<std::string, std::size_t> index; // point id -> position in st.points
    slots.clear();
    for (std::size_t r = 0; r < requests.size(); ++r)
        for (int s = 0; s < requests[r].seeds; ++s)
            for (std::size_t g = 0; g < gs.size(); ++g) {
                const Experiment &e = design.find(gs[g].front());
                // The diagnosis reads the summary only (the lab kind makes no plot); a mole
                // hammers in a coupled run.
                study::Kind kind = e.type == ExperimentType::Mole
                                       ? study::standardKind("run", "")
                                       : study::standardKind("lab", testSectionOf(e.type));
                // Beds of its own: another packing seed for every experiment.
                const int seed =
                    requests[r].seed_offset + s + (requests[r].own_beds ? 1009 * int(g + 1) : 0);
                const YAML::Node scenario = scenarioNode(design, gs[g], requests[r], seed);
                if (kind.summary_file_of)
                    kind.summary_file = kind.summary_file_of(scenario);
                // Named by every experiment of its group: one lab test runs them all, and a
                // refused scenario (a plate of 80 m) may be any one's, not the first's.
                std::string ids;
                for (std::size_t i = 0; i < gs[g].size() && i < 4; ++i)
                    ids += (i ? ", " : "") + gs[g][i];
                if (gs[g].size() > 4)
                    ids += ", ... (" + std::to_string(gs[g].size()) + " experiments)";
                const study::Point p =
                    study::makePoint(kind, study::emitYaml(scenario),
                                     requests[r].label + " seed " + std::to_string(s) + " " + ids);
                auto [it, fresh] = index.try_emplace(p.id, st.points.size());
                if (fresh)
                    st.points.push_back(p);
                slots.push_back({r, s, g, it->second});
            }
    return st;
}

std::string StudySimulator::refusal(const ExperimentSet &design,
                                    const VariantRequest &request) const {
    try {
        plan(design, {request});
    } catch (const std::exception &e) {
        return e.what();
    }
    return "";
}

namespace {

/// Where in the base file `key` (a dotted path a generated scenario's error names, such as
/// soil.material.youngs_modulus_pa) was written: in its soil, a test's soil or section, a
/// box's or a condition's soil. "" where it is in none of them (a value the diagnosis made).
std::string baseLineOf(const std::string &base_path, const std::string &key) {
    std::vector<std::string> parts;
    for (std::size_t a = 0, b; a <= key.size(); a = b + 1) {
        b = std::min(key.find('.', a), key.size());
        parts.push_back(key.substr(a, b - a));
    }
    const auto walk = [&](ConfigNode node) -> std::optional<int> {
        for (const std::string &p : parts) {
            const bool index = !p.empty() && p.find_first_not_of("0123456789") == std::string::npos;
            if (index && node.yaml().IsSequence() && std::stoul(p) < node.yaml().size())
                node = node.items()[std::stoul(p)];
            else if (node.yaml().IsMap() && node.has(p))
                node = node[p];
            else
                return std::nullopt;
        }
        return node.line();
    };
    std::vector<ConfigNode> roots; // where the key may start
    try {
        const ConfigNode root = ConfigNode::loadFile(base_path);
        roots.push_back(root);
        for (const char *overlays : {"tests", "boxes"})
            if (root.has(overlays))
                for (const std::string &k : root[overlays].keys())
                    roots.push_back(root[overlays][k]);
        if (root.has("conditions"))
            for (const std::string &c : root["conditions"].keys())
                for (const std::string &v : root["conditions"][c].keys())
                    roots.push_back(root["conditions"][c][v]);
        std::string lines;
        for (const ConfigNode &node : roots)
            if (const auto line = walk(node))
                lines += (lines.empty() ? "" : ", ") + std::to_string(*line);
        return lines.empty() ? "" : base_path + ":" + lines;
    } catch (const std::exception &) {
        return "";
    }
}

} // namespace

std::string StudySimulator::withBaseLine(const std::string &what) const {
    // A generated scenario's error names its key ("key 'soil.x'"); say where the base wrote it.
    const std::string marker = "key '";
    const auto at = what.find(marker);
    const auto end = at == std::string::npos ? at : what.find('\'', at + marker.size());
    const std::string where =
        end == std::string::npos
            ? ""
            : baseLineOf(base_.path, what.substr(at + marker.size(), end - at - marker.size()));
    return where.empty() ? what : what + " (written in " + where + ")";
}

void StudySimulator::collectLabWarnings() {
    // What the lab says of the base's direct shear box (one under ten grains across) is said
    // once here, at the line of the base that wrote it, where it would otherwise sit unread in
    // every run's log. An error is left to the runs' own check, which names it with its runs.
    if (!base_.tests.count("direct_shear"))
        return;
    const ExperimentSet stand_in =
        standIn(ExperimentType::DirectShear, "shear_stress_Pa", Curve{{0.0, 1.0e-3}, {0.0, 1.0}},
                {{"normal_stress_Pa", 1.0e4}});
    VariantRequest plain;
    plain.label = "base";
    try {
        const lab::LabScenario scenario = lab::parseLabScenario(
            "direct_shear",
            ConfigNode::loadString(
                study::emitYaml(scenarioNode(stand_in, {"direct_shear"}, plain, 0)), base_.path));
        for (const config::KeyWarning &w : lab::labWarnings(scenario)) {
            const std::string where = baseLineOf(base_.path, w.key);
            lab_warnings_.push_back((where.empty() ? base_.path : where) +
                                    ": tests.direct_shear: '" + w.key + "': " + w.message);
        }
    } catch (const std::exception &) {
    }
}

void StudySimulator::sayLabWarnings() const {
    for (const std::string &warning : lab_warnings_)
        std::fprintf(stderr, "[gap] base: %s\n", warning.c_str());
}

std::vector<std::string> StudySimulator::runIds(const ExperimentSet &design,
                                                const VariantRequest &request) const {
    std::vector<Slot> slots;
    const study::Study st = studyOf(design, groups(design, {request}), {request}, slots);
    std::vector<std::string> ids;
    for (const study::Point &p : st.points)
        ids.push_back(p.id);
    return ids;
}

StudySimulator::RunCount StudySimulator::plan(const ExperimentSet &design,
                                              const std::vector<VariantRequest> &requests) const {
    std::vector<Slot> slots;
    const study::Study st = studyOf(design, groups(design, requests), requests, slots);
    try {
        study::validate(st);
    } catch (const std::exception &e) {
        throw std::invalid_argument(withBaseLine(e.what()));
    }
    RunCount count;
    for (const study::PointResult &r : study::collect(st)) {
        ++count.runs;
        count.done += r.status == study::PointStatus::Done;
        count.failed += r.status == study::PointStatus::Failed;
    }
    return count;
}

std::vector<SimulatedCurves> StudySimulator::curves(const ExperimentSet &design,
                                                    const std::vector<VariantRequest> &requests,
                                                    std::vector<int> &seeds_of) {
    const auto gs = groups(design, requests);
    std::vector<Slot> slots;
    const study::Study st = studyOf(design, gs, requests, slots);
    const auto results = [&] { // study::run validates every point before it runs one
        try {
            return study::run(st, executor_);
        } catch (const std::exception &e) {
            throw std::runtime_error(withBaseLine(e.what()));
        }
    }();
    for (const auto &res : results)
        (res.ran_now ? runs_done_ : runs_reused_)++;

    // Parse each finished point once.
    std::vector<std::optional<lab::LabSummary>> summaries(results.size());
    for (std::size_t i = 0; i < results.size(); ++i) {
        if (results[i].status != study::PointStatus::Done) {
            std::fprintf(stderr, "[gap] run %s (%s) %s: %s; log %s; its features are missing\n",
                         results[i].point.id.c_str(), results[i].point.label.c_str(),
                         results[i].status == study::PointStatus::Failed ? "failed" : "unfinished",
                         results[i].error.c_str(), results[i].log.c_str());
            continue;
        }
        if (results[i].point.kind.name != "run")
            summaries[i] = lab::labSummaryFromJson(results[i].summary.dump(), results[i].folder);
    }
    std::vector<SimulatedCurves> out;
    seeds_of.clear();
    for (std::size_t r = 0; r < requests.size(); ++r)
        for (int s = 0; s < requests[r].seeds; ++s) {
            SimulatedCurves c;
            for (const Slot &slot : slots) {
                if (slot.request != r || slot.seed != s ||
                    results[slot.point].status != study::PointStatus::Done)
                    continue;
                if (!summaries[slot.point]) { // a mole's coupled run
                    for (const std::string &id : gs[slot.group])
                        c[id]["depth_m"] = moleCurve(results[slot.point].summary);
                    continue;
                }
                const lab::LabSummary &sum = *summaries[slot.point];
                for (const std::string &id : gs[slot.group]) {
                    const Experiment &e = design.find(id);
                    if (e.type == ExperimentType::WheelSteadyState) {
                        for (const std::string &o : e.observables)
                            c[id][o] = wheelCurve(sum, o);
                        continue;
                    }
                    for (const std::string &obs : e.observables) {
                        Curve curve;
                        const auto pick = [&](const char *value_key, double want, const char *x,
                                              const char *y) {
                            for (const auto &run : sum.runs)
                                if (close(run.value(value_key), want)) {
                                    curve.x = run.curve(x);
                                    curve.y = run.curve(y);
                                }
                        };
                        switch (e.type) {
                        case ExperimentType::PlateSinkage:
                            pick("plate_radius_m", 0.5 * e.numbers.at("plate_diameter_m"),
                                 "sinkage_m", "pressure_Pa");
                            break;
                        case ExperimentType::DirectShear:
                            pick("target_normal_stress_Pa", e.numbers.at("normal_stress_Pa"),
                                 "displacement_m",
                                 obs == "vertical_displacement_m" ? "plate_height_m"
                                                                  : "shear_stress_Pa");
                            break;
                        case ExperimentType::BevameterShear:
                            pick("target_pressure_Pa", e.numbers.at("normal_pressure_Pa"),
                                 "shear_displacement_m", "shear_stress_Pa");
                            break;
                        case ExperimentType::AngleOfRepose:
                            for (const auto &fit : sum.fits)
                                if (fit.law == "repose")
                                    curve = Curve{{0.0}, {sum.fitted("repose", "angle").value}};
                            // The grains spread flat: no heap, a slope of zero. A missing value
                            // would drop the bed, and a model whose beds mostly spread would be
                            // judged by the one that kept a heap.
                            if (curve.empty())
                                curve = Curve{{0.0}, {0.0}};
                            break;
                        default:
                            break;
                        }
                        for (auto [effect, strength] :
                             {std::pair{requests[r].effect, requests[r].strength},
                              std::pair{requests[r].second, requests[r].second_strength}})
                            if (effect && effect->kind == Effect::Kind::Measurement)
                                curve = applyMeasurementEffect(*effect, strength, e, obs, curve);
                        c[id][obs] = curve;
                    }
                }
            }
            out.push_back(std::move(c));
            seeds_of.push_back(s);
        }
    return out;
}

std::vector<Eigen::MatrixXd> StudySimulator::simulate(const ExperimentSet &design,
                                                      const FeatureDesign &features,
                                                      const std::vector<VariantRequest> &requests) {
    std::vector<int> seeds;
    const auto all = curves(design, requests, seeds);
    std::vector<Eigen::MatrixXd> out;
    std::size_t k = 0;
    for (const VariantRequest &r : requests) {
        Eigen::MatrixXd rows(r.seeds, Eigen::Index(features.size()));
        for (int s = 0; s < r.seeds; ++s)
            rows.row(s) = simulatedFeatures(design, features, all[k++]).transpose();
        out.push_back(rows);
    }
    return out;
}

std::vector<ExperimentSet> StudySimulator::probes(const ExperimentSet &design) const {
    std::set<std::string> present;
    for (const Experiment &e : design.experiments)
        present.insert(typeName(e.type));
    std::vector<ExperimentSet> out;
    for (const auto &[type, node] : base_.tests) {
        if (present.count(type) || !node["probe"])
            continue;
        ExperimentSet p;
        p.name = type; // its conditions are named with the feature that separates most
        p.directory = base_.path;
        int k = 0;
        for (const auto &cond : node["probe"]["conditions"]) {
            Experiment e;
            e.id = "probe_" + type + "_" + std::to_string(k++);
            e.type = parseType(type);
            e.source = base_.path + ": tests." + type + ".probe";
            for (auto it = cond.begin(); it != cond.end(); ++it) {
                const std::string key = it->first.as<std::string>();
                try {
                    e.numbers[key] = it->second.as<double>();
                } catch (const YAML::Exception &) {
                    e.labels[key] = it->second.as<std::string>();
                }
            }
            // A flat stand-in trial over the probe's reach: it only sets the bins.
            const double reach = node["probe"]["reach"].as<double>();
            if (e.type == ExperimentType::PlateSinkage) {
                e.x_name = "sinkage_m", e.observables = {"pressure_Pa"};
            } else if (e.type == ExperimentType::DirectShear || e.type == ExperimentType::BevameterShear) {
                e.x_name = "shear_displacement_m", e.observables = {"shear_stress_Pa"};
            } else {
                e.x_name = "", e.observables = {"angle_deg"};
            }
            Trial t;
            t.curves[e.observables[0]] = e.x_name.empty() ? Curve{{0.0}, {0.0}} : Curve{{0.0, reach}, {0.0, 0.0}};
            e.trials.push_back(t);
            p.experiments.push_back(e);
        }
        out.push_back(p);
    }
    return out;
}

std::string StudySimulator::bedGroup(const Experiment &experiment) const {
    const auto box = experiment.labels.find("box");
    return std::string(typeName(experiment.type)) +
           (box != experiment.labels.end() ? " in box " + box->second : std::string());
}

} // namespace grainlink::gap
