// The diagnosis pipeline on an analytic "soil" whose effects are known exactly: it must name a
// hidden effect with its strength, claim nothing where there is no gap, and call an effect
// outside the catalogue unexplained. The reference is the planted truth, not the code.
#include "grainlink/gap/Diagnosis.hpp"
#include "ShippedEffects.hpp"
#include "grainlink/gap/Report.hpp"
#include "grainlink/gap/Selftest.hpp"

#include <boost/math/distributions/students_t.hpp>
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <unistd.h>

using namespace grainlink::gap;

namespace {

/// Plate pressure of the analytic soil: Bekker-like p = k (1 + a / d) z^1.3 with a box factor,
/// and each effect a change of its own shape.
struct Truth {
    std::string effect; ///< "" none; a catalogue name; "crust" (not in the catalogue)
    double strength = 0.0;
    /// How the measuring world's soil differs from the base model whatever the effect (another
    /// DEM code, another contact law): the exponent of z, and a trend with plate size.
    double exponent_shift = 0.0;
    double size_trend = 0.0;
    /// The measuring world's heap (an angle of repose experiment, where the set has one): by
    /// default the model's own law (`angle`), else this angle.
    double heap_deg = 0.0;
    /// A sensor zero offset (m) on top of the effect: a world with two effects at once.
    double zero_offset_m = 0.0;
};

/// The analytic heap's angle: 30 deg, which denser grains steepen in proportion (the model's
/// law; a world may differ).
double angle(const Truth &t) {
    return 30.0 * (t.effect == "grain_density" ? t.strength : 1.0);
}

double pressure(double z, double d, const std::string &box, const Truth &t) {
    const double confinement = box == "small" ? 1.25 : 1.0;
    double k = 2.0e6, a = 0.03;
    double p = k * (1.0 + a / d) * std::pow(std::max(z, 0.0), 1.3 + t.exponent_shift) *
               std::pow(0.02, -t.exponent_shift) * std::pow(d / 0.08, t.size_trend) * confinement;
    if (t.effect == "grain_stiffness") // stiffer grains: more pressure within an elastic zone
        p *= 1.0 + (std::pow(t.strength, 0.5) - 1.0) * std::exp(-z / (0.06 * d)); // ~ the plate

    if (t.effect == "cohesion") // a bearing term that grows with the plate
        p += t.strength * 0.08 * (d / 0.1) * std::min(1.0, z / 0.003);
    if (t.effect == "domain_size") // a narrower box confines the larger plates more
        p *= 1.0 + 0.6 * (1.0 / t.strength - 1.0) * (d / 0.1) * (box == "small" ? 1.5 : 1.0);
    if (t.effect == "grain_density") // self-weight: a uniform factor on this soil
        p *= t.strength;
    if (t.effect == "crust") // a stiff top layer: extra pressure only in the first millimetres
        p += t.strength * std::exp(-z / 0.0015) * std::min(1.0, z / 0.0005);
    return p;
}

Curve plateCurve(double d, const std::string &box, const Truth &t, double reach, double bed,
                 double noise, std::mt19937 &rng) {
    std::normal_distribution<double> z01;
    // One bed realisation: the whole curve moves and tilts.
    const double level = 1.0 + bed * z01(rng), tilt = bed * z01(rng);
    Curve c;
    for (int i = 0; i <= 100; ++i) {
        const double z = reach * i / 100.0;
        c.x.push_back(z);
        c.y.push_back(pressure(z, d, box, t) * (level + tilt * (z / reach - 0.5)) *
                      (1.0 + noise * z01(rng)));
    }
    return c;
}

ExperimentSet measuredSet(const Truth &t, unsigned seed) {
    ExperimentSet set;
    set.name = "analytic";
    std::mt19937 rng(seed);
    for (const std::string box : {"large", "small"})
        for (double d : {0.05, 0.07, 0.09, 0.11}) {
            Experiment e;
            e.id = box + "_" + std::to_string(int(d * 1000));
            e.type = ExperimentType::PlateSinkage;
            e.observables = {"pressure_Pa"};
            e.numbers["plate_diameter_m"] = d;
            e.labels["box"] = box;
            for (int r = 0; r < 4; ++r) {
                Trial tr;
                Curve c = plateCurve(d, box, t, 0.02, 0.03, 0.01, rng);
                if (t.effect == "sensor_zero_offset" || t.effect == "rig_compliance") {
                    Effect m;
                    m.kind = Effect::Kind::Measurement;
                    m.builtin = t.effect;
                    c = applyMeasurementEffect(m, t.strength, e, "pressure_Pa", c);
                }
                if (t.zero_offset_m != 0.0) {
                    Effect m;
                    m.kind = Effect::Kind::Measurement;
                    m.builtin = "sensor_zero_offset";
                    c = applyMeasurementEffect(m, t.zero_offset_m, e, "pressure_Pa", c);
                }
                tr.curves["pressure_Pa"] = c;
                e.trials.push_back(tr);
            }
            set.experiments.push_back(e);
        }
    return set;
}

/// The analytic soil as a simulator: effects it knows act through `pressure`, measurement
/// effects through applyMeasurementEffect, the rest do nothing; seeds are bed realisations.
class AnalyticSimulator final : public Simulator {
public:
    /// How much the resolution check moves every curve (1.01: resolved; over 1.5: not).
    double resolution_factor = 1.01;
    /// Bed scatter of a run with an effect (the base's is 0.03): another grain shape can scatter
    /// more from bed to bed.
    double effect_bed_scatter = 0.03;
    /// Bed scatter of one effect's confirming runs (by its catalogue name): at the fitted
    /// strength an effect can scatter more than its signature runs showed.
    std::map<std::string, double> confirm_scatter_of;
    /// Each simulated sample's own noise (independent from bin to bin within a curve).
    double sample_noise = 0.01;
    /// Report the plates of a box as simulated on the same beds (as grainlink's packing cache).
    bool beds_by_box = false;
    /// Catalogue entries that are another entry's physics under a name of their own.
    std::map<std::string, std::string> alias;
    /// Experiments whose runs stop short (their reach in m; 0.025 otherwise).
    std::map<std::string, double> reach;
    std::string bedGroup(const Experiment &e) const override {
        return beds_by_box ? e.labels.at("box") : e.id;
    }
    std::vector<std::string> checks() const override { return {"resolution"}; }
    YAML::Node referenceScenario() const override {
        return YAML::Load(
            "soil: {contact: {rolling: {model: none}, tangential: {stick_angle_deg: 30}}, "
            "deposition: {radius: {distribution: constant, value_m: 0.002}}}");
    }
    /// Name each run by its soil variant, check and seed, as grainlink's cache does (the
    /// measuring chain's effects read the run of the rest), and keep every id simulate is asked.
    bool names_runs = false;
    std::set<std::string> made;
    int asked = 0;
    std::vector<std::string> runIds(const ExperimentSet &, const VariantRequest &r) const override {
        std::vector<std::string> ids;
        if (!names_runs)
            return ids;
        std::string soil = r.check;
        for (auto [eff, str] :
             {std::pair{r.effect, r.strength}, std::pair{r.second, r.second_strength}})
            if (eff && eff->kind != Effect::Kind::Measurement)
                soil += " " + eff->name + "=" + std::to_string(str);
        for (int s = 0; s < r.seeds; ++s)
            ids.push_back(soil + " seed " + std::to_string(r.seed_offset + s));
        return ids;
    }
    std::vector<Eigen::MatrixXd> simulate(const ExperimentSet &set, const FeatureDesign &design,
                                          const std::vector<VariantRequest> &requests) override {
        std::vector<Eigen::MatrixXd> out;
        for (const VariantRequest &r : requests) {
            for (const std::string &id : runIds(set, r)) {
                made.insert(id);
                ++asked;
            }
            Eigen::MatrixXd rows(r.seeds, Eigen::Index(design.size()));
            for (int s = 0; s < r.seeds; ++s) {
                std::mt19937 rng(1000 + s); // the same seeds for every variant
                SimulatedCurves curves;
                for (const Experiment &e : set.experiments) {
                    Truth t;
                    std::vector<std::pair<const Effect *, double>> chain; // read below
                    for (auto [eff, str] : {std::pair{r.effect, r.strength},
                                            std::pair{r.second, r.second_strength}}) {
                        if (!eff)
                            continue;
                        if (eff->kind == Effect::Kind::Measurement)
                            chain.emplace_back(eff, str);
                        else
                            t = {alias.count(eff->name) ? alias.at(eff->name) : eff->name, str};
                    }
                    const bool confirming = r.label.rfind("confirm ", 0) == 0;
                    const double bed = !r.effect ? 0.03
                                       : confirming && confirm_scatter_of.count(r.effect->name)
                                           ? confirm_scatter_of.at(r.effect->name)
                                           : effect_bed_scatter;
                    if (e.type == ExperimentType::AngleOfRepose) {
                        curves[e.id]["angle_deg"] = Curve{
                            {0.0}, {angle(t) * (1.0 + bed * std::normal_distribution<>()(rng))}};
                        continue;
                    }
                    const double d = e.numbers.at("plate_diameter_m");
                    // Plates on the same beds draw the same bed (its level and tilt).
                    std::mt19937 same_bed(2000 + 31 * s + (e.labels.at("box") == "small"));
                    Curve c = plateCurve(d, e.labels.at("box"), t,
                                         reach.count(e.id) ? reach.at(e.id) : 0.025, bed,
                                         sample_noise, beds_by_box ? same_bed : rng);
                    for (auto [eff, str] : chain)
                        c = applyMeasurementEffect(*eff, str, e, "pressure_Pa", c);
                    if (r.check == "resolution")
                        for (double &y : c.y)
                            y *= resolution_factor;
                    curves[e.id]["pressure_Pa"] = c;
                }
                rows.row(s) = simulatedFeatures(set, design, curves).transpose();
            }
            out.push_back(rows);
        }
        return out;
    }
};

/// Four base seeds, three per signature; by default calibrated on the 50 and 70 mm plates and
/// predicting the 90 and 110 mm ones: a generic discrepancy must extrapolate in plate size, the
/// physics of an effect carries over.
DiagnosisOptions analyticOptions(std::vector<std::string> held_out = {"large_90", "large_110",
                                                                      "small_90", "small_110"}) {
    DiagnosisOptions o;
    o.seeds = 4;
    o.signature_seeds = 3;
    o.held_out = std::move(held_out);
    return o;
}

Diagnosis run(const Truth &t, unsigned seed = 7,
              std::vector<std::string> held_out = {"large_90", "large_110", "small_90",
                                                   "small_110"}) {
    const EffectCatalogue c = shippedEffects();
    AnalyticSimulator sim;
    return diagnose(measuredSet(t, seed), c.diagnosable(), sim, analyticOptions(held_out));
}

} // namespace

TEST_CASE("diagnosis on an analytic soil: no effect, no gap, no claim", "[gap][diagnosis]") {
    for (unsigned seed : {1u, 2u, 3u}) {
        const Diagnosis d = run({}, seed);
        INFO(d.verdict.summary);

        CHECK(d.outcome == Diagnosis::Outcome::NoGap);
    }
}

TEST_CASE("diagnosis on an analytic soil names the hidden effect and its strength",
          "[gap][diagnosis]") {
    const std::vector<Truth> truths{{"grain_stiffness", 3.0},
                                    {"cohesion", 4.0e4},
                                    {"domain_size", 0.75},
                                    {"sensor_zero_offset", 0.0015},
                                    {"rig_compliance", 2.0e-5}};
    for (const Truth &t : truths) {
        const Diagnosis d = run(t);
        INFO(t.effect << ": " << d.claim << " | null gap " << d.held_out_null.gap << " smse "
                      << d.held_out_null.smse << " base smse " << d.held_out_base.smse);
        for (const auto &c : d.candidates)
            if (c.confirmed)
                UNSCOPED_INFO(c.name << " smse " << c.held_out.smse << " n " << c.held_out.features
                                     << " p " << c.versus_null.p_value << " fit " << c.fit.strength
                                     << " [" << c.fit.lo << "," << c.fit.hi << "] birge "
                                     << c.fit.birge << " after " << c.after.summary);
        REQUIRE(d.outcome == Diagnosis::Outcome::Explained);
        const CandidateResult *winner = nullptr;
        for (const auto &c : d.candidates)
            if (c.explains && (!winner || c.held_out.log_density > winner->held_out.log_density))
                winner = &c;
        REQUIRE(winner);
        CHECK(winner->name == t.effect);
        // The named model is the best held-out density among those that explain, not the first
        // by calibration chi^2 (the self-test scored the first, and the report plotted it).
        CHECK(d.explained_by == winner->name);
        CHECK(d.best_model == winner->name);
        CHECK(d.best_model_mean.size() == winner->confirmed_mean.size());
        CHECK(winner->fit.strength == Approx(t.strength).epsilon(0.25));
        CHECK(winner->held_out.gap < 0.3 * d.held_out_base.gap);
    }
}

