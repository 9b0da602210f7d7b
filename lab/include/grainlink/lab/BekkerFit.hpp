#pragma once
// Bekker's pressure-sinkage relation p = (k_c / b + k_phi) z^n fitted to plate tests of two or
// more sizes by nonlinear least squares, with confidence intervals (docs/physics.md §12.6).
#include <Eigen/Core>

#include <functional>
#include <string>
#include <vector>

namespace grainlink::lab {

/// One plate's p(z) curve.
struct PressureSinkageCurve {
    double plate_radius_m = 0.0;     ///< [m] b in Bekker's law (radius of a circular plate)
    std::vector<double> sinkage_m;   ///< [m] z
    std::vector<double> pressure_Pa; ///< [Pa] p
};

struct BekkerParameters {
    double k_c = 0.0;   ///< [N/m^(n+1)] cohesive modulus
    double k_phi = 0.0; ///< [N/m^(n+2)] frictional modulus
    double n = 1.0;     ///< [-] sinkage exponent
    /// Bekker pressure at sinkage z under a plate of radius b [Pa].
    double pressure(double plate_radius_m, double sinkage_m) const;
};

struct BekkerFit {
    BekkerParameters parameters;
    Eigen::Vector3d standard_error; ///< of (k_c, k_phi, n), from s^2 (J^T J)^-1
    Eigen::Vector3d half_width_95;  ///< 95 % confidence half widths: t(0.975, dof) * SE
    Eigen::Matrix3d covariance;     ///< of (k_c, k_phi, n)
    double rms_residual_Pa = 0.0;
    std::size_t points = 0;     ///< points used (z > min sinkage)
    int degrees_of_freedom = 0; ///< points - 3
    int iterations = 0;
    std::string describe() const;
};

/// Fits all curves' points with z > min_sinkage_m. Throws std::invalid_argument with fewer than
/// two distinct plate radii (k_c and k_phi are then not separable) or fewer than four points.
BekkerFit fitBekker(const std::vector<PressureSinkageCurve> &curves, double min_sinkage_m = 0.0);

/// A nonlinear least-squares problem in (scaled) parameters theta: residuals f(theta) and their
/// Jacobian. Shared by the lab's fits (Bekker, Janosi-Hanamoto).
struct LeastSquaresProblem {
    int parameter_count = 0;
    int residual_count = 0;
    std::function<void(const Eigen::VectorXd &theta, Eigen::VectorXd &f)> residuals;
    std::function<void(const Eigen::VectorXd &theta, Eigen::MatrixXd &jacobian)> jacobian;
};

struct LeastSquaresSolution {
    Eigen::VectorXd theta;
    Eigen::MatrixXd covariance; ///< of theta: s^2 (J^T J)^-1, s^2 = RSS / dof
    double rss = 0.0;           ///< sum of squared residuals at theta
    int degrees_of_freedom = 0; ///< residuals - parameters
    int iterations = 0;
};

/// Levenberg-Marquardt (Eigen's unsupported module) from `start`, then the covariance at the
/// optimum. Needs more residuals than parameters (throws std::invalid_argument otherwise).
LeastSquaresSolution solveLeastSquares(const LeastSquaresProblem &problem, Eigen::VectorXd start);

/// Starting point for a model linear in every parameter but the last, q: for each q on `grid`
/// solves design(q) c = y in the least-squares sense and returns (c, q) of the smallest residual.
Eigen::VectorXd separableStart(const std::vector<double> &grid,
                               const std::function<Eigen::MatrixXd(double q)> &design,
                               const Eigen::VectorXd &y);

/// Student-t quantile t(0.975, dof) (Cornish-Fisher expansion, A&S 26.7.5; exact table for
/// dof <= 4), for the confidence intervals.
double studentT975(int degrees_of_freedom);

} // namespace grainlink::lab
