#include "grainlink/lab/BekkerFit.hpp"

#include "grainlink/dem/SteadySignal.hpp"

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
    return dem::studentT95(std::size_t(dof)); // one t quantile in the project (Boost.Math)
}

namespace {

/// Adapts a LeastSquaresProblem to Eigen's functor interface.
struct Functor : Eigen::DenseFunctor<double> {
    explicit Functor(const LeastSquaresProblem &p)
        : Eigen::DenseFunctor<double>(p.parameter_count, p.residual_count), problem(p) {}
    int operator()(const InputType &x, ValueType &f) const {
        problem.residuals(x, f);
        return 0;
    }
    int df(const InputType &x, JacobianType &jac) const {
        problem.jacobian(x, jac);
        return 0;
    }
    const LeastSquaresProblem &problem;
};

struct Point {
    double b, z, p;
};

} // namespace

LeastSquaresSolution solveLeastSquares(const LeastSquaresProblem &problem, Eigen::VectorXd x) {
    const int n = problem.parameter_count, m = problem.residual_count;
    if (n < 1 || m <= n || x.size() != n)
        throw std::invalid_argument("solveLeastSquares: needs more residuals (" +
                                    std::to_string(m) + ") than parameters (" + std::to_string(n) +
                                    ") and a start of that size");
    Functor functor(problem);
    Eigen::LevenbergMarquardt<Functor> lm(functor);
    lm.setXtol(1e-14);
    lm.setFtol(1e-14);
    lm.setMaxfev(2000);
    lm.minimize(x);

    LeastSquaresSolution out;
    out.theta = x;
    out.iterations = int(lm.iterations());
    out.degrees_of_freedom = m - n;
    Eigen::VectorXd f(m);
    problem.residuals(x, f);
    Eigen::MatrixXd jac(m, n);
    problem.jacobian(x, jac);
    out.rss = f.squaredNorm();
    const Eigen::MatrixXd jtj = jac.transpose() * jac;
    out.covariance = out.rss / double(out.degrees_of_freedom) * jtj.inverse();
    return out;
}

Eigen::VectorXd separableStart(const std::vector<double> &grid,
                               const std::function<Eigen::MatrixXd(double q)> &design,
                               const Eigen::VectorXd &y) {
    Eigen::VectorXd best_x;
    double best = std::numeric_limits<double>::infinity();
    for (double q : grid) {
        const Eigen::MatrixXd a = design(q);
        const Eigen::VectorXd c = a.colPivHouseholderQr().solve(y);
        const double rss = (a * c - y).squaredNorm();
        if (rss < best) {
            best = rss;
            best_x.resize(c.size() + 1);
            best_x << c, q;
        }
    }
    if (best_x.size() == 0)
        throw std::invalid_argument("separableStart: no finite fit on the grid");
    return best_x;
}

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

    // Scaled parameters theta = (c1, c2, n): p = p_ref (c1 b_ref / b + c2) (z / z_ref)^n,
    // residual (p_model - p) / p_ref.
    const auto m = Eigen::Index(points.size());
    Eigen::VectorXd y(m);
    for (Eigen::Index i = 0; i < m; ++i)
        y[i] = points[std::size_t(i)].p / p_ref;
    // Start: for each n on a grid the model is linear in (c1, c2); take the best.
    std::vector<double> n_grid;
    for (int k = 0; k <= 46; ++k)
        n_grid.push_back(0.2 + 0.05 * k);
    auto design = [&](double n) {
        Eigen::MatrixXd a(m, 2);
        for (Eigen::Index i = 0; i < m; ++i) {
            const Point &q = points[std::size_t(i)];
            const double s = std::pow(q.z / z_ref, n);
            a(i, 0) = b_ref / q.b * s;
            a(i, 1) = s;
        }
        return a;
    };
    LeastSquaresProblem problem;
    problem.parameter_count = 3;
    problem.residual_count = int(m);
    problem.residuals = [&](const Eigen::VectorXd &x, Eigen::VectorXd &f) {
        for (Eigen::Index i = 0; i < m; ++i) {
            const Point &q = points[std::size_t(i)];
            f[i] = (x[0] * b_ref / q.b + x[1]) * std::pow(q.z / z_ref, x[2]) - y[i];
        }
    };
    problem.jacobian = [&](const Eigen::VectorXd &x, Eigen::MatrixXd &jac) {
        for (Eigen::Index i = 0; i < m; ++i) {
            const Point &q = points[std::size_t(i)];
            const double s = std::pow(q.z / z_ref, x[2]);
            jac(i, 0) = b_ref / q.b * s;
            jac(i, 1) = s;
            jac(i, 2) = (x[0] * b_ref / q.b + x[1]) * s * std::log(q.z / z_ref);
        }
    };
    const LeastSquaresSolution solution =
        solveLeastSquares(problem, separableStart(n_grid, design, y));
    const Eigen::VectorXd &x = solution.theta;

    BekkerFit fit;
    fit.points = points.size();
    fit.degrees_of_freedom = solution.degrees_of_freedom;
    fit.iterations = solution.iterations;
    fit.rms_residual_Pa = p_ref * std::sqrt(solution.rss / double(m));
    // Covariance of theta, s^2 (J^T J)^-1, carried to (k_c, k_phi, n) by the delta method.
    const Eigen::Matrix3d cov_theta = solution.covariance;
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
