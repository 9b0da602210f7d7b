// grainlink-two-mass-node: one side of the two-mass example as its own process.
// `grainlink run scenarios/coupling/two_mass.yaml` starts two of them; the fault options let the
// tests play a participant that dies, hangs or freezes.
#include "TwoMassParticipant.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>

int main(int argc, char **argv) {
    using namespace grainlink;
    CLI::App app{"one side of the two-mass coupling example"};
    std::string side, name, endpoint = "tcp://127.0.0.1:5555", keys;
    examples::SideHooks misbehave;
    app.add_option("--side", side, "multibody (mass 1) or soil (mass 2 and the coupling spring)")
        ->required()
        ->check(CLI::IsMember({"multibody", "soil"}));
    app.add_option("--name", name, "participant name (default: the side)");
    app.add_option("--endpoint", endpoint, "the coordinator's endpoint");
    app.add_option("--keys", keys, "directory with <name>.key and coordinator.pub (CURVE)");
    auto *faults = app.add_option_group("fault injection", "for the coordinator's fault tests");
    faults->add_option("--die-at-window", misbehave.die_at_window, "SIGKILL itself here");
    faults->add_option("--hang-at-window", misbehave.hang_at_window, "never finish this window");
    faults->add_option("--freeze-at-window", misbehave.freeze_at_window, "SIGSTOP itself here");
    faults->add_option("--throw-at-window", misbehave.throw_at_window,
                       "the model throws here (its message reaches the coordinator)");
    CLI11_PARSE(app, argc, argv);
    if (name.empty())
        name = side;
    try {
        const auto role = side == "multibody" ? coupling::Role::Multibody : coupling::Role::Soil;
        auto config = examples::twoMassConfig(role, name, endpoint);
        if (!keys.empty())
            config.curve = coupling::loadClientKeys(keys, name);
        coupling::Participant participant(config);
        const double x = examples::runTwoMassSide(participant, {}, misbehave);
        std::printf("%s: done, x = %.9f m\n", name.c_str(), x);
    } catch (const std::exception &e) {
        std::fprintf(stderr, "%s: error: %s\n", name.c_str(), e.what());
        return 1;
    }
    return 0;
}
