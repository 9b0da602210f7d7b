#include "grainlink/gap/Comparison.hpp"

#include "NotANumber.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace grainlink::gap {

namespace {

std::string slot(const std::string &id, const std::string &observable) {
    return id + "/" + observable;
}

/// Each trial's curve of `observable` with the experiment's zero applied.
std::vector<Curve> zeroedTrials(const Experiment &e, const std::string &observable) {
    std::vector<Curve> out;
    for (const Trial &t : e.trials) {
        const auto it = t.curves.find(observable);
        if (it != t.curves.end())
            out.push_back(applyZero(it->second, e.zero));
    }
    return out;
}

double lowerMedian(std::vector<double> v) {
    if (v.empty())
        return kNaN;
    std::sort(v.begin(), v.end());
    return v[(v.size() - 1) / 2];
}

std::vector<std::pair<double, double>> scatterPoints(const Experiment &e,
                                                     const std::string &observable) {
    std::vector<std::pair<double, double>> p;
    for (const Trial &t : e.trials) {
        const auto it = t.curves.find(observable);
        if (it != t.curves.end() && !it->second.empty())
            p.emplace_back(it->second.x[0], it->second.y[0]);
    }
    return p;
}

/// Whether a run at x falls in the key's bin: [lo, hi), the experiment's last bin [lo, hi],
/// as `scatterBinMeans` bins (a run on an inner edge counts in one bin, where the simulated
/// slips were chosen).
bool inScatterBin(const FeatureDesign &design, const FeatureKey &key, double x) {
    const auto edges = design.edges.find(slot(key.experiment, key.observable));
    const bool last =
        edges != design.edges.end() && !edges->second.empty() && key.x_hi == edges->second.back();
    return x >= key.x_lo && (x < key.x_hi || (last && x == key.x_hi));
}

} // namespace

FeatureDesign designFeatures(const ExperimentSet &set, int bins) {
    FeatureDesign d;
    // Per kind: where its curves start and how far they typically reach.
    std::map<std::string, std::vector<double>> reaches, starts;
    for (const Experiment &e : set.experiments)
        for (const auto &o : e.observables) {
            if (e.x_name.empty())
                continue;
            if (e.scatter) {
                for (const auto &[x, y] : scatterPoints(e, o)) {
                    reaches[e.kind(o)].push_back(x);
                    starts[e.kind(o)].push_back(x);
                }
                d.x_reach[slot(e.id, o)] = kNaN;
                continue;
            }
            std::vector<double> maxima;
            for (const Curve &c : zeroedTrials(e, o))
                if (!c.empty())
                    maxima.push_back(c.x.back());
            // Said here, naming it: else its reach is NaN and its whole kind gets no bins.
            if (maxima.empty())
                throw std::runtime_error(
                    e.source + ": experiment '" + e.id + "': no trial of '" + o +
                    "' has a sample from its zero on (a force_threshold above every measured "
                    "value? check zero.threshold and its unit)");
            // The reach of at least half of the trials: the lower median of their maxima.
            const double reach = lowerMedian(maxima);
            d.x_reach[slot(e.id, o)] = reach;
            reaches[e.kind(o)].push_back(reach);
        }
    std::map<std::string, std::vector<double>> kind_edges;
    for (const auto &[kind, r] : reaches) {
        const bool scatter_kind = starts.count(kind) > 0;
        const double start =
            scatter_kind ? *std::min_element(starts[kind].begin(), starts[kind].end()) : 0.0;
        const double end = scatter_kind ? *std::max_element(r.begin(), r.end()) : lowerMedian(r);
        if (end > start)
            kind_edges[kind] = roundBinEdges(start, end, bins, scatter_kind);
        else if (scatter_kind)
            kind_edges[kind] = {start, end}; // every run at one slip: that slip is the bin
    }
    for (const Experiment &e : set.experiments)
        for (const auto &o : e.observables) {
            const std::string s = slot(e.id, o);
            if (e.x_name.empty()) {
                d.by_experiment[e.id].push_back(Eigen::Index(d.keys.size()));
                d.keys.push_back({e.id, o, e.kind(o), 0.0, 0.0});
                d.edges[s] = {};
                continue;
            }
            std::vector<double> edges = !e.bin_edges.empty() ? e.bin_edges : kind_edges[e.kind(o)];
            // Scatter bins extend to the data's last point; curve bins stop at their reach.
            std::vector<double> kept;
            if (e.scatter) {
                std::vector<int> counts;
                scatterBinMeans(scatterPoints(e, o), edges, counts);
                for (std::size_t b = 0; b + 1 < edges.size(); ++b)
                    if (counts[b] > 0) {
                        d.by_experiment[e.id].push_back(Eigen::Index(d.keys.size()));
                        d.keys.push_back({e.id, o, e.kind(o), edges[b], edges[b + 1]});
                    }
            } else {
                // A bin is a feature where a trial has a sample in it: where none has, its
                // value would be the line between two samples, not a measurement (sparse
                // data, a few readings over a plate's travel).
                std::vector<double> sampled;
                for (const Curve &c : zeroedTrials(e, o))
                    sampled.insert(sampled.end(), c.x.begin(), c.x.end());
                const auto measured = [&](double lo, double hi) {
                    const double tol = 1e-9 * (hi - lo);
                    return std::any_of(sampled.begin(), sampled.end(),
                                       [&](double x) { return x >= lo - tol && x <= hi + tol; });
                };
                const double reach = d.x_reach[s];
                for (std::size_t b = 0; b + 1 < edges.size(); ++b)
                    if (edges[b + 1] <= reach * (1.0 + 1e-12) && measured(edges[b], edges[b + 1])) {
                        d.by_experiment[e.id].push_back(Eigen::Index(d.keys.size()));
                        d.keys.push_back({e.id, o, e.kind(o), edges[b], edges[b + 1]});
                    }
            }
            d.edges[s] = edges;
        }
    return d;
}

