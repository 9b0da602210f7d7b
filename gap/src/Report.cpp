#include "grainlink/gap/Report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <tuple>

namespace grainlink::gap {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

namespace {

Json number(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

Json score(const HeldOutScore &s) {
    return {{"features", s.features},
            {"relative_rmse", number(s.relative_rmse)},
            {"gap_beyond_uncertainty", number(s.gap)},
            {"mean_squared_standardised_error", number(s.smse)},
            {"log_predictive_density", number(s.log_density)}};
}

/// The held-out log-density gain over the null, and what its p value rests on.
Json gain(const DensityComparison &c) {
    return {{"mean_per_feature", number(c.mean_gain)},
            {"features", c.features},
            {"experiments", c.experiments},
            {"counted_by", c.per_experiment ? "experiment, shared luck measured" : "group of beds"},
            {"share_between_experiments", number(c.gain_correlation)},
            {"seed_jackknife_variance", number(c.seed_variance)},
            {"measured_shared_variance", number(c.measured_variance)}};
}

Json verdict(const GapVerdict &g) {
    return {{"gap", g.gap},
            {"flagged_features", g.flagged},
            {"features", g.features},
            {"largest_abs_z", number(g.max_abs)}, // nearest its kind's bound
            {"largest_abs_z_kind", g.worst_kind},
            {"feature_bound", number(g.feature_bound)},
            {"worst_experiment", g.worst_experiment},
            {"worst_experiment_rms_z", number(g.worst_rms)},
            {"experiment_bound", number(g.experiment_bound)},
            {"summary", g.summary}};
}

Json strength(const Effect &e, const StrengthFit &f) {
    return {{"parameter", e.parameter},
            {"unit", e.unit},
            {"value", number(f.strength)},
            {"ci95", {number(f.lo), number(f.hi)}},
            {"base_value", number(e.prior.off)},
            {"prior", {e.prior.lo, e.prior.hi}},
            {"at_prior_bound", f.at_bound},
            {"beyond_prior", f.beyond_prior},
            {"at_prior_edge", f.at_prior_edge},
            {"bed_luck_sd", number(f.luck_sd)},
            {"bed_luck_sd_scale", e.prior.log_scale ? "log" : "linear"}};
}

/// An effect's strength asked for by each kind of observable, and their agreement, into `into`.
void byKind(Json &into, const Effect &e,
            const std::vector<std::pair<std::string, StrengthFit>> &by_kind,
            const StrengthAgreement &agreement) {
    into["strength_by_kind"] = Json::array();
    for (const auto &[kind, fit] : by_kind)
        into["strength_by_kind"].push_back({{"kind", kind}, {"strength", strength(e, fit)}});
    into["strength_agreement"] = {{"chi2", number(agreement.chi2)},
                                  {"dof", agreement.dof},
                                  {"p_value", number(agreement.p_value)},
                                  {"weighted_mean", number(agreement.mean)}};
}

void writeAtomically(const fs::path &path, const std::string &text) {
    const fs::path tmp = path.string() + ".tmp";
    {
        std::ofstream out(tmp);
        out << text;
        if (!out)
            throw std::runtime_error(tmp.string() + ": cannot write");
    }
    fs::rename(tmp, path);
}

std::string pct(double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%.1f %%", 100.0 * v);
    return b;
}

/// The verdict for a script: the outcome, the model it names and its strengths, the held-out
/// gaps and the test, without reading `claim`. null where there is none.
Json verdictJson(const Diagnosis &d) {
    Json v{{"outcome", outcomeName(d.outcome)}, {"text", headline(d)}};
    v["model"] = d.best_model.empty() ? Json(nullptr) : Json(d.best_model);
    v["model_is"] = d.best_model.empty()     ? Json(nullptr)
                    : d.explained_by.empty() ? Json("closest, not claimed")
                                             : Json("claimed");
    v["strengths"] = Json::array();
    v["held_out_gap"] = {{"base", number(d.held_out_base.gap)},
                         {"null_model", number(d.held_out_null.gap)},
                         {"with_model", nullptr}};
    v["p_value_against_null"] = nullptr;
    v["level"] = nullptr;
    const NamedModel m = namedModel(d);
    for (const auto &[effect, fit] : m.strengths) {
        Json s = strength(*effect, fit);
        s["effect"] = effect->name;
        v["strengths"].push_back(s);
    }
    if (m.held_out) {
        v["held_out_gap"]["with_model"] = number(m.held_out->gap);
        v["p_value_against_null"] = number(m.versus_null->p_value);
        v["level"] = number(m.level);
    }
    v["gap_test"] = {{"flagged_features", d.verdict.flagged}, {"features", d.verdict.features}};
    return v;
}

} // namespace

Json toJson(const Diagnosis &d, const ExperimentSet &set) {
    Json j;
    j["format"] = "grainlink-gap-diagnosis";
    j["version"] = 1;
    j["measurements"] = set.name;
    j["measurement_notes"] = set.notes;
    j["not_compared"] = d.not_compared;
    j["partly_compared"] = d.partly_compared;
    j["outcome"] = outcomeName(d.outcome);
    j["verdict"] = verdictJson(d);
    j["claim"] = d.claim;
    j["numerical_warning"] = d.numerical_warning;
    // The parts of u_val, each a median share of the simulated value (null where undefined).
    j["uncertainty_budget"] = Json::object();
    for (const auto &[part, share] : uncertaintyBudget(d.validation))
        j["uncertainty_budget"][part] = std::isfinite(share) ? Json(share) : Json(nullptr);
    j["explained_by"] = d.explained_by;
    j["best_model"] = d.best_model;
    j["nearest_to_claim"] = d.nearest_to_claim;
    j["where"] = Json::array();
    for (const RegimeFinding &f : d.findings)
        j["where"].push_back({{"kind", f.kind},
                              {"x_range", {f.x_lo, f.x_hi}},
                              {"sign", f.sign},
                              {"experiments", f.experiments},
                              {"of", f.covering},
                              {"ratio_simulated_over_measured", {number(f.ratio_min), number(f.ratio_max)}},
                              {"text", f.text}});
    j["gap_test"] = verdict(d.verdict);
    j["calibration_experiments"] = d.calibration_experiments;
    j["held_out_experiments"] = d.held_out_experiments;
    j["held_out"] = {{"base", score(d.held_out_base)}, {"null", score(d.held_out_null)}};
    j["candidates"] = Json::array();
    for (const CandidateResult &c : d.candidates) {
        Json cj{{"effect", c.name}, {"acts_on", c.effect.acts_on}, {"description", c.effect.description}};
        if (!c.applicability.empty()) {
            cj["applicable"] = false;
            cj["why_not"] = c.applicability;
        } else {
            cj["applicable"] = true;
            cj["signature_chi2"] = number(c.signature_chi2);
            cj["acts_on_design"] = c.actsOnDesign();
            cj["strength"] = strength(c.effect, c.fit);
            cj["calibration_chi2"] = number(c.fit.chi2);
            cj["ranking_chi2"] = number(c.ranking_chi2); // on the signatures alone
            cj["calibration_chi2_gain"] = number(c.calibration_gain);
            cj["confirmed"] = c.confirmed;
            if (c.confirmed) {
                cj["held_out"] = score(c.held_out);
                cj["p_value_against_null"] = number(c.versus_null.p_value);
                cj["held_out_gain"] = gain(c.versus_null);
                cj["beats_null"] = c.beats_null;
                cj["gap_test_with_effect"] = verdict(c.after);
                byKind(cj, c.effect, c.by_kind, c.agreement);
                cj["explains"] = c.explains;
            }
        }
        j["candidates"].push_back(cj);
    }
    j["pairs"] = Json::array();
    for (const PairResult &p : d.pairs) {
        Json pj{{"effects", {p.a, p.b}},
                {"strengths", {number(p.fit.a.strength), number(p.fit.b.strength)}},
                {"calibration_chi2", number(p.fit.chi2)},
                {"confirmed", p.confirmed}};
        if (p.confirmed) {
            pj["held_out"] = score(p.held_out);
            pj["p_value_against_null"] = number(p.versus_null.p_value);
            pj["held_out_gain"] = gain(p.versus_null);
            pj["gap_test_with_effects"] = verdict(p.after);
            pj["explains"] = p.explains;
            pj["p_value_best_pair_over_it"] = number(p.best_over_it_p);
            // Each strength by kind, the other held at its fit.
            Json parts = Json::array();
            for (const auto &[name, by_kind, agreement] :
                 {std::tie(p.a, p.a_by_kind, p.a_agreement),
                  std::tie(p.b, p.b_by_kind, p.b_agreement)})
                for (const CandidateResult &c : d.candidates)
                    if (c.name == name) {
                        Json part{{"effect", name}};
                        byKind(part, c.effect, by_kind, agreement);
                        parts.push_back(part);
                    }
            pj["by_kind"] = parts;
        }
        j["pairs"].push_back(pj);
    }
    Json names = Json::array();
    for (const CandidateResult &c : d.candidates)
        if (c.applicability.empty())
            names.push_back(c.name);
    j["signature_overlap"] = {{"effects", names}, {"fraction", d.overlap}};
    j["rivals"] = Json::array();
    for (const Diagnosis::Rival &r : d.rivals)
        j["rivals"].push_back({{"effect", r.name},
                               {"p_value_claimed_over_it", r.p_value},
                               {"at_prior_edge", r.at_prior_edge},
                               {"beats_null", r.beats_null}});
    j["indistinguishable_from_leader"] = d.indistinguishable;
    j["separating_experiment"] = d.separating_experiment;
    j["separating_chi2"] = number(d.separating_chi2);
    j["separating_feature"] = d.separating_feature;
    j["separating_predictions"] = Json::array();
    for (const auto &p : d.separating_predictions)
        j["separating_predictions"].push_back(
            {{"model", p.model}, {"strength", p.strength}, {"mean", number(p.mean)},
             {"sd", number(p.sd)}});
    j["unexplained"] = d.unexplained;
    j["claim_level"] = {{"single", number(d.single_level)}, {"pair", number(d.pair_level)}};
    j["simulations"] = d.simulations;
    j["simulations_read"] = d.reads;
    return j;
}

std::string reportText(const Diagnosis &d, const ExperimentSet &set) {
    std::ostringstream r;
    r << "grainlink gap diagnose: " << set.name << "\n\n";
    r << "Verdict: " << headline(d) << "\n";
    if (d.outcome != Diagnosis::Outcome::NoGap && d.outcome != Diagnosis::Outcome::Unresolved)
        r << "  (held-out gap: how far the held-out experiments lie beyond their validation "
             "uncertainty u_val, as a share of the measured value; the null model is the base "
             "plus a generic correction fitted on the calibration experiments; an effect is "
             "claimed only where it predicts the held-out experiments better than the null "
             "model, p below the level, and leaves no gap)\n";
    r << "\nResult: " << d.claim << "\n\n";
    if (!d.numerical_warning.empty())
        r << "Warning: " << d.numerical_warning << "\n\n";
    for (const std::string &note : set.notes)
        r << "Read: " << note << '\n';
    if (!set.notes.empty())
        r << '\n';
    r << "Numerical uncertainty and the gap test: " << d.verdict.summary << "\n";
    {
        // V&V 20's budget: which part of u_val a finer base model would shrink.
        std::ostringstream parts;
        std::string total;
        for (const auto &[part, share] : uncertaintyBudget(d.validation)) {
            if (!std::isfinite(share))
                continue;
            char pct[32];
            std::snprintf(pct, sizeof pct, share < 0.01 ? "%.1f %%" : "%.0f %%", 100.0 * share);
            // A check whose every run failed somewhere counts as none there: not a measured 0.
            // (a copy: C++17 lambdas cannot capture a structured binding)
            const std::string name = part;
            const bool failed =
                std::any_of(d.validation.check_failures.begin(), d.validation.check_failures.end(),
                            [&](const auto &f) { return f.first == name; });
            if (part == "u_val")
                total = pct;
            else
                parts << (parts.tellp() > 0 ? ", " : "") << part << ' ' << pct
                      << (failed ? " (its runs failed on some experiments: unknown there)" : "");
        }
        r << "Validation uncertainty by part (median share of the simulated value): " << parts.str()
          << "; u_val " << total << "\n";
    }
    r << "Where the gap lies:\n";
    for (const RegimeFinding &f : d.findings)
        r << "  - " << f.text << '\n';
    r << "\nCalibration experiments: ";
    for (const auto &e : d.calibration_experiments)
        r << e << ' ';
    r << "\nHeld-out experiments:    ";
    for (const auto &e : d.held_out_experiments)
        r << e << ' ';
    r << "\nHeld-out gap beyond uncertainty: base " << pct(d.held_out_base.gap) << ", null model "
      << pct(d.held_out_null.gap)
      << "\n\nCandidates (by calibration chi^2 on their signatures, which chose those "
         "re-simulated):\n";
    for (const CandidateResult &c : d.candidates) {
        r << "  " << c.name << ": ";
        if (!c.applicability.empty()) {
            r << "not applicable (" << c.applicability << ")\n";
            continue;
        }
        if (!c.actsOnDesign()) {
            r << "no signature on these experiments (its strongest simulated change moves them by "
              << "chi^2 " << c.signature_chi2 << ")\n";
            continue;
        }
        r << c.effect.parameter << " = " << c.fit.strength << " [" << c.fit.lo << ", " << c.fit.hi
          << "] " << c.effect.unit << ", chi^2 " << c.fit.chi2 << " (off: " << c.fit.chi2_off << ")";
        // Refitted once its confirming runs joined the table: say what ranked it too.
        if (std::abs(c.fit.chi2 - c.ranking_chi2) > 1e-6 * (1.0 + c.ranking_chi2))
            r << " with its confirming runs (" << c.ranking_chi2 << " on the signatures alone)";
        if (c.confirmed)
            r << "; re-simulated at it: held-out gap " << pct(c.held_out.gap)
              << ", p = " << c.versus_null.p_value << ", "
              << (c.explains ? std::string("EXPLAINS") : standing(c));
        if (c.confirmed && c.agreement.dof > 0) {
            r << "\n      by kind:";
            for (const auto &[kind, fit] : c.by_kind)
                r << ' ' << kind << ' ' << fit.strength << " [" << fit.lo << ", " << fit.hi << "];";
            r << " agreement chi^2 " << c.agreement.chi2 << " (" << c.agreement.dof
              << " dof), p = " << c.agreement.p_value;
        }
        if (c.fit.beyond_prior)
            r << "; pinned at its prior's edge (the data ask for more than " << c.effect.prior.lo
              << "-" << c.effect.prior.hi << " allows)";
        else if (c.fit.at_prior_edge)
            r << "; at its prior's edge (" << c.effect.prior.lo << "-" << c.effect.prior.hi
              << "): never claimed";
        r << '\n';
    }
    if (!d.indistinguishable.empty()) {
        r << "\nCannot be told apart from the leader on these experiments: ";
        for (const auto &n : d.indistinguishable)
            r << n << ' ';
        r << '\n';
        if (!d.separating_experiment.empty()) {
            r << "The experiment that would separate them best: " << d.separating_experiment
              << " (chi^2 between them " << d.separating_chi2 << ")\n";
            if (!d.separating_predictions.empty()) {
                r << "  where they differ most, " << d.separating_feature << ":";
                for (const auto &p : d.separating_predictions)
                    r << (&p == &d.separating_predictions.front() ? " " : "; ") << p.label() << ' '
                      << p.mean << " +- " << p.sd;
                r << '\n';
            }
        }
    }
    if (!d.unexplained.empty())
        r << "\nWhat remains beyond 2 u_val with the best model: " << d.unexplained << '\n';
    r << "\nSimulations: " << d.simulations << " runs asked for (cached runs reused)";
    if (d.reads > 0)
        r << "; " << d.reads << " more asked for were read from those runs (the measuring chain)";
    r << "\n";
    return r.str();
}

std::vector<std::string> writeDiagnosis(const Diagnosis &d, const ExperimentSet &set,
                                        const std::string &directory,
                                        const std::string &plot_tool) {
    const fs::path dir(directory);
    fs::create_directories(dir);
    std::vector<std::string> files;
    writeAtomically(dir / "diagnosis.json", toJson(d, set).dump(2) + "\n");
    files.push_back("diagnosis.json");

    // The best model's prediction, for the plots: the one the claim names.
    const Eigen::VectorXd *best = d.best_model.empty() ? nullptr : &d.best_model_mean;
    const std::string &best_name = d.best_model;
    std::ostringstream csv;
    csv.precision(10);
    csv << "experiment,observable,kind,x_lo,x_hi,held_out,measured,u_D,simulated,u_seed,u_bed,"
           "u_num,u_val,dof,z,ratio,null_mean,null_sd,best_model,best_model_mean,best_model_z";
    for (const auto &[name, u] : d.validation.u_checks)
        csv << ",u_check_" << name;
    csv << '\n';
    const std::set<Eigen::Index> held(d.held_out.begin(), d.held_out.end());
    const auto &v = d.validation;
    for (std::size_t i = 0; i < d.design.keys.size(); ++i) {
        const Eigen::Index k = Eigen::Index(i);
        const FeatureKey &key = d.design.keys[i];
        const auto num = [](double x) {
            std::ostringstream s;
            s.precision(10);
            if (std::isfinite(x))
                s << x;
            return s.str();
        };
        csv << key.experiment << ',' << key.observable << ',' << key.kind << ',' << key.x_lo << ','
            << key.x_hi << ',' << (held.count(k) ? 1 : 0) << ',' << num(d.measured.value[k]) << ','
            << num(v.u_D[k]) << ',' << num(v.simulated[k]) << ',' << num(v.u_seed[k]) << ','
            << num(v.u_bed[k]) << ',' << num(v.u_num[k]) << ',' << num(v.u_val[k]) << ','
            << num(v.dof[k]) << ',' << num(v.z[k]) << ',' << num(v.ratio[k]) << ','
            << (held.count(k) && d.null_mean.size() ? num(d.null_mean[k]) : "") << ','
            << (held.count(k) && d.null_variance.size() ? num(std::sqrt(d.null_variance[k])) : "")
            << ',' << best_name << ',' << (best ? num((*best)[k]) : "") << ','
            << (best && d.best_model_z.size() == best->size() ? num(d.best_model_z[k]) : "");
        for (const auto &[name, u] : v.u_checks)
            csv << ',' << num(u[k]);
        csv << '\n';
    }
    writeAtomically(dir / "features.csv", csv.str());
    files.push_back("features.csv");
    writeAtomically(dir / "report.txt", reportText(d, set));
    files.push_back("report.txt");
    if (!plot_tool.empty()) {
        const std::string cmd = "/usr/bin/python3 '" + plot_tool + "' '" + dir.string() + "'";
        if (std::system(cmd.c_str()) == 0 && fs::exists(dir / "report.html"))
            files.push_back("report.html");
        else
            std::fprintf(stderr, "[gap] report.html not written (needs /usr/bin/python3 with "
                                 "matplotlib: %s); diagnosis.json and report.txt are complete\n",
                         cmd.c_str());
    }
    return files;
}

} // namespace grainlink::gap
