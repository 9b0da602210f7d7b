#pragma once
// The effect catalogue grainlink ships (data/effects.yaml), as the gap tests read it.
#include "grainlink/gap/Effects.hpp"

inline grainlink::gap::EffectCatalogue shippedEffects() {
    return grainlink::gap::loadEffects(GRAINLINK_SOURCE_DIR "/data/effects.yaml");
}
