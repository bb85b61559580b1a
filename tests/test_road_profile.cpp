// The road profile recovered from the residual when elevation is withheld: the module's force, the hills named and
// their profile against the truth's (its own code path, discovery/truths.cpp), and never called where elevation is
// recorded or nothing is missing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "rollsim/diagnose/diagnose.hpp"
#include "rollsim/discovery/generate.hpp"
#include "rollsim/discovery/truths.hpp"
#include "rollsim/effects/road_profile.hpp"

namespace rollsim {
namespace {

constexpr double kG = 9.80665;

// The stage is on by default (DiagnoseOptions::infer_road_profile); said here so the tests do not depend on it.
DiagnoseOptions profile_on() {
  DiagnoseOptions o;
  o.infer_road_profile = true;
  return o;
}


Vehicle ev() { return load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml"); }

const Finding* find(const Diagnosis& d, const std::string& effect) {
  for (const auto& f : d.findings)
    if (f.effect == effect) return &f;
  return nullptr;
}

bool names_a_road(const Vehicle& v, const SyntheticCase& c) {
  const Diagnosis d = diagnose(v, {generate_case(v, c)}, profile_on());
  return find(d, "road_profile") != nullptr;
}

SyntheticCase hills_case(double amplitude_m, unsigned seed) {
  SyntheticCase c = real_logger(SyntheticCase{});
  c.effects = {{"rolling_hills", amplitude_m}};
  c.seed = seed;
  return c;
}

// The truth's hills, drawn as generate_case draws them (its truth stream).
RollingHills truth_hills(double amplitude_m, unsigned seed) {
  std::mt19937 truth_rng(seed * 7919u + 13u);
  return rolling_hills(amplitude_m, truth_rng);
}

// Pearson correlation of the recovered elevation with the truth's at the profile's knots, both relative to the start;
// `detrend` first removes each one's least-squares line in distance (on one trip a constant grade is the RRC level's
// shape, so the net climb is the least known part of a recovered profile).
double profile_correlation(const RecoveredProfile& p, const RollingHills& h, bool detrend) {
  const std::size_t n = p.distance_m.size();
  std::vector<double> x(p.elevation_m), y(n);
  for (std::size_t i = 0; i < n; ++i) y[i] = h.elevation_m(p.distance_m[i]) - h.elevation_m(0.0);
  auto centre = [&](std::vector<double>& v) {
    double ms = 0, mv = 0, sss = 0, ssv = 0;
    for (std::size_t i = 0; i < n; ++i) ms += p.distance_m[i] / n, mv += v[i] / n;
    for (std::size_t i = 0; i < n; ++i) sss += (p.distance_m[i] - ms) * (p.distance_m[i] - ms), ssv += (p.distance_m[i] - ms) * (v[i] - mv);
    const double slope = detrend ? ssv / sss : 0.0;
    for (std::size_t i = 0; i < n; ++i) v[i] -= mv + slope * (p.distance_m[i] - ms);
  };
  centre(x), centre(y);
  double sxy = 0, sxx = 0, syy = 0;
  for (std::size_t i = 0; i < n; ++i) sxy += x[i] * y[i], sxx += x[i] * x[i], syy += y[i] * y[i];
  return sxy / std::sqrt(sxx * syy);
}

TEST(RoadProfileEffect, GradeForceFollowsTheElevationSlopeWhileMoving) {
  const ElevationProfile p{{0.0, 100.0, 300.0}, {0.0, 5.0, -1.0}};
  EXPECT_DOUBLE_EQ(p.grade_at(50.0), 0.05);
  EXPECT_DOUBLE_EQ(p.grade_at(200.0), -0.03);
  EXPECT_DOUBLE_EQ(p.grade_at(-1.0), 0.0);   // before the profile: flat
  EXPECT_DOUBLE_EQ(p.grade_at(300.0), 0.0);  // beyond it: flat
  const RoadProfile road(p, 1.0, 1500.0);
  EffectInputs in;
  in.speed_mps = 10.0;
  in.distance_m = 50.0;
  EXPECT_NEAR(road.extra_resistance_n(in, nullptr), 1500.0 * kG * std::sin(std::atan(0.05)), 1e-9);
  in.distance_m = 200.0;
  EXPECT_NEAR(road.extra_resistance_n(in, nullptr), 1500.0 * kG * std::sin(std::atan(-0.03)), 1e-9);
  in.speed_mps = 0.0;  // standing: the brakes hold the car
  EXPECT_EQ(road.extra_resistance_n(in, nullptr), 0.0);
  // From the registry (a vehicle file) it has no knots: flat at any scale.
  in.speed_mps = 10.0;
  EffectContext ctx;
  ctx.mass_kg = 1500.0;
  EXPECT_EQ(make_effect(EffectId::road_profile, {{"profile_scale", 2.0}}, ctx)->extra_resistance_n(in, nullptr), 0.0);
}

TEST(RoadProfile, WithheldHillsAreNamedAndTheirProfileFollowsTheTruth) {
  const Vehicle v = ev();
  for (unsigned seed : {3u, 6u}) {
    const Recording rec = generate_case(v, hills_case(25.0, seed));
    const Diagnosis d = diagnose(v, {rec}, profile_on());
    ASSERT_FALSE(d.findings.empty()) << seed;
    EXPECT_EQ(d.findings.front().effect, "road_profile") << seed;
    const Finding* f = find(d, "road_profile");
    ASSERT_NE(f, nullptr) << seed;
    ASSERT_TRUE(f->road_profile.has_value());
    const RecoveredProfile& p = *f->road_profile;
    ASSERT_EQ(p.distance_m.size(), p.elevation_m.size());
    ASSERT_GT(p.distance_m.size(), 100u);
    EXPECT_EQ(p.elevation_m.front(), 0.0);  // relative to the start
    for (std::size_t i = 0; i < p.distance_m.size(); ++i) {
      EXPECT_LE(p.elevation_ci_low_m[i], p.elevation_m[i]);
      EXPECT_GE(p.elevation_ci_high_m[i], p.elevation_m[i]);
    }
    EXPECT_GE(profile_correlation(p, truth_hills(25.0, seed), true), 0.8) << seed;
    // The held-out windows improve and the model's residual shrinks towards the noise.
    EXPECT_LT(f->heldout_rmse_after_j, 0.7 * f->heldout_rmse_before_j) << seed;
    EXPECT_LT(d.final_residual_to_noise_ratio, 0.5 * d.residual_to_noise_ratio) << seed;
  }
}

TEST(RoadProfile, JsonCarriesTheProfileInsideTheFinding) {
  const Vehicle v = ev();
  const std::string j = diagnosis_json(diagnose(v, {generate_case(v, hills_case(25.0, 3u))}, profile_on()));
  const auto at = j.find("\"effect\": \"road_profile\"");
  ASSERT_NE(at, std::string::npos);
  const auto prof = j.find("\"road_profile\": {\"distance_m\": [", at);
  ASSERT_NE(prof, std::string::npos);
  EXPECT_NE(j.find("\"elevation_m\": [", prof), std::string::npos);
  EXPECT_LT(prof, j.find("\"located\""));  // inside the findings
}

TEST(RoadProfile, ALoopByLatitudeAndLongitudeReturnsToItsStartElevation) {
  const Vehicle v = ev();
  Recording rec = generate_case(v, hills_case(25.0, 3u));
  rec.latitude_deg = std::vector<double>(rec.time_s.size(), 48.1);
  rec.longitude_deg = std::vector<double>(rec.time_s.size(), 11.5);
  const Finding* f = nullptr;
  const Diagnosis d = diagnose(v, {rec}, profile_on());
  f = find(d, "road_profile");
  ASSERT_NE(f, nullptr);
  EXPECT_NEAR(f->road_profile->elevation_m.back(), 0.0, 0.5);
}

TEST(RoadProfile, NotCalledWhereElevationIsRecordedOrNothingIsMissing) {
  const Vehicle v = ev();
  // The same hills with the road's elevation recorded: the grade is known, nothing is left for a profile.
  Recording rec = generate_case(v, hills_case(25.0, 3u));
  const RollingHills h = truth_hills(25.0, 3u);
  std::vector<double> elevation(rec.time_s.size());
  double s = 0.0;
  for (std::size_t i = 0; i < rec.time_s.size(); ++i) {
    elevation[i] = h.elevation_m(s);
    if (i + 1 < rec.time_s.size()) s += 0.5 * (rec.speed_mps[i] + rec.speed_mps[i + 1]) * (rec.time_s[i + 1] - rec.time_s[i]);
  }
  rec.elevation_m = elevation;
  EXPECT_EQ(find(diagnose(v, {rec}, profile_on()), "road_profile"), nullptr);
  // Real-logger nulls (lag, scale jitter, noise): no road.
  for (unsigned seed : {56001u, 56002u, 56003u}) {
    SyntheticCase c = real_logger(SyntheticCase{});
    c.seed = seed;
    EXPECT_EQ(find(diagnose(v, {generate_case(v, c)}, profile_on()), "road_profile"), nullptr) << seed;
  }
}

// Measurement, not a check (run with --gtest_also_run_disabled_tests): how often the recovered profile of 25 m hills
// correlates >= 0.8 with the truth, raw and detrended, over 100 seeds of the benchmark's row.
TEST(RoadProfile, IsOnByDefaultAndCanBeSwitchedOff) {
  const Vehicle v = ev();
  const Recording rec = generate_case(v, hills_case(25.0, 3u));
  EXPECT_NE(find(diagnose(v, {rec}), "road_profile"), nullptr);
  DiagnoseOptions off;
  off.infer_road_profile = false;
  EXPECT_EQ(find(diagnose(v, {rec}, off), "road_profile"), nullptr);
}

// On one pass a profile along distance absorbs any loss that drifts along the trip as well as it absorbs hills. Only
// a road can push the force below zero loss, so these are not named a road (each was, in most seeds, before the
// descent rule: the scorecard of 2026-11-23 with the stage on, docs/scorecard-road-profile-on-100-seeds.txt).
TEST(RoadProfile, LossesDriftingAlongTheTripAreNotARoad) {
  const Vehicle v = ev();
  for (unsigned seed : {60001u, 60002u, 60003u}) {  // an RRC rising towards the end (a warm-up run backwards)
    SyntheticCase c = SyntheticCase{};
    c.effects = {{"tyre_two_node", 0.3}};
    c.time_reversed = true;
    c.seed = seed;
    EXPECT_FALSE(names_a_road(v, c)) << "reversed warm-up, seed " << seed;
  }
  for (unsigned seed : {61001u, 61002u}) {  // a gusting headwind
    SyntheticCase c = SyntheticCase{};
    c.effects = {{"wind_gusty", 1.5}};
    c.seed = seed;
    EXPECT_FALSE(names_a_road(v, c)) << "gusty wind, seed " << seed;
  }
  for (unsigned seed : {62001u, 62002u}) {  // a tailwind takes the force below zero loss, as a descent does
    SyntheticCase c = SyntheticCase{};
    c.effects = {{"wind_tail", 5.0}};
    c.seed = seed;
    EXPECT_FALSE(names_a_road(v, c)) << "tailwind, seed " << seed;
  }
}

TEST(RoadProfile, DISABLED_ProfileCorrelationOver100Seeds) {
  const Vehicle v = ev();
  int named = 0, raw = 0, flat = 0;
  std::vector<double> rs, ds;
  for (unsigned seed = 15001; seed < 15101; ++seed) {
    const Diagnosis d = diagnose(v, {generate_case(v, hills_case(25.0, seed))}, profile_on());
    const Finding* f = find(d, "road_profile");
    if (!f) continue;
    ++named;
    const double r = profile_correlation(*f->road_profile, truth_hills(25.0, seed), false);
    const double dt = profile_correlation(*f->road_profile, truth_hills(25.0, seed), true);
    rs.push_back(r), ds.push_back(dt);
    raw += r >= 0.8, flat += dt >= 0.8;
  }
  std::sort(rs.begin(), rs.end()), std::sort(ds.begin(), ds.end());
  std::cout << "profile found in " << named << " of 100; correlation >= 0.8: raw " << raw << ", detrended " << flat
            << "; median raw " << (rs.empty() ? 0 : rs[rs.size() / 2]) << ", detrended " << (ds.empty() ? 0 : ds[ds.size() / 2]) << "\n";
}

}  // namespace
}  // namespace rollsim
