#pragma once
// One spelling of "no value" for the gap's sources: a figure not computed, or not measured.
#include <limits>

namespace grainlink::gap {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

} // namespace grainlink::gap