namespace {

/// Each request as "label xSEEDS".
std::vector<std::string> labels(const std::vector<VariantRequest> &requests) {
    std::vector<std::string> out;
    for (const VariantRequest &r : requests)
        out.push_back(r.label + " x" + std::to_string(r.seeds));
    return out;
}

/// The analytic simulator, with the labels of every call's requests recorded.
class RecordingSimulator final : public Simulator {
public:
    AnalyticSimulator inner;
    std::vector<std::vector<std::string>> calls;
    std::vector<std::string> checks() const override { return inner.checks(); }
    YAML::Node referenceScenario() const override { return inner.referenceScenario(); }
    std::vector<Eigen::MatrixXd> simulate(const ExperimentSet &set, const FeatureDesign &design,
                                          const std::vector<VariantRequest> &requests) override {
        calls.push_back(labels(requests));
        return inner.simulate(set, design, requests);
    }
};

} // namespace

TEST_CASE("a dry run plans the runs the diagnosis then asks for, and names what cannot act",
          "[gap][diagnosis]") {
    const EffectCatalogue c = shippedEffects();
    std::vector<const Effect *> effects = c.diagnosable();
    // One that cannot act on this base: it needs a rolling model the base does not have.
    Effect needs = c.find("rolling_resistance");
    needs.name = "rolling_resistance_on_grain_shape";
    needs.requires_text = {"soil.contact.rolling.model=grain_shape"};
    effects.push_back(&needs);
    const ExperimentSet set = measuredSet({"cohesion", 4.0e4}, 7);
    RecordingSimulator sim;
    const DiagnosisPlan plan = planDiagnosis(set, effects, sim, analyticOptions());
    const Diagnosis d = diagnose(set, effects, sim, analyticOptions());
    REQUIRE(d.verdict.gap); // else the signatures are never asked for
    REQUIRE(sim.calls.size() >= 2);
    CHECK(labels(plan.first) == sim.calls[0]);
    CHECK(labels(plan.signatures) == sim.calls[1]);
    CHECK(labels(plan.first) == std::vector<std::string>{"base x4", "check resolution x3"});
    CHECK(plan.design.size() == d.design.size());
    CHECK(plan.held_out == analyticOptions().held_out);
    // Every diagnosable effect is either planned or named with why not, as in the diagnosis.
    CHECK(plan.applicable.size() + plan.inapplicable.size() == effects.size());
    REQUIRE(plan.inapplicable.size() >= 1);
    CHECK(plan.inapplicable.back().first == "rolling_resistance_on_grain_shape");
    for (const auto &[name, why] : plan.inapplicable) {
        CHECK_FALSE(why.empty());
        bool same = false;
        for (const CandidateResult &r : d.candidates)
            same = same || (r.name == name && r.applicability == why);
        CHECK(same);
    }
}

TEST_CASE("diagnosis: every candidate is fitted against the same base runs, the measuring "
          "chain's effects too",
          "[gap][diagnosis]") {
    // Candidates are ranked by calibration chi^2: their "off" must be one model. The measuring
    // chain's effects had the base over all four seeds (a smaller variance, a larger chi^2),
    // the soil's over the three signature seeds: on the full self-test that was 80 against 57
    // for the same base, and the hidden zero offset ranked behind five effects of the soil.
    const Diagnosis d = run({"sensor_zero_offset", 0.0015});
    double chi2_off = -1.0;
    int compared = 0;
    for (const CandidateResult &c : d.candidates) {
        if (!c.applicability.empty())
            continue;
        INFO(c.name << ": chi^2 off " << c.fit.chi2_off);
        if (chi2_off < 0.0)
            chi2_off = c.fit.chi2_off;
        CHECK(c.fit.chi2_off == Approx(chi2_off).epsilon(1e-9));
        ++compared;
    }
    CHECK(compared >= 5);
}

TEST_CASE("diagnosis with one seed per signature and check still names the hidden effect",
          "[gap][diagnosis]") {
    // The CMU base runs one seed per signature: only the base's seeds pool (one or two degrees of
    // freedom per feature), so one bed's scatter is taken relative, per experiment. Read as the
    // raw pooled sd (and without the measuring chain's variants, which had padded it) it made
    // every soil effect's chi^2 twenty times too large and put an effect left at off first.
    const EffectCatalogue c = shippedEffects();
    AnalyticSimulator sim;
    sim.sample_noise = 0.15; // a bin's scatter of its own, as a DEM bed's small-sinkage bins
    DiagnosisOptions o = analyticOptions();
    o.seeds = 2;
    o.signature_seeds = 1;
    o.check_seeds = 1;
    for (const Truth &t : {Truth{"grain_stiffness", 3.0}, Truth{"cohesion", 4.0e4}}) {
        const Diagnosis d = diagnose(measuredSet(t, 7), c.diagnosable(), sim, o);
        INFO(t.effect << ": " << d.claim);
        REQUIRE_FALSE(d.candidates.empty());
        CHECK(d.candidates.front().name == t.effect);
        CHECK(d.candidates.front().fit.strength == Approx(t.strength).epsilon(0.25));
    }
}

TEST_CASE("diagnosis: what the report says remains is judged as the chosen model's gap test "
          "judged it, with the model's own bed scatter",
          "[gap][diagnosis]") {
    // The model's runs scatter three times as much as the base's. The words on what remains
    // were standardised by the base's u_val while the model's gap test used its own runs'
    // scatter: the CMU report listed two bins "beyond 2 u_val" where that test flagged none.
    const EffectCatalogue c = shippedEffects();
    AnalyticSimulator sim;
    sim.effect_bed_scatter = 0.09;
    for (const Truth &t : {Truth{"grain_stiffness", 3.0}, Truth{"crust", 8000.0}}) {
        const Diagnosis d = diagnose(measuredSet(t, 7), c.diagnosable(), sim, analyticOptions());
        INFO(t.effect << ": " << d.claim << " | remains: " << d.unexplained);
        REQUIRE_FALSE(d.best_model.empty());
        const auto chosen =
            std::find_if(d.candidates.begin(), d.candidates.end(),
                         [&](const CandidateResult &r) { return r.name == d.best_model; });
        REQUIRE(chosen != d.candidates.end());
        REQUIRE(d.best_model_z.size() == chosen->confirmed_mean.size());
        const int beyond = int((d.best_model_z.array().abs() > 2.0).count());
        CHECK(beyond == chosen->after.flagged);
        if (chosen->after.flagged == 0)
            CHECK(d.unexplained.empty());
    }
}

TEST_CASE("diagnosis on an analytic soil: an effect outside the catalogue stays unexplained",
          "[gap][diagnosis]") {
    const Diagnosis d = run({"crust", 8000.0});
    INFO(d.claim);
    CHECK(d.verdict.gap);
    CHECK(d.outcome == Diagnosis::Outcome::Unexplained);
    CHECK_FALSE(d.unexplained.empty());
}

TEST_CASE("diagnosis on an analytic soil: the null model interpolates between calibrated "
          "plates, and does not extrapolate beyond them",
          "[gap][diagnosis]") {
    // Denser grains scale every plate's pressure alike here. Calibrated on the 50 and 110 mm
    // plates, the generic discrepancy predicts the 70 and 90 mm ones; calibrated on the 50 and
    // 70 mm plates, it fades towards the base model on the larger ones, where the effect's
    // physics still holds.
    const Diagnosis inside =
        run({"grain_density", 1.6}, 7, {"large_70", "large_90", "small_70", "small_90"});
    CHECK(inside.held_out_null.gap < 0.25 * inside.held_out_base.gap);
    const Diagnosis beyond = run({"grain_density", 1.6});
    CHECK(beyond.held_out_null.gap > 0.4 * beyond.held_out_base.gap);
    INFO(beyond.claim);
    CHECK(beyond.outcome == Diagnosis::Outcome::Explained);
}

