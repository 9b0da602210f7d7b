#include "grainlink/gap/Selftest.hpp"

#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/gap/Report.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

namespace grainlink::gap {

namespace fs = std::filesystem;
using config::ConfigNode;

namespace {

/// The twins to make (selftest.yaml beside the design).
struct Plan {
    std::vector<std::string> effects;   ///< twins of these; empty: every applicable one
    std::vector<std::string> catalogue; ///< what the diagnosis considers; empty: all
    int nulls = 3;
    std::vector<std::pair<std::string, double>> out_of_catalogue; ///< effect, strength
    double noise = 0.01, level_noise = 0.02;
    StrengthDraw strengths = StrengthDraw::Prior; ///< `strengths: prior | far_half`
    bool own_beds = false;                        ///< `beds: shared | own`
    std::vector<std::string> hold_out; ///< the diagnosis' held-out ids; empty: its default split
};

Plan loadPlan(const std::string &path, const Design &design) {
    Plan p;
    if (!fs::exists(path))
        return p;
    const ConfigNode root = ConfigNode::loadFile(path);
    if (root.has("effects"))
        for (const ConfigNode &e : root["effects"].items())
            p.effects.push_back(e.text());
    if (root.has("catalogue"))
        for (const ConfigNode &e : root["catalogue"].items())
            p.catalogue.push_back(e.text());
    if (root.has("nulls"))
        p.nulls = int(root["nulls"].integer(0, 100));
    if (const auto o = root.optional("out_of_catalogue"))
        for (const ConfigNode &e : o->items()) {
            p.out_of_catalogue.emplace_back(e["effect"].text(), e["strength"].number());
            e.finish();
        }
    if (const auto d = root.optional("strengths")) {
        const std::string w = d->text();
        if (w == "far_half")
            p.strengths = StrengthDraw::FarHalf;
        else if (w != "prior")
            d->fail("must be prior (uniform over each prior) or far_half (over the half of each "
                    "side of off that lies farther from it)");
    }
    if (const auto h = root.optional("hold_out"))
        for (const ConfigNode &id : h->items()) {
            if (!design.repeats.count(id.text()))
                id.fail("names no experiment of the design");
            p.hold_out.push_back(id.text());
        }
    if (const auto b = root.optional("beds"))
        p.own_beds = b->choice({"shared", "own"}) == "own";
    p.noise = root.number("noise", p.noise);
    p.level_noise = root.number("level_noise", p.level_noise);
    root.finish();
    return p;
}

std::string outcomeWord(const Diagnosis &d) {
    switch (d.outcome) {
    case Diagnosis::Outcome::NoGap:
        return "no gap";
    case Diagnosis::Outcome::Unexplained:
        return "unexplained";
    case Diagnosis::Outcome::Unresolved:
        return "unresolved";
    case Diagnosis::Outcome::Explained:
    case Diagnosis::Outcome::ExplainedByPair:
        return d.explained_by; // the model the claim names, not the first that explains
    }
    return "?";
}

} // namespace

void scoreTwin(const Diagnosis &d, const Effect *hidden, SelftestTwin &t, SelftestResult &R) {
    const auto within25 = [&](double strength) {
        return std::abs(strength - t.key.strength) <= 0.25 * std::abs(t.key.strength);
    };
    const bool in_catalogue = hidden && hidden->in_catalogue;
    if (!hidden) {
        ++R.nulls;
        R.null_false += !t.claimed.empty();
        t.correct = d.outcome == Diagnosis::Outcome::NoGap;
    } else if (!in_catalogue) {
        ++R.oocs;
        t.correct = t.weak ? d.outcome == Diagnosis::Outcome::NoGap
                           : d.outcome == Diagnosis::Outcome::Unexplained;
        R.ooc_unexplained += t.correct;
    } else {
        ++R.top1_of;
        R.weak += t.weak;
        if (t.weak) {
            t.correct = d.outcome == Diagnosis::Outcome::NoGap;
        } else {
            t.correct = d.outcome == Diagnosis::Outcome::Explained && t.claimed == t.key.effect;
            const CandidateResult *winner = nullptr;
            for (const auto &c : d.candidates)
                if (c.explains && c.name == t.claimed)
                    winner = &c;
            if (winner && d.held_out_base.gap > 0.0)
                t.reduction_pct = 100.0 * (1.0 - winner->held_out.gap / d.held_out_base.gap);
            if (t.correct) {
                t.claimed_strength = winner->fit.strength;
                ++R.strength_of;
                t.strength_within_25 = within25(winner->fit.strength);
                R.strength_ok += t.strength_within_25;
            }
        }
        R.top1 += t.correct;
        if (!t.weak && !t.correct) {
            ++R.named_of;
            for (const CandidateResult &c : d.candidates)
                if (c.name == t.key.effect &&
                    (c.name == d.best_model || c.name == d.nearest_to_claim)) {
                    t.named = true;
                    t.named_strength = c.fit.strength;
                }
            R.named += t.named;
            R.named_strength_ok += t.named && within25(t.named_strength);
        }
    }
}

std::optional<TwinKey>
drawUntilMade(const std::function<std::optional<double>(int, const std::vector<double> &)> &draw,
              const std::function<TwinKey(std::optional<double>)> &make, int tries,
              std::vector<std::string> &failures) {
    std::vector<double> failed;
    for (int k = 0; k < tries; ++k) {
        const std::optional<double> strength = draw(k, failed);
        try {
            return make(strength);
        } catch (const std::exception &e) {
            std::ostringstream why;
            if (strength) {
                why << " at " << *strength;
                failed.push_back(*strength);
            }
            why << ": " << e.what();
            failures.push_back(why.str());
        }
    }
    return std::nullopt;
}

SelftestResult runSelftest(const SelftestOptions &o) {
    const auto t0 = std::chrono::steady_clock::now();
    const BaseModel base = loadBaseModel(o.base_model);
    const Design design = loadDesign(o.design);
    if (!o.plan.empty() && !fs::exists(o.plan))
        throw std::runtime_error(o.plan + ": no such self-test plan");
    const Plan plan = loadPlan(
        o.plan.empty() ? (fs::path(o.design).parent_path() / "selftest.yaml").string() : o.plan,
        design);
    const std::string sims = o.sims.empty() ? o.out + "/sims" : o.sims;
    StudySimulator sim(base, sims, o.executor);
    sim.sayLabWarnings();
    fs::create_directories(o.out);

    // The twins: every catalogue effect (that can act on this base) at a random strength, the
    // null twins, the out-of-catalogue ones.
    struct Planned {
        std::string name, effect;
        std::optional<double> strength;
    };
    std::vector<Planned> planned;
    const YAML::Node reference = sim.referenceScenario();
    for (const Effect *e : o.catalogue.diagnosable()) {
        if (!plan.effects.empty() &&
            std::find(plan.effects.begin(), plan.effects.end(), e->name) == plan.effects.end())
            continue;
        if (!inapplicable(*e, reference).empty())
            continue;
        planned.push_back({e->name, e->name, std::nullopt});
    }
    for (int k = 0; k < plan.nulls; ++k)
        planned.push_back({"null_" + std::to_string(k + 1), "", std::nullopt});
    for (const auto &[name, s] : plan.out_of_catalogue)
        planned.push_back({"ooc_" + name, name, s});

    std::vector<const Effect *> diagnosable;
    for (const Effect *e : o.catalogue.diagnosable())
        if (plan.catalogue.empty() || std::find(plan.catalogue.begin(), plan.catalogue.end(),
                                                e->name) != plan.catalogue.end())
            diagnosable.push_back(e);
    for (const std::string &name : plan.catalogue)
        o.catalogue.find(name); // an unknown name stops here
    SelftestResult R;
    unsigned k = 0;
    for (const Planned &p : planned) {
        ++k;
        const std::string folder = o.out + "/twins/" + p.name;
        const std::string key_path = o.out + "/keys/" + p.name + ".json";
        TwinOptions to;
        to.effect = p.effect;
        to.seed = o.seed * 100 + k;
        to.noise = plan.noise;
        to.level_noise = plan.level_noise;
        to.own_beds = plan.own_beds;
        // A drawn strength whose twin cannot be simulated on this design (its grains past the
        // overlap limit) is drawn again from the prior cut at it, nearer off, each try said:
        // drawn again from the whole prior, the soft surface layer went unscored on every
        // draw of the full self-test (four draws below 0.29; on its soft base 0.4 runs).
        const bool drawn = !p.strength && !p.effect.empty();
        std::vector<std::string> tries;
        const std::optional<TwinKey> made = drawUntilMade(
            [&](int draw, const std::vector<double> &failed) -> std::optional<double> {
                if (p.strength)
                    return p.strength;
                if (!drawn)
                    return std::nullopt;
                return drawStrength(resolveAgainst(o.catalogue.find(p.effect), reference),
                                    to.seed + 100003u * unsigned(draw), plan.strengths, failed);
            },
            [&](std::optional<double> strength) {
                to.strength = strength;
                std::fprintf(stderr, "[selftest] twin %u/%zu: %s%s\n", k, planned.size(),
                             p.name.c_str(),
                             strength ? (" at " + std::to_string(*strength)).c_str() : "");
                fs::remove_all(folder); // no file of a failed draw stays beside the twin
                return makeTwin(design, o.catalogue, sim, to, folder, key_path);
            },
            drawn ? kStrengthDraws : 1, tries);
        for (std::string &t : tries)
            t = p.name + t;
        if (!made) { // a twin whose simulations failed cannot be scored: said, and left out
            R.failed_twins.push_back(tries.back());
            tries.pop_back();
        }
        R.redrawn.insert(R.redrawn.end(), tries.begin(), tries.end());
        if (!made)
            continue;
        const TwinKey key = *made;

        // Blind: the diagnosis gets the folder and the catalogue, never the key.
        const ExperimentSet set = loadExperiments(folder);
        DiagnosisOptions dopt;
        dopt.seeds = base.seeds;
        dopt.signature_seeds = base.signature_seeds;
        dopt.check_seeds = base.check_seeds;
        dopt.held_out = plan.hold_out;
        dopt.log = [&](const std::string &line) {
            std::fprintf(stderr, "[selftest %s] %s\n", p.name.c_str(), line.c_str());
        };
        const Diagnosis d = diagnose(set, diagnosable, sim, dopt);
        writeDiagnosis(d, set, folder + "/diagnosis", o.plot_tool);

        SelftestTwin t;
        t.name = p.name;
        t.key = key;
        t.outcome = d.outcome;
        t.claimed = d.outcome == Diagnosis::Outcome::Explained ||
                            d.outcome == Diagnosis::Outcome::ExplainedByPair
                        ? outcomeWord(d)
                        : "";
        t.claim = d.claim;
        // Weak: the hidden effect, simulated on the twin's own beds without noise, stays within
        // the diagnosis' validation uncertainty of the base.
        if (!key.effect.empty()) {
            const VariantRequest truth = twinRequest(design, key, &o.catalogue.find(key.effect));
            const Eigen::MatrixXd rows = sim.simulate(set, d.design, {truth})[0];
            const ColumnStats s = columnStats(rows);
            // The same standardisation as the diagnosis' own gap test: the normal deviate of
            // Student's t with u_val's degrees of freedom.
            Eigen::VectorXd z =
                (s.mean - d.validation.simulated).array() / d.validation.u_val.array();
            for (Eigen::Index k = 0; k < z.size(); ++k)
                z[k] = normalEquivalent(z[k], d.validation.dof[k]);
            t.weak = !testGap(d.design.keys, z).gap;
        }
        scoreTwin(d, key.effect.empty() ? nullptr : &o.catalogue.find(key.effect), t, R);
        R.twins.push_back(t);
    }

    // The line, the targets, the confusion matrix.
    std::vector<double> reductions;
    for (const auto &t : R.twins)
        if (t.key.in_catalogue && !t.key.effect.empty() && !t.weak)
            reductions.push_back(t.reduction_pct);
    std::sort(reductions.begin(), reductions.end());
    R.median_reduction_pct =
        reductions.empty() ? 0.0
                           : (reductions.size() % 2 ? reductions[reductions.size() / 2]
                                                    : 0.5 * (reductions[reductions.size() / 2 - 1] +
                                                             reductions[reductions.size() / 2]));
    const double top1_pct = R.top1_of ? 100.0 * R.top1 / R.top1_of : 0.0;
    char line[512];
    std::snprintf(line, sizeof line,
                  "selftest: top-1 %d/%d (%.0f %%), strength within 25 %%: %d/%d, held-out gap "
                  "reduction median %.0f %%, null false claims %d/%d, out-of-catalogue "
                  "unexplained %d/%d",
                  R.top1, R.top1_of, top1_pct, R.strength_ok, R.strength_of, R.median_reduction_pct,
                  R.null_false, R.nulls, R.ooc_unexplained, R.oocs);
    R.line = line;
    R.passed = R.failed_twins.empty() && top1_pct >= 90.0 && R.strength_ok == R.strength_of &&
               R.median_reduction_pct >= 70.0 && R.null_false == 0 && R.ooc_unexplained == R.oocs;

    std::map<std::string, std::map<std::string, int>> confusion;
    std::vector<std::string> columns;
    const auto column = [&](const std::string &c) {
        if (std::find(columns.begin(), columns.end(), c) == columns.end())
            columns.push_back(c);
        return c;
    };
    for (const auto &t : R.twins) {
        const std::string row = t.key.effect.empty() ? "(null)" : t.key.effect;
        const std::string col =
            t.claimed.empty() ? (t.outcome == Diagnosis::Outcome::NoGap ? "no gap" : "unexplained")
                              : t.claimed;
        ++confusion[row][column(col)];
    }
    std::ostringstream rep;
    rep << R.line << "\n";
    rep << "weak twins (hidden effect within the validation uncertainty; correct only as 'no "
           "gap'): "
        << R.weak << " of " << R.top1_of << "\n";
    if (R.named_of > 0)
        rep << "strong twins without a correct claim whose hidden effect the report named "
               "(closest or nearest to a claim): "
            << R.named << " of " << R.named_of
            << ", within 25 % of its strength: " << R.named_strength_ok << " of " << R.named
            << "\n";
    rep << "\nconfusion matrix (rows: hidden, columns: diagnosed)\n";
    rep << "  " << std::string(22, ' ');
    for (const auto &c : columns)
        rep << " | " << c;
    rep << '\n';
    for (const auto &[row, cells] : confusion) {
        char label[64];
        std::snprintf(label, sizeof label, "  %-22s", row.c_str());
        rep << label;
        for (const auto &c : columns)
            rep << " | " << (cells.count(c) ? std::to_string(cells.at(c)) : "0");
        rep << '\n';
    }
    for (const auto &f : R.redrawn)
        rep << "twin not made, its strength drawn again: " << f << '\n';
    for (const auto &f : R.failed_twins)
        rep << "twin not made (left out of the scores): " << f << '\n';
    rep << "\ntwins:\n";
    for (const auto &t : R.twins) {
        rep << "  " << t.name << ": hidden " << (t.key.effect.empty() ? "none" : t.key.effect);
        if (!t.key.effect.empty())
            rep << " = " << t.key.strength << (t.weak ? " (weak)" : "");
        rep << "; diagnosed " << (t.claimed.empty() ? outcomeName(t.outcome) : t.claimed);
        if (t.correct && t.claimed_strength != 0.0)
            rep << " = " << t.claimed_strength
                << (t.strength_within_25 ? " (within 25 %)" : " (off by more than 25 %)");
        if (t.named)
            rep << " (named "
                << (t.claim.find("closest: " + t.key.effect) != std::string::npos
                        ? "closest"
                        : "nearest to a claim")
                << " at " << t.named_strength << ")";
        rep << (t.correct ? "  [correct]" : "  [WRONG]") << '\n';
    }
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    rep << "\nsimulations: " << sim.runsDone() << " run, " << sim.runsReused() << " reused; wall "
        << std::lround(wall) << " s\n";
    R.report = rep.str();
    std::ofstream(o.out + "/selftest.txt") << R.report;
    return R;
}

} // namespace grainlink::gap
