#include "grainlink/lab/BekkerFit.hpp"

#include <Eigen/Dense>
#include <unsupported/Eigen/LevenbergMarquardt>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace grainlink::lab {

double BekkerParameters::pressure(double plate_radius_m, double sinkage_m) const {
    // Bekker's pressure-sinkage law, docs/physics.md §12.6.
    return (k_c / plate_radius_m + k_phi) * std::pow(std::max(sinkage_m, 0.0), n);
}

double studentT975(int dof) {
    if (dof < 1)
        throw std::invalid_argument("studentT975: degrees of freedom must be >= 1, got " +
                                    std::to_string(dof));
    // Below 5 the expansion is poor; these are the exact quantiles.
    static const double kSmall[] = {12.7062047, 4.30265273, 3.18244631, 2.77644511};
    if (dof <= 4)
        return kSmall[dof - 1];
    // Cornish-Fisher expansion about the normal quantile (Abramowitz & Stegun 26.7.5).
    const double z = 1.959963984540054, v = dof;
    const double z2 = z * z, z3 = z2 * z, z5 = z3 * z2, z7 = z5 * z2, z9 = z7 * z2;
    const double g1 = (z3 + z) / 4.0;
    const double g2 = (5.0 * z5 + 16.0 * z3 + 3.0 * z) / 96.0;
    const double g3 = (3.0 * z7 + 19.0 * z5 + 17.0 * z3 - 15.0 * z) / 384.0;
    const double g4 = (79.0 * z9 + 776.0 * z7 + 1482.0 * z5 - 1920.0 * z3 - 945.0 * z) / 92160.0;
    return z + g1 / v + g2 / (v * v) + g3 / (v * v * v) + g4 / (v * v * v * v);
}

namespace {

struct Point {
    double b, z, p;
};

/// Residuals in scaled form: theta = (c1, c2, n) with
/// p = p_ref (c1 b_ref / b + c2) (z / z_ref)^n, residual (p_model - p) / p_ref.
struct BekkerResiduals : Eigen::DenseFunctor<double> {
    BekkerResiduals(const std::vector<Point> &points, double b_ref, double z_ref, double p_ref)
        : Eigen::DenseFunctor<double>(3, int(points.size())), points(points), b_ref(b_ref),
          z_ref(z_ref), p_ref(p_ref) {}
    int operator()(const InputType &x, ValueType &f) const {
        for (std::size_t i = 0; i < points.size(); ++i) {
            const Point &q = points[i];
            const double s = std::pow(q.z / z_ref, x[2]);
            f[Eigen::Index(i)] = (x[0] * b_ref / q.b + x[1]) * s - q.p / p_ref;
        }
        return 0;
    }
    int df(const InputType &x, JacobianType &jac) const {
        for (std::size_t i = 0; i < points.size(); ++i) {
            const Point &q = points[i];
            const double s = std::pow(q.z / z_ref, x[2]);
            const auto row = Eigen::Index(i);
            jac(row, 0) = b_ref / q.b * s;
            jac(row, 1) = s;
            jac(row, 2) = (x[0] * b_ref / q.b + x[1]) * s * std::log(q.z / z_ref);
        }
        return 0;
    }
    const std::vector<Point> &points;
    double b_ref, z_ref, p_ref;
};

} // namespace

