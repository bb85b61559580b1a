// The hysteresis model, `rollsim tyre fit` and its evidence: analytic limits, synthetic truths, the measured
// Michelin J2452 surfaces held out tyre by tyre, and bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <tuple>
#include <numbers>
#include <string>
#include <vector>

#include "rollsim/common/error.hpp"
#include "rollsim/common/text.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/tyre/hysteresis_model.hpp"
#include "rollsim/tyre/j2452.hpp"
#include "rollsim/tyre/j2452_evaluation.hpp"
#include "rollsim/tyre/tyre_fit.hpp"
#include "rollsim/tyre/tyre_fit_plan.hpp"
#include "rollsim/tyre/tyre_model.hpp"
#include "rollsim/tyre/tyre_spec.hpp"
#include "rollsim/common/statistics.hpp"
#include "test_support.hpp"

using namespace rollsim;
using rollsim::test::CmdResult;
using rollsim::test::json_number;
using rollsim::test::lines;
using rollsim::test::temp_dir;

namespace {

const std::string kJ2452Csv = std::string(ROLLSIM_SHARED_DIR) + "/data/tyres/j2452_michelin_part.csv";
// Eight more Michelin sets, added after the model and its constants were fixed on the nine (tyres/measured).
const std::string kHeldOutCsv = std::string(ROLLSIM_SOURCE_DIR) + "/tyres/measured/j2452_michelin_holdout.csv";

TyreState hysteresis_tyre() {
  TyreState t;
  t.geometry = {0.3159, 0.205, 0.2032};
  t.pressure_pa = 2.1e5;
  t.model = TyreModelKind::Hysteresis;
  t.hysteresis.rrc_ref = 0.009;
  return t;
}

// The hysteresis tyre fitted to two points with the fit's own choice of what to free.
TyreFit fit_two_points(const RrcPoint& a, const RrcPoint& b) {
  FitRequest r;
  r.points = {a, b};
  return fit_hysteresis(hysteresis_tyre(), r);
}

// The evaluation is deterministic and takes ~0.2 s; computed once for the tests that read it.
const J2452Evaluation& evaluation() {
  static const J2452Evaluation ev = evaluate_j2452(load_j2452_csv(kJ2452Csv), kJ2452DrumRadius_m);
  return ev;
}

const J2452Evaluation& held_out_evaluation() {
  static const J2452Evaluation ev =
      evaluate_j2452_held_out(load_j2452_csv(kJ2452Csv), load_j2452_csv(kHeldOutCsv), kJ2452DrumRadius_m);
  return ev;
}

std::vector<double> plan_rms(const J2452Evaluation& ev, const std::string& plan) {
  for (std::size_t k = 0; k < ev.plans.size(); ++k) {
    if (ev.plans[k].name == plan) return plan_rms_column(ev, k);
  }
  ADD_FAILURE() << "no plan " << plan;
  return {};
}

CmdResult fit(const std::string& args) { return rollsim::test::run_rollsim("tyre fit " + args); }

bool has(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }


}  // namespace

// --- the model: analytic limits and invariants ---

TEST(HysteresisModel, WithoutSpeedAndScalingTermsRrcIsItsLevel) {
  TyreState t = hysteresis_tyre();
  t.hysteresis.deflection_exponent = t.hysteresis.load_exponent = 0.0;
  t.hysteresis.frequency_slope_per_hz = t.hysteresis.speed_loss_rrc_per_hz2 = 0.0;
  for (double z : {2000.0, 4000.0, 7000.0}) {
    EXPECT_NEAR(evaluate_rolling_resistance(t, z, 30.0).rrc, 0.009, 1e-15);
  }
  EXPECT_EQ(evaluate_rolling_resistance(t, 4000.0, 0.0).rrc, 0.0);  // standstill: no rolling loss
}

TEST(HysteresisModel, LoadScalingFollowsItsExponentsExactly) {
  // Rhyne's stiffness does not depend on load, so deflection is proportional to load and the hysteresis part
  // scales as Z^(n_d + n_z); the speed-squared part as Z^n_w.
  TyreState t = hysteresis_tyre();
  const auto a = TyreAtLoad::prepare(t, 3000.0), b = TyreAtLoad::prepare(t, 6000.0);
  const auto& h = t.hysteresis;
  EXPECT_NEAR(b.k0() / a.k0(), std::pow(2.0, h.deflection_exponent + h.load_exponent), 1e-12);
  EXPECT_NEAR(b.k2_s2_per_m2() / a.k2_s2_per_m2(), std::pow(2.0, h.speed_loss_load_exponent), 1e-12);
  // The frequency rise: k1 / k0 = s_f / (2 pi R).
  EXPECT_NEAR(a.k1_s_per_m() / a.k0(), h.frequency_slope_per_hz / (2 * std::numbers::pi * 0.3159), 1e-12);
}

TEST(HysteresisModel, PreparedTyreEqualsTheDirectEvaluation) {
  const TyreState t = hysteresis_tyre();
  const auto prepared = TyreAtLoad::prepare(t, 4321.0);
  for (double kmh = 1.0; kmh <= 250.0; kmh += 7.0) {
    const auto r = evaluate_rolling_resistance(t, 4321.0, kmh / 3.6);
    EXPECT_NEAR(prepared.rrc(kmh / 3.6), r.rrc, 1e-15);
    EXPECT_NEAR(r.rrc_coulomb + r.rrc_viscous + r.rrc_rotational_drag, r.rrc, 1e-15);
  }
}

TEST(HysteresisModel, RrcFallsWithPressureAndRisesWithSpeed) {
  TyreState t = hysteresis_tyre();
  const double low = evaluate_rolling_resistance(t, 4000.0, 22.0).rrc;
  t.pressure_pa = 2.8e5;
  EXPECT_LT(evaluate_rolling_resistance(t, 4000.0, 22.0).rrc, low);
  EXPECT_GT(evaluate_rolling_resistance(t, 4000.0, 30.0).rrc, evaluate_rolling_resistance(t, 4000.0, 22.0).rrc);
}

// A what-if on the size keeps the measured tyre's reference deflection, so the size acts through the deflection as
// the model's law says: RRC ~ dz^n_d at a fixed load and pressure. Before session 13 the reference deflection was
// re-derived from the resized tyre and cancelled it: a sweep over width was flat and its elasticity 0.
TEST(HysteresisModel, AWhatIfOnTheSizeActsThroughTheDeflection) {
  const TyreState t = hysteresis_tyre();
  const double z = 4000.0, v = 22.0;
  // The tyre at its own size is unchanged by the pinning.
  EXPECT_DOUBLE_EQ(evaluate_rolling_resistance(with_geometry(t, t.geometry), z, v).rrc,
                   evaluate_rolling_resistance(t, z, v).rrc);
  // Width changes neither the frequency nor the speed-squared term: the whole hysteresis part scales as dz^n_d.
  TyreState no_speed = t;
  no_speed.hysteresis.frequency_slope_per_hz = no_speed.hysteresis.speed_loss_rrc_per_hz2 = 0.0;
  for (double scale : {0.7, 1.3}) {
    TyreGeometry g = t.geometry;
    g.section_width_m *= scale;
    const TyreState wide = with_geometry(no_speed, g);
    const double dz_ratio = vertical_stiffness_n_per_m(no_speed) / vertical_stiffness_n_per_m(wide);
    EXPECT_NEAR(evaluate_rolling_resistance(wide, z, v).rrc / evaluate_rolling_resistance(no_speed, z, v).rrc,
                std::pow(dz_ratio, t.hysteresis.deflection_exponent), 1e-12);
    EXPECT_NE(dz_ratio, 1.0);
  }
  // A wider or taller tyre deflects less and loses less; the thesis model is untouched by the pinning.
  TyreGeometry wider = t.geometry, taller = t.geometry;
  wider.section_width_m *= 1.2;
  taller.outer_radius_m *= 1.1;
  EXPECT_LT(evaluate_rolling_resistance(with_geometry(t, wider), z, v).rrc, evaluate_rolling_resistance(t, z, v).rrc);
  EXPECT_LT(evaluate_rolling_resistance(with_geometry(t, taller), z, v).rrc, evaluate_rolling_resistance(t, z, v).rrc);
  TyreState thesis = t;
  thesis.model = TyreModelKind::Thesis;
  EXPECT_EQ(with_geometry(thesis, wider).hysteresis.reference_deflection_m, 0.0);
}

