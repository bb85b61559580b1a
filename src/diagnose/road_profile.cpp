// Diagnosis stage 5b: the road profile when elevation is withheld. The residual of short windows is inverted into an
// elevation along distance (piecewise linear between knots, a roughness penalty chosen by generalised
// cross-validation); it is named only where it explains decisively more than any single catalogue or unexplained
// shape (BIC with its effective degrees of freedom), predicts held-out windows, the residual is quiet standing, and
// some descent is steeper than the car's whole rolling resistance (which no loss drifting over the trip can mimic).
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "pipeline.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/effects/road_profile.hpp"

namespace rollsim::diag {
namespace {

constexpr double kShortWindowS = 10.0;     // a grade's energy resolved over 100-300 m at urban to road speeds
constexpr double kMinKnotSpacingM = 200.0;  // hills of 0.5-3 km; a 10 s window covers 100-300 m
constexpr int kLinearisations = 5;         // Gauss-Newton steps: the descents move the powertrain from drive to regen
constexpr double kMaxKnots = 400.0;
constexpr double kLoopClosureM = 200.0;
constexpr double kStandingShare = 0.25;    // the standing residual's variance, of the moving one's, that vetoes a road
constexpr double kGradeSd = 0.04;           // prior on a road's grade: public roads rarely exceed 8-10 %    // start and end within this (latitude/longitude): the trip is a loop

// The shift of the simulated channel by a fractional lag (replay.cpp's `shifted`) as weights on two samples.
struct ShiftWeights {
  std::size_t j0 = 0, j1 = 0;
  double w0 = 1.0, w1 = 0.0;
};
ShiftWeights shift_of(std::size_t i, double lag, std::size_t n) {
  const double pos = static_cast<double>(i) - lag;
  if (pos <= 0.0) return {0, 0, 1.0, 0.0};
  const auto k = static_cast<std::size_t>(pos);
  const double f = pos - static_cast<double>(k);
  if (k + 1 >= n) return {n - 1, n - 1, 1.0, 0.0};
  return {k, k + 1, 1.0 - f, f};
}

// Each segment's distance at its middle (the replay's trapezoid) and its knot interval.
struct Bins {
  double spacing_m = 0.0, total_m = 0.0;
  Eigen::Index count = 0;
  std::vector<Eigen::Index> of_segment;
};
Bins bins_of(const DriveCycle& c) {
  Bins b;
  std::vector<double> mid(c.time_s.size() - 1);
  double s = 0.0;
  for (std::size_t i = 0; i + 1 < c.time_s.size(); ++i) {
    const double ds = 0.5 * (c.speed_mps[i] + c.speed_mps[i + 1]) * (c.time_s[i + 1] - c.time_s[i]);
    mid[i] = s + 0.5 * ds;
    s += ds;
  }
  b.total_m = s;
  b.spacing_m = std::max(kMinKnotSpacingM, s / kMaxKnots);
  b.count = std::max<Eigen::Index>(1, static_cast<Eigen::Index>(std::ceil(s / b.spacing_m)));
  for (double m : mid) b.of_segment.push_back(std::min(b.count - 1, static_cast<Eigen::Index>(m / b.spacing_m)));
  return b;
}

// Short-window energy per unit grade in each knot interval: the channel's power per newton of force while moving
// (`per_newton_w`, from the replay with 1 N added) times m g, shifted by the channel lag like every signature.
Eigen::MatrixXd profile_design(const Observations& sw, const std::vector<double>& per_unit_grade_w, const Bins& b, double lag) {
  Eigen::MatrixXd x = Eigen::MatrixXd::Zero(sw.n(), b.count);
  const std::size_t n = per_unit_grade_w.size();
  for (std::size_t w = 0; w < sw.windows.size(); ++w) {
    const auto& win = sw.windows[w];
    for (std::size_t i = win.begin; i < win.end; ++i) {
      const ShiftWeights sh = shift_of(i, lag, n);
      const double dt = sw.dt_s[win.rec][i];
      for (auto [j, wt] : {std::pair{sh.j0, sh.w0}, std::pair{sh.j1, sh.w1}})
        if (wt != 0.0 && j < b.of_segment.size()) x(static_cast<Eigen::Index>(w), b.of_segment[j]) += dt * wt * per_unit_grade_w[j];
    }
  }
  return x;
}

// Penalised least squares of the grades: (X'X + lambda D'D + closure) g = X'r, D the grade's first differences
// (the elevation's curvature); its effective degrees of freedom are tr((X'X + lambda P)^-1 X'X).
struct ProfileFit {
  Eigen::VectorXd grade;
  Eigen::MatrixXd a_inv;
  double lambda = 0.0, edf = 0.0, rss = 0.0;
};
ProfileFit solve_profile(const Eigen::MatrixXd& xtx, const Eigen::VectorXd& xtr, const Eigen::MatrixXd& penalty,
                         const Eigen::MatrixXd& closure, double lambda, double rtr) {
  ProfileFit f;
  f.lambda = lambda;
  const Eigen::MatrixXd a = xtx + lambda * penalty + closure;
  f.a_inv = a.ldlt().solve(Eigen::MatrixXd::Identity(a.rows(), a.cols()));
  f.grade = f.a_inv * xtr;
  f.edf = (f.a_inv * xtx).trace();
  f.rss = std::max(1e-300, rtr - 2.0 * f.grade.dot(xtr) + f.grade.dot(xtx * f.grade));
  return f;
}

Eigen::MatrixXd roughness(Eigen::Index k) {
  Eigen::MatrixXd p = Eigen::MatrixXd::Zero(k, k);
  for (Eigen::Index i = 0; i + 1 < k; ++i) {
    p(i, i) += 1.0, p(i + 1, i + 1) += 1.0, p(i, i + 1) -= 1.0, p(i + 1, i) -= 1.0;
  }
  p.diagonal().array() += 1e-6;  // intervals no window sees stay at the neighbours' grade, not undefined
  return p;
}

// A loop (start and end within kLoopClosureM by latitude/longitude) returns to its start elevation: the grades'
// elevation sum is held at zero by a stiff penalty. Otherwise the net climb is free.
bool is_loop(const Recording& r) {
  if (!r.latitude_deg || !r.longitude_deg || r.latitude_deg->empty()) return false;
  const double dlat = units::deg_to_rad(r.latitude_deg->back() - r.latitude_deg->front());
  const double dlon = units::deg_to_rad(r.longitude_deg->back() - r.longitude_deg->front()) *
                      std::cos(units::deg_to_rad(r.latitude_deg->front()));
  return units::kEarthRadius_m * std::hypot(dlat, dlon) < kLoopClosureM;
}

double bic_single(double rtr, const Eigen::VectorXd& col, const Eigen::VectorXd& r, double n_eff) {
  const double cc = col.squaredNorm();
  if (!(cc > 0.0)) return -1e300;
  const double cr = col.dot(r);
  return n_eff * std::log(rtr / std::max(1e-300, rtr - cr * cr / cc)) - std::log(n_eff);
}

// Standing short windows: a road does nothing there, so their residual must look like the noise floor's.
struct Standing {
  int windows = 0;
  double ratio = 0.0, z = 0.0;
  double moving_ratio = 0.0;  // the residual before the profile in the other windows, over the floor
};
Standing standing_check(const Observations& sw, const DriveCycle& c, const Eigen::VectorXd& r, const Eigen::VectorXd& r_before,
                        const NoiseFloor& nf) {
  Standing st;
  double sum = 0.0, moving = 0.0;
  int moving_windows = 0;
  for (std::size_t w = 0; w < sw.windows.size(); ++w) {
    const auto& win = sw.windows[w];
    bool still = true;
    double dur = 0.0;
    // Standing since 3 s before the window: a braking spike shifted by a slightly wrong lag is not a road's doing.
    std::size_t from = win.begin;
    while (from > 0 && c.time_s[win.begin] - c.time_s[from - 1] <= 3.0) --from;
    for (std::size_t i = from; i <= win.end && still; ++i) still = c.speed_mps[i] <= 0.0;
    for (std::size_t i = win.begin; i < win.end; ++i) dur += sw.dt_s[win.rec][i];
    if (!(nf.variance_per_s > 0.0)) continue;
    const auto wi = static_cast<Eigen::Index>(w);
    if (!still) {
      moving += r_before[wi] * r_before[wi] / (nf.variance_per_s * dur);
      ++moving_windows;
      continue;
    }
    sum += r[wi] * r[wi] / (nf.variance_per_s * dur);
    ++st.windows;
  }
  st.moving_ratio = moving_windows > 0 ? moving / moving_windows : 0.0;
  if (st.windows == 0) return st;
  st.ratio = sum / st.windows;
  st.z = (st.ratio - 1.0) * std::sqrt(0.5 * st.windows);
  return st;
}

// The car's rolling resistance as a grade (force over m g), at its calibrated level, averaged over the trip the way
// the channel sees it: its whole RRC is 10 x the calibration's +10 % signature, a grade the unit force times m g.
double rolling_grade(const Signatures& sig, const BasisShape& unit, const Eigen::VectorXd& k, double m_g) {
  double rrc_w = 0.0, per_newton_w = 0.0;
  const std::vector<double>& base = sig.base.power_w.front();
  for (std::size_t i = 0; i < base.size(); ++i) {
    rrc_w += 10.0 * (sig.rrc.power_w.front()[i] - base[i]);
    per_newton_w += unit.power_w.front()[i] - base[i];
  }
  if (!(std::abs(per_newton_w) > 0.0)) return 0.0;
  return (1.0 + 0.1 * k[1] / k[0]) * rrc_w / (per_newton_w * m_g);
}

// z with P(Z > z) = p for a standard normal, by bisection on erfc (a handful of calls per diagnosis).
double normal_upper_quantile(double p) {
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 200 && hi - lo > 1e-9; ++i) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(mid / std::sqrt(2.0)) > p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// A road is the one explanation in the catalogue whose force can fall below zero loss: a descent steeper than the
// car's whole rolling resistance. Losses that vary along the trip (an RRC rising with rain or warm-up run
// backwards, an auxiliary load, a payload, wind gusts about a headwind) move the force by a fraction of it, and a
// one-pass profile absorbs them as well as it absorbs hills. So a profile is a road only where some knot's grade is
// below minus the rolling grade by more than the knots' family-wise 95 % bound (Bonferroni over the knots).
struct Descent {
  double grade = 0.0, rolling_grade = 0.0, z = 0.0, z_needed = 0.0;
  bool road_only = false;
};
Descent steepest_descent(const Eigen::VectorXd& grade, const Eigen::MatrixXd& cov, double rolling_grade) {
  Descent d;
  d.rolling_grade = rolling_grade;
  d.z = -1e300;
  for (Eigen::Index i = 0; i < grade.size(); ++i) {
    const double sd = std::sqrt(std::max(1e-300, cov(i, i)));
    const double z = (-rolling_grade - grade[i]) / sd;
    if (z > d.z) d.z = z, d.grade = grade[i];
  }
  d.z_needed = normal_upper_quantile(0.025 / static_cast<double>(std::max<Eigen::Index>(1, grade.size())));
  d.road_only = d.z >= d.z_needed;
  return d;
}

struct Competitor {
  std::string name;
  Eigen::VectorXd column;
  double dbic = -1e300;
};

}  // namespace

std::optional<Finding> infer_road_profile(const SelectionContext& sc, const std::vector<DriveCycle>& cycles,
                                          const Signatures& sig, const std::vector<Finding>& found,
                                          const std::vector<EffectId>& chosen, const NoiseFloor& floor, Model& m,
                                          std::vector<std::string>& notes) {
  const Observations& o = sc.obs;
  const auto& recs = sc.recordings;
  if (recs.size() != 1 || o.channel == ChannelKind::soc) return std::nullopt;  // one route, a per-sample channel
  if (recs.front().elevation_m || recs.front().grade) return std::nullopt;     // elevation given: the grade is known
  const DriveCycle& cyc = cycles.front();
  const Bins bins = bins_of(cyc);
  const Observations sw = rewindow(o, recs, kShortWindowS);
  if (sw.n() < 30 || bins.count < 5) {
    notes.push_back("road_profile not tested: under 30 short windows or 500 m of road");
    return std::nullopt;
  }
  double lag = sc.lag_samples;  // re-estimated once the profile explains the channel (hills corrupt the first estimate)
  const Eigen::VectorXd& k = m.fit.coef;
  auto energies = [&](const std::vector<std::vector<double>>& p) { return window_energies(p, sw, lag); };

  // The current model (calibration and the effects found) on the short windows: its found effects replayed at their
  // fitted sizes.
  EffectList found_effects;
  for (const auto& f : found) {
    if (f.effect == "unexplained") continue;
    try {
      found_effects.push_back(make_effect(effect_info(f.effect).id, f.fitted, sc.ctx));
    } catch (const std::exception&) {
    }
  }
  std::vector<EffectList> runs{found_effects};
  Eigen::VectorXd base_s = energies(sig.base.power_w);
  const std::vector<std::vector<double>> fitted_w = found_effects.empty() ? sig.base.power_w : sc.replayer.run(runs, o, lag)[0].power_w;
  auto predicted = [&] {
    return Eigen::VectorXd(k[0] * energies(fitted_w) + k[1] * (energies(sig.rrc.power_w) - energies(sig.base.power_w)) +
                           k[2] * (energies(sig.drag.power_w) - energies(sig.base.power_w)));
  };
  Eigen::VectorXd pred = predicted();
  Eigen::VectorXd r = sw.measured_j - pred;
  double rtr = r.squaredNorm();

  const BasisShape* unit = nullptr;  // the unexplained basis' 1 N force while moving
  for (const auto& b : sig.basis)
    if (b.kind == BasisShape::force && b.shape == ForceShape::constant && b.decay_s == 0.0) unit = &b;
  if (!unit || unit->power_w.empty()) return std::nullopt;

  // Gauss-Newton on the grades: each step linearises the channel about the current profile (the channel's power per
  // newton of force while moving, from a replay with 1 N added, times m g) and re-solves the penalised fit, the
  // roughness chosen by generalised cross-validation over a log grid fixed in advance (scaled to the design).
  const Eigen::Index kb = bins.count;
  const Eigen::MatrixXd penalty = roughness(kb);
  Eigen::MatrixXd closure = Eigen::MatrixXd::Zero(kb, kb);
  const bool loop = is_loop(recs.front());
  const double n = static_cast<double>(sw.n());
  const double m_g = sc.ctx.mass_kg * units::kStandardGravity_mps2;
  const std::vector<double>& base_w = sig.base.power_w.front();
  std::vector<double> at_w = base_w, plus_w = unit->power_w.front();  // the operating point, and it with 1 N more
  Eigen::VectorXd grade = Eigen::VectorXd::Zero(kb), r_now = r;
  Eigen::MatrixXd x, xtx;
  Eigen::VectorXd profile_window_j;  // the profile switched on, per (long) window
  ProfileFit best;
  auto profile_of = [&](const Eigen::VectorXd& g) {
    ElevationProfile p;
    double h = 0.0;
    for (Eigen::Index i = 0; i <= kb; ++i) {
      p.distance_m.push_back(std::min(bins.total_m, static_cast<double>(i) * bins.spacing_m));
      p.elevation_m.push_back(h);
      if (i < kb) h += g[i] * (std::min(bins.total_m, static_cast<double>(i + 1) * bins.spacing_m) - p.distance_m.back());
    }
    return p;
  };
  for (int step = 0; step < kLinearisations; ++step) {
    std::vector<double> per_grade_w(base_w.size());
    for (std::size_t i = 0; i < per_grade_w.size(); ++i) per_grade_w[i] = k[0] * (plus_w[i] - at_w[i]) * m_g;
    x = profile_design(sw, per_grade_w, bins, lag);
    xtx = x.transpose() * x;
    closure = Eigen::MatrixXd::Zero(kb, kb);
    if (loop) {  // (sum of grade x interval length)^2, stiffly: the elevation gained over the trip is zero
      Eigen::VectorXd len = Eigen::VectorXd::Constant(kb, bins.spacing_m);
      len[kb - 1] = bins.total_m - static_cast<double>(kb - 1) * bins.spacing_m;
      closure = 1e6 * xtx.diagonal().maxCoeff() / len.squaredNorm() * len * len.transpose();
    }
    // The grade prior as a ridge: the window noise variance over the prior's variance.
    closure.diagonal().array() += floor.variance_per_s * kShortWindowS / (kGradeSd * kGradeSd);
    const Eigen::VectorXd target = r_now + x * grade;
    const Eigen::VectorXd xtr = x.transpose() * target;
    const double scale = std::max(1e-300, xtx.trace() / static_cast<double>(kb));
    if (step == 0) {
      double best_gcv = 1e300;
      for (int e = -3; e <= 3; ++e) {
        ProfileFit f = solve_profile(xtx, xtr, penalty, closure, scale * std::pow(10.0, e), target.squaredNorm());
        const double gcv = n * f.rss / std::pow(std::max(1.0, n - f.edf), 2.0);
        if (gcv < best_gcv) best_gcv = gcv, best = std::move(f);
      }
    } else {
      best = solve_profile(xtx, xtr, penalty, closure, best.lambda, target.squaredNorm());
    }
    // Step control: the full Gauss-Newton step and a half step are both simulated, the better one kept (the
    // linearisation is local: a descent moves the powertrain from drive to regen or the friction brakes).
    const Eigen::VectorXd previous = grade;
    const Eigen::VectorXd full = best.grade, half = 0.5 * (previous + best.grade);
    runs.clear();
    for (const Eigen::VectorXd* g : {&full, &half}) {
      const auto road = std::make_shared<RoadProfile>(profile_of(*g), 1.0, sc.ctx.mass_kg);
      runs.push_back({road});
      runs.push_back({road, signature_force(ForceShape::constant, 0.0)});
    }
    std::vector<Variant> v = sc.replayer.run(runs, o, lag);
    // The lag again, against the channel with the profile (only if the profile explains more than it costs).
    const double lag_before = lag;
    const LagEstimate le = estimate_lag(v[0].power_w, o);
    lag = le.samples;
    base_s = energies(sig.base.power_w);
    pred = predicted();
    r = sw.measured_j - pred;
    if (lag != lag_before) {
      rtr = r.squaredNorm();
      for (auto& var : v) var.window_j = window_energies(var.power_w, o, lag);
    }
    double kept_rss = 1e300;
    for (std::size_t c = 0; c < 2; ++c) {
      const Eigen::VectorXd rc = r - k[0] * (energies(v[2 * c].power_w) - base_s);
      if (rc.squaredNorm() >= kept_rss) continue;
      kept_rss = rc.squaredNorm();
      grade = c == 0 ? full : half;
      r_now = rc;
      at_w = v[2 * c].power_w.front();
      profile_window_j = v[2 * c].window_j;
      plus_w = v[2 * c + 1].power_w.front();
    }
  }
  const Eigen::VectorXd fitted = r - r_now;
  const double rss = std::max(1e-300, r_now.squaredNorm());
  const double rho = std::clamp(lag1_autocorrelation(r_now), 0.0, 0.95);
  const double n_eff = std::max(4.0, n * (1.0 - rho) / (1.0 + rho));
  const double dbic = n_eff * std::log(rtr / rss) - best.edf * std::log(n_eff);

  // Held out: alternate 20 s blocks; each predicted by the profile fitted on the others at the same roughness.
  const Eigen::VectorXd lin_target = r_now + x * grade;
  Eigen::VectorXd oof(sw.n());
  for (int fold = 0; fold < 2; ++fold) {
    Eigen::MatrixXd xt = x;
    Eigen::VectorXd rt = lin_target;
    for (Eigen::Index w = 0; w < sw.n(); ++w)
      if ((w / 2) % 2 == fold) xt.row(w).setZero(), rt[w] = 0.0;
    const ProfileFit f = solve_profile(xt.transpose() * xt, xt.transpose() * rt, penalty, closure, best.lambda, rt.squaredNorm());
    for (Eigen::Index w = 0; w < sw.n(); ++w)
      if ((w / 2) % 2 == fold) oof[w] = x.row(w).dot(f.grade);
  }
  const double rmse_before = rmse(r, Eigen::VectorXd::Zero(sw.n())), rmse_after = rmse(lin_target, oof);

  // Competitors: every single shape that could describe the same residual (catalogue effects not found, including
  // mass, RRC-like and net-climb shapes, and the unexplained basis), on the same windows and n_eff.
  std::vector<Competitor> comps;
  for (const auto& c : sig.candidates) {
    if (c.power_w.empty() || std::find(chosen.begin(), chosen.end(), c.id) != chosen.end()) continue;
    comps.push_back({to_string(c.id), k[0] * (energies(c.power_w) - base_s) / c.amplitude->nominal});
  }
  for (const auto& b : sig.basis)
    comps.push_back({"unexplained", b.kind == BasisShape::force ? Eigen::VectorXd(k[0] * (energies(b.power_w) - base_s))
                                                                : Eigen::VectorXd(k[0] * power_signature(sw, cycles, b.decay_s))});
  // A force growing over the trip (an RRC rising with rain or a rougher road), linear and quadratic in time, through
  // the same per-newton channel power: smooth in distance too, so a profile must beat it as well.
  {
    const auto& t = cyc.time_s;
    const double span = std::max(1.0, t.back() - t.front());
    for (int power = 1; power <= 2; ++power) {
      std::vector<std::vector<double>> grow(1, std::vector<double>(base_w.size()));
      for (std::size_t i = 0; i < base_w.size(); ++i)
        grow[0][i] = (unit->power_w.front()[i] - base_w[i]) * std::pow((t[i] - t.front()) / span, power);
      comps.push_back({"unexplained", k[0] * energies(grow)});
    }
  }
  const Competitor* rival = nullptr;
  for (auto& c : comps) {
    c.dbic = bic_single(rtr, c.column, r, n_eff);
    if (!rival || c.dbic > rival->dbic) rival = &c;
  }
  const double rival_dbic = rival ? rival->dbic : -1e300;
  // A road acts on a moving car (holding on a slope costs a motor little): a residual as large standing as moving is
  // a load or a logger, not a road.
  const Standing still = standing_check(sw, cyc, r_now, r, floor);
  const bool quiet = still.windows < 3 || still.z < sc.opt.adequacy_z || still.ratio < sc.opt.adequacy_min_ratio ||
                     still.ratio < kStandingShare * still.moving_ratio;
  const double thr = sc.opt.bic_threshold;
  const double sigma2 = rss / std::max(1.0, n - best.edf) * n / n_eff;
  const Eigen::MatrixXd cov = sigma2 * best.a_inv * xtx * best.a_inv;
  const Descent descent = steepest_descent(grade, cov, rolling_grade(sig, *unit, k, m_g));
  const bool named = dbic >= thr && rmse_after < rmse_before && dbic - rival_dbic >= thr && quiet && descent.road_only;
  notes.push_back("road_profile (elevation withheld): Delta BIC " + fixed(dbic, 1) + " at " + fixed(best.edf, 1) +
                  " effective parameters on " + std::to_string(sw.n()) + " windows of " + fixed(kShortWindowS, 0) +
                  " s, best single shape (" + (rival ? rival->name : std::string("none")) + ") " + fixed(rival_dbic, 1) +
                  ", held-out RMSE " + fixed(rmse_before / 1e3, 1) + " -> " + fixed(rmse_after / 1e3, 1) + " kJ, standing residual " +
                  fixed(still.ratio, 2) + " x the floor (" + std::to_string(still.windows) + " windows; moving " + fixed(still.moving_ratio, 1) + " x)" +
                  (loop ? ", a loop (net climb held at 0)" : "") + ", steepest descent " + fixed(100.0 * descent.grade, 1) + " % (" +
                  // A level profile is far from steeper; "-162.9 sd beyond" read backwards (session 27's outside tester).
                  (descent.z > 0.0 ? fixed(descent.z, 1) + " sd steeper than the rolling resistance's "
                                   : std::string("not steeper than the rolling resistance's ")) +
                  fixed(-100.0 * descent.rolling_grade, 1) + " %, " + fixed(descent.z_needed, 1) + " sd needed)" +
                  (named ? ": named" : ": not named"));
  if (!named) return std::nullopt;

  // The profile: elevations at the knots, relative to the start, with a 95 % band from the sandwich covariance
  // (residual variance per effective window).
  RecoveredProfile prof;
  Eigen::MatrixXd cum = Eigen::MatrixXd::Zero(kb + 1, kb);
  for (Eigen::Index i = 1; i <= kb; ++i) {
    cum.row(i) = cum.row(i - 1);
    cum(i, i - 1) = std::min(bins.spacing_m, bins.total_m - static_cast<double>(i - 1) * bins.spacing_m);
  }
  const Eigen::VectorXd elev = cum * grade;
  const Eigen::VectorXd var = (cum * cov * cum.transpose()).diagonal();
  for (Eigen::Index i = 0; i <= kb; ++i) {
    const double sd = std::sqrt(std::max(0.0, var[i]));
    prof.distance_m.push_back(std::min(bins.total_m, static_cast<double>(i) * bins.spacing_m));
    prof.elevation_m.push_back(elev[i]);
    prof.elevation_ci_low_m.push_back(elev[i] - 1.96 * sd);
    prof.elevation_ci_high_m.push_back(elev[i] + 1.96 * sd);
  }

  // The profile switched on as the catalogue module (full simulator: regen and friction braking on the descents),
  // its scale fitted with the model: 1 where the inversion holds.
  const Eigen::VectorXd sig60 = profile_window_j - sig.base.window_j;
  Scored s = score_column(m, sig60);
  add_heldout(m, sig60, s);
  const double profile_scale = s.amplitude(), scale_se = s.amplitude_se(m.inflate);

  Finding f;
  f.effect = to_string(EffectId::road_profile);
  const auto [lo, hi] = std::minmax_element(prof.elevation_m.begin(), prof.elevation_m.end());
  f.description = "a road profile along the distance driven, elevation withheld: " + fixed(*hi - *lo, 0) + " m from lowest to highest over " +
                  fixed(bins.total_m / 1e3, 1) + " km (knots every " + fixed(bins.spacing_m, 0) + " m, " + fixed(best.edf, 1) +
                  " effective parameters); it explains the residual decisively better than any single shape (next: " +
                  (rival ? rival->name : std::string("none")) + ", Delta BIC " + fixed(rival_dbic, 1) +
                  "); held-out figures are for alternate 20 s blocks of 10 s windows";
  f.delta_bic = dbic;
  const double net_sd = std::sqrt(std::max(0.0, var[kb]));
  f.parameters.push_back({"profile_scale", "1", profile_scale, profile_scale - 1.96 * scale_se, profile_scale + 1.96 * scale_se});
  f.parameters.push_back({"net_climb_m", "m", elev[kb], elev[kb] - 1.96 * net_sd, elev[kb] + 1.96 * net_sd});
  f.parameters.push_back({"knot_spacing_m", "m", bins.spacing_m, bins.spacing_m, bins.spacing_m});
  f.parameters.push_back({"effective_parameters", "1", best.edf, best.edf, best.edf});
  for (const auto& c : comps) {
    if (c.dbic < thr) continue;
    const double corr = c.column.dot(fitted) / std::max(1e-300, c.column.norm() * fitted.norm());
    if (std::abs(corr) > sc.opt.collinear_corr && std::find(f.confounded_with.begin(), f.confounded_with.end(), c.name) == f.confounded_with.end()) {
      f.confounded_with.push_back(c.name);
      f.separating_tests.push_back(c.name + ": " + separating_test(f.effect, c.name));
    }
  }
  f.fitted = {{"profile_scale", std::clamp(profile_scale, 0.0, 3.0)}, {"knot_spacing_m", bins.spacing_m}};
  f.heldout_rmse_before_j = rmse_before;
  f.heldout_rmse_after_j = rmse_after;
  f.heldout_energy_error_pct_before = energy_error_pct(pred, sw.measured_j);
  f.heldout_energy_error_pct_after = energy_error_pct(Eigen::VectorXd(pred + oof), sw.measured_j);
  f.heldout_lag1_autocorrelation_before = lag1_autocorrelation(r);
  f.heldout_lag1_autocorrelation_after = lag1_autocorrelation(Eigen::VectorXd(r - oof));
  f.heldout_scored = true;
  f.road_profile = std::move(prof);
  m = extended(m, sig60, s);
  return f;
}

}  // namespace rollsim::diag
