// Least squares with calibration priors, out-of-fold prediction, and the one Delta BIC every test uses.
#include <algorithm>
#include <cmath>

#include "pipeline.hpp"

namespace rollsim::diag {
namespace {

// Penalised least squares: each prior row pulls its column's coefficient towards its target with its weight.
// Columns listed in `fixed_out` are left out of the design (their prior rows too).
Fit penalised(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, const std::vector<Prior::Row>& rows) {
  const auto np = static_cast<Eigen::Index>(rows.size());
  Eigen::MatrixXd xa = Eigen::MatrixXd::Zero(x.rows() + np, x.cols());
  Eigen::VectorXd ya = Eigen::VectorXd::Zero(x.rows() + np);
  xa.topRows(x.rows()) = x;
  ya.head(x.rows()) = y;
  for (Eigen::Index k = 0; k < np; ++k) {
    const auto& r = rows[static_cast<std::size_t>(k)];
    xa(x.rows() + k, r.column) = r.weight;
    ya[x.rows() + k] = r.weight * r.target;
  }
  Fit f;
  f.coef = xa.colPivHouseholderQr().solve(ya);
  f.rss = (y - x * f.coef).squaredNorm();
  const double dof = std::max<double>(1.0, static_cast<double>(x.rows() - x.cols()));
  f.cov = (xa.transpose() * xa).completeOrthogonalDecomposition().pseudoInverse() * (f.rss / dof);
  return f;
}

}  // namespace

// The scale's box is exact for a convex quadratic: profiled over the scale (the rest minimised), the criterion is a
// parabola in it, so where the free optimum leaves the box the constrained one sits on the nearer bound.
Fit least_squares(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, const Prior& prior) {
  Fit f = penalised(x, y, prior.rows);
  if (f.coef[0] >= prior.scale_low && f.coef[0] <= prior.scale_high) return f;
  const double s = std::clamp(f.coef[0], prior.scale_low, prior.scale_high);
  const Eigen::Index k = x.cols() - 1;
  std::vector<Prior::Row> rows;
  for (const auto& r : prior.rows)
    if (r.column > 0) rows.push_back({r.column - 1, r.weight, r.target});
  Fit rest;
  if (k > 0) rest = penalised(x.rightCols(k), y - s * x.col(0), rows);
  Fit out;
  out.coef.resize(x.cols());
  out.coef[0] = s;
  if (k > 0) out.coef.tail(k) = rest.coef;
  out.rss = (y - x * out.coef).squaredNorm();
  out.cov = Eigen::MatrixXd::Zero(x.cols(), x.cols());
  if (k > 0) out.cov.bottomRightCorner(k, k) = rest.cov;
  return out;
}

double lag1_autocorrelation(const Eigen::VectorXd& r) {
  if (r.size() < 3) return 0.0;
  const double mean = r.mean();
  double num = 0.0, den = 0.0;
  for (Eigen::Index i = 0; i < r.size(); ++i) {
    den += (r[i] - mean) * (r[i] - mean);
    if (i > 0) num += (r[i] - mean) * (r[i - 1] - mean);
  }
  return den > 0.0 ? num / den : 0.0;
}

double rmse(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return std::sqrt((a - b).squaredNorm() / static_cast<double>(std::max<Eigen::Index>(1, a.size())));
}

double energy_error_pct(const Eigen::VectorXd& pred, const Eigen::VectorXd& meas) {
  return 100.0 * (pred.sum() - meas.sum()) / std::max(1e-9, std::abs(meas.sum()));
}

Eigen::MatrixXd hcat(const Eigen::MatrixXd& a, const Eigen::VectorXd& b) {
  Eigen::MatrixXd m(a.rows(), a.cols() + 1);
  m << a, b;
  return m;
}

Eigen::VectorXd cleaned(const Eigen::MatrixXd& basis, const Eigen::VectorXd& s) {
  const Eigen::VectorXd c = basis.colPivHouseholderQr().solve(s);
  return s - basis * c;
}

// Out-of-fold prediction: each window predicted by a fit on the other folds (alternating blocks of windows within
// one recording, or whole recordings when several are given).
Eigen::VectorXd heldout_prediction(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, const std::vector<int>& fold_of,
                                   const Prior& prior) {
  const Eigen::Index n = x.rows();
  Eigen::VectorXd pred(n);
  const int folds = 1 + *std::max_element(fold_of.begin(), fold_of.end());
  for (int fold = 0; fold < folds; ++fold) {
    std::vector<Eigen::Index> train, test;
    for (Eigen::Index i = 0; i < n; ++i) (fold_of[static_cast<std::size_t>(i)] == fold ? test : train).push_back(i);
    if (train.empty()) train = test;
    Eigen::MatrixXd xt(static_cast<Eigen::Index>(train.size()), x.cols());
    Eigen::VectorXd yt(static_cast<Eigen::Index>(train.size()));
    for (std::size_t k = 0; k < train.size(); ++k) {
      xt.row(static_cast<Eigen::Index>(k)) = x.row(train[k]);
      yt[static_cast<Eigen::Index>(k)] = y[train[k]];
    }
    const Eigen::VectorXd c = least_squares(xt, yt, prior).coef;
    for (Eigen::Index i : test) pred[i] = x.row(i).dot(c);
  }
  return pred;
}

double Scored::amplitude_se(double inflate) const {
  const Eigen::Index j = fit.coef.size() - 1;
  return std::sqrt(std::max(0.0, fit.cov(j, j))) * inflate / std::max(1e-300, std::abs(fit.coef[0]));
}

double delta_bic(const Model& m, double rss_with) { return m.n_eff * std::log(m.fit.rss / rss_with) - std::log(m.n_eff); }

Scored score_column(const Model& m, const Eigen::VectorXd& signature) {
  Scored s;
  const Eigen::MatrixXd xk = hcat(m.x, signature);
  s.fit = least_squares(xk, *m.y, m.prior);
  if (!(s.fit.rss > 0.0)) return s;
  s.dbic = delta_bic(m, s.fit.rss);
  return s;
}

void add_heldout(const Model& m, const Eigen::VectorXd& signature, Scored& s) {
  s.heldout = heldout_prediction(hcat(m.x, signature), *m.y, *m.fold_of, m.prior);
}

bool improves_heldout(const Model& m, const Scored& s) {
  return rmse(s.heldout, *m.y) < rmse(m.heldout, *m.y);
}

Model extended(const Model& m, const Eigen::VectorXd& signature, const Scored& s) {
  Model e = m;
  e.x = hcat(m.x, signature);
  e.fit = s.fit;
  e.heldout = s.heldout;
  return e;
}

void set_heldout_metrics(Finding& f, const Model& before, const Eigen::VectorXd& after_pred) {
  const Eigen::VectorXd& y = *before.y;
  f.heldout_rmse_before_j = rmse(before.heldout, y);
  f.heldout_rmse_after_j = rmse(after_pred, y);
  f.heldout_energy_error_pct_before = energy_error_pct(before.heldout, y);
  f.heldout_energy_error_pct_after = energy_error_pct(after_pred, y);
  f.heldout_lag1_autocorrelation_before = lag1_autocorrelation(Eigen::VectorXd(y - before.heldout));
  f.heldout_lag1_autocorrelation_after = lag1_autocorrelation(Eigen::VectorXd(y - after_pred));
}

}  // namespace rollsim::diag
