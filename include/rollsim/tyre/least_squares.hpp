// Nonlinear least squares for the tyre fits: Eigen's Levenberg-Marquardt with a forward-difference Jacobian.
#pragma once

#include <Eigen/Dense>
#include <functional>

namespace rollsim {

/// residuals(x, r) fills r (size m) at parameters x (size n <= m).
using ResidualFunction = std::function<void(const Eigen::VectorXd& x, Eigen::VectorXd& r)>;

struct LeastSquaresResult {
  Eigen::VectorXd x;         ///< parameters at the minimum
  Eigen::VectorXd residuals;  ///< r(x)
  Eigen::MatrixXd jacobian;  ///< dr/dx at x (central differences), for covariances
  int evaluations = 0;
};

/// Minimises |r(x)|^2 from x0. n <= m is required (Eigen's MINPACK port refuses otherwise).
LeastSquaresResult least_squares(const ResidualFunction& residuals, int m, const Eigen::VectorXd& x0);

/// Central-difference Jacobian of r at x (step relative to |x|, at least 1e-6).
Eigen::MatrixXd jacobian_at(const ResidualFunction& residuals, int m, const Eigen::VectorXd& x);

}  // namespace rollsim
