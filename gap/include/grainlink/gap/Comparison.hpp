#pragma once
// What is compared: the features of a measurement set (every experiment's observables on bins
// shared by its kind), the measured value and uncertainty of each, and the same features of any
// simulated set of curves (docs/gap.md, "Features").
#include "grainlink/gap/Discrepancy.hpp"
#include "grainlink/gap/Experiments.hpp"
#include "grainlink/gap/Validation.hpp"

#include <Eigen/Core>

#include <map>
#include <string>
#include <vector>

namespace grainlink::gap {

/// Simulated curves of one run of the design: experiment id -> observable -> curve (for a
/// scatter experiment, one point per simulated condition, x = the condition).
using SimulatedCurves = std::map<std::string, std::map<std::string, Curve>>;

struct FeatureDesign {
    std::vector<FeatureKey> keys;
    /// Bin edges per experiment and observable ("id/observable"); empty for a scalar.
    std::map<std::string, std::vector<double>> edges;
    /// The x reached by at least half of an experiment's trials (the simulation must reach it).
    std::map<std::string, double> x_reach;
    /// Indices of keys per experiment id.
    std::map<std::string, std::vector<Eigen::Index>> by_experiment;
    std::size_t size() const { return keys.size(); }
};

/// Bins for every experiment: `bins` equal, round bins per kind (or the experiment's own
/// `bins:`), from x = 0 (slip: from the smallest measured slip) to about the median reach of
/// the kind's experiments; each experiment keeps the bins at least half of its trials cover.
FeatureDesign designFeatures(const ExperimentSet &set, int bins = 6);

/// Measured values and their uncertainty u_D on the design (docs/gap.md, "Uncertainty of the
/// measurement").
Measured measure(const ExperimentSet &set, const FeatureDesign &design);

/// The design's features of one simulated run (NaN where the run does not cover a bin).
Eigen::VectorXd simulatedFeatures(const ExperimentSet &set, const FeatureDesign &design,
                                  const SimulatedCurves &curves);

/// Regime coordinates of the design's features for the null model: the bin centre, every
/// numeric condition and every text condition of its experiment, scaled by their range over
/// the `reference` features (the calibration; empty: all).
std::vector<RegimePoint> regimePoints(const ExperimentSet &set, const FeatureDesign &design,
                                      const std::vector<bool> &reference = {});

/// How each kind's x axis is written in reports.
std::map<std::string, AxisLabel> axisLabels(const ExperimentSet &set);

} // namespace grainlink::gap
