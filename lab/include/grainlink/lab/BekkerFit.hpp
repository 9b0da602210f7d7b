#pragma once
// Bekker's pressure-sinkage relation p = (k_c / b + k_phi) z^n fitted to plate tests of two or
// more sizes by nonlinear least squares, with confidence intervals (docs/physics.md §12.6).
#include <Eigen/Core>

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

/// Student-t quantile t(0.975, dof) (Cornish-Fisher expansion, A&S 26.7.5; exact table for
/// dof <= 4), for the confidence intervals.
double studentT975(int degrees_of_freedom);

} // namespace grainlink::lab
