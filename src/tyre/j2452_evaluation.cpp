#include "rollsim/tyre/j2452_evaluation.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>

#include "rollsim/common/error.hpp"
#include "rollsim/common/json.hpp"
#include "rollsim/common/statistics.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/tyre/hysteresis_model.hpp"
#include "rollsim/tyre/least_squares.hpp"
#include "rollsim/tyre/tyre_fit.hpp"
#include "rollsim/tyre/tyre_spec.hpp"

namespace rollsim {
namespace {

constexpr double kRefPressure_pa = 210e3;
constexpr double kRefLoad_n = 4000.0;
const double kRefSpeed_mps = units::kmh_to_mps(80.0);

// A model of RRC over (P, Z, V); surfaces are compared through it.
using Surface = std::function<double(double p_pa, double z_n, double v_mps)>;

Surface scaled_at_reference(const Surface& shape, double measured_ref_rrc) {
  const double k = measured_ref_rrc / shape(kRefPressure_pa, kRefLoad_n, kRefSpeed_mps);
  return [shape, k](double p, double z, double v) { return k * shape(p, z, v); };
}

struct ErrorStats {
  double rms = 0.0, max = 0.0;
};
ErrorStats grid_error(const Surface& model, const std::vector<RrcPoint>& truth) {
  ErrorStats s;
  for (const auto& pt : truth) {
    const double e = model(pt.pressure_pa, pt.load_n, pt.speed_mps) / pt.rrc - 1.0;
    s.rms += e * e;
    s.max = std::max(s.max, std::abs(e));
  }
  s.rms = std::sqrt(s.rms / truth.size());
  return s;
}

SurfaceScaling scaling_of(const Surface& rrc) {
  auto force = [&](double p, double z, double v) { return rrc(p, z, v) * z; };
  const double v80 = kRefSpeed_mps;
  SurfaceScaling s;
  s.pressure_exponent = std::log(force(300e3, kRefLoad_n, v80) / force(180e3, kRefLoad_n, v80)) / std::log(300.0 / 180.0);
  s.load_exponent = std::log(force(kRefPressure_pa, 6000.0, v80) / force(kRefPressure_pa, 3000.0, v80)) / std::log(2.0);
  s.speed_rise = force(kRefPressure_pa, kRefLoad_n, units::kmh_to_mps(115.0)) /
                     force(kRefPressure_pa, kRefLoad_n, units::kmh_to_mps(15.0)) - 1.0;
  return s;
}

Surface hysteresis_surface(const TyreState& tyre) {
  return [tyre](double p, double z, double v) {
    TyreState t = tyre;
    t.pressure_pa = p;
    const SpeedPolynomial k = hysteresis_polynomial(t, z);
    return k.k0 + v * (k.k1_s_per_m + v * k.k2_s2_per_m2);
  };
}

Surface j2452_surface(const J2452Set& s, double drum_radius_m) {
  return [s, drum_radius_m](double p, double z, double v) { return j2452_flat_rrc(s, p, z, v, drum_radius_m); };
}

// The hysteresis model with `shared` constants and its level set from the tyre's reference point. The model is
// linear in rrc_ref, so the level is solved, not searched.
TyreState one_point_tyre(const J2452Set& set, const HysteresisConstants& shared, double drum_radius_m) {
  TyreState t = j2452_tyre(set);
  t.model = TyreModelKind::Hysteresis;
  t.hysteresis = shared;
  t.hysteresis.rrc_ref = 0.0;
  const double rest = hysteresis_surface(t)(kRefPressure_pa, kRefLoad_n, kRefSpeed_mps);
  t.hysteresis.rrc_ref = 1.0;
  const double unit = hysteresis_surface(t)(kRefPressure_pa, kRefLoad_n, kRefSpeed_mps) - rest;
  const double measured = j2452_flat_rrc(set, kRefPressure_pa, kRefLoad_n, kRefSpeed_mps, drum_radius_m);
  t.hysteresis.rrc_ref = (measured - rest) / unit;
  return t;
}

Surface median_shape_of(const std::vector<J2452Set>& others) {
  std::vector<double> al, be, b, c;
  for (const auto& s : others) {
    al.push_back(s.alpha);
    be.push_back(s.beta);
    b.push_back(s.b / s.a);
    c.push_back(s.c / s.a);
  }
  J2452Set m{"median", "", median(al), median(be), 1.0, median(b), median(c), 0.3};
  return j2452_surface(m, kJ2452DrumRadius_m);  // the drum factor is a constant: scaling removes it
}

constexpr HysteresisParam kShared[] = {HysteresisParam::FrequencySlope, HysteresisParam::DeflectionExponent,
                                       HysteresisParam::LoadExponent, HysteresisParam::SpeedLoss,
                                       HysteresisParam::SpeedLossLoadExponent};

// The plan's points, the reference point first, each with the RRC `rrc_at` gives it.
std::vector<RrcPoint> plan_points(const MeasurementPlan& plan, const std::function<double(const OperatingPoint&)>& rrc_at) {
  std::vector<RrcPoint> points;
  const OperatingPoint reference{kRefPressure_pa, kRefLoad_n, kRefSpeed_mps};
  points.push_back({reference.pressure_pa, reference.load_n, reference.speed_mps, rrc_at(reference), "reference point"});
  for (const auto& o : plan.extra) points.push_back({o.pressure_pa, o.load_n, o.speed_mps, rrc_at(o), plan.name});
  return points;
}

// The plan's points on the tyre's surface, fitted from the shared constants.
double plan_rms(const MeasurementPlan& plan, const J2452Set& set, const HysteresisConstants& shared,
                const std::vector<RrcPoint>& truth, double drum_radius_m) {
  FitRequest request;  // free: what the points determine
  request.points = plan_points(plan, [&](const OperatingPoint& o) {
    return j2452_flat_rrc(set, o.pressure_pa, o.load_n, o.speed_mps, drum_radius_m);
  });
  const TyreFit fit = fit_hysteresis(one_point_tyre(set, shared, drum_radius_m), request);
  return grid_error(hysteresis_surface(fit.tyre), truth).rms;
}

}  // namespace

std::vector<MeasurementPlan> j2452_measurement_plans() {
  const OperatingPoint v15{kRefPressure_pa, kRefLoad_n, units::kmh_to_mps(15.0)};
  const OperatingPoint v115{kRefPressure_pa, kRefLoad_n, units::kmh_to_mps(115.0)};
  const OperatingPoint p180{180e3, kRefLoad_n, kRefSpeed_mps}, p300{300e3, kRefLoad_n, kRefSpeed_mps};
  const OperatingPoint z3{kRefPressure_pa, 3000.0, kRefSpeed_mps}, z6{kRefPressure_pa, 6000.0, kRefSpeed_mps};
  std::vector<MeasurementPlan> plans{{"+15 km/h", {v15}, {}},
                                      {"+115 km/h", {v115}, {}},
                                      {"+180 kPa", {p180}, {}},
                                      {"+300 kPa", {p300}, {}},
                                      {"+3 kN", {z3}, {}},
                                      {"+6 kN", {z6}, {}},
                                      {"+15 km/h, +180 kPa", {v15, p180}, {}},
                                      {"+15 km/h, +300 kPa", {v15, p300}, {}},
                                      {"+115 km/h, +180 kPa", {v115, p180}, {}},
                                      {"+115 km/h, +300 kPa", {v115, p300}, {}},
                                      {"+15 km/h, +115 km/h", {v15, v115}, {}},
                                      {"+15 km/h, +115 km/h, +180 kPa", {v15, v115, p180}, {}},
                                      {"+15 km/h, +115 km/h, +300 kPa", {v15, v115, p300}, {}}};
  for (auto& plan : plans) {  // what `rollsim tyre fit` frees for these points; their RRC does not matter here
    plan.fitted = identifiable_params(plan_points(plan, [](const OperatingPoint&) { return 0.01; }));
  }
  return plans;
}

TyreState j2452_tyre(const J2452Set& set) {
  const TyreSize size = parse_tyre_size(set.size, "J2452 set '" + set.name + "'");
  TyreState t;
  t.geometry.outer_radius_m = size.outer_radius_m;
  t.geometry.section_width_m = size.section_width_m;
  t.geometry.rim_radius_m = size.rim_diameter_m / 2.0;
  t.pressure_pa = kRefPressure_pa;
  return t;
}

// The shared constants as a single tyre's fit holds them: one that must not be negative and fits below 0 is held at 0
// and the rest refitted (and a held speed loss takes its load exponent with it). Left free, a set with a small speed
// term (c = 1e-5) drove the others' speed loss to -2.5e-6 and the evaluation ended in a domain error naming no set
// (session 24's outside testing).
HysteresisConstants fit_shared_constants(const std::vector<J2452Set>& training, double drum_radius_m) {
  const OperatingGrid grid = j2452_grid();
  std::vector<std::vector<RrcPoint>> truth;
  for (const auto& s : training) truth.push_back(sample_j2452(s, grid, drum_radius_m, s.name));
  HysteresisConstants held;
  std::vector<HysteresisParam> free(std::begin(kShared), std::end(kShared));
  const int m = static_cast<int>(training.size() * grid.pressures_pa.size() * grid.loads_n.size() * grid.speeds_mps.size());
  while (true) {
    auto constants = [&](const Eigen::VectorXd& x) {
      HysteresisConstants c = held;
      for (std::size_t k = 0; k < free.size(); ++k) set_hysteresis_param(c, free[k], x[static_cast<Eigen::Index>(k)]);
      return c;
    };
    const ResidualFunction residuals = [&](const Eigen::VectorXd& x, Eigen::VectorXd& r) {
      const HysteresisConstants c = constants(x);
      int i = 0;
      for (std::size_t k = 0; k < training.size(); ++k) {
        const Surface model = hysteresis_surface(one_point_tyre(training[k], c, drum_radius_m));
        for (const auto& pt : truth[k]) r[i++] = model(pt.pressure_pa, pt.load_n, pt.speed_mps) / pt.rrc - 1.0;
      }
    };
    Eigen::VectorXd x0(static_cast<Eigen::Index>(free.size()));
    for (std::size_t k = 0; k < free.size(); ++k) x0[static_cast<Eigen::Index>(k)] = hysteresis_param_value(held, free[k]);
    const HysteresisConstants fitted = constants(least_squares(residuals, m, x0).x);
    std::vector<HysteresisParam> below;
    for (auto p : free)
      if (hysteresis_param_non_negative(p) && hysteresis_param_value(fitted, p) < 0.0) below.push_back(p);
    if (below.empty()) return fitted;
    for (auto p : below) {
      set_hysteresis_param(held, p, 0.0);
      free.erase(std::find(free.begin(), free.end(), p));
      if (p == HysteresisParam::SpeedLoss) free.erase(std::remove(free.begin(), free.end(), HysteresisParam::SpeedLossLoadExponent), free.end());
    }
  }
}

Eigen::VectorXd minimise_on_simplex(const Eigen::MatrixXd& q, const Eigen::VectorXd& c) {
  const Eigen::Index n = q.rows();
  Eigen::VectorXd w = Eigen::VectorXd::Constant(n, 1.0 / n);
  // Frank-Wolfe with away steps (Lacoste-Julien and Jaggi 2015), which converges linearly here where the plain
  // method crawls towards a face of the simplex.
  for (int iter = 0; iter < 100000; ++iter) {
    const Eigen::VectorXd grad = 2.0 * q * w + c;
    const double at_w = grad.dot(w);
    Eigen::Index j = 0, k = -1;
    grad.minCoeff(&j);
    for (Eigen::Index i = 0; i < n; ++i) {
      if (w[i] > 0.0 && (k < 0 || grad[i] > grad[k])) k = i;
    }
    if (k < 0 || !std::isfinite(grad[j])) throw std::logic_error("minimise_on_simplex: not finite");
    if (at_w - grad[j] < 1e-15) break;  // the duality gap: w is optimal to round-off
    Eigen::VectorXd d = -w;
    double max_step = 1.0;
    if (at_w - grad[j] >= grad[k] - at_w) {
      d[j] += 1.0;
    } else {
      d = w;
      d[k] -= 1.0;
      max_step = w[k] / (1.0 - w[k]);
    }
    const double curvature = d.dot(q * d);
    if (curvature <= 0.0) break;
    w += std::clamp(-grad.dot(d) / (2.0 * curvature), 0.0, max_step) * d;
  }
  return w;
}

EnclosingBall smallest_enclosing_ball(const Eigen::MatrixXd& shapes) {
  const Eigen::MatrixXd gram = shapes * shapes.transpose() / static_cast<double>(shapes.cols());
  // The dual, max sum w_i G_ii - w'Gw over the simplex, is concave; every w on it gives a lower bound on the
  // radius^2 (for any centre, the largest squared distance is at least the w-weighted mean one, itself at least
  // the dual's value), and its maximiser weights the points that lie on the ball.
  const Eigen::VectorXd w = minimise_on_simplex(gram, -gram.diagonal());
  EnclosingBall ball;
  ball.centre = shapes.transpose() * w;
  ball.radius = std::sqrt(std::max(0.0, gram.diagonal().dot(w) - w.dot(gram * w)));
  return ball;
}

NearestMix nearest_mix(const Eigen::MatrixXd& shapes, const Eigen::VectorXd& target) {
  const double cols = static_cast<double>(shapes.cols());
  // A free level is a constant added over the grid: centring every row and the target removes it.
  const Eigen::MatrixXd a = shapes.colwise() - shapes.rowwise().mean();
  const Eigen::VectorXd y = target.array() - target.mean();
  const Eigen::VectorXd w = minimise_on_simplex(a * a.transpose() / cols, -2.0 * a * y / cols);
  NearestMix out;
  out.weights = w;
  out.log_rms = std::sqrt((a.transpose() * w - y).squaredNorm() / cols);
  // The relative error of the mix at its best level: mean((e^(d+c) - 1)^2) is least where e^c = mean(e^d) / mean(e^2d).
  const Eigen::ArrayXd ed = (shapes.transpose() * w - target).array().exp();
  const double level = ed.mean() / ed.square().mean();
  out.rms = std::sqrt((ed * level - 1.0).square().mean());
  return out;
}

namespace {

// Each tyre's log-RRC over the grid relative to its own reference point (one row per set): its shape, as a
// one-point fit sees it.
Eigen::MatrixXd log_shapes(const std::vector<J2452Set>& sets, double drum_radius_m) {
  const OperatingGrid grid = j2452_grid();
  Eigen::MatrixXd shapes;
  for (std::size_t i = 0; i < sets.size(); ++i) {
    const auto truth = sample_j2452(sets[i], grid, drum_radius_m, sets[i].name);
    if (i == 0) shapes.resize(static_cast<Eigen::Index>(sets.size()), static_cast<Eigen::Index>(truth.size()));
    const double ref = j2452_flat_rrc(sets[i], kRefPressure_pa, kRefLoad_n, kRefSpeed_mps, drum_radius_m);
    for (std::size_t g = 0; g < truth.size(); ++g) shapes(i, g) = std::log(truth[g].rrc / ref);
  }
  return shapes;
}

CommonShapeBound common_shape_bound(const std::vector<J2452Set>& sets, double drum_radius_m) {
  const Eigen::MatrixXd shapes = log_shapes(sets, drum_radius_m);
  const EnclosingBall ball = smallest_enclosing_ball(shapes);
  CommonShapeBound out;
  out.worst_log_rms = ball.radius;
  for (Eigen::Index i = 0; i < shapes.rows(); ++i) {
    const Eigen::ArrayXd e = (ball.centre.transpose() - shapes.row(i)).array().exp() - 1.0;
    out.rms.push_back(std::sqrt(e.square().mean()));
  }
  return out;
}

// One tyre judged with shared constants fitted without it: the one point, the measurement plans, a full fit
// (started from `full_fit_start`), and the baselines, the median J2452 shape taken from `others`.
TyreEvaluation evaluate_tyre(const J2452Set& set, const HysteresisConstants& shared, const std::vector<J2452Set>& others,
                             const HysteresisConstants& full_fit_start, const std::vector<MeasurementPlan>& plans,
                             double drum_radius_m) {
  const auto truth = sample_j2452(set, j2452_grid(), drum_radius_m, set.name);
  const double ref_rrc = j2452_flat_rrc(set, kRefPressure_pa, kRefLoad_n, kRefSpeed_mps, drum_radius_m);
  TyreEvaluation e;
  e.name = set.name;
  e.flagged = set.flagged;
  e.reference_rrc = ref_rrc;
  e.shared = shared;
  const Surface one_point = hysteresis_surface(one_point_tyre(set, shared, drum_radius_m));
  const ErrorStats op = grid_error(one_point, truth);
  e.one_point_rms = op.rms;
  e.one_point_max = op.max;
  for (const auto& plan : plans) e.plan_rms.push_back(plan_rms(plan, set, shared, truth, drum_radius_m));

  FitRequest request;
  request.points = truth;
  request.free = all_hysteresis_params();
  const TyreFit full = fit_hysteresis(one_point_tyre(set, full_fit_start, drum_radius_m), request);
  const Surface full_surface = hysteresis_surface(full.tyre);
  e.full_fit_rms = grid_error(full_surface, truth).rms;

  const TyreState thesis_tyre = j2452_tyre(set);
  const Surface thesis = scaled_at_reference(
      [thesis_tyre](double p, double z, double v) {
        TyreState t = thesis_tyre;
        t.pressure_pa = p;
        return evaluate_rolling_resistance(t, z, v).rrc;
      },
      ref_rrc);
  e.thesis_rms = grid_error(thesis, truth).rms;
  e.constant_rms = grid_error([ref_rrc](double, double, double) { return ref_rrc; }, truth).rms;
  e.median_shape_rms = grid_error(scaled_at_reference(median_shape_of(others), ref_rrc), truth).rms;

  e.measured = scaling_of(j2452_surface(set, drum_radius_m));
  e.one_point = scaling_of(one_point);
  e.full_fit = scaling_of(full_surface);
  e.thesis = scaling_of(thesis);
  return e;
}

}  // namespace

J2452Evaluation evaluate_j2452(const std::vector<J2452Set>& sets, double drum_radius_m) {
  J2452Evaluation out;
  out.shared_all = fit_shared_constants(sets, drum_radius_m);
  out.common_shape = common_shape_bound(sets, drum_radius_m);
  out.plans = j2452_measurement_plans();
  const Eigen::MatrixXd shapes = log_shapes(sets, drum_radius_m);
  for (std::size_t i = 0; i < sets.size(); ++i) {
    std::vector<J2452Set> others;
    std::vector<Eigen::Index> seen;
    for (std::size_t j = 0; j < sets.size(); ++j) {
      if (j != i) others.push_back(sets[j]), seen.push_back(static_cast<Eigen::Index>(j));
    }
    out.tyres.push_back(evaluate_tyre(sets[i], fit_shared_constants(others, drum_radius_m), others, out.shared_all,
                                      out.plans, drum_radius_m));
    out.tyres.back().seen_shapes = nearest_mix(shapes(seen, Eigen::all), shapes.row(static_cast<Eigen::Index>(i)).transpose());
  }
  return out;
}

J2452Evaluation evaluate_j2452_held_out(const std::vector<J2452Set>& training, const std::vector<J2452Set>& test,
                                        double drum_radius_m, const std::string& training_source, const std::string& test_source) {
  // Judged on a tyre it was fitted on, the table's "none of the tyres below" would be false.
  for (const auto& h : test)
    for (const auto& s : training)
      if (same_j2452_tyre(h, s))
        throw InputError(test_source, "the set " + h.name + " is also in " + training_source + " (" + s.name +
                                          "): a held-out tyre must not be one the constants are fitted on");
  J2452Evaluation out;
  out.leave_one_out = false;
  out.shared_all = fit_shared_constants(training, drum_radius_m);
  out.common_shape = common_shape_bound(test, drum_radius_m);
  out.plans = j2452_measurement_plans();
  const Eigen::MatrixXd seen = log_shapes(training, drum_radius_m), judged = log_shapes(test, drum_radius_m);
  for (std::size_t i = 0; i < test.size(); ++i) {
    out.tyres.push_back(evaluate_tyre(test[i], out.shared_all, training, out.shared_all, out.plans, drum_radius_m));
    out.tyres.back().seen_shapes = nearest_mix(seen, judged.row(static_cast<Eigen::Index>(i)).transpose());
  }
  return out;
}

namespace {

JsonObject scaling_json(const SurfaceScaling& s) {
  return JsonObject()
      .add("pressure_exponent", s.pressure_exponent)
      .add("load_exponent", s.load_exponent)
      .add("speed_rise_pct", 100.0 * s.speed_rise);
}

JsonObject shared_json(const std::string& without, const HysteresisConstants& c) {
  JsonObject j;
  j.add("kind", "shared").add("fitted_without", without);
  for (const auto p : kShared) j.add(hysteresis_param_key(p), hysteresis_param_value(c, p));
  return j;
}

}  // namespace

std::vector<double> plan_rms_column(const J2452Evaluation& ev, std::size_t k) {
  std::vector<double> rms;
  for (const auto& e : ev.tyres) rms.push_back(e.plan_rms.at(k));
  return rms;
}

void write_j2452_evaluation_json(std::ostream& out, const J2452Evaluation& ev) {
  for (const auto& e : ev.tyres) {
    out << JsonObject()
               .add("kind", "tyre")
               .add("name", e.name)
               .add("flagged", e.flagged)
               .add("rrc_kg_per_t", 1e3 * e.reference_rrc)
               .add("one_point_rms_pct", 100.0 * e.one_point_rms)
               .add("one_point_max_pct", 100.0 * e.one_point_max)
               .add("full_fit_rms_pct", 100.0 * e.full_fit_rms)
               .add("thesis_rms_pct", 100.0 * e.thesis_rms)
               .add("constant_rms_pct", 100.0 * e.constant_rms)
               .add("median_shape_rms_pct", 100.0 * e.median_shape_rms)
               .add("seen_shapes_bound_log_rms_pct", 100.0 * e.seen_shapes.log_rms)
               .add("seen_shapes_bound_rms_pct", 100.0 * e.seen_shapes.rms)
               .add("measured", scaling_json(e.measured))
               .add("one_point", scaling_json(e.one_point))
               .add("full_fit", scaling_json(e.full_fit))
               .add("thesis", scaling_json(e.thesis))
               .str()
        << '\n';
  }
  for (std::size_t k = 0; k < ev.plans.size(); ++k) {
    const std::vector<double> rms = plan_rms_column(ev, k);
    JsonObject per_tyre;
    for (std::size_t i = 0; i < ev.tyres.size(); ++i) per_tyre.add(ev.tyres[i].name, 100.0 * rms[i]);
    out << JsonObject()
               .add("kind", "plan")
               .add("measured_besides", ev.plans[k].name)
               .add("fitted", hysteresis_param_keys(ev.plans[k].fitted))
               .add("median_rms_pct", 100.0 * median(rms))
               .add("worst_rms_pct", 100.0 * *std::max_element(rms.begin(), rms.end()))
               .add("rms_pct", per_tyre)
               .str()
        << '\n';
  }
  out << JsonObject().add("kind", "common_shape").add("worst_log_rms_pct", 100.0 * ev.common_shape.worst_log_rms).str()
      << '\n';
  out << shared_json("", ev.shared_all).str() << '\n';
  if (ev.leave_one_out) {
    for (const auto& e : ev.tyres) out << shared_json(e.name, e.shared).str() << '\n';
  }
}

}  // namespace rollsim
