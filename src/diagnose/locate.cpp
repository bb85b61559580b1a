// Diagnosis stage 8: where the calibrated model misses: mean residual by regime, and the per-window series.
#include <algorithm>
#include <cmath>
#include <map>

#include "pipeline.hpp"

#include "rollsim/common/units.hpp"

namespace rollsim::diag {
namespace {

struct Mean {
  double mean = 0.0, se = 0.0, n_eff = 0.0;
};

// Mean of the values with its standard error, variance inflated for AR(1) correlation `rho` (clamped to [0, 0.99]).
Mean ar1_mean(const std::vector<double>& v, double rho) {
  const double rs = std::clamp(rho, 0.0, 0.99);
  const double factor = (1.0 + rs) / (1.0 - rs);
  double mean = 0.0, var = 0.0;
  for (double e : v) mean += e;
  mean /= static_cast<double>(v.size());
  for (double e : v) var += (e - mean) * (e - mean);
  var /= static_cast<double>(v.size() - 1);
  const double n_eff = static_cast<double>(v.size()) / factor;
  return {mean, std::sqrt(var / n_eff), n_eff};
}

// Do the standstills' mean residuals scatter beyond the noise within them? A one-way analysis of variance over the
// standstills of 5 samples or more: the noise variance from successive differences within each (a level that
// switches between standstills does not enter it), inflated for its pooled lag-1 autocorrelation, against the
// scatter of their means; the chi-square as a normal deviate (Wilson-Hilferty).
void standstill_switching(const std::vector<std::vector<double>>& runs, SelectionContext::Standing& out) {
  constexpr std::size_t kMinSamples = 5;
  std::vector<double> means;
  std::vector<double> sizes;
  double diff2 = 0.0, diffs = 0.0, total = 0.0, samples = 0.0;
  for (const auto& run : runs) {
    if (run.size() < kMinSamples) continue;
    double m = 0.0;
    for (double x : run) m += x / static_cast<double>(run.size());
    means.push_back(m);
    sizes.push_back(static_cast<double>(run.size()));
    total += m * static_cast<double>(run.size()), samples += static_cast<double>(run.size());
    for (std::size_t k = 1; k < run.size(); ++k) diff2 += (run[k] - run[k - 1]) * (run[k] - run[k - 1]), diffs += 1.0;
  }
  out.standstills = static_cast<int>(means.size());
  if (means.size() < 3 || !(diff2 > 0.0)) return;
  double c0 = 0.0, c1 = 0.0;
  std::size_t q = 0;
  for (const auto& run : runs) {
    if (run.size() < kMinSamples) continue;
    const double m = means[q++];
    for (std::size_t k = 0; k < run.size(); ++k) {
      c0 += (run[k] - m) * (run[k] - m);
      if (k > 0) c1 += (run[k] - m) * (run[k - 1] - m);
    }
  }
  const double rho = c0 > 0.0 ? std::clamp(c1 / c0, 0.0, 0.95) : 0.0;
  const double noise_var = diff2 / (2.0 * diffs) * (1.0 + rho) / (1.0 - rho);
  const double grand = total / samples;
  double chi2 = 0.0;
  for (std::size_t r = 0; r < means.size(); ++r) chi2 += sizes[r] * (means[r] - grand) * (means[r] - grand) / noise_var;
  const double dof = static_cast<double>(means.size() - 1);
  out.switching_z = (std::cbrt(chi2 / dof) - (1.0 - 2.0 / (9.0 * dof))) / std::sqrt(2.0 / (9.0 * dof));
  const auto [lo, hi] = std::minmax_element(means.begin(), means.end());
  out.low_w = *lo, out.high_w = *hi;
}

// Mean residual of each regime (in `order`, those with two values or more) with a 95 % normal interval.
void append_regime_means(const std::vector<std::string>& order, const std::map<std::string, std::vector<double>>& vals,
                         double rho, std::vector<RegimeResidual>& out) {
  for (const auto& name : order) {
    const auto it = vals.find(name);
    if (it == vals.end() || it->second.size() < 2) continue;
    const Mean m = ar1_mean(it->second, rho);
    out.push_back({name, static_cast<int>(it->second.size()), m.mean, m.mean - 1.96 * m.se, m.mean + 1.96 * m.se});
  }
}

// SOC gives energy per window, not power per sample: locate by window, each window in the regimes of its own means
// (speed, grade, time since start). Mean residual power of the windows, with the same AR(1) inflation.
std::vector<RegimeResidual> locate_windows(const Observations& o, const std::vector<Recording>& recordings,
                                           const std::vector<DriveCycle>& cycles, const Eigen::VectorXd& res_j) {
  std::map<std::string, std::vector<double>> vals;
  const std::vector<std::string> order{"standing (window)", "speed 0-50 km/h (window)", "speed 50-90 km/h (window)",
                                       "speed >90 km/h (window)", "first 10 min (window)", "10-30 min (window)",
                                       "after 30 min (window)", "uphill > 1 % (window)", "level (window)",
                                       "downhill < -1 % (window)"};
  for (std::size_t w = 0; w < o.windows.size(); ++w) {
    const auto& win = o.windows[w];
    const DriveCycle& c = cycles[win.rec];
    const double duration_s = c.time_s[win.end] - c.time_s[win.begin];
    if (!(duration_s > 0.0)) continue;
    double distance_m = 0.0, rise = 0.0;
    for (std::size_t i = win.begin; i < win.end; ++i) {
      const double ds = 0.5 * (c.speed_mps[i] + c.speed_mps[i + 1]) * (c.time_s[i + 1] - c.time_s[i]);
      distance_m += ds;
      rise += c.grade[i] * ds;
    }
    const double v = distance_m / duration_s;
    const double p_w = res_j[static_cast<Eigen::Index>(w)] / duration_s;
    const double mid_s = 0.5 * (c.time_s[win.begin] + c.time_s[win.end]) - c.time_s.front();
    vals[v < 0.5 ? "standing (window)" : v < units::kmh_to_mps(50.0) ? "speed 0-50 km/h (window)"
                                       : v < units::kmh_to_mps(90.0) ? "speed 50-90 km/h (window)" : "speed >90 km/h (window)"].push_back(p_w);
    vals[mid_s < 600 ? "first 10 min (window)" : mid_s < 1800 ? "10-30 min (window)" : "after 30 min (window)"].push_back(p_w);
    const Recording& r = recordings[win.rec];
    if ((r.grade || r.elevation_m) && distance_m > 0.0) {
      const double g = rise / distance_m;
      vals[g > 0.01 ? "uphill > 1 % (window)" : g < -0.01 ? "downhill < -1 % (window)" : "level (window)"].push_back(p_w);
    }
  }
  std::vector<RegimeResidual> out;
  append_regime_means(order, vals, lag1_autocorrelation(res_j), out);
  return out;
}

}  // namespace

std::vector<RegimeResidual> locate_regimes(const Observations& o, const std::vector<Recording>& recordings,
                                           const std::vector<DriveCycle>& cycles, const Signatures& s,
                                           const Eigen::VectorXd& cal_coef, double lag_samples, SelectionContext::Standing* standing) {
  if (o.channel == ChannelKind::soc) {
    const Eigen::VectorXd res_j = o.measured_j - (cal_coef[0] * s.base.window_j + cal_coef[1] * (s.rrc.window_j - s.base.window_j) +
                                                  cal_coef[2] * (s.drag.window_j - s.base.window_j));
    return locate_windows(o, recordings, cycles, res_j);
  }
  const std::vector<std::string> order{"standing", "accelerating", "cruising", "braking", "speed 0-50 km/h",
                                       "speed 50-90 km/h", "speed >90 km/h", "first 10 min", "10-30 min", "after 30 min",
                                       "uphill (> 1 %)", "level", "downhill (< -1 %)"};
  std::map<std::string, std::vector<double>> vals;
  std::vector<double> all;
  std::vector<std::vector<double>> standstills;  // each standstill's residuals, recording by recording
  // The model at the channel's whole lag, fraction included, as the windows read it: rounded to a sample, a null
  // with a 0.4 s lag at 1 Hz read 'accelerating -601 W [-817, -385]' (session 25's outside testing).
  for (std::size_t ri = 0; ri < recordings.size(); ++ri) {
    const Recording& r = recordings[ri];
    bool standing_before = false;
    for (std::size_t i = 0; i + 1 < r.time_s.size(); ++i) {
      const double base = lagged_power_w(s.base, ri, i, lag_samples);
      const double sim = cal_coef[0] * base + cal_coef[1] * (lagged_power_w(s.rrc, ri, i, lag_samples) - base) +
                         cal_coef[2] * (lagged_power_w(s.drag, ri, i, lag_samples) - base);
      const double res = o.measured_w[ri][i] - sim;
      const double v = r.speed_mps[i], a = (r.speed_mps[i + 1] - v) / o.dt_s[ri][i];
      const double t = r.time_s[i] - r.time_s.front();
      all.push_back(res);
      vals[v < 0.3 ? "standing" : a > 0.3 ? "accelerating" : a < -0.3 ? "braking" : "cruising"].push_back(res);
      if (v < 0.3 && !standing_before) standstills.emplace_back();
      if (v < 0.3) standstills.back().push_back(res);
      standing_before = v < 0.3;
      if (v >= 0.3) vals[v < units::kmh_to_mps(50.0) ? "speed 0-50 km/h" : v < units::kmh_to_mps(90.0) ? "speed 50-90 km/h" : "speed >90 km/h"].push_back(res);
      vals[t < 600 ? "first 10 min" : t < 1800 ? "10-30 min" : "after 30 min"].push_back(res);
      // Grade regimes only where the recording gave grade or elevation (the replay trace then carries it).
      if (r.grade || r.elevation_m) {
        const double g = cycles[ri].grade[i];
        if (v >= 0.3) vals[g > 0.01 ? "uphill (> 1 %)" : g < -0.01 ? "downhill (< -1 %)" : "level"].push_back(res);
      }
    }
  }
  const double rho = lag1_autocorrelation(Eigen::Map<Eigen::VectorXd>(all.data(), static_cast<Eigen::Index>(all.size())));
  std::vector<RegimeResidual> out;
  append_regime_means(order, vals, rho, out);
  if (standing && vals["standing"].size() >= 2) {
    const Mean m = ar1_mean(vals["standing"], rho);
    *standing = {true, m.mean, m.se, m.n_eff};
    standstill_switching(standstills, *standing);
  }
  return out;
}

std::vector<DiagnosisWindow> window_series(const Observations& o, const std::vector<Recording>& recordings,
                                           const Eigen::VectorXd& base_j, const Eigen::VectorXd& calibrated_j,
                                           const Eigen::VectorXd& fitted_j) {
  std::vector<DiagnosisWindow> out;
  for (Eigen::Index w = 0; w < o.n(); ++w) {
    const auto& win = o.windows[static_cast<std::size_t>(w)];
    const Recording& r = recordings[win.rec];
    DiagnosisWindow dw;
    dw.recording = static_cast<int>(win.rec);
    dw.start_s = r.time_s[win.begin] - r.time_s.front();
    dw.end_s = r.time_s[win.end] - r.time_s.front();
    double sv = 0.0, sa = 0.0, T = 0.0;
    for (std::size_t i = win.begin; i < win.end; ++i) {
      const double dt = o.dt_s[win.rec][i];
      sv += 0.5 * (r.speed_mps[i] + r.speed_mps[i + 1]) * dt;
      sa += std::max(0.0, r.speed_mps[i + 1] - r.speed_mps[i]);
      T += dt;
    }
    dw.mean_speed_mps = sv / std::max(1e-9, T);
    dw.mean_positive_accel_mps2 = sa / std::max(1e-9, T);
    dw.measured_j = o.measured_j[w];
    dw.simulated_j = base_j[w];
    dw.calibrated_j = calibrated_j[w];
    dw.fitted_j = fitted_j[w];
    out.push_back(dw);
  }
  return out;
}

}  // namespace rollsim::diag
