#include "RunBodies.hpp"

#include "OutputCheck.hpp"
#include "RunState.hpp"

#include <algorithm>
#include <map>

namespace grainlink::coupling {

namespace {

std::string who(const Declaration &d) {
    return "participant '" + d.name + "'";
}

} // namespace

RunBodies collectBodies(const std::vector<Declaration> &participants, const RunNeeds &needs) {
    RunBodies run;
    std::map<std::string, std::string> provider, consumer;
    for (const auto &p : participants)
        for (std::size_t b = 0; b < p.provides.size(); ++b) {
            const auto &body = p.provides[b];
            if (provider.count(body.name))
                throw PeerError(who(p), "provides body '" + body.name + "', which '" +
                                            provider[body.name] + "' provides already");
            provider[body.name] = p.name;
            if (b >= p.initial_states.size() || p.initial_states[b].body != body.name)
                throw PeerError(who(p), "gave no initial state for body '" + body.name + "'");
            if (const auto problem = checkOutputs(std::vector{p.initial_states[b]}, {body.name}))
                throw PeerError(who(p), "gave a " + problem->text + " in its Hello");
            run.bodies.push_back(body);
            run.names.push_back(body.name);
            run.initial_states.push_back(p.initial_states[b]);
        }
    for (const auto &p : participants)
        for (const auto &name : p.consumes) {
            if (!provider.count(name))
                throw PeerError(who(p), "consumes body '" + name +
                                            "', which no multibody participant provides");
            if (consumer.count(name))
                throw PeerError(who(p), "consumes body '" + name + "', which '" + consumer[name] +
                                            "' consumes already");
            consumer[name] = p.name;
        }
    for (const auto &[name, by] : provider)
        if (!consumer.count(name))
            throw PeerError("participant '" + by + "'",
                            "provides body '" + name + "', which no soil participant consumes");
    for (const auto &p : participants)
        if (needs.scheme == SchemeKind::Implicit && !p.capabilities.rollback)
            throw PeerError(who(p), "cannot roll back its state, which implicit coupling needs");
    for (const auto &p : participants)
        if (needs.checkpoint_every_windows > 0 && !p.capabilities.checkpoint)
            throw PeerError(who(p), "cannot write checkpoints, but checkpoint_every_windows = " +
                                        std::to_string(needs.checkpoint_every_windows));
    for (const auto &p : participants) {
        std::vector<std::string> outputs;
        if (p.role == Role::Multibody)
            for (const auto &b : p.provides)
                outputs.push_back(b.name);
        else
            outputs = p.consumes;
        std::vector<std::size_t> inputs;
        for (std::size_t b = 0; b < run.names.size(); ++b)
            if (std::find(outputs.begin(), outputs.end(), run.names[b]) != outputs.end())
                inputs.push_back(b);
        run.inputs.push_back(std::move(inputs));
        run.outputs.push_back(std::move(outputs));
    }
    return run;
}

} // namespace grainlink::coupling