// A file's constants extrapolate without limit: deflection and load exponents of 5 give RRC 0.46 at 1.5 times the
// reference load, which the model returned as a number (and simulate and sweep used) before session 13. Beyond 0.1
// it is a domain error naming the level and the exponents; at the reference load the same file is fine.
TEST(TyreModels, ALevelNoTyreReachesIsADomainErrorNotANumber) {
  TyreState t = hysteresis_tyre();
  t.hysteresis.deflection_exponent = t.hysteresis.load_exponent = 5.0;
  check_hysteresis_constants(t.hysteresis);
  EXPECT_NO_THROW(evaluate_rolling_resistance(t, t.hysteresis.reference_load_n, 20.0));
  try {
    evaluate_rolling_resistance(t, 1.5 * t.hysteresis.reference_load_n, 20.0);
    ADD_FAILURE() << "no domain error";
  } catch (const ModelDomainError& e) {
    EXPECT_NE(std::string(e.what()).find("beyond 0.1"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("deflection 5, load 5"), std::string::npos) << e.what();
  }
  EXPECT_THROW(TyreAtLoad::prepare(t, 1.5 * t.hysteresis.reference_load_n), ModelDomainError);
  // The same bound holds for the thesis model's constants: a Coulomb damping of 10 MN gave RRC 423.
  TyreState thesis = hysteresis_tyre();
  thesis.model = TyreModelKind::Thesis;
  EXPECT_NO_THROW(TyreAtLoad::prepare(thesis, 4000.0));
  thesis.constants.coulomb_damping_n = 1e7;
  EXPECT_THROW(TyreAtLoad::prepare(thesis, 4000.0), ModelDomainError);
  EXPECT_THROW(evaluate_rolling_resistance(thesis, 4000.0, 20.0), ModelDomainError);
}

// --- fitting: known truths ---

TEST(TyreFit, RecoversEveryConstantFromASurfaceItGenerated) {
  TyreState truth = hysteresis_tyre();
  auto& h = truth.hysteresis;
  h.rrc_ref = 0.0072, h.deflection_exponent = 0.8, h.load_exponent = -0.3, h.frequency_slope_per_hz = 0.03;
  h.speed_loss_rrc_per_hz2 = 8e-6, h.speed_loss_load_exponent = -0.5;
  FitRequest req;
  const OperatingGrid g = j2452_grid();
  for (double p : g.pressures_pa)
    for (double z : g.loads_n)
      for (double v : g.speeds_mps) {
        TyreState at = truth;
        at.pressure_pa = p;
        req.points.push_back({p, z, v, evaluate_rolling_resistance(at, z, v).rrc, "synthetic"});
      }
  TyreState start = truth;
  start.hysteresis = HysteresisConstants{};
  const TyreFit f = fit_hysteresis(start, req);
  ASSERT_EQ(f.params.size(), 6u);
  for (const auto& e : f.params) {
    const double want = hysteresis_param_value(h, e.param);
    EXPECT_NEAR(e.value, want, 1e-6 * std::max(1.0, std::abs(want))) << hysteresis_param_key(e.param);
  }
  EXPECT_LT(f.rms_relative_error, 1e-9);
}

TEST(TyreFit, OnePointReproducesItWithTheAssumedUncertaintyAsInterval) {
  FitRequest req;
  req.points = {{2.1e5, 4825.0, 80 / 3.6, 0.0085, "p"}};
  const TyreFit f = fit_hysteresis(hysteresis_tyre(), req);
  ASSERT_EQ(f.params.size(), 1u);
  EXPECT_EQ(f.params[0].param, HysteresisParam::RrcRef);
  EXPECT_NEAR(f.residuals[0].model_rrc, 0.0085, 1e-12);
  EXPECT_FALSE(f.sigma_from_residuals);
  // One parameter, one point, relative residual r: d r / d ln(rrc_ref) is the hysteresis share of RRC (the
  // speed-squared loss does not scale with the level), so the log-interval is +-1.96 sigma / share.
  const auto k = TyreAtLoad::prepare(f.tyre, 4825.0);
  const double v_mps = 80 / 3.6;
  const double share = (k.k0() + k.k1_s_per_m() * v_mps) / k.rrc(v_mps);
  const double v = f.params[0].value;
  EXPECT_NEAR(std::log(f.params[0].high95 / v), 1.96 * 0.02 / share, 1e-6);
  EXPECT_NEAR(std::log(v / f.params[0].low95), 1.96 * 0.02 / share, 1e-6);
}

TEST(TyreFit, ChoosesOnlyWhatThePointsDetermine) {
  auto pt = [](double kpa, double z, double kmh) { return RrcPoint{kpa * 1e3, z, kmh / 3.6, 0.009, "p"}; };
  EXPECT_EQ(identifiable_params({pt(210, 4000, 80)}).size(), 1u);
  const auto two_speeds = identifiable_params({pt(210, 4000, 50), pt(210, 4000, 100)});
  ASSERT_EQ(two_speeds.size(), 2u);
  EXPECT_EQ(two_speeds[1], HysteresisParam::FrequencySlope);
  const auto pressures = identifiable_params({pt(180, 4000, 80), pt(240, 4000, 80), pt(300, 4000, 80)});
  EXPECT_EQ(pressures.size(), 2u);  // level and deflection exponent; no speed or load information
}

// A dense sweep is as many conditions as it spans, however close its neighbours: grouped by each value's neighbour,
// 180-300 kPa in 0.1 kPa steps chained into one pressure and the deflection exponent was held at the shared 0.54
// (2.98 % RMS against a truth of 0.8; session 24's outside testing). Likewise loads in 2 N steps.
TEST(TyreFit, ADenseSweepIsManyConditionsAndFreesItsExponent) {
  TyreState truth = hysteresis_tyre();
  truth.hysteresis.deflection_exponent = 0.8, truth.hysteresis.load_exponent = -0.3;
  FitRequest pressures, loads;
  for (int k = 0; k <= 1200; ++k) {
    TyreState at = truth;
    at.pressure_pa = 180e3 + 100.0 * k;
    pressures.points.push_back({at.pressure_pa, 4000.0, 80 / 3.6, evaluate_rolling_resistance(at, 4000.0, 80 / 3.6).rrc, "p"});
  }
  for (int k = 0; k <= 1500; ++k) {
    const double z = 3000.0 + 2.0 * k;
    loads.points.push_back({truth.pressure_pa, z, 80 / 3.6, evaluate_rolling_resistance(truth, z, 80 / 3.6).rrc, "z"});
  }
  EXPECT_GE(identifiable_params(pressures.points).size(), 2u);
  TyreState start = truth;
  start.hysteresis = HysteresisConstants{};
  const TyreFit fp = fit_hysteresis(start, pressures);
  EXPECT_LT(fp.rms_relative_error, 1e-6);
  // A load sweep alone tells the load and deflection exponents' sum, not each (both scale with the load).
  EXPECT_LT(fit_hysteresis(start, loads).rms_relative_error, 1e-6);
  // Neighbours within 0.1 % of a group's first value are still one condition (a repeated measurement).
  auto pt = [](double kpa) { return RrcPoint{kpa * 1e3, 4000.0, 80 / 3.6, 0.009, "p"}; };
  EXPECT_EQ(identifiable_params({pt(210.0), pt(210.1), pt(210.2)}).size(), 1u);
}

// Points that have RRC rise with pressure contradict the model's law (loss grows with deflection) and every measured
// set: the deflection exponent is held at its bound 0 and the contradiction stays in the residuals, as a negative
// frequency slope does. Before session 13 two such points wrote a tyre with a deflection exponent of -2.9.
TEST(TyreFit, RrcRisingWithPressureHoldsTheDeflectionExponentAtZero) {
  const TyreFit f = fit_two_points({210e3, 4000.0, 80 / 3.6, 0.008, "a"}, {250e3, 4000.0, 80 / 3.6, 0.012, "b"});
  bool held = false;
  for (const auto& e : f.params) {
    if (e.param != HysteresisParam::DeflectionExponent) continue;
    held = e.at_bound;
    EXPECT_EQ(e.value, 0.0);
  }
  EXPECT_TRUE(held);
  EXPECT_EQ(f.tyre.hysteresis.deflection_exponent, 0.0);
  // With no pressure dependence left the two points get one RRC: the residuals carry the +-20 % the data disagree.
  EXPECT_NEAR(f.residuals[0].model_rrc, f.residuals[1].model_rrc, 1e-12);
  TyreState bad = hysteresis_tyre();
  bad.hysteresis.deflection_exponent = -0.5;
  EXPECT_THROW(check_hysteresis_constants(bad.hysteresis), ModelDomainError);
}

// The same point given twice is fitted exactly: residuals of 0 are no estimate of the scatter, and the interval
// falls back to the assumed uncertainty instead of a zero width (before session 13: [x, x], "0.00 % from the
// residuals").
TEST(TyreFit, RepeatedIdenticalPointsDoNotClaimAZeroWidthInterval) {
  const TyreFit f = fit_two_points({210e3, 4000.0, 80 / 3.6, 0.008, "a"}, {210e3, 4000.0, 80 / 3.6, 0.008, "b"});
  EXPECT_EQ(f.degrees_of_freedom, 1);
  EXPECT_FALSE(f.sigma_from_residuals);
  EXPECT_EQ(f.sigma_relative, FitRequest{}.assumed_relative_uncertainty);
  EXPECT_EQ(sigma_source(f), "assumed: the residuals are all 0");
  ASSERT_EQ(f.params.size(), 1u);
  EXPECT_LT(f.params[0].low95, 0.99 * f.params[0].value);
}

// --- measured data: the nine J2452 sets, each held out ---

TEST(J2452, DrumToFlatFactorIsTheStatedRelation) {
  EXPECT_NEAR(drum_to_flat_factor(0.85, 0.3), std::sqrt(0.85 / 1.15), 1e-15);
  EXPECT_LT(drum_to_flat_factor(0.85, 0.3), 1.0);                  // a drum reads high
  EXPECT_NEAR(drum_to_flat_factor(1e9, 0.3), 1.0, 1e-9);           // an infinite drum is a flat road
  const auto sets = load_j2452_csv(kJ2452Csv);
  ASSERT_EQ(sets.size(), 9u);
  // P205/60R15 HI at 210 kPa, 4000 N, 80 km/h, from the CSV's coefficients by hand.
  const double f = std::pow(210.0, -0.4243) * std::pow(4000.0, 0.9568) * (0.159 + 3.44e-4 * 80 + 1.25e-6 * 6400);
  EXPECT_NEAR(j2452_flat_rrc(sets[0], 2.1e5, 4000.0, 80 / 3.6, 0.85), f * std::sqrt(0.85 / 1.154) / 4000.0, 1e-12);
}

TEST(J2452, OneLabelPointPredictsHeldOutTyresBetterThanEveryBaseline) {
  const auto& ev = evaluation();
  ASSERT_EQ(ev.tyres.size(), 9u);
  std::vector<double> one, shape, thesis, constant;
  for (const auto& e : ev.tyres) {
    one.push_back(e.one_point_rms);
    shape.push_back(e.median_shape_rms);
    thesis.push_back(e.thesis_rms);
    constant.push_back(e.constant_rms);
  }
  EXPECT_LE(median(one), 0.025);  // the target, leave-one-tyre-out
  EXPECT_LT(median(one), median(shape));
  EXPECT_LT(median(one), 0.25 * median(thesis));
  EXPECT_LT(median(one), 0.25 * median(constant));
  // The baselines on this grid: thesis scaled 14-20 %, constant 19 %, as it measured them.
  EXPECT_GT(median(thesis), 0.10);
  EXPECT_LT(median(thesis), 0.20);
  EXPECT_NEAR(median(constant), 0.19, 0.02);
  // Eight of nine within 5 %; the ninth (P225/60R16 HI: pressure exponent -0.59, speed rise 20 %) is unlike
  // every other tyre and no one-point method here reaches 5 % on it.
  EXPECT_EQ(std::count_if(one.begin(), one.end(), [](double e) { return e <= 0.05; }), 8);
}

TEST(J2452, AThirdPointAtLowSpeedAndAnotherPressureMeetsBothTargets) {
  // What one point cannot tell (the bound below), a point at 15 km/h and one at another pressure do: the held-out
  // tyre's own speed and pressure dependence. The targets, median <= 2.5 % and worst <= 5 %, on the
  // points a user would measure, with the shared constants still fitted without the tyre.
  const auto& ev = evaluation();
  int judged = 0;
  for (std::size_t k = 0; k < ev.plans.size(); ++k) {
    if (ev.plans[k].name != "+15 km/h, +180 kPa" && ev.plans[k].name != "+15 km/h, +300 kPa") continue;
    ++judged;
    ASSERT_EQ(ev.plans[k].extra.size(), 2u);
    const std::vector<double> rms = plan_rms_column(ev, k);
    EXPECT_LE(median(rms), 0.025) << ev.plans[k].name;
    EXPECT_LE(*std::max_element(rms.begin(), rms.end()), 0.05) << ev.plans[k].name;
  }
  EXPECT_EQ(judged, 2);
}

// --- eight measured tyres the model never saw ---

// The shared constants keep the single fit's signs: a set with a small speed term (c = 1e-5 on P205/60R15 LO) drove
// the others' shared speed loss to -2.5e-6 and the evaluation ended in a domain error naming no set (session 24).
TEST(J2452, SharedConstantsHoldANegativeSpeedLossAtZero) {
  std::vector<J2452Set> sets = load_j2452_csv(kJ2452Csv);
  for (auto& s : sets)
    if (s.name == "P205/60R15 LO") s.c = 1e-5;
  J2452Evaluation ev;
  ASSERT_NO_THROW(ev = evaluate_j2452(sets, kJ2452DrumRadius_m));
  EXPECT_GE(ev.shared_all.speed_loss_rrc_per_hz2, 0.0);
  for (const auto& t : ev.tyres) {
    EXPECT_GE(t.shared.speed_loss_rrc_per_hz2, 0.0) << t.name;
    EXPECT_GE(t.shared.frequency_slope_per_hz, 0.0) << t.name;
    EXPECT_GE(t.shared.deflection_exponent, 0.0) << t.name;
  }
  // The shipped sets need no bound: their constants are as fitted before (README's table).
  EXPECT_GT(evaluation().shared_all.speed_loss_rrc_per_hz2, 0.0);
}

// Each tyre once: a set given twice stayed in the training when its twin was held out, and a held-out file that
// repeats the fitting file was judged as "none of the tyres below" (session 24's outside testing).
TEST(CliTyreFit, AJ2452SetGivenTwiceOrJudgedOnItsOwnTrainingIsRefused) {
  const auto dir = temp_dir();
  std::ifstream in(kJ2452Csv);
  std::string header, first, rest, line;
  std::getline(in, header);
  std::getline(in, first);
  while (std::getline(in, line)) rest += line + "\n";
  const auto twice = dir / "twice.csv";
  std::ofstream(twice) << header << "\n" << first << "\n" << rest << first << "\n";
  const CmdResult r = fit("--evaluate-j2452 '" + twice.string() + "'");
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_TRUE(has(r.err, "is also on line 2")) << r.err;
  EXPECT_TRUE(has(r.err, "give each tyre once")) << r.err;
  const CmdResult same = fit("--evaluate-j2452 '" + kJ2452Csv + "' --held-out-j2452 '" + kJ2452Csv + "'");
  EXPECT_EQ(same.exit_code, 2) << same.out;
  EXPECT_TRUE(has(same.err, "a held-out tyre must not be one the constants are fitted on")) << same.err;
}

// A held-out tyre that is also a fitting one is refused by the library itself, not only by the command line (which
// had held the check: session 24's note), naming both sources.
TEST(J2452HeldOut, ATyreAmongTheFittingSetsIsRefusedByTheLibrary) {
  const auto sets = load_j2452_csv(kJ2452Csv);
  try {
    evaluate_j2452_held_out(sets, {load_j2452_csv(kHeldOutCsv).front(), sets[2]}, kJ2452DrumRadius_m, "fit.csv", "held.csv");
    FAIL() << "accepted a fitting tyre as held out";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("held.csv: the set " + sets[2].name + " is also in fit.csv"), std::string::npos) << e.what();
  }
}

