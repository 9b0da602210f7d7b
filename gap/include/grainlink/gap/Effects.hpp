#pragma once
// The catalogue of candidate effects (docs/gap.md, "The effect catalogue"): each a real,
// switchable change of the simulation with one strength parameter, its unit and prior range.
// Most are edits of the scenario (YAML keys set, scaled or replaced, with values written as
// expressions of the strength `s` and the base value `base`, evaluated by muParser); a few
// are built in (the grain size spread, the domain size) and two belong to the measuring chain
// (a compliant rig, a sensor zero offset), applied to the simulated curves rather than
// simulated. A user's effects.yaml adds or replaces effects by name without recompiling.
#include "grainlink/gap/Attribution.hpp"
#include "grainlink/gap/Comparison.hpp"
#include "grainlink/gap/Experiments.hpp"

#include <yaml-cpp/yaml.h>

#include <optional>
#include <set>
#include <string>
#include <vector>

namespace grainlink::gap {

/// One scenario edit. `key` is a dotted path into the test scenario (`soil.material.density_kg_m3`,
/// list elements by index or `*` for all); `value` an expression of s and base (the key's
/// present value, or `fallback` when absent).
struct EffectEdit {
    enum class Op {
        Set,    ///< key = value (a number)
        Scale,  ///< every number under key *= value
        Text,   ///< key = the text `text` (a model name)
        Node,   ///< key = the YAML `node`, whose string leaves starting with '=' are expressions
        Remove, ///< drop the key
        Keep,   ///< where key is absent, key = the value at `source` (what it inherits now)
    };
    std::string key;
    Op op = Op::Set;
    std::string value;                 ///< expression (Set, Scale)
    std::string text;                  ///< Text
    YAML::Node node;                   ///< Node
    std::string source;                ///< Keep: the key whose value `key` inherits
    std::optional<std::string> when;   ///< expression; the edit applies where it is non-zero
    std::optional<std::string> only_if; ///< `if: key=value|value`: the scenario must hold it
    std::optional<double> fallback;    ///< `base` where the key is absent (else absent = error)
    std::vector<std::string> types;    ///< experiment types it applies to (empty: all)
    std::string where;                 ///< "file:line" of the edit, for errors found on a base
};

struct Effect {
    std::string name;
    std::string description;
    std::string acts_on;   ///< grain-grain, grain-wall, grain-tool, bed, domain, measurement
    std::string parameter; ///< the strength's name, e.g. "coefficient"
    std::string unit;      ///< of the strength
    Prior prior;           ///< prior.off: the base model's value (resolved against the base)
    /// Where the base model holds the strength (absolute effects): keys tried in order, each
    /// optionally "key: expression of base" (e.g. a stick angle's tangent as a friction).
    std::vector<std::string> off_keys;
    std::optional<double> off_fallback; ///< off where no off_key is present in the base
    std::vector<double> signature; ///< strengths simulated for the signature (>= 2 with off)
    enum class Kind { Edits, Builtin, Measurement };
    Kind kind = Kind::Edits;
    std::string builtin;   ///< Builtin / Measurement: polydispersity, domain_size, rig_compliance,
                           ///< sensor_zero_offset, crust
    std::vector<EffectEdit> edits;
    std::vector<std::string> requires_text; ///< "key=value|value" the base must satisfy
    bool in_catalogue = true; ///< false: only for twins (an out-of-catalogue effect)
    std::string source;       ///< file:line
};

struct EffectCatalogue {
    std::vector<Effect> effects;
    const Effect &find(const std::string &name) const; ///< throws naming the known effects
    std::vector<const Effect *> diagnosable() const;   ///< in_catalogue ones
};

/// Reads an effects file; entries of `over` replace same-named entries of `base`.
EffectCatalogue loadEffects(const std::string &path);
EffectCatalogue mergeEffects(EffectCatalogue base, const EffectCatalogue &over);

/// A dotted path into a YAML tree.
std::vector<YAML::Node> findNodes(YAML::Node root, const std::string &path, bool create);
/// The number at `path`, if present and numeric.
std::optional<double> numberAt(const YAML::Node &root, const std::string &path);

/// Why an effect cannot act on a base (empty: it can): a requirement it does not meet.
std::string inapplicable(const Effect &effect, const YAML::Node &scenario);

/// The effect's off value and prior resolved against a base scenario: off = the base's value at
/// off_key (or the fallback), and the prior widened to hold it.
Effect resolveAgainst(const Effect &effect, const YAML::Node &scenario);

/// The test scenario (a deep copy) with the effect at strength `s`, for a test of `type`.
/// A measurement effect leaves the scenario as it is (it acts on the curves).
YAML::Node applyEffect(const Effect &effect, double s, const YAML::Node &scenario,
                       ExperimentType type);

/// A measurement effect on one simulated curve of an experiment (x shifted by the zero offset,
/// or by compliance times the force); other effects return the curve unchanged.
Curve applyMeasurementEffect(const Effect &effect, double s, const Experiment &experiment,
                             const std::string &observable, const Curve &curve);

/// Evaluates a muParser expression of s and base; throws naming the expression.
double evaluate(const std::string &expression, double s, double base);

} // namespace grainlink::gap
