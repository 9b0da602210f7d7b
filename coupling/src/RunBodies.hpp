#pragma once
// The run's bodies, collected from the participants' Hellos and checked: each body provided by
// one multibody participant with its initial state, consumed by one soil participant, and every
// participant able to do what the scheme asks of it. A pure function: no sockets, no state.
// Internal to coupling/.
#include "grainlink/coupling/Types.hpp"

#include <string>
#include <vector>

namespace grainlink::coupling {

/// What one participant declared in its Hello.
struct Declaration {
    std::string name;
    Role role = Role::Multibody;
    std::vector<BodyDescription> provides; ///< multibody
    std::vector<BodyState> initial_states; ///< multibody: one per provided body, same order
    std::vector<std::string> consumes;     ///< soil
    Capabilities capabilities;
};

/// What the run asks of every participant beyond its bodies.
struct RunNeeds {
    SchemeKind scheme = SchemeKind::ExplicitSerial; ///< implicit: everyone must roll back
    unsigned checkpoint_every_windows = 0;          ///< > 0: everyone must write checkpoints
};

struct RunBodies {
    std::vector<BodyDescription> bodies;   ///< in the order the participants provided them
    std::vector<std::string> names;        ///< of `bodies`
    std::vector<BodyState> initial_states; ///< of `bodies`
    /// Per participant (in the order given): the bodies (indices into `bodies`) whose inputs it
    /// gets, and the names it must answer for in each WindowDone (what it provides or consumes).
    std::vector<std::vector<std::size_t>> inputs;
    std::vector<std::vector<std::string>> outputs;
};

/// Throws PeerError naming the participant at fault.
RunBodies collectBodies(const std::vector<Declaration> &participants, const RunNeeds &needs);

} // namespace grainlink::coupling