TEST(J2452HeldOut, TheFileHoldsEightSetsAndOneFlaggedReading) {
  const auto sets = load_j2452_csv(kHeldOutCsv);
  ASSERT_EQ(sets.size(), 8u);
  const auto flagged = std::count_if(sets.begin(), sets.end(), [](const J2452Set& s) { return s.flagged; });
  EXPECT_EQ(flagged, 1);
  // P235/70R16 LO at 210 kPa, 4000 N, 80 km/h from the ADVISOR file's coefficients by hand.
  const auto lo = std::find_if(sets.begin(), sets.end(), [](const J2452Set& s) { return s.name == "P235/70R16 LO"; });
  ASSERT_NE(lo, sets.end());
  const double f = std::pow(210.0, -0.4704) * std::pow(4000.0, 1.0129) * (0.0849 + 1.16e-4 * 80 + 2.64e-6 * 6400);
  EXPECT_NEAR(j2452_flat_rrc(*lo, 2.1e5, 4000.0, 80 / 3.6, 0.85), f * std::sqrt(0.85 / 1.205) / 4000.0, 1e-12);
  for (const auto& s : load_j2452_csv(kJ2452Csv)) EXPECT_FALSE(s.flagged) << s.name;  // no column: none flagged
}

TEST(J2452, CsvCoefficientsAreHeldToTheRangesOfTheCommandLineSet) {
  // The same ranges as --j2452: a file's set that the option would refuse is refused, naming line and column.
  const auto dir = temp_dir();
  const std::string head = "size,rr_class,alpha,beta,a,b,c,wh_radius_m\n";
  const struct {
    std::string row, column;
  } cases[] = {{"P205/60R15,LO,0.7,1.0,0.068,2.3E-04,1.2E-06,0.304", "alpha"},
               {"P205/60R15,LO,-0.48,2.5,0.068,2.3E-04,1.2E-06,0.304", "beta"},
               {"P205/60R15,LO,-0.48,1.0,0,2.3E-04,1.2E-06,0.304", "a"},
               {"P205/60R15,LO,-0.48,1.0,0.068,-2.3E-04,1.2E-06,0.304", "b"},
               {"P205/60R15,LO,-0.48,1.0,0.068,2.3E-04,-1.2E-06,0.304", "c"},
               {"P235/75R15,HI,-0.26,0.83,0.2,0.250-04,4.18-06,0.352", "b"}};  // the ADVISOR file's typo as written
  for (const auto& c : cases) {
    const auto path = (dir / "sets.csv").string();
    std::ofstream(path) << head << c.row << "\n";
    try {
      load_j2452_csv(path);
      ADD_FAILURE() << c.row;
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_TRUE(has(what, "line 2") && has(what, "'" + c.column + "'")) << what;
    }
  }
}

TEST(J2452HeldOut, OnePointPredictsTyresItNeverSawAsWellAsItsOwn) {
  const auto& ev = held_out_evaluation();
  ASSERT_EQ(ev.tyres.size(), 8u);
  std::vector<double> one, thesis, constant;
  for (const auto& e : ev.tyres) {
    one.push_back(e.one_point_rms);
    thesis.push_back(e.thesis_rms);
    constant.push_back(e.constant_rms);
    EXPECT_LT(e.full_fit_rms, 0.01) << e.name;  // the model's form holds each new surface too
  }
  EXPECT_LE(median(one), 0.025);  // the median target, on tyres no constant was fitted to
  EXPECT_LT(median(one), 0.25 * median(thesis));
  EXPECT_LT(median(one), 0.25 * median(constant));
}

