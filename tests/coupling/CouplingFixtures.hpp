#pragma once
// Shared set-up of the networked coupling tests: the two-mass run's coordinator configuration and
// one side of it started on its own thread.
#include "TwoMassParticipant.hpp"
#include "grainlink/coupling/Coordinator.hpp"

#include <unistd.h>

#include <filesystem>
#include <future>
#include <string>

namespace grainlink::testing {

/// A fresh directory per test process (ctest runs test cases in parallel processes).
inline std::string scratch(const std::string &name) {
    const auto dir = std::filesystem::temp_directory_path() /
                     ("grainlink-coupling-" + std::to_string(::getpid())) / name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir.string();
}

/// The error a coordinator's run stops with.
inline std::string failureOf(coupling::Coordinator &coordinator) {
    try {
        coordinator.run();
    } catch (const coupling::CouplingError &e) {
        return e.what();
    }
    return "(the run did not fail)";
}

/// The error a participant's side (started on its own thread) stops with.
template <typename T> std::string failureOf(std::future<T> &side) {
    try {
        side.get();
    } catch (const std::exception &e) {
        return e.what();
    }
    return "(the participant did not fail)";
}

inline coupling::CoordinatorConfig
twoMassRun(coupling::SchemeKind kind, const std::string &endpoint, double window_s, double end_s) {
    coupling::CoordinatorConfig c;
    c.endpoint = endpoint;
    c.participants = {{"mbs", coupling::Role::Multibody, {}, false},
                      {"soil", coupling::Role::Soil, {}, false}};
    c.scheme.kind = kind;
    c.macro_step_s = window_s;
    c.end_time_s = end_s;
    c.handshake_timeout_s = 10;
    return c;
}

/// One side ("mbs" multibody or "soil") running on its own thread; the future holds mass x.
inline std::future<double> startSide(coupling::Role role, const std::string &endpoint,
                                     examples::SideHooks hooks = {}, double peer_timeout_s = 5.0) {
    return std::async(std::launch::async, [=] {
        auto config = examples::twoMassConfig(
            role, role == coupling::Role::Multibody ? "mbs" : "soil", endpoint);
        config.peer_timeout_s = peer_timeout_s;
        // A coordinator that fails its handshake before this side joined cannot tell it: the
        // side then gives up after this long.
        config.handshake_timeout_s = 10.0;
        coupling::Participant p(config);
        return examples::runTwoMassSide(p, {}, hooks);
    });
}

} // namespace grainlink::testing
