#pragma once
// Data whose cause is known (docs/gap.md, "Proof on data whose effect is withheld"): a twin is
// a measurements folder simulated from the base model with one effect hidden in it (or none,
// or one outside the catalogue), on a design of experiments, with noise; the effect and its
// strength go to a key file beside the folder that the diagnosis never reads. The self-test
// runs the diagnosis blind on many twins and scores it against their keys.
#include "grainlink/gap/Effects.hpp"
#include "grainlink/gap/StudySimulator.hpp"

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace grainlink::gap {

/// A design: experiments with their conditions and how far each reaches, no data
/// (design.yaml, docs/gap.md). `repeats` per experiment id.
struct Design {
    ExperimentSet set; ///< each experiment with one flat stand-in trial over its reach
    std::map<std::string, int> repeats;
};
Design loadDesign(const std::string &path);

struct TwinKey {
    std::string effect; ///< "" for a null twin
    double strength = 0.0;
    bool in_catalogue = true;
    unsigned seed = 0;
    double noise = 0.0, level_noise = 0.0;
    bool own_beds = false; ///< every experiment on beds of its own (`beds: own` in the folder)
};

struct TwinOptions {
    std::string effect;             ///< "" with !random: a null twin
    std::optional<double> strength; ///< none: drawn from the prior
    unsigned seed = 1;              ///< the beds' seeds and the draws
    double noise = 0.01;            ///< relative sd of every sample
    double level_noise = 0.02;      ///< relative sd of a trial's level (its calibration)
    /// Every experiment's repeats on beds of its own, as a test bed rebuilt for every trial;
    /// otherwise trial t of every experiment of a group is made on bed t.
    bool own_beds = false;
};

/// Which part of an effect's prior a twin's strength is drawn from.
enum class StrengthDraw {
    Prior,   ///< uniformly over the whole prior
    FarHalf, ///< over the half of each side of "off" that lies farther from it
};

/// Draws a strength uniformly on the effect's prior (on its own scale), or on its far half: a
/// draw at distance d from off on a side of length L is moved to L/2 + d/2 (an off outside the
/// prior counts from the nearer end). Each strength in `failed` (a twin that could not be
/// simulated there) cuts the prior at it: that strength and all beyond it on its side of off
/// are left out, the effect taken to grow harder to simulate the stronger it is.
double drawStrength(const Effect &effect, unsigned seed, StrengthDraw draw = StrengthDraw::Prior,
                    const std::vector<double> &failed = {});

/// Writes a twin's measurements folder `out` (experiments.yaml + data/) from its simulated
/// repeats (`curves[r]`: repeat r's curves per experiment id and observable) with the key's
/// noise (its seed draws it), and the key to `key_path`; reads the folder back strictly.
void writeTwin(const Design &design, const std::vector<SimulatedCurves> &curves, const TwinKey &key,
               const std::string &out, const std::string &key_path);

/// The simulation a twin's data come from (`effect` the key's, null for a null twin): every
/// repeat of the design on the twin's own beds, not the ones the diagnosis simulates.
VariantRequest twinRequest(const Design &design, const TwinKey &key, const Effect *effect);

/// Simulates the twin into `out` (writeTwin) and returns its key.
TwinKey makeTwin(const Design &design, const EffectCatalogue &catalogue, StudySimulator &simulator,
                 const TwinOptions &options, const std::string &out, const std::string &key_path);

} // namespace grainlink::gap