TEST(J2452HeldOut, ThreePointsMeetBothTargetsOnTyresItNeverSaw) {
  for (const char* plan : {"+15 km/h, +180 kPa", "+15 km/h, +300 kPa"}) {
    const auto rms = plan_rms(held_out_evaluation(), plan);
    ASSERT_EQ(rms.size(), 8u);
    EXPECT_LE(median(rms), 0.025) << plan;
    EXPECT_LE(*std::max_element(rms.begin(), rms.end()), 0.05) << plan;
  }
}

TEST(J2452HeldOut, JudgedWithTheShippedSharedConstants) {
  const HysteresisConstants shipped;
  for (const auto& e : held_out_evaluation().tyres) {
    for (auto p : {HysteresisParam::FrequencySlope, HysteresisParam::DeflectionExponent, HysteresisParam::LoadExponent,
                   HysteresisParam::SpeedLoss, HysteresisParam::SpeedLossLoadExponent}) {
      const double want = hysteresis_param_value(shipped, p);
      EXPECT_NEAR(hysteresis_param_value(e.shared, p), want, 2e-3 * std::abs(want) + 1e-9) << e.name;
    }
  }
}

TEST(J2452, SmallestEnclosingBallOfKnownPointSets) {
  Eigen::MatrixXd line(3, 1);
  line << 0.0, 2.0, 0.5;  // on a line: the midpoint of the extremes, whatever lies between
  const EnclosingBall a = smallest_enclosing_ball(line);
  EXPECT_NEAR(a.centre[0], 1.0, 1e-6);
  EXPECT_NEAR(a.radius, 1.0, 1e-6);
  Eigen::MatrixXd triangle(3, 2);  // equilateral, side 2 (RMS over 2 columns: divide by sqrt 2)
  triangle << 0.0, 0.0, 2.0, 0.0, 1.0, std::sqrt(3.0);
  const EnclosingBall b = smallest_enclosing_ball(triangle);
  EXPECT_NEAR(b.radius, 2.0 / std::sqrt(3.0) / std::sqrt(2.0), 1e-6);
  EXPECT_NEAR(b.centre[1], 1.0 / std::sqrt(3.0), 1e-5);
}

// Each set's log-RRC over the grid relative to its own value at the one point (210 kPa, 4000 N, 80 km/h), computed
// here from the J2452 law as sampled, not through the evaluation's own code.
namespace {
std::vector<std::vector<double>> log_shapes_of(const std::vector<J2452Set>& sets) {
  const OperatingGrid grid = j2452_grid();
  std::vector<std::vector<double>> shapes;
  for (const auto& s : sets) {
    const double ref = j2452_flat_rrc(s, 2.1e5, 4000.0, 80 / 3.6, kJ2452DrumRadius_m);
    std::vector<double> x;
    for (const auto& pt : sample_j2452(s, grid, kJ2452DrumRadius_m, s.name)) x.push_back(std::log(pt.rrc / ref));
    shapes.push_back(x);
  }
  return shapes;
}
}  // namespace

TEST(J2452, CommonShapeBoundLiesBetweenHalfTheWidestPairAndTheBestShapeFound) {
  // The bound is a lower bound for any model giving every tyre one shape: it must lie between half the largest
  // pairwise distance of two tyres' shapes and the worst error of the best shape found.
  const auto sets = load_j2452_csv(kJ2452Csv);
  const auto& b = evaluation().common_shape;
  ASSERT_EQ(b.rms.size(), sets.size());
  const std::vector<std::vector<double>> shapes = log_shapes_of(sets);
  double half_widest = 0.0;
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      double d2 = 0.0;
      for (std::size_t g = 0; g < shapes[i].size(); ++g) d2 += std::pow(shapes[i][g] - shapes[j][g], 2);
      half_widest = std::max(half_widest, 0.5 * std::sqrt(d2 / shapes[i].size()));
    }
  }
  EXPECT_GE(b.worst_log_rms, half_widest - 1e-12);
  const double best_found = *std::max_element(b.rms.begin(), b.rms.end());
  EXPECT_LE(b.worst_log_rms, best_found * 1.05);
  // A constant RRC is one common shape, so it cannot beat the bound.
  double worst_constant = 0.0;
  for (const auto& e : evaluation().tyres) worst_constant = std::max(worst_constant, e.constant_rms);
  EXPECT_GT(worst_constant, b.worst_log_rms);
}

TEST(J2452, NearestMixOfKnownShapes) {
  Eigen::MatrixXd shapes(2, 4);
  shapes << 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0;
  Eigen::VectorXd inside(4);
  inside << 3.5, 3.5, 3.0, 3.0;  // half of each, 3 higher: a mix at another level
  const NearestMix a = nearest_mix(shapes, inside);
  EXPECT_NEAR(a.log_rms, 0.0, 1e-7);
  EXPECT_NEAR(a.rms, 0.0, 1e-7);
  EXPECT_NEAR(a.weights[0], 0.5, 1e-6);
  Eigen::VectorXd outside(4);
  outside << 0.0, 0.0, 1.0, 0.0;
  // Centred, the mix w a + (1 - w) b misses it by (w, 1 - w, -1, 0): least at w = 1/2, sqrt(1.5 / 4).
  const NearestMix b = nearest_mix(shapes, outside);
  EXPECT_NEAR(b.log_rms, std::sqrt(1.5 / 4.0), 1e-7);
  EXPECT_NEAR(b.weights[0], 0.5, 1e-6);
  EXPECT_NEAR(b.weights.sum(), 1.0, 1e-12);
  // On the simplex: the point of it nearest p minimises |w|^2 - 2 p'w; a p outside it lands on its edge.
  Eigen::VectorXd p(3);
  p << 1.0, 0.5, -1.0;
  const Eigen::VectorXd w = minimise_on_simplex(Eigen::MatrixXd::Identity(3, 3), -2.0 * p);
  EXPECT_NEAR(w[0], 0.75, 1e-7);
  EXPECT_NEAR(w[1], 0.25, 1e-7);
  EXPECT_NEAR(w[2], 0.0, 1e-12);
}

// Every tyre seen is itself a mix of the shapes seen (all weight on it), so the bound can be no worse than the
// nearest single tyre at its best level; and the measured sets make it large for one tyre: no prediction that
// stays among the other eight tyres' shapes comes within 5 % of P225/60R16 HI, which is why issue 12's worst-tyre
// target is out of reach from one point on these data.
TEST(J2452, SeenShapesBoundIsNoWorseThanTheNearestTyreSeen) {
  const auto sets = load_j2452_csv(kJ2452Csv);
  const std::vector<std::vector<double>> shapes = log_shapes_of(sets);
  const auto& tyres = evaluation().tyres;
  ASSERT_EQ(tyres.size(), sets.size());
  for (std::size_t i = 0; i < sets.size(); ++i) {
    double nearest = 1e9;
    for (std::size_t j = 0; j < sets.size(); ++j) {
      if (j == i) continue;
      double mean = 0.0, sq = 0.0;
      for (std::size_t g = 0; g < shapes[i].size(); ++g) mean += (shapes[j][g] - shapes[i][g]) / shapes[i].size();
      for (std::size_t g = 0; g < shapes[i].size(); ++g) sq += std::pow(shapes[j][g] - shapes[i][g] - mean, 2);
      nearest = std::min(nearest, std::sqrt(sq / shapes[i].size()));
    }
    EXPECT_LE(tyres[i].seen_shapes.log_rms, nearest + 1e-9) << tyres[i].name;
    EXPECT_GE(tyres[i].seen_shapes.log_rms, 0.0);
    EXPECT_NEAR(tyres[i].seen_shapes.weights.sum(), 1.0, 1e-9);
    if (tyres[i].name == "P225/60R16 HI") EXPECT_GT(tyres[i].seen_shapes.rms, 0.05);
  }
}

TEST(J2452, FullFitFollowsEachSurfaceAndItsMeasuredExponents) {
  for (const auto& e : evaluation().tyres) {
    EXPECT_LT(e.full_fit_rms, 0.01) << e.name;
    EXPECT_NEAR(e.full_fit.pressure_exponent, e.measured.pressure_exponent, 0.02) << e.name;
    EXPECT_NEAR(e.full_fit.load_exponent, e.measured.load_exponent, 0.02) << e.name;
    EXPECT_NEAR(e.full_fit.speed_rise, e.measured.speed_rise, 0.02) << e.name;
  }
}

TEST(J2452, OnePointModelHasTheMeasuredScalingsTheThesisMisses) {
  // The issue: measured pressure exponent about -0.4, load about 0.95, speed rise 30-54 %; the thesis model
  // grows as Z^0.44 and rises 18 %.
  for (const auto& e : evaluation().tyres) {
    EXPECT_NEAR(e.one_point.pressure_exponent, -0.43, 0.05) << e.name;
    EXPECT_NEAR(e.one_point.load_exponent, 0.95, 0.05) << e.name;
    EXPECT_GT(e.one_point.speed_rise, 0.30) << e.name;
    EXPECT_LT(e.one_point.speed_rise, 0.54) << e.name;
    EXPECT_LT(e.thesis.load_exponent, 0.6) << e.name;
    EXPECT_LT(e.thesis.speed_rise, 0.25) << e.name;
  }
}

