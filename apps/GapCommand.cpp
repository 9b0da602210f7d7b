// `grainlink gap`: import, diagnose, twin, selftest (docs/gap.md). The pipeline is the gap
// library; this is its command line.
#include "GapCommand.hpp"

#include "grainlink/config/Number.hpp"
#include "grainlink/gap/Importers.hpp"
#include "grainlink/gap/Report.hpp"
#include "grainlink/gap/Selftest.hpp"
#include "grainlink/gap/StudySimulator.hpp"
#include "grainlink/gap/Twin.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>

namespace grainlink::apps {

namespace {

namespace fs = std::filesystem;

std::string duration(double s) {
    char text[32];
    if (s < 0.0 || !std::isfinite(s))
        return "?";
    if (s < 120.0)
        std::snprintf(text, sizeof text, "%.0f s", s);
    else
        std::snprintf(text, sizeof text, "%.0f min %02.0f s", std::floor(s / 60.0), std::fmod(s, 60.0));
    return text;
}

study::ExecutorOptions executorOptions(const ExecutorFlags &flags) {
    study::ExecutorOptions o = flags.options();
    o.progress = [](const study::StudyProgress &p) {
        std::fprintf(stderr, "[gap] simulations: %zu/%zu done (%zu reused), %zu running, %zu failed; %s "
                             "elapsed, ETA %s\n",
                     p.done, p.total, p.reused, p.running, p.failed, duration(p.elapsed_s).c_str(),
                     duration(p.eta_s).c_str());
    };
    return o;
}

gap::EffectCatalogue catalogueWith(const std::string &extra) {
    gap::EffectCatalogue c = gap::loadEffects(shipped("data/effects.yaml"));
    if (!extra.empty())
        c = gap::mergeEffects(c, gap::loadEffects(extra));
    return c;
}

gap::DiagnosisOptions diagnosisOptions(const gap::BaseModel &base) {
    gap::DiagnosisOptions o;
    o.seeds = base.seeds;
    o.signature_seeds = base.signature_seeds;
    o.check_seeds = base.check_seeds;
    o.log = [](const std::string &line) { std::fprintf(stderr, "[gap] %s\n", line.c_str()); };
    return o;
}

/// The user's --hold-out ids, trimmed ("a, b" from a shell), each one the diagnosis compares:
/// one left out (no test for it in the base) is named with why, and holding out every
/// experiment leaves nothing to fit a candidate on.
std::vector<std::string> checkedHeldOut(std::vector<std::string> ids, const gap::ExperimentSet &set,
                                        const std::vector<std::string> &left_out) {
    for (std::string &id : ids) {
        id.erase(0, id.find_first_not_of(" \t"));
        id.erase(id.find_last_not_of(" \t") + 1);
        const bool compared = std::any_of(set.experiments.begin(), set.experiments.end(),
                                          [&](const gap::Experiment &e) { return e.id == id; });
        if (compared)
            continue;
        for (const std::string &why : left_out)
            if (why.rfind(id + " (", 0) == 0)
                throw std::invalid_argument("--hold-out " + id +
                                            ": that experiment is left out of "
                                            "the diagnosis: " +
                                            why);
        set.find(id); // throws naming an unknown id
    }
    if (!ids.empty() && ids.size() >= set.experiments.size())
        throw std::invalid_argument("--hold-out names every experiment the diagnosis compares: "
                                    "none is left to fit a candidate's strength on");
    return ids;
}

/// `gap diagnose --dry-run`: what the diagnosis compares, how it splits, and the runs it needs.
int printPlan(const gap::DiagnosisPlan &plan, const gap::ExperimentSet &set,
              const gap::StudySimulator &sim, const gap::DiagnosisOptions &options) {
    std::printf("design: %zu experiments, %zu features\n", set.experiments.size(),
                plan.design.size());
    for (const gap::Experiment &e : set.experiments) {
        const auto it = plan.design.by_experiment.find(e.id);
        const std::size_t bins = it == plan.design.by_experiment.end() ? 0 : it->second.size();
        std::string range;
        if (bins > 0 && !e.x_name.empty()) {
            const auto &keys = plan.design.keys;
            char text[96];
            std::snprintf(text, sizeof text, " over %s %.4g to %.4g", e.x_name.c_str(),
                          keys[std::size_t(it->second.front())].x_lo,
                          keys[std::size_t(it->second.back())].x_hi);
            range = text;
        }
        // Reading refuses an experiment with no bin of its own; on its kind's shared bins a
        // curve shorter than the others' may still have none: said with where they start.
        std::string none;
        if (bins == 0 && !e.x_name.empty()) {
            const std::string slot = e.id + "/" + e.observables.front();
            const auto edges = plan.design.edges.find(slot);
            const auto reach = plan.design.x_reach.find(slot);
            char text[200];
            std::snprintf(
                text, sizeof text,
                "  (no measured bin, not compared: its curves reach %s %.4g, the first "
                "bin of its kind ends at %.4g; give it bins: of its own)",
                e.x_name.c_str(), reach == plan.design.x_reach.end() ? NAN : reach->second,
                edges == plan.design.edges.end() || edges->second.size() < 2 ? NAN
                                                                             : edges->second[1]);
            none = text;
        }
        const bool held =
            std::find(plan.held_out.begin(), plan.held_out.end(), e.id) != plan.held_out.end();
        std::printf("  %-20s %-16s %zu feature(s)%s, %zu trial(s); %s%s\n", e.id.c_str(),
                    gap::typeName(e.type), bins, range.c_str(), e.trials.size(),
                    held ? "held out" : "calibration", none.c_str());
        // The values as read, in SI: a unit mistaken (kPa for Pa, m for mm) shows here.
        std::string measured;
        for (const std::string &o : e.observables) {
            double lo = INFINITY, hi = -INFINITY;
            for (const gap::Trial &t : e.trials)
                if (const auto c = t.curves.find(o); c != t.curves.end())
                    for (double y : c->second.y)
                        lo = std::min(lo, y), hi = std::max(hi, y);
            char text[96];
            std::snprintf(text, sizeof text, "%s%s %.4g to %.4g", measured.empty() ? "" : ", ",
                          o.c_str(), lo, hi);
            measured += text;
        }
        std::printf("  %-20s measured %s\n", "", measured.c_str());
        // The conditions as read, in SI: a diameter given in mm shows here too.
        std::string conditions;
        for (const auto &[key, value] : e.conditionText())
            conditions += (conditions.empty() ? "" : ", ") + key + " " + value;
        if (!conditions.empty())
            std::printf("  %-20s conditions %s\n", "", conditions.c_str());
    }
    if (plan.held_out.size() < 2)
        std::printf("note: %s held out: the diagnosis can locate a gap but claim no effect (a "
                    "claim needs two or more held-out experiments: two or more of a type, or "
                    "--hold-out)\n",
                    plan.held_out.empty() ? "no experiment is" : "one experiment is");
    for (const std::string &note : gap::splitNotes(set, plan.held_out))
        std::printf("note: %s\n", note.c_str());
    std::string checks;
    for (const std::string &c : sim.checks())
        checks += (checks.empty() ? "" : ", ") + c;
    std::printf("numerical checks: %s\n", checks.empty() ? "none" : checks.c_str());
    std::printf("effects: %zu applicable", plan.applicable.size());
    for (const auto &[name, why] : plan.inapplicable)
        std::printf("\n  not applicable: %s: %s", name.c_str(), why.c_str());
    std::printf("\n");
    for (const auto &[name, why] : plan.probes_refused)
        std::printf("probe %s (an experiment the diagnosis may propose) cannot run: %s\n",
                    name.c_str(), why.c_str());
    // Scenarios are checked here, as a study checks its points before it runs one.
    const auto first = sim.plan(set, plan.first);
    auto all = plan.first;
    all.insert(all.end(), plan.signatures.begin(), plan.signatures.end());
    const auto both = sim.plan(set, all);
    std::printf("runs before the gap test (base x %d seeds, checks x %d): %zu, %zu in the cache "
                "(%zu failed there)\n",
                options.seeds, options.check_seeds, first.runs, first.done, first.failed);
    std::printf("runs of the signatures, once a gap shows (x %d seeds): %zu more, %zu in the cache "
                "(%zu failed there)\n",
                options.signature_seeds, both.runs - first.runs, both.done - first.done,
                both.failed - first.failed);
    std::printf("then up to %d candidates and 2 pairs confirmed at %d seeds each; every scenario "
                "above is valid; nothing was run\n",
                options.max_confirmed, options.seeds);
    return 0;
}

} // namespace

GapCommand::GapCommand(CLI::App &app) {
    command_ = app.add_subcommand("gap", "sim-to-real gap diagnosis (docs/gap.md)");
    command_->require_subcommand(1);

    diagnose_ = command_->add_subcommand(
        "diagnose", "where a simulation disagrees with measurements, which effect causes it, and "
                    "how far the held-out gap shrinks once it is added");
    diagnose_->add_option("measurements", measurements_, "folder with experiments.yaml")->required();
    diagnose_->add_option("--model", model_, "base model YAML (docs/gap.md)")->required();
    diagnose_->add_option("--out", out_, "output folder (default out/gap/<measurements name>)");
    diagnose_->add_option("--hold-out", held_out_,
                          "experiment ids to hold out (comma separated; default: docs/gap.md's rule)")
        ->delimiter(',');
    diagnose_->add_option("--only", only_, "diagnose with these catalogue effects only")->delimiter(',');
    diagnose_->add_flag("--dry-run", dry_run_,
                        "read and check everything, print the design and the runs it needs "
                        "(and the cache holds); run nothing");

    twin_ = command_->add_subcommand(
        "twin", "simulated measurements with one effect hidden; the key goes to a separate file");
    twin_->add_option("--model", model_, "base model YAML")->required();
    twin_->add_option("--design", design_, "design YAML: experiments, conditions, reach (docs/gap.md)")
        ->required();
    twin_->add_option("--out", out_, "the twin's measurements folder")->required();
    twin_->add_option("--key", key_, "the key file (default <out>.key.json, outside the folder)");
    auto *which = twin_->add_option_group("effect");
    which->add_option("--effect", effect_, "the hidden effect (a catalogue name, or crust)");
    which->add_flag("--random", random_, "a catalogue effect drawn with --seed");
    which->add_flag("--null", null_, "no effect at all");
    which->require_option(1);
    twin_->add_option("--strength", strength_, "its strength (default: drawn from its prior)");
    twin_->add_option("--seed", seed_, "seed of the beds and the draws");
    twin_->add_option("--noise", noise_, "relative sd of every sample");
    twin_->add_option("--level-noise", level_noise_, "relative sd of each trial's level");
    twin_->add_flag("--own-beds", own_beds_,
                    "every experiment on beds of its own (a test bed rebuilt for every trial)");

    selftest_ = command_->add_subcommand(
        "selftest", "the diagnosis run blind on twins of every catalogue effect, null twins and "
                    "an effect outside the catalogue, scored against their keys");
    selftest_->add_option("--scale", scale_, "ci (minutes) or full (the benchmark)")
        ->check(CLI::IsMember({"ci", "full"}));
    selftest_->add_option("--out", out_, "output folder (default out/gap/selftest-<scale>)");
    selftest_->add_option("--seed", seed_, "seed of the strengths and the twins' beds");
    selftest_->add_option("--model", model_, "your base model YAML instead of the scale's");
    selftest_->add_option("--design", design_, "your design YAML instead of the scale's");
    selftest_->add_option("--plan", plan_,
                          "selftest.yaml: the twins to make (default: beside the design)");

    executor_.progress_interval_s = 30.0; // a diagnosis runs for tens of minutes
    for (auto *c : {diagnose_, twin_, selftest_}) {
        c->add_option("--effects", effects_file_, "an effects file added to the catalogue");
        c->add_option("--sims", sims_, "the simulation cache (a study folder; default <out>/sims)");
        executor_.addTo(*c);
    }

    import_ = command_->add_subcommand("import", "write a measurements folder from raw data");
    import_->require_subcommand(1);
    import_cmu_ = import_->add_subcommand("cmu", "the CMU 3d-terramechanics test bed's plate and wheel tests");
    import_cmu_->add_option("source", source_, "the data folder (plates/, steady_state_wheel/)")->required();
    import_cmu_->add_option("--out", out_, "measurements folder to write")->required();
    import_cmu_->add_option("--sinkage", sinkage_, "synced, authors or deflection_corrected")
        ->check(CLI::IsMember({"synced", "authors", "deflection_corrected"}));
    import_cmu_->add_flag("--no-wheels", no_wheels_, "plates only");
    import_cmu_->add_flag("--no-plates", no_plates_, "wheels only");
    import_csv_ = import_->add_subcommand(
        "csv", "CSV files as one experiment (appended): one file, or one per repeat of the test");
    import_csv_->add_option("files", csv_files_, "CSV file(s), each one repeat of the test")
        ->required();
    import_csv_->add_option("--out", out_, "measurements folder")->required();
    import_csv_->add_option("--id", csv_id_, "experiment id")->required();
    import_csv_->add_option("--type", csv_type_, "experiment type (plate_sinkage, direct_shear, ...)")
        ->required();
    import_csv_->add_option("--x", csv_x_, "x column and unit, COLUMN:UNIT (none for a scalar)");
    import_csv_->add_option("--y", csv_y_, "observable, column and unit, OBSERVABLE=COLUMN:UNIT")
        ->required();
    import_csv_->add_option("--condition", csv_conditions_, "a condition KEY=VALUE (SI key names)");
    import_csv_->add_flag("--scatter", csv_scatter_, "one point per row (steady-state tests)");
    import_csv_->add_option("--delimiter", csv_delimiter_, "how cells are separated")
        ->check(CLI::IsMember({",", ";", "tab", "whitespace"}))
        ->default_str(",");
    import_csv_
        ->add_option("--decimal", csv_decimal_,
                     "the decimal mark: , with --delimiter ';' (or quoted cells)")
        ->check(CLI::IsMember({".", ","}))
        ->default_str(".");
    import_csv_->add_option("--comment", csv_comment_, "lines starting with it are skipped")
        ->default_str("#");
    import_csv_
        ->add_option("--columns", csv_columns_,
                     "the columns' names of files without a header line (comma separated)")
        ->delimiter(',');
    import_csv_->add_flag("--units-row", csv_units_row_, "the line under the header holds units");
    import_csv_
        ->add_option("--skip-lines", csv_skip_lines_,
                     "lines before the header (a title, a preamble), skipped")
        ->check(CLI::NonNegativeNumber);
    import_csv_->add_option("--x-scale", csv_x_scale_,
                            "multiplies the x column (-1: another code's z up)");
    import_csv_->add_option("--y-scale", csv_y_scale_,
                            "OBSERVABLE=FACTOR multiplies that column (-1: a force along z up)");
    import_csv_->add_option("--filter", csv_filter_,
                            "COLUMN=VALUE: only the rows holding it (one slip angle of a file "
                            "holding several)");
    import_csv_->add_option("--trial", csv_trial_,
                            "COLUMN telling apart trials written one after the other in a file "
                            "(a run number): each value is one trial");
    import_csv_->add_option("--zero", csv_zero_,
                            "where x is zero: as_recorded, first_sample or "
                            "force_threshold=VALUE:UNIT");
}

int GapCommand::run() const {
    if (diagnose_->parsed())
        return diagnose();
    if (twin_->parsed())
        return twin();
    if (selftest_->parsed())
        return selftest();
    if (import_cmu_->parsed())
        return importCmu();
    if (import_csv_->parsed())
        return importCsv();
    return 2;
}

int GapCommand::diagnose() const {
    const auto t0 = std::chrono::steady_clock::now();
    gap::BaseModel base = gap::loadBaseModel(model_);
    std::vector<std::string> left_out;
    gap::ExperimentSet set = gap::simulable(gap::loadExperiments(measurements_), base, left_out);
    if (const std::string note = gap::addRateCheckWhereSpeedDiffers(base, set); !note.empty())
        set.notes.push_back(note);
    for (const std::string &why : left_out)
        std::fprintf(stderr, "[gap] left out: %s\n", why.c_str());
    for (const std::string &note : set.notes)
        std::fprintf(stderr, "[gap] read: %s\n", note.c_str());
    const gap::EffectCatalogue catalogue = catalogueWith(effects_file_);
    std::vector<const gap::Effect *> effects;
    for (const gap::Effect *e : catalogue.diagnosable())
        if (only_.empty() || std::find(only_.begin(), only_.end(), e->name) != only_.end())
            effects.push_back(e);
    for (const std::string &name : only_)
        catalogue.find(name); // names an unknown effect
    const std::string out = out_.empty() ? "out/gap/" + set.name : out_;
    gap::StudySimulator sim(base, sims_.empty() ? out + "/sims" : sims_,
                            executorOptions(executor_));
    sim.sayLabWarnings();
    set.notes.insert(set.notes.end(), sim.labWarnings().begin(), sim.labWarnings().end());
    gap::DiagnosisOptions options = diagnosisOptions(base);
    options.held_out = checkedHeldOut(held_out_, set, left_out);
    if (dry_run_)
        return printPlan(gap::planDiagnosis(set, effects, sim, options), set, sim, options);
    // Said in the report too, among its Read: lines.
    for (const std::string &note : gap::splitNotes(set, gap::heldOutIds(set, options))) {
        std::fprintf(stderr, "[gap] split: %s\n", note.c_str());
        set.notes.push_back(note);
    }
    const gap::Diagnosis d = gap::diagnose(set, effects, sim, options);
    const auto files = gap::writeDiagnosis(d, set, out, shipped("tools/gap_report.py"));
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("%s", gap::reportText(d, set).c_str());
    std::printf("\nsimulations: %d run now, %d reused from the cache; wall %s\n", sim.runsDone(),
                sim.runsReused(), duration(wall).c_str());
    std::printf("written:");
    for (const auto &f : files)
        std::printf(" %s/%s", out.c_str(), f.c_str());
    std::printf("\n");
    return 0;
}

int GapCommand::twin() const {
    const gap::BaseModel base = gap::loadBaseModel(model_);
    const gap::EffectCatalogue catalogue = catalogueWith(effects_file_);
    const gap::Design design = gap::loadDesign(design_);
    gap::StudySimulator sim(base, sims_.empty() ? out_ + ".sims" : sims_,
                            executorOptions(executor_));
    sim.sayLabWarnings();
    gap::TwinOptions o;
    o.seed = seed_;
    o.noise = noise_;
    o.level_noise = level_noise_;
    o.own_beds = own_beds_;
    o.strength = strength_;
    if (random_) {
        const auto list = catalogue.diagnosable();
        std::mt19937 rng(seed_);
        o.effect = list[std::uniform_int_distribution<std::size_t>(0, list.size() - 1)(rng)]->name;
    } else if (!null_) {
        o.effect = effect_;
    }
    const std::string key = key_.empty() ? out_ + ".key.json" : key_;
    gap::makeTwin(design, catalogue, sim, o, out_, key);
    std::printf("twin written to %s; its key (not to be read by the diagnosis) to %s\n",
                out_.c_str(), key.c_str());
    return 0;
}

int GapCommand::selftest() const {
    gap::SelftestOptions o;
    o.scale = scale_;
    o.out = out_.empty() ? "out/gap/selftest-" + scale_ : out_;
    o.sims = sims_;
    o.seed = seed_;
    // A user's own base and design prove the diagnosis where it will be used.
    const std::string suite = "scenarios/gap/selftest-" + scale_;
    o.base_model = model_.empty() ? shipped(suite + "/base.yaml") : model_;
    o.design = design_.empty() ? shipped(suite + "/design.yaml") : design_;
    o.plan = plan_;
    o.catalogue = catalogueWith(effects_file_);
    o.executor = executorOptions(executor_);
    o.plot_tool = shipped("tools/gap_report.py");
    const gap::SelftestResult r = gap::runSelftest(o);
    std::printf("%s", r.report.c_str());
    return r.passed ? 0 : 1;
}

int GapCommand::importCmu() const {
    gap::CmuImportOptions o;
    o.sinkage = sinkage_;
    o.wheels = !no_wheels_;
    o.plates = !no_plates_;
    const auto ids = gap::importCmu(source_, out_, o);
    std::printf("wrote %s/experiments.yaml: %zu experiments\n", out_.c_str(), ids.size());
    return 0;
}

int GapCommand::importCsv() const {
    gap::CsvImport csv;
    csv.files = csv_files_;
    csv.comment = csv_comment_;
    csv.columns = csv_columns_;
    csv.units_row = csv_units_row_;
    csv.trial_column = csv_trial_;
    csv.id = csv_id_;
    csv.type = csv_type_;
    csv.scatter = csv_scatter_;
    csv.delimiter = csv_delimiter_;
    csv.decimal = csv_decimal_;
    // An option's two parts, named by its form where one is missing. A unit never holds ':',
    // so a column named "Sinkage: mm" splits at the last one; a name never holds '='.
    const auto split = [](const std::string &option, const std::string &form, const std::string &s,
                          char c) {
        const auto at = c == ':' ? s.rfind(c) : s.find(c);
        if (at == std::string::npos || at == 0 || at + 1 == s.size())
            throw std::invalid_argument(option + " '" + s + "': give " + form);
        std::string second = s.substr(at + 1);
        if (c == ':') // "Sinkage: mm" for a column with no unit: the unit without its blank
            second.erase(0, second.find_first_not_of(' '));
        return std::pair{s.substr(0, at), second};
    };
    if (!csv_x_.empty()) {
        const auto [col, unit] = split("--x", "COLUMN:UNIT (\"Sinkage [mm]:mm\")", csv_x_, ':');
        csv.x_column = col;
        csv.x_unit = unit;
    }
    for (const std::string &y : csv_y_) {
        const std::string form = "OBSERVABLE=COLUMN:UNIT (\"pressure_Pa=Pressure [kPa]:kPa\")";
        const auto [obs, rest] = split("--y", form, y, '=');
        if (rest.find(':') == std::string::npos) // no unit: said with the whole option
            throw std::invalid_argument("--y '" + y + "': give " + form);
        csv.y[obs] = split("--y", form, rest, ':');
    }
    for (const std::string &c : csv_conditions_) {
        const auto [k, v] = split("--condition", "KEY=VALUE (plate_diameter_m=0.02)", c, '=');
        csv.conditions[k] = v;
    }
    csv.skip_lines = csv_skip_lines_;
    csv.x_scale = csv_x_scale_;
    const auto numberOf = [](const std::string &option, const std::string &text) {
        if (const auto v = config::wholeNumber(text))
            return *v;
        throw std::invalid_argument(option + ": '" + text + "' is not a number");
    };
    for (const std::string &s : csv_y_scale_) {
        const auto [obs, factor] = split("--y-scale", "OBSERVABLE=FACTOR", s, '=');
        csv.y_scale[obs] = numberOf("--y-scale " + s, factor);
    }
    for (const std::string &f : csv_filter_) {
        const auto [column, value] = split("--filter", "COLUMN=VALUE", f, '=');
        csv.filter[column] = numberOf("--filter " + f, value);
    }
    if (!csv_zero_.empty()) {
        csv.zero_method = csv_zero_.substr(0, csv_zero_.find('='));
        if (csv_zero_.find('=') != std::string::npos) {
            if (csv.zero_method != "force_threshold")
                throw std::invalid_argument("--zero " + csv_zero_ +
                                            ": only force_threshold takes a value");
            const auto [value, unit] = split("--zero", "force_threshold=VALUE:UNIT",
                                             csv_zero_.substr(csv_zero_.find('=') + 1), ':');
            csv.zero_threshold = numberOf("--zero " + csv_zero_, value);
            csv.zero_unit = unit;
        } else if (csv.zero_method == "force_threshold") {
            throw std::invalid_argument("--zero force_threshold: give its threshold, "
                                        "force_threshold=VALUE:UNIT");
        }
    }
    for (const std::string &warning : gap::importCsv(csv, out_))
        std::fprintf(stderr, "grainlink: warning: %s\n", warning.c_str());
    std::printf("added experiment '%s' to %s/experiments.yaml\n", csv_id_.c_str(), out_.c_str());
    return 0;
}

} // namespace grainlink::apps
