// The coordinator's YAML: `coupling:` (how to couple) and `participants:` (who takes part).
// Every key is documented in docs/protocol.md §Configuration.
#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/coupling/Coordinator.hpp"

#include <filesystem>

namespace grainlink::coupling {

namespace {

using config::ConfigNode;

/// A path in the file, relative to the file's own folder.
std::string besideFile(const ConfigNode &node) {
    const std::filesystem::path value = node.text();
    if (value.is_absolute())
        return value.string();
    return (std::filesystem::path(node.file()).parent_path() / value).string();
}

SchemeKind schemeFrom(const ConfigNode &node) {
    const std::string name = node.choice({"explicit-serial", "explicit-parallel", "implicit"});
    if (name == "explicit-serial")
        return SchemeKind::ExplicitSerial;
    if (name == "explicit-parallel")
        return SchemeKind::ExplicitParallel;
    return SchemeKind::Implicit;
}

unsigned count(const ConfigNode &node, long long minimum) {
    return static_cast<unsigned>(node.integer(minimum, std::numeric_limits<unsigned>::max()));
}

} // namespace

CoordinatorConfig coordinatorConfigFrom(const ConfigNode &root) {
    CoordinatorConfig c;
    const ConfigNode coupling = root["coupling"];
    c.endpoint = coupling.text("endpoint", ""); // empty: the command picks its default
    c.insecure = coupling.boolean("insecure", false);
    if (auto keys = coupling.optional("keys_directory"))
        c.curve = loadServerKeys(besideFile(*keys));
    c.scheme.kind = schemeFrom(coupling["scheme"]);
    c.tick_s = coupling.has("tick_s") ? coupling["tick_s"].positive() : c.tick_s;
    c.start_time_s = coupling.number("start_time_s", 0.0);
    c.end_time_s = coupling["end_time_s"].number();
    c.macro_step_s = coupling["macro_step_s"].positive();
    // Time is counted in whole ticks (64-bit); past 1e15 of them a double no longer holds every
    // tick and the count overflows: a run would end at once, 'complete'.
    if (!((c.end_time_s - c.start_time_s) / c.tick_s <= kMaxTicks))
        coupling[coupling.has("tick_s") ? "tick_s" : "end_time_s"].fail(
            "the run would be more than 1e15 ticks long: raise tick_s or shorten end_time_s");
    if (auto adaptive = coupling.optional("adaptive")) {
        c.min_macro_step_s = (*adaptive)["min_macro_step_s"].positive();
        c.max_macro_step_s = (*adaptive)["max_macro_step_s"].positive();
        if (c.min_macro_step_s > c.max_macro_step_s)
            adaptive->fail("min_macro_step_s must not exceed max_macro_step_s");
        adaptive->finish();
    }
    if (auto guard = coupling.optional("guard")) {
        auto &g = c.guard;
        g.enabled = guard->boolean("enabled", true);
        if (guard->has("energy_ratio"))
            g.energy_ratio = (*guard)["energy_ratio"].positive();
        g.oscillation_autocorrelation =
            guard->number("oscillation_autocorrelation", g.oscillation_autocorrelation);
        if (!(g.oscillation_autocorrelation > -1.0 && g.oscillation_autocorrelation < 1.0))
            (*guard)["oscillation_autocorrelation"].fail("must lie in (-1, 1)");
        if (guard->has("bounce_energy_share"))
            g.bounce_energy_share = (*guard)["bounce_energy_share"].positive();
        if (guard->has("bounce_spans"))
            g.bounce_spans = count((*guard)["bounce_spans"], 1);
        if (guard->has("span_windows"))
            g.span_windows = count((*guard)["span_windows"], 3);
        g.shorten = guard->boolean("shorten", false);
        if (g.shorten && !coupling.has("adaptive"))
            (*guard)["shorten"].fail("the coordinator shortens the macro step within "
                                     "coupling.adaptive's bounds: set min_macro_step_s and "
                                     "max_macro_step_s there");
        guard->finish();
    }
    if (auto implicit = coupling.optional("implicit")) {
        if (c.scheme.kind != SchemeKind::Implicit)
            implicit->fail("settings for implicit coupling, but scheme is not implicit");
        auto &s = c.scheme;
        if (implicit->has("relative_tolerance"))
            s.relative_tolerance = (*implicit)["relative_tolerance"].positive();
        s.absolute_tolerance = implicit->number("absolute_tolerance", s.absolute_tolerance);
        if (implicit->has("max_iterations"))
            s.max_iterations = count((*implicit)["max_iterations"], 1);
        if (auto name = implicit->optional("acceleration"))
            s.acceleration.kind =
                accelerationFromName(name->choice({"constant", "aitken", "iqn-ils"}));
        if (implicit->has("initial_relaxation"))
            s.acceleration.initial_relaxation = (*implicit)["initial_relaxation"].positive();
        if (implicit->has("reuse_windows")) {
            if (s.acceleration.kind != AccelerationKind::IqnIls) // the others keep no history
                (*implicit)["reuse_windows"].fail("only acceleration: iqn-ils reuses past "
                                                  "windows: remove the key");
            s.acceleration.reuse_windows = count((*implicit)["reuse_windows"], 0);
        }
        implicit->finish();
    }
    if (coupling.has("heartbeat_interval_s"))
        c.heartbeat_interval_s = coupling["heartbeat_interval_s"].positive();
    if (coupling.has("peer_timeout_s"))
        c.peer_timeout_s = coupling["peer_timeout_s"].positive();
    if (coupling.has("window_timeout_s"))
        c.window_timeout_s = coupling["window_timeout_s"].positive();
    if (coupling.has("handshake_timeout_s"))
        c.handshake_timeout_s = coupling["handshake_timeout_s"].positive();
    if (c.peer_timeout_s < 3 * c.heartbeat_interval_s)
        coupling["peer_timeout_s"].fail("must be at least three heartbeat intervals");
    if (coupling.has("checkpoint_every_windows"))
        c.checkpoint_every_windows = count(coupling["checkpoint_every_windows"], 0);
    if (auto limits = coupling.optional("limits")) {
        auto &l = c.limits;
        if (limits->has("max_message_bytes"))
            l.max_message_bytes = count((*limits)["max_message_bytes"], 1024);
        if (limits->has("max_bodies"))
            l.max_bodies = count((*limits)["max_bodies"], 1);
        if (limits->has("max_name_bytes"))
            l.max_name_bytes = count((*limits)["max_name_bytes"], 1);
        if (limits->has("max_stranger_messages_per_s"))
            l.max_stranger_messages_per_s = count((*limits)["max_stranger_messages_per_s"], 1);
        limits->finish();
    }
    // A heartbeat connection beats once an interval: three times that rate is never a flood.
    if (c.limits.max_stranger_messages_per_s < 3.0 / c.heartbeat_interval_s) {
        const auto limits = coupling.optional("limits");
        if (limits && limits->has("max_stranger_messages_per_s"))
            (*limits)["max_stranger_messages_per_s"].fail(
                "must be at least three heartbeats per heartbeat_interval_s");
        coupling["heartbeat_interval_s"].fail(
            "beats faster than limits.max_stranger_messages_per_s / 3 allows");
    }
    coupling.finish();

    for (const auto &item : root["participants"].items()) {
        ParticipantSpec p;
        p.name = item["name"].text();
        p.role = item["role"].choice({"multibody", "soil"}) == "multibody" ? Role::Multibody
                                                                           : Role::Soil;
        p.external = item.boolean("external", false);
        if (auto command = item.optional("command")) {
            if (p.external)
                command->fail("an external participant is started by the user, not by a command");
            for (const auto &arg : command->items())
                p.command.push_back(arg.text());
            if (p.command.empty())
                command->fail("give the program and its arguments as a list");
        }
        item.finish();
        c.participants.push_back(std::move(p));
    }
    return c;
}

CoordinatorConfig loadCoordinatorConfig(const std::string &path) {
    const ConfigNode root = ConfigNode::loadFile(path);
    CoordinatorConfig c = coordinatorConfigFrom(root);
    root.finish();
    return c;
}

} // namespace grainlink::coupling
