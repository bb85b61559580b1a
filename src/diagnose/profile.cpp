// A found effect's time constant refined on a log grid, with its profile-likelihood interval.
#include <algorithm>
#include <cmath>

#include "pipeline.hpp"
#include "rollsim/common/error.hpp"

namespace rollsim {

ProfileInterval profile_likelihood_interval(const std::vector<double>& grid, const std::vector<double>& rss, double n_eff,
                                            double critical) {
  if (grid.empty() || grid.size() != rss.size()) throw InputError("profile", "grid and RSS must be non-empty and of one length");
  for (std::size_t i = 0; i < grid.size(); ++i) {
    if (!(grid[i] > 0.0) || (i > 0 && !(grid[i] > grid[i - 1]))) throw InputError("profile", "grid must be positive and ascending");
    if (!(rss[i] > 0.0)) throw InputError("profile", "RSS must be positive");
  }
  ProfileInterval p;
  p.best = static_cast<std::size_t>(std::min_element(rss.begin(), rss.end()) - rss.begin());
  p.value = grid[p.best];
  auto stat = [&](std::size_t i) { return n_eff * std::log(rss[i] / rss[p.best]); };
  // Where the statistic crosses `critical` between grid points i (inside) and o (outside), in log(parameter).
  auto crossing = [&](std::size_t i, std::size_t o) {
    const double si = stat(i), so = stat(o);
    const double f = so > si ? (critical - si) / (so - si) : 0.0;
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
  double kept = tp.selected;
  if (tp.grid[r.interval.best] != tp.selected) {
    Scored s = score_column(m, sigs[r.interval.best]);
    add_heldout(m, sigs[r.interval.best], s);
    const double amp = s.amplitude();
    if (amp >= amp_min && amp <= amp_max && rmse(s.heldout, *m.y) < rmse(selected_score.heldout, *m.y)) {
      r.score = s;
      r.signature = sigs[r.interval.best];
      kept = tp.grid[r.interval.best];
    }
  }
  // The value kept is the selection's when the profile's best did not also fit better held out: keep it inside.
  r.interval.value = kept;
  r.interval.low = std::min(r.interval.low, kept);
  r.interval.high = std::max(r.interval.high, kept);
  return r;
}

}  // namespace diag
}  // namespace rollsim
