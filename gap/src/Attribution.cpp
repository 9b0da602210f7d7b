#include "grainlink/gap/Attribution.hpp"

#include "NotANumber.hpp"

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/students_t.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <tuple>

namespace grainlink::gap {

namespace {

constexpr int kGrid = 201;
constexpr double kDeltaChi2_95 = 3.841458820694124; // chi^2_1 at 95 %

template <class F> double goldenMinimum(F f, double a, double b) {
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    double c = b - g * (b - a), d = a + g * (b - a);
    double fc = f(c), fd = f(d);
    for (int i = 0; i < 60 && std::abs(b - a) > 1e-10 * (1.0 + std::abs(a)); ++i) {
        if (fc < fd) {
            b = d, d = c, fd = fc;
            c = b - g * (b - a), fc = f(c);
        } else {
            a = c, c = d, fc = fd;
            d = a + g * (b - a), fd = f(d);
        }
    }
    return 0.5 * (a + b);
}

/// The minimum of f(x, y) within [x0, x1] x [y0, y1] by Nelder and Mead's simplex from
/// (x, y), its first steps dx and dy.
template <class F>
std::pair<double, double> simplexMinimum(F f, double x, double y, double dx, double dy, double x0,
                                         double x1, double y0, double y1) {
    using P = Eigen::Vector2d;
    const auto clamp = [&](P p) { return P(std::clamp(p[0], x0, x1), std::clamp(p[1], y0, y1)); };
    const auto value = [&](const P &p) { return f(p[0], p[1]); };
    std::array<P, 3> v{P(x, y), clamp(P(x + dx, y)), clamp(P(x, y + dy))};
    if (v[1] == v[0])
        v[1] = clamp(P(x - dx, y));
    if (v[2] == v[0])
        v[2] = clamp(P(x, y - dy));
    std::array<double, 3> c{value(v[0]), value(v[1]), value(v[2])};
    for (int it = 0; it < 400; ++it) {
        std::array<int, 3> o{0, 1, 2};
        std::sort(o.begin(), o.end(), [&](int i, int j) { return c[i] < c[j]; });
        const P best = v[o[0]], good = v[o[1]], worst = v[o[2]];
        if (std::abs((best - worst)[0]) < 1e-9 * (x1 - x0) &&
            std::abs((best - worst)[1]) < 1e-9 * (y1 - y0))
            break;
        const P mid = 0.5 * (best + good);
        const P r = clamp(mid + (mid - worst));
        const double cr = value(r);
        if (cr < c[o[0]]) {
            const P e = clamp(mid + 2.0 * (mid - worst));
            const double ce = value(e);
            v[o[2]] = ce < cr ? e : r, c[o[2]] = std::min(ce, cr);
        } else if (cr < c[o[1]]) {
            v[o[2]] = r, c[o[2]] = cr;
        } else {
            const P k = 0.5 * (mid + (cr < c[o[2]] ? r : worst));
            const double ck = value(k);
            if (ck < std::min(cr, c[o[2]])) {
                v[o[2]] = k, c[o[2]] = ck;
            } else { // shrink towards the best
                for (int i : {o[1], o[2]}) {
                    v[i] = 0.5 * (v[i] + best);
                    c[i] = value(v[i]);
                }
            }
        }
    }
    const int b = int(std::min_element(c.begin(), c.end()) - c.begin());
    return {v[b][0], v[b][1]};
}

/// Best point of f on a grid over [t0, t1], refined by golden section; the profile's interval.
struct Profile {
    double t_best, chi2, t_lo, t_hi;
    bool at_bound;
};
template <class F> Profile minimiseProfile(F chi2, double t0, double t1, double threshold_scale) {
    std::vector<double> t(kGrid), c(kGrid);
    int best = 0;
    for (int k = 0; k < kGrid; ++k) {
        t[std::size_t(k)] = t0 + (t1 - t0) * k / double(kGrid - 1);
        c[std::size_t(k)] = chi2(t[std::size_t(k)]);
        if (c[std::size_t(k)] < c[std::size_t(best)])
            best = k;
    }
    Profile p;
    const double a = t[std::size_t(std::max(0, best - 1))];
    const double b = t[std::size_t(std::min(kGrid - 1, best + 1))];
    p.t_best = goldenMinimum(chi2, a, b);
    p.chi2 = chi2(p.t_best);
    if (p.chi2 > c[std::size_t(best)]) { // flat or noisy: keep the grid point
        p.t_best = t[std::size_t(best)];
        p.chi2 = c[std::size_t(best)];
    }
    p.at_bound = best == 0 || best == kGrid - 1;
    const double limit = p.chi2 + kDeltaChi2_95 * threshold_scale;
    // Walk out from the best grid point to where the profile crosses the limit.
    int lo = best, hi = best;
    while (lo > 0 && c[std::size_t(lo - 1)] <= limit)
        --lo;
    while (hi < kGrid - 1 && c[std::size_t(hi + 1)] <= limit)
        ++hi;
    const auto cross = [&](int inside, int outside) {
        const double ci = c[std::size_t(inside)], co = c[std::size_t(outside)];
        const double w = co > ci ? (limit - ci) / (co - ci) : 0.0;
        return t[std::size_t(inside)] + w * (t[std::size_t(outside)] - t[std::size_t(inside)]);
    };
    p.t_lo = lo > 0 ? cross(lo, lo - 1) : t.front();
    p.t_hi = hi < kGrid - 1 ? cross(hi, hi + 1) : t.back();
    p.t_lo = std::min(p.t_lo, p.t_best);
    p.t_hi = std::max(p.t_hi, p.t_best);
    return p;
}

/// Whether the profile's best point is at a prior end that is not "off".
bool atPriorEdge(const Profile &p, double t0, double t1, double t_off) {
    if (!p.at_bound)
        return false;
    const double end = std::abs(p.t_best - t1) < std::abs(p.t_best - t0) ? t1 : t0;
    return std::abs(end - t_off) > 1e-9 * std::max(1.0, std::abs(t1 - t0));
}

/// Whether chi^2 keeps falling past the prior end at which the profile's best point lies (an
/// end that is not "off": the data asking for less than nothing is no claim anyway): a fifth
/// of the span further it is lower by 3.84 and by a tenth of itself. Not by 3.84 times the
/// Birge ratio: a fit pinned at an edge is poor because it is pinned.
template <class F>
bool beyondPrior(F chi2, const Profile &p, double t0, double t1, double t_off) {
    if (!atPriorEdge(p, t0, t1, t_off))
        return false;
    const bool upper = std::abs(p.t_best - t1) < std::abs(p.t_best - t0);
    const double beyond = upper ? t1 + 0.2 * (t1 - t0) : t0 - 0.2 * (t1 - t0);
    const double c = chi2(beyond);
    return std::isfinite(c) && c < p.chi2 - std::max(kDeltaChi2_95, 0.1 * p.chi2);
}

/// A strength fit from the profile `q` of `chi2` over `prior` (on its scale): the best
/// strength, its interval (the spread's too, until the beds' luck widens it) and where it lies
/// against the prior's ends.
template <class F>
StrengthFit fitOfProfile(const Profile &q, const Prior &prior, F chi2, int features, double birge) {
    const double t0 = prior.toScale(prior.lo), t1 = prior.toScale(prior.hi),
                 t_off = prior.toScale(prior.off);
    StrengthFit f;
    f.strength = prior.fromScale(q.t_best);
    f.lo = f.spread_lo = prior.fromScale(q.t_lo);
    f.hi = f.spread_hi = prior.fromScale(q.t_hi);
    f.chi2 = q.chi2;
    f.at_bound = q.at_bound;
    f.beyond_prior = beyondPrior(chi2, q, t0, t1, t_off);
    f.at_prior_edge = atPriorEdge(q, t0, t1, t_off);
    f.features = features;
    f.birge = birge;
    return f;
}

/// `mean` with every feature a response lacks somewhere taken at the base (`off`): one missing
/// at some strengths (a bin a softer soil never reaches) would drop out of chi^2 only there and
/// make those strengths look better; dropped everywhere, the effect's chi^2 would be summed over
/// fewer features than its rivals'. At the base, it counts for every strength and every effect
/// as what this effect does not explain.
Eigen::VectorXd atBaseWhereMissing(Eigen::VectorXd mean, const std::vector<bool> &has,
                                   const Eigen::VectorXd &off) {
    for (Eigen::Index k = 0; k < mean.size(); ++k)
        if (!has[std::size_t(k)])
            mean[k] = off[k];
    return mean;
}

/// Where a strength profile over [t0, t1] looks: its grid, "off", and a fifth of the span
/// beyond each end (where a pinned fit is tested).
std::vector<double> profilePoints(double t0, double t1, double t_off) {
    std::vector<double> t{t_off, t0 - 0.2 * (t1 - t0), t1 + 0.2 * (t1 - t0)};
    for (int k = 0; k < kGrid; ++k)
        t.push_back(t0 + (t1 - t0) * k / double(kGrid - 1));
    return t;
}

/// Which of the features marked in `all` `response` has at every point a profile over `prior`
/// looks at.
std::vector<bool> hasEverywhere(const Response &response, const Prior &prior,
                                std::vector<bool> all) {
    const Eigen::Index n = Eigen::Index(all.size());
    const double t0 = prior.toScale(prior.lo), t1 = prior.toScale(prior.hi);
    for (double t : profilePoints(t0, t1, prior.toScale(prior.off))) {
        const Eigen::VectorXd m = response.mean(prior.fromScale(t));
        for (Eigen::Index k = 0; k < n; ++k)
            all[std::size_t(k)] = all[std::size_t(k)] && std::isfinite(m[k]);
    }
    return all;
}

} // namespace

double Prior::toScale(double s) const {
    if (!log_scale)
        return s;
    if (!(s > 0.0))
        throw std::invalid_argument("Prior: a logarithmic strength must be > 0, got " +
                                    std::to_string(s));
    return std::log(s);
}

double Prior::fromScale(double t) const { return log_scale ? std::exp(t) : t; }

TabulatedResponse::TabulatedResponse(const Prior &prior, std::vector<double> strengths,
                                     std::vector<Eigen::VectorXd> means,
                                     std::vector<Eigen::VectorXd> variances)
    : prior_(prior) {
    if (strengths.size() < 2 || means.size() != strengths.size() ||
        variances.size() != strengths.size())
        throw std::invalid_argument("TabulatedResponse: need >= 2 strengths, each with a mean "
                                    "and a variance");
    std::vector<std::size_t> order(strengths.size());
    for (std::size_t i = 0; i < order.size(); ++i)
        order[i] = i;
    std::sort(order.begin(), order.end(),
              [&](std::size_t a, std::size_t b) { return strengths[a] < strengths[b]; });
    for (std::size_t i : order) {
        strengths_.push_back(strengths[i]);
        means_.push_back(means[i]);
        variances_.push_back(variances[i]);
    }
}

Eigen::VectorXd TabulatedResponse::interpolate(const std::vector<Eigen::VectorXd> &table,
                                               double s) const {
    const double t = prior_.toScale(s);
    std::size_t seg = 0;
    while (seg + 2 < strengths_.size() && t > prior_.toScale(strengths_[seg + 1]))
        ++seg;
    const double t0 = prior_.toScale(strengths_[seg]), t1 = prior_.toScale(strengths_[seg + 1]);
    const double w = (t - t0) / (t1 - t0);
    return (1.0 - w) * table[seg] + w * table[seg + 1];
}

void TabulatedResponse::add(double s, const Eigen::VectorXd &mean, const Eigen::VectorXd &variance) {
    const auto at = std::lower_bound(strengths_.begin(), strengths_.end(), s);
    const std::size_t i = std::size_t(at - strengths_.begin());
    if (at != strengths_.end() && *at == s) {
        means_[i] = mean;
        variances_[i] = variance;
        return;
    }
    strengths_.insert(at, s);
    means_.insert(means_.begin() + std::ptrdiff_t(i), mean);
    variances_.insert(variances_.begin() + std::ptrdiff_t(i), variance);
}

Eigen::VectorXd TabulatedResponse::mean(double s) const { return interpolate(means_, s); }

Eigen::VectorXd TabulatedResponse::variance(double s) const {
    // Noise does not extrapolate: beyond the table, the nearest strength's.
    const double clamped = std::clamp(s, strengths_.front(), strengths_.back());
    return interpolate(variances_, clamped).cwiseMax(0.0);
}

double chiSquare(const Eigen::VectorXd &measured, const Eigen::VectorXd &mean,
                 const Eigen::VectorXd &variance, const Eigen::VectorXd &u2_fixed,
                 const FeatureSet &use, const BlockCorrelation &correlation) {
    Eigen::VectorXd e = Eigen::VectorXd::Constant(measured.size(), kNaN);
    for (Eigen::Index k : use) {
        const double v = u2_fixed[k] + variance[k];
        const double r = measured[k] - mean[k];
        if (std::isfinite(r) && v > 0.0)
            e[k] = r / std::sqrt(v);
    }
    return correlation.chiSquare(e, use);
}

StrengthFit fitStrength(const Response &response, const Prior &prior,
                        const Eigen::VectorXd &measured, const Eigen::VectorXd &u2_fixed,
                        const FeatureSet &use, const BlockCorrelation &correlation) {
    const double t0 = prior.toScale(prior.lo), t1 = prior.toScale(prior.hi);
    const std::vector<bool> has =
        hasEverywhere(response, prior, std::vector<bool>(std::size_t(measured.size()), true));
    const Eigen::VectorXd off_mean = response.mean(prior.off),
                          off_var = response.variance(prior.off);
    const auto chi2 = [&](double t) {
        const double s = prior.fromScale(t);
        return chiSquare(measured, atBaseWhereMissing(response.mean(s), has, off_mean),
                         atBaseWhereMissing(response.variance(s), has, off_var), u2_fixed, use,
                         correlation);
    };
    // A first pass gives the Birge ratio that widens the interval of a poor best fit.
    const Profile first = minimiseProfile(chi2, t0, t1, 1.0);
    const int features = int(use.size());
    const double birge = std::max(1.0, first.chi2 / std::max(1, features - 1));
    const Profile p = birge > 1.0 ? minimiseProfile(chi2, t0, t1, birge) : first;
    StrengthFit fit = fitOfProfile(p, prior, chi2, features, birge);
    fit.chi2_off = chi2(prior.toScale(prior.off));
    return fit;
}

Eigen::VectorXd bedLuckSd(const std::function<Eigen::VectorXd(const Eigen::VectorXd &)> &refit,
                          const Eigen::VectorXd &t_fit, const Eigen::VectorXd &at_fit,
                          const Eigen::MatrixXd &rows) {
    Eigen::VectorXd sum2 = Eigen::VectorXd::Zero(t_fit.size());
    if (rows.rows() < 2)
        return sum2;
    const Eigen::VectorXd mean = columnStats(rows).mean;
    for (Eigen::Index j = 0; j < rows.rows(); ++j) {
        // A bin this bed lacks tells nothing of its luck there: no departure. (Left out of the
        // refit instead, it would move the strength by the features it lost, not by luck.)
        Eigen::VectorXd departure = rows.row(j).transpose() - mean;
        for (Eigen::Index k = 0; k < departure.size(); ++k)
            if (!std::isfinite(departure[k]))
                departure[k] = 0.0;
        const Eigen::VectorXd pseudo = at_fit + departure;
        sum2 += (refit(pseudo) - t_fit).array().square().matrix();
    }
    return (sum2 / double(rows.rows() - 1)).cwiseSqrt();
}

void widenInterval(StrengthFit &fit, const Prior &prior, double sd, double dof) {
    if (!(sd > 0.0) || !std::isfinite(sd) || !(dof >= 1.0))
        return;
    const double t = prior.toScale(fit.strength);
    const double t0 = prior.toScale(prior.lo), t1 = prior.toScale(prior.hi);
    const double below = t - prior.toScale(fit.lo), above = prior.toScale(fit.hi) - t;
    const auto widened = [&](double half, double &lo, double &hi) {
        lo = prior.fromScale(std::max(t - std::hypot(below, half), std::min(t0, t)));
        hi = prior.fromScale(std::min(t + std::hypot(above, half), std::max(t1, t)));
    };
    widened(boost::math::quantile(boost::math::students_t(dof), 0.975) * sd, fit.lo, fit.hi);
    widened(1.959963984540054 * sd, fit.spread_lo, fit.spread_hi);
    fit.luck_sd = sd;
}

StrengthAgreement strengthAgreement(const std::vector<StrengthFit> &parts, const Prior &prior) {
    const double t0 = prior.toScale(prior.lo), t1 = prior.toScale(prior.hi), span = t1 - t0;
    struct Part {
        double t, below, above; // strength and half-widths on the prior's scale
    };
    std::vector<Part> used;
    // The interval with the beds' luck at the normal quantile, read back at it: the 95 %
    // interval (`lo`, `hi`) widens it by Student's t of the few beds (4.3 at three seeds), and
    // read at 1.96 it made every sd up to 2.2 times too wide, the veto that much too weak.
    for (const StrengthFit &f : parts) {
        const double t = prior.toScale(f.strength), lo = prior.toScale(f.spread_lo),
                     hi = prior.toScale(f.spread_hi);
        if (std::isfinite(t) && std::isfinite(lo) && std::isfinite(hi) && hi - lo < 0.9 * span)
            used.push_back({t, t - lo, hi - t});
    }
    StrengthAgreement a;
    a.mean = kNaN;
    if (used.empty())
        return a;
    // A half-width of nothing (a profile as sharp as the grid) would weigh without end: a
    // two-hundredth of the prior at least.
    const double floor = 0.005 * span, z95 = 1.959963984540054;
    const auto sd = [&](const Part &p, double towards) {
        return std::max(towards >= p.t ? p.above : p.below, floor) / z95;
    };
    const auto weightedMean = [&](auto sdOf) {
        double sum = 0.0, weights = 0.0;
        for (const Part &p : used) {
            const double s = sdOf(p);
            sum += p.t / (s * s), weights += 1.0 / (s * s);
        }
        return sum / weights;
    };
    // The mean with the symmetric widths, then once more with the sides that face it.
    const double first = weightedMean(
        [&](const Part &p) { return std::max(0.5 * (p.below + p.above), floor) / z95; });
    const double mean = weightedMean([&](const Part &p) { return sd(p, first); });
    a.mean = prior.fromScale(mean);
    for (const Part &p : used)
        a.chi2 += (p.t - mean) * (p.t - mean) / (sd(p, mean) * sd(p, mean));
    a.dof = int(used.size()) - 1;
    if (a.dof > 0)
        a.p_value =
            boost::math::cdf(boost::math::complement(boost::math::chi_squared(a.dof), a.chi2));
    return a;
}

Eigen::VectorXd PairResponse::mean(double sa, double sb) const {
    return a_.mean(sa) + b_.mean(sb) - base_mean_;
}

Eigen::VectorXd PairResponse::variance(double sa, double sb) const {
    // Each simulated response carries the base's noise once; their sum, twice.
    return (a_.variance(sa) + b_.variance(sb) - base_var_).cwiseMax(0.0);
}

ChainOnEffectResponse::ChainOnEffectResponse(const Prior &under, std::vector<double> strengths,
                                             std::vector<TabulatedResponse> rows, bool under_is_a)
    : under_(under), strengths_(std::move(strengths)), rows_(std::move(rows)),
      under_is_a_(under_is_a) {
    if (strengths_.size() < 2 || rows_.size() != strengths_.size())
        throw std::invalid_argument("ChainOnEffectResponse: need >= 2 strengths of the partner, "
                                    "each with the chain's response");
}

TabulatedResponse ChainOnEffectResponse::underTable(double s_chain) const {
    std::vector<Eigen::VectorXd> means, variances;
    for (const TabulatedResponse &row : rows_) {
        means.push_back(row.mean(s_chain));
        variances.push_back(row.variance(s_chain));
    }
    return TabulatedResponse(under_, strengths_, std::move(means), std::move(variances));
}

Eigen::VectorXd ChainOnEffectResponse::mean(double sa, double sb) const {
    const double under = under_is_a_ ? sa : sb, chain = under_is_a_ ? sb : sa;
    return underTable(chain).mean(under);
}

Eigen::VectorXd ChainOnEffectResponse::variance(double sa, double sb) const {
    const double under = under_is_a_ ? sa : sb, chain = under_is_a_ ? sb : sa;
    return underTable(chain).variance(under);
}

PairFit fitPair(const PairModel &pair, const Prior &pa, const Prior &pb,
                const Eigen::VectorXd &base_mean, const Eigen::VectorXd &base_variance,
                const Eigen::VectorXd &measured, const Eigen::VectorXd &u2_fixed,
                const FeatureSet &use, const BlockCorrelation &correlation) {
    const double a0 = pa.toScale(pa.lo), a1 = pa.toScale(pa.hi);
    const double b0 = pb.toScale(pb.lo), b1 = pb.toScale(pb.hi);
    constexpr int n = 41;
    // The features the pair has along each strength, the other off.
    const std::vector<bool> has =
        hasEverywhere(PairSlice(pair, false, pa.off), pb,
                      hasEverywhere(PairSlice(pair, true, pb.off), pa,
                                    std::vector<bool>(std::size_t(measured.size()), true)));
    const auto chi2 = [&](double ta, double tb) {
        const double sa = pa.fromScale(ta), sb = pb.fromScale(tb);
        return chiSquare(measured, atBaseWhereMissing(pair.mean(sa, sb), has, base_mean),
                         atBaseWhereMissing(pair.variance(sa, sb), has, base_variance), u2_fixed,
                         use, correlation);
    };
    double best = std::numeric_limits<double>::infinity(), ta = a0, tb = b0;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            const double x = a0 + (a1 - a0) * i / (n - 1.0), y = b0 + (b1 - b0) * j / (n - 1.0);
            const double c = chi2(x, y);
            if (c < best)
                best = c, ta = x, tb = y;
        }
    // Refined from the grid's best by a simplex (two strengths that trade against each other
    // lie along a narrow diagonal valley, where three rounds of one strength at a time stopped
    // short: (1.47, 0.36) for (1.5, 0.4) in the chain-on-soil test), then each strength's
    // profile at the other's best.
    std::tie(ta, tb) = simplexMinimum([&](double x, double y) { return chi2(x, y); }, ta, tb,
                                      (a1 - a0) / (n - 1.0), (b1 - b0) / (n - 1.0), a0, a1, b0, b1);
    PairFit fit;
    fit.chi2 = chi2(ta, tb);
    const int dof = std::max(1, int(use.size()) - 2);
    const double birge = std::max(1.0, fit.chi2 / dof);
    const Profile qa = minimiseProfile([&](double t) { return chi2(t, tb); }, a0, a1, birge);
    const Profile qb = minimiseProfile([&](double t) { return chi2(ta, t); }, b0, b1, birge);
    const int features = int(use.size());
    fit.a = fitOfProfile(
        qa, pa, [&](double t) { return chi2(t, tb); }, features, birge);
    fit.b = fitOfProfile(
        qb, pb, [&](double t) { return chi2(ta, t); }, features, birge);
    fit.chi2 = std::min({fit.chi2, qa.chi2, qb.chi2});
    fit.a.chi2_off = fit.b.chi2_off = chi2(pa.toScale(pa.off), pb.toScale(pb.off));
    return fit;
}

