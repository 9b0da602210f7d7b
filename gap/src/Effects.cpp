#include "grainlink/gap/Effects.hpp"

#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/lab/Wheel.hpp"

#include <muParser.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace grainlink::gap {

using config::ConfigNode;

namespace {

std::vector<std::string> splitPath(const std::string &path) {
    std::vector<std::string> parts;
    std::string part;
    std::istringstream in(path);
    while (std::getline(in, part, '.'))
        parts.push_back(part);
    return parts;
}

void collect(YAML::Node node, const std::vector<std::string> &parts, std::size_t i, bool create,
             std::vector<YAML::Node> &out) {
    if (i == parts.size()) {
        out.push_back(node);
        return;
    }
    const std::string &p = parts[i];
    if (p == "*") {
        if (node.IsSequence())
            for (std::size_t k = 0; k < node.size(); ++k)
                collect(node[k], parts, i + 1, create, out);
        return;
    }
    if (const auto k = config::listIndex(p)) {
        if (node.IsSequence() && *k < node.size())
            collect(node[*k], parts, i + 1, create, out);
        return;
    }
    if (node.IsMap() && node[p]) {
        collect(node[p], parts, i + 1, create, out);
        return;
    }
    // Missing steps are created, except a list a wildcard would walk: `*` names only the items
    // there are (a test without walls gets no walls).
    const bool before_wildcard = i + 1 < parts.size() && parts[i + 1] == "*";
    if (create && !before_wildcard && (node.IsMap() || node.IsNull())) {
        node[p] = YAML::Node(YAML::NodeType::Map);
        collect(node[p], parts, i + 1, create, out);
    }
}

/// Numbers under a node, recursively (a list of corners, a map of settings).
void scaleNumbers(YAML::Node node, double factor) {
    if (node.IsScalar()) {
        try {
            node = node.as<double>() * factor;
        } catch (const YAML::Exception &) {
        }
        return;
    }
    if (node.IsSequence())
        for (std::size_t k = 0; k < node.size(); ++k)
            scaleNumbers(node[k], factor);
    if (node.IsMap())
        for (auto it = node.begin(); it != node.end(); ++it)
            scaleNumbers(it->second, factor);
}

/// A copy of `templ` whose string leaves "=expr" are evaluated.
YAML::Node instantiate(const YAML::Node &templ, double s, double base) {
    if (templ.IsScalar()) {
        const std::string v = templ.Scalar();
        if (!v.empty() && v[0] == '=')
            return YAML::Node(evaluate(v.substr(1), s, base));
        return YAML::Node(v);
    }
    YAML::Node out(templ.Type());
    if (templ.IsSequence())
        for (const auto &item : templ)
            out.push_back(instantiate(item, s, base));
    if (templ.IsMap())
        for (auto it = templ.begin(); it != templ.end(); ++it)
            out[it->first.Scalar()] = instantiate(it->second, s, base);
    return out;
}

void removeKey(YAML::Node root, const std::string &path) {
    const auto parts = splitPath(path);
    if (parts.empty())
        return;
    std::string parent;
    for (std::size_t i = 0; i + 1 < parts.size(); ++i)
        parent += (i ? "." : "") + parts[i];
    for (YAML::Node n : parent.empty() ? std::vector<YAML::Node>{root} : findNodes(root, parent, false))
        if (n.IsMap())
            n.remove(parts.back());
}

std::string textAt(const YAML::Node &root, const std::string &path) {
    const auto nodes = findNodes(YAML::Clone(root), path, false);
    if (nodes.empty() || !nodes[0].IsScalar())
        return "none";
    return nodes[0].Scalar();
}

// --- built-in effects -------------------------------------------------------------------------

/// The grains' radius spread as a width w = (r_max - r_min) / (r_max + r_min) about the same
/// mean radius, with the grain count kept to the same solid volume (a uniform distribution on
/// r (1 +- w) has E[r^3] = r^3 (1 + w^2)) and the time step kept stable for the smallest grain.
double radiusWidth(const YAML::Node &scenario) {
    const YAML::Node r = scenario["soil"]["deposition"]["radius"];
    if (!r)
        return 0.0;
    const std::string d = r["distribution"].as<std::string>("constant");
    if (d == "uniform") {
        const double lo = r["min_m"].as<double>(), hi = r["max_m"].as<double>();
        return (hi - lo) / (hi + lo);
    }
    return 0.0;
}

void applyPolydispersity(YAML::Node scenario, double w) {
    YAML::Node dep = scenario["soil"]["deposition"];
    YAML::Node r = dep["radius"];
    const std::string d = r["distribution"].as<std::string>("constant");
    double mean = 0.0;
    if (d == "uniform")
        mean = 0.5 * (r["min_m"].as<double>() + r["max_m"].as<double>());
    else if (d == "constant")
        mean = r["value_m"].as<double>();
    else
        throw std::invalid_argument("polydispersity: the base's radius distribution '" + d +
                                    "' is neither constant nor uniform");
    const double w0 = radiusWidth(scenario);
    YAML::Node fresh(YAML::NodeType::Map);
    if (w > 0.0) {
        fresh["distribution"] = "uniform";
        fresh["min_m"] = mean * (1.0 - w);
        fresh["max_m"] = mean * (1.0 + w);
    } else {
        fresh["distribution"] = "constant";
        fresh["value_m"] = mean;
    }
    dep["radius"] = fresh;
    dep["count"] = std::llround(dep["count"].as<double>() * (1.0 + w0 * w0) / (1.0 + w * w));
    YAML::Node dt = scenario["soil"]["simulation"]["time_step_s"];
    dt = dt.as<double>() * std::min(1.0, (1.0 - w) / (1.0 - w0));
}

/// The container's horizontal size times f about the deposition region's centre, with the
/// grain count times f^2 (the same bed depth).
/// The container f_x times as long and f_y times as wide about the region's centre, the same
/// depth of grains.
void applyDomainSize(YAML::Node scenario, double f_x, double f_y) {
    YAML::Node soil = scenario["soil"];
    YAML::Node region = soil["deposition"]["region"];
    const auto lo = region["lower_m"].as<std::vector<double>>();
    const auto hi = region["upper_m"].as<std::vector<double>>();
    const double cx = 0.5 * (lo[0] + hi[0]), cy = 0.5 * (lo[1] + hi[1]);
    const auto scalePoint = [&](YAML::Node p) {
        if (!p || !p.IsSequence() || p.size() != 3)
            return;
        p[0] = cx + f_x * (p[0].as<double>() - cx);
        p[1] = cy + f_y * (p[1].as<double>() - cy);
    };
    scalePoint(region["lower_m"]);
    scalePoint(region["upper_m"]);
    if (soil["walls"])
        for (std::size_t k = 0; k < soil["walls"].size(); ++k) {
            YAML::Node w = soil["walls"][k];
            scalePoint(w["lower_m"]);
            scalePoint(w["upper_m"]);
            scalePoint(w["point_m"]);
        }
    soil["deposition"]["count"] =
        std::llround(soil["deposition"]["count"].as<double>() * f_x * f_y);
}

/// The factor a wheel bin's width (y) is scaled by for a domain width factor s: the clearance
/// between the wheel's footprint and the walls scales by s, the footprint stays (a steered
/// wheel's reaches further across), so that a narrower bin still holds the wheel.
double wheelBinFactor(const YAML::Node &scenario, double s) {
    const YAML::Node region = scenario["soil"]["deposition"]["region"];
    const double width = region["upper_m"][1].as<double>() - region["lower_m"][1].as<double>();
    const YAML::Node wheel = scenario["wheel"], shape = wheel["shape"];
    const double reach = 0.5 * shape["diameter_m"].as<double>() +
                         (shape["grouser_height_m"] ? shape["grouser_height_m"].as<double>() : 0.0);
    const double beta = wheel["slip_angle_deg"] ? wheel["slip_angle_deg"].as<double>() : 0.0;
    const double footprint =
        2.0 * lab::steeredHalfExtent(reach, shape["width_m"].as<double>(), beta).y();
    return (footprint + s * (width - footprint)) / width;
}

} // namespace

