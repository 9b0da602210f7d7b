#pragma once
// Frames that turn a Simbody joint's own axis (x for a slider, z for a pin) onto a body or Ground
// axis while the body frame stays parallel to its parent's: shared by the built-in models.
#include <Simbody.h>

namespace grainlink::mbs {

inline const SimTK::Rotation kXToZ(-SimTK::Pi / 2, SimTK::YAxis); ///< slider axis x -> z
inline const SimTK::Rotation kZToY(-SimTK::Pi / 2, SimTK::XAxis); ///< pin axis z -> y

} // namespace grainlink::mbs
