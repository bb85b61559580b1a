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

// The criterion least_squares minimises: the residual's sum of squares and the priors' penalties.
double penalised_criterion(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, const Prior& prior, const Eigen::VectorXd& c) {
  double v = (y - x * c).squaredNorm();
  for (const auto& r : prior.rows) v += r.weight * r.weight * (c[r.column] - r.target) * (c[r.column] - r.target);
  return v;
}

}  // namespace

// Boxes by active sets: where the free optimum leaves a box, every combination of boxed columns held free, at
// their lower or at their upper bound is solved, and the feasible one of least penalised criterion kept (exact for
// this convex quadratic; at most 3^3 small solves, and only when a bound is active).
Fit least_squares(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, const Prior& prior) {
  Fit free = penalised(x, y, prior.rows);
  auto feasible = [&](const Eigen::VectorXd& c) {
    for (const auto& b : prior.boxes)
      if (c[b.column] < b.low - 1e-12 || c[b.column] > b.high + 1e-12) return false;
    return true;
  };
  if (feasible(free.coef)) return free;
  const std::size_t nb = prior.boxes.size();
  int combos = 1;
  for (std::size_t k = 0; k < nb; ++k) combos *= 3;
  Fit best;
  double best_value = 1e300;
  for (int combo = 1; combo < combos; ++combo) {
    std::vector<int> state(nb);  // 0 free, 1 low, 2 high
    for (int k = 0, c = combo; k < static_cast<int>(nb); ++k, c /= 3) state[static_cast<std::size_t>(k)] = c % 3;
    std::vector<double> fixed_value(static_cast<std::size_t>(x.cols()), std::nan(""));
    for (std::size_t k = 0; k < nb; ++k)
      if (state[k]) fixed_value[static_cast<std::size_t>(prior.boxes[k].column)] = state[k] == 1 ? prior.boxes[k].low : prior.boxes[k].high;
    std::vector<Eigen::Index> free_cols, new_index(static_cast<std::size_t>(x.cols()), -1);
    Eigen::VectorXd yr = y;
    for (Eigen::Index c = 0; c < x.cols(); ++c) {
      const double v = fixed_value[static_cast<std::size_t>(c)];
      if (std::isnan(v)) {
        new_index[static_cast<std::size_t>(c)] = static_cast<Eigen::Index>(free_cols.size());
        free_cols.push_back(c);
      } else {
        yr -= v * x.col(c);
      }
    }
    Eigen::VectorXd coef(x.cols());
    Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(x.cols(), x.cols());
    if (!free_cols.empty()) {
      Eigen::MatrixXd xr(x.rows(), static_cast<Eigen::Index>(free_cols.size()));
      for (std::size_t k = 0; k < free_cols.size(); ++k) xr.col(static_cast<Eigen::Index>(k)) = x.col(free_cols[k]);
      std::vector<Prior::Row> rows;
      for (const auto& r : prior.rows)
        if (new_index[static_cast<std::size_t>(r.column)] >= 0) rows.push_back({new_index[static_cast<std::size_t>(r.column)], r.weight, r.target});
      const Fit f = penalised(xr, yr, rows);
      for (std::size_t k = 0; k < free_cols.size(); ++k) {
        coef[free_cols[k]] = f.coef[static_cast<Eigen::Index>(k)];
        for (std::size_t q = 0; q < free_cols.size(); ++q)
          cov(free_cols[k], free_cols[q]) = f.cov(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(q));
      }
    }
    for (Eigen::Index c = 0; c < x.cols(); ++c)
      if (!std::isnan(fixed_value[static_cast<std::size_t>(c)])) coef[c] = fixed_value[static_cast<std::size_t>(c)];
    if (!feasible(coef)) continue;
    const double value = penalised_criterion(x, y, prior, coef);
    if (value >= best_value) continue;
    best_value = value;
    best.coef = coef;
    best.cov = cov;
  }
  if (best.coef.size() == 0) return free;  // unreachable: all at bounds is always feasible
  best.rss = (y - x * best.coef).squaredNorm();
  return best;
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

namespace {

bool box_active(const Prior& prior, const Eigen::VectorXd& coef) {
  for (const auto& b : prior.boxes)
    if (std::abs(coef[b.column] - b.low) < 1e-12 || std::abs(coef[b.column] - b.high) < 1e-12) return true;
  return false;
}

}  // namespace

std::pair<double, double> amplitude_interval(const Model& m, const Eigen::VectorXd& signature, const Scored& s, double inflate) {
  const double value = s.amplitude(), se = s.amplitude_se(inflate);
  const std::pair<double, double> wald{value - 1.96 * se, value + 1.96 * se};
  if (!box_active(m.prior, s.fit.coef) || !(se > 0.0)) return wald;
  // At amplitude a the model is c0 (x0 + a signature) + the rest: linear in the coefficients, boxes kept.
  auto rise = [&](double a) {
    Eigen::MatrixXd x = m.x;
    x.col(0) += a * signature;
    const Fit f = least_squares(x, *m.y, m.prior);
    return penalised_criterion(x, *m.y, m.prior, f.coef);
  };
  const Eigen::Index n = m.x.rows(), p = m.x.cols() + 1;
  const double variance = s.fit.rss / std::max<double>(1.0, static_cast<double>(n - p));
  const double minimum = rise(value), threshold = minimum + 1.96 * 1.96 * inflate * inflate * variance;
  // Each end: stepped out from the Wald end (doubling) until the criterion passes the threshold, then bisected.
  auto end = [&](double direction) {
    double inside = value, outside = value + direction * 1.96 * se;
    for (int k = 0; k < 12 && rise(outside) < threshold; ++k) inside = outside, outside = value + direction * 1.96 * se * std::pow(2.0, k + 1);
    for (int k = 0; k < 40; ++k) {
      const double mid = 0.5 * (inside + outside);
      (rise(mid) < threshold ? inside : outside) = mid;
    }
    return 0.5 * (inside + outside);
  };
  return {std::min(wald.first, end(-1.0)), std::max(wald.second, end(+1.0))};
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

void set_finding_metrics(Finding& f, const Model& before, const Eigen::VectorXd& signature, const Scored& after) {
  const Eigen::VectorXd& y = *before.y;
  const Eigen::VectorXd& after_pred = after.heldout;
  f.energy_share_pct = 100.0 * after.fit.coef[after.fit.coef.size() - 1] * signature.sum() / std::max(1e-9, std::abs(y.sum()));
  f.heldout_rmse_before_j = rmse(before.heldout, y);
  f.heldout_rmse_after_j = rmse(after_pred, y);
  f.heldout_energy_error_pct_before = energy_error_pct(before.heldout, y);
  f.heldout_energy_error_pct_after = energy_error_pct(after_pred, y);
  f.heldout_lag1_autocorrelation_before = lag1_autocorrelation(Eigen::VectorXd(y - before.heldout));
  f.heldout_lag1_autocorrelation_after = lag1_autocorrelation(Eigen::VectorXd(y - after_pred));
  f.heldout_scored = true;
}

}  // namespace rollsim::diag