Measured measure(const ExperimentSet &set, const FeatureDesign &design) {
    Measured m;
    m.keys = design.keys;
    const Eigen::Index n = Eigen::Index(design.size());
    m.value = Eigen::VectorXd::Constant(n, kNaN);
    m.u_D = Eigen::VectorXd::Zero(n);
    m.u_repeats = Eigen::VectorXd::Zero(n);
    m.trials = Eigen::VectorXi::Zero(n);
    m.from_repeats.assign(std::size_t(n), false);
    std::size_t most_trials = 0;
    for (const Experiment &e : set.experiments)
        most_trials = std::max(most_trials, e.trials.size());
    m.trial_values = Eigen::MatrixXd::Constant(Eigen::Index(most_trials), n, kNaN);
    for (const auto &[id, idx] : design.by_experiment) {
        const Experiment &e = set.find(id);
        const MeasurementUncertainty &u = e.uncertainty;
        for (Eigen::Index k : idx) {
            const FeatureKey &key = design.keys[std::size_t(k)];
            std::vector<double> values;
            if (e.x_name.empty()) {
                for (std::size_t r = 0; r < e.trials.size(); ++r) {
                    values.push_back(e.trials[r].curves.at(key.observable).y[0]);
                    m.trial_values(Eigen::Index(r), k) = values.back();
                }
            } else if (e.scatter) { // points, not trials: no trial's own value
                for (const auto &[x, y] : scatterPoints(e, key.observable))
                    if (inScatterBin(design, key, x))
                        values.push_back(y);
            } else {
                const std::vector<Curve> curves = zeroedTrials(e, key.observable);
                for (std::size_t r = 0; r < curves.size(); ++r)
                    if (const auto v = binMean(curves[r], key.x_lo, key.x_hi)) {
                        values.push_back(*v);
                        m.trial_values(Eigen::Index(r), k) = *v;
                    }
            }
            const int count = int(values.size());
            m.trials[k] = count;
            if (count == 0)
                continue;
            double mean = 0.0;
            for (double v : values)
                mean += v;
            mean /= count;
            double var_repeats = 0.0;
            if (count >= 2) {
                for (double v : values)
                    var_repeats += (v - mean) * (v - mean);
                var_repeats /= (count - 1);
            }
            m.value[k] = mean;
            m.from_repeats[std::size_t(k)] = count >= 2 && u.rebuilt_bed;
            const double per_trial = u.y_sigma * u.y_sigma + std::pow(u.y_relative * mean, 2);
            m.u_repeats[k] = std::sqrt(var_repeats / count);
            m.u_D[k] = std::sqrt(var_repeats / count + per_trial / count +
                                 u.y_systematic * u.y_systematic);
        }
        // The x zero's uncertainty moves a bin's mean by the curve's slope times it.
        if (u.x_zero_sigma > 0.0 && !e.x_name.empty())
            for (std::size_t i = 0; i < idx.size(); ++i) {
                const Eigen::Index k = idx[i];
                // The slope from the neighbouring bins of the same observable (an experiment's
                // bins run observable after observable): one-sided at each one's ends.
                const auto &bins = idx; // (a structured binding is not captured in C++17)
                const auto same = [&](std::size_t j) {
                    return design.keys[std::size_t(bins[j])].observable ==
                               design.keys[std::size_t(k)].observable &&
                           std::isfinite(m.value[bins[j]]);
                };
                const Eigen::Index a = idx[i > 0 && same(i - 1) ? i - 1 : i];
                const Eigen::Index b = idx[i + 1 < idx.size() && same(i + 1) ? i + 1 : i];
                const double dx = design.keys[std::size_t(b)].centre() -
                                  design.keys[std::size_t(a)].centre();
                if (a == b || dx <= 0.0)
                    continue;
                const double slope = (m.value[b] - m.value[a]) / dx;
                const double zero = slope * u.x_zero_sigma / std::sqrt(std::max(1, m.trials[k]));
                if (std::isfinite(zero))
                    m.u_D[k] = std::sqrt(m.u_D[k] * m.u_D[k] + zero * zero);
            }
    }
    return m;
}