TEST(J2452, ShippedSharedConstantsAreTheFitToAllNineSets) {
  const HysteresisConstants shipped;
  const HysteresisConstants& fitted = evaluation().shared_all;
  for (auto p : {HysteresisParam::FrequencySlope, HysteresisParam::DeflectionExponent, HysteresisParam::LoadExponent,
                 HysteresisParam::SpeedLoss, HysteresisParam::SpeedLossLoadExponent}) {
    const double want = hysteresis_param_value(fitted, p);
    EXPECT_NEAR(hysteresis_param_value(shipped, p), want, 2e-3 * std::abs(want) + 1e-9) << hysteresis_param_key(p);
  }
}

// --- what a user has, turned into a fit (shared by the CLI and Python) ---

TEST(TyreFitPlan, LabelAloneIsOneIsoPointWithTheBandAsItsUncertainty) {
  TyreFitInputs in;
  in.size = parse_tyre_size("205/55 R16 91V", "size");
  in.label_class = "B";
  const TyreFitPlan plan = plan_tyre_fit(in);
  ASSERT_EQ(plan.request.points.size(), 1u);
  // Regulation (EU) 2020/740, class B: 6.6-7.7 kg/t, declared to 0.1, so 6.55-7.75 on ISO 28580's 2.0 m drum; the
  // point is the band's geometric middle brought to a flat road, sqrt(1 / (1 + r)) with r = 8 in + 0.55 x 205 mm
  // (Clark's relation, as SAE J2452 and ISO 28580 take it); load index 91 is 615 kg.
  const RrcPoint& p = plan.request.points[0];
  const double r_m = 8 * 0.0254 + 0.55 * 0.205;
  EXPECT_NEAR(p.rrc, std::sqrt(6.55e-3 * 7.75e-3) * std::sqrt(1.0 / (1.0 + r_m)), 1e-12);
  EXPECT_NEAR(p.pressure_pa, 210e3, 1e-9);
  EXPECT_NEAR(p.load_n, 0.8 * 615.0 * 9.80665, 1e-9);
  EXPECT_NEAR(p.speed_mps, 80.0 / 3.6, 1e-12);
  // 1.96 of it spans 95 % of the band's log width: a uniform band's 95 % interval, inside the band.
  EXPECT_NEAR(1.96 * plan.request.assumed_relative_uncertainty, 0.95 * 0.5 * std::log(7.75 / 6.55), 1e-12);
  // With a measured point the label only checks the fit: the point is the data.
  in.points.push_back({210e3, 4500.0, 80.0 / 3.6, 0.0085, "point"});
  const TyreFitPlan with_point = plan_tyre_fit(in);
  ASSERT_EQ(with_point.request.points.size(), 1u);
  EXPECT_EQ(with_point.request.points[0].rrc, 0.0085);
  EXPECT_TRUE(with_point.band.has_value());
  EXPECT_NEAR(with_point.request.assumed_relative_uncertainty, FitRequest{}.assumed_relative_uncertainty, 0.0);
}

TEST(TyreFitPlan, ItsNumbersAreCheckedAndNamed) {
  TyreFitInputs in;
  in.size = parse_tyre_size("205/55 R16 91V", "size");
  in.points.push_back({210e3, 4500.0, 80.0 / 3.6, 0.0085, "point"});
  auto refused = [&](TyreFitInputs bad, const std::string& name) {
    try {
      plan_tyre_fit(bad);
      ADD_FAILURE() << name;
    } catch (const InputError& e) {
      EXPECT_TRUE(has(e.what(), name)) << e.what();
    }
  };
  TyreFitInputs drum = in;
  drum.j2452 = parse_j2452_text("-0.4815,1.0051,0.0682,2.32E-04,1.20E-06", "j2452");
  drum.drum_radius_m = 0.05;
  drum.drum_where = "the drum";
  refused(drum, "the drum");
  TyreFitInputs scatter = in;
  scatter.uncertainty_pct = 0.0;
  scatter.uncertainty_where = "the scatter";
  refused(scatter, "the scatter");
  TyreFitInputs label = in;
  label.label_class = "F";
  label.label_where = "the label";
  refused(label, "the label");
  EXPECT_THROW(fitted_file_pressure_pa(in.size, 0.0, "pressure"), InputError);  // 0 bar
  EXPECT_NEAR(fitted_file_pressure_pa(in.size, std::nullopt, "pressure"), 210e3, 0.0);
  EXPECT_NEAR(fitted_file_pressure_pa(parse_tyre_size("215/45 R17 91W XL", "size"), std::nullopt, "pressure"), 250e3, 0.0);
}

TEST(CliTyreFit, JsonLinesCarryTheFitItsConstantsAndEveryResidual) {
  const auto out = temp_dir() / "t.yaml";
  const CmdResult r = fit("--size '205/55 R16 91V' --point 210,4500,80,0.0085 --point 250,4500,80,0.0079 "
                          "--point 210,4500,40,0.0080 --label B --json --output '" + out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto ls = lines(r.out);
  ASSERT_EQ(ls.size(), 1u + 6u + 3u) << r.out;  // the fit, six constants, three points
  EXPECT_TRUE(has(ls[0], "\"kind\": \"fit\"") && has(ls[0], "\"label_class\": \"B\"")) << ls[0];
  EXPECT_EQ(json_number(ls[0], "points"), 3);
  int free = 0;
  for (std::size_t i = 1; i <= 6; ++i) {
    EXPECT_TRUE(has(ls[i], "\"kind\": \"param\"")) << ls[i];
    free += has(ls[i], "\"free\": true");
  }
  EXPECT_EQ(free, 3);  // the level, the deflection exponent (2 pressures), the frequency slope (2 speeds)
  for (std::size_t i = 7; i < ls.size(); ++i) {
    EXPECT_TRUE(has(ls[i], "\"kind\": \"residual\"")) << ls[i];
    EXPECT_NEAR(json_number(ls[i], "model_rrc") / json_number(ls[i], "rrc") - 1.0, json_number(ls[i], "error_pct") / 100.0, 1e-12);
  }
  EXPECT_TRUE(std::filesystem::exists(out));  // the tyre file is still written
}

// --- label and ISO conditions ---

TEST(TyreLabel, ClassBandsOfRegulation2020_740ForC1) {
  // Annex I Part A: A <= 6.5, B 6.6-7.7, C 7.8-9.0, D 9.1-10.5, E >= 10.6 kg/t (declared to 0.1 kg/t). A-C are
  // the bands of Regulation (EC) 1222/2009 (legislation.gov.uk/eur/2009/1222/annex/I), whose E (9.1-10.5) is D now.
  EXPECT_NEAR(eu_label_band_c1("A", "x").rrc_max, 6.55e-3, 1e-12);
  EXPECT_NEAR(eu_label_band_c1("b", "x").rrc_min, 6.55e-3, 1e-12);
  EXPECT_NEAR(eu_label_band_c1("C", "x").rrc_max, 9.05e-3, 1e-12);
  EXPECT_NEAR(eu_label_band_c1("D", "x").rrc_min, 9.05e-3, 1e-12);
  EXPECT_NEAR(eu_label_band_c1("D", "x").rrc_max, 10.55e-3, 1e-12);
  EXPECT_TRUE(eu_label_band_c1("E", "x").open_above);
  // The open classes are closed with their neighbour's declared width: A with B's (7.7 - 6.6), E with D's (10.5 - 9.1).
  EXPECT_NEAR(eu_label_band_c1("A", "x").rrc_min, 6.55e-3 - (7.7e-3 - 6.6e-3), 1e-12);
  EXPECT_NEAR(eu_label_band_c1("E", "x").rrc_max, 10.55e-3 + (10.5e-3 - 9.1e-3), 1e-12);
  EXPECT_THROW(eu_label_band_c1("F", "--label F"), InputError);
  EXPECT_THROW(eu_label_band_c1("AB", "--label AB"), InputError);
  // Each edge is in one class, the one above it (a declared 6.55 rounds to 6.6, class B), also when computed onto it.
  for (const auto& [edge, below, above] : {std::tuple{6.55e-3, "A", "B"}, {7.75e-3, "B", "C"}, {9.05e-3, "C", "D"},
                                           {10.55e-3, "D", "E"}}) {
    for (double rrc : {edge, std::nextafter(edge, 0.0)}) {
      EXPECT_FALSE(eu_label_band_c1(below, "x").contains(rrc)) << rrc;
      EXPECT_TRUE(eu_label_band_c1(above, "x").contains(rrc)) << rrc;
    }
    EXPECT_TRUE(eu_label_band_c1(below, "x").contains(edge - 0.01e-3)) << edge;
  }
  EXPECT_TRUE(eu_label_band_c1("A", "x").contains(4.0e-3));  // open below
  EXPECT_TRUE(eu_label_band_c1("E", "x").contains(13.0e-3));  // open above
}

TEST(TyreLabel, Iso28580ConditionsFollowTheLoadIndexAndLoadVersion) {
  const RrcPoint std_load = iso28580_point(parse_tyre_size("205/55 R16 91V", "s"), 0.008, "w");
  EXPECT_NEAR(std_load.load_n, 0.8 * 615 * 9.80665, 1e-9);
  EXPECT_NEAR(std_load.pressure_pa, 210e3, 1e-9);
  EXPECT_NEAR(std_load.speed_mps, 80 / 3.6, 1e-12);
  EXPECT_NEAR(iso28580_point(parse_tyre_size("205/55 R16 94V XL", "s"), 0.008, "w").pressure_pa, 250e3, 1e-9);
  EXPECT_THROW(iso28580_point(parse_tyre_size("205/55 R16", "s"), 0.008, "w"), InputError);
}

// Van and truck sizes (EU classes C2 and C3) are marked by a dual load index, a "C" after the rim or a truck rim, not
// only by "LT": their ISO 28580 point is not a passenger tyre's, so a label or test-report point is refused as for LT.
// A truck tyre had been placed at 210 kPa and 24.7 kN with the C1 bands (session 24's outside testing).
TEST(TyreLabel, VanAndTruckSizesAreNotGivenThePassengerPoint) {
  for (const char* size : {"275/70 R22.5 148/145M", "195/75 R16 107/105R", "215/65 R16C 109/107T", "245/70 R19.5 136M",
                           "LT245/75 R16 120/116S"}) {
    const TyreSize s = parse_tyre_size(size, "s");
    EXPECT_TRUE(s.commercial) << size;
    try {
      iso28580_point(s, 0.006, "--label B");
      ADD_FAILURE() << size << " given a passenger point";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("EU class C2 or C3"), std::string::npos) << e.what();
    }
  }
  // "R16C" is the van marker, not a second speed symbol; its own speed symbol and load index are still read.
  const TyreSize van = parse_tyre_size("215/65 R16C 109/107T", "s");
  EXPECT_EQ(van.load_index, 109);
  EXPECT_EQ(van.speed_symbol, "T");
  for (const char* size : {"205/55 R16 91V", "205/55 R16 94V XL", "175/65 R14 82T"})
    EXPECT_FALSE(parse_tyre_size(size, "s").commercial) << size;
}

