// Diagnosis stage 6: what the catalogue left: a residual described by its signature, and the adequacy test of the
// final model against the recording's own noise floor.
#include <algorithm>
#include <cmath>

#include "pipeline.hpp"

#include "rollsim/common/units.hpp"

namespace rollsim::diag {
namespace {

constexpr double kDecayGridLowS = 150.0, kDecayGridHighS = 4800.0;  // the basis' 300-2400 s lie on it

struct BasisWords {
  std::string what, size_text, name, unit;
};

BasisWords words_of(const BasisShape& b, double value, double vref_kmh, ChannelKind channel) {
  const double u = vref_kmh / 100.0;
  const double at_ref = b.shape == ForceShape::speed ? u : b.shape == ForceShape::speed_squared ? u * u : 1.0;
  if (b.kind == BasisShape::power)
    return {"a constant power at the " + to_string(channel) + " channel", "about " + fixed(value, 0) + " W", "power", "W"};
  if (b.shape == ForceShape::positive_accel)
    return {"a force proportional to acceleration, when accelerating only",
            "about " + fixed(value, 0) + " N at 1 m/s^2 (as if " + fixed(value, 0) +
                " kg more mass had to be accelerated but none came back in braking)",
            "force_per_positive_accel", "N s^2/m"};
  if (b.shape == ForceShape::constant) return {"a constant force while moving", "about " + fixed(value, 0) + " N", "force", "N"};
  return {b.shape == ForceShape::speed ? "a force proportional to speed" : "a force proportional to speed squared",
          "about " + fixed(value * at_ref, 0) + " N at " + fixed(vref_kmh, 0) + " km/h", "force_at_100kmh", "N"};
}

// "Mostly in the first N minutes": when 80 % of the signature's energy has accrued (windows by end time).
double minutes_to_80pct(const Observations& o, const std::vector<DriveCycle>& cycles, const Eigen::VectorXd& sig) {
  std::vector<std::pair<double, double>> by_end;
  for (Eigen::Index w = 0; w < o.n(); ++w) {
    const auto& win = o.windows[static_cast<std::size_t>(w)];
    by_end.push_back({cycles[win.rec].time_s[win.end], std::abs(sig[w])});
  }
  std::sort(by_end.begin(), by_end.end());
  double total = 0.0, cum = 0.0, t80 = 0.0;
  for (const auto& p : by_end) total += p.second;
  for (const auto& p : by_end) {
    cum += p.second;
    t80 = p.first;
    if (cum >= 0.8 * total) break;
  }
  return std::ceil(t80 / 60.0);
}

}  // namespace

// The basis shape that explains most of what is left, if it passes the same BIC threshold and held-out test.
std::optional<Finding> describe_unexplained(const SelectionContext& sc, const std::vector<DriveCycle>& cycles,
                                            const std::vector<BasisShape>& basis, Model& m) {
  // Across recordings a shape must also beat each trip's own aero level: a day's air density moves 1-3 % with the
  // barometer, unrecorded, and pooled trips read it as "a force proportional to speed squared decaying from the start
  // of the trip" (session 27's outside tester: 5 of 30 pooled null sets, their residuals at 0.8-1.0 x the floor).
  Model weather = m;
  for (std::size_t r = 1; r < sc.recordings.size(); ++r) {
    Eigen::VectorXd aero = Eigen::VectorXd::Zero(m.x.rows());
    for (Eigen::Index w = 0; w < m.x.rows(); ++w)
      if (sc.obs.windows[static_cast<std::size_t>(w)].rec == r) aero[w] = m.x(w, 2);
    weather = extended(weather, aero, score_column(weather, aero));
  }
  int best_k = -1;
  Scored best;
  best.dbic = sc.opt.bic_threshold;
  for (std::size_t k = 0; k < basis.size(); ++k) {
    if (basis[k].signature.norm() <= 0.0) continue;
    Scored s = score_column(m, basis[k].signature);
    if (s.dbic <= best.dbic) continue;
    if (sc.recordings.size() > 1 && score_column(weather, basis[k].signature).dbic <= sc.opt.bic_threshold) continue;
    add_heldout(m, basis[k].signature, s);
    if (!improves_heldout(m, s)) continue;
    best_k = static_cast<int>(k);
    best = std::move(s);
  }
  if (best_k < 0) return std::nullopt;
  BasisShape b = basis[static_cast<std::size_t>(best_k)];
  std::optional<ProfileResult> prof;
  if (b.decay_s > 0.0) {
    // A decaying shape's time constant came from the basis' grid: refine and profile it as for the warm-ups.
    TimeProfile tp;
    tp.parameter = "decay_time_constant_s";
    tp.selected = b.decay_s;
    tp.grid = log_grid(kDecayGridLowS, kDecayGridHighS, sc.opt.profile_points_per_octave, b.decay_s);
    tp.signatures = [&](const std::vector<double>& values) {
      std::vector<Eigen::VectorXd> sigs(values.size());
      std::vector<EffectList> runs;
      std::vector<std::size_t> run_of;
      for (std::size_t g = 0; g < values.size(); ++g) {
        const auto same = std::find_if(basis.begin(), basis.end(), [&](const BasisShape& o) {
          return o.kind == b.kind && o.shape == b.shape && o.decay_s == values[g];
        });
        if (same != basis.end()) sigs[g] = same->signature;
        else if (b.kind == BasisShape::power) sigs[g] = power_signature(sc.obs, cycles, values[g]);
        else {
          runs.push_back({signature_force(b.shape, values[g])});
          run_of.push_back(g);
        }
      }
      const std::vector<Variant> pv = sc.replayer.run(runs, sc.obs, sc.lag_samples);
      for (std::size_t r = 0; r < pv.size(); ++r) sigs[run_of[r]] = pv[r].window_j - sc.base.window_j;
      return sigs;
    };
    prof = profile_time_constant(m, tp, b.signature, best, -1e300, 1e300);
    b.signature = prof->signature;
    b.decay_s = prof->interval.value;
    best = prof->score;
  }
  Finding f;
  f.effect = "unexplained";
  f.delta_bic = best.dbic;
  const double value = best.amplitude(), s = best.fit.coef[0];
  const auto [low, high] = amplitude_interval(m, b.signature, best, m.inflate);
  double vmax = 0.0;
  for (const auto& r : sc.recordings)
    for (double v : r.speed_mps) vmax = std::max(vmax, v);
  const BasisWords w = words_of(b, value, vmax > units::kmh_to_mps(90.0) ? 100.0 : 50.0, sc.obs.channel);
  set_finding_metrics(f, m, b.signature, best);
  f.parameters.push_back({w.name, w.unit, value, low, high});
  std::string when;
  if (prof) {
    const auto& pi = prof->interval;
    f.parameters.push_back({"decay_time_constant_s", "s", b.decay_s, pi.low, pi.high, true, pi.low_open, pi.high_open});
    when = ", decaying from the start of the trip with a time constant of about " + fixed(b.decay_s / 60.0, 0) +
           " min: mostly (80 %) in the first " + fixed(minutes_to_80pct(sc.obs, cycles, b.signature), 0) + " min";
  }
  f.description = w.what + ", " + w.size_text + when + "; " + fixed(f.energy_share_pct, 1) +
                  " % of the measured energy, beside a channel scale of " + fixed(s, 3);
  // Only a Willans line lacks the map; an engine_map car's residual is the map's own error, not a missing map.
  if (std::holds_alternative<CombustionPowertrainParams>(sc.replayer.vehicle.powertrain) && b.decay_s == 0.0)
    f.description += ". The combustion engine is a Willans line with no efficiency map: efficiency changing with "
                     "load and speed (enrichment at high load, pumping loss at low load) has no module to name, and shows up this way";
  else if (std::holds_alternative<ConventionalPowertrainParams>(sc.replayer.vehicle.powertrain) && b.decay_s == 0.0)
    f.description += ". The engine has a fuel map: a residual like this is where the map (or the gear and converter "
                     "choice that sets its operating point) differs from this engine's, which no effect module names";
  m = extended(m, b.signature, best);
  return f;
}

}  // namespace rollsim::diag