Overlap signatureOverlap(const Response &i, double s_i, const Response &j, const Prior &pj,
                         const Eigen::VectorXd &base_mean, const Eigen::VectorXd &u2,
                         const FeatureSet &use, const BlockCorrelation &correlation) {
    const Eigen::VectorXd di = i.mean(s_i) - base_mean;
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(di.size());
    // Signatures are differences from the base; their distance is a chi^2 like a residual's.
    const double norm = chiSquare(di, zero, zero, u2, use, correlation);
    const auto distance = [&](double t) {
        const Eigen::VectorXd dj = j.mean(pj.fromScale(t)) - base_mean;
        return chiSquare(di, dj, zero, u2, use, correlation);
    };
    const Profile p = minimiseProfile(distance, pj.toScale(pj.lo), pj.toScale(pj.hi), 1.0);
    Overlap o;
    o.distance_chi2 = p.chi2;
    o.strength_j = pj.fromScale(p.t_best);
    o.fraction = norm > 0.0 ? std::clamp(1.0 - p.chi2 / norm, 0.0, 1.0) : 1.0;
    return o;
}

double logPredictiveDensity(double r, double v, double dof) {
    if (!(dof < 1e6))
        return -0.5 * (r * r / v + std::log(2.0 * M_PI * v));
    return std::lgamma(0.5 * (dof + 1.0)) - std::lgamma(0.5 * dof) -
           0.5 * std::log(dof * M_PI * v) - 0.5 * (dof + 1.0) * std::log1p(r * r / (dof * v));
}

