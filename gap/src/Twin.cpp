#include "grainlink/gap/Twin.hpp"

#include "grainlink/config/ConfigNode.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>

namespace grainlink::gap {

namespace fs = std::filesystem;
using config::ConfigNode;

namespace {

/// A design experiment's observables: its `observables` list, or by default a wheel's
/// traction, sinkage and torque and every other test's first (a shear box's stress).
std::vector<std::string> designObservables(const ConfigNode &n, ExperimentType type) {
    const auto list = n.optional("observables");
    const auto &allowed = observablesOf(type);
    if (!list)
        return type == ExperimentType::WheelSteadyState
                   ? std::vector<std::string>{"traction_N", "sinkage_m", "torque_N_m"}
                   : std::vector<std::string>{allowed.front()};
    std::vector<std::string> out;
    for (const ConfigNode &o : list->items()) {
        // A plate's force is read into its pressure: a design names the pressure.
        if (std::find(allowed.begin(), allowed.end(), o.text()) == allowed.end() ||
            o.text() == "force_N")
            o.fail("'" + o.text() + "' is not an observable of " + typeName(type));
        out.push_back(o.text());
    }
    if (out.empty())
        list->fail("name at least one observable");
    return out;
}

} // namespace

Design loadDesign(const std::string &path) {
    const ConfigNode root = ConfigNode::loadFile(path);
    Design d;
    d.set.name = root.text("name", fs::path(path).stem().string());
    d.set.directory = fs::path(path).parent_path().string();
    std::set<std::string> ids;
    for (const ConfigNode &n : root["experiments"].items()) {
        Experiment e;
        e.source = path + ":" + std::to_string(n.line());
        e.id = n["id"].text();
        if (!ids.insert(e.id).second)
            n["id"].fail("experiment id '" + e.id + "' is used twice");
        try {
            e.type = parseType(n["type"].text());
        } catch (const std::invalid_argument &ex) {
            n["type"].fail(ex.what());
        }
        e.observables = designObservables(n, e.type);
        e.x_name = xNameOf(e.type);
        if (const auto c = n.optional("conditions")) {
            for (const auto &key : c->keys()) {
                const ConfigNode v = (*c)[key];
                if (dimensionOf(key) == "dimensionless" && !v.isNumber())
                    e.labels[key] = v.text();
                else
                    e.numbers[key] = v.number();
            }
            c->finish();
        }
        if (e.type == ExperimentType::WheelSteadyState) {
            // A scatter over slip: one stand-in run at each slip the wheel is tested at.
            e.scatter = true;
            const ConfigNode slips = n["slips"];
            for (double slip : slips.numbers()) {
                if (!(slip >= -1.0 && slip <= 1.0))
                    slips.fail("a slip lies in [-1, 1]");
                Trial run;
                for (const std::string &o : e.observables)
                    run.curves[o] = Curve{{slip}, {0.0}};
                e.trials.push_back(run);
            }
            if (e.trials.empty())
                slips.fail("give at least one slip");
        } else {
            Trial stand_in;
            const double reach = e.x_name.empty() ? 0.0 : n["reach"].positive();
            for (const std::string &o : e.observables)
                stand_in.curves[o] =
                    e.x_name.empty() ? Curve{{0.0}, {0.0}} : Curve{{0.0, reach}, {0.0, 0.0}};
            e.trials.push_back(stand_in);
        }
        d.repeats[e.id] = int(n.integer("repeats", 1, 32, 2));
        n.finish();
        d.set.experiments.push_back(std::move(e));
    }
    root.finish();
    return d;
}

double drawStrength(const Effect &effect, unsigned seed, StrengthDraw draw,
                    const std::vector<double> &failed) {
    std::mt19937 rng(seed * 2654435761u + 17u);
    const Prior &p = effect.prior;
    double lo = p.toScale(p.lo), hi = p.toScale(p.hi);
    const double off_t = p.toScale(p.off);
    for (double f : failed) { // what failed there fails farther from off too
        const double t = p.toScale(f);
        if (t < off_t)
            lo = std::max(lo, t);
        else if (t > off_t)
            hi = std::min(hi, t);
    }
    std::uniform_real_distribution<double> u(lo, hi);
    double t = u(rng);
    if (draw == StrengthDraw::FarHalf) {
        const double off = std::clamp(off_t, lo, hi);
        const double side = t < off ? off - lo : hi - off;
        const double d = std::abs(t - off);
        t = off + std::copysign(0.5 * side + 0.5 * d, t - off);
    }
    return p.fromScale(t);
}

TwinKey makeTwin(const Design &design, const EffectCatalogue &catalogue, StudySimulator &simulator,
                 const TwinOptions &options, const std::string &out, const std::string &key_path) {
    TwinKey key;
    key.seed = options.seed;
    key.noise = options.noise;
    key.level_noise = options.level_noise;
    key.own_beds = options.own_beds;
    const Effect *effect = nullptr;
    if (!options.effect.empty()) {
        effect = &catalogue.find(options.effect);
        key.effect = effect->name;
        key.in_catalogue = effect->in_catalogue;
        key.strength = options.strength ? *options.strength : drawStrength(*effect, options.seed);
        if (!effect->prior.contains(key.strength))
            std::fprintf(stderr, "[twin] %s = %g lies outside its prior [%g, %g]\n",
                         effect->name.c_str(), key.strength, effect->prior.lo, effect->prior.hi);
    }
    std::vector<int> seeds;
    writeTwin(design, simulator.curves(design.set, {twinRequest(design, key, effect)}, seeds), key,
              out, key_path);
    return key;
}

VariantRequest twinRequest(const Design &design, const TwinKey &key, const Effect *effect) {
    int most = 1;
    for (const auto &[id, r] : design.repeats)
        most = std::max(most, r);
    VariantRequest truth;
    truth.label = "twin " + (key.effect.empty() ? std::string("null") : key.effect) + " seed " +
                  std::to_string(key.seed);
    truth.effect = effect;
    truth.strength = key.strength;
    truth.seeds = most;
    // The twin's beds are other realisations than the ones the diagnosis simulates.
    truth.seed_offset = 1000 + 37 * int(key.seed % 1000);
    truth.own_beds = key.own_beds;
    return truth;
}

void writeTwin(const Design &design, const std::vector<SimulatedCurves> &curves, const TwinKey &key,
               const std::string &out, const std::string &key_path) {
    fs::create_directories(fs::path(out) / "data");
    std::mt19937 rng(key.seed * 7919u + 3u);
    std::normal_distribution<double> z;
    YAML::Node root;
    root["name"] = folderName(out);
    YAML::Node list(YAML::NodeType::Sequence);
    for (const Experiment &e : design.set.experiments) {
        const std::string &obs = e.observables[0];
        YAML::Node n;
        n["id"] = e.id;
        n["type"] = typeName(e.type);
        YAML::Node cond;
        for (const auto &[k, v] : e.numbers)
            cond[k] = v;
        for (const auto &[k, v] : e.labels)
            cond[k] = v;
        if (cond.size())
            n["conditions"] = cond;
        std::vector<double> scalar_values;
        YAML::Node files(YAML::NodeType::Sequence);
        for (int r = 0; r < design.repeats.at(e.id); ++r) {
            const auto it = curves[std::size_t(r)].find(e.id);
            if (it == curves[std::size_t(r)].end() || it->second.at(obs).empty()) {
                // A run that failed (its log says why) is a trial that was not made.
                std::fprintf(stderr, "[twin] %s: repeat %d has no simulation; left out\n",
                             e.id.c_str(), r + 1);
                continue;
            }
            const Curve &c = it->second.at(obs);
            const double level = 1.0 + key.level_noise * z(rng);
            if (e.x_name.empty()) {
                // A repose test whose grains spread gives no angle: that repeat has no value.
                if (std::isfinite(c.y[0]))
                    scalar_values.push_back(c.y[0] * level * (1.0 + key.noise * z(rng)));
                continue;
            }
            const std::string file = "data/" + e.id + "_" + std::to_string(r + 1) + ".csv";
            std::ofstream f(fs::path(out) / file);
            f.precision(10);
            f << "# twin of " << e.id << ", repeat " << r + 1 << "\n" << e.x_name;
            for (const std::string &o : e.observables)
                f << ',' << o;
            f << '\n';
            if (e.scatter) {
                // A wheel: a row per slip run, where every observable has its steady value.
                for (double x : c.x) {
                    std::vector<double> row;
                    for (const std::string &o : e.observables) {
                        const auto found = it->second.find(o);
                        if (found == it->second.end())
                            break;
                        const Curve &oc = found->second;
                        const auto at = std::find(oc.x.begin(), oc.x.end(), x);
                        const std::size_t j = std::size_t(at - oc.x.begin());
                        if (at == oc.x.end() || !std::isfinite(oc.y[j]))
                            break;
                        row.push_back(oc.y[j]);
                    }
                    if (row.size() < e.observables.size())
                        continue; // this slip's run failed or did not settle
                    f << x;
                    for (double v : row)
                        f << ',' << v * level * (1.0 + key.noise * z(rng));
                    f << '\n';
                }
            } else {
                // Only as far as the design reaches: the diagnosis then simulates the same tests.
                // Every observable of a curve test is sampled with its first (one run's
                // samples: a shear box's stress and its plate's rise).
                const double reach = e.trials.front().curves.at(obs).x.back();
                for (const std::string &o : e.observables)
                    if (it->second.count(o) == 0 || it->second.at(o).x != c.x)
                        throw std::runtime_error("twin: experiment '" + e.id + "', repeat " +
                                                 std::to_string(r + 1) + ": its '" + o +
                                                 "' was not sampled with its '" + obs + "'");
                for (std::size_t i = 0; i < c.x.size(); ++i)
                    if (c.x[i] <= reach) {
                        f << c.x[i];
                        for (const std::string &o : e.observables)
                            f << ',' << it->second.at(o).y[i] * level * (1.0 + key.noise * z(rng));
                        f << '\n';
                    }
            }
            files.push_back(file);
        }
        if (!e.x_name.empty() && files.size() == 0)
            throw std::runtime_error("twin: no repeat of experiment '" + e.id + "' was simulated");
        YAML::Node data;
        if (e.x_name.empty()) {
            if (scalar_values.empty())
                throw std::runtime_error("twin: no repeat of experiment '" + e.id +
                                         "' gave a value "
                                         "(an angle of repose without a heap)");
            data["values"] = scalar_values;
            data["unit"] = "deg";
        } else {
            data["files"] = files;
            if (e.scatter)
                data["scatter"] = true;
            YAML::Node x, y;
            x["column"] = e.x_name;
            const std::string x_unit = unitOf(e.x_name); // a slip's and a stroke's: none
            x["unit"] = x_unit.empty() ? "-" : x_unit;
            data["x"] = x;
            for (const std::string &o : e.observables) {
                YAML::Node yc;
                yc["column"] = o;
                yc["unit"] = unitOf(o);
                y[o] = yc;
            }
            data["y"] = y;
        }
        n["data"] = data;
        YAML::Node u;
        u["y_relative"] = key.level_noise;
        u["repeats"] = "rebuilt_bed";
        if (key.own_beds)
            u["beds"] = "own";
        n["uncertainty"] = u;
        list.push_back(n);
    }
    root["experiments"] = list;
    {
        YAML::Emitter em;
        em << root;
        std::ofstream f(fs::path(out) / "experiments.yaml");
        f << "# A twin made by `grainlink gap twin` (docs/gap.md): simulated data, its cause kept\n"
             "# in a separate key file.\n"
          << em.c_str() << '\n';
    }
    nlohmann::ordered_json j{{"effect", key.effect.empty() ? nullptr : nlohmann::json(key.effect)},
                             {"strength", key.strength},
                             {"in_catalogue", key.in_catalogue},
                             {"seed", key.seed},
                             {"noise", key.noise},
                             {"level_noise", key.level_noise},
                             {"own_beds", key.own_beds},
                             {"twin", out}};
    fs::create_directories(fs::absolute(key_path).parent_path());
    std::ofstream(key_path) << j.dump(2) << '\n';
    loadExperiments(out); // reads back strictly
}

} // namespace grainlink::gap