double evaluate(const std::string &expression, double s, double base) {
    try {
        mu::Parser p;
        p.DefineVar("s", &s);
        p.DefineVar("base", &base);
        p.SetExpr(expression);
        return p.Eval();
    } catch (const mu::Parser::exception_type &e) {
        throw std::invalid_argument("expression '" + expression + "': " + e.GetMsg());
    }
}

std::vector<YAML::Node> findNodes(YAML::Node root, const std::string &path, bool create) {
    std::vector<YAML::Node> out;
    collect(root, splitPath(path), 0, create, out);
    return out;
}

std::optional<double> numberAt(const YAML::Node &root, const std::string &path) {
    const auto nodes = findNodes(YAML::Clone(root), path, false);
    if (nodes.empty() || !nodes[0].IsScalar())
        return std::nullopt;
    try {
        return nodes[0].as<double>();
    } catch (const YAML::Exception &) {
        return std::nullopt;
    }
}

const Effect &EffectCatalogue::find(const std::string &name) const {
    std::string known;
    for (const Effect &e : effects) {
        if (e.name == name)
            return e;
        known += (known.empty() ? "" : ", ") + e.name;
    }
    throw std::invalid_argument("unknown effect '" + name + "' (known: " + known + ")");
}

std::vector<const Effect *> EffectCatalogue::diagnosable() const {
    std::vector<const Effect *> out;
    for (const Effect &e : effects)
        if (e.in_catalogue)
            out.push_back(&e);
    return out;
}