double logPredictiveSlope(double r, double v, double dof) {
    return !(dof < 1e6) ? -r / v : -(dof + 1.0) * r / (dof * v + r * r);
}

HeldOutScore scoreHeldOut(const Eigen::VectorXd &measured, const Eigen::VectorXd &predicted,
                          const Eigen::VectorXd &variance, const Eigen::VectorXd &u2_val,
                          const FeatureSet &use, const EstimatedVariance &estimated) {
    HeldOutScore s;
    double se = 0.0, rel = 0.0, excess = 0.0;
    for (Eigen::Index k : use) {
        const double r = measured[k] - predicted[k], v = variance[k], y = measured[k];
        if (!std::isfinite(r) || !(v > 0.0) || y == 0.0)
            continue;
        ++s.features;
        se += r * r / v;
        rel += (r / y) * (r / y);
        // Relative to the measured value, or to its uncertainty where that is larger: a value
        // near zero (a straight wheel's side force, traction at zero slip) weighted by 1/y^2
        // outweighed every other feature (the CMU wheels: 2.9x too much traction, gap "0 %").
        excess += (r * r - u2_val[k]) / (y * y + u2_val[k]);
        s.log_density += logPredictiveDensity(r, v, estimated.dofOf(k, v));
    }
    if (s.features == 0)
        return s;
    s.smse = se / s.features;
    s.relative_rmse = std::sqrt(rel / s.features);
    s.gap = std::sqrt(std::max(0.0, excess / s.features));
    return s;
}

