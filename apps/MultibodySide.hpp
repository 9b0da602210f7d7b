#pragma once
// What the multibody-side participants share: a model's states on the wire. (Its coupled
// bodies' descriptions need no translation: the model's are the handshake's.)
#include "Series.hpp"
#include "grainlink/coupling/Types.hpp"
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

} // namespace grainlink::apps
