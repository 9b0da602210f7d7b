#pragma once
// The one check of a window's outputs, run by both sides: by a participant before it sends them,
// by the coordinator when they arrive. Internal to coupling/.
#include "grainlink/coupling/Types.hpp"

#include <optional>
#include <string>
#include <vector>

namespace grainlink::coupling {

/// What is wrong with a window's states or wrenches; each side words it for its own message.
struct OutputProblem {
    enum class Kind {
        NonFinite,   ///< text: "non-finite wrench on body 'mass1'"
        WrongBodies, ///< text: "wrenches for { wheel } but must give exactly one for each of ..."
    };
    Kind kind;
    std::string text;
};

/// Nothing when every value is finite and `outputs` names each of `expected` exactly once (in
/// any order; the usual case, the same order, costs one comparison per body).
std::optional<OutputProblem> checkOutputs(const std::vector<BodyState> &outputs,
                                          const std::vector<std::string> &expected);
std::optional<OutputProblem> checkOutputs(const std::vector<Wrench> &outputs,
                                          const std::vector<std::string> &expected);

} // namespace grainlink::coupling