EffectCatalogue mergeEffects(EffectCatalogue base, const EffectCatalogue &over) {
    for (const Effect &e : over.effects) {
        const auto it = std::find_if(base.effects.begin(), base.effects.end(),
                                     [&](const Effect &b) { return b.name == e.name; });
        if (it != base.effects.end())
            *it = e;
        else
            base.effects.push_back(e);
    }
    return base;
}

EffectCatalogue loadEffects(const std::string &path) {
    const ConfigNode root = ConfigNode::loadFile(path);
    EffectCatalogue cat;
    const YAML::Node raw = YAML::LoadFile(path); // the edits' node templates, as written
    std::size_t index = 0;
    for (const ConfigNode &n : root["effects"].items()) {
        const YAML::Node raw_effect = raw["effects"][index++];
        Effect e;
        e.source = path + ":" + std::to_string(n.line());
        e.name = n["name"].text();
        e.description = n["description"].text();
        e.acts_on = n["acts_on"].choice(
            {"grain-grain", "grain-wall", "grain-tool", "bed", "domain", "measurement"});
        e.in_catalogue = n.boolean("catalogue", true);
        const ConfigNode st = n["strength"];
        e.parameter = st["parameter"].text();
        e.unit = st["unit"].text();
        const std::vector<double> prior = st["prior"].numbers();
        if (prior.size() != 2 || !(prior[0] < prior[1]))
            st["prior"].fail("give [low, high] with low < high");
        e.prior.lo = prior[0];
        e.prior.hi = prior[1];
        if (st.has("scale"))
            e.prior.log_scale = st["scale"].choice({"linear", "log"}) == "log";
        if (st.has("off"))
            e.prior.off = st["off"].number();
        if (const auto keys = st.optional("off_key")) {
            if (keys->isSequence())
                for (const ConfigNode &k : keys->items())
                    e.off_keys.push_back(k.text());
            else
                e.off_keys.push_back(keys->text());
        }
        if (st.has("off_fallback"))
            e.off_fallback = st["off_fallback"].number();
        if (!st.has("off") && e.off_keys.empty())
            st.fail("give `off` (the value that switches the effect off) or `off_key` (where "
                    "the base model holds it)");
        e.signature = st["signature"].numbers();
        if (e.signature.size() < 2)
            st["signature"].fail("simulate at least two strengths (docs/gap.md)");
        for (double s : e.signature)
            if (s < e.prior.lo || s > e.prior.hi)
                st["signature"].fail("every signature strength lies in the prior range");
        if (e.prior.log_scale && e.prior.lo <= 0.0)
            st["prior"].fail("a logarithmic strength needs a positive range");
        st.finish();
        if (n.has("builtin")) {
            e.builtin = n["builtin"].choice({"polydispersity", "domain_size", "rig_compliance",
                                             "sensor_zero_offset"});
            e.kind = (e.builtin == "rig_compliance" || e.builtin == "sensor_zero_offset")
                         ? Effect::Kind::Measurement
                         : Effect::Kind::Builtin;
        }
        if (const auto req = n.optional("requires"))
            for (const ConfigNode &r : req->items()) {
                const std::string t = r.text();
                if (t.find('=') == std::string::npos)
                    r.fail("a requirement reads key=value|value");
                e.requires_text.push_back(t);
            }
        if (const auto edits = n.optional("edits")) {
            std::size_t k = 0;
            for (const ConfigNode &en : edits->items()) {
                const YAML::Node raw_edit = raw_effect["edits"][k++];
                EffectEdit ed;
                ed.key = en["key"].text();
                ed.where = en.file() + ":" + std::to_string(en.line());
                int ops = 0;
                if (en.has("set"))
                    ed.op = EffectEdit::Op::Set, ed.value = en["set"].text(), ++ops;
                if (en.has("scale"))
                    ed.op = EffectEdit::Op::Scale, ed.value = en["scale"].text(), ++ops;
                if (en.has("text"))
                    ed.op = EffectEdit::Op::Text, ed.text = en["text"].text(), ++ops;
                if (en.has("node")) {
                    ed.op = EffectEdit::Op::Node, ++ops;
                    ed.node = YAML::Clone(raw_edit["node"]);
                    (void)en["node"];
                }
                if (en.has("remove"))
                    ed.op = EffectEdit::Op::Remove, ++ops, (void)en["remove"].boolean();
                if (en.has("keep_inherited_from"))
                    ed.op = EffectEdit::Op::Keep, ed.source = en["keep_inherited_from"].text(),
                    ++ops;
                if (ops != 1)
                    en.fail(
                        "give exactly one of set, scale, text, node, remove, keep_inherited_from");
                if (en.has("when"))
                    ed.when = en["when"].text();
                if (en.has("if")) {
                    ed.only_if = en["if"].text();
                    if (ed.only_if->find('=') == std::string::npos)
                        en["if"].fail("a condition reads key=value|value");
                }
                if (en.has("fallback"))
                    ed.fallback = en["fallback"].number();
                if (const auto types = en.optional("types"))
                    for (const ConfigNode &t : types->items()) {
                        try {
                            parseType(t.text());
                        } catch (const std::invalid_argument &ex) {
                            t.fail(ex.what());
                        }
                        ed.types.push_back(t.text());
                    }
                // Check every expression once now, not in the middle of a diagnosis.
                for (const std::string &x : {ed.value, ed.when.value_or("")})
                    if (!x.empty())
                        try {
                            evaluate(x, e.signature.front(), 1.0);
                        } catch (const std::invalid_argument &ex) {
                            en.fail(ex.what());
                        }
                en.finish();
                e.edits.push_back(std::move(ed));
            }
        }
        if (e.kind == Effect::Kind::Edits && e.edits.empty())
            n.fail("an effect needs edits or a builtin");
        n.finish();
        cat.effects.push_back(std::move(e));
    }
    root.finish();
    return cat;
}

