// The `grainlink` command: one binary, one subcommand per job.
#include "CouplingCommands.hpp"
#include "GapCommand.hpp"
#include "LabCommands.hpp"
#include "Nodes.hpp"
#include "StudyCommand.hpp"
#include "grainlink/dem/ScenarioRun.hpp"
#include "grainlink/lab/LabTest.hpp"
#include "grainlink/study/Kind.hpp"

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>

#ifdef GRAINLINK_REQUIRES_X86_64_V3
// A build for x86-64-v3 (CMake's GRAINLINK_ARCH) copied to an older processor would die of an
// illegal instruction: it says why instead. Compiled for the base instruction set, and run
// before every other initialiser.
__attribute__((constructor(101), target("arch=x86-64"))) static void requireX86_64_v3() {
    __builtin_cpu_init();
    if (!__builtin_cpu_supports("x86-64-v3")) {
        std::fputs("grainlink: this build needs an x86-64-v3 processor (AVX2, FMA) and this one "
                   "is older: rebuild here, or configure with -DGRAINLINK_ARCH=x86-64\n",
                   stderr);
        std::_Exit(1);
    }
}
#endif

int main(int argc, char **argv) {
    // A study's or a diagnosis' coupled runs are checked by `grainlink run`'s own reader.
    grainlink::study::setRunScenarioCheck([](const grainlink::config::ConfigNode &root) {
        grainlink::apps::checkedCoupledConfig(root);
    });
    CLI::App app{"grainlink: co-simulation of planetary locomotion on granular soil"};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string("grainlink ") + GRAINLINK_VERSION + " (" +
                                          (GRAINLINK_ISA_NAME[0] ? GRAINLINK_ISA_NAME
                                                                 : "compiler's default") +
                                          " instruction set)");

    auto *dem =
        app.add_subcommand("dem", "run a DEM-only scenario (deposition, then prescribed bodies)");
    std::string scenario_path, out_dir;
    bool resume = false;
    double progress_s = 5.0;
    dem->add_option("scenario", scenario_path, "scenario YAML file (keys: docs/scenario.md)")
        ->required();
    dem->add_option("--out", out_dir, "output directory (default: out/<scenario name>)");
    dem->add_flag("--resume", resume, "continue from the last checkpoint in the output directory");
    dem->add_option("--progress-interval", progress_s, "seconds between progress lines");

    grainlink::apps::CoupledRunOptions coupled;
    auto *run = app.add_subcommand(
        "run", "run a coupled scenario: the coordinator plus the participant processes it names");
    auto *coordinator = app.add_subcommand(
        "coordinator", "run only the coordinator; participants connect by themselves");
    for (auto *command : {run, coordinator}) {
        command->add_option("config", coupled.config_path, "YAML file (keys: docs/protocol.md)")
            ->required();
        command->add_option("--out", coupled.output_directory,
                            "output directory (default: out/<file name>)");
        command->add_flag("--resume", coupled.resume,
                          "continue from the last complete checkpoint in the output directory");
        command->add_option("--endpoint", coupled.endpoint, "overrides coupling.endpoint");
        command->add_flag("--insecure", coupled.insecure,
                          "allow a non-loopback endpoint without CURVE keys");
        command
            ->add_option("--progress-interval", coupled.progress_interval_s,
                         "seconds between progress lines (0: none)")
            ->check(CLI::NonNegativeNumber);
    }
    auto *keygen = app.add_subcommand("keygen", "make CURVE keys for a run across machines");
    std::string key_directory;
    std::vector<std::string> key_names;
    keygen->add_option("directory", key_directory, "where to write the key files")->required();
    keygen->add_option("--participants", key_names, "participant names, comma separated")
        ->delimiter(',')
        ->required();

    auto *wheel_stl = app.add_subcommand(
        "wheel-stl", "write a scenario's parametric wheel as STL (the mesh the grains touch)");
    std::string stl_path;
    bool stl_binary = false;
    wheel_stl->add_option("scenario", scenario_path, "scenario YAML with a rig.wheel block")
        ->required();
    wheel_stl->add_option("stl", stl_path, "STL file to write")->required();
    wheel_stl->add_flag("--binary", stl_binary, "binary STL (default ASCII)");

    grainlink::apps::ParamsOptions params_options;
    auto *params = app.add_subcommand(
        "params", "derive DEM parameters from a soil and test description (docs/lab.md)");
    params->add_option("description", params_options.input_path, "soil and test YAML");
    params->add_option("--friction-angle", params_options.friction_angle_deg,
                       "instead of a description: propose (phi, gamma) for this macroscopic "
                       "friction angle [deg] from the soil table");
    params->add_option("--repose-angle", params_options.repose_angle_deg,
                       "with --friction-angle: also match this angle of repose [deg]");
    params->add_option("--table", params_options.table_path,
                       "soil table CSV (default: the data/soil_table.csv grainlink ships)");
    params->add_option("--out", params_options.output_path,
                       "matrix file, .yaml or .csv (default out/params/<name>.yaml)");

    grainlink::apps::SoilTableCommandOptions table_options;
    auto *soil_table = app.add_subcommand(
        "soil-table", "run the direct shear (and repose) test over a (phi, gamma) grid and write "
                      "the lookup table (docs/lab.md)");
    soil_table->add_option("spec", table_options.spec_path, "table spec YAML")->required();
    soil_table->add_option("--out", table_options.output_path, "table CSV")->required();
    soil_table->add_option("--runs", table_options.runs_directory,
                           "keep each grid point's lab outputs under this directory");
    soil_table->add_option("--progress-interval", table_options.progress_interval_s,
                           "seconds between progress lines");

    grainlink::apps::LabOptions lab_options;
    auto *lab = app.add_subcommand("lab", "virtual soil laboratory test (docs/lab.md)");
    lab->add_option("test", lab_options.test,
                    "the test: bevameter, repose, direct_shear, bevameter_shear or wheel")
        ->required()
        ->check(CLI::IsMember(grainlink::lab::labTestNames()));
    lab->add_option("scenario", lab_options.scenario_path, "lab scenario YAML")->required();
    lab->add_option("--out", lab_options.output_directory, "output directory (default out/<name>)");
    lab->add_option("--progress-interval", lab_options.progress_interval_s,
                    "seconds between progress lines");
    lab->add_option("--check", lab_options.check,
                    "rerun on a wider box (walls), finer grains (resolution) or both and report "
                    "how far the answers moved")
        ->check(CLI::IsMember({"walls", "resolution", "both"}));
    lab->add_flag("--no-plot", lab_options.no_plot,
                  "skip the plot (a study's and the diagnosis' runs: they read only "
                  "summary.json, and a plot costs about a fifth of a small test's time)");
    lab->add_option("--check-factor", lab_options.check_factor,
                    "box width factor (> 1, default 2) or grain radius factor (< 1, default 0.75)");

    grainlink::apps::NodeOptions node;
    auto *mbs_node = app.add_subcommand(
        "mbs-node", "the multibody participant (started by run): the Simbody single-wheel rig, "
                    "rover, mole or a URDF model, whichever the scenario names");
    auto *dem_node =
        app.add_subcommand("dem-node", "the DEM soil as a soil participant (started by run)");
    auto *floor_node = app.add_subcommand(
        "floor-node", "a rigid flat floor as the soil participant (verification; started by run)");
    for (auto *command : {mbs_node, dem_node, floor_node}) {
        command->add_option("scenario", node.scenario_path, "coupled scenario YAML")->required();
        command->add_option("--name", node.name, "participant name")->required();
        command->add_option("--endpoint", node.endpoint, "the coordinator's endpoint")->required();
        command->add_option("--out", node.output_directory, "output directory")->required();
        command->add_option("--keys", node.keys_directory, "CURVE keys directory");
    }
    // Every node prints progress lines; `grainlink run --progress-interval` reaches the nodes it
    // starts through GRAINLINK_PROGRESS_INTERVAL, which a node's own flag overrides.
    for (auto *command : {mbs_node, dem_node, floor_node})
        command
            ->add_option("--progress-interval", node.progress_interval_s,
                         "seconds between progress lines (default: the run's "
                         "--progress-interval, else 10; 0: none)")
            ->check(CLI::NonNegativeNumber);
    for (auto *command : {dem_node, floor_node})
        command->add_option("--bodies", node.bodies, "the coupled bodies it loads (comma separated)")
            ->delimiter(',')
            ->required();
    dem_node->add_option("--section", node.section,
                         "the scenario section of its bed (default soil; one per soil node when "
                         "several share the bodies)");

    grainlink::apps::StudyCommand study(app);
    grainlink::apps::GapCommand gap(app);

    // --threads on every command that runs grains: it overrides the scenarios' threads, in this
    // process and in the processes it starts (a run's participants), through GRAINLINK_THREADS.
    int threads = 0;
    for (CLI::App *command : {dem, run, lab, soil_table, dem_node})
        command->add_option("--threads", threads,
                            "threads per DEM run, overriding the scenario's simulation.threads "
                            "(default: the scenario's, else OMP_NUM_THREADS, else 1)")
            ->check(CLI::Range(1, 1024));

    CLI11_PARSE(app, argc, argv);
    if (threads > 0)
        ::setenv("GRAINLINK_THREADS", std::to_string(threads).c_str(), 1);
    if (run->count("--progress-interval") > 0) {
        char value[32];
        std::snprintf(value, sizeof value, "%.17g", coupled.progress_interval_s);
        ::setenv("GRAINLINK_PROGRESS_INTERVAL", value, 1);
    }
    for (auto *command : {mbs_node, dem_node, floor_node})
        if (command->parsed() && command->count("--progress-interval") == 0)
            if (const char *inherited = std::getenv("GRAINLINK_PROGRESS_INTERVAL")) {
                char *end = nullptr;
                node.progress_interval_s = std::strtod(inherited, &end);
                if (end == inherited || *end != '\0' || !std::isfinite(node.progress_interval_s) ||
                    node.progress_interval_s < 0.0) {
                    std::fprintf(stderr,
                                 "%s: error: GRAINLINK_PROGRESS_INTERVAL = '%s' is not a number of "
                                 "seconds >= 0\n",
                                 node.name.c_str(), inherited);
                    return 1;
                }
            }
    try {
        if (dem->parsed()) {
            const auto scenario = grainlink::dem::loadScenario(scenario_path);
            grainlink::dem::RunOptions options;
            options.output_directory = out_dir.empty() ? "out/" + scenario.name : out_dir;
            options.resume = resume;
            options.progress_interval_s = progress_s;
            grainlink::dem::runScenario(scenario, options);
        } else if (run->parsed()) {
            return grainlink::apps::runCoupled(coupled);
        } else if (coordinator->parsed()) {
            return grainlink::apps::runCoordinator(coupled);
        } else if (mbs_node->parsed()) {
            return grainlink::apps::runMultibodyNode(node);
        } else if (dem_node->parsed()) {
            return grainlink::apps::runSoilNode(node);
        } else if (floor_node->parsed()) {
            return grainlink::apps::runFloorNode(node);
        } else if (wheel_stl->parsed()) {
            return grainlink::apps::exportWheelStl(scenario_path, stl_path, stl_binary);
        } else if (params->parsed()) {
            return grainlink::apps::runParams(params_options);
        } else if (soil_table->parsed()) {
            return grainlink::apps::runSoilTable(table_options);
        } else if (lab->parsed()) {
            return grainlink::apps::runLab(lab_options);
        } else if (study.parsed()) {
            return study.run();
        } else if (gap.parsed()) {
            return gap.run();
        } else if (keygen->parsed()) {
            return grainlink::apps::generateKeys(key_directory, key_names);
        }
    } catch (const std::exception &e) {
        // A participant node's line names the participant (its run has several processes).
        const bool node_command = mbs_node->parsed() || dem_node->parsed() || floor_node->parsed();
        std::fprintf(stderr, "%s: error: %s\n", node_command ? node.name.c_str() : "grainlink",
                     e.what());
        return 1;
    }
    return 0;
}