// --- the command ---

TEST(CliTyreFit, OnePointFileIsANormalTyreFileThatReproducesThePoint) {
  const auto out = temp_dir() / "fit_one.yaml";
  const CmdResult r = fit("--size '205/55 R16 91V' --point 210,4500,80,0.0085 --output '" + out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(has(r.out, "rrc_ref"));
  const TyreSpec spec = load_tyre_file(out.string());
  EXPECT_EQ(spec.state.model, TyreModelKind::Hysteresis);
  const CmdResult t = rollsim::test::run_rollsim("tyre '" + out.string() +
                                                 "' --pressure-bar 2.1 --load-n 4500 --speed-kmh 80 --json");
  ASSERT_EQ(t.exit_code, 0) << t.err;
  EXPECT_NEAR(json_number(t.out, "rrc"), 0.0085, 0.0085 * 1e-7);
  EXPECT_TRUE(has(t.out, "\"model\": \"hysteresis\""));
  // Its table names its own three parts, not the thesis' damping mechanisms (before session 14: Coulomb, viscous,
  // drag over a fitted tyre's static loss, frequency rise and speed-squared loss).
  const CmdResult table = rollsim::test::run_rollsim("tyre '" + out.string() + "'");
  EXPECT_TRUE(has(table.out, "static  freq. rise  V^2 loss")) << table.out;
  EXPECT_FALSE(has(table.out, "Coulomb")) << table.out;
  // The thesis' mechanisms do not describe this model: --explain says so instead of printing them.
  const CmdResult x = rollsim::test::run_rollsim("tyre '" + out.string() + "' --explain");
  EXPECT_EQ(x.exit_code, 2);
  EXPECT_TRUE(has(x.err, "hysteresis model")) << x.err;
}

TEST(CliTyreFit, J2452SetAndLabelGiveFittedConstantsWithIntervals) {
  const auto out = temp_dir() / "fit_j2452.yaml";
  const CmdResult r = fit("--size 'P205/60R15 91H' --j2452 -0.4815,1.0051,0.0682,2.32E-04,1.20E-06 --label B "
                          "--output '" + out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(has(r.out, "150 point(s), 6 constant(s) free"));
  EXPECT_TRUE(has(r.out, "EU label class B"));
  EXPECT_TRUE(has(r.out, "from the residuals"));
  const TyreSpec spec = load_tyre_file(out.string());
  // The measured exponents of this set (P205/60R15 LO): the fit's load scaling at fixed pressure.
  const auto a = TyreAtLoad::prepare(spec.state, 3000.0), b = TyreAtLoad::prepare(spec.state, 6000.0);
  EXPECT_NEAR(std::log(b.rr_force_n(80 / 3.6) / a.rr_force_n(80 / 3.6)) / std::log(2.0), 1.0051, 0.02);
}

TEST(CliTyreFit, MeasuredCsvFitsAndTooFewPointsIsNamed) {
  const auto csv = temp_dir() / "measured.csv";
  {
    std::ofstream f(csv);
    f << "pressure_kpa,load_n,speed_kmh,rrc\n210,4000,50,0.0090\n210,4000,80,0.0095\n210,4000,110,0.0102\n";
  }
  const auto out = temp_dir() / "fit_csv.yaml";
  const CmdResult r = fit("--size '205/55 R16 91V' --measured '" + csv.string() + "' --output '" + out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(has(r.out, "3 point(s), 3 constant(s) free"));  // level, frequency slope, speed loss
  const CmdResult few = fit("--size '205/55 R16 91V' --measured '" + csv.string() +
                            "' --free rrc_ref,load_exponent --output '" + out.string() + "'");
  EXPECT_EQ(few.exit_code, 2);
  EXPECT_TRUE(has(few.err, "too few points")) << few.err;
  EXPECT_TRUE(has(few.err, "2 or more loads")) << few.err;
  EXPECT_FALSE(has(r.err, "not read")) << r.err;
  // A column the fit does not read is said (a temperature_c changed nothing without a word: session 24).
  const auto extra = temp_dir() / "measured_extra.csv";
  std::ofstream(extra) << "pressure_kpa,load_n,speed_kmh,rrc,temperature_c\n210,4000,50,0.0090,25\n210,4000,80,0.0095,25\n";
  const CmdResult t = fit("--size '205/55 R16 91V' --measured '" + extra.string() + "' --output '" + out.string() + "'");
  ASSERT_EQ(t.exit_code, 0) << t.err;
  EXPECT_TRUE(has(t.err, "measured_extra.csv: column(s) 'temperature_c' not read")) << t.err;
}

TEST(CliTyreFit, BadInputGetsOneNamedErrorAndNoFile) {
  const auto out = temp_dir() / "never.yaml";
  const std::string o = " --output '" + out.string() + "'";
  struct Case {
    std::string args;
    std::vector<std::string> mentions;
  };
  const std::vector<Case> cases = {
      {"--size '205/55 R16 91V' --point 0,4000,80,0.009", {"--point 0,4000,80,0.009", "pressure 0 kPa", "passenger tyre", "[100, 500] kPa"}},
      {"--size '205/55 R16 91V' --point 210,4000,80,0.5", {"--point", "RRC 0.5", "[0.001, 0.05]"}},
      {"--size '205/55 R16 91V' --label F", {"--label F", "A, B, C, D, E"}},
      {"--size '205/55 R16 91V' --point 210,60000,80,0.009", {"--point", "physical range", "rim"}},
      {"--size '205/55 R16 91V' --point 0.009 --free rrc_ref,frequency_slope_per_hz", {"--free", "too few points"}},
      {"--size '205/55 R16 91V'", {"too few points", "no measured point"}},
      {"--size '205/55 R16' --label B", {"--label B", "load index"}},
      {"--size '205/55 R16 91V' --j2452 -0.4,0.9,0.1", {"--j2452", "expected ALPHA,BETA,A,B,C"}},
      {"--size '205/55 R16 91V' --point 210,4000,0,0.009", {"--point", "speed 0 km/h"}},
      {"--size '205/55 R16 91V' --point 0.009 --free rrc_ref,bogus", {"--free", "bogus"}},
      // A light-truck (C2) size has neither the passenger ISO point nor the C1 label bands (before session 14 it
      // got both, and a file at 2.1 bar).
      {"--size 'LT245/75R16 120/116S' --label C", {"--label C", "light-truck", "C2"}},
      {"--size 'LT245/75R16 120/116S' --point 0.008", {"--point 0.008", "light-truck"}},
      {"--size 'LT245/75R16 120/116S' --point 450,9000,80,0.008", {"--pressure-bar", "light-truck"}},
      // Fits no tyre file may hold were written, and `rollsim tyre` then refused them (session 22's outside testing):
      // a deflection exponent of 8.09 (the two points' hysteresis ratio over their stiffness ratio), a level run to
      // 2e-9 chasing a speed rise of 5.7 where (1 + s f) can give at most f(300) / f(80) = 3.75, a load exponent of -5.3.
      {"--size '205/55 R16 91V' --point 210,4500,80,0.012 --point 250,4500,80,0.004", {"tyre fit", "'model.deflection_exponent'", "8.09", "[0, 5]", "nothing written"}},
      {"--size '205/55 R16 91V' --point 210,4500,80,0.008 --point 210,4500,300,0.05", {"tyre fit", "'model.rrc_ref'", "[0.001, 0.05]"}},
      {"--size '205/55 R16 91V' --point 210,3000,80,0.04 --point 210,6000,80,0.002", {"tyre fit", "'model.load_exponent'", "[-5, 5]"}},
      // A passenger tyre's points are held to a passenger tyre file's pressures (50 kPa was fitted, then refused).
      {"--size '205/55 R16 91V' --point 50,4500,80,0.008", {"--point 50,4500,80,0.008", "passenger tyre", "[100, 500] kPa"}},
      // A trailing comma was a field dropped ('0.008,' read as 0.008), a drum radius without a drum set was ignored,
      // and a speed was said as its conversion (999.9999999999999 km/h): session 22's outside testing.
      {"--size '205/55 R16 91V' --point 0.008,", {"--point 0.008,", "expected KPA,LOAD_N,KMH,RRC"}},
      {"--size '205/55 R16 91V' --point 0.008 --drum-radius-m 2", {"--drum-radius-m", "J2452 set only"}},
      {"--size '205/55 R16 91V' --point 210,4500,1000,0.008", {"speed 1000 km/h is not allowed"}},
      {"--size '205/55 R16 91V' --point 210,4500,1e300,0.008", {"speed 1e+300 km/h is not allowed"}},  // was "inf"
      // Three points at two conditions determine two constants, not three.
      {"--size '205/55 R16 91V' --point 210,4500,40,0.0075 --point 250,4500,80,0.0078 --point 210,4500,40,0.0076 "
       "--free rrc_ref,frequency_slope_per_hz,deflection_exponent", {"--free", "2 distinct condition(s)"}},
  };
  for (const auto& c : cases) {
    const CmdResult r = fit(c.args + o);
    EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.err;
    EXPECT_TRUE(r.out.empty()) << c.args << "\n" << r.out;
    EXPECT_EQ(lines(r.err).size(), 1u) << c.args << "\n" << r.err;
    for (const auto& m : c.mentions) EXPECT_TRUE(has(r.err, m)) << c.args << ": should mention '" << m << "'\n" << r.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << c.args;
  }
}

TEST(CliTyreFit, EvaluationTablePrintsEveryTyreAndTheSharedConstants) {
  const CmdResult r = fit("--evaluate-j2452 '" + kJ2452Csv + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const auto& e : evaluation().tyres) EXPECT_TRUE(has(r.out, e.name)) << e.name;
  EXPECT_TRUE(has(r.out, "median"));
  EXPECT_TRUE(has(r.out, "(none: all sets)"));
  for (const auto& plan : evaluation().plans) EXPECT_TRUE(has(r.out, plan.name)) << plan.name;
}

TEST(CliTyreFit, EvaluationAsJsonLinesHoldsEveryTableRow) {
  const CmdResult r = fit("--evaluate-j2452 '" + kJ2452Csv + "' --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto& ev = evaluation();
  const auto ls = lines(r.out);
  // A line per tyre, per plan, the bound, the all-sets constants and each tyre's leave-one-out constants.
  ASSERT_EQ(ls.size(), ev.tyres.size() + ev.plans.size() + 1 + 1 + ev.tyres.size()) << r.out;
  for (std::size_t i = 0; i < ev.tyres.size(); ++i) {
    EXPECT_TRUE(has(ls[i], "\"name\": \"" + ev.tyres[i].name + "\"")) << ls[i];
    EXPECT_NEAR(json_number(ls[i], "one_point_rms_pct"), 100.0 * ev.tyres[i].one_point_rms, 1e-9);
  }
  const std::string& plan = ls[ev.tyres.size() + 7];  // the eighth plan: +15 km/h, +300 kPa
  EXPECT_TRUE(has(plan, "\"measured_besides\": \"+15 km/h, +300 kPa\"")) << plan;
  EXPECT_LE(json_number(plan, "worst_rms_pct"), 5.0);
  EXPECT_TRUE(has(ls[ev.tyres.size() + ev.plans.size()], "common_shape"));
  const CmdResult held = fit("--evaluate-j2452 '" + kJ2452Csv + "' --held-out-j2452 '" + kHeldOutCsv + "' --json");
  ASSERT_EQ(held.exit_code, 0) << held.err;
  EXPECT_EQ(lines(held.out).size(), 8u + ev.plans.size() + 1 + 1);  // one set of shared constants: the nine's
}

TEST(CliTyreFit, HeldOutEvaluationJudgesTheOtherFileAndNeedsTheFirst) {
  const CmdResult r = fit("--evaluate-j2452 '" + kJ2452Csv + "' --held-out-j2452 '" + kHeldOutCsv + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const auto& s : load_j2452_csv(kHeldOutCsv)) EXPECT_TRUE(has(r.out, s.name)) << s.name;
  EXPECT_TRUE(has(r.out, "fitted once on the 9 sets"));
  EXPECT_TRUE(has(r.out, "P235/75R15 HI *"));  // the flagged reading is marked
  const CmdResult alone = fit("--held-out-j2452 '" + kHeldOutCsv + "'");
  EXPECT_NE(alone.exit_code, 0);
  EXPECT_TRUE(has(alone.err, "--held-out-j2452")) << alone.err;
  EXPECT_EQ(lines(alone.err).size(), 1u) << alone.err;
  const auto dir = temp_dir();
  std::ofstream(dir / "bad.csv") << "size,rr_class,alpha,beta,a,b,c,wh_radius_m,value_flagged\n"
                                 << "P205/60R15,LO,-0.48,1.0,0.068,2.3E-04,1.2E-06,0.304,maybe\n";
  const CmdResult bad = fit("--evaluate-j2452 '" + kJ2452Csv + "' --held-out-j2452 '" + (dir / "bad.csv").string() + "'");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_TRUE(has(bad.err, "maybe") && has(bad.err, "bad.csv")) << bad.err;
}

// A set whose coefficients are each in range but multiply to a force no tyre has: a = 1e308 overflowed to inf, and
// the evaluation's NaN shapes indexed out of bounds (double free, exit 134; session 21's outside testing). Now one
// error naming the file, the line and the set, as for --j2452 and for a held-out file.
TEST(CliTyreFit, ASetsSurfaceOutsideAnyTyresIsNamedNotACrash) {
  const auto dir = temp_dir();
  for (const std::string a : {"1e308", "9.0"}) {
    std::ofstream(dir / "huge.csv") << "size,rr_class,alpha,beta,a,b,c,wh_radius_m\n"
                                    << "P205/60R15,LO,-0.48,1.0,0.068,2.3E-04,1.2E-06,0.304\n"
                                    << "P205/60R15,HI,-0.48,1.0," << a << ",2.3E-04,1.2E-06,0.304\n";
    for (const std::string option : {"--evaluate-j2452 '" + (dir / "huge.csv").string() + "'",
                                     "--evaluate-j2452 '" + kJ2452Csv + "' --held-out-j2452 '" + (dir / "huge.csv").string() + "'"}) {
      const CmdResult r = fit(option);
      EXPECT_EQ(r.exit_code, 2) << a << ": " << r.err;
      EXPECT_TRUE(has(r.err, "huge.csv: line 3: the set P205/60R15 HI gives an RRC of")) << r.err;
      EXPECT_EQ(lines(r.err).size(), 1u) << r.err;
    }
  }
  const CmdResult text = fit("--size '205/55 R16 91V' --j2452 -0.4,1,1e308,0,0 --output '" + (dir / "huge_set.yaml").string() + "'");
  EXPECT_EQ(text.exit_code, 2);
  EXPECT_TRUE(has(text.err, "--j2452 -0.4,1,1e308,0,0: the set '-0.4,1,1e308,0,0' gives an RRC of inf")) << text.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "huge_set.yaml"));
}

// tyre fit took --pressure-bar 0.5-6 and wrote files every other command refused (0.6 bar: "must be in [1, 5]").
// Now the tyre file's own check (session 21).
// Repeated measurements of one condition fix its RRC, not another constant: three points at two conditions freed
// three constants, and the deflection exponent got a 95 % interval (0.50-0.60) for a direction the points cannot see
// (the Jacobian's third singular value 9e-10; session 22's outside testing). Two are freed, the rest shared.
TEST(TyreFit, RepeatedConditionsFreeNoMoreConstantsThanTheyTellApart) {
  FitRequest r;
  r.points = {{210e3, 4500.0, 40 / 3.6, 0.0075, "a"}, {250e3, 4500.0, 80 / 3.6, 0.0078, "b"}, {210e3, 4500.0, 40 / 3.6, 0.0076, "c"}};
  const TyreFit f = fit_hysteresis(hysteresis_tyre(), r);
  ASSERT_EQ(f.params.size(), 2u);
  EXPECT_EQ(f.params[0].param, HysteresisParam::RrcRef);
  // Two constants meet both conditions: the second exactly, the repeated one at the RRC m that minimises the relative
  // errors, sum (m / y_i - 1) / y_i = 0, i.e. m = sum(1 / y_i) / sum(1 / y_i^2).
  const double m = (1 / 0.0075 + 1 / 0.0076) / (1 / (0.0075 * 0.0075) + 1 / (0.0076 * 0.0076));
  EXPECT_NEAR(f.residuals[0].relative_error, m / 0.0075 - 1.0, 1e-6);
  EXPECT_NEAR(f.residuals[2].relative_error, m / 0.0076 - 1.0, 1e-6);
  EXPECT_NEAR(f.residuals[1].relative_error, 0.0, 1e-6);
}

// A point loaded past the size's rating is fitted and said, as `rollsim tyre` says it (it was silent: 20 kN on a
// load index 91 tyre, 615 kg = 6031 N; session 22's outside testing).
TEST(CliTyreFit, APointLoadedPastTheRatingIsSaid) {
  const auto out = temp_dir() / "overloaded.yaml";
  const CmdResult r = fit("--size '205/55 R16 91V' --point 210,20000,80,0.008 --output '" + out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(has(r.err, "warning: --point 210,20000,80,0.008: load 20000 N is above the tyre's rated maximum 6031 N")) << r.err;
}

// A light-truck tyre's points may be at a light-truck tyre's pressures (655 kPa was refused: 50-600 kPa for any size).
TEST(CliTyreFit, ALightTruckTyresPointsAreAtItsOwnPressures) {
  const auto out = temp_dir() / "lt_point.yaml";
  const CmdResult r = fit("--size 'LT245/75R16 120/116S' --point 655,12000,80,0.008 --pressure-bar 6.55 --output '" + out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const CmdResult read = rollsim::test::run_rollsim("tyre '" + out.string() + "' --pressure-bar 6.55 --load-n 12000 --speed-kmh 80 --json");
  ASSERT_EQ(read.exit_code, 0) << read.err;
  EXPECT_NEAR(rollsim::test::json_number(read.out, "rrc"), 0.008, 1e-9);
}

TEST(CliTyreFit, TheWrittenPressureIsOneTheTyreFileTakes) {
  const auto out = temp_dir() / "pressure_written.yaml";
  const CmdResult low = fit("--size '205/55 R16 91V' --point 0.0072 --pressure-bar 0.6 --output '" + out.string() + "'");
  EXPECT_EQ(low.exit_code, 2);
  EXPECT_TRUE(has(low.err, "--pressure-bar: 0.6 bar is not allowed for a passenger tyre")) << low.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  const CmdResult ok = fit("--size '205/55 R16 91V' --point 0.0072 --pressure-bar 1.2 --output '" + out.string() + "'");
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  const CmdResult read = rollsim::test::run_rollsim("tyre '" + out.string() + "' --json");
  EXPECT_EQ(read.exit_code, 0) << read.err;
}

// Student's t at the residuals' degrees of freedom (published two-sided 95 % quantiles), towards the normal's 1.96.
TEST(TyreFit, IntervalsFromFewResidualsUseStudentsT) {
  for (const auto& [dof, t] : {std::pair{1, 12.7062}, {2, 4.3027}, {3, 3.1824}, {4, 2.7764}, {5, 2.5706}, {10, 2.2281},
                               {30, 2.0423}, {144, 1.9766}}) {
    EXPECT_NEAR(student_t_95(dof), t, 1e-4) << dof;
  }
  EXPECT_NEAR(student_t_95(100000), 1.95997, 1e-4);
  // A fit with one degree of freedom says so, and its interval is 12.71 standard errors each side, not 1.96.
  const auto out = temp_dir() / "few_dof.yaml";
  const CmdResult r = fit("--size '205/55 R16 91V' --point 210,4500,80,0.0085 --point 210,4500,50,0.0081 "
                          "--point 210,4500,110,0.0093 --point 210,4500,30,0.0078 --output '" + out.string() + "' --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(has(r.out, "\"degrees_of_freedom\": 1,")) << r.out;
  for (const auto& l : lines(r.out)) {
    if (!has(l, "\"key\": \"rrc_ref\"")) continue;
    const double value = rollsim::test::json_number(l, "value"), low = rollsim::test::json_number(l, "low95"),
                 high = rollsim::test::json_number(l, "high95"), se = rollsim::test::json_number(l, "std_error");
    // rrc_ref's interval is symmetric in its logarithm: log(high / low) / 2 = t x se / value.
    EXPECT_NEAR(std::log(high / low) / 2.0, student_t_95(1) * se / value, 1e-6 * student_t_95(1)) << l;
  }
}

// The label check: A and E are open-ended classes (5.0 kg/t is an A, 13.0 an E), and a value computed onto an edge is
// on it (6.549999999999998 against 6.550000000000001 read OUTSIDE); session 21's outside testing. An edge is the class
// above's (6.55 is a B, not also an A: session 24's).
TEST(CliTyreFit, TheLabelCheckKeepsOpenEndsOpenAndEdgesOnTheEdge) {
  const auto out = temp_dir() / "label_check.yaml";
  for (const auto& [point, label, inside] : {std::tuple<std::string, std::string, bool>{"0.0050", "A", true}, {"0.0130", "E", true},
                                             {"0.00655", "B", true}, {"0.00655", "A", false}, {"0.00775", "C", true}}) {
    const CmdResult r = fit("--size '205/55 R16 91V' --point " + point + " --label " + label + " --output '" + out.string() + "'");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(has(r.out, "inside the band"), inside) << point << " " << label << ": " << r.out;
  }
  const CmdResult outside = fit("--size '205/55 R16 91V' --point 0.0050 --label B --output '" + out.string() + "' --json");
  EXPECT_TRUE(has(outside.out, "\"inside_label_band\": false")) << outside.out;
  EXPECT_TRUE(has(outside.out, "\"label_rrc_min_kg_per_t\": 6.55,")) << outside.out;
  EXPECT_TRUE(has(outside.out, "\"label_open_below\": false, \"label_open_above\": false")) << outside.out;
  const CmdResult e = fit("--size '205/55 R16 91V' --point 0.0130 --label E --output '" + out.string() + "' --json");
  EXPECT_TRUE(has(e.out, "\"label_open_below\": false, \"label_open_above\": true")) << e.out;
}

// A measured pressure of 1e308 kPa overflowed to Pa and was named "pressure inf kPa" (session 21).
TEST(CliTyreFit, AnAbsurdMeasuredPressureIsNamedAsWritten) {
  const auto csv = temp_dir() / "absurd_pressure.csv";
  std::ofstream(csv) << "pressure_kpa,load_n,speed_kmh,rrc\n1e308,4000,80,0.0090\n210,4000,50,0.0085\n";
  const CmdResult r = fit("--size '205/55 R16 91V' --measured '" + csv.string() + "' --output '" +
                          (temp_dir() / "absurd_pressure.yaml").string() + "'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(has(r.err, "pressure 1e+308 kPa is not allowed for a road vehicle's tyre")) << r.err;
}

// --- tyre files choose their model ---

TEST(TyreFileModel, ThesisIsTheDefaultAndHysteresisNeedsItsLevel) {
  const auto dir = temp_dir();
  auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  };
  const std::string base = "size: \"205/55 R16 91V\"\npressure_bar: 2.1\n";
  EXPECT_EQ(load_tyre_file(write("d.yaml", base)).state.model, TyreModelKind::Thesis);
  EXPECT_EQ(load_tyre_file(write("t.yaml", base + "model: thesis\n")).state.model, TyreModelKind::Thesis);
  const auto h = load_tyre_file(write("h.yaml", base + "model:\n  kind: hysteresis\n  rrc_ref: 0.008\n"));
  EXPECT_EQ(h.state.model, TyreModelKind::Hysteresis);
  EXPECT_DOUBLE_EQ(h.state.hysteresis.rrc_ref, 0.008);
  EXPECT_THROW(load_tyre_file(write("m.yaml", base + "model: hysteresis\n")), InputError);  // no level
  EXPECT_THROW(load_tyre_file(write("x.yaml", base + "model:\n  kind: hysteresis\n  rrc_ref: 0.008\n  coulomb_damping_n: 10\n")),
               InputError);
  EXPECT_THROW(load_tyre_file(write("y.yaml", base + "model:\n  rrc_ref: 0.008\n")), InputError);  // thesis kind
  EXPECT_THROW(load_tyre_file(write("z.yaml", base + "model: magic\n")), InputError);
}

// Two points whose force falls with load (10 kg/t at 3 kN, 5 kg/t at 6 kN: 30 N both, a little less at 6 kN in the
// fitted law) contradict every measured tyre; the fit says so. A pair whose force grows as Z^0.95, the J2452 sets'
// median, does not draw the warning (before session 14 neither did).
TEST(TyreFit, AForceFallingWithLoadIsSaid) {
  const TyreFit bad = fit_two_points({210e3, 3000.0, 80 / 3.6, 0.010, "a"}, {210e3, 6000.0, 80 / 3.6, 0.005, "b"});
  ASSERT_EQ(bad.warnings.size(), 1u);
  EXPECT_NE(bad.warnings[0].find("falls with load"), std::string::npos) << bad.warnings[0];
  const double rrc_6kn = 0.010 * std::pow(2.0, 0.95 - 1.0);
  const TyreFit good = fit_two_points({210e3, 3000.0, 80 / 3.6, 0.010, "a"}, {210e3, 6000.0, 80 / 3.6, rrc_6kn, "b"});
  EXPECT_TRUE(good.warnings.empty());
}

namespace rollsim {
// A name with a line break or a quote is written as a YAML double-quoted scalar that reads back as the name (which a
// table then shows on one line, display_name): a raw line break broke the file ("a\n---\nb": "illegal document
// indicator", blamed on the points); session 22's outside testing. The source, kept as written, shows it exactly.
TEST(TyreFit, AnyNameIsWrittenSoThatItReadsBack) {
  for (const std::string name : {std::string("x\"\nmodel: thesis"), std::string("a\n---\nb"), std::string("tab\there \\ # : del\x7f")}) {
    FittedTyreFile file;
    file.name = name;
    file.size = "205/55 R16 91V";
    file.pressure_pa = 210e3;
    file.source = name;
    FitRequest r;
    r.points = {{210e3, 4825.0, 80 / 3.6, 0.0072, "p"}};
    const TyreFit fit = fit_hysteresis(hysteresis_tyre(), r);
    const TyreSpec back = load_tyre_text(fitted_tyre_file_text(file, fit), "fitted");
    EXPECT_EQ(back.name, display_name(name));
    EXPECT_EQ(back.reference, name);
  }
}
}  // namespace rollsim