namespace {

/// Why `scenario` does not hold the condition "key=value|value" (empty: it does).
std::string unmet(const std::string &condition, const YAML::Node &scenario) {
    const auto eq = condition.find('=');
    const std::string key = condition.substr(0, eq);
    const std::string have = textAt(scenario, key);
    std::istringstream options(condition.substr(eq + 1));
    std::string o;
    while (std::getline(options, o, '|'))
        if (o == have)
            return "";
    return "needs " + key + " in {" + condition.substr(eq + 1) + "}, the base has '" + have + "'";
}

} // namespace

std::string inapplicable(const Effect &effect, const YAML::Node &scenario) {
    for (const std::string &r : effect.requires_text)
        if (const std::string why = unmet(r, scenario); !why.empty())
            return why;
    return "";
}

Effect resolveAgainst(const Effect &effect, const YAML::Node &scenario) {
    Effect e = effect;
    if (e.builtin == "polydispersity")
        e.prior.off = radiusWidth(scenario);
    else if (!e.off_keys.empty()) {
        std::optional<double> off;
        for (const std::string &entry : e.off_keys) {
            const auto colon = entry.find(':');
            const std::string key = entry.substr(0, colon);
            if (const auto v = numberAt(scenario, key)) {
                off = colon == std::string::npos ? *v : evaluate(entry.substr(colon + 1), 0.0, *v);
                break;
            }
        }
        if (!off && !e.off_fallback)
            throw std::invalid_argument("effect '" + e.name + "': the base has none of its "
                                        "off keys and the effect gives no off_fallback");
        e.prior.off = off ? *off : *e.off_fallback;
    }
    e.prior.lo = std::min(e.prior.lo, e.prior.off);
    e.prior.hi = std::max(e.prior.hi, e.prior.off);
    return e;
}

