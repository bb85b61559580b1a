// Grade from elevation: the Savitzky-Golay (cubic) derivative keeps short steep hills and states its noise gain.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "rollsim/common/statistics.hpp"
#include "rollsim/cycle/elevation.hpp"

namespace rollsim {
namespace {

constexpr double kTwoPi = 6.283185307179586;

// 30 km at 20 m/s sampled at 10 Hz (2 m apart) over h = 20 sin(2 pi s / wave): the fraction of the true grade the
// filter keeps, by least squares over the interior (away from the ends).
double hill_gain(double wave_m) {
  std::vector<double> t, v, h, truth;
  for (int i = 0; i <= 15000; ++i) {
    const double s = 2.0 * i;
    t.push_back(0.1 * i);
    v.push_back(20.0);
    h.push_back(100.0 + 20.0 * std::sin(kTwoPi * s / wave_m));
    // s is the distance along the road, so dh/ds is the sine of the road's angle; the grade is its tangent.
    const double sine = 20.0 * kTwoPi / wave_m * std::cos(kTwoPi * s / wave_m);
    truth.push_back(sine / std::sqrt(1.0 - sine * sine));
  }
  const ElevationGrade g = grade_from_elevation(t, v, h);
  double num = 0.0, den = 0.0;
  for (std::size_t i = 500; i + 500 < t.size(); ++i) {
    num += g.grade[i] * truth[i];
    den += truth[i] * truth[i];
  }
  return num / den;
}

TEST(Elevation, CubicDerivativeKeepsHillsLongerThanAKilometre) {
  // Analytic response of a cubic Savitzky-Golay slope over 300 m on a sine of wavelength L: 99.84 % at 1 km. The
  // 200 m moving average it replaces kept 87 % at 1 km and 94 % at 1.5 km (the false rotational_inertia).
  for (double wave : {1000.0, 1500.0, 2000.0, 4000.0}) {
    const double gain = hill_gain(wave);
    EXPECT_GE(gain, 0.995) << wave;
    EXPECT_LE(gain, 1.002) << wave;
  }
  EXPECT_LT(hill_gain(300.0), 0.9);  // noise-length bumps are still filtered
}

TEST(Elevation, SlopeWeightsAreExactForCubicsAndOffCentreAtTheEnds) {
  for (auto [first, last] : {std::pair<std::ptrdiff_t, std::ptrdiff_t>{-30, 30}, {0, 60}, {-10, 50}, {-2, 2}}) {
    const auto w = cubic_slope_weights(first, last);
    double slope = 0.0, constant = 0.0;
    for (std::ptrdiff_t k = first; k <= last; ++k) {
      const double x = static_cast<double>(k);
      slope += w[static_cast<std::size_t>(k - first)] * (3.0 + 0.5 * x - 0.02 * x * x + 0.001 * x * x * x);
      constant += w[static_cast<std::size_t>(k - first)];
    }
    EXPECT_NEAR(slope, 0.5, 1e-9) << first << ".." << last;  // d/dx at x = 0
    EXPECT_NEAR(constant, 0.0, 1e-9);
  }
}

TEST(Elevation, NoiseGainIsTheFiltersStated) {
  // White elevation noise of 0.5 m per sample (no step reaches the glitch test), five samples per 5 m cell at 1 m
  // spacing: the cell mean has sd 0.5 / sqrt(5) m, and the grade noise is that times sqrt(sum w^2) / 5 m (0.0036 per
  // metre of cell noise over 300 m).
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<double> t, v, h;
  for (int i = 0; i <= 50000; ++i) {
    t.push_back(0.1 * i);
    v.push_back(10.0);
    h.push_back(100.0 + 0.5 * n(rng));
  }
  const ElevationGrade g = grade_from_elevation(t, v, h);
  double ss = 0.0;
  int count = 0;
  for (std::size_t i = 1000; i + 1000 < t.size(); i += 1) {
    ss += g.grade[i] * g.grade[i];
    ++count;
  }
  const auto w = cubic_slope_weights(-30, 30);
  double w2 = 0.0;
  for (double x : w) w2 += x * x;
  const double predicted = 0.5 * std::sqrt(w2) / 5.0 / std::sqrt(5.0);
  EXPECT_NEAR(std::sqrt(w2) / 5.0, 0.0036, 0.0001);
  EXPECT_NEAR(std::sqrt(ss / count), predicted, 0.1 * predicted);
}


// A town-and-country speed trace at 1 Hz: 90 s runs to 20 m/s and back with 20 s stops, `runs` times; its speeds and
// times, and level-road elevations at 150 m plus white noise of `sd_m` per reading.
struct Trace {
  std::vector<double> t, v, h;
};
Trace stop_and_go(int runs, double sd_m, unsigned seed, int per_second = 1) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  Trace tr;
  const double dt = 1.0 / per_second;
  double t = 0.0;
  for (int k = 0; k < runs; ++k) {
    for (int i = 0; i < 110 * per_second; ++i, t += dt) {
      tr.t.push_back(t);
      tr.v.push_back(i < 90 * per_second ? 20.0 * std::sin(kTwoPi * i / (180.0 * per_second)) : 0.0);
      tr.h.push_back(150.0 + sd_m * n(rng));
    }
  }
  return tr;
}

double moving_rms(const Trace& tr, const std::vector<double>& g) {
  double ss = 0.0;
  int count = 0;
  for (std::size_t i = 0; i < g.size(); ++i)
    if (tr.v[i] > 0.0) ss += g[i] * g[i], ++count;
  return std::sqrt(ss / count);
}

TEST(Elevation, WhiteNoiseOnTheReadingsIsEstimated) {
  for (double sd : {0.3, 1.0, 1.5}) {
    const Trace tr = stop_and_go(40, sd, 7);
    const ElevationGrade g = grade_from_elevation(tr.t, tr.v, tr.h);
    EXPECT_NEAR(g.noise_sd_m, sd, 0.1 * sd) << sd;
    EXPECT_GT(g.noise_triples, 3000);
  }
  // A noise-free road of 1 km hills 20 m high (12.6 % at their steepest) reads as 0.05 m of noise: what its
  // curvature moves a reading from the line through its neighbours 15 m either side.
  std::vector<double> t, v, h;
  for (int i = 0; i <= 3000; ++i) {
    t.push_back(i);
    v.push_back(15.0);
    h.push_back(150.0 + 20.0 * std::sin(kTwoPi * 15.0 * i / 1000.0));
  }
  EXPECT_LT(grade_from_elevation(t, v, h).noise_sd_m, 0.06);
}

TEST(Elevation, NoisyReadingsAreNotTakenForGlitches) {
  // 1.5 m per reading: a step's sd is 2.1 m, and the fixed 5 m tolerance took 1-2 % of them for glitches near the
  // stops, each dropped step shifting the rest of the road by the noise's excursion (grades of 6-9 % on a level road
  // in session 25's outside testing). The tolerance is now 5 sds of a step: none dropped, and the grade's error is
  // the filter's noise gain alone. A real glitch, 60 m up for one reading, is still dropped: its step up and back.
  Trace tr = stop_and_go(40, 1.5, 8);
  const ElevationGrade g = grade_from_elevation(tr.t, tr.v, tr.h);
  EXPECT_EQ(g.rejected_steps, 0);
  double worst = 0.0;
  for (double x : g.grade) worst = std::max(worst, std::abs(x));
  EXPECT_LT(worst, 0.04);
  tr.h[2000] += 60.0;
  EXPECT_EQ(grade_from_elevation(tr.t, tr.v, tr.h).rejected_steps, 2);
}

TEST(Elevation, GradeNoiseDrawsHoldTheFiltersErrorOnFreshNoise) {
  // The draws from one recording against the grade's actual error over 40 recordings of the same level road with
  // fresh noise drawn here: the same rms overall, and the same along the trip (the off-centre windows at its ends
  // are noisier than its middle).
  const double sd = 1.2;
  const Trace one = stop_and_go(20, sd, 9);
  const ElevationGrade read = grade_from_elevation(one.t, one.v, one.h);
  const auto draws = grade_noise_draws(one.t, one.v, one.h, read.noise_sd_m, 64, 5u);
  ASSERT_EQ(draws.size(), 64u);
  const std::size_t n = one.t.size();
  std::vector<double> drawn(n, 0.0), actual(n, 0.0);
  for (const auto& d : draws)
    for (std::size_t i = 0; i < n; ++i) drawn[i] += d[i] * d[i] / 64.0;
  for (unsigned k = 0; k < 40; ++k) {
    const Trace fresh = stop_and_go(20, sd, 1000 + k);
    const ElevationGrade g = grade_from_elevation(fresh.t, fresh.v, fresh.h);
    for (std::size_t i = 0; i < n; ++i) actual[i] += g.grade[i] * g.grade[i] / 40.0;
  }
  auto rms = [&](const std::vector<double>& var, std::size_t from, std::size_t to) {
    double s = 0.0;
    for (std::size_t i = from; i < to; ++i) s += var[i];
    return std::sqrt(s / static_cast<double>(to - from));
  };
  EXPECT_NEAR(rms(drawn, 0, n), rms(actual, 0, n), 0.1 * rms(actual, 0, n));
  EXPECT_NEAR(rms(drawn, 0, 20), rms(actual, 0, 20), 0.2 * rms(actual, 0, 20));  // the trip's first 300 m
  EXPECT_NEAR(rms(drawn, n / 2 - 110, n / 2), rms(actual, n / 2 - 110, n / 2), 0.2 * rms(actual, n / 2 - 110, n / 2));
  EXPECT_GT(rms(actual, 0, 20), 1.5 * rms(actual, n / 2 - 110, n / 2));  // the ends are noisier: a real check
  EXPECT_TRUE(grade_noise_draws(one.t, one.v, one.h, 0.0, 64, 5u).empty());
}


TEST(Elevation, EachSamplesGradeIsItsSegmentsMeanGrade) {
  // The replay holds a sample's grade over its segment to the next, so the grade must be that segment's mean, read at
  // its middle along the road. Read at the sample it lagged by half a segment (10 m at 20 m/s and 1 Hz), and a
  // noise-free hilly null read 13 x its floor (session 26's outside testing). A 1 km hill 20 m high at 1 Hz.
  std::vector<double> t, v, h;
  for (int i = 0; i <= 1500; ++i) {
    t.push_back(i);
    v.push_back(20.0);
    h.push_back(150.0 + 20.0 * std::sin(kTwoPi * 20.0 * i / 1000.0));
  }
  const ElevationGrade g = grade_from_elevation(t, v, h);
  double ss = 0.0, ss_start = 0.0;
  int count = 0;
  for (std::size_t i = 100; i + 100 < t.size(); ++i) {
    const double mean_sine = (h[i + 1] - h[i]) / 20.0;  // the segment's rise over its road length
    const double mean = mean_sine / std::sqrt(1.0 - mean_sine * mean_sine);
    const double at_start = 20.0 * kTwoPi / 1000.0 * std::cos(kTwoPi * 20.0 * i / 1000.0);
    ss += (g.grade[i] - mean) * (g.grade[i] - mean);
    ss_start += (at_start - mean) * (at_start - mean);
    ++count;
  }
  EXPECT_LT(std::sqrt(ss / count), 0.001);       // 0.1 % of grade
  EXPECT_GT(std::sqrt(ss_start / count), 0.005);  // what reading it at the sample missed by: a real check
}


TEST(Elevation, ALostFixIsBridgedAlongTheRoad) {
  // 15 readings of 0 ("no fix") on a 2 km hill 10 m high at 20 m/s: the road goes on climbing under them. Held level,
  // the run flattened 300 m of hill (session 26's outside testing); bridged, the grade there is the chord's.
  std::vector<double> t, v, h;
  for (int i = 0; i <= 600; ++i) {
    t.push_back(i);
    v.push_back(20.0);
    h.push_back(150.0 + 10.0 * std::sin(kTwoPi * 20.0 * i / 2000.0 - 0.44));
  }
  auto clean_h_at = [&](int i) { return 150.0 + 10.0 * std::sin(kTwoPi * 20.0 * i / 2000.0 - 0.44); };
  for (int i = 300; i < 315; ++i) h[static_cast<std::size_t>(i)] = 0.0;
  const ElevationGrade g = grade_from_elevation(t, v, h);
  EXPECT_EQ(g.rejected_steps, 1);  // the drop; the return is taken from the last good reading
  // The climb booked from 200 m before the gap to 200 m after it (each grade over its 20 m segment) against the
  // road's: held level, the gap's own 9 m were missing.
  double booked = 0.0;
  for (std::size_t i = 290; i < 325; ++i) booked += 20.0 * g.grade[i] / std::sqrt(1.0 + g.grade[i] * g.grade[i]);
  const double road = h[325] - h[290], gap = clean_h_at(315) - clean_h_at(300);
  EXPECT_GT(std::abs(gap), 5.0);
  EXPECT_NEAR(booked, road, 0.1 * std::abs(gap));
}

// Standing, the road does not move, so the readings' spread is the GPS's: its white noise alone, or several times
// that where the altitude drifts over tens of seconds (AR(1), 30 s, 3 m here, seen in 20 s stops), which the
// filter takes for road.
ElevationGrade wandering_trace(bool drift, int per_second, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  Trace tr = stop_and_go(30, 0.0, 1, per_second);
  double a = 0.0;
  const double phi = std::exp(-1.0 / (30.0 * per_second));
  for (auto& x : tr.h) {
    a = phi * a + 3.0 * std::sqrt(1.0 - phi * phi) * n(rng);
    x += 0.5 * n(rng) + (drift ? a : 0.0);
  }
  return grade_from_elevation(tr.t, tr.v, tr.h);
}

TEST(Elevation, AWanderingAltitudeShowsAtStandstills) {
  auto trace = [](bool drift) {
    std::mt19937 rng(12);
    std::normal_distribution<double> n(0.0, 1.0);
    Trace tr = stop_and_go(30, 0.0, 1);
    double a = 0.0;
    const double phi = std::exp(-1.0 / 30.0);
    for (auto& x : tr.h) {
      a = phi * a + 3.0 * std::sqrt(1.0 - phi * phi) * n(rng);
      x += 0.5 * n(rng) + (drift ? a : 0.0);
    }
    return grade_from_elevation(tr.t, tr.v, tr.h);
  };
  const ElevationGrade white = trace(false), drifting = trace(true);
  EXPECT_GT(white.standing_s, 500.0);  // thirty 20 s stops
  EXPECT_NEAR(white.standing_wander_m, white.noise_sd_m, 0.15 * white.noise_sd_m);
  EXPECT_GT(drifting.standing_wander_m, 1.5 * drifting.noise_sd_m + 0.2);
  // The drift, from how the standstills' differences grow with their time apart: 20 s stops see its start only (a
  // rate of 2 sd^2 / time, 0.6 m^2/s here), so the sd and time are not each the truth's; the rate within a factor 2.
  EXPECT_LT(white.drift_sd_m, 0.3);
  const double rate = 2.0 * drifting.drift_sd_m * drifting.drift_sd_m / drifting.drift_time_s;
  EXPECT_GT(rate, 0.3);
  EXPECT_LT(rate, 1.2);
}

TEST(Elevation, AWanderingAltitudeLoggedAtTenHertzIsReadOverTheSameSeconds) {
  // The drift is a process in time: at 10 Hz its fit must see the same tens of seconds of lag as at 1 Hz, not 60
  // samples (6 s, where it read this 3 m, 30 s drift as 9-18 m over 300 s). Over eight noise draws, as at 1 Hz: the
  // rate 2 sd^2 / time within a factor 2 of the truth's 0.6 m^2/s, the sd below 1.5 x the truth (20 s stops see the
  // drift's start only, so neither sd nor time is the truth's alone).
  std::vector<double> rate, sd;
  for (unsigned seed = 1; seed <= 8; ++seed) {
    const ElevationGrade white = wandering_trace(false, 10, seed), drifting = wandering_trace(true, 10, seed);
    EXPECT_GT(drifting.standing_wander_m, 1.5 * drifting.noise_sd_m + 0.2);
    EXPECT_LT(white.drift_sd_m, 0.3);
    EXPECT_LE(drifting.drift_time_s, 60.0);
    rate.push_back(2.0 * drifting.drift_sd_m * drifting.drift_sd_m / drifting.drift_time_s);
    sd.push_back(drifting.drift_sd_m);
  }
  EXPECT_GT(median(rate), 0.3);
  EXPECT_LT(median(rate), 1.2);
  EXPECT_LT(*std::max_element(sd.begin(), sd.end()), 4.5);
}

// The typical sample interval the drift's lags and the speed lattice are read in: a gap does not move it.
TEST(Statistics, MedianStepIsTheTypicalSampleInterval) {
  EXPECT_DOUBLE_EQ(median_step({0.0, 1.0, 2.0, 30.0, 31.0, 32.0}), 1.0);
  EXPECT_DOUBLE_EQ(median_step({0.0, 0.1, 0.2, 0.3}), 0.1);
  EXPECT_TRUE(std::isnan(median_step({5.0})));
}

}  // namespace
}  // namespace rollsim
