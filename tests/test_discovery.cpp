// Discovery benchmark's new truths and scoring: hills, duty-cycled loads, fractional lag, signed scores.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "rollsim/discovery/generate.hpp"
#include "rollsim/discovery/scorecard.hpp"
#include "rollsim/discovery/truths.hpp"

namespace rollsim {
namespace {

constexpr double kTwoPi = 6.283185307179586;

Vehicle ev() { return load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml"); }

TEST(Truths, RollingHillsHaveTheirAmplitudeWavelengthsAndGrade) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    std::mt19937 rng(seed);
    const RollingHills h = rolling_hills(25.0, rng);
    ASSERT_EQ(h.amplitude_m.size(), 3u);
    // sqrt(2) RMS of three sinusoids over many wavelengths is sqrt(sum a^2) = the amplitude asked for.
    double sum2 = 0.0, peak_grade = 0.0;
    const int n = 200000;
    for (int i = 0; i < n; ++i) {
      const double s = 5.0 * i;  // 1000 km at 5 m
      sum2 += h.elevation_m(s) * h.elevation_m(s);
      peak_grade = std::max(peak_grade, std::abs(h.grade(s)));
      if (i % 997 == 0) EXPECT_NEAR(h.grade(s), (h.elevation_m(s + 0.01) - h.elevation_m(s - 0.01)) / 0.02, 1e-6);
    }
    EXPECT_NEAR(std::sqrt(2.0 * sum2 / n), 25.0, 25.0 * 0.05) << "seed " << seed;
    EXPECT_LE(peak_grade, 0.08 + 1e-9);
    for (double l : h.wavelength_m) EXPECT_GE(l, 500.0);
    // Wavelengths beyond 3 km only where the 8 % grade cap stretched them.
    double grade_sum = 0.0;
    for (std::size_t k = 0; k < 3; ++k) grade_sum += h.amplitude_m[k] * kTwoPi / h.wavelength_m[k];
    for (double l : h.wavelength_m)
      if (l > 3000.0) EXPECT_NEAR(grade_sum, 0.08, 1e-9);
  }
}

TEST(Truths, CompressorCyclesOnAndOffWithinItsDutyRange) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    std::mt19937 rng(seed);
    const DutyCycle d = compressor_cycles(1000.0, 3600.0, rng);
    // Duty 0.3-0.7 with each cycle's period jittered: the trip's mean is inside 0.2-0.8 of the on power.
    const double mean = d.mean_power_w(3600.0);
    EXPECT_GT(mean, 200.0);
    EXPECT_LT(mean, 800.0);
    // Periods of 2-6 min, +-25 %: between 3600 / 450 and 3600 / 90 cycles (plus the one begun before the start).
    EXPECT_GE(d.on_from_s.size(), 8u);
    EXPECT_LE(d.on_from_s.size(), 41u);
    double on_s = 0.0;
    for (double t = 0.05; t < 3600.0; t += 0.1) {
      const double p = d.power_w(t);
      EXPECT_TRUE(p == 0.0 || p == 1000.0);
      on_s += p > 0.0 ? 0.1 : 0.0;
    }
    EXPECT_NEAR(on_s / 3600.0 * 1000.0, mean, 2.0);
  }
}

TEST(Truths, LagBetweenSamplesInterpolates) {
  const std::vector<double> t{0, 1, 2, 3, 4}, x{0, 10, 30, 20, 5};
  EXPECT_EQ(delayed(t, x, 0.0), x);
  EXPECT_EQ(delayed(t, x, 1.0), (std::vector<double>{0, 0, 10, 30, 20}));
  const std::vector<double> half = delayed(t, x, 0.5);
  EXPECT_DOUBLE_EQ(half[2], 20.0);  // halfway between 10 and 30
  EXPECT_DOUBLE_EQ(half[4], 12.5);
  EXPECT_DOUBLE_EQ(delayed(t, x, 1.25)[3], 25.0);  // t = 1.75: three quarters of the way from 10 to 30
}

// A recording with only the truth (no noise, quantum, jitter): what the generator writes is the physics.
SyntheticCase clean(unsigned seed) {
  SyntheticCase c;
  c.rrc_level_jitter = 0.0;
  c.scale_jitter = 0.0;
  c.noise_w = 0.0;
  c.quantum_w = 0.0;
  c.lag_s = 0.0;
  c.seed = seed;
  return c;
}

TEST(Generator, FractionalLagIsTheInterpolatedChannel) {
  const Vehicle v = ev();
  SyntheticCase a = clean(3), b = clean(3), h = clean(3);
  b.lag_s = 1.0;
  h.lag_s = 0.5;
  const auto pa = *generate_case(v, a).battery_power_w, pb = *generate_case(v, b).battery_power_w;
  const auto ph = *generate_case(v, h).battery_power_w;
  for (std::size_t i = 1; i < ph.size(); ++i) ASSERT_NEAR(ph[i], 0.5 * (pa[i] + pb[i]), 1e-9) << i;
  // A real logger's lag is drawn per seed within 0.3-1.7 s: never a whole sample here.
  SyntheticCase r = real_logger(clean(4));
  EXPECT_DOUBLE_EQ(r.lag_s, 0.3);
  EXPECT_DOUBLE_EQ(r.lag_max_s, 1.7);
  EXPECT_DOUBLE_EQ(r.scale_jitter, 0.03);
}

