#pragma once
// The blind self-test (docs/gap.md, "Proof on data whose effect is withheld"): twins of every
// catalogue effect at a strength drawn from its prior, null twins and twins of an effect
// outside the catalogue, each diagnosed without its key, then scored against it.
#include "grainlink/gap/Diagnosis.hpp"
#include "grainlink/gap/Twin.hpp"
#include "grainlink/study/Study.hpp"

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace grainlink::gap {

struct SelftestOptions {
    std::string scale = "ci";
    std::string out, sims;                ///< sims: the shared simulation cache (default out/sims)
    std::string base_model, design, plan; ///< plan: selftest.yaml (default beside the design)
    std::string plot_tool;                ///< tools/gap_report.py, for each twin's report.html
    unsigned seed = 1;
    EffectCatalogue catalogue;
    study::ExecutorOptions executor;
};

struct SelftestTwin {
    std::string name; ///< folder name under out/twins
    TwinKey key;
    bool weak = false; ///< the hidden effect stays within the validation uncertainty
    Diagnosis::Outcome outcome = Diagnosis::Outcome::NoGap;
    std::string claimed; ///< the claimed effect ("" none; "a + b" a pair)
    double claimed_strength = 0.0;
    bool correct = false;
    bool strength_within_25 = false;
    double reduction_pct = 0.0; ///< held-out gap reduction of the claimed model (0 if none)
    std::string claim;
    /// Unclaimed: the candidate the report names as closest or nearest to a claim, when it is
    /// the hidden effect, and its fitted strength (a ranking right, its evidence short).
    bool named = false;
    double named_strength = 0.0;
};

struct SelftestResult {
    std::vector<SelftestTwin> twins;
    std::vector<std::string> failed_twins; ///< twins whose simulations failed, with why
    /// Drawn strengths whose twin could not be simulated on the design, with why: each drawn
    /// again from the prior cut at it (a soft surface layer's grains past the overlap limit).
    std::vector<std::string> redrawn;
    std::string line;    ///< "selftest: top-1 A/B (P %), strength within 25 %: C/D, ..."
    std::string report;  ///< the line, the confusion matrix and every twin
    bool passed = false; ///< every target of docs/gap.md met
    int top1 = 0, top1_of = 0, strength_ok = 0, strength_of = 0, null_false = 0, nulls = 0,
        ooc_unexplained = 0, oocs = 0, weak = 0;
    /// Strong catalogue twins without a correct claim whose hidden effect the report named
    /// (closest or nearest to a claim), and of those, named within 25 % of its strength.
    int named = 0, named_of = 0, named_strength_ok = 0;
    double median_reduction_pct = 0.0;
};

SelftestResult runSelftest(const SelftestOptions &options);

/// How often a self-test draws an effect's strength before it leaves the twin out.
constexpr int kStrengthDraws = 6;

/// A twin made at the strength `draw(k, failed)` gives for the k-th try (`failed`: the
/// strengths tried before it), by `make`, tried again where `make` throws (its simulations
/// failed), `tries` times in all. Each failure is added to `failures` as " at STRENGTH: why"
/// (": why" without a strength). Nothing where every try failed.
std::optional<TwinKey>
drawUntilMade(const std::function<std::optional<double>(int, const std::vector<double> &)> &draw,
              const std::function<TwinKey(std::optional<double>)> &make, int tries,
              std::vector<std::string> &failures);

/// Scores one twin's diagnosis against its key and adds it to R's counts (docs/gap.md, "The
/// self-test"): t.key, t.weak, t.outcome and t.claimed are set; `hidden` is the key's effect
/// (null for a null twin).
void scoreTwin(const Diagnosis &d, const Effect *hidden, SelftestTwin &t, SelftestResult &R);

} // namespace grainlink::gap
