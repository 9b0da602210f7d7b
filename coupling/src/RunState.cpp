#include "RunState.hpp"

#include <cstdio>

namespace grainlink::coupling {

const char *stateName(Coordinator::State state) {
    switch (state) {
    case Coordinator::State::Bound:
        return "bound";
    case Coordinator::State::Handshake:
        return "handshake";
    case Coordinator::State::Running:
        return "running";
    case Coordinator::State::Finished:
        return "finished";
    case Coordinator::State::Failed:
        return "failed";
    }
    return "?";
}

const char *RunState::whatToDo() const {
    switch (state_.load()) {
    case State::Bound:
        return "call run()";
    case State::Handshake:
    case State::Running:
        return "run() is already running: wait for it to return";
    case State::Finished:
        return "the run is over and a coordinator runs once: construct a new Coordinator for "
               "another run";
    case State::Failed:
        return "the run failed and a coordinator runs once: construct a new Coordinator (with "
               "resume = true to continue from the last checkpoint)";
    }
    return "";
}

void RunState::enter(State next) {
    const State now = state_;
    const bool allowed = next == State::Failed ||
                         (now == State::Bound && next == State::Handshake) ||
                         (now == State::Handshake && next == State::Running) ||
                         (now == State::Running && next == State::Finished);
    if (!allowed)
        throw LifecycleError(std::string("coordinator: cannot go from state '") + stateName(now) +
                             "' to '" + stateName(next) + "'; " + whatToDo());
    state_ = next;
}

std::string RunState::where() const {
    const State now = state_;
    if (now == State::Bound || now == State::Handshake)
        return "during the handshake";
    char t[32];
    std::snprintf(t, sizeof t, "%.6g", tick * tick_s_);
    return "in window " + std::to_string(window) + " (t = " + t + " s)";
}

std::string RunState::failure(const std::string &who, const std::string &why) const {
    return who + " failed " + where() + ": " + why;
}

} // namespace grainlink::coupling