YAML::Node applyEffect(const Effect &effect, double s, const YAML::Node &scenario,
                       ExperimentType type) {
    YAML::Node out = YAML::Clone(scenario);
    if (effect.kind == Effect::Kind::Measurement)
        return out;
    if (effect.builtin == "polydispersity") {
        applyPolydispersity(out, s);
        return out;
    }
    if (effect.builtin == "domain_size") {
        // A direct shear box and a repose tube are the test's own geometry (their sizes are
        // measured conditions), not a container around the bed; a wheel's bin confines it
        // across its width (y) beyond its footprint, its length being the travel.
        if (type == ExperimentType::WheelSteadyState)
            applyDomainSize(out, 1.0, wheelBinFactor(out, s));
        else if (type != ExperimentType::DirectShear && type != ExperimentType::AngleOfRepose)
            applyDomainSize(out, s, s);
        return out;
    }
    const std::string type_name = typeName(type);
    for (const EffectEdit &ed : effect.edits) {
        if (!ed.types.empty() &&
            std::find(ed.types.begin(), ed.types.end(), type_name) == ed.types.end())
            continue;
        if (ed.only_if && !unmet(*ed.only_if, out).empty())
            continue;
        if (ed.op == EffectEdit::Op::Remove) {
            removeKey(out, ed.key);
            continue;
        }
        if (ed.op == EffectEdit::Op::Keep) {
            // A contact type that takes the grains' value keeps it when a later edit changes
            // the grains' (an effect on grain-grain contacts only); its own value stands.
            const std::vector<YAML::Node> from = findNodes(out, ed.source, false);
            // Without its source the key would inherit the changed value, silently.
            if (from.size() != 1)
                throw std::invalid_argument(
                    ed.where + ": effect '" + effect.name + "', keep_inherited_from '" + ed.source +
                    "': the scenario " +
                    (from.empty() ? "has no such key" : "has it more than once") + ", so '" +
                    ed.key + "' cannot keep what it inherits");
            if (findNodes(out, ed.key, false).empty())
                for (YAML::Node n : findNodes(out, ed.key, true))
                    n = YAML::Clone(from[0]); // a copy: the grains' value changes next
            continue;
        }
        std::vector<YAML::Node> nodes = findNodes(out, ed.key, false);
        const bool absent = nodes.empty();
        if (absent) {
            if (ed.op == EffectEdit::Op::Scale)
                continue; // nothing there to scale
            // Decided before the key is made: a skipped edit must not leave an empty key behind.
            if (ed.when && evaluate(*ed.when, s, ed.fallback.value_or(std::nan(""))) == 0.0)
                continue;
            nodes = findNodes(out, ed.key, true);
        }
        for (YAML::Node n : nodes) {
            double base = ed.fallback.value_or(std::nan(""));
            if (!absent && n.IsScalar())
                try {
                    base = n.as<double>();
                } catch (const YAML::Exception &) {
                }
            if (ed.when && evaluate(*ed.when, s, base) == 0.0)
                continue;
            switch (ed.op) {
            case EffectEdit::Op::Set:
                n = evaluate(ed.value, s, base);
                break;
            case EffectEdit::Op::Scale:
                scaleNumbers(n, evaluate(ed.value, s, base));
                break;
            case EffectEdit::Op::Text:
                n = ed.text;
                break;
            case EffectEdit::Op::Node:
                n = instantiate(ed.node, s, base);
                break;
            case EffectEdit::Op::Remove:
            case EffectEdit::Op::Keep:
                break;
            }
        }
    }
    return out;
}

Curve applyMeasurementEffect(const Effect &effect, double s, const Experiment &experiment,
                             const std::string &observable, const Curve &curve) {
    if (effect.kind != Effect::Kind::Measurement ||
        experiment.type != ExperimentType::PlateSinkage || observable != "pressure_Pa")
        return curve;
    Curve out = curve;
    if (effect.builtin == "sensor_zero_offset") {
        for (double &x : out.x)
            x += s;
    } else if (effect.builtin == "rig_compliance") {
        // The carriage moves the plate's sinkage plus the rig's deflection c F.
        const auto d = experiment.numbers.find("plate_diameter_m");
        if (d == experiment.numbers.end())
            return curve;
        const double area = M_PI * d->second * d->second / 4.0;
        for (std::size_t i = 0; i < out.x.size(); ++i)
            out.x[i] += s * out.y[i] * area;
    }
    return out;
}

} // namespace grainlink::gap