TEST_CASE("the diagnosis writes diagnosis.json, features.csv, report.txt and a self-contained "
          "report.html",
          "[gap][diagnosis][report]") {
    const Diagnosis d = run({"cohesion", 4.0e4});
    const ExperimentSet set = measuredSet({"cohesion", 4.0e4}, 7);
    const auto dir = std::filesystem::temp_directory_path() /
                     ("grainlink-gap-report-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    const auto files =
        writeDiagnosis(d, set, dir.string(), GRAINLINK_SOURCE_DIR "/tools/gap_report.py");
    std::ifstream in(dir / "diagnosis.json");
    const nlohmann::json j = nlohmann::json::parse(in);
    CHECK(j["outcome"] == "explained");
    CHECK(j["claim"].get<std::string>().find("cohesion") != std::string::npos);
    CHECK(j["candidates"].size() == d.candidates.size());
    // The claimed candidate's held-out gain and what its p value rests on: the four held-out
    // plates, eight features each.
    for (const auto &c : j["candidates"])
        if (c["effect"] == "cohesion") {
            CHECK(c["held_out_gain"]["experiments"] == 4);
            CHECK(c["held_out_gain"]["features"] == 32);
            CHECK(c["held_out_gain"]["mean_per_feature"].get<double>() > 0.0);
        }
    // The candidates are listed as the report's heading says, by the chi^2 on their signatures
    // that chose those re-simulated (a confirmed one's calibration_chi2 is refitted after).
    double ranked = -1.0;
    for (const auto &c : j["candidates"])
        if (c.contains("ranking_chi2")) {
            CHECK(c["ranking_chi2"].get<double>() >= ranked);
            ranked = c["ranking_chi2"].get<double>();
        }
    CHECK(ranked >= 0.0);
    // The budget of u_val: the analytic simulator's one check, the seeds, the measurement.
    CHECK(j["uncertainty_budget"].contains("resolution"));
    CHECK(j["uncertainty_budget"]["u_val"].get<double>() >=
          j["uncertainty_budget"]["resolution"].get<double>());
    std::ifstream report(dir / "report.txt");
    const std::string report_text((std::istreambuf_iterator<char>(report)),
                                  std::istreambuf_iterator<char>());
    CHECK(report_text.find("Validation uncertainty by part") != std::string::npos);
    std::ifstream features(dir / "features.csv");
    std::string line;
    std::getline(features, line);
    CHECK(line.find(",u_check_resolution") != std::string::npos);
    int lines = 1;
    while (std::getline(features, line))
        ++lines;
    CHECK(lines == int(d.design.size()) + 1);
    if (std::find(files.begin(), files.end(), "report.html") != files.end()) {
        std::ifstream page(dir / "report.html");
        const std::string text((std::istreambuf_iterator<char>(page)),
                               std::istreambuf_iterator<char>());
        CHECK(text.find("data:image/png;base64,") != std::string::npos);
        CHECK(text.find("EXPLAINED by cohesion") != std::string::npos);
        CHECK(text.find("<i>Each panel is one experiment") != std::string::npos); // captions
        CHECK(text.find("<i>One panel per kind of observable") != std::string::npos);
    } else {
        WARN("report.html not made: /usr/bin/python3 with matplotlib missing");
    }
    // The verdict for a script, read against the claimed candidate's own record.
    const nlohmann::json &v = j["verdict"];
    CHECK(v["outcome"] == "explained");
    CHECK(v["model"] == "cohesion");
    CHECK(v["model_is"] == "claimed");
    REQUIRE(v["strengths"].size() == 1);
    for (const auto &c : j["candidates"])
        if (c["effect"] == "cohesion") {
            CHECK(v["strengths"][0]["value"] == c["strength"]["value"]);
            CHECK(v["strengths"][0]["ci95"] == c["strength"]["ci95"]);
            CHECK(v["held_out_gap"]["with_model"] == c["held_out"]["gap_beyond_uncertainty"]);
            CHECK(v["p_value_against_null"] == c["p_value_against_null"]);
        }
    CHECK(v["held_out_gap"]["base"] == j["held_out"]["base"]["gap_beyond_uncertainty"]);
    CHECK(v["level"] == j["claim_level"]["single"]);
    CHECK(report_text.find("Verdict: EXPLAINED by cohesion, cohesion_energy_density = ") !=
          std::string::npos);
    // A diagnosis.json from an older grainlink (no verdict) is refused by name, with the fix,
    // not with a Python traceback.
    if (std::find(files.begin(), files.end(), "report.html") != files.end()) {
        nlohmann::json old = j;
        old.erase("verdict");
        std::ofstream(dir / "diagnosis.json") << old.dump();
        const auto said = dir / "said.txt";
        const std::string cmd = "/usr/bin/python3 '" GRAINLINK_SOURCE_DIR
                                "/tools/gap_report.py' '" +
                                dir.string() + "' 2> '" + said.string() + "'";
        CHECK(std::system(cmd.c_str()) != 0);
        std::ifstream err(said);
        const std::string text((std::istreambuf_iterator<char>(err)),
                               std::istreambuf_iterator<char>());
        CHECK(text.find("diagnosis.json has no 'verdict': it was written by an older grainlink; "
                        "run `grainlink gap diagnose` again") != std::string::npos);
        CHECK(text.find("Traceback") == std::string::npos);
    }
}

TEST_CASE("diagnosis against another code's soil: a difference outside the catalogue is not "
          "claimed as an effect",
          "[gap][diagnosis][mismatch]") {
    // The measuring world's soil has another exponent of z or another trend with plate size
    // than the base model, and no catalogue effect: a gap, which no effect may claim.
    const std::vector<Truth> worlds{
        {"", 0.0, -0.25, 0.0}, {"", 0.0, 0.0, 0.3}, {"", 0.0, 0.15, -0.3}};
    for (const Truth &t : worlds)
        for (unsigned seed : {1u, 2u}) {
            const Diagnosis d = run(t, seed);
            INFO("exponent shift " << t.exponent_shift << ", size trend " << t.size_trend
                                   << ", seed " << seed << ": " << d.claim);
            CHECK(d.verdict.gap);
            CHECK(d.outcome != Diagnosis::Outcome::Explained);
            CHECK(d.outcome != Diagnosis::Outcome::ExplainedByPair);
        }
    // A known limit (docs/gap.md, "Limits"): a steeper p(z) than the base's is what an early
    // sinkage zero gives too, on plates alone; if anything is claimed for it, it is that.
    for (unsigned seed : {1u, 2u}) {
        const Diagnosis d = run({"", 0.0, 0.25, 0.0}, seed);
        INFO("exponent shift 0.25, seed " << seed << ": " << d.claim);
        CHECK(d.verdict.gap);
        CHECK(d.outcome != Diagnosis::Outcome::ExplainedByPair);
        if (d.outcome == Diagnosis::Outcome::Explained)
            CHECK(d.claim.rfind("explained by sensor_zero_offset", 0) == 0);
    }
}

TEST_CASE("diagnosis against another code's soil: a strong hidden effect still leads the "
          "candidates",
          "[gap][diagnosis][mismatch]") {
    const std::vector<Truth> truths{{"cohesion", 6.0e4, 0.08, 0.0},
                                    {"grain_stiffness", 3.0, -0.08, 0.0},
                                    {"sensor_zero_offset", 0.0015, 0.0, 0.1}};
    for (const Truth &t : truths) {
        const Diagnosis d = run(t);
        INFO(t.effect << ": " << d.claim);
        REQUIRE(d.verdict.gap);
        const CandidateResult *leader = nullptr;
        for (const auto &c : d.candidates)
            if (c.confirmed && (!leader || c.fit.chi2 < leader->fit.chi2))
                leader = &c;
        REQUIRE(leader);
        CHECK(leader->name == t.effect);
        // Claimed or not, nothing else is claimed in its place.
        for (const auto &c : d.candidates)
            if (c.explains)
                CHECK(c.name == t.effect);
    }
}

namespace {
/// The analytic soil whose runs of some experiments all fail: their features are missing.
class FailingSimulator final : public Simulator {
public:
    explicit FailingSimulator(std::set<std::string> failing) : failing_(std::move(failing)) {}
    std::vector<std::string> checks() const override { return inner_.checks(); }
    YAML::Node referenceScenario() const override { return inner_.referenceScenario(); }
    std::vector<Eigen::MatrixXd> simulate(const ExperimentSet &set, const FeatureDesign &design,
                                          const std::vector<VariantRequest> &requests) override {
        auto rows = inner_.simulate(set, design, requests);
        for (auto &m : rows)
            for (const auto &id : failing_)
                for (Eigen::Index k : design.by_experiment.at(id))
                    m.col(k).setConstant(std::numeric_limits<double>::quiet_NaN());
        return rows;
    }

private:
    AnalyticSimulator inner_;
    std::set<std::string> failing_;
};

/// The analytic soil, except that every run of one effect fails on some experiments (the DEM
/// stopping at its overlap limit under a plate, as soft grains did with LIGGGHTS' data), or
/// with `first_bin_only` no longer reaches their first bin (a zero offset moving a curve past it).
class FailingEffectSimulator final : public Simulator {
public:
    FailingEffectSimulator(std::string effect, std::set<std::string> failing,
                           bool only_confirming = false, bool first_bin_only = false)
        : effect_(std::move(effect)), failing_(std::move(failing)),
          only_confirming_(only_confirming), first_bin_only_(first_bin_only) {}
    std::vector<std::string> checks() const override { return inner_.checks(); }
    YAML::Node referenceScenario() const override { return inner_.referenceScenario(); }
    std::vector<Eigen::MatrixXd> simulate(const ExperimentSet &set, const FeatureDesign &design,
                                          const std::vector<VariantRequest> &requests) override {
        auto rows = inner_.simulate(set, design, requests);
        for (std::size_t i = 0; i < requests.size(); ++i)
            if (((requests[i].effect && requests[i].effect->name == effect_) ||
                 (requests[i].second && requests[i].second->name == effect_)) &&
                (!only_confirming_ || requests[i].label.rfind("confirm", 0) == 0))
                for (const auto &id : failing_)
                    for (Eigen::Index k : design.by_experiment.at(id)) {
                        rows[i].col(k).setConstant(std::numeric_limits<double>::quiet_NaN());
                        if (first_bin_only_)
                            break;
                    }
        return rows;
    }

private:
    AnalyticSimulator inner_;
    std::string effect_;
    std::set<std::string> failing_;
    bool only_confirming_ = false, first_bin_only_ = false;
};

/// The analytic model whose study refuses one effect's variants (as a lab scenario whose grains
/// a wider size distribution coarsens below a plate's resolution): running one is an error.
class RefusingEffectSimulator final : public Simulator {
public:
    /// `only_confirming`: its signatures run; its confirming runs (at a fitted strength) are
    /// refused.
    explicit RefusingEffectSimulator(std::string effect, bool only_confirming = false)
        : effect_(std::move(effect)), only_confirming_(only_confirming) {}
    /// Only strengths below this are refused (a box narrower than its plates).
    double refuse_below = std::numeric_limits<double>::infinity();
    std::vector<std::string> checks() const override { return inner_.checks(); }
    YAML::Node referenceScenario() const override { return inner_.referenceScenario(); }
    std::string refusal(const ExperimentSet &, const VariantRequest &r) const override {
        const double s = r.effect && r.effect->name == effect_ ? r.strength : r.second_strength;
        const bool refused =
            ((r.effect && r.effect->name == effect_) || (r.second && r.second->name == effect_)) &&
            (!only_confirming_ || r.label.rfind("confirm", 0) == 0) && s < refuse_below;
        return refused ? "key 'bevameter.plate_radii_m': Gamma = 2.9 < min_resolution 3" : "";
    }
    std::vector<Eigen::MatrixXd> simulate(const ExperimentSet &set, const FeatureDesign &design,
                                          const std::vector<VariantRequest> &requests) override {
        for (const VariantRequest &r : requests)
            if (!refusal(set, r).empty())
                throw std::runtime_error("a refused variant was run: " + r.label);
        return inner_.simulate(set, design, requests);
    }

private:
    AnalyticSimulator inner_;
    std::string effect_;
    bool only_confirming_ = false;
};
} // namespace

TEST_CASE("diagnosis: failed simulations are never read as agreement, nor bins they do not reach",
          "[gap][diagnosis]") {
    const EffectCatalogue c = shippedEffects();
    DiagnosisOptions o;
    o.seeds = 3;
    o.signature_seeds = 2;
    const ExperimentSet set = measuredSet({}, 1);
    std::set<std::string> every;
    for (const Experiment &e : set.experiments)
        every.insert(e.id);
    FailingSimulator none_ran(every);
    CHECK_THROWS_WITH(diagnose(set, c.diagnosable(), none_ran, o),
                      Catch::Contains("no experiment could be compared") &&
                          Catch::Contains("large_50"));
    // Some ran: the result speaks for those, and names the others.
    FailingSimulator some_ran({"small_90", "small_110"});
    const Diagnosis d = diagnose(set, c.diagnosable(), some_ran, o);
    INFO(d.claim);
    CHECK(d.outcome == Diagnosis::Outcome::NoGap);
    CHECK(d.claim.find("every compared experiment agrees") != std::string::npos);
    CHECK(d.claim.find("not compared (no simulated feature): small_90, small_110") !=
          std::string::npos);

    // Runs that stop short of some measured bins: the experiment is named with how much of it
    // went uncompared (the gap test saw only the rest, and said nothing).
    AnalyticSimulator shallow;
    shallow.reach["small_110"] = 0.011;
    const Diagnosis part = diagnose(set, c.diagnosable(), shallow, o);
    INFO(part.claim);
    REQUIRE(part.partly_compared.size() == 1);
    CHECK_THAT(part.partly_compared[0],
               Catch::StartsWith("small_110 (") && Catch::EndsWith(" measured bins)"));
    CHECK(part.claim.find("compared in part (no simulated value): small_110") != std::string::npos);
}

TEST_CASE("diagnosis: without a held-out experiment a gap is found but nothing is claimed, and "
          "it says why",
          "[gap][diagnosis]") {
    const EffectCatalogue c = shippedEffects();
    AnalyticSimulator sim;
    const DiagnosisOptions o = analyticOptions({});
    ExperimentSet set = measuredSet({"cohesion", 6.0e4}, 7);
    set.experiments.resize(1); // one plate: nothing to hold out
    const Diagnosis d = diagnose(set, c.diagnosable(), sim, o);
    INFO(d.claim);
    CHECK(d.verdict.gap);
    CHECK(d.held_out.empty());
    CHECK(d.outcome == Diagnosis::Outcome::Unexplained);
    CHECK(d.claim.find("no held-out experiment to test a candidate on") != std::string::npos);
}

TEST_CASE("diagnosis: on a base that its numerical check moves by over half, a gap is located "
          "but no effect is claimed",
          "[gap][diagnosis]") {
    // The hidden cohesion that the analytic test names at 4e4 (above), strong enough here to
    // show beyond a resolution check that moves every curve by 60 %: an effect fitted on such a
    // base may be fitting its numerical error, so the outcome is capped at unexplained.
    const EffectCatalogue c = shippedEffects();
    AnalyticSimulator sim;
    sim.resolution_factor = 1.6;
    const DiagnosisOptions o = analyticOptions();
    const Diagnosis d = diagnose(measuredSet({"cohesion", 1.5e5}, 7), c.diagnosable(), sim, o);
    INFO(d.claim);
    REQUIRE(d.verdict.gap);
    CHECK(d.outcome == Diagnosis::Outcome::Unexplained);
    CHECK(d.explained_by.empty());
    CHECK(d.claim.find("not resolved numerically: its resolution check") != std::string::npos);
    CHECK(d.claim.find("none is claimed") != std::string::npos);
}

TEST_CASE("diagnosis: one held-out experiment is one piece of evidence: located, not claimed",
          "[gap][diagnosis]") {
    // The cohesion that four held-out plates confirm (above), held out on one plate only.
    const Diagnosis d = run({"cohesion", 4.0e4}, 7, {"small_110"});
    INFO(d.claim);
    REQUIRE(d.verdict.gap);
    CHECK(d.outcome == Diagnosis::Outcome::Unexplained);
    CHECK(d.claim.find("one piece of evidence") != std::string::npos);
    CHECK(d.best_model == "cohesion");
}

namespace {
const CandidateResult &candidate(const Diagnosis &d, const std::string &name) {
    for (const CandidateResult &r : d.candidates)
        if (r.name == name)
            return r;
    throw std::logic_error("no candidate " + name);
}
} // namespace

TEST_CASE("diagnosis: a candidate that does not act on the design is neither confirmed nor named "
          "closest",
          "[gap][diagnosis]") {
    // On the CMU wheels (eight beds, --only sensor_zero_offset) a zero offset, which moves a
    // wheel's features by chi^2 0, was confirmed and named closest ("held-out gap 69 % -> 69 %").
    // Here the only candidate changes the plates' pressure by 0.05 % against a hidden cohesion.
    const EffectCatalogue c = shippedEffects();
    Effect faint = c.find("grain_density");
    faint.name = "faint_density";
    faint.prior = {0.999, 1.001, 1.0, false};
    faint.signature = {0.9995, 1.0005};
    AnalyticSimulator sim;
    sim.alias["faint_density"] = "grain_density";
    const Diagnosis d =
        diagnose(measuredSet({"cohesion", 4.0e4}, 7), {&faint}, sim, analyticOptions());
    INFO(d.claim);
    REQUIRE(d.verdict.gap);
    const CandidateResult &r = candidate(d, "faint_density");
    CHECK(r.applicability.empty());
    CHECK(r.signature_chi2 < 1.0);
    CHECK(r.calibration_gain > 0.0); // it leans towards the gap: it used to be confirmed
    CHECK_FALSE(r.confirmed);
    CHECK(d.outcome == Diagnosis::Outcome::Unexplained);
    CHECK(d.best_model.empty());
    CHECK_THAT(d.claim, Catch::Contains("no candidate acts on these experiments"));
}

TEST_CASE("diagnosis: held-out plates that the model presses into the same beds are judged "
          "per plate with those beds' luck measured",
          "[gap][diagnosis]") {
    // The simulator says the plates of a box share their beds (grainlink's packing cache does)
    // and draws them so: the four plates of the small box held out are one group, and two
    // plates of each box two groups; either is judged per plate with the seed jackknife.
    const EffectCatalogue c = shippedEffects();
    AnalyticSimulator sim;
    sim.beds_by_box = true;
    const Diagnosis one =
        diagnose(measuredSet({"cohesion", 4.0e4}, 7), c.diagnosable(), sim,
                 analyticOptions({"small_50", "small_70", "small_90", "small_110"}));
    INFO(one.claim);
    REQUIRE(one.verdict.gap);
    int confirmed = 0;
    for (const CandidateResult &r : one.candidates)
        if (r.confirmed) {
            ++confirmed;
            CHECK(r.versus_null.per_experiment);
            CHECK(r.versus_null.experiments == 4);
            CHECK(r.versus_null.seed_variance > 0.0);
        }
    CHECK(confirmed > 0);
    // The hidden cohesion moves every plate far beyond the beds' luck: claimed all the same.
    CHECK(one.explained_by == "cohesion");
    const Diagnosis two =
        diagnose(measuredSet({"cohesion", 4.0e4}, 7), c.diagnosable(), sim, analyticOptions());
    for (const CandidateResult &r : two.candidates)
        if (r.confirmed) {
            CHECK(r.versus_null.per_experiment);
            CHECK(r.versus_null.experiments == 4);
            CHECK(r.versus_null.seed_variance > 0.0);
            CHECK(r.versus_null.measured_variance > 0.0);
        }
    CHECK(two.explained_by == "cohesion");

    // The same data declared `beds: own` (each plate's trials on beds no other plate used):
    // the measured beds share no luck and the term is zero; the claim stands. (Its p need not
    // fall: the term, of many degrees of freedom, also raised the Welch-Satterthwaite ones,
    // here 2.3e-5 with it against 1.2e-4 without; the rates are AttributionTest's.)
    auto own = measuredSet({"cohesion", 4.0e4}, 7);
    for (Experiment &e : own.experiments)
        e.uncertainty.own_beds = true;
    const Diagnosis apart = diagnose(own, c.diagnosable(), sim, analyticOptions());
    REQUIRE(apart.explained_by == "cohesion");
    const CandidateResult &shared_beds = candidate(two, "cohesion"),
                          &own_beds = candidate(apart, "cohesion");
    CHECK(own_beds.versus_null.measured_variance == 0.0);
    CHECK(own_beds.versus_null.seed_variance == Approx(shared_beds.versus_null.seed_variance));
    CHECK(own_beds.versus_null.p_value < 0.05 / 3.0);
}

namespace {
/// The analytic cohesion twin diagnosed with a second catalogue entry of cohesion's physics
/// whose prior ends at `cap`, below the hidden 4e4 (fitted at 4.02e4 [3.88e4, 4.16e4]).
Diagnosis withCappedCohesion(double cap) {
    EffectCatalogue c = shippedEffects();
    Effect capped = c.find("cohesion");
    capped.name = "cohesion_capped";
    capped.prior.hi = cap;
    capped.signature = {1.5e4, 3.0e4};
    c.effects.push_back(capped);
    AnalyticSimulator sim;
    sim.alias["cohesion_capped"] = "cohesion";
    return diagnose(measuredSet({"cohesion", 4.0e4}, 7), c.diagnosable(), sim, analyticOptions());
}

} // namespace

TEST_CASE("diagnosis: a confirmed model is judged on every held-out bin the base reaches, a bin "
          "its runs miss taken at the base",
          "[gap][diagnosis]") {
    // Judged without the bins it misses, a model gains by missing the bin it predicts worst.
    // The hidden cohesion, confirmed with the held-out plates' first bins unreached: it is
    // scored on as many held-out features as when it reaches them, and those bins count at the
    // base's value (without cohesion), so its held-out gap cannot shrink.
    const EffectCatalogue c = shippedEffects();
    const ExperimentSet set = measuredSet({"cohesion", 4.0e4}, 7);
    AnalyticSimulator whole;
    const Diagnosis reached = diagnose(set, c.diagnosable(), whole, analyticOptions());
    FailingEffectSimulator missing("cohesion", {"large_90", "large_110"}, true, true);
    const Diagnosis d = diagnose(set, c.diagnosable(), missing, analyticOptions());
    const CandidateResult &full = candidate(reached, "cohesion");
    const CandidateResult &part = candidate(d, "cohesion");
    REQUIRE(full.confirmed);
    REQUIRE(part.confirmed);
    CHECK(part.versus_null.features == full.versus_null.features);
    CHECK(part.held_out.gap >= full.held_out.gap);
    CHECK(part.held_out.log_density <= full.held_out.log_density);
}

TEST_CASE("diagnosis: a claim names the rivals that its held-out experiments cannot tell it "
          "from, at their prior's edge too, a better prediction that cannot be claimed leaves "
          "it unexplained",
          "[gap][diagnosis]") {
    // Pinned at its edge the capped entry predicts the held-out plates about as well: never
    // claimed (the edge), it is still a rival the claim must name (on the CMU plates softer
    // grains at the softest allowed predicted the small box as well as grain shape).
    // 3.87e4 predicts a little worse than the truth, 3.99e4 better (the truth's interval, with
    // the beds' luck, spreads its prediction: 3.88e4 predicted better than it too).
    int claimed = 0, blocked = 0;
    for (double cap : {3.87e4, 3.99e4}) {
        const Diagnosis d = withCappedCohesion(cap);
        INFO("cap " << cap << ": " << d.claim);
        const CandidateResult &truth = candidate(d, "cohesion");
        const CandidateResult &edge = candidate(d, "cohesion_capped");
        REQUIRE(truth.explains);
        REQUIRE(edge.confirmed);
        CHECK(edge.fit.at_prior_edge);
        CHECK_FALSE(edge.after.gap);
        if (edge.held_out.log_density < truth.held_out.log_density) {
            // The claimable one predicts best: claimed, the edge named beside it.
            ++claimed;
            REQUIRE(d.explained_by == "cohesion");
            const auto rival = std::find_if(d.rivals.begin(), d.rivals.end(), [](const auto &r) {
                return r.name == "cohesion_capped";
            });
            REQUIRE(rival != d.rivals.end());
            CHECK(rival->at_prior_edge);
            CHECK(rival->p_value >= 0.05);
            CHECK(d.claim.find("do not tell it from cohesion_capped") != std::string::npos);
        } else {
            // The unclaimable one predicts better still: nothing is claimed, both are named.
            ++blocked;
            CHECK(d.outcome == Diagnosis::Outcome::Unexplained);
            CHECK(d.claim.find("cohesion_capped predicts the held-out experiments better still") !=
                  std::string::npos);
            CHECK(std::count(d.indistinguishable.begin(), d.indistinguishable.end(), "cohesion") ==
                  1);
        }
        // A rival the held-out plates do tell apart is named with its p, not as indistinguishable.
        for (const Diagnosis::Rival &r : d.rivals)
            if (r.p_value < 0.05)
                CHECK(std::count(d.indistinguishable.begin(), d.indistinguishable.end(), r.name) ==
                      0);
    }
    CHECK(claimed == 1);
    CHECK(blocked == 1);
}

TEST_CASE("diagnosis: held-out densities are Student's t of the measured repeats' degrees of "
          "freedom",
          "[gap][diagnosis]") {
    // Four trials of each plate (3 dof): the base's held-out log density (its prediction with
    // u_val) is the sum of Student's t densities (Boost's) of Welch-Satterthwaite dof
    // 3 (u_val^2 / u_rep^2)^2, not the normal one's.
    const Diagnosis d = run({"cohesion", 4.0e4});
    REQUIRE(d.held_out.size() > 10);
    double t_sum = 0.0, normal_sum = 0.0;
    for (Eigen::Index k : d.held_out) {
        const double r = d.measured.value[k] - d.validation.simulated[k];
        const double v = d.validation.u_val[k] * d.validation.u_val[k];
        const double u2 = d.measured.u_repeats[k] * d.measured.u_repeats[k];
        REQUIRE(d.measured.trials[k] == 4);
        REQUIRE(u2 > 0.0);
        REQUIRE(d.validation.u_bed[k] == 0.0);
        const double nu = 3.0 * (v / u2) * (v / u2);
        t_sum += std::log(boost::math::pdf(boost::math::students_t(nu), r / std::sqrt(v)) /
                          std::sqrt(v));
        normal_sum += -0.5 * (r * r / v + std::log(2.0 * M_PI * v));
    }
    INFO("t " << t_sum << ", normal " << normal_sum << ", diagnosis "
              << d.held_out_base.log_density);
    CHECK(d.held_out_base.log_density == Approx(t_sum).epsilon(1e-9));
    CHECK(std::abs(t_sum - normal_sum) > 0.5);
}

TEST_CASE("diagnosis: a claim names a rival that leaves no gap without beating the null",
          "[gap][diagnosis]") {
    // cohesion_loose is cohesion's physics whose confirming beds scatter ten times more: its
    // prediction is as right on average and too vague to beat the null. It leaves no gap all the
    // same, so the claim must be put to the test against it and say when the held-out plates cannot
    // tell the two apart (on the full self-test a wrong domain size was claimed where grain
    // stiffness also left no gap, without beating the null).
    EffectCatalogue c = shippedEffects();
    Effect loose = c.find("cohesion");
    loose.name = "cohesion_loose";
    c.effects.push_back(loose);
    AnalyticSimulator sim;
    sim.alias["cohesion_loose"] = "cohesion";
    // 0.132: there (and at 0.13 and 0.135) its p against the null, 0.028, misses the level 0.025
    // while its mean of four beds stays close enough to leave no gap; at 0.125 it beats the null,
    // at 0.138 its mean drifts into a gap (with normal held-out densities, until 2026-12-08, the
    // window was 0.12-0.13: the Student's t densities forgive a vague mean's misses more).
    sim.confirm_scatter_of["cohesion_loose"] = 0.132;
    DiagnosisOptions o = analyticOptions();
    const Diagnosis d = diagnose(measuredSet({"cohesion", 4.0e4}, 7), c.diagnosable(), sim, o);
    INFO(d.claim);
    std::ostringstream table;
    for (const CandidateResult &r : d.candidates)
        table << r.name << " chi2 " << r.fit.chi2 << " s " << r.fit.strength << " confirmed "
              << r.confirmed << " beats " << r.beats_null << " gap " << r.after.gap << " p "
              << r.versus_null.p_value << "\n";
    INFO(table.str());
    REQUIRE(d.explained_by == "cohesion");
    const CandidateResult &rival = candidate(d, "cohesion_loose");
    REQUIRE(rival.confirmed);
    REQUIRE_FALSE(rival.beats_null);
    REQUIRE_FALSE(rival.after.gap);
    const auto named = std::find_if(d.rivals.begin(), d.rivals.end(),
                                    [](const auto &r) { return r.name == "cohesion_loose"; });
    REQUIRE(named != d.rivals.end());
    CHECK_FALSE(named->beats_null);
    // The same physics, only vaguer: the held-out plates cannot prefer the claim over it.
    CHECK(named->p_value >= 0.05);
    CHECK(std::count(d.indistinguishable.begin(), d.indistinguishable.end(), "cohesion_loose") ==
          1);
    CHECK(d.claim.find("do not tell it from cohesion_loose (p = ") != std::string::npos);
    CHECK(d.claim.find("leaves no gap without beating the null") != std::string::npos);
}

TEST_CASE("diagnosis: an effect whose runs failed is not fitted as if it agreed",
          "[gap][diagnosis]") {
    // Every polydispersity run fails on the calibration plates: with their features missing its
    // chi^2 was 0 and it led the candidates. It must be left out, saying why, and the hidden
    // cohesion still named.
    const EffectCatalogue c = shippedEffects();
    FailingEffectSimulator sim("polydispersity", {"large_50", "large_70"});
    const DiagnosisOptions o = analyticOptions();
    const Diagnosis d = diagnose(measuredSet({"cohesion", 4.0e4}, 7), c.diagnosable(), sim, o);
    INFO(d.claim);
    const CandidateResult *poly = nullptr;
    for (const auto &cand : d.candidates)
        if (cand.name == "polydispersity")
            poly = &cand;
    REQUIRE(poly);
    CHECK(poly->applicability.find("signature runs failed") != std::string::npos);
    CHECK(d.outcome == Diagnosis::Outcome::Explained);
    CHECK(d.explained_by == "cohesion");
}

TEST_CASE("diagnosis: an effect whose variants are no valid scenario on this design is not "
          "applicable, said with why, and the diagnosis goes on",
          "[gap][diagnosis]") {
    // One candidate's variants cannot run here (a user's small plates and the wider size
    // distribution's coarser grains): that stopped the whole diagnosis, the dry run included.
    const EffectCatalogue c = shippedEffects();
    RefusingEffectSimulator sim("polydispersity");
    const DiagnosisOptions o = analyticOptions();
    const ExperimentSet set = measuredSet({"cohesion", 4.0e4}, 7);
    const DiagnosisPlan plan = planDiagnosis(set, c.diagnosable(), sim, o);
    const auto refused = std::find_if(plan.inapplicable.begin(), plan.inapplicable.end(),
                                      [](const auto &p) { return p.first == "polydispersity"; });
    REQUIRE(refused != plan.inapplicable.end());
    CHECK_THAT(refused->second,
               Catch::StartsWith("at strength ") && Catch::Contains("no valid scenario here: key "
                                                                    "'bevameter.plate_radii_m'"));
    const Diagnosis d = diagnose(set, c.diagnosable(), sim, o);
    INFO(d.claim);
    CHECK(candidate(d, "polydispersity").applicability == refused->second);
    CHECK(d.outcome == Diagnosis::Outcome::Explained);
    CHECK(d.explained_by == "cohesion");
}

namespace {
/// How many candidates a diagnosis re-simulated at their fitted strength.
int confirmedCount(const Diagnosis &d) {
    int n = 0;
    for (const auto &cand : d.candidates)
        n += cand.confirmed;
    return n;
}
} // namespace

TEST_CASE("diagnosis: a candidate whose confirming runs failed is replaced by the next one",
          "[gap][diagnosis]") {
    // The hidden cohesion leads; its confirming runs fail on a held-out plate. It is not
    // claimed, and one more candidate than otherwise is confirmed in its place.
    const EffectCatalogue c = shippedEffects();
    const DiagnosisOptions o = analyticOptions();
    const ExperimentSet set = measuredSet({"cohesion", 4.0e4}, 7);
    AnalyticSimulator fine;
    const Diagnosis before = diagnose(set, c.diagnosable(), fine, o);
    FailingEffectSimulator failing("cohesion", {"large_90"}, true);
    const Diagnosis d = diagnose(set, c.diagnosable(), failing, o);
    INFO(d.claim);
    CHECK(d.explained_by != "cohesion");
    CHECK(confirmedCount(d) == confirmedCount(before) + 1);
    // The level is divided among the candidates that can be claimed: the failed one takes no
    // share (5 % over 3 before, over 3 again here, not 4).
    REQUIRE(confirmedCount(before) >= 1);
    CHECK(before.single_level == Approx(o.alpha / confirmedCount(before)));
    CHECK(d.single_level == Approx(o.alpha / (confirmedCount(d) - 1)));
}

TEST_CASE("diagnosis: a candidate whose fitted strength is no valid scenario is taken as failed, "
          "not an error that ends the diagnosis",
          "[gap][diagnosis]") {
    // The full self-test's narrow box at a fitted width x 0.71 was narrower than its 25 mm
    // plate: the study refused the confirming run, and the whole self-test stopped. Here the
    // hidden cohesion's signatures run and its confirming runs are refused: it is not claimed,
    // the next candidate is confirmed in its place, and the simulator never runs a refused one.
    const EffectCatalogue c = shippedEffects();
    const ExperimentSet set = measuredSet({"cohesion", 4.0e4}, 7);
    RefusingEffectSimulator refusing("cohesion", true);
    Diagnosis d;
    REQUIRE_NOTHROW(d = diagnose(set, c.diagnosable(), refusing, analyticOptions()));
    INFO(d.claim);
    CHECK(d.explained_by != "cohesion");
    AnalyticSimulator fine;
    const Diagnosis before = diagnose(set, c.diagnosable(), fine, analyticOptions());
    CHECK(confirmedCount(d) == confirmedCount(before) + 1);
    CHECK(d.single_level == Approx(analyticOptions().alpha / (confirmedCount(d) - 1)));
}

TEST_CASE("diagnosis: a fitted strength the design cannot run is confirmed at the nearest that it "
          "can",
          "[gap][diagnosis]") {
    // Boxes narrower than x 0.74 are refused (their plates would not fit), the signatures' x 0.75
    // runs; the hidden x 0.70 is fitted below the edge and confirmed at it, never run where
    // refused (the simulator throws if it is).
    const EffectCatalogue c = shippedEffects();
    const ExperimentSet set = measuredSet({"domain_size", 0.70}, 7);
    RefusingEffectSimulator narrow("domain_size");
    narrow.refuse_below = 0.74;
    Diagnosis d;
    REQUIRE_NOTHROW(d = diagnose(set, c.diagnosable(), narrow, analyticOptions()));
    INFO(d.claim);
    const CandidateResult &box = candidate(d, "domain_size");
    REQUIRE(box.applicability.empty());
    REQUIRE(box.confirmed);
    CHECK(box.fit.strength >= 0.74);
    CHECK(box.fit.strength == Approx(0.74).epsilon(1e-3));
    CHECK(std::isfinite(box.held_out.log_density)); // its runs ran: not taken as failed
}

TEST_CASE("the verdict line names the outcome, the model, its strength and why it is or is not "
          "claimed",
          "[gap][diagnosis][report]") {
    Diagnosis d;
    CHECK(headline(d) == "NO GAP: the base model agrees with the measurements within their "
                         "validation uncertainty");
    // The closest, beating the null but leaving a gap: said so, not "does not beat the null".
    CandidateResult c;
    c.name = "grain_stiffness";
    c.effect.name = "grain_stiffness";
    c.effect.parameter = "stiffness_factor";
    c.effect.unit = "-";
    c.effect.prior.lo = 0.2;
    c.effect.prior.hi = 5.0;
    c.fit.strength = 4.04;
    c.fit.lo = 3.62;
    c.fit.hi = 4.51;
    c.confirmed = true;
    c.held_out.gap = 0.0;
    c.versus_null.p_value = 0.046;
    c.beats_null = true;
    c.strengths_agree = true;
    c.after.gap = true;
    c.after.flagged = 5;
    c.after.features = 115;
    d.outcome = Diagnosis::Outcome::Unexplained;
    d.best_model = "grain_stiffness";
    d.candidates = {c};
    d.held_out_base.gap = 1.16; // 116 %, not 1.2e+02
    d.held_out_null.gap = 0.398;
    d.single_level = 0.05;
    CHECK(headline(d) == "UNEXPLAINED; closest: grain_stiffness, stiffness_factor = 4.04 [3.62, "
                         "4.51]; held-out gap 116 % -> 0 % with it (null model 40 %); p = 0.046 "
                         "against the level 0.05: beats the null model but leaves a gap (5 of "
                         "115 features beyond 2 u_val)");
    // Claimed, with a unit.
    c.effect.parameter = "zero_offset";
    c.effect.unit = "m";
    c.effect.prior.lo = -2.0; // (the strengths are kept from above: only the words matter)
    c.name = c.effect.name = "sensor_zero_offset";
    c.explains = true;
    c.after.gap = false;
    d.candidates = {c};
    d.best_model = d.explained_by = "sensor_zero_offset";
    d.outcome = Diagnosis::Outcome::Explained;
    CHECK(headline(d).rfind("EXPLAINED by sensor_zero_offset, zero_offset = 4.04 [3.62, 4.51] m; "
                            "held-out gap 116 % -> 0 % with it (null model 40 %); p = 0.046 "
                            "against the level 0.05: explains",
                            0) == 0);
    // An interval that ends at the prior's edge is said to.
    d.candidates[0].fit.hi = 5.0;
    CHECK(headline(d).find("zero_offset = 4.04 [3.62, 5] m (its interval cut at the prior's "
                           "edge)") != std::string::npos);
    // A pair: both strengths, in the pair's order (each at the other's best value, not at its
    // single fit), judged at the pair's level, not the singles'.
    CandidateResult w;
    w.name = w.effect.name = "wall_friction";
    w.effect.parameter = "wall_friction";
    w.effect.unit = "-";
    w.effect.prior.lo = 0.0;
    w.effect.prior.hi = 1.0;
    w.fit.strength = 0.9; // its single fit: must not be the one named
    d.candidates = {c, w};
    d.candidates[0].explains = false;
    PairResult p;
    p.a = "sensor_zero_offset";
    p.b = "wall_friction";
    p.fit.a = c.fit;
    p.fit.b.strength = 0.18;
    p.fit.b.lo = 0.1;
    p.fit.b.hi = 0.26;
    p.confirmed = true;
    p.held_out.gap = 0.05;
    p.versus_null.mean_gain = 0.4;
    p.versus_null.p_value = 0.02;
    d.pairs = {p};
    d.pair_level = 0.01;
    d.best_model = "sensor_zero_offset + wall_friction";
    d.explained_by = "";
    d.outcome = Diagnosis::Outcome::Unexplained;
    CHECK(headline(d) == "UNEXPLAINED; closest: the pair sensor_zero_offset + wall_friction, "
                         "zero_offset = 4.04 [3.62, 4.51] m, wall_friction = 0.18 [0.1, 0.26]; "
                         "held-out gap 116 % -> 5 % with it (null model 40 %); p = 0.02 against "
                         "the level 0.01: does not beat the null model");
    d.pairs[0].versus_null.p_value = 0.004;
    d.pairs[0].strengths_agree = false; // beats the null, no gap: the kinds' agreement stops it
    CHECK(headline(d).find("p = 0.004 against the level 0.01: beats the null model but its kinds "
                           "of observable ask for different strengths") != std::string::npos);
    d.pairs[0].strengths_agree = true;
    d.pairs[0].explains = true;
    d.explained_by = d.best_model;
    d.outcome = Diagnosis::Outcome::ExplainedByPair;
    CHECK(headline(d).rfind("EXPLAINED by the pair sensor_zero_offset + wall_friction, "
                            "zero_offset = 4.04 [3.62, 4.51] m, wall_friction = 0.18 [0.1, 0.26]; "
                            "held-out gap 116 % -> 5 % with it (null model 40 %); p = 0.004 "
                            "against the level 0.01: explains",
                            0) == 0);
    // Nothing confirmed.
    d.candidates.clear();
    d.pairs.clear();
    d.best_model = d.explained_by = "";
    d.outcome = Diagnosis::Outcome::Unexplained;
    CHECK(headline(d) == "UNEXPLAINED: no catalogued effect was confirmed against held-out "
                         "experiments");
}

TEST_CASE("when nothing is claimed the closest by held-out gap and the nearest to a claim are "
          "both named",
          "[gap][diagnosis]") {
    // The CMU box split's case: grain stiffness leaves the smaller held-out gap, grain shape is
    // nearer to a claim (smaller p); an unconfirmed candidate with p 0 counts for neither.
    const auto candidate = [](const char *name, bool confirmed, double gap, double p) {
        CandidateResult R;
        R.name = name;
        R.confirmed = confirmed;
        R.held_out.gap = gap;
        R.versus_null.p_value = p;
        R.signature_chi2 = 10.0; // each acts on the design
        return R;
    };
    const std::vector<CandidateResult> candidates{candidate("rig_compliance", true, 1.20, 0.82),
                                                  candidate("grain_stiffness", true, 0.0, 0.14),
                                                  candidate("grain_shape", true, 0.43, 0.017),
                                                  candidate("cohesion", false, 0.0, 0.0)};
    const ClosestCandidates c = closestCandidates(candidates);
    REQUIRE(c.by_gap != nullptr);
    REQUIRE(c.by_p_value != nullptr);
    CHECK(c.by_gap->name == "grain_stiffness");
    CHECK(c.by_p_value->name == "grain_shape");
    const ClosestCandidates none = closestCandidates({candidate("cohesion", false, 0.0, 0.0)});
    CHECK(none.by_gap == nullptr);
    CHECK(none.by_p_value == nullptr);
    // With no evidence at all (p = 1: one group of beds held out) or no prediction somewhere
    // (its confirming runs failed: an infinite gap) nothing is nearer to a claim than another.
    const std::vector<CandidateResult> without{
        candidate("grain_stiffness", true, 0.3, 1.0),
        candidate("polydispersity", true, std::numeric_limits<double>::infinity(), 0.5)};
    const ClosestCandidates no_evidence = closestCandidates(without);
    CHECK(no_evidence.by_gap->name == "grain_stiffness");
    CHECK(no_evidence.by_p_value == nullptr);
    // Two leave no gap at all: the sharper held-out prediction is the closest, whichever the
    // calibration ranked first (the plates self-test's domain-size twin).
    std::vector<CandidateResult> tied{candidate("grain_stiffness", true, 0.0, 0.047),
                                      candidate("domain_size", true, 0.0, 0.072)};
    tied[0].held_out.log_density = -270.7;
    tied[1].held_out.log_density = -263.9;
    CHECK(closestCandidates(tied).by_gap->name == "domain_size");
    // No held-out experiment (one mole experiment; every held-out gap 0): the best calibration
    // fit, even where its confirming runs failed (the hull's friction that let the mole through
    // the column's floor), not the first with a gap of 0 (grain density, at its prior's edge).
    std::vector<CandidateResult> calibration_only{
        candidate("grain_density", true, 0.0, 1.0),
        candidate("tool_friction", true, std::numeric_limits<double>::infinity(), 1.0),
        candidate("cohesion", false, 0.0, 1.0)};
    for (auto &[R, chi2] :
         {std::pair{&calibration_only[0], 14.6}, std::pair{&calibration_only[1], 1.22},
          std::pair{&calibration_only[2], 260.1}}) {
        R->fit.chi2 = chi2;
        R->fit.features = 8;
    }
    const ClosestCandidates by_fit = closestCandidates(calibration_only, false);
    REQUIRE(by_fit.by_gap != nullptr);
    CHECK(by_fit.by_gap->name == "tool_friction");
    CHECK(by_fit.by_p_value == nullptr);
    CHECK(closestCandidates(calibration_only).by_gap->name == "grain_density");
}

TEST_CASE("the default held-out experiments: the last box, else the last half of a type, "
          "widened to two where one would be all",
          "[gap][diagnosis]") {
    const auto set = [](int plates, bool boxes) {
        ExperimentSet s;
        for (int i = 0; i < plates; ++i) {
            Experiment e;
            e.id = "p" + std::to_string(i);
            e.type = ExperimentType::PlateSinkage;
            if (boxes)
                e.labels["box"] = i < 2 ? "large" : "small";
            s.experiments.push_back(e);
        }
        Experiment shear;
        shear.id = "shear";
        shear.type = ExperimentType::DirectShear;
        s.experiments.push_back(shear); // alone of its type: calibration only
        return s;
    };
    CHECK(defaultHeldOut(set(4, false)) == std::vector<std::string>{"p2", "p3"});
    CHECK(defaultHeldOut(set(5, false)) == std::vector<std::string>{"p3", "p4"});
    // Three plates: the last half rounded down would hold out one, which can carry no claim.
    CHECK(defaultHeldOut(set(3, false)) == std::vector<std::string>{"p1", "p2"});
    CHECK(defaultHeldOut(set(2, false)) == std::vector<std::string>{"p1"}); // as much as it can
    CHECK(defaultHeldOut(set(1, false)).empty());
    CHECK(defaultHeldOut(set(5, true)) == std::vector<std::string>{"p2", "p3", "p4"});
    // Two boxes, the last with one plate: the fuller box is held out instead.
    CHECK(defaultHeldOut(set(3, true)) == std::vector<std::string>{"p0", "p1"});
    // What the split leaves thin is said: plates calibrated on one, three held out (the
    // LIGGGHTS design's 1 + 3); the shear box alone of its type is calibration, not thin.
    const std::vector<std::string> thin = splitNotes(set(4, false), {"p1", "p2", "p3"});
    REQUIRE(thin.size() == 1);
    CHECK(thin[0] == "plate_sinkage is calibrated on one experiment (p0) and held out on 3: its "
                     "fitted strengths rest on that one (--hold-out to choose)");
    CHECK(splitNotes(set(4, false), defaultHeldOut(set(4, false))).empty());
}

TEST_CASE("the self-test scores each twin against its key: claims, weak twins, nulls, effects "
          "outside the catalogue, and the hidden effect named without a claim",
          "[gap][selftest]") {
    // Hand-built diagnoses, each scored against the rule in docs/gap.md ("The self-test").
    Effect stiff, crust;
    stiff.name = "grain_stiffness";
    crust.name = "crust";
    crust.in_catalogue = false;
    const auto candidate = [](const std::string &name, double strength, bool explains) {
        CandidateResult c;
        c.name = name;
        c.fit.strength = strength;
        c.explains = explains;
        c.held_out.gap = explains ? 0.1 : 0.5;
        return c;
    };
    const auto twin = [](const std::string &effect, double strength, bool weak,
                         Diagnosis::Outcome outcome, const std::string &claimed) {
        SelftestTwin t;
        t.key.effect = effect;
        t.key.strength = strength;
        t.key.in_catalogue = effect != "crust";
        t.weak = weak;
        t.outcome = outcome;
        t.claimed = claimed;
        return t;
    };
    SelftestResult R;
    using O = Diagnosis::Outcome;

    Diagnosis claimed; // claimed right, strength 10 % off
    claimed.outcome = O::Explained;
    claimed.held_out_base.gap = 1.0;
    claimed.candidates = {candidate("grain_stiffness", 3.3, true)};
    SelftestTwin a = twin("grain_stiffness", 3.0, false, O::Explained, "grain_stiffness");
    scoreTwin(claimed, &stiff, a, R);
    CHECK(a.correct);
    CHECK(a.strength_within_25);
    CHECK(a.reduction_pct == Approx(90.0));

    Diagnosis closest; // unexplained, the hidden effect closest, 10 % off
    closest.outcome = O::Unexplained;
    closest.best_model = "grain_stiffness";
    closest.candidates = {candidate("grain_stiffness", 2.7, false),
                          candidate("cohesion", 1e5, false)};
    SelftestTwin b = twin("grain_stiffness", 3.0, false, O::Unexplained, "");
    scoreTwin(closest, &stiff, b, R);
    CHECK_FALSE(b.correct);
    CHECK(b.named);

    Diagnosis nearest; // unexplained, another closest, the hidden one nearest to a claim, 2x off
    nearest.outcome = O::Unexplained;
    nearest.best_model = "cohesion";
    nearest.nearest_to_claim = "grain_stiffness";
    nearest.candidates = {candidate("cohesion", 1e5, false),
                          candidate("grain_stiffness", 6.0, false)};
    SelftestTwin c = twin("grain_stiffness", 3.0, false, O::Unexplained, "");
    scoreTwin(nearest, &stiff, c, R);
    CHECK(c.named);

    Diagnosis wrong; // another effect closest, the hidden one not named
    wrong.outcome = O::Unexplained;
    wrong.best_model = "cohesion";
    wrong.candidates = {candidate("cohesion", 1e5, false),
                        candidate("grain_stiffness", 3.0, false)};
    SelftestTwin d = twin("grain_stiffness", 3.0, false, O::Unexplained, "");
    scoreTwin(wrong, &stiff, d, R);
    CHECK_FALSE(d.named);

    Diagnosis nogap; // a weak twin is right only as "no gap"
    nogap.outcome = O::NoGap;
    SelftestTwin e = twin("grain_stiffness", 1.1, true, O::NoGap, "");
    scoreTwin(nogap, &stiff, e, R);
    CHECK(e.correct);

    Diagnosis false_claim; // a null twin with a claim
    false_claim.outcome = O::Explained;
    SelftestTwin f = twin("", 0.0, false, O::Explained, "cohesion");
    scoreTwin(false_claim, nullptr, f, R);
    CHECK_FALSE(f.correct);

    Diagnosis ooc; // outside the catalogue, strong: right only as "unexplained"
    ooc.outcome = O::Unexplained;
    SelftestTwin g = twin("crust", 20.0, false, O::Unexplained, "");
    scoreTwin(ooc, &crust, g, R);
    CHECK(g.correct);

    CHECK(R.top1 == 2);
    CHECK(R.top1_of == 5);
    CHECK(R.weak == 1);
    CHECK(R.strength_ok == 1);
    CHECK(R.strength_of == 1);
    CHECK(R.null_false == 1);
    CHECK(R.nulls == 1);
    CHECK(R.ooc_unexplained == 1);
    CHECK(R.oocs == 1);
    CHECK(R.named_of == 3);
    CHECK(R.named == 2);
    CHECK(R.named_strength_ok == 1);
}

namespace fs = std::filesystem;

TEST_CASE("selftest: a plan with an unknown strength draw or a held-out id the design lacks is "
          "refused, naming the file, the key and the line, before anything runs",
          "[gap][selftest]") {
    // {plan text, its key, what the message suggests}
    const auto [text, key, hint] = GENERATE(table<std::string, std::string, std::string>(
        {{"nulls: 1\nstrengths: wide\n", "strengths", "far_half"},
         {"nulls: 1\nhold_out: [wide_d20, wide_d25]\n", "hold_out",
          "no experiment of the design"}}));
    const fs::path dir = fs::temp_directory_path() / ("grainlink-plan-" + std::to_string(getpid()));
    fs::create_directories(dir);
    const fs::path plan = dir / "selftest.yaml";
    std::ofstream(plan) << text;
    SelftestOptions o;
    const std::string ci = GRAINLINK_SOURCE_DIR "/scenarios/gap/selftest-ci";
    o.base_model = ci + "/base.yaml";
    o.design = ci + "/design.yaml";
    o.plan = plan.string();
    o.out = (dir / "out").string();
    o.catalogue = shippedEffects();
    try {
        runSelftest(o);
        FAIL("the plan was accepted: " << text);
    } catch (const std::exception &e) {
        const std::string what = e.what();
        INFO(what);
        CHECK(what.find(plan.string()) != std::string::npos);
        CHECK(what.find(key) != std::string::npos);
        CHECK(what.find(plan.string() + ":2:") != std::string::npos); // file:line
        CHECK(what.find(hint) != std::string::npos);
    }
    CHECK_FALSE(fs::exists(dir / "out" / "twins"));
    fs::remove_all(dir);
}

TEST_CASE("the separating experiment: a probe's features scored by how far the candidates' "
          "means lie apart in the probe's own scatter",
          "[gap][diagnosis]") {
    // Base, A and B on two seeds each. Feature 0 scatters by +-1 in every model (pooled
    // variance (2 + 2 + 2) / 3 = 2, a two-seed mean's 1): A and B lie 10 apart, chi^2
    // 10^2 / (1 + 1 + 1). Feature 1 differs (5 against 6) but never scatters: nothing says
    // how far apart that is, and it counts nothing.
    Eigen::MatrixXd base(2, 2), a(2, 2), b(2, 2);
    base << 10, 5, 12, 5;
    a << 20, 5, 22, 5;
    b << 10, 6, 12, 6;
    const ProbeSeparation p = probeSeparation({base, a, b});
    CHECK(p.chi2[0] == Approx(100.0 / 3.0).epsilon(1e-12));
    CHECK(p.chi2[1] == 0.0);
    CHECK(p.mean[1][0] == Approx(21.0));
    CHECK(p.sd[1][0] == Approx(1.0).epsilon(1e-12));
    // One seed each: no scatter is known, so no separation either.
    const ProbeSeparation one = probeSeparation({base.topRows(1), a.topRows(1), b.topRows(1)});
    CHECK(one.chi2.sum() == 0.0);
}

TEST_CASE("diagnosis: no pair is tried where a single effect within its prior leaves no gap "
          "without beating the null",
          "[gap][diagnosis]") {
    // The hidden cohesion's confirming beds scatter so much that it misses the level while its
    // mean leaves no gap: the held-out plates lack the power, not the single effect the
    // explanation. A pair would add an effect that nothing asks for (on the full self-test's
    // powered design a hidden grain stiffness, p = 0.066, was claimed as stiffness + wall
    // friction); the outcome is unexplained, the single named closest. Two plates held out (p =
    // 0.069 against 0.05; a gap at 0.135, the level beaten at 0.115): with four, since the
    // held-out densities are Student's t (2026-12-08), no scatter leaves the mean without a gap
    // and short of the level.
    const EffectCatalogue c = shippedEffects();
    AnalyticSimulator sim;
    sim.confirm_scatter_of["cohesion"] = 0.125;
    const Diagnosis d = diagnose(measuredSet({"cohesion", 4.0e4}, 7), c.diagnosable(), sim,
                                 analyticOptions({"large_110", "small_110"}));
    INFO(d.claim);
    const CandidateResult &single = candidate(d, "cohesion");
    REQUIRE(single.confirmed);
    REQUIRE_FALSE(single.beats_null);
    REQUIRE_FALSE(single.after.gap);
    REQUIRE_FALSE(single.fit.at_prior_edge);
    CHECK(d.pairs.empty());
    CHECK(d.outcome == Diagnosis::Outcome::Unexplained);
    CHECK(d.best_model == "cohesion");
}

TEST_CASE("diagnosis: a fitted strength's interval carries the measured trials' luck and holds "
          "the hidden strength",
          "[gap][diagnosis]") {
    // Every measured trial is a bed of its own (level and tilt); the simulated side's seeds are
    // beds too. The luck both carry is in the interval, and it grows with the trials' scatter.
    const EffectCatalogue c = shippedEffects();
    const auto fitOf = [&](const std::string &effect, const ExperimentSet &set) {
        AnalyticSimulator sim;
        const std::vector<const Effect *> only{&c.find(effect)};
        return candidate(diagnose(set, only, sim, analyticOptions()), effect).fit;
    };
    ExperimentSet set = measuredSet({"cohesion", 4.0e4}, 7);
    const StrengthFit fit = fitOf("cohesion", set);
    CHECK(fit.luck_sd > 0.0);
    // The same trials three times as far from their mean, bin by bin: more luck.
    for (Experiment &e : set.experiments) {
        std::vector<double> mean(e.trials.front().curves.at("pressure_Pa").y.size(), 0.0);
        for (const Trial &t : e.trials)
            for (std::size_t i = 0; i < mean.size(); ++i)
                mean[i] += t.curves.at("pressure_Pa").y[i] / double(e.trials.size());
        for (Trial &t : e.trials)
            for (std::size_t i = 0; i < mean.size(); ++i) {
                double &y = t.curves.at("pressure_Pa").y[i];
                y = mean[i] + 3.0 * (y - mean[i]);
            }
    }
    const StrengthFit wider = fitOf("cohesion", set);
    CHECK(wider.luck_sd > 1.5 * fit.luck_sd);
    CHECK(wider.hi - wider.lo > fit.hi - fit.lo);
    // Over 30 measured draws of each (the simulated beds fixed: their luck is one draw), the
    // interval holds the hidden strength (measured 25/30 and 30/30).
    int held = 0;
    for (const auto &[effect, s] :
         {std::pair<std::string, double>{"cohesion", 4.0e4}, {"grain_stiffness", 3.0}})
        for (unsigned seed = 1; seed <= 30; ++seed) {
            const StrengthFit f = fitOf(effect, measuredSet({effect, s}, seed));
            held += f.lo <= s && s <= f.hi;
        }
    CHECK(held >= 50);
}

namespace {

/// The analytic plates and a heap, measured three times (2 % scatter from heap to heap).
ExperimentSet withHeap(const Truth &t, unsigned seed) {
    ExperimentSet set = measuredSet(t, seed);
    std::mt19937 rng(seed + 100);
    std::normal_distribution<double> z01;
    Experiment e;
    e.id = "repose";
    e.type = ExperimentType::AngleOfRepose;
    e.x_name = ""; // a scalar
    e.observables = {"angle_deg"};
    e.labels["box"] = "large";
    for (int r = 0; r < 3; ++r) {
        Trial tr;
        tr.curves["angle_deg"] =
            Curve{{0.0}, {(t.heap_deg > 0.0 ? t.heap_deg : angle(t)) * (1.0 + 0.02 * z01(rng))}};
        e.trials.push_back(tr);
    }
    set.experiments.push_back(e);
    return set;
}

} // namespace

TEST_CASE("diagnosis: an effect whose kinds of observable ask for different strengths of it is "
          "not claimed",
          "[gap][diagnosis][mismatch]") {
    // Denser grains (x 1.5) raise the analytic plates' pressure 1.5 times and, in the model, the
    // heap's angle from 30 to 45 deg. Where the measuring world's heap follows that law the plates
    // and the heap ask for one density (the hidden 1.5) and it is claimed. Where its heap stands
    // at 41 deg (another code's law: 41 / 30 = x 1.37 by the model's), the fit on plates and heap
    // together still beats the null and leaves no gap (|z| of the heap below the bound), so
    // without the agreement test it is claimed; the plates (x 1.5) and the heap (x 1.37) disagree
    // at p < 0.01, and the density absorbs a difference of model form: not claimed.
    const EffectCatalogue c = shippedEffects();
    const auto diagnoseWith = [&](double heap_deg, double level) {
        AnalyticSimulator sim;
        DiagnosisOptions o = analyticOptions();
        o.agreement_level = level;
        Truth t{"grain_density", 1.5};
        t.heap_deg = heap_deg;
        return diagnose(withHeap(t, 7), c.diagnosable(), sim, o);
    };
    const auto density = [](const Diagnosis &d) {
        for (const CandidateResult &r : d.candidates)
            if (r.name == "grain_density")
                return r;
        FAIL("grain_density was not a candidate");
        return CandidateResult{};
    };
    const auto kindStrength = [](const CandidateResult &r, const std::string &kind) {
        for (const auto &[k, fit] : r.by_kind)
            if (k == kind)
                return fit.strength;
        FAIL("no strength for " << kind);
        return 0.0;
    };

    const Diagnosis agree = diagnoseWith(0.0, 0.01);
    INFO(agree.claim);
    CHECK(agree.outcome == Diagnosis::Outcome::Explained);
    CHECK(agree.explained_by == "grain_density");
    const CandidateResult one = density(agree);
    CHECK(one.agreement.dof == 1);
    CHECK(one.agreement.p_value >= 0.01);
    CHECK(kindStrength(one, "plate_sinkage/pressure_Pa") == Approx(1.5).epsilon(0.05));
    CHECK(kindStrength(one, "angle_of_repose/angle_deg") == Approx(1.5).epsilon(0.05));

    const Diagnosis unchecked = diagnoseWith(41.0, 0.0);
    INFO(unchecked.claim);
    CHECK(unchecked.outcome == Diagnosis::Outcome::Explained);

    const Diagnosis torn = diagnoseWith(41.0, 0.01);
    INFO(torn.claim);
    CHECK(torn.outcome == Diagnosis::Outcome::Unexplained);
    CHECK_THAT(torn.claim, Catch::Contains("grain_density") &&
                               Catch::Contains("the kinds of observable ask for different "
                                               "strengths of it") &&
                               Catch::Contains("absorbs a difference of model form"));
    const CandidateResult two = density(torn);
    CHECK_FALSE(two.strengths_agree);
    CHECK(two.agreement.p_value < 0.01);
    CHECK(kindStrength(two, "plate_sinkage/pressure_Pa") == Approx(1.5).epsilon(0.05));
    CHECK(kindStrength(two, "angle_of_repose/angle_deg") == Approx(41.0 / 30.0).epsilon(0.05));
}

TEST_CASE("selftest: a drawn strength whose twin cannot be simulated is drawn again from its "
          "prior cut at it, each failed try said, and left out only after the last",
          "[gap][selftest]") {
    // The full self-test's soft surface layer: drawn from the far half of its prior (0.1-1, off
    // at 1), its twins below about 0.3 pressed the soft base's grains past the overlap limit.
    const Effect &layer = shippedEffects().find("soft_surface_layer");
    const auto draw = [&](int k, const std::vector<double> &failed) -> std::optional<double> {
        // the full self-test's seed 1 (twin 12: seed 100 + 12)
        return drawStrength(layer, 112u + 100003u * unsigned(k), StrengthDraw::FarHalf, failed);
    };
    std::vector<double> tried;
    const auto make = [&](double below) {
        return [&tried, below](std::optional<double> s) {
            tried.push_back(*s);
            if (*s < below)
                throw std::runtime_error("twin: no repeat of experiment 'wide_d20' was simulated");
            TwinKey key;
            key.effect = "soft_surface_layer";
            key.strength = *s;
            return key;
        };
    };
    std::vector<std::string> failures;
    SECTION("made at the first strength that can be simulated, each try nearer off") {
        // Below 0.3 nothing is made (on the full self-test's base 0.283 failed, 0.4 ran). The
        // first draw is the far half's own (0.1 to 10^-0.5); each after a failure lies between
        // it and off, so the tries climb towards the runnable strengths.
        const std::optional<TwinKey> made =
            drawUntilMade(draw, make(0.3), kStrengthDraws, failures);
        REQUIRE(made);
        // as on 2026-12-07: 0.161, 0.177 and 0.284 failed on the base, 0.502 was made
        REQUIRE(tried.size() == 4);
        CHECK(tried[0] == Approx(0.160637).epsilon(1e-5));
        CHECK(tried[3] == Approx(0.502011).epsilon(1e-5));
        CHECK(made->strength == tried.back());
        CHECK(made->strength >= 0.3);
        CHECK(tried.front() >= 0.1);
        CHECK(tried.front() <= std::pow(10.0, -0.5) + 1e-12);
        REQUIRE(failures.size() == tried.size() - 1);
        REQUIRE_FALSE(failures.empty()); // the first draw, below 0.3, failed
        for (std::size_t i = 0; i < failures.size(); ++i) {
            CHECK_THAT(failures[i], Catch::StartsWith(" at 0.") &&
                                        Catch::Contains("no repeat of experiment 'wide_d20'"));
            CHECK(tried[i] < 0.3);
            CHECK(tried[i + 1] > tried[i]);
            // the far half of what is left, [failed, sqrt(failed)] on the log scale
            CHECK(tried[i + 1] <= std::sqrt(tried[i]) * (1 + 1e-12));
        }
    }
    SECTION("left out, every try said, when none can be simulated") {
        CHECK_FALSE(drawUntilMade(draw, make(1.0), kStrengthDraws, failures));
        CHECK(tried.size() == std::size_t(kStrengthDraws));
        CHECK(failures.size() == std::size_t(kStrengthDraws));
        for (std::size_t i = 1; i < tried.size(); ++i)
            CHECK(tried[i] > tried[i - 1]);
    }
    SECTION("a strength given by the plan (out of the catalogue) is tried once") {
        const auto given = [](int, const std::vector<double> &) -> std::optional<double> {
            return 0.15;
        };
        CHECK_FALSE(drawUntilMade(given, make(0.2), 1, failures));
        CHECK(tried == std::vector<double>{0.15});
        REQUIRE(failures.size() == 1);
        CHECK_THAT(failures[0], Catch::StartsWith(" at 0.15: twin: no repeat"));
    }
}

TEST_CASE("a claim goes to the best held-out prediction among the models that leave no gap, "
          "singles and pairs alike, and only if that one explains",
          "[gap][diagnosis]") {
    // Until 2026-12-07 a pair was claimed as the best of the pairs that explain, while a single
    // had to be the best of those that leave no gap: a better pair that missed the level did
    // not stop a worse one from being claimed.
    std::vector<PairResult> pairs(3);
    for (PairResult &p : pairs)
        p.confirmed = true;
    pairs[0].held_out.log_density = -10.0; // explains
    pairs[0].explains = true;
    pairs[1].held_out.log_density = -5.0; // predicts better, short of the level
    pairs[2].held_out.log_density = 0.0;  // best of all, but leaves a gap
    pairs[2].after.gap = true;
    CHECK(bestWithoutGap(pairs) == &pairs[1]); // not claimable: nothing is claimed
    pairs[1].after.gap = true;
    CHECK(bestWithoutGap(pairs) == &pairs[0]);
    pairs[0].confirmed = false; // its runs never ran
    CHECK(bestWithoutGap(pairs) == nullptr);

    std::vector<CandidateResult> singles(2);
    for (CandidateResult &c : singles)
        c.confirmed = true;
    singles[0].held_out.log_density = -3.0;
    singles[1].held_out.log_density = -std::numeric_limits<double>::infinity(); // runs failed
    CHECK(bestWithoutGap(singles) == &singles[0]);
}

namespace {

/// The shipped catalogue with cohesion's physics under a second name, `cohesion_twin`, tabulated
/// at `signature` (other table points: not the very same fit); `sim` runs it as cohesion.
EffectCatalogue withCohesionTwin(std::vector<double> signature, AnalyticSimulator &sim) {
    EffectCatalogue c = shippedEffects();
    Effect twin = c.find("cohesion");
    twin.name = "cohesion_twin";
    twin.signature = std::move(signature);
    c.effects.push_back(twin);
    sim.alias["cohesion_twin"] = "cohesion";
    return c;
}

} // namespace

TEST_CASE("diagnosis: two effects that each explain and that the held-out experiments cannot tell "
          "apart are both named, and neither is claimed",
          "[gap][diagnosis]") {
    // cohesion_twin is cohesion's physics under another name: it passes every test cohesion
    // passes. Claiming the one that predicts a little better would be a coin's toss between
    // them; until 2026-12-07 it was claimed, the other named beside it.
    AnalyticSimulator sim;
    const EffectCatalogue c = withCohesionTwin({1.2e4, 2.5e4}, sim);
    const Diagnosis d =
        diagnose(measuredSet({"cohesion", 4.0e4}, 7), c.diagnosable(), sim, analyticOptions());
    INFO(d.claim);
    REQUIRE(candidate(d, "cohesion").explains);
    REQUIRE(candidate(d, "cohesion_twin").explains);
    CHECK(d.outcome == Diagnosis::Outcome::Unexplained);
    CHECK(d.explained_by.empty());
    CHECK_THAT(d.claim, Catch::Contains("each beat the null model and leave no gap, and these "
                                        "experiments do not tell them apart"));
    CHECK(d.indistinguishable.size() == 1);
    CHECK((d.best_model == "cohesion" || d.best_model == "cohesion_twin"));
}

/// Diagnoses the analytic worlds with `effect` hidden beside a sensor zero offset, each of
/// `worlds` (its strength, the offset) on three measured draws; checks that no single is
/// claimed and that a pair claimed is `effect` + the offset, its strength within `tolerance`
/// and the offset within 10 %. Returns how many were claimed.
int claimedWithOffset(const std::string &effect,
                      const std::vector<std::pair<double, double>> &worlds, double tolerance) {
    int explained = 0;
    for (unsigned seed : {7u, 1u, 2u})
        for (const auto &[strength, offset] : worlds) {
            Truth t{effect, strength};
            t.zero_offset_m = offset;
            const Diagnosis d = run(t, seed);
            INFO("seed " << seed << ", " << effect << " " << strength << ", offset " << offset
                         << ": " << d.claim);
            CHECK(d.outcome != Diagnosis::Outcome::Explained); // no single is the cause
            if (d.outcome != Diagnosis::Outcome::ExplainedByPair)
                continue;
            ++explained;
            const PairResult *pair = nullptr;
            for (const PairResult &p : d.pairs)
                if (p.a + " + " + p.b == d.best_model)
                    pair = &p;
            REQUIRE(pair);
            const bool effect_first = pair->a == effect;
            const StrengthFit &e = effect_first ? pair->fit.a : pair->fit.b,
                              &z = effect_first ? pair->fit.b : pair->fit.a;
            CHECK((effect_first ? pair->b : pair->a) == "sensor_zero_offset");
            CHECK(e.strength == Approx(strength).epsilon(tolerance));
            CHECK(z.strength == Approx(offset).epsilon(0.10));
        }
    return explained;
}

TEST_CASE("diagnosis: a hidden effect of the soil with a sensor zero offset is explained by the "
          "pair at both strengths",
          "[gap][diagnosis]") {
    // No single effect explains a cohesion whose curves a zero offset also shifts. The pair's
    // fit reads the offset on cohesion's own runs (`ChainOnEffectResponse`): with their changes
    // added instead it claimed 2 of these 12 worlds, both strengths 18-25 % low, and left a gap
    // on the rest (offsets fitted down to a quarter of the hidden one). Measured here: 10 of 12,
    // every strength within 6 %.
    const int explained = claimedWithOffset(
        "cohesion", {{4.0e4, 0.001}, {8.0e4, 0.001}, {8.0e4, 0.0015}, {4.0e4, 0.0015}}, 0.10);
    // The other two: the right pair, short of the pairs' level.
    CHECK(explained >= 9);
}

TEST_CASE("diagnosis: a rig compliance with a sensor zero offset is explained by the pair at "
          "both strengths",
          "[gap][diagnosis][chainpair]") {
    // Two effects of the measuring chain: each moves the sinkage axis of whatever curve the
    // soil gives, the offset by a constant, the rig by its deflection under the force. Alone,
    // the compliance fitted a tenth of its strength beside the offset and ranked fifth among
    // the singles, out of the pairs' pool: offset + domain size was claimed in 8 of these 12
    // worlds (p down to 1e-7) and the rest left unexplained. With the leader paired with every
    // effect, and the compliance read on the offset's reads, measured: 10 of 12 claimed, the
    // other two the right pair not told apart from offset + domain size (p = 0.13, 0.14). The
    // compliance is within 35 %: fitted alone on these draws it misses by up to 32 % (1.98e-5
    // [1.56e-5, 2.42e-5] for 1.5e-5 on seed 2, the draw's tilt), the offset within 10 %.
    const int explained = claimedWithOffset(
        "rig_compliance", {{1.5e-5, 0.001}, {3.0e-5, 0.001}, {3.0e-5, 0.0015}, {1.5e-5, 0.0015}},
        0.35);
    CHECK(explained >= 9);
}

TEST_CASE("diagnosis counts each run it asks for once: the measuring chain's variants read runs "
          "already asked for",
          "[gap][diagnosis]") {
    // A cohesion with a zero offset goes through every step that asks for runs: the base and
    // its check, the signatures (the offset's and the compliance's read the base's runs), the
    // confirmations, the chain read on cohesion's runs and the pairs' confirmations.
    AnalyticSimulator sim;
    sim.names_runs = true;
    const EffectCatalogue c = shippedEffects();
    Truth t{"cohesion", 8.0e4};
    t.zero_offset_m = 0.001;
    const Diagnosis d = diagnose(measuredSet(t, 7), c.diagnosable(), sim, analyticOptions());
    INFO(d.claim);
    REQUIRE_FALSE(d.pairs.empty());
    CHECK(d.simulations == int(sim.made.size()));
    CHECK(d.simulations + d.reads == sim.asked);
    // At least each measuring-chain signature: two effects, their strengths, three seeds.
    int chain_signatures = 0;
    for (const Effect *e : c.diagnosable())
        if (e->kind == Effect::Kind::Measurement)
            chain_signatures += int(e->signature.size()) * analyticOptions().signature_seeds;
    CHECK(d.reads >= chain_signatures);
}

TEST_CASE("diagnosis: two pairs that each explain and that the held-out experiments cannot tell "
          "apart are both named, and neither is claimed",
          "[gap][diagnosis]") {
    // cohesion_twin is cohesion's physics under another name: with the zero offset, each pair
    // passes every test the other passes. As for two singles, claiming the one that predicts a
    // little better would be a coin's toss.
    AnalyticSimulator sim;
    const EffectCatalogue c = withCohesionTwin({1.2e5, 2.5e5}, sim);
    Truth t{"cohesion", 8.0e4};
    t.zero_offset_m = 0.001;
    const Diagnosis d = diagnose(measuredSet(t, 7), c.diagnosable(), sim, analyticOptions());
    INFO(d.claim);
    int explaining = 0;
    for (const PairResult &p : d.pairs)
        if (p.explains) {
            ++explaining;
            UNSCOPED_INFO(p.a << " + " << p.b << " p " << p.versus_null.p_value << " best over it "
                              << p.best_over_it_p);
        }
    REQUIRE(explaining == 2);
    CHECK(d.outcome == Diagnosis::Outcome::Unexplained);
    CHECK_THAT(d.claim, Catch::Contains("each beat the null model and leave no gap, and these "
                                        "experiments do not tell them apart"));
    CHECK_THAT(d.claim, Catch::Contains("cohesion_twin + sensor_zero_offset"));
    int compared = 0;
    for (const PairResult &p : d.pairs)
        compared += std::isfinite(p.best_over_it_p);
    CHECK(compared == 1);
}

TEST_CASE("diagnosis: a pair whose kinds of observable ask for different strengths of one of its "
          "effects is not claimed",
          "[gap][diagnosis][mismatch]") {
    // The singles' test with a 1 mm zero offset on the plates as well: no single explains, the
    // pair denser grains + offset does. Where the measuring world's heap stands at 41 deg, not
    // at the model law's 45, the plates ask for density x 1.5 and the heap for x 1.37 with the
    // offset held: without the kinds' agreement the pair was claimed (measured p = 0.002 and
    // 2e-5 against the null on seeds 7 and 1), with it not.
    const EffectCatalogue c = shippedEffects();
    const auto diagnoseWith = [&](double heap_deg, double level, unsigned seed) {
        AnalyticSimulator sim;
        DiagnosisOptions o = analyticOptions();
        o.agreement_level = level;
        Truth t{"grain_density", 1.5};
        t.heap_deg = heap_deg;
        t.zero_offset_m = 0.001;
        return diagnose(withHeap(t, seed), c.diagnosable(), sim, o);
    };
    const auto density = [](const PairResult &p) {
        return p.a == "grain_density" ? p.fit.a.strength : p.fit.b.strength;
    };
    for (unsigned seed : {7u, 1u}) {
        const Diagnosis agree = diagnoseWith(0.0, 0.01, seed);
        INFO("seed " << seed << ", the model's heap: " << agree.claim);
        REQUIRE(agree.outcome == Diagnosis::Outcome::ExplainedByPair);
        const PairResult &claimed = agree.pairs.front().explains ? agree.pairs[0] : agree.pairs[1];
        CHECK(agree.best_model == claimed.a + " + " + claimed.b);
        CHECK(density(claimed) == Approx(1.5).epsilon(0.05));
        CHECK(claimed.strengths_agree);

        const Diagnosis unchecked = diagnoseWith(41.0, 0.0, seed);
        INFO("seed " << seed << ", a heap at 41 deg, unchecked: " << unchecked.claim);
        CHECK(unchecked.outcome == Diagnosis::Outcome::ExplainedByPair);

        const Diagnosis torn = diagnoseWith(41.0, 0.01, seed);
        INFO("seed " << seed << ", a heap at 41 deg: " << torn.claim);
        CHECK(torn.outcome == Diagnosis::Outcome::Unexplained);
        CHECK_THAT(torn.claim, Catch::Contains("the kinds of observable ask for different "
                                               "strengths of grain_density"));
        bool vetoed = false;
        for (const PairResult &p : torn.pairs)
            vetoed = vetoed || (p.confirmed && !p.after.gap && !p.strengths_agree);
        CHECK(vetoed);
    }
}
