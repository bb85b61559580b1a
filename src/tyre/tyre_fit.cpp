#include "rollsim/tyre/tyre_fit.hpp"

#include "rollsim/common/json.hpp"
#include "rollsim/tyre/j2452.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include "rollsim/common/csv.hpp"
#include "rollsim/common/error.hpp"
#include "rollsim/common/statistics.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/tyre/hysteresis_model.hpp"
#include "rollsim/tyre/least_squares.hpp"
#include "rollsim/common/format.hpp"

namespace rollsim {
namespace {

constexpr HysteresisParam kAllParams[] = {HysteresisParam::RrcRef,         HysteresisParam::FrequencySlope,
                                          HysteresisParam::DeflectionExponent, HysteresisParam::LoadExponent,
                                          HysteresisParam::SpeedLoss,      HysteresisParam::SpeedLossLoadExponent};

// The optimiser works on scaled parameters of order one; the level on its logarithm so it stays positive.
double to_internal(HysteresisParam p, double v) {
  switch (p) {
    case HysteresisParam::RrcRef: return std::log(v);
    case HysteresisParam::FrequencySlope: return v * 10.0;
    case HysteresisParam::SpeedLoss: return v * 1e5;
    default: return v;
  }
}
double from_internal(HysteresisParam p, double x) {
  switch (p) {
    case HysteresisParam::RrcRef: return std::exp(x);
    case HysteresisParam::FrequencySlope: return x / 10.0;
    case HysteresisParam::SpeedLoss: return x / 1e5;
    default: return x;
  }
}

// How many distinct pressures, loads and speeds the points hold (to 0.1 % of the value).
struct Spread {
  std::size_t pressures = 0, loads = 0, speeds = 0;
};
// Each point's group along one field: sorted, a group holds the values within 0.1 % above its first. Measured
// against each value's neighbour instead, a dense sweep chained into one group (180-300 kPa in 0.1 kPa steps read as
// "1 pressure(s)" and its exponent was silently held: session 24's outside testing).
std::vector<std::size_t> groups(const std::vector<RrcPoint>& pts, double RrcPoint::*field) {
  std::vector<std::size_t> order(pts.size()), group(pts.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return pts[a].*field < pts[b].*field; });
  std::size_t g = 0;
  double first = 0.0;
  for (std::size_t k = 0; k < order.size(); ++k) {
    const double v = pts[order[k]].*field;
    if (k == 0) first = v;
    else if (v > first + 1e-3 * std::abs(first)) first = v, ++g;
    group[order[k]] = g;
  }
  return group;
}
std::size_t distinct(const std::vector<RrcPoint>& pts, double RrcPoint::*field) {
  const std::vector<std::size_t> g = groups(pts, field);
  return g.empty() ? 0 : *std::max_element(g.begin(), g.end()) + 1;
}
// How many distinct conditions (pressure, load and speed together, grouped as above) the points hold: repeated
// measurements of one condition fix its RRC better, not another constant (three points at two conditions freed three
// constants and printed a 95 % interval for one the points cannot tell from another: session 22's outside testing).
std::size_t distinct_conditions(const std::vector<RrcPoint>& pts) {
  const auto p = groups(pts, &RrcPoint::pressure_pa), z = groups(pts, &RrcPoint::load_n), v = groups(pts, &RrcPoint::speed_mps);
  std::set<std::array<std::size_t, 3>> seen;
  for (std::size_t i = 0; i < pts.size(); ++i) seen.insert({p[i], z[i], v[i]});
  return seen.size();
}
Spread spread(const std::vector<RrcPoint>& pts) {
  return {distinct(pts, &RrcPoint::pressure_pa), distinct(pts, &RrcPoint::load_n), distinct(pts, &RrcPoint::speed_mps)};
}

// Empty when the points can determine `p`, else what is missing.
std::string missing_for(HysteresisParam p, const Spread& s) {
  switch (p) {
    case HysteresisParam::RrcRef: return "";
    case HysteresisParam::FrequencySlope: return s.speeds >= 2 ? "" : "points at 2 or more speeds";
    case HysteresisParam::DeflectionExponent: return s.pressures >= 2 ? "" : "points at 2 or more pressures";
    case HysteresisParam::LoadExponent: return s.loads >= 2 ? "" : "points at 2 or more loads";
    case HysteresisParam::SpeedLoss: return s.speeds >= 3 ? "" : "points at 3 or more speeds";
    case HysteresisParam::SpeedLossLoadExponent:
      return s.speeds >= 3 && s.loads >= 2 ? "" : "points at 3 or more speeds and 2 or more loads";
  }
  return "";
}

void check_request(const FitRequest& r, const std::vector<HysteresisParam>& free) {
  if (r.points.empty()) {
    throw InputError("--point", "too few points for what is asked: no measured point given (give --point, "
                                "--measured, --j2452 or --label)");
  }
  std::set<HysteresisParam> seen;
  const Spread s = spread(r.points);
  for (auto p : free) {
    if (!seen.insert(p).second) throw InputError("--free", std::string(hysteresis_param_key(p)) + " is listed twice");
    const std::string need = missing_for(p, s);
    if (!need.empty()) {
      throw InputError("--free", std::string("too few points for what is asked: ") + hysteresis_param_key(p) +
                                     " needs " + need + "; the " + std::to_string(r.points.size()) +
                                     " point(s) given have " + std::to_string(s.pressures) + " pressure(s), " +
                                     std::to_string(s.loads) + " load(s), " + std::to_string(s.speeds) + " speed(s)");
    }
  }
  if (const std::size_t conditions = distinct_conditions(r.points); free.size() > conditions) {
    throw InputError("--free", "too few points for what is asked: " + std::to_string(r.points.size()) + " point(s) at " +
                                   std::to_string(conditions) + " distinct condition(s) cannot determine " +
                                   std::to_string(free.size()) + " parameters (" + hysteresis_param_keys(free) + ")");
  }
  if (!(r.assumed_relative_uncertainty > 0.0)) {
    throw InputError("--rrc-uncertainty-pct", "must be > 0");
  }
}

double model_rrc(const TyreState& t, const RrcPoint& p) {
  TyreState at = t;
  at.pressure_pa = p.pressure_pa;
  const SpeedPolynomial k = hysteresis_polynomial(at, p.load_n);
  return k.k0 + p.speed_mps * (k.k1_s_per_m + p.speed_mps * k.k2_s2_per_m2);
}

// Of free parameters the points move only together (the Jacobian's columns, each scaled to unit length, nearly
// dependent), the one that leans most on the dependence; the level is never it. Distinct spreads of pressure and
// speed do not rule this out: two conditions that differ in both tell the two constants apart only with a third.
// Read at the start (the shared constants), where it is the points' structure; at a solution that ran off to an
// extreme every Jacobian degenerates, and that fit is refused as a file, not explained as undetermined.
std::optional<HysteresisParam> entangled_param(const Eigen::MatrixXd& jacobian, const std::vector<HysteresisParam>& free) {
  Eigen::MatrixXd unit = jacobian;
  for (Eigen::Index k = 0; k < unit.cols(); ++k) {
    if (!(unit.col(k).norm() > 0.0)) return std::nullopt;  // a flat column is said as such at the solution
    unit.col(k) /= unit.col(k).norm();
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(unit, Eigen::ComputeFullV);
  const Eigen::VectorXd& sv = svd.singularValues();
  if (sv.size() == unit.cols() && sv[sv.size() - 1] > 1e-7 * sv[0]) return std::nullopt;
  const Eigen::VectorXd null = svd.matrixV().col(unit.cols() - 1);
  std::optional<HysteresisParam> out;
  double largest = 0.0;
  for (Eigen::Index k = 0; k < unit.cols(); ++k) {
    if (free[static_cast<std::size_t>(k)] == HysteresisParam::RrcRef || !(std::abs(null[k]) > largest)) continue;
    largest = std::abs(null[k]);
    out = free[static_cast<std::size_t>(k)];
  }
  return out;
}

// One least-squares pass over the given free parameters; fills values, intervals and residuals. `flat` gets the free
// parameters the residuals do not move with at the solution (a zero Jacobian column): the points say nothing of
// them, and the pseudo-inverse would give them a zero-width interval.
TyreFit fit_once(const TyreState& start, const FitRequest& r, const std::vector<HysteresisParam>& free,
                 std::vector<HysteresisParam>& flat) {
  const int m = static_cast<int>(r.points.size());
  const int n = static_cast<int>(free.size());
  auto apply = [&](const Eigen::VectorXd& x) {
    TyreState t = start;
    for (int k = 0; k < n; ++k) set_hysteresis_param(t.hysteresis, free[k], from_internal(free[k], x[k]));
    return t;
  };
  const ResidualFunction residuals = [&](const Eigen::VectorXd& x, Eigen::VectorXd& out) {
    const TyreState t = apply(x);
    for (int i = 0; i < m; ++i) out[i] = model_rrc(t, r.points[i]) / r.points[i].rrc - 1.0;
  };
  Eigen::VectorXd x0(n);
  for (int k = 0; k < n; ++k) x0[k] = to_internal(free[k], hysteresis_param_value(start.hysteresis, free[k]));
  const LeastSquaresResult ls = least_squares(residuals, m, x0);

  TyreFit fit;
  fit.tyre = apply(ls.x);
  fit.degrees_of_freedom = m - n;
  const double ssr = ls.residuals.squaredNorm();
  fit.rms_relative_error = std::sqrt(ssr / m);
  // Residuals that are all zero (repeated identical points fitted exactly) say nothing of the scatter: an interval
  // of zero width would claim certainty no measurement has.
  fit.sigma_from_residuals = fit.degrees_of_freedom > 0 && fit.rms_relative_error > 1e-9;
  fit.sigma_relative = fit.sigma_from_residuals ? std::sqrt(ssr / fit.degrees_of_freedom) : r.assumed_relative_uncertainty;
  // Covariance of the scaled parameters; a pseudo-inverse keeps a degenerate direction from producing NaN.
  const Eigen::MatrixXd jtj = ls.jacobian.transpose() * ls.jacobian;
  const double widest = ls.jacobian.colwise().norm().maxCoeff();
  flat.clear();
  for (int k = 0; k < n; ++k)
    if (!(ls.jacobian.col(k).norm() > 1e-12 * widest)) flat.push_back(free[k]);
  if (flat.empty() && n >= 2) {  // one constant is never entangled: no start Jacobian on the one-point path
    if (const auto p = entangled_param(jacobian_at(residuals, m, x0), free)) flat.push_back(*p);
  }
  const Eigen::MatrixXd cov =
      fit.sigma_relative * fit.sigma_relative * jtj.completeOrthogonalDecomposition().pseudoInverse();
  // A scatter estimated from few residuals is itself uncertain: Student's t with their degrees of freedom, not the
  // normal's 1.96 (at 2 dof the 1.96 interval held the truth 81 % of the time, at 1 dof 71 %: session 21's outside
  // testing); an assumed scatter is taken as known.
  fit.interval_quantile = fit.sigma_from_residuals ? student_t_95(fit.degrees_of_freedom) : 1.96;
  for (int k = 0; k < n; ++k) {
    ParamEstimate e;
    e.param = free[k];
    e.value = from_internal(free[k], ls.x[k]);
    const double sd_internal = std::sqrt(std::max(0.0, cov(k, k)));
    e.low95 = from_internal(free[k], ls.x[k] - fit.interval_quantile * sd_internal);
    e.high95 = from_internal(free[k], ls.x[k] + fit.interval_quantile * sd_internal);
    e.std_error = free[k] == HysteresisParam::RrcRef ? e.value * sd_internal
                                                     : std::abs(from_internal(free[k], sd_internal));
    fit.params.push_back(e);
  }
  for (int i = 0; i < m; ++i) {
    fit.residuals.push_back({r.points[i], model_rrc(fit.tyre, r.points[i]), ls.residuals[i]});
  }
  for (auto p : kAllParams) {
    if (std::find(free.begin(), free.end(), p) == free.end()) fit.held.push_back(p);
  }
  return fit;
}

}  // namespace

std::string hysteresis_param_keys(const std::vector<HysteresisParam>& ps) {
  std::string s;
  for (auto p : ps) s += (s.empty() ? "" : ", ") + std::string(hysteresis_param_key(p));
  return s;
}

std::vector<HysteresisParam> all_hysteresis_params() { return {std::begin(kAllParams), std::end(kAllParams)}; }

const char* hysteresis_param_key(HysteresisParam p) {
  switch (p) {
    case HysteresisParam::RrcRef: return "rrc_ref";
    case HysteresisParam::FrequencySlope: return "frequency_slope_per_hz";
    case HysteresisParam::DeflectionExponent: return "deflection_exponent";
    case HysteresisParam::LoadExponent: return "load_exponent";
    case HysteresisParam::SpeedLoss: return "speed_loss_rrc_per_hz2";
    case HysteresisParam::SpeedLossLoadExponent: return "speed_loss_load_exponent";
  }
  return "";
}

std::optional<HysteresisParam> hysteresis_param_from_key(const std::string& key) {
  for (auto p : kAllParams) {
    if (key == hysteresis_param_key(p)) return p;
  }
  return std::nullopt;
}

double hysteresis_param_value(const HysteresisConstants& c, HysteresisParam p) {
  switch (p) {
    case HysteresisParam::RrcRef: return c.rrc_ref;
    case HysteresisParam::FrequencySlope: return c.frequency_slope_per_hz;
    case HysteresisParam::DeflectionExponent: return c.deflection_exponent;
    case HysteresisParam::LoadExponent: return c.load_exponent;
    case HysteresisParam::SpeedLoss: return c.speed_loss_rrc_per_hz2;
    case HysteresisParam::SpeedLossLoadExponent: return c.speed_loss_load_exponent;
  }
  return 0.0;
}

void set_hysteresis_param(HysteresisConstants& c, HysteresisParam p, double value) {
  switch (p) {
    case HysteresisParam::RrcRef: c.rrc_ref = value; break;
    case HysteresisParam::FrequencySlope: c.frequency_slope_per_hz = value; break;
    case HysteresisParam::DeflectionExponent: c.deflection_exponent = value; break;
    case HysteresisParam::LoadExponent: c.load_exponent = value; break;
    case HysteresisParam::SpeedLoss: c.speed_loss_rrc_per_hz2 = value; break;
    case HysteresisParam::SpeedLossLoadExponent: c.speed_loss_load_exponent = value; break;
  }
}

namespace {
void check_rrc_range(double rrc, const std::string& where) {
  if (!(rrc >= 0.001 && rrc <= 0.05)) {
    throw InputError(where, "RRC " + format_value(rrc) + " is outside a tyre's physical range: must be in "
                                                          "[0.001, 0.05] (1-50 kg/t; car tyres measure 5-15 kg/t)");
  }
}
}  // namespace

void check_rrc_point(const TyreState& tyre, const RrcPoint& p) {
  check_pressure_plausible_kpa(p.pressure_pa / 1e3, std::nullopt, p.where);  // the size's class: plan_tyre_fit
  const double kmh = units::mps_to_kmh(p.speed_mps);
  if (!(kmh > 0.0 && kmh <= 300.0)) {
    throw InputError(p.where, "speed " + format_value(std::abs(kmh) < 1e9 ? std::round(kmh * 1e9) / 1e9 : kmh) + " km/h is not allowed: must be in (0, 300] km/h (a "
                                                             "rolling tyre; RRC is not defined at standstill)");
  }
  check_rrc_range(p.rrc, p.where);
  TyreState at = tyre;
  at.pressure_pa = p.pressure_pa;
  try {
    check_operating_point(at, p.load_n, p.speed_mps);
  } catch (const ModelDomainError& e) {
    throw InputError(p.where, std::string("outside the tyre's physical range: ") + e.what());
  }
}

bool hysteresis_param_non_negative(HysteresisParam p) {
  return p == HysteresisParam::FrequencySlope || p == HysteresisParam::SpeedLoss || p == HysteresisParam::DeflectionExponent;
}

std::vector<HysteresisParam> identifiable_params(const std::vector<RrcPoint>& points) {
  const Spread s = spread(points);
  const std::size_t conditions = distinct_conditions(points);
  std::vector<HysteresisParam> out{HysteresisParam::RrcRef};
  for (auto p : kAllParams) {
    if (p == HysteresisParam::RrcRef || out.size() >= conditions) continue;
    if (missing_for(p, s).empty()) out.push_back(p);
  }
  return out;
}

namespace {

// The RR force's log-slope against load at the reference point (80 km/h): every measured set rises with load
// (J2452 load exponents 0.89-1.09). Not held as a bound, because the load and the deflection exponents share it;
// a fit whose force falls with load is said, since the points then contradict every measured tyre.
std::optional<std::string> force_falling_with_load(const TyreFit& fit) {
  const bool load_free = std::any_of(fit.params.begin(), fit.params.end(), [](const ParamEstimate& e) {
    return e.param == HysteresisParam::LoadExponent || e.param == HysteresisParam::SpeedLossLoadExponent;
  });
  if (!load_free) return std::nullopt;
  const HysteresisConstants& h = fit.tyre.hysteresis;
  const double speed_mps = units::kmh_to_mps(80.0), step = 1.1;
  auto force_n = [&](double load_n) {
    return load_n * model_rrc(fit.tyre, {h.reference_pressure_pa, load_n, speed_mps, 0.0, ""});
  };
  const double slope = std::log(force_n(h.reference_load_n * step) / force_n(h.reference_load_n / step)) /
                       std::log(step * step);
  if (slope > 0.0) return std::nullopt;
  return "the fitted rolling-resistance force falls with load (log-slope " + fixed(slope, 2) + " at " +
         fixed(h.reference_load_n, 0) + " N, " + fixed(h.reference_pressure_pa / 1e3, 0) +
         " kPa, 80 km/h), where every measured tyre's rises (the nine Michelin J2452 sets: 0.89-1.09): check the points' loads and RRCs";
}

}  // namespace

TyreFit fit_hysteresis(const TyreState& start_in, const FitRequest& r) {
  std::vector<HysteresisParam> free = r.free.empty() ? identifiable_params(r.points) : r.free;
  check_request(r, free);
  TyreState start = start_in;
  start.model = TyreModelKind::Hysteresis;
  for (const auto& p : r.points) check_rrc_point(start, p);
  // Start the level where the first point says, so the optimiser begins near the answer.
  start.hysteresis.rrc_ref = 0.01;
  start.hysteresis.rrc_ref *= r.points.front().rrc / model_rrc(start, r.points.front());

  // A constant that must not be negative and fits below 0 is held at 0 and the rest refitted.
  std::vector<HysteresisParam> at_bound, undetermined, flat;
  while (true) {
    TyreFit fit = fit_once(start, r, free, flat);
    bool changed = false;
    for (const auto& e : fit.params) {
      if (hysteresis_param_non_negative(e.param) && e.value < 0.0) {
        set_hysteresis_param(start.hysteresis, e.param, 0.0);
        free.erase(std::find(free.begin(), free.end(), e.param));
        at_bound.push_back(e.param);
        changed = true;
      }
    }
    // A constant the points cannot see (e.g. the speed loss' load exponent once the speed loss is held at 0) keeps
    // its shared value, and the fit says so, rather than reporting it as fitted with a zero-width interval.
    if (!changed) {
      for (auto p : flat) {
        if (p == HysteresisParam::RrcRef) continue;  // the level always moves the fit
        free.erase(std::find(free.begin(), free.end(), p));
        undetermined.push_back(p);
        changed = true;
      }
    }
    if (!changed) {
      for (auto p : undetermined) {
        fit.warnings.push_back(std::string(hysteresis_param_key(p)) + " is not determined by these points (the fit does "
                               "not change with it, or only as another constant does" + (p == HysteresisParam::SpeedLossLoadExponent &&
                                                               hysteresis_param_value(start.hysteresis, HysteresisParam::SpeedLoss) == 0.0
                                                           ? ": it scales speed_loss_rrc_per_hz2, which is 0"
                                                           : "") +
                               "); it keeps the shared value");
      }
      for (auto p : at_bound) {
        fit.params.push_back({p, 0.0, 0.0, 0.0, 0.0, true});
        fit.held.erase(std::find(fit.held.begin(), fit.held.end(), p));
      }
      if (const auto w = force_falling_with_load(fit)) fit.warnings.push_back(*w);
      return fit;
    }
  }
}

LabelBand eu_label_band_c1(const std::string& label_class, const std::string& where) {
  // Regulation (EU) 2020/740, Annex I, Part A, table for C1 tyres (RRC in kg/t = 1e-3):
  // A: RRC <= 6.5; B: 6.6-7.7; C: 7.8-9.0; D: 9.1-10.5; E: RRC >= 10.6 (https://eur-lex.europa.eu/eli/reg/2020/740/oj).
  // A-C are 1222/2009's bands unchanged; D, empty there, takes its old E, and E its old F and G.
  // Values are declared to 0.1 kg/t, so a band's edges are half a digit outside its printed limits. A and E are
  // open-ended in the regulation; we close them with the declared width of the neighbouring band (our assumption):
  // A with B's 1.1 kg/t, E with D's 1.4 (E was closed with B's width too, 10.55-11.65, until session 19's outside
  // testing).
  static const LabelBand kBands[] = {{'A', 5.45e-3, 6.55e-3, true, false},
                                     {'B', 6.55e-3, 7.75e-3, false, false},
                                     {'C', 7.75e-3, 9.05e-3, false, false},
                                     {'D', 9.05e-3, 10.55e-3, false, false},
                                     {'E', 10.55e-3, 11.95e-3, false, true}};
  if (label_class.size() == 1) {
    const char c = static_cast<char>(std::toupper(static_cast<unsigned char>(label_class[0])));
    for (const auto& b : kBands) {
      if (b.label_class == c) return b;
    }
  }
  throw InputError(where, "'" + label_class + "' is not an EU tyre label fuel-efficiency class: allowed A, B, C, D, E "
                          "(Regulation (EU) 2020/740; its classes F and G of Regulation (EC) 1222/2009 no longer exist)");
}

RrcPoint rrc_point_from_file_units(double pressure_kpa, double load_n, double speed_kmh, double rrc, std::string where) {
  // Checked in the file's unit: 1e308 kPa overflowed to "pressure inf kPa" in Pa (session 21).
  if (!std::isfinite(pressure_kpa * 1e3)) check_pressure_plausible_kpa(pressure_kpa, std::nullopt, where);
  return {pressure_kpa * 1e3, load_n, units::kmh_to_mps(speed_kmh), rrc, std::move(where)};
}

std::vector<RrcPoint> load_measured_rrc_csv(const std::string& path, std::vector<std::string>* unread) {
  const CsvTable t = read_csv(path);
  const char* kCols[] = {"pressure_kpa", "load_n", "speed_kmh", "rrc"};
  std::size_t col[4];
  for (int k = 0; k < 4; ++k) {
    const auto c = t.column(kCols[k]);
    if (!c) {
      throw InputError(path, std::string("missing column '") + kCols[k] +
                                 "'; expected pressure_kpa, load_n, speed_kmh, rrc; found " + t.columns_list());
    }
    col[k] = *c;
  }
  std::string others;
  for (std::size_t c = 0; c < t.header.size(); ++c)
    if (std::find(std::begin(col), std::end(col), c) == std::end(col)) others += (others.empty() ? "'" : ", '") + t.header[c] + "'";
  if (unread && !others.empty())
    unread->push_back(path + ": column(s) " + others + " not read: the fit reads pressure_kpa, load_n, speed_kmh and rrc");
  std::vector<RrcPoint> out;
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    double v[4];
    for (int k = 0; k < 4; ++k) {
      const auto x = parse_number(t.rows[i][col[k]]);
      if (!x || !std::isfinite(*x)) throw InputError(t.where(i, col[k]), kCols[k] + std::string(" '") + t.rows[i][col[k]] + "' is not a number");
      v[k] = *x;
    }
    out.push_back(rrc_point_from_file_units(v[0], v[1], v[2], v[3], path + ": line " + std::to_string(t.row_line[i])));
  }
  if (out.empty()) throw InputError(path, "too few points for what is asked: the file has no data rows");
  return out;
}

