#pragma once
// The force servo lives in dem/ (the compaction plate of a bed's preparation uses it too); the
// lab tests keep their name for it.
#include "grainlink/dem/LoadServo.hpp"

namespace grainlink::lab {
using dem::LoadServo;
} // namespace grainlink::lab
