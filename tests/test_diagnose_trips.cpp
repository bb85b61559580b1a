// Across-trip diagnosis: ambient temperature on RRC is a candidate only when several recordings at different
// ambients are given; the sparse baseline's threshold sweep.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "rollsim/common/error.hpp"
#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/diagnose/diagnose.hpp"
#include "rollsim/discovery/baselines.hpp"
#include "rollsim/discovery/generate.hpp"
#include "rollsim/discovery/scorecard.hpp"
#include "rollsim/effects/catalogue.hpp"
#include "rollsim/sim/simulation.hpp"

namespace rollsim {
namespace {

Vehicle ev() { return load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml"); }

const Finding* finding(const Diagnosis& d, const std::string& id) {
  for (const auto& f : d.findings)
    if (f.effect == id) return &f;
  return nullptr;
}

const ParameterEstimate* parameter(const Finding& f, const std::string& name) {
  for (const auto& p : f.parameters)
    if (p.name == name) return &p;
  return nullptr;
}

bool has_note(const Diagnosis& d, const std::string& text) {
  return std::any_of(d.notes.begin(), d.notes.end(), [&](const std::string& n) { return n.find(text) != std::string::npos; });
}

// The air of a trip at `ambient_c`: density ~ 1 / T against the vehicle's at 20 degC, so an extra aero force
// 0.5 rho_20 CdA (293.15 / T - 1) v^2 (written here, apart from the diagnosis' own correction).
class AirAt final : public Effect {
 public:
  AirAt(const Vehicle& v, double ambient_c)
      : k_(0.5 * v.body.air_density_kg_per_m3 * v.body.drag_coefficient * v.body.frontal_area_m2 * (293.15 / (ambient_c + 273.15) - 1.0)) {}
  std::string id() const override { return "test_air"; }
  double extra_resistance_n(const EffectInputs& in, const double*) const override { return k_ * in.speed_mps * in.speed_mps; }

 private:
  double k_;
};

// A trip whose measured power carries one catalogue module at a known size (an exact law, the analytic limit the fit
// must recover), optionally in the air of that ambient, with white noise; its recorded ambient is `ambient_c`.
Recording catalogue_law_trip(const Vehicle& v, const std::string& cycle, double ambient_c, const std::string& effect,
                             const EffectParameters& params, bool air_at_ambient, unsigned seed) {
  const DriveCycle c = load_cycle(cycle);
  VehicleModel m = VehicleModel::assemble(v);
  EffectContext ctx = effect_context(v);
  m.effects.push_back(make_effect(effect, params, ctx));
  if (air_at_ambient) m.effects.push_back(std::make_shared<AirAt>(v, ambient_c));
  SimulationOptions so;
  so.record_trace = true;
  const SimulationResult r = simulate_replay(m, c, so);
  Recording rec;
  rec.source = cycle + " at " + std::to_string(ambient_c) + " degC";
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 300.0);
  std::vector<double> p;
  for (std::size_t i = 0; i < r.trace.size(); ++i) {
    rec.time_s.push_back(c.time_s[i] - c.time_s.front());
    rec.speed_mps.push_back(c.speed_mps[i]);
    p.push_back(r.trace[i].battery_power_w + noise(rng));
  }
  rec.battery_power_w = p;
  rec.ambient_temp_k = std::vector<double>(p.size(), ambient_c + 273.15);
  return rec;
}

Recording linear_ambient_trip(const Vehicle& v, const std::string& cycle, double ambient_c, double c_per_k, unsigned seed) {
  return catalogue_law_trip(v, cycle, ambient_c, "ambient_rrc",
                            {{"rrc_change_per_k", c_per_k}, {"ambient_temp_c", ambient_c}, {"reference_temp_c", 20.0}}, true, seed);
}

// hvac_ambient's exact law, in the vehicle's air (the diagnosis is then told not to correct the density).
Recording hvac_law_trip(const Vehicle& v, const std::string& cycle, double ambient_c, double heat, double cool, unsigned seed) {
  return catalogue_law_trip(v, cycle, ambient_c, "hvac_ambient",
                            {{"heat_w_per_k", heat}, {"cool_w_per_k", cool}, {"ambient_temp_c", ambient_c}}, false, seed);
}

TEST(DiagnoseTrips, RecoversALinearAmbientLawAcrossTrips) {
  // Exact catalogue law at c = 0.008 /K over four trips at -5, 5, 18 and 30 degC: the fitted c's interval holds it.
  const Vehicle v = ev();
  constexpr double kC = 0.008;
  const std::vector<Recording> recs{linear_ambient_trip(v, "wltc", -5.0, kC, 1), linear_ambient_trip(v, "ftp75", 18.0, kC, 2),
                                    linear_ambient_trip(v, "artemis_road", 30.0, kC, 3), linear_ambient_trip(v, "wltc", 5.0, kC, 4)};
  const Diagnosis d = diagnose(v, recs);
  ASSERT_FALSE(d.findings.empty()) << diagnosis_text(d);
  EXPECT_EQ(d.findings.front().effect, "ambient_rrc") << diagnosis_text(d);
  const Finding* f = finding(d, "ambient_rrc");
  ASSERT_NE(f, nullptr);
  const auto& c = f->parameters.front();
  EXPECT_EQ(c.name, "rrc_change_per_k");
  EXPECT_EQ(c.unit, "1/K");
  EXPECT_LT(c.ci_low, kC) << diagnosis_text(d);
  EXPECT_GT(c.ci_high, kC) << diagnosis_text(d);
  EXPECT_GT(c.ci_low, 0.0);
  EXPECT_LT(f->heldout_rmse_after_j, f->heldout_rmse_before_j);
  // The reference is the trips' mean ambient (12 degC), the same for both fixed parameters.
  for (const auto& p : f->parameters)
    if (p.name != "rrc_change_per_k") EXPECT_NEAR(p.value, 12.0, 1e-6) << p.name;
}

TEST(DiagnoseTrips, StaysOutOfOneTripSameAmbientAndUnrecordedAmbient) {
  const Vehicle v = ev();
  // One trip with a strong law: within one trip it is the RRC level, so never a candidate.
  const Recording cold = linear_ambient_trip(v, "wltc", -5.0, 0.012, 1);
  const Diagnosis one = diagnose(v, {cold});
  EXPECT_EQ(finding(one, "ambient_rrc"), nullptr);
  EXPECT_TRUE(has_note(one, "ambient_rrc not tested: one recording")) << diagnosis_text(one);
  for (const auto& l : one.detection_limits) EXPECT_NE(l.effect, "ambient_rrc");
  // Two trips 2 K apart: under the 5 K spread, so not tested (the same ambient).
  const Diagnosis same = diagnose(v, {linear_ambient_trip(v, "wltc", 10.0, 0.012, 1), linear_ambient_trip(v, "ftp75", 12.0, 0.012, 2)});
  EXPECT_EQ(finding(same, "ambient_rrc"), nullptr);
  EXPECT_TRUE(has_note(same, "span 2.0 K")) << diagnosis_text(same);
  // No ambient column in one of them: not tested, and said so.
  Recording blind = linear_ambient_trip(v, "ftp75", 30.0, 0.012, 2);
  blind.ambient_temp_k.reset();
  const Diagnosis unrecorded = diagnose(v, {cold, blind});
  EXPECT_EQ(finding(unrecorded, "ambient_rrc"), nullptr);
  EXPECT_TRUE(has_note(unrecorded, "not every recording has an ambient_temp_c column")) << diagnosis_text(unrecorded);
}

TEST(DiagnoseTrips, GeneratedTripsShareTheCarAndSpreadTheAmbients) {
  const Vehicle v = ev();
  MultiTripCase m;
  m.seed = 7;
  const std::vector<Recording> trips = generate_trips(v, m);
  ASSERT_EQ(trips.size(), m.cycles.size());
  // Stratified: one trip per 8.75 K slice of -5..30 degC (sensor noise 0.3 K, 0.5 K quantum).
  std::vector<double> mean_c;
  for (const auto& t : trips) {
    ASSERT_TRUE(t.ambient_temp_k.has_value());
    double s = 0.0;
    for (double x : *t.ambient_temp_k) {
      EXPECT_NEAR(x / 0.5, std::round(x / 0.5), 1e-9);
      s += x;
    }
    mean_c.push_back(s / static_cast<double>(t.ambient_temp_k->size()) - 273.15);
  }
  std::sort(mean_c.begin(), mean_c.end());
  for (std::size_t k = 0; k < mean_c.size(); ++k) {
    EXPECT_GE(mean_c[k], -5.0 + 8.75 * static_cast<double>(k) - 0.5);
    EXPECT_LE(mean_c[k], -5.0 + 8.75 * static_cast<double>(k + 1) + 0.5);
  }
  // A cold trip with the compound law uses more energy than the same trip without it; the effect's sign is right.
  MultiTripCase hot = m;
  hot.effects = {{"ambient_compound", 0.012}};
  const std::vector<Recording> with = generate_trips(v, hot);
  std::size_t coldest = 0;
  for (std::size_t k = 0; k < trips.size(); ++k)
    if ((*trips[k].ambient_temp_k)[0] < (*trips[coldest].ambient_temp_k)[0]) coldest = k;
  double e0 = 0.0, e1 = 0.0;
  for (std::size_t i = 0; i < trips[coldest].battery_power_w->size(); ++i) {
    e0 += (*trips[coldest].battery_power_w)[i];
    e1 += (*with[coldest].battery_power_w)[i];
  }
  EXPECT_GT(e1, e0);
  EXPECT_THROW(generate_case(v, [] {
                 SyntheticCase s;
                 s.effects = {{"ambient_compound", 0.008}};
                 return s;
               }()),
               InputError);  // the truth needs the trip's ambient
}

TEST(DiagnoseTrips, NamesTheConcealedCompoundLawAndNotTheNull) {
  const Vehicle v = ev();
  for (unsigned seed : {3u, 4u}) {
    MultiTripCase m;
    m.seed = seed;
    const Diagnosis nul = diagnose(v, generate_trips(v, m));
    EXPECT_EQ(nul.verdict, "nothing_missing") << diagnosis_text(nul);
    m.effects = {{"ambient_compound", 0.008}};
    const Diagnosis d = diagnose(v, generate_trips(v, m));
    ASSERT_FALSE(d.findings.empty()) << diagnosis_text(d);
    EXPECT_EQ(d.findings.front().effect, "ambient_rrc") << diagnosis_text(d);
    // The truth's slope is c = 0.008 +- 10 % at 20 degC and steeper when cold (WLF-like curvature, C2 120-180 K):
    // over -5..30 degC its chord slope relative to the mean RRC is 1.0-1.5 c.
    const double c = d.findings.front().parameters.front().value;
    EXPECT_GT(c, 0.7 * 0.008) << diagnosis_text(d);
    EXPECT_LT(c, 2.0 * 0.008) << diagnosis_text(d);
  }
}

TEST(DiagnoseTrips, HvacDiagnosisRecoversTheLawAcrossTripsWithAnInterval) {
  // The exact catalogue law, heating 60 W/K and cooling half that, over four trips at -5, 8, 21 and 33 degC.
  const Vehicle v = ev();
  DiagnoseOptions opt;
  opt.air_density_from_ambient = false;  // the trips' air is the vehicle's here
  const std::vector<Recording> recs{hvac_law_trip(v, "wltc", -5.0, 60.0, 30.0, 1), hvac_law_trip(v, "ftp75", 8.0, 60.0, 30.0, 2),
                                    hvac_law_trip(v, "artemis_road", 21.0, 60.0, 30.0, 3), hvac_law_trip(v, "wltc", 33.0, 60.0, 30.0, 4)};
  const Diagnosis d = diagnose(v, recs, opt);
  ASSERT_FALSE(d.findings.empty()) << diagnosis_text(d);
  EXPECT_EQ(d.findings.front().effect, "hvac_ambient") << diagnosis_text(d);
  EXPECT_EQ(finding(d, "ambient_rrc"), nullptr) << diagnosis_text(d);
  const Finding* f = finding(d, "hvac_ambient");
  ASSERT_NE(f, nullptr);
  const ParameterEstimate* heat = parameter(*f, "heat_w_per_k");
  const ParameterEstimate* cool = parameter(*f, "cool_w_per_k");
  ASSERT_NE(heat, nullptr);
  ASSERT_NE(cool, nullptr);
  EXPECT_EQ(heat->unit, "W/K");
  EXPECT_LT(heat->ci_low, 60.0) << diagnosis_text(d);
  EXPECT_GT(heat->ci_high, 60.0) << diagnosis_text(d);
  EXPECT_GT(heat->ci_low, 0.0);
  EXPECT_NEAR(cool->value / heat->value, 0.5, 1e-9);  // the grid's ratio that is the truth's
  EXPECT_TRUE(has_note(d, "hvac_ambient tested across 4 recordings")) << diagnosis_text(d);
}

TEST(DiagnoseTrips, HvacNotTestedOnOneTripTheSameAmbientOrInTheDeadBand) {
  const Vehicle v = ev();
  const Recording cold = hvac_law_trip(v, "wltc", -5.0, 80.0, 0.0, 1);
  const Diagnosis one = diagnose(v, {cold});
  EXPECT_EQ(finding(one, "hvac_ambient"), nullptr);
  EXPECT_TRUE(has_note(one, "hvac_ambient not tested: one recording")) << diagnosis_text(one);
  const Diagnosis band = diagnose(v, {hvac_law_trip(v, "wltc", 18.5, 80.0, 80.0, 1), hvac_law_trip(v, "ftp75", 23.5, 80.0, 80.0, 2)});
  EXPECT_EQ(finding(band, "hvac_ambient"), nullptr);
  EXPECT_TRUE(has_note(band, "within its dead band")) << diagnosis_text(band);
}

TEST(SparseBaseline, ThresholdSweepIsConsistentAndHasItsLimits) {
  const Vehicle v = ev();
  SyntheticCase s;
  s.seed = 11;
  const Recording rec = generate_case(v, s);
  const SparseSweep sw = sparse_regression_sweep(v, rec);
  ASSERT_EQ(sw.by_threshold.size(), sparse_thresholds().size());
  for (std::size_t t = 0; t < sparse_thresholds().size(); ++t)
    EXPECT_EQ(sw.by_threshold[t], sparse_regression_discovery(v, rec, 60.0, sparse_thresholds()[t]));
  // Limits: a vanishing threshold keeps every mapped term; one far above the measured energy keeps none.
  EXPECT_EQ(sparse_regression_discovery(v, rec, 60.0, 1e-12).size(), 4u);
  EXPECT_TRUE(sparse_regression_discovery(v, rec, 60.0, 1e6).empty());
  EXPECT_GE(sw.bic_threshold, 0.001 - 1e-12);
  EXPECT_LE(sw.bic_threshold, 0.3 + 1e-12);
  EXPECT_THROW(sparse_regression_discovery(v, rec, 60.0, 0.0), InputError);
}

}  // namespace
}  // namespace rollsim

