#include "grainlink/study/Design.hpp"

#include "grainlink/study/ScenarioEdit.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>

namespace grainlink::study {

namespace fs = std::filesystem;
using config::ConfigNode;

namespace {

// Bounds against typos: a study of more points than this is a mistake on any cluster we know.
constexpr long long kMaxPoints = 100'000;
constexpr long long kMaxReplicates = 10'000;

/// One varied key: its values, each with the line of the study file it came from.
struct Factor {
    std::string key;
    std::vector<YAML::Node> values;
    std::vector<int> lines;
};

YAML::Node numberNode(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.12g", v); // 28 + 3 * 0.1 reads 28.3, not 28.300000001
    return YAML::Node(std::string(text));
}

/// `range: {from, to, step}` (to included) or `range: {from, to, count}` (evenly spaced).
std::vector<YAML::Node> rangeValues(const ConfigNode &range) {
    const double from = range["from"].number(), to = range["to"].number();
    std::vector<YAML::Node> values;
    if (range.has("count")) {
        const long long n = range["count"].integer(2, kMaxPoints); // from and to at least
        for (long long k = 0; k < n; ++k)
            values.push_back(numberNode(from + (to - from) * double(k) / double(n - 1)));
    } else {
        const double step = range["step"].number();
        if (!(step > 0.0) || to < from)
            range["step"].fail("needs step > 0 and to >= from");
        const long long n = std::llround(std::floor((to - from) / step + 1e-9)) + 1;
        for (long long k = 0; k < n; ++k)
            values.push_back(numberNode(from + step * double(k)));
    }
    range.finish();
    return values;
}

/// A dotted path of keys and list indices ("contact.tangential.stick_angle_deg",
/// "bodies.0.motion.0.velocity_m_s"): no empty step anywhere.
std::string dottedPath(const ConfigNode &node) {
    const std::string path = node.text();
    try {
        pathSteps(path);
    } catch (const std::invalid_argument &) {
        node.fail("'" + path +
                  "' is not a dotted path of keys (e.g. contact.tangential.stick_angle_deg)");
    }
    return path;
}

Factor parseFactor(const ConfigNode &node) {
    Factor f;
    f.key = dottedPath(node["key"]);
    if (const auto list = node.optional("values")) {
        for (const ConfigNode &v : list->items()) {
            f.values.push_back(v.yaml());
            f.lines.push_back(v.line());
        }
        if (node.has("range"))
            node["range"].fail("give values or range, not both");
    } else if (const auto range = node.optional("range")) {
        f.values = rangeValues(*range);
        f.lines.assign(f.values.size(), range->line());
    } else {
        node.fail("needs values: [...] or range: {from, to, step or count}");
    }
    if (f.values.empty())
        node["values"].fail("is empty");
    node.finish();
    return f;
}

/// The index combinations of the design: every combination (factorial) or the i-th of each.
std::vector<std::vector<std::size_t>> combinations(const std::vector<Factor> &factors, bool zip,
                                                   const ConfigNode &vary) {
    std::vector<std::vector<std::size_t>> out;
    if (factors.empty())
        return {{}};
    if (zip) {
        for (const Factor &f : factors)
            if (f.values.size() != factors[0].values.size())
                vary.fail("zip needs lists of one length: '" + factors[0].key + "' has " +
                          std::to_string(factors[0].values.size()) + " values, '" + f.key +
                          "' has " + std::to_string(f.values.size()));
        for (std::size_t i = 0; i < factors[0].values.size(); ++i)
            out.emplace_back(factors.size(), i);
        return out;
    }
    std::vector<std::size_t> index(factors.size(), 0);
    while (true) { // odometer: the last key turns fastest
        out.push_back(index);
        std::size_t k = factors.size();
        while (k > 0 && ++index[k - 1] == factors[k - 1].values.size())
            index[--k] = 0;
        if (k == 0)
            return out;
    }
}

/// Label names of the keys: the shortest tail of each dotted path that no other key shares
/// ("stick_angle_deg", "force_N.2"; "motion.0.duration_s" beside "run.duration_s").
std::vector<std::string> shortNames(const std::vector<std::string> &keys) {
    auto tail = [](const std::string &key, int steps) {
        std::size_t cut = key.size();
        for (int k = 0; k < steps && cut != std::string::npos && cut > 0; ++k)
            cut = key.rfind('.', cut - 1);
        return cut == std::string::npos ? key : key.substr(cut + 1);
    };
    std::vector<std::string> names;
    for (const std::string &key : keys) {
        for (int steps = 1;; ++steps) {
            const std::string name = tail(key, steps);
            // a name starts with a key, not a list index: "force_N.2", "motion.0.duration_s"
            bool unique = !std::isdigit(static_cast<unsigned char>(name[0]));
            for (const std::string &other : keys)
                unique = unique && (other == key || tail(other, steps) != name);
            if (unique || name == key) {
                names.push_back(name);
                break;
            }
        }
    }
    return names;
}

} // namespace

Study loadStudy(const std::string &path, const std::string &directory,
                const DesignOptions &options) {
    const ConfigNode root = ConfigNode::loadFile(path);
    Study study;
    study.source = path;
    study.directory = directory;
    study.name = root["name"].text();

    const ConfigNode base = root["base"];
    Kind kind;
    try {
        kind = standardKind(base["kind"].text(), base.text("test", ""));
    } catch (const std::invalid_argument &e) {
        base["kind"].fail(e.what());
    }
    const ConfigNode scenario_key = base["scenario"];
    fs::path scenario = scenario_key.text();
    if (scenario.is_relative())
        scenario = fs::path(path).parent_path() / scenario;
    base.finish();
    YAML::Node scenario_tree;
    // A folder opens as a stream and fails only when read, with the stream's own words (an
    // empty or tagged `scenario:` names the study's folder: the fuzzer's).
    if (fs::is_directory(scenario))
        scenario_key.fail("cannot read scenario '" + scenario.string() + "': it is a folder");
    try {
        scenario_tree = YAML::LoadFile(scenario.string());
    } catch (const std::exception &e) {
        scenario_key.fail("cannot read scenario '" + scenario.string() + "': " + e.what());
    }
    absolutizeFilePaths(scenario_tree, scenario.parent_path().string());
    if (kind.summary_file_of)
        kind.summary_file = kind.summary_file_of(scenario_tree);
    if (options.threads)
        setAtPath(scenario_tree, kind.threads_key, YAML::Node(*options.threads));

    std::vector<Factor> factors;
    bool zip = false;
    int replicates = 1;
    long long first_seed = 1;
    // Replicate r gives its i-th seed key first + r K + i (K keys): beds of their own per key
    // (a rover's two soil strips) that never repeat another replicate's.
    std::vector<std::string> seed_keys{kind.seed_key};
    std::optional<ConfigNode> replicate_node;
    const auto design = root.optional("design");
    std::optional<ConfigNode> vary;
    if (design) {
        zip = design->text("combine", "factorial") == "zip";
        if (const auto c = design->optional("combine"))
            c->choice({"factorial", "zip"});
        vary = design->optional("vary");
        if (vary)
            for (const ConfigNode &item : vary->items())
                factors.push_back(parseFactor(item));
        if ((replicate_node = design->optional("replicates"))) {
            const ConfigNode &r = *replicate_node;
            if (r.isScalar()) {
                replicates = int(r.integer(1, kMaxReplicates));
            } else {
                replicates = int(r["count"].integer(1, kMaxReplicates));
                if (r.has("key") && r.has("keys"))
                    r["keys"].fail("give key or keys, not both");
                if (r.has("key"))
                    seed_keys = {dottedPath(r["key"])};
                if (r.has("keys")) {
                    seed_keys.clear();
                    for (const ConfigNode &k : r["keys"].items()) {
                        seed_keys.push_back(dottedPath(k));
                        if (std::count(seed_keys.begin(), seed_keys.end(), seed_keys.back()) > 1)
                            k.fail("'" + seed_keys.back() + "' is given twice");
                    }
                    if (seed_keys.empty())
                        r["keys"].fail("name at least one key");
                }
                first_seed = r.has("first") ? r["first"].integer() : 1;
                r.finish();
            }
            if (replicates < 1)
                r.fail("needs at least 1 replicate");
        }
        design->finish();
    }
    for (const Factor &f : factors) {
        study.varied_keys.push_back(f.key);
        if (replicate_node && std::count(seed_keys.begin(), seed_keys.end(), f.key))
            replicate_node->fail("'" + f.key + "' is both varied and the replicates' key");
    }
    if (replicate_node)
        study.replicate_key = seed_keys.front();
    for (const ConfigNode &o : root["observables"].items())
        study.observables.push_back(o.text());
    if (study.observables.empty())
        root["observables"].fail("name at least one field of the runs' " + kind.summary_file);
    root.finish();

    std::vector<std::string> label_keys = study.varied_keys;
    label_keys.insert(label_keys.end(), seed_keys.begin(), seed_keys.end());
    const std::vector<std::string> names = shortNames(label_keys);
    std::set<std::string> ids;
    for (const auto &combination : combinations(factors, zip, vary ? *vary : root)) {
        for (int r = 0; r < replicates; ++r) {
            YAML::Node tree = YAML::Clone(scenario_tree);
            std::vector<std::pair<std::string, std::string>> settings;
            std::string label, origin;
            for (std::size_t k = 0; k < factors.size(); ++k) {
                const Factor &f = factors[k];
                const YAML::Node &value = f.values[combination[k]];
                try {
                    setAtPath(tree, f.key, value);
                } catch (const std::invalid_argument &e) {
                    (*vary).items()[k]["key"].fail(e.what());
                }
                settings.emplace_back(f.key, inlineText(value));
                label += (label.empty() ? "" : " ") + names[k] + "=" + inlineText(value);
                origin += (origin.empty() ? "" : ", ") + path + ":" +
                          std::to_string(f.lines[combination[k]]) + ": " + f.key + " = " +
                          inlineText(value);
            }
            for (std::size_t i = 0; replicate_node && i < seed_keys.size(); ++i) {
                const std::string &key = seed_keys[i];
                const std::string seed = std::to_string(
                    first_seed + (long long)(r) * (long long)(seed_keys.size()) + (long long)(i));
                try {
                    setAtPath(tree, key, YAML::Node(seed));
                } catch (const std::invalid_argument &e) {
                    replicate_node->fail(e.what());
                }
                settings.emplace_back(key, seed);
                label += (label.empty() ? "" : " ") + names[factors.size() + i] + "=" + seed;
                origin += (origin.empty() ? "" : ", ") + path + ":" +
                          std::to_string(replicate_node->line()) + ": " + key + " = " + seed;
            }
            Point p = makePoint(kind, emitYaml(tree), label.empty() ? "base" : label);
            p.origin = origin.empty() ? path + ": the base scenario" : origin;
            p.settings = std::move(settings);
            if (!ids.insert(p.id).second)
                root.fail("two points of the design are the same scenario (" + p.label +
                          "): a value is repeated");
            study.points.push_back(std::move(p));
        }
    }
    return study;
}

} // namespace grainlink::study
