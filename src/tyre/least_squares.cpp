#include "rollsim/tyre/least_squares.hpp"

#include <unsupported/Eigen/NonLinearOptimization>
#include <unsupported/Eigen/NumericalDiff>

#include <algorithm>
#include <cmath>

namespace rollsim {
namespace {

// The functor shape Eigen's NumericalDiff and LevenbergMarquardt expect.
struct Functor {
  using Scalar = double;
  enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };
  using InputType = Eigen::VectorXd;
  using ValueType = Eigen::VectorXd;
  using JacobianType = Eigen::MatrixXd;

  const ResidualFunction* f;
  int n, m;
  int* evaluations;
  int inputs() const { return n; }
  int values() const { return m; }
  int operator()(const Eigen::VectorXd& x, Eigen::VectorXd& r) const {
    r.resize(m);
    (*f)(x, r);
    ++*evaluations;
    return 0;
  }
};

}  // namespace

Eigen::MatrixXd jacobian_at(const ResidualFunction& residuals, int m, const Eigen::VectorXd& x) {
  Eigen::MatrixXd j(m, x.size());
  Eigen::VectorXd up(m), down(m);
  for (int k = 0; k < x.size(); ++k) {
    const double h = std::max(1e-6, 1e-6 * std::abs(x[k]));
    Eigen::VectorXd xp = x, xm = x;
    xp[k] += h;
    xm[k] -= h;
    residuals(xp, up);
    residuals(xm, down);
    j.col(k) = (up - down) / (2.0 * h);
  }
  return j;
}

LeastSquaresResult least_squares(const ResidualFunction& residuals, int m, const Eigen::VectorXd& x0) {
  LeastSquaresResult out;
  Functor functor{&residuals, static_cast<int>(x0.size()), m, &out.evaluations};
  Eigen::NumericalDiff<Functor> diff(functor);
  Eigen::LevenbergMarquardt<Eigen::NumericalDiff<Functor>> lm(diff);
  lm.parameters.xtol = 1e-12;
  lm.parameters.ftol = 1e-12;
  lm.parameters.maxfev = 4000;
  out.x = x0;
  lm.minimize(out.x);
  out.residuals.resize(m);
  residuals(out.x, out.residuals);
  out.jacobian = jacobian_at(residuals, m, out.x);
  return out;
}

}  // namespace rollsim
