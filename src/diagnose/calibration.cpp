// Diagnosis stage 3: calibration (channel scale, RRC level, aero C) within each quantity's physical prior.
#include <algorithm>
#include <cmath>

#include "pipeline.hpp"
#include "rollsim/common/error.hpp"

namespace rollsim {

std::string to_string(ChannelKind k) {
  switch (k) {
    case ChannelKind::battery_power: return "battery_power";
    case ChannelKind::battery_voltage_x_current: return "battery_voltage_x_current";
    case ChannelKind::fuel_rate: return "fuel_rate";
    case ChannelKind::soc: return "soc";
  }
  return "soc";
}

double CalibrationPriors::scale_bound(ChannelKind k) const {
  switch (k) {
    case ChannelKind::battery_power:
    case ChannelKind::battery_voltage_x_current: return terminal_scale_bound;
    case ChannelKind::fuel_rate: return fuel_scale_bound;
    case ChannelKind::soc: return soc_scale_bound;
  }
  return soc_scale_bound;
}

CalibrationPriors calibration_priors_from_yaml(YamlMap& file) {
  CalibrationPriors p;
  auto m = file.optional_map("calibration_priors");
  if (!m) return p;
  const Range fraction = Range::closed(0.001, 0.5);
  if (auto v = m->optional_number("terminal_scale_bound", fraction)) p.terminal_scale_bound = *v;
  if (auto v = m->optional_number("fuel_scale_bound", fraction)) p.fuel_scale_bound = *v;
  if (auto v = m->optional_number("soc_scale_bound", fraction)) p.soc_scale_bound = *v;
  if (auto v = m->optional_number("rrc_level_sd", fraction)) p.rrc_level_sd = *v;
  if (auto v = m->optional_number("drag_sd", fraction)) p.drag_sd = *v;
  m->finish();
  return p;
}

namespace diag {

// measured = s sim + a S_rrc + b S_drag, with a and b per 10 % change. RRC level and aero C carry Gaussian
// penalties at their published uncertainty (they keep short trips, where scale, RRC and C are nearly collinear,
// physical); the scale is held in its box. Whatever the box keeps the scale from absorbing is left in the residual,
// for the effects and the adequacy test to explain: a calibration never hides it.
Calibration calibrate(const Observations& o, const Variant& base, const Variant& rrc, const Variant& drag,
                      const CalibrationPriors& priors) {
  const Eigen::Index n = o.n();
  Calibration c;
  Model& m = c.model;
  m.x.resize(n, 3);
  m.x.col(0) = base.window_j;
  m.x.col(1) = rrc.window_j - base.window_j;
  m.x.col(2) = drag.window_j - base.window_j;
  m.y = &o.measured_j;
  m.fold_of = &o.fold_of;
  const Fit unpenalised = least_squares(m.x, o.measured_j);
  const double noise_sd = std::sqrt(unpenalised.rss / std::max<double>(1.0, static_cast<double>(n - 3)));
  m.prior.rows = {{1, noise_sd / (priors.rrc_level_sd / 0.1), 0.0}, {2, noise_sd / (priors.drag_sd / 0.1), 0.0}};
  const Fit free = least_squares(m.x, o.measured_j, m.prior);
  const double bound = priors.scale_bound(o.channel);
  m.prior.scale_low = 1.0 - bound;
  m.prior.scale_high = 1.0 + bound;
  c.prior_scale_sd = bound;
  c.free_scale = free.coef[0];
  m.fit = least_squares(m.x, o.measured_j, m.prior);
  c.scale_at_bound = m.fit.coef[0] != c.free_scale;
  c.absorbed_j = (m.x * free.coef).sum() - (m.x * m.fit.coef).sum();
  const Eigen::VectorXd resid = o.measured_j - m.x * m.fit.coef;
  const double rho = std::clamp(lag1_autocorrelation(resid), 0.0, 0.95);
  m.n_eff = std::max(4.0, static_cast<double>(n) * (1.0 - rho) / (1.0 + rho));
  m.inflate = std::sqrt(static_cast<double>(n) / m.n_eff);  // autocorrelated windows carry less information
  m.heldout = heldout_prediction(m.x, o.measured_j, o.fold_of, m.prior);
  return c;
}

}  // namespace diag
}  // namespace rollsim

namespace rollsim::diag {

// What the scale held at its bound leaves, and which catalogue effects could take a level error of that size: an
// effect whose signature alone explains at least half of it with an amplitude inside its bounds.
std::string calibration_outside_prior_text(const Calibration& c, const Observations& o, const std::vector<Candidate>& cands) {
  const Eigen::VectorXd& base = c.model.x.col(0);
  const double s = c.model.fit.coef[0];
  const Eigen::VectorXd left = (c.free_scale - s) * base;
  std::string could;
  for (const auto& cand : cands) {
    const double ss = cand.signature.squaredNorm();
    if (!(ss > 0.0) || could.find(to_string(cand.id)) != std::string::npos) continue;
    const double proj = cand.signature.dot(left);
    const double amp = proj / ss / s, explained = proj * proj / ss / std::max(1e-300, left.squaredNorm());
    if (explained >= 0.5 && amp >= cand.min() && amp <= cand.max())
      could += (could.empty() ? "" : ", ") + to_string(cand.id) + " (" + fixed(amp, 3) + " " + cand.amplitude->unit + ")";
  }
  return "the data alone wanted a channel scale of " + fixed(c.free_scale, 3) + ", outside its prior [" +
         fixed(c.model.prior.scale_low, 2) + ", " + fixed(c.model.prior.scale_high, 2) + "] for a " + to_string(o.channel) +
         " channel; it would have absorbed " + fixed(100.0 * c.absorbed_j / std::max(1e-9, std::abs(o.measured_j.sum())), 1) +
         " % of the measured energy. " +
         (could.empty() ? std::string("No catalogue effect alone explains a level error of that size: a drive efficiency, "
                                      "capacity or consumer the model lacks")
                        : "Effects that could explain a level error of that size: " + could +
                              " (not separable from it on this data: log a standstill, a steady-speed run and a hill)");
}

}  // namespace rollsim::diag
