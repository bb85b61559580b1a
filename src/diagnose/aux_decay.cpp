// Diagnosis stage 5, aux_load's shape: whether a found auxiliary load decays from the start of the trip (a winter
// heater bringing a cold cabin to temperature), with its time constant profiled.
#include <algorithm>
#include <cmath>

#include "pipeline.hpp"

namespace rollsim::diag {
namespace {

// The decaying share s of a load P0 + P1 exp(-t / tau) at one tau: both columns fitted beside the model, s = P1 /
// (P0 + P1) clamped to [0, 1] (a load never draws negative power), with its delta-method standard error.
struct ShareFit {
  double share = 0.0, se = 0.0;
  Eigen::VectorXd signature;
  double rss = 0.0;
};
ShareFit fit_share(const Model& m, const Eigen::VectorXd& constant, const Eigen::VectorXd& decaying) {
  const Fit two = least_squares(hcat(hcat(m.x, constant), decaying), *m.y, m.prior);
  const Eigen::Index j = two.coef.size() - 2;
  const double a0 = two.coef[j], a1 = two.coef[j + 1], sum = a0 + a1;
  ShareFit f;
  f.share = sum > 0.0 ? std::clamp(a1 / sum, 0.0, 1.0) : 0.0;
  if (sum > 0.0 && f.share > 0.0 && f.share < 1.0) {
    const double g0 = -a1 / (sum * sum), g1 = a0 / (sum * sum);  // d s / d(a0, a1)
    f.se = std::sqrt(std::max(0.0, g0 * g0 * two.cov(j, j) + 2.0 * g0 * g1 * two.cov(j, j + 1) + g1 * g1 * two.cov(j + 1, j + 1)));
  }
  f.signature = (1.0 - f.share) * constant + f.share * decaying;
  f.rss = least_squares(hcat(m.x, f.signature), *m.y, m.prior).rss;
  return f;
}

}  // namespace

std::optional<ProfileResult> refine_aux_decay(const SelectionContext& sc, Candidate& c, const Model& m, Scored& score,
                                              double decay_low_s, double decay_high_s) {
  // An electrical load on a fuel channel is seen through the alternator; a combustion car heats its cabin from the
  // coolant, and a decaying fuel excess is the engine's own warm-up (engine_warmup), so only electric channels.
  if (c.id != EffectId::aux_load || sc.obs.channel == ChannelKind::fuel_rate || !c.shape.empty()) return std::nullopt;
  const std::vector<double> grid = log_grid(decay_low_s, decay_high_s, sc.opt.profile_points_per_octave, decay_low_s);
  std::vector<EffectList> runs;
  for (double tau : grid)
    runs.push_back({make_effect(c.id, {{c.amplitude->name, c.amplitude->nominal}, {"decay_s", tau}, {"decaying_share", 1.0}}, sc.ctx)});
  const std::vector<Variant> vars = sc.replayer.run(runs, sc.obs, sc.lag_samples);
  std::vector<ShareFit> fits;
  std::vector<double> rss;
  for (const auto& v : vars) {
    fits.push_back(fit_share(m, c.signature, (v.window_j - sc.base.window_j) / c.amplitude->nominal));
    rss.push_back(fits.back().rss);
  }
  // The windows' autocorrelation from the residual of the decaying load's best fit: under the constant load both
  // residuals are the same noise, and where the load does decay the constant's residual is the decay itself, which
  // would count its own signal as correlated noise (a 3 kW heater's left the calibration 4-7 effective windows).
  const std::size_t at = static_cast<std::size_t>(std::min_element(rss.begin(), rss.end()) - rss.begin());
  const Fit with = least_squares(hcat(m.x, fits[at].signature), *m.y, m.prior);
  const Eigen::VectorXd resid = *m.y - hcat(m.x, fits[at].signature) * with.coef;
  const double rho = std::clamp(lag1_autocorrelation(resid), 0.0, 0.95), n = static_cast<double>(m.y->size());
  const double n_eff = std::max(4.0, n * (1.0 - rho) / (1.0 + rho));
  const ProfileInterval interval = profile_likelihood_interval(grid, rss, n_eff);
  const ShareFit& best = fits[interval.best];
  // The decay costs two parameters (its share and time constant) against the constant load, at the threshold every
  // discovery passes, and must predict held-out windows better.
  if (!(best.share > 0.0) || n_eff * std::log(score.fit.rss / best.rss) - 2.0 * std::log(n_eff) < sc.opt.bic_threshold)
    return std::nullopt;
  Scored s = score_column(m, best.signature);
  const double amp = s.amplitude();
  if (amp < c.min() || amp > c.max()) return std::nullopt;
  add_heldout(m, best.signature, s);
  if (rmse(s.heldout, *m.y) >= rmse(score.heldout, *m.y)) return std::nullopt;
  ProfileResult r{interval, "decay_s", best.signature, s, {}};
  r.nuisance.push_back({"decaying_share", "1", best.share, std::max(0.0, best.share - 1.96 * best.se * m.inflate),
                        std::min(1.0, best.share + 1.96 * best.se * m.inflate)});
  c.shape = {{"decay_s", interval.value}, {"decaying_share", best.share}};
  c.signature = best.signature;
  score = s;
  return r;
}

}  // namespace rollsim::diag