RrcPoint iso28580_point(const TyreSize& size, double drum_rrc, const std::string& where) {
  if (!size.load_index) {
    throw InputError(where, "the size '" + size.designation + "' has no load index, so the ISO 28580 load (80 % of "
                            "the load index's load) is unknown; give the size with its load index, e.g. '205/55 R16 91V'");
  }
  if (size.commercial) {
    // ISO 28580 tests a C2 or C3 tyre at 85 % of its load at the pressure of its load-inflation table, and its EU
    // label has bands of its own: neither is built, and the passenger point would be a silently wrong one (a
    // 275/70 R22.5 148/145M truck tyre was placed at 210 kPa and 24.7 kN with C1 bands: session 24's outside testing).
    throw InputError(where, "'" + size.designation + "' is a light-truck, van or truck size (EU class C2 or C3): its "
                            "ISO 28580 point (85 % of the load index's load, at its load-inflation table's pressure) "
                            "and its label bands are not built; give its measured point(s) as KPA,LOAD_N,KMH,RRC");
  }
  check_rrc_range(drum_rrc, where);
  RrcPoint p;
  p.pressure_pa = iso28580_passenger_pressure_pa(size);
  p.load_n = 0.8 * *load_index_max_load_kg(*size.load_index) * units::kStandardGravity_mps2;
  p.speed_mps = units::kmh_to_mps(80.0);
  // A label's or test report's value was taken flat until session 22 (outside testing): 13-15 % above the flat road
  // the model and a J2452 set's correction give, for the same tyre.
  p.rrc = drum_rrc * drum_to_flat_factor(kIso28580DrumRadius_m, size.outer_radius_m);
  p.where = where + " (ISO 28580 drum; flat road " + significant(p.rrc, 4) + ")";
  return p;
}

}  // namespace rollsim

