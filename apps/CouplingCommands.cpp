#include "CouplingCommands.hpp"

#include "ChildProcesses.hpp"
#include "Nodes.hpp"
#include "SoilSide.hpp"
#include "grainlink/coupling/Coordinator.hpp"
#include "grainlink/dem/RigidFloor.hpp"
#include "grainlink/dem/Scenario.hpp"
#include "grainlink/dem/SteadySignal.hpp"
#include "grainlink/mbs/Mole.hpp"
#include "grainlink/mbs/RockerBogie.hpp"
#include "grainlink/mbs/WheelTest.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

namespace grainlink::apps {

namespace {

using coupling::Coordinator;
using coupling::CoordinatorConfig;

std::atomic<Coordinator *> running{nullptr};

extern "C" void onStopSignal(int) {
    if (Coordinator *c = running.load())
        c->requestStop();
}

/// Ctrl-C and SIGTERM stop the run cleanly: participants are told, files stay readable.
struct StopSignals {
    explicit StopSignals(Coordinator &c) {
        running = &c;
        std::signal(SIGINT, onStopSignal);
        std::signal(SIGTERM, onStopSignal);
    }
    ~StopSignals() {
        std::signal(SIGINT, SIG_DFL);
        std::signal(SIGTERM, SIG_DFL);
        running = nullptr;
    }
};

/// What the scenario's own participant commands run: a Simbody node, a rigid floor, and the bed
/// sections its soil nodes read (`soil`, or what each `--section` names).
struct NodesInScenario {
    bool simbody = false;
    bool floor = false;
    std::vector<std::string> soil_sections;
};

NodesInScenario nodesIn(const config::ConfigNode &root) {
    NodesInScenario nodes;
    for (const auto &p : root["participants"].items()) {
        if (!p.has("command"))
            continue; // an external participant
        const auto words = p["command"].items();
        bool soil_node = false;
        std::string section = "soil";
        for (std::size_t w = 0; w < words.size(); ++w) {
            nodes.simbody = nodes.simbody || words[w].text() == "mbs-node";
            nodes.floor = nodes.floor || words[w].text() == "floor-node";
            soil_node = soil_node || words[w].text() == "dem-node";
            if (words[w].text() == "--section" && w + 1 < words.size())
                section = words[w + 1].text();
        }
        if (soil_node)
            nodes.soil_sections.push_back(section);
    }
    return nodes;
}

} // namespace

CoordinatorConfig checkedCoupledConfig(const config::ConfigNode &root) {
    // The coupling sections, and the participants' own sections checked up front, so a typo
    // stops the run before any process starts.
    CoordinatorConfig config = coupling::coordinatorConfigFrom(root);
    checkParticipantSections(root, root.file());
    root.finish();
    return config;
}

namespace {

CoordinatorConfig configFor(const CoupledRunOptions &options, const char *default_endpoint) {
    CoordinatorConfig config =
        checkedCoupledConfig(config::ConfigNode::loadFile(options.config_path));
    if (!options.endpoint.empty())
        config.endpoint = options.endpoint;
    if (config.endpoint.empty())
        config.endpoint = default_endpoint;
    config.insecure = config.insecure || options.insecure;
    config.output_directory =
        options.output_directory.empty()
            ? "out/" + std::filesystem::path(options.config_path).stem().string()
            : options.output_directory;
    config.resume = options.resume;
    config.progress_interval_s = options.progress_interval_s;
    return config;
}

void printSummary(const coupling::CoordinatorSummary &s, const CoordinatorConfig &config) {
    std::printf("coupling: %llu windows (%.2f passes each) to t = %.6g s in %.2f s wall; "
                "coupling energy mismatch %.3g J\n",
                static_cast<unsigned long long>(s.windows),
                s.windows ? double(s.iterations) / double(s.windows) : 0.0, s.end_time_s, s.wall_s,
                s.cumulative_mismatch_J);
    for (std::size_t b = 0; b < s.final_states.size(); ++b) {
        const auto &st = s.final_states[b];
        const auto &w = s.final_wrenches[b];
        std::printf("  %s: position (%.6g, %.6g, %.6g) m, force (%.6g, %.6g, %.6g) N\n",
                    st.body.c_str(), st.position_m.x(), st.position_m.y(), st.position_m.z(),
                    w.force_N.x(), w.force_N.y(), w.force_N.z());
    }
    std::printf("coupling: time series in %s/coupling.csv\n", config.output_directory.c_str());
    for (const auto &warning : s.guard_warnings)
        std::printf("coupling guard: %s\n", warning.c_str());
}

std::string substitute(std::string text, const std::string &key, const std::string &value) {
    for (auto at = text.find(key); at != std::string::npos; at = text.find(key, at + value.size()))
        text.replace(at, key.size(), value);
    return text;
}

/// A rig that ended unsteady says why as the run's last line (a study shows a failed point's
/// last line as its error).
void printRigVerdict(const std::string &directory) {
    const std::string path = directory + "/rig_summary.json";
    if (!std::filesystem::exists(path))
        return;
    const auto summary = nlohmann::json::parse(std::ifstream(path), nullptr, false);
    if (summary.is_object() && summary.value("steady", true) == false)
        std::fprintf(stderr, "run: %s\n", summary.value("message", std::string()).c_str());
}

/// One window's row of a soil node's series (soil.csv) for one body.
struct SoilRow {
    double time_s, sinkage_m, end_wall_ahead_N, end_wall_behind_N, fx_N, fz_N;
};

/// The rows of `body` (every body's, for "") in the soil series `path`, in time order; a
/// column the file lacks (a series from before the end-wall columns were written) reads NaN.
std::vector<SoilRow> soilSeries(const std::string &path, const std::string &body) {
    std::ifstream series(path);
    std::string line;
    std::getline(series, line);
    std::map<std::string, std::size_t> column;
    {
        std::istringstream names(line);
        std::string name;
        while (std::getline(names, name, ','))
            column.emplace(name, column.size());
    }
    std::vector<SoilRow> rows;
    while (std::getline(series, line)) {
        std::vector<std::string> cells;
        std::istringstream row(line);
        for (std::string cell; std::getline(row, cell, ',');)
            cells.push_back(cell);
        const auto value = [&](const char *name) {
            const auto c = column.find(name);
            return c == column.end() || c->second >= cells.size()
                       ? std::nan("")
                       : std::strtod(cells[c->second].c_str(), nullptr);
        };
        if (cells.size() < 2 || (!body.empty() && cells[1] != body))
            continue;
        rows.push_back({value("time_s"), value("sinkage_m"), value("end_wall_ahead_N"),
                        value("end_wall_behind_N"), value("Fx_N"), value("Fz_N")});
    }
    return rows;
}

double meanOf(const std::vector<double> &v) {
    double sum = 0.0;
    for (double x : v)
        sum += x;
    return sum / double(v.size());
}

/// The mean, sd and standard error of v's rise over `minus` (dem::summarizeSignal).
nlohmann::json riseStatistics(const std::vector<double> &v, double minus) {
    std::vector<double> rise;
    for (double x : v)
        rise.push_back(x - minus);
    const auto s = dem::summarizeSignal(rise);
    return nlohmann::json{{"mean", s.mean}, {"sd", s.sd}, {"standard_error", s.standard_error}};
}

void writeJsonAtomically(const std::string &path, const nlohmann::json &j) {
    const std::string partial = path + ".partial";
    std::ofstream(partial) << j.dump(2) << '\n';
    std::filesystem::rename(partial, path);
}

/// A mole's strokes (mbs_summary.json) get the depth of the hull's tip below the settled bed
/// surface at each stroke's end, from the soil's series: what a mole's depth is measured as
/// (the run's own `penetration_m` counts from the tip's start above the grains).
void addMoleDepths(const config::ConfigNode &root, const std::string &directory,
                   const std::string &soil_section) {
    const std::string summary_path = directory + "/mbs_summary.json";
    if (!std::filesystem::exists(summary_path))
        return;
    auto summary = nlohmann::json::parse(std::ifstream(summary_path));
    if (!summary.contains("strokes") || !summary["strokes"].is_array())
        return;
    const mbs::MoleSettings mole = mbs::parseMole(root["mole"]);
    const auto rows = soilSeries(directory + "/" + soil_section + ".csv", mole.hull_name);
    if (rows.empty())
        return;
    // The last window that ended by `t`: the depth then.
    const auto depthAt = [&rows](double t) {
        const SoilRow *at = nullptr;
        for (const SoilRow &r : rows)
            if (r.time_s <= t + 1e-9)
                at = &r;
        return at ? nlohmann::json(at->sinkage_m) : nlohmann::json(nullptr);
    };
    // Resting on the grains under its weight, before the first stroke's release.
    summary["depth_before_strokes_m"] = depthAt(mole.first_cocking_s + mole.cocking_duration_s);
    for (auto &stroke : summary["strokes"])
        stroke["depth_m"] = depthAt(stroke.value("end_time_s", 0.0));
    summary["depth_m"] = rows.back().sinkage_m;
    writeJsonAtomically(summary_path, summary);
    std::printf("run: the mole's tip %.1f mm below the bed surface after %zu strokes (%s)\n",
                1e3 * rows.back().sinkage_m, summary["strokes"].size(), summary_path.c_str());
}

/// A rover's strips (mbs_summary.json, `end_walls`): for each soil section, the rise of the
/// push on its end walls over the run's second half above their push at the end of the drop,
/// and its share of the section's wheels' push along x (dem::endWallShare; the wheels' weight
/// floors it). A share above rover.end_wall_limit refuses the run, as the rig's steady state:
/// the soil the wheels push reached a strip's end. Returns whether the run stands.
bool addRoverEndWalls(const config::ConfigNode &root, const std::string &directory,
                      const std::vector<std::string> &sections) {
    const std::string summary_path = directory + "/mbs_summary.json";
    if (!std::filesystem::exists(summary_path))
        return true;
    auto summary = nlohmann::json::parse(std::ifstream(summary_path));
    if (!summary.contains("second_half_from_s"))
        return true;
    const mbs::RockerBogieSettings rover = mbs::parseRockerBogie(root["rover"]);
    const double from = summary["second_half_from_s"];
    // At rest on the beds: the drop's second half (the run's first tenth without a drop).
    const double rest_to = rover.release_time_s.value_or(0.2 * from);
    bool stands = true;
    std::string why;
    for (const std::string &section : sections) {
        // One sample per window: the walls' push (the same on every body's row), the wheels'
        // forces summed.
        std::map<double, SoilRow> windows;
        for (const SoilRow &r : soilSeries(directory + "/" + section + ".csv", "")) {
            auto [it, first] = windows.emplace(r.time_s, r);
            if (!first)
                it->second.fx_N += r.fx_N, it->second.fz_N += r.fz_N;
        }
        std::vector<double> ahead, behind, rest_ahead, rest_behind, fx, fz;
        for (const auto &[t, r] : windows) {
            if (t >= from - 1e-9) {
                ahead.push_back(r.end_wall_ahead_N);
                behind.push_back(r.end_wall_behind_N);
                fx.push_back(r.fx_N);
                fz.push_back(r.fz_N);
            } else if (t > 0.5 * rest_to && t <= rest_to + 1e-9) {
                rest_ahead.push_back(r.end_wall_ahead_N);
                rest_behind.push_back(r.end_wall_behind_N);
            }
        }
        if (ahead.empty() || rest_ahead.empty() || !std::isfinite(meanOf(ahead)) ||
            !std::isfinite(meanOf(rest_ahead)))
            continue; // no end walls along x, or a series from before they were written
        nlohmann::json walls;
        walls["ahead_N"] = riseStatistics(ahead, meanOf(rest_ahead));
        walls["behind_N"] = riseStatistics(behind, meanOf(rest_behind));
        // The wheels' push on the soil along x is the soil's force on them, reversed.
        const double push = -meanOf(fx);
        walls["push_N"] = push;
        const double share = dem::endWallShare(walls["ahead_N"]["mean"], walls["behind_N"]["mean"],
                                               push, std::abs(meanOf(fz)));
        walls["share"] = share;
        summary["end_walls"][section] = walls;
        std::printf("run: %s's end walls %+.3g N ahead, %+.3g N behind over the second half "
                    "(share %.2f of the wheels' push)\n",
                    section.c_str(), walls["ahead_N"]["mean"].get<double>(),
                    walls["behind_N"]["mean"].get<double>(), share);
        if (share > rover.end_wall_limit) {
            std::ostringstream w;
            w << section << "'s end walls took " << std::lround(100.0 * share)
              << " % of its wheels' push along x over the run's second half, more than "
                 "rover.end_wall_limit = "
              << rover.end_wall_limit
              << ": the soil the wheels pushed reached the strip's end, and the slips are the "
                 "strip's, not the soil's. Lengthen the strip (its walls and deposition region "
                 "along x); the results are written to "
              << directory;
            why += (why.empty() ? "" : "; ") + w.str();
            stands = false;
        }
    }
    if (!stands) {
        summary["end_walls_refused"] = why;
        std::fprintf(stderr, "run: %s\n", why.c_str());
    }
    if (summary.contains("end_walls"))
        writeJsonAtomically(summary_path, summary);
    return stands;
}

} // namespace

/// A mole's strokes get their depths below the bed surface (above). The rig's steady report
/// (rig_summary.json, written by the rig) gets what only the soil knows,
/// over the span the rig judged, with the same statistics: the wheel's sinkage (below the
/// settled surface) and the rise of the soil's push on the bin's end walls over their push
/// before the drive. A steady state whose push the end wall it goes towards took more than
/// wheel_test.end_wall_limit of is refused: the report says why, and the run fails. Run after
/// the participants ended, so both files are complete. Returns whether the run stands.
bool addSoilMeasures(const config::ConfigNode &root, const std::string &directory) {
    const auto sections = nodesIn(root).soil_sections;
    if (root.has("mole") && sections.size() == 1)
        addMoleDepths(root, directory, sections[0]);
    if (root.has("rover"))
        return addRoverEndWalls(root, directory, sections);
    const std::string summary_path = directory + "/rig_summary.json";
    if (!root.has("rig") || sections.size() != 1 || !std::filesystem::exists(summary_path))
        return true;
    auto summary = nlohmann::json::parse(std::ifstream(summary_path));
    if (!summary.contains("span_s"))
        return true; // the drop never ended: no span was judged
    const double from = summary["span_s"][0], to = summary["span_s"][1];
    const double drive_start = summary.value("drive_start_s", from);
    const double hold_from = drive_start - summary.value("span_length_s", 0.0);
    const std::string wheel = mbs::parseSingleWheelRig(root["rig"]).wheel_name;
    std::vector<double> sinkage, ahead, behind, hold_ahead, hold_behind;
    for (const SoilRow &row : soilSeries(directory + "/" + sections[0] + ".csv", wheel)) {
        if (row.time_s >= from - 1e-9 && row.time_s <= to + 1e-9) {
            sinkage.push_back(row.sinkage_m);
            ahead.push_back(row.end_wall_ahead_N);
            behind.push_back(row.end_wall_behind_N);
        } else if (row.time_s > hold_from + 1e-9 && row.time_s <= drive_start + 1e-9) {
            hold_ahead.push_back(row.end_wall_ahead_N);
            hold_behind.push_back(row.end_wall_behind_N);
        }
    }
    if (sinkage.empty())
        return true;
    summary["sinkage_m"] = riseStatistics(sinkage, 0.0);
    std::printf("run: steady sinkage %.2f +- %.2f mm (se %.2f) in %s\n",
                1e3 * summary["sinkage_m"]["mean"].get<double>(),
                1e3 * summary["sinkage_m"]["sd"].get<double>(),
                1e3 * summary["sinkage_m"]["standard_error"].get<double>(), summary_path.c_str());
    bool stands = true;
    // (A series without the end-wall columns, from before they were written, reads NaN.)
    if (!hold_ahead.empty() && std::isfinite(meanOf(ahead)) && std::isfinite(meanOf(hold_ahead)) &&
        summary.contains("drawbar_pull_N") && summary.contains("normal_load_N")) {
        summary["end_wall_ahead_N"] = riseStatistics(ahead, meanOf(hold_ahead));
        summary["end_wall_behind_N"] = riseStatistics(behind, meanOf(hold_behind));
        // The wheel's push on the soil along x is the soil's force on it, reversed.
        const double share = dem::endWallShare(
            summary["end_wall_ahead_N"]["mean"], summary["end_wall_behind_N"]["mean"],
            -summary["drawbar_pull_N"]["mean"].get<double>(), summary["normal_load_N"]);
        summary["end_wall_share"] = share;
        const auto test = root.optional("wheel_test");
        const double limit =
            (test ? mbs::parseWheelTest(*test) : mbs::WheelTestSettings{}).end_wall_limit;
        std::printf("run: end walls %+.3g N ahead, %+.3g N behind (share %.2f of the push)\n",
                    summary["end_wall_ahead_N"]["mean"].get<double>(),
                    summary["end_wall_behind_N"]["mean"].get<double>(), share);
        if (summary.value("steady", false) && share > limit) {
            std::ostringstream why;
            why << "the bin's end walls took " << std::lround(100.0 * share)
                << " % of the wheel's push along its travel over the steady span, more than "
                   "wheel_test.end_wall_limit = "
                << limit
                << ": the soil pushed by the wheel reached the bin's end, and the steady values "
                   "are the bin's, not the soil's. Lengthen the bin (soil.walls and the "
                   "deposition region along x); the results are written to "
                << directory;
            summary["steady"] = false;
            summary["message"] = why.str();
            stands = false;
        }
    }
    writeJsonAtomically(summary_path, summary);
    return stands;
}

void checkParticipantSections(const config::ConfigNode &root, const std::string &path) {
    const NodesInScenario nodes = nodesIn(root);
    const auto unread = [&root](const char *section, const std::string &why) {
        if (root.has(section))
            root[section].fail(why + ": remove the section");
    };
    for (const auto &section : nodes.soil_sections)
        parseSoilSection(root, section);
    if (nodes.soil_sections.empty())
        unread("mirror", "mirror symmetry is the DEM soil's (no participant runs `grainlink "
                         "dem-node`)");
    else
        MirrorSymmetry::parse(root);
    if (nodes.floor)
        dem::parseRigidFloor(root["floor"]);
    else
        unread("floor", "no participant runs `grainlink floor-node`, which reads it");
    const char *models[] = {"rig", "rover", "mole", "model"};
    const char *model = nullptr;
    for (const char *m : models)
        if (root.has(m)) {
            if (model)
                root[m].fail(std::string("a second multibody model (`") + model +
                             ":` is the first): the multibody node runs one");
            model = m;
        }
    if (!nodes.simbody) {
        for (const char *m : models)
            unread(m, "no participant runs `grainlink mbs-node`, which reads it");
    } else if (root.has("rig")) {
        mbs::parseSingleWheelRig(root["rig"]);
    } else {
        makeModel(root, path); // builds it once: every model error shows now
    }
    if (!root.has("rig") || !nodes.simbody)
        unread("wheel_test", "the wheel test is the single-wheel rig's procedure (`rig:` run by "
                             "`grainlink mbs-node`)");
    else if (const auto test = root.optional("wheel_test"))
        mbs::parseWheelTest(*test);
}

int runCoordinator(const CoupledRunOptions &options) {
    const CoordinatorConfig config = configFor(options, "tcp://127.0.0.1:5555");
    Coordinator coordinator(config);
    std::printf("coordinator: waiting for participants at %s\n",
                coordinator.boundEndpoint().c_str());
    std::fflush(stdout);
    StopSignals signals(coordinator);
    printSummary(coordinator.run(), config);
    return 0;
}

int runCoupled(const CoupledRunOptions &options) {
    const CoordinatorConfig config = configFor(options, "tcp://127.0.0.1:*");
    for (const auto &p : config.participants) {
        if (p.external && config.endpoint.find(":*") != std::string::npos)
            throw coupling::CouplingError("participant '" + p.name +
                                          "' is external: give coupling.endpoint a fixed port so "
                                          "it knows where to connect");
        if (!p.external && p.command.empty())
            throw coupling::CouplingError("participant '" + p.name +
                                          "' has no command and is not marked external");
    }
    Coordinator coordinator(config);
    const std::string endpoint = coordinator.boundEndpoint();
    ChildProcesses children([&](const std::string &name, const std::string &how) {
        coordinator.reportFailure(name, "its process " + how);
    });
    std::filesystem::create_directories(config.output_directory);
    for (const auto &p : config.participants) {
        if (p.external) {
            std::printf("run: waiting for external participant '%s' at %s\n", p.name.c_str(),
                        endpoint.c_str());
            continue;
        }
        std::vector<std::string> argv;
        for (const auto &arg : p.command)
            argv.push_back(substitute(substitute(substitute(substitute(arg, "{endpoint}", endpoint),
                                                            "{out}", config.output_directory),
                                                 "{name}", p.name),
                                      "{scenario}",
                                      std::filesystem::absolute(options.config_path).string()));
        children.start(p.name, argv);
    }
    std::fflush(stdout);
    StopSignals signals(coordinator);
    try {
        const auto summary = coordinator.run();
        const auto failed = children.stopAll(10.0);
        printSummary(summary, config);
        const bool stands = addSoilMeasures(config::ConfigNode::loadFile(options.config_path),
                                            config.output_directory);
        std::fflush(stdout); // the failures below are the log's last lines
        for (const auto &f : failed)
            std::fprintf(stderr, "run: participant %s\n", f.c_str());
        if (!failed.empty() || !stands)
            printRigVerdict(config.output_directory);
        return failed.empty() && stands ? 0 : 1;
    } catch (...) {
        children.stopAll(3.0); // a frozen process will not exit by itself
        throw;
    }
}

int generateKeys(const std::string &directory, const std::vector<std::string> &participants) {
    if (participants.empty())
        throw coupling::CouplingError("name the participants: --participants mbs,soil");
    coupling::writeKeyPair(directory, "coordinator", coupling::generateKeyPair());
    for (const auto &name : participants)
        coupling::writeKeyPair(directory, name, coupling::generateKeyPair());
    std::printf("keygen: wrote coordinator.key/.pub and %zu participant key pairs to %s\n"
                "keygen: the coordinator host needs coordinator.key and every <name>.pub;\n"
                "        each participant host needs its <name>.key and coordinator.pub.\n",
                participants.size(), directory.c_str());
    return 0;
}

} // namespace grainlink::apps