Eigen::VectorXd simulatedFeatures(const ExperimentSet &set, const FeatureDesign &design,
                                  const SimulatedCurves &curves) {
    Eigen::VectorXd row = Eigen::VectorXd::Constant(Eigen::Index(design.size()), kNaN);
    for (const auto &[id, idx] : design.by_experiment) {
        const auto exp_it = curves.find(id);
        if (exp_it == curves.end())
            continue;
        const Experiment &e = set.find(id);
        for (Eigen::Index k : idx) {
            const FeatureKey &key = design.keys[std::size_t(k)];
            const auto it = exp_it->second.find(key.observable);
            if (it == exp_it->second.end() || it->second.empty())
                continue;
            if (e.x_name.empty()) {
                row[k] = it->second.y[0];
            } else if (e.scatter) {
                double sum = 0.0;
                int count = 0;
                for (std::size_t i = 0; i < it->second.x.size(); ++i)
                    if (inScatterBin(design, key, it->second.x[i]))
                        sum += it->second.y[i], ++count;
                if (count > 0)
                    row[k] = sum / count;
            } else if (const auto v = binMean(applyZero(it->second, e.zero), key.x_lo, key.x_hi)) {
                row[k] = *v;
            }
        }
    }
    return row;
}

std::vector<RegimePoint> regimePoints(const ExperimentSet &set, const FeatureDesign &design,
                                      const std::vector<bool> &reference) {
    std::vector<std::string> kinds;
    std::vector<std::map<std::string, double>> coords;
    std::vector<std::map<std::string, std::string>> labels;
    for (const FeatureKey &key : design.keys) {
        const Experiment &e = set.find(key.experiment);
        std::map<std::string, double> c = e.numbers;
        if (!key.scalar())
            c["x"] = key.centre();
        kinds.push_back(key.kind);
        coords.push_back(std::move(c));
        labels.push_back(e.labels);
    }
    return regimeCoordinates(kinds, coords, labels, reference);
}

std::map<std::string, AxisLabel> axisLabels(const ExperimentSet &set) {
    std::map<std::string, AxisLabel> out;
    for (const Experiment &e : set.experiments)
        for (const auto &o : e.observables) {
            AxisLabel a{e.x_name, "", 1.0};
            if (e.x_name == "sinkage_m")
                a = {"sinkage", "mm", 1000.0};
            else if (e.x_name == "shear_displacement_m")
                a = {"shear displacement", "mm", 1000.0};
            else if (e.x_name == "slip")
                a = {"slip", "", 1.0};
            out[e.kind(o)] = a;
        }
    return out;
}

} // namespace grainlink::gap