namespace rollsim {
namespace {

std::string num(double v) { return significant(v, 9); }

}  // namespace

std::string sigma_source(const TyreFit& fit) {
  if (fit.sigma_from_residuals) {
    return "from the residuals, " + std::to_string(fit.degrees_of_freedom) + " degree(s) of freedom: Student's t " +
           fixed(fit.interval_quantile, 2) + " standard errors each side";
  }
  return fit.degrees_of_freedom > 0 ? "assumed: the residuals are all 0" : "assumed: no degrees of freedom left";
}

void write_fitted_tyre_yaml(std::ostream& out, const FittedTyreFile& file, const TyreFit& fit) {
  const HysteresisConstants& h = fit.tyre.hysteresis;
  out << "# Written by 'rollsim tyre fit': hysteresis model fitted to " << fit.residuals.size()
      << " point(s), RMS relative error " << fixed(fit.rms_relative_error * 100.0, 2)
      << " %.\n";  // as the command prints it: an exact fit reads 0.00, not its rounding noise
  out << "# 95 % intervals (Jacobian covariance, relative scatter " << num(fit.sigma_relative * 100.0) << " % "
      << sigma_source(fit) << "):\n";
  for (const auto& e : fit.params) {
    out << "#   " << hysteresis_param_key(e.param) << " " << num(e.value);
    if (e.at_bound) out << " (held at its bound 0)\n";
    else out << " [" << num(e.low95) << ", " << num(e.high95) << "]\n";
  }
  if (!fit.held.empty()) {
    out << "# held at the shared values (fitted to the nine Michelin J2452 sets):";
    for (auto p : fit.held) out << " " << hysteresis_param_key(p);
    out << "\n";
  }
  out << "name: " << yaml_double_quoted(file.name) << "\n";
  out << "size: " << yaml_double_quoted(file.size) << "\n";
  out << "pressure_bar: " << num(file.pressure_pa / 1e5) << "\n";
  out << "source: " << yaml_double_quoted(file.source) << "\n";
  out << "model:\n  kind: hysteresis\n";
  out << "  reference_pressure_bar: " << num(h.reference_pressure_pa / 1e5) << "\n";
  out << "  reference_load_n: " << num(h.reference_load_n) << "\n";
  for (auto p : kAllParams) out << "  " << hysteresis_param_key(p) << ": " << num(hysteresis_param_value(h, p)) << "\n";
  const TyreModelConstants defaults;
  if (fit.tyre.constants.stiffness_pressure_coeff != defaults.stiffness_pressure_coeff) {
    out << "  stiffness_pressure_coeff: " << num(fit.tyre.constants.stiffness_pressure_coeff) << "\n";
  }
  if (fit.tyre.constants.stiffness_offset_kgf_per_mm != defaults.stiffness_offset_kgf_per_mm) {
    out << "  stiffness_offset_kgf_per_mm: " << num(fit.tyre.constants.stiffness_offset_kgf_per_mm) << "\n";
  }
}

}  // namespace rollsim