TEST(Generator, DutyCycledAcAddsItsOnPowerAtTheBattery) {
  const Vehicle v = ev();
  SyntheticCase ac = clean(7);
  ac.effects = {{"ac_duty_cycle", 1000.0}};
  const auto p0 = *generate_case(v, clean(7)).battery_power_w, p1 = *generate_case(v, ac).battery_power_w;
  // Each sample is its segment's mean (two Gauss points on a ramp): half the power where the compressor switches.
  int on = 0, switching = 0;
  for (std::size_t i = 0; i < p0.size(); ++i) {
    const double d = p1[i] - p0[i];
    ASSERT_TRUE(std::abs(d) < 1e-6 || std::abs(d - 500.0) < 1e-6 || std::abs(d - 1000.0) < 1e-6) << i << ": " << d;
    on += d > 750.0;
    switching += std::abs(d - 500.0) < 1e-6;
  }
  EXPECT_LT(switching, 0.05 * static_cast<double>(p0.size()));
  const double duty = static_cast<double>(on) / static_cast<double>(p0.size());
  EXPECT_GT(duty, 0.2);
  EXPECT_LT(duty, 0.8);
}

TEST(Generator, WithheldHillsCostEnergyUphillAndNoGradeIsRecorded) {
  const Vehicle v = ev();
  SyntheticCase hills = clean(11);
  hills.effects = {{"rolling_hills", 25.0}};
  const Recording flat = generate_case(v, clean(11)), hilly = generate_case(v, hills);
  EXPECT_FALSE(hilly.grade.has_value());
  EXPECT_FALSE(hilly.elevation_m.has_value());
  // Regenerate the hills to know where the road climbs: the extra battery power has the sign of the grade at speed.
  std::mt19937 truth_rng(11u * 7919u + 13u);
  const RollingHills h = rolling_hills(25.0, truth_rng);
  double s = 0.0;
  int agree = 0, counted = 0;
  for (std::size_t i = 0; i + 1 < flat.time_s.size(); ++i) {
    const double ds = 0.5 * (flat.speed_mps[i] + flat.speed_mps[i + 1]) * (flat.time_s[i + 1] - flat.time_s[i]);
    const double g = h.grade(s + 0.5 * ds);
    s += ds;
    if (std::abs(g) < 0.01 || flat.speed_mps[i] < 10.0) continue;
    ++counted;
    agree += ((*hilly.battery_power_w)[i] - (*flat.battery_power_w)[i]) * g > 0.0;
  }
  ASSERT_GT(counted, 200);
  EXPECT_GT(agree, 0.95 * counted);
}

TEST(Scorecard, SignedAndReversedRowsCountNegativeSizesAsMistakes) {
  const RowRule warm{"single", {"tyre_warmup"}, +1, ""};
  bool wrong = false;
  EXPECT_EQ(score_findings(warm, {{"tyre_warmup", {}, 0.3}}, &wrong), Tally::named);
  EXPECT_FALSE(wrong);
  EXPECT_EQ(score_findings(warm, {{"tyre_warmup", {}, -0.4}}, &wrong), Tally::mistaken);
  EXPECT_TRUE(wrong);
  EXPECT_EQ(score_findings(warm, {{"engine_warmup", {"tyre_warmup"}, 0.2}}), Tally::confounded);
  EXPECT_EQ(score_findings(warm, {{"unexplained", {}, 1.0}}), Tally::missed);
  EXPECT_EQ(score_findings(warm, {}), Tally::missed);
  // Unsigned truths (hills: either sign of grade) take either sign.
  EXPECT_EQ(score_findings({"single", {"road_grade"}, 0, ""}, {{"road_grade", {}, -0.01}}), Tally::named);
  // A null for warm-up: any tyre_warmup finding, of either sign and in any place, is the mistake.
  const RowRule rising{"reversed", {}, 0, "tyre_warmup"};
  EXPECT_EQ(score_findings(rising, {{"unexplained", {}, 1.0}, {"tyre_warmup", {}, -0.4}}, &wrong), Tally::mistaken);
  EXPECT_TRUE(wrong);
  EXPECT_EQ(score_findings(rising, {{"unexplained", {}, 1.0}}), Tally::missed);
  EXPECT_EQ(score_findings({"null", {}, 0, ""}, {{"unexplained", {}, 1.0}}), Tally::mistaken);
  EXPECT_EQ(score_findings({"two", {"tyre_warmup", "aux_load"}, 0, ""}, {{"aux_load", {}, 500.0}, {"tyre_warmup", {}, 0.2}}),
            Tally::named);
  // Two at once: an unexplained finding alone is missed (the table's rule for every effect row), not a wrong name.
  const RowRule two{"two", {"wind", "mass"}, 0, ""};
  EXPECT_EQ(score_findings(two, {{"unexplained", {}, 1.0}}), Tally::missed);
  EXPECT_EQ(score_findings(two, {{"unexplained", {}, 1.0}, {"wind", {}, 3.0}}), Tally::confounded);
  EXPECT_EQ(score_findings(two, {{"aux_load", {}, 300.0}}), Tally::mistaken);
}

}  // namespace
}  // namespace rollsim