namespace {
std::size_t distinctExperiments(const FeatureSet &use, const std::vector<FeatureKey> &keys) {
    std::set<std::string> ids;
    for (Eigen::Index k : use)
        ids.insert(keys[std::size_t(k)].experiment);
    return ids.size();
}
} // namespace

bool canCarryClaim(const FeatureSet &use, const std::vector<FeatureKey> &bed_keys,
                   const std::vector<FeatureKey> &experiment_keys, std::size_t seeds) {
    return distinctExperiments(use, bed_keys) >= 2 ||
           (!experiment_keys.empty() && distinctExperiments(use, experiment_keys) >= 2 &&
            seeds >= 2);
}

DensityComparison compareDensities(const Eigen::VectorXd &measured,
                                   const Eigen::VectorXd &model_mean,
                                   const Eigen::VectorXd &model_variance,
                                   const Eigen::VectorXd &null_mean,
                                   const Eigen::VectorXd &null_variance, const FeatureSet &use,
                                   const std::vector<FeatureKey> &bed_keys,
                                   const std::vector<FeatureKey> &experiment_keys,
                                   const SharedLuck &shared, const EstimatedVariance &estimated) {
    const auto gains = [&](const Eigen::VectorXd &model, const Eigen::VectorXd &null) {
        Eigen::VectorXd gain = Eigen::VectorXd::Constant(measured.size(), kNaN);
        for (Eigen::Index k : use) {
            const double rm = measured[k] - model[k], rn = measured[k] - null[k];
            const double vm = model_variance[k], vn = null_variance[k];
            if (std::isfinite(rm) && std::isfinite(rn) && vm > 0.0 && vn > 0.0)
                gain[k] = logPredictiveDensity(rm, vm, estimated.dofOf(k, vm)) -
                          logPredictiveDensity(rn, vn, estimated.dofOf(k, vn));
        }
        return gain;
    };
    const Eigen::VectorXd gain = gains(model_mean, null_mean);
    FeatureSet scored;
    for (Eigen::Index k : use)
        if (std::isfinite(gain[k]))
            scored.push_back(k);
    const std::size_t seeds =
        shared.null_mean.size() == shared.model_mean.size() ? shared.model_mean.size() : 0;
    const bool per_experiment = seeds >= 2 && !experiment_keys.empty();
    ClusteredMean g = clusteredMean(gain, scored, per_experiment ? experiment_keys : bed_keys);
    DensityComparison c;
    c.features = g.values;
    c.experiments = g.experiments;
    c.mean_gain = g.mean;
    c.gain_correlation = g.icc;
    c.per_experiment = per_experiment;
    if (!canCarryClaim(scored, bed_keys, experiment_keys, seeds))
        return c; // one piece of evidence cannot tell a better model from luck: p = 1
    double variance = g.variance, dof = g.dof;
    if (per_experiment) {
        // The model's own bed draw: how far the mean gain moves when one of its beds is left
        // out (the jackknife: (S - 1)/S sum (g_j - g.)^2).
        std::vector<double> left_out;
        for (std::size_t j = 0; j < seeds; ++j)
            left_out.push_back(clusteredMean(gains(shared.model_mean[j], shared.null_mean[j]),
                                             scored, experiment_keys)
                                   .mean);
        double centre = 0.0, spread = 0.0;
        for (double x : left_out)
            centre += x / double(seeds);
        for (double x : left_out)
            spread += (x - centre) * (x - centre);
        c.seed_variance = spread * double(seeds - 1) / double(seeds);
        // The measured beds' luck, one shift per group of beds: d gain / d y times its scatter,
        // each feature at its weight in the mean (its experiment's share, 1 / m, over its
        // experiment's features).
        std::map<std::string, double> shift, size;
        for (Eigen::Index k : scored)
            size[experiment_keys[std::size_t(k)].experiment] += 1.0;
        if (shared.measured_sd.size() == measured.size())
            for (Eigen::Index k : scored) {
                const double weight =
                    1.0 / (double(size.size()) * size[experiment_keys[std::size_t(k)].experiment]);
                const double vm = model_variance[k], vn = null_variance[k];
                const double d_gain =
                    logPredictiveSlope(measured[k] - model_mean[k], vm, estimated.dofOf(k, vm)) -
                    logPredictiveSlope(measured[k] - null_mean[k], vn, estimated.dofOf(k, vn));
                if (std::isfinite(shared.measured_sd[k]))
                    shift[bed_keys[std::size_t(k)].experiment] +=
                        weight * d_gain * shared.measured_sd[k];
            }
        for (const auto &[group, s] : shift)
            c.measured_variance += s * s;
        const double a = g.variance, b = c.seed_variance, m = c.measured_variance;
        variance = a + b + m;
        const double den = (g.dof > 0.0 ? a * a / g.dof : 0.0) + b * b / double(seeds - 1) +
                           (shared.measured_dof > 0.0 ? m * m / shared.measured_dof : 0.0);
        dof = den > 0.0 ? variance * variance / den : 0.0;
    }
    // Gains without any spread cannot tell a better model from luck either (p = 1; the t test
    // would give 0 for any gain above zero).
    if (!(variance > 0.0) || !std::isfinite(variance) || !(dof > 0.0))
        return c;
    const boost::math::students_t dist(dof);
    c.p_value = boost::math::cdf(boost::math::complement(dist, c.mean_gain / std::sqrt(variance)));
    return c;
}

} // namespace grainlink::gap