BekkerFit fitBekker(const std::vector<PressureSinkageCurve> &curves, double min_sinkage_m) {
    std::vector<Point> points;
    std::vector<double> radii;
    for (const auto &c : curves) {
        if (!(c.plate_radius_m > 0.0))
            throw std::invalid_argument("fitBekker: plate radius must be > 0, got " +
                                        std::to_string(c.plate_radius_m));
        if (c.sinkage_m.size() != c.pressure_Pa.size())
            throw std::invalid_argument("fitBekker: sinkage and pressure differ in length");
        bool used = false;
        for (std::size_t i = 0; i < c.sinkage_m.size(); ++i)
            if (c.sinkage_m[i] > min_sinkage_m && std::isfinite(c.pressure_Pa[i])) {
                points.push_back({c.plate_radius_m, c.sinkage_m[i], c.pressure_Pa[i]});
                used = true;
            }
        if (used && std::none_of(radii.begin(), radii.end(), [&](double r) {
                return std::abs(r - c.plate_radius_m) <= 1e-9 * c.plate_radius_m;
            }))
            radii.push_back(c.plate_radius_m);
    }
    if (radii.size() < 2)
        throw std::invalid_argument("fitBekker: needs curves of at least two plate radii (got " +
                                    std::to_string(radii.size()) +
                                    "): k_c and k_phi cannot be separated with one size");
    if (points.size() < 4)
        throw std::invalid_argument("fitBekker: needs at least 4 points with sinkage > " +
                                    std::to_string(min_sinkage_m) + " m, got " +
                                    std::to_string(points.size()));

    double b_ref = 0.0, z_ref = 0.0, p_ref = 0.0;
    for (double r : radii)
        b_ref += r / double(radii.size());
    for (const Point &q : points) {
        z_ref = std::max(z_ref, q.z);
        p_ref = std::max(p_ref, std::abs(q.p));
    }
    if (!(p_ref > 0.0))
        throw std::invalid_argument("fitBekker: every pressure is zero");

    // Start: for each n on a grid the model is linear in (c1, c2); take the best.
    const auto m = Eigen::Index(points.size());
    Eigen::VectorXd x(3);
    double best = std::numeric_limits<double>::infinity();
    for (double n = 0.2; n <= 2.5001; n += 0.05) {
        Eigen::MatrixXd a(m, 2);
        Eigen::VectorXd y(m);
        for (Eigen::Index i = 0; i < m; ++i) {
            const Point &q = points[std::size_t(i)];
            const double s = std::pow(q.z / z_ref, n);
            a(i, 0) = b_ref / q.b * s;
            a(i, 1) = s;
            y[i] = q.p / p_ref;
        }
        const Eigen::Vector2d c = a.colPivHouseholderQr().solve(y);
        const double rss = (a * c - y).squaredNorm();
        if (rss < best) {
            best = rss;
            x << c[0], c[1], n;
        }
    }

    BekkerResiduals residuals(points, b_ref, z_ref, p_ref);
    Eigen::LevenbergMarquardt<BekkerResiduals> lm(residuals);
    lm.setXtol(1e-14);
    lm.setFtol(1e-14);
    lm.setMaxfev(2000);
    lm.minimize(x);

    BekkerFit fit;
    fit.points = points.size();
    fit.degrees_of_freedom = int(points.size()) - 3;
    fit.iterations = int(lm.iterations());
    Eigen::VectorXd f(m);
    residuals(x, f);
    Eigen::MatrixXd jac(m, 3);
    residuals.df(x, jac);
    const double s2 = f.squaredNorm() / double(fit.degrees_of_freedom);
    fit.rms_residual_Pa = p_ref * std::sqrt(f.squaredNorm() / double(m));
    // Covariance of theta, s^2 (J^T J)^-1, then to (k_c, k_phi, n) by the delta method.
    const Eigen::Matrix3d jtj = jac.transpose() * jac;
    const Eigen::Matrix3d cov_theta = s2 * jtj.inverse();
    const double zn = std::pow(z_ref, x[2]), lz = std::log(z_ref);
    BekkerParameters &p = fit.parameters;
    p.k_c = p_ref * x[0] * b_ref / zn;
    p.k_phi = p_ref * x[1] / zn;
    p.n = x[2];
    Eigen::Matrix3d t = Eigen::Matrix3d::Zero();
    t(0, 0) = p_ref * b_ref / zn;
    t(0, 2) = -p.k_c * lz;
    t(1, 1) = p_ref / zn;
    t(1, 2) = -p.k_phi * lz;
    t(2, 2) = 1.0;
    fit.covariance = t * cov_theta * t.transpose();
    fit.standard_error = fit.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
    fit.half_width_95 = studentT975(std::max(1, fit.degrees_of_freedom)) * fit.standard_error;
    return fit;
}

std::string BekkerFit::describe() const {
    std::ostringstream out;
    out << std::setprecision(5);
    out << "Bekker fit p = (k_c/b + k_phi) z^n over " << points << " points (" << degrees_of_freedom
        << " dof), 95 % confidence intervals:\n";
    out << "  k_c   = " << parameters.k_c << " +- " << half_width_95[0] << " N/m^(n+1)\n";
    out << "  k_phi = " << parameters.k_phi << " +- " << half_width_95[1] << " N/m^(n+2)\n";
    out << "  n     = " << parameters.n << " +- " << half_width_95[2] << "\n";
    out << "  rms residual " << rms_residual_Pa << " Pa\n";
    return out.str();
}

} // namespace grainlink::lab
