#pragma once
// What the multibody-side participants share: a model's states on the wire and its participant
// configuration (its coupled bodies' descriptions need no translation: the model's are the
// handshake's).
#include "Nodes.hpp"
#include "grainlink/coupling/Types.hpp"
#include "grainlink/dem/Series.hpp"
#include "grainlink/mbs/MultibodyModel.hpp"

#include <fstream>
#include <optional>
#include <string>
#include <vector>

namespace grainlink::apps {

inline coupling::BodyState toCoupling(const std::string &name, const mbs::RigidState &s) {
    coupling::BodyState out;
    out.body = name;
    out.position_m = s.position_m;
    out.orientation = s.orientation;
    out.linear_velocity_m_s = s.linear_velocity_m_s;
    out.angular_velocity_rad_s = s.angular_velocity_rad_s;
    return out;
}

/// The multibody participant of the scenario `root` for `model`: its coupled bodies exactly as
/// the model describes them, their initial states, rollback and checkpoints.
inline coupling::ParticipantConfig multibodyParticipantConfig(const NodeOptions &options,
                                                              const config::ConfigNode &root,
                                                              const mbs::MultibodyModel &model) {
    coupling::ParticipantConfig config;
    config.handshake_timeout_s = handshakeTimeout(root);
    config.name = options.name;
    config.role = coupling::Role::Multibody;
    config.endpoint = options.endpoint;
    config.provides = model.coupledBodies(); // the model's own descriptions, unchanged
    const auto states = model.bodyStates();
    for (std::size_t b = 0; b < config.provides.size(); ++b)
        config.initial_states.push_back(toCoupling(config.provides[b].name, states[b]));
    config.capabilities.rollback = true;
    config.capabilities.checkpoint = true;
    if (!options.keys_directory.empty())
        config.curve = coupling::loadClientKeys(options.keys_directory, options.name);
    return config;
}

} // namespace grainlink::apps