namespace rollsim {
namespace {

TEST(ProfileInterval, MatchesAQuadraticProfileInLogParameter) {
  // n_eff ln(RSS / RSS_min) = ((ln theta - ln theta0) / w)^2: the 95 % interval is theta0 exp(+-w sqrt(3.84)).
  const double theta0 = 700.0, w = 0.4, n_eff = 30.0;
  std::vector<double> grid, rss;
  for (int i = 0; i <= 400; ++i) {
    const double t = 50.0 * std::pow(2.0, i / 40.0);
    grid.push_back(t);
    const double z = (std::log(t) - std::log(theta0)) / w;
    rss.push_back(5.0e6 * std::exp(z * z / n_eff));
  }
  const ProfileInterval p = profile_likelihood_interval(grid, rss, n_eff);
  EXPECT_NEAR(p.value, theta0, theta0 * 0.01);  // the nearest grid point (steps of 1.7 %)
  EXPECT_FALSE(p.low_open || p.high_open);
  // Interpolation is linear in ln theta across one step of ln 2 / 40; the quadratic's error over it is tiny.
  EXPECT_NEAR(std::log(p.low), std::log(theta0) - w * std::sqrt(3.84), 0.01);
  EXPECT_NEAR(std::log(p.high), std::log(theta0) + w * std::sqrt(3.84), 0.01);
}

TEST(ProfileInterval, FlatProfileIsOpenAtBothEndsAndBadInputIsRefused) {
  const std::vector<double> grid{100.0, 200.0, 400.0, 800.0};
  const ProfileInterval flat = profile_likelihood_interval(grid, {1.0, 1.0001, 1.0, 1.0002}, 10.0);
  EXPECT_TRUE(flat.low_open && flat.high_open);
  EXPECT_EQ(flat.low, 100.0);
  EXPECT_EQ(flat.high, 800.0);
  // Open above only: the criterion keeps falling towards the largest value.
  const ProfileInterval rising = profile_likelihood_interval(grid, {4.0, 2.0, 1.05, 1.0}, 10.0);
  EXPECT_FALSE(rising.low_open);
  EXPECT_TRUE(rising.high_open);
  EXPECT_GT(rising.low, 200.0);
  EXPECT_LT(rising.low, 400.0);
  EXPECT_THROW(profile_likelihood_interval({200.0, 100.0}, {1.0, 1.0}, 10.0), InputError);
  EXPECT_THROW(profile_likelihood_interval({100.0, 200.0}, {1.0}, 10.0), InputError);
  EXPECT_THROW(profile_likelihood_interval({100.0, 200.0}, {1.0, 0.0}, 10.0), InputError);
}

TEST(ProfileInterval, FoundWarmupCarriesAProfiledHeatCapacity) {
  const Vehicle v = ev();
  SyntheticOptions o;
  o.tyre_cold_excess = 0.3;
  o.seed = 1;
  const Diagnosis d = diagnose(v, {generate_recording(v, o)});
  const Finding* f = finding(d, "tyre_warmup");
  ASSERT_NE(f, nullptr) << diagnosis_text(d);
  bool seen = false;
  for (const auto& p : f->parameters) {
    if (p.name != "heat_capacity_j_per_k") continue;
    seen = true;
    EXPECT_TRUE(p.profiled);
    EXPECT_LE(p.ci_low, p.value);
    EXPECT_GE(p.ci_high, p.value);
    EXPECT_LT(p.ci_low, p.ci_high) << diagnosis_text(d);  // a real interval, not the grid point repeated
    EXPECT_GE(p.ci_low, 10000.0);
    EXPECT_LE(p.ci_high, 400000.0);
    EXPECT_EQ(f->fitted.at("heat_capacity_j_per_k"), p.value);  // the written vehicle carries the refined value
  }
  EXPECT_TRUE(seen);
  EXPECT_NE(diagnosis_json(d).find("\"interval\": \"profile\""), std::string::npos);
}

}  // namespace
}  // namespace rollsim
