#include "grainlink/gap/Twin.hpp"

#include "grainlink/config/ConfigNode.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

namespace grainlink::gap {

namespace fs = std::filesystem;
using config::ConfigNode;

namespace {

std::string xName(ExperimentType type) {
    switch (type) {
    case ExperimentType::PlateSinkage:
        return "sinkage_m";
    case ExperimentType::BevameterShear:
    case ExperimentType::DirectShear:
        return "shear_displacement_m";
    case ExperimentType::AngleOfRepose:
        return "";
    case ExperimentType::WheelSteadyState:
        return "slip";
    case ExperimentType::Mole:
        return "stroke";
    }
    return "";
}

std::string observableOf(ExperimentType type) {
    switch (type) {
    case ExperimentType::PlateSinkage:
        return "pressure_Pa";
    case ExperimentType::BevameterShear:
    case ExperimentType::DirectShear:
        return "shear_stress_Pa";
    case ExperimentType::AngleOfRepose:
        return "angle_deg";
    default:
        break;
    }
    throw std::invalid_argument(std::string("a design cannot hold ") + typeName(type) +
                                " experiments yet");
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
            e.observables = {observableOf(e.type)};
        } catch (const std::invalid_argument &ex) {
            n["type"].fail(ex.what());
        }
        e.x_name = xName(e.type);
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
        Trial stand_in;
        if (e.x_name.empty()) {
            stand_in.curves[e.observables[0]] = Curve{{0.0}, {0.0}};
        } else {
            const double reach = n["reach"].positive();
            stand_in.curves[e.observables[0]] = Curve{{0.0, reach}, {0.0, 0.0}};
        }
        e.trials.push_back(stand_in);
        d.repeats[e.id] = int(n.integer("repeats", 1, 32, 2));
        n.finish();
        d.set.experiments.push_back(std::move(e));
    }
    root.finish();
    return d;
}

double drawStrength(const Effect &effect, unsigned seed) {
    std::mt19937 rng(seed * 2654435761u + 17u);
    std::uniform_real_distribution<double> u(effect.prior.toScale(effect.prior.lo),
                                             effect.prior.toScale(effect.prior.hi));
    return effect.prior.fromScale(u(rng));
}

TwinKey makeTwin(const Design &design, const EffectCatalogue &catalogue, StudySimulator &simulator,
                 const TwinOptions &options, const std::string &out, const std::string &key_path) {
    TwinKey key;
    key.seed = options.seed;
    key.noise = options.noise;
    key.level_noise = options.level_noise;
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
    int most = 1;
    for (const auto &[id, r] : design.repeats)
        most = std::max(most, r);
    VariantRequest truth;
    truth.label = "twin " + (key.effect.empty() ? std::string("null") : key.effect) + " seed " +
                  std::to_string(options.seed);
    truth.effect = effect;
    truth.strength = key.strength;
    truth.seeds = most;
    // The twin's beds are other realisations than the ones the diagnosis simulates.
    truth.seed_offset = 1000 + 37 * int(options.seed % 1000);
    std::vector<int> seeds;
    const auto curves = simulator.curves(design.set, {truth}, seeds);

    fs::create_directories(fs::path(out) / "data");
    std::mt19937 rng(options.seed * 7919u + 3u);
    std::normal_distribution<double> z;
    YAML::Node root;
    root["name"] = fs::path(out).filename().string();
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
            const double level = 1.0 + options.level_noise * z(rng);
            if (e.x_name.empty()) {
                // A repose test whose grains spread gives no angle: that repeat has no value.
                if (std::isfinite(c.y[0]))
                    scalar_values.push_back(c.y[0] * level * (1.0 + options.noise * z(rng)));
                continue;
            }
            // Only as far as the design reaches: the diagnosis then simulates the same tests.
            const double reach = e.trials.front().curves.at(obs).x.back();
            const std::string file = "data/" + e.id + "_" + std::to_string(r + 1) + ".csv";
            std::ofstream f(fs::path(out) / file);
            f.precision(10);
            f << "# twin of " << e.id << ", repeat " << r + 1 << "\n" << e.x_name << ',' << obs << '\n';
            for (std::size_t i = 0; i < c.x.size(); ++i)
                if (c.x[i] <= reach)
                    f << c.x[i] << ',' << c.y[i] * level * (1.0 + options.noise * z(rng)) << '\n';
            files.push_back(file);
        }
        if (!e.x_name.empty() && files.size() == 0)
            throw std::runtime_error("twin: no repeat of experiment '" + e.id + "' was simulated");
        YAML::Node data;
        if (e.x_name.empty()) {
            if (scalar_values.empty())
                throw std::runtime_error("twin: no repeat of experiment '" + e.id + "' gave a value "
                                         "(an angle of repose without a heap)");
            data["values"] = scalar_values;
            data["unit"] = "deg";
        } else {
            data["files"] = files;
            YAML::Node x, y, yc;
            x["column"] = e.x_name;
            x["unit"] = e.x_name == "slip" ? "-" : "m";
            data["x"] = x;
            yc["column"] = obs;
            yc["unit"] = dimensionOf(obs) == "pressure" ? "Pa" : "deg";
            y[obs] = yc;
            data["y"] = y;
        }
        n["data"] = data;
        YAML::Node u;
        u["y_relative"] = options.level_noise;
        u["repeats"] = "rebuilt_bed";
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
                             {"twin", out}};
    fs::create_directories(fs::absolute(key_path).parent_path());
    std::ofstream(key_path) << j.dump(2) << '\n';
    loadExperiments(out); // reads back strictly
    return key;
}

} // namespace grainlink::gap
