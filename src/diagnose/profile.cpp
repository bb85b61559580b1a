// A found effect's shape parameters profiled (time constants on a log grid, the wind's bearing by the degree), with
// their intervals.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "pipeline.hpp"
#include "rollsim/common/error.hpp"
#include "rollsim/common/units.hpp"

namespace rollsim {

namespace {

constexpr double kChiSquare1_95 = 3.84;  // the chi-square quantile of one degree of freedom at 95 %

// The interval about the least RSS of an ascending grid, its ends interpolated in log(parameter) (a scale parameter)
// or linearly (an angle).
ProfileInterval interval_on_grid(const std::vector<double>& grid, const std::vector<double>& rss, double n_eff, double critical,
                                 bool log_axis) {
  ProfileInterval p;
  p.best = static_cast<std::size_t>(std::min_element(rss.begin(), rss.end()) - rss.begin());
  p.value = grid[p.best];
  auto stat = [&](std::size_t i) { return n_eff * std::log(rss[i] / rss[p.best]); };
  // Where the statistic crosses `critical` between grid points i (inside) and o (outside), in log(parameter).
  auto crossing = [&](std::size_t i, std::size_t o) {
    const double si = stat(i), so = stat(o);
    const double f = so > si ? (critical - si) / (so - si) : 0.0;
    if (!log_axis) return grid[i] + f * (grid[o] - grid[i]);
    return std::exp(std::log(grid[i]) + f * (std::log(grid[o]) - std::log(grid[i])));
  };
  std::size_t lo = p.best, hi = p.best;
  while (lo > 0 && stat(lo - 1) < critical) --lo;
  while (hi + 1 < grid.size() && stat(hi + 1) < critical) ++hi;
  p.low_open = lo == 0;
  p.high_open = hi + 1 == grid.size();
  p.low = p.low_open ? grid.front() : crossing(lo, lo - 1);
  p.high = p.high_open ? grid.back() : crossing(hi, hi + 1);
  return p;
}

}  // namespace

ProfileInterval profile_likelihood_interval(const std::vector<double>& grid, const std::vector<double>& rss, double n_eff,
                                            double critical) {
  if (grid.empty() || grid.size() != rss.size()) throw InputError("profile", "grid and RSS must be non-empty and of one length");
  for (std::size_t i = 0; i < grid.size(); ++i) {
    if (!(grid[i] > 0.0) || (i > 0 && !(grid[i] > grid[i - 1]))) throw InputError("profile", "grid must be positive and ascending");
    if (!(rss[i] > 0.0)) throw InputError("profile", "RSS must be positive");
  }
  return interval_on_grid(grid, rss, n_eff, critical, true);
}

namespace diag {

std::vector<double> log_grid(double low, double high, int per_octave, double also) {
  std::vector<double> g;
  const int k = std::max(1, per_octave);
  for (int i = 0;; ++i) {
    const double v = low * std::pow(2.0, static_cast<double>(i) / k);
    if (v > high * (1.0 + 1e-9)) break;
    g.push_back(std::abs(v - also) <= 1e-9 * also ? also : v);  // the chosen value itself where it lies on the grid
  }
  if (std::find(g.begin(), g.end(), also) == g.end()) g.push_back(also);
  std::sort(g.begin(), g.end());
  return g;
}

namespace {

// Adopts the profile's best grid point (its signature and score) if its amplitude is within bounds and it also fits
// better out of fold; otherwise the selection's value stays. The value kept is always inside the interval.
void keep_best_if_better(const Model& m, const std::vector<double>& grid, const Eigen::VectorXd& best_signature, double selected,
                         double amp_min, double amp_max, ProfileResult& r) {
  double kept = selected;
  if (grid[r.interval.best] != selected) {
    Scored s = score_column(m, best_signature);
    add_heldout(m, best_signature, s);
    const double amp = s.amplitude();
    if (amp >= amp_min && amp <= amp_max && rmse(s.heldout, *m.y) < rmse(r.score.heldout, *m.y)) {
      r.score = s;
      r.signature = best_signature;
      kept = grid[r.interval.best];
    }
  }
  r.interval.value = kept;
  r.interval.low = std::min(r.interval.low, kept);
  r.interval.high = std::max(r.interval.high, kept);
}

// How much wider than the likelihood ratio's the bearing's interval must be (>= 1): the bearing's delete-a-block
// jackknife variance against the variance the ratio's own interval implies ((high - low) / (2 x 1.96))^2. The ratio
// n_eff ln(RSS / RSS_min) gives every window one variance, but a steady wind fitted to a gusty one leaves residuals
// that grow where the route runs along the wind, in the windows that carry the bearing, and the bearing's profile is
// far from quadratic at a few m/s: its 95 % interval held the gusty truth on 2 of 3 seeds (a Newey-West sandwich,
// linearised at the best bearing, brought that to 4 of 5). The jackknife refits everything, the calibration's boxes
// included, without each of `groups` contiguous blocks of windows.
double bearing_jackknife_widening(const Model& m, const std::vector<double>& grid, const std::vector<Eigen::VectorXd>& sigs,
                                  const ProfileInterval& ratio_interval) {
  const Eigen::Index n = m.x.rows(), cols = m.x.cols() + 1;
  const Eigen::Index groups = std::min<Eigen::Index>(20, n / 3);
  if (groups < 5 || ratio_interval.low_open || ratio_interval.high_open) return 1.0;
  std::vector<double> estimate;
  Eigen::MatrixXd xk;
  for (Eigen::Index b = 0; b < groups; ++b) {
    const Eigen::Index from = n * b / groups, to = n * (b + 1) / groups, kept = n - (to - from);
    xk.resize(kept, cols);
    xk.topLeftCorner(from, cols - 1) = m.x.topRows(from);
    xk.bottomLeftCorner(n - to, cols - 1) = m.x.bottomRows(n - to);
    Eigen::VectorXd yk(kept);
    yk << m.y->head(from), m.y->tail(n - to);
    double best_rss = std::numeric_limits<double>::infinity(), best_deg = grid.front();
    for (std::size_t g = 0; g < grid.size(); ++g) {
      xk.col(cols - 1) << sigs[g].head(from), sigs[g].tail(n - to);
      const double rss = least_squares(xk, yk, m.prior).rss;
      if (rss < best_rss) best_rss = rss, best_deg = grid[g];
    }
    estimate.push_back(best_deg);
  }
  double mean = 0.0, var = 0.0;
  for (double e : estimate) mean += e / static_cast<double>(groups);
  for (double e : estimate) var += (e - mean) * (e - mean);
  var *= static_cast<double>(groups - 1) / static_cast<double>(groups);
  const double half_width = 0.5 * (ratio_interval.high - ratio_interval.low) / 1.96;
  if (!(half_width > 0.0)) return 1.0;
  return std::max(1.0, var / (half_width * half_width));
}

}  // namespace

// Only for a found effect, so a recording with nothing to find costs nothing more.
ProfileResult profile_time_constant(const Model& m, const TimeProfile& tp, const Eigen::VectorXd& selected_signature,
                                    const Scored& selected_score, double amp_min, double amp_max) {
  std::vector<double> others;
  for (double g : tp.grid)
    if (g != tp.selected) others.push_back(g);
  const std::vector<Eigen::VectorXd> other_sigs = tp.signatures(others);
  std::vector<Eigen::VectorXd> sigs;
  std::vector<double> rss;
  std::size_t k = 0;
  for (double g : tp.grid) {
    sigs.push_back(g == tp.selected ? selected_signature : other_sigs[k++]);
    // Where the effect does nothing at this grid value (a regen limit above every braking power of the trace), the
    // model is the one without it: a zero column has no least-squares solution of its own.
    const bool inert = !(sigs.back().norm() > 0.0);
    rss.push_back(inert ? m.fit.rss : least_squares(hcat(m.x, sigs.back()), *m.y, m.prior).rss);
  }
  ProfileResult r{profile_likelihood_interval(tp.grid, rss, m.n_eff), tp.parameter, selected_signature, selected_score, {}};
  keep_best_if_better(m, tp.grid, sigs[r.interval.best], tp.selected, amp_min, amp_max, r);
  return r;
}

ProfileResult profile_bearing(const Model& m, double centre_deg, double step_deg, const std::vector<Eigen::VectorXd>& replayed,
                              const Scored& centre_score, double amp_min, double amp_max) {
  constexpr double kStepDeg = 1.0, kHalfDeg = 90.0;
  const std::size_t last = replayed.size() - 1;
  if (replayed.size() < 3 || replayed.size() % 2 == 0 || std::abs(static_cast<double>(last) * step_deg - 2.0 * kHalfDeg) > 1e-9)
    throw std::logic_error("profile_bearing: needs an odd number of replays spanning the half circle");
  std::vector<double> grid, rss;
  std::vector<Eigen::VectorXd> sigs;
  for (double d = -kHalfDeg; d <= kHalfDeg + 1e-9; d += kStepDeg) {
    // Between replays the signature is interpolated: it turns smoothly with the bearing, and a replay per degree
    // would cost 181 of them.
    const double at = (d + kHalfDeg) / step_deg;
    const std::size_t k = std::min(static_cast<std::size_t>(at), last - 1);
    const double f = at - static_cast<double>(k);
    grid.push_back(centre_deg + d);  // d steps by whole degrees from -90: exactly 0 at the centre
    sigs.push_back((1.0 - f) * replayed[k] + f * replayed[k + 1]);
    rss.push_back(least_squares(hcat(m.x, sigs.back()), *m.y, m.prior).rss);
  }
  const ProfileInterval ratio_interval = interval_on_grid(grid, rss, m.n_eff, kChiSquare1_95, false);
  const double widening = bearing_jackknife_widening(m, grid, sigs, ratio_interval);
  ProfileResult r{widening > 1.0 ? interval_on_grid(grid, rss, m.n_eff, kChiSquare1_95 * widening, false) : ratio_interval,
                  "wind_from_deg", replayed[last / 2], centre_score, {}};
  keep_best_if_better(m, grid, sigs[r.interval.best], centre_deg, amp_min, amp_max, r);
  return r;
}

}  // namespace diag
}  // namespace rollsim
