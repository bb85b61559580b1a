// Road grade from recorded elevation: glitch rejection, then a Savitzky-Golay (cubic) derivative over distance.
#include "rollsim/cycle/elevation.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "rollsim/common/statistics.hpp"

namespace rollsim {

std::vector<double> cubic_slope_weights(std::ptrdiff_t first, std::ptrdiff_t last) {
  const auto count = static_cast<std::size_t>(std::max<std::ptrdiff_t>(0, last - first + 1));
  std::vector<double> w(count, 0.0);
  if (count < 2) return w;
  const std::size_t terms = std::min<std::size_t>(4, count);  // a cubic, or the highest order the points allow
  // Normal equations in u = k / scale (well conditioned): the slope at k = 0 is b1 / scale.
  const double scale = static_cast<double>(std::max(std::abs(first), std::abs(last)));
  double a[4][5] = {};
  for (std::ptrdiff_t k = first; k <= last; ++k) {
    const double u = static_cast<double>(k) / scale;
    double pu[4] = {1.0, u, u * u, u * u * u};
    for (std::size_t r = 0; r < terms; ++r)
      for (std::size_t c = 0; c < terms; ++c) a[r][c] += pu[r] * pu[c];
  }
  a[1][terms] = 1.0;  // solve A x = e1: then the weight of point k is sum_p x_p u_k^p
  for (std::size_t i = 0; i < terms; ++i) {  // Gauss-Jordan; A is symmetric positive definite
    for (std::size_t r = 0; r < terms; ++r) {
      if (r == i) continue;
      const double f = a[r][i] / a[i][i];
      for (std::size_t c = i; c <= terms; ++c) a[r][c] -= f * a[i][c];
    }
  }
  double x[4] = {};
  for (std::size_t i = 0; i < terms; ++i) x[i] = a[i][terms] / a[i][i];
  for (std::size_t j = 0; j < count; ++j) {
    const double u = static_cast<double>(first + static_cast<std::ptrdiff_t>(j)) / scale;
    w[j] = (x[0] + u * (x[1] + u * (x[2] + u * x[3]))) / scale;
  }
  return w;
}

namespace {
// Less than this of road since the last sample the car had moved to: standing (a creep of 0.36 km/h at 1 Hz moves it).
constexpr double kStandingStep_m = 0.1;

// The recorded elevation along the distance the speed gives, its glitches dropped.
struct CorrectedProfile {
  std::vector<double> s_m, h_m;
  std::vector<char> own_reading;  // the sample's elevation is its own reading (not a standstill's or a glitch's copy)
  int rejected_steps = 0;
};

CorrectedProfile corrected_profile(const std::vector<double>& time_s, const std::vector<double>& speed_mps,
                                   const std::vector<double>& elevation_m, const ElevationGradeOptions& opt) {
  const std::size_t n = time_s.size();
  CorrectedProfile p;
  p.s_m.assign(n, 0.0);
  p.h_m.assign(n, elevation_m[0]);
  p.own_reading.assign(n, 0);
  p.own_reading[0] = 1;
  // Each step is read from the last sample the car had moved to (`ref`), not the previous one: while it stands the
  // elevation cannot change, so a GPS drifting 6 m in small steps during a stop and snapping back as it moves off was
  // booked as a 6 m climb per stop, the snap-back being the one step dropped as a glitch (11 % more energy on a level
  // route with six stops: session 23's outside testing).
  std::size_t ref = 0;
  bool no_fix = false;  // within a run of "0 = no fix" readings that began with a dropped step; ref is the last good
  for (std::size_t i = 1; i < n; ++i) {
    const double ds = 0.5 * (speed_mps[i] + speed_mps[i - 1]) * (time_s[i] - time_s[i - 1]);
    p.s_m[i] = p.s_m[i - 1] + ds;
    if (no_fix && elevation_m[i] == 0.0) {
      p.h_m[i] = p.h_m[i - 1];
      continue;
    }
    if (p.s_m[i] - p.s_m[ref] < kStandingStep_m) {
      p.h_m[i] = p.h_m[i - 1];
      continue;
    }
    const double dh = elevation_m[i] - elevation_m[ref];
    // A step no road could climb over that distance is a GPS glitch: drop the step, so an offset glitch does not
    // shift the rest of the trip and a spike (up then down) vanishes.
    if (std::abs(dh) > opt.max_step_grade * (p.s_m[i] - p.s_m[ref]) + opt.step_tolerance_m) {
      p.h_m[i] = p.h_m[i - 1];
      ++p.rejected_steps;
      // A drop to exactly 0 is a lost fix: the road goes on under it, so the readings after it are taken from the last
      // good one and the run is bridged along the road. Held level, a 15 s run flattened 130-250 m of hill (session
      // 26's outside testing).
      if (!no_fix && elevation_m[i] == 0.0) {
        no_fix = true;
        continue;
      }
    } else if (no_fix) {
      const double h0 = p.h_m[ref], s0 = p.s_m[ref], h1 = p.h_m[ref] + dh;
      for (std::size_t k = ref + 1; k <= i; ++k) p.h_m[k] = h0 + (h1 - h0) * (p.s_m[k] - s0) / (p.s_m[i] - s0);
      p.own_reading[i] = 1;
    } else {
      p.h_m[i] = p.h_m[i - 1] + dh;
      p.own_reading[i] = 1;
    }
    no_fix = false;
    ref = i;
  }
  return p;
}

// The grade per sample of a corrected profile: linear in its elevations but for the tangent and the clamps.
std::vector<double> grade_of_profile(const std::vector<double>& s, const std::vector<double>& h, const ElevationGradeOptions& opt) {
  const std::size_t n = s.size();
  std::vector<double> grade(n, 0.0);
  const double total = s.back();
  if (total < 2.0 * opt.grid_m) return grade;
  // Average onto a distance grid: standing still gives many samples at one place, which must weigh as one place.
  // Each cell's mean elevation is placed at its samples' mean distance, not at its centre, and the profile is read
  // at the centres between those points (beyond the first and last, along the line through the nearest two): a car
  // accelerating through a cell has its samples bunched at the cell's start, which read a constant 5 % climb over a
  // 300 m trip as 4.70-5.10 % and booked 0.56 % less climb than m g dh (session 25's outside testing).
  const std::size_t cells = static_cast<std::size_t>(std::floor(total / opt.grid_m)) + 1;
  std::vector<double> sum_h(cells, 0.0), sum_s(cells, 0.0), count(cells, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = std::min(cells - 1, static_cast<std::size_t>(s[i] / opt.grid_m));
    sum_h[c] += h[i];
    sum_s[c] += s[i];
    count[c] += 1.0;
  }
  std::vector<double> at_s, at_h;  // the filled cells' mean distance and elevation, ascending in distance
  for (std::size_t c = 0; c < cells; ++c) {
    if (count[c] == 0.0) continue;
    at_s.push_back(sum_s[c] / count[c]);
    at_h.push_back(sum_h[c] / count[c]);
  }
  std::vector<double> prof(cells, at_h.front());
  if (at_s.size() > 1) {
    std::size_t k = 0;  // the segment [k, k + 1] of the points that a centre is read on
    for (std::size_t c = 0; c < cells; ++c) {
      const double x = (static_cast<double>(c) + 0.5) * opt.grid_m;
      while (k + 2 < at_s.size() && at_s[k + 1] < x) ++k;
      const double span = at_s[k + 1] - at_s[k];
      prof[c] = span > 0.0 ? at_h[k] + (at_h[k + 1] - at_h[k]) * (x - at_s[k]) / span : at_h[k];
    }
  }
  // Slope of a least-squares cubic over filter_length_m of distance (a Savitzky-Golay derivative): a cubic keeps a
  // hill's curvature, where the moving average it replaces flattened 1.5 km hills by 6 %. The window keeps its
  // length at the ends of the trip, off-centre.
  const auto half = static_cast<std::ptrdiff_t>(std::max(1.0, std::round(0.5 * opt.filter_length_m / opt.grid_m)));
  const auto nc = static_cast<std::ptrdiff_t>(cells);
  const std::vector<double> interior = cubic_slope_weights(-half, half);
  std::vector<double> g(cells, 0.0);
  for (std::ptrdiff_t c = 0; c < nc; ++c) {
    const std::ptrdiff_t a = std::clamp<std::ptrdiff_t>(c - half, 0, std::max<std::ptrdiff_t>(0, nc - 1 - 2 * half));
    const std::ptrdiff_t b = std::min(nc - 1, a + 2 * half);
    const std::vector<double> w = a == c - half && b == c + half ? interior : cubic_slope_weights(a - c, b - c);
    double slope = 0.0;
    for (std::ptrdiff_t j = a; j <= b; ++j) slope += w[static_cast<std::size_t>(j - a)] * prof[static_cast<std::size_t>(j)];
    // The distance is travelled along the road, so the profile's slope over it is the sine of the road's angle;
    // the grade is rise over run, its tangent (0.5 % more at 10 %).
    const double sine = std::clamp(slope / opt.grid_m, -0.99, 0.99);
    g[static_cast<std::size_t>(c)] = std::clamp(sine / std::sqrt(1.0 - sine * sine), -opt.max_grade, opt.max_grade);
  }
  // Each sample's grade is held over its segment to the next (the replay's and the cycle's rule), so it is read at
  // the segment's middle along the road: read at its start it lagged the road by half a sample, 7-15 m at 1 Hz,
  // and a noise-free hilly null read 13 x its floor (session 26's outside testing).
  for (std::size_t i = 0; i < n; ++i) {
    const double mid_m = i + 1 < n ? 0.5 * (s[i] + s[i + 1]) : s[i];
    const double x = mid_m / opt.grid_m;  // cell centres are at (c + 0.5) grid; interpolate between them
    const double u = std::clamp(x - 0.5, 0.0, static_cast<double>(cells - 1));
    const auto c0 = static_cast<std::size_t>(std::floor(u));
    const std::size_t c1 = std::min(cells - 1, c0 + 1);
    const double f = u - static_cast<double>(c0);
    grade[i] = (1.0 - f) * g[c0] + f * g[c1];
  }
  return grade;
}

// White noise on each reading, from each own reading's deviation from the line through its neighbours along the
// road (a road's curvature moves it by under 0.1 m at the spacings taken: a 2 km sag curve's 0.06 m at 30 m).
// Readings further than this apart are not compared: a long gap spans the road's shape, not its noise.
constexpr double kNoiseSpan_m = 150.0;

void estimate_white_noise(const CorrectedProfile& p, ElevationGrade& out) {
  std::vector<std::size_t> own;
  for (std::size_t i = 0; i < p.s_m.size(); ++i)
    if (p.own_reading[i]) own.push_back(i);
  double sum = 0.0;
  int triples = 0;
  for (std::size_t k = 1; k + 1 < own.size(); ++k) {
    const double sa = p.s_m[own[k - 1]], sb = p.s_m[own[k]], sc = p.s_m[own[k + 1]];
    if (!(sc - sa > 0.0) || sc - sa > kNoiseSpan_m) continue;
    const double alpha = (sc - sb) / (sc - sa), beta = (sb - sa) / (sc - sa);
    const double r = p.h_m[own[k]] - alpha * p.h_m[own[k - 1]] - beta * p.h_m[own[k + 1]];
    sum += r * r / (1.0 + alpha * alpha + beta * beta);
    ++triples;
  }
  out.noise_triples = triples;
  out.noise_sd_m = triples > 0 ? std::sqrt(sum / triples) : 0.0;
}

// The corrected profile with a glitch tolerance of at least kGlitchNoiseSds sds of a step's noise: at 1.5 m of
// white noise a step's sd is 2.1 m, and the 5 m tolerance took 1.6 % of the noise's own steps at walking pace for
// glitches; each dropped step shifted the rest of the profile by the noise's excursion, a grade error of up to 8 %
// on a level road (session 25's outside testing). Real glitches are tens to hundreds of metres.
constexpr double kGlitchNoiseSds = 5.0;

CorrectedProfile noise_aware_profile(const std::vector<double>& time_s, const std::vector<double>& speed_mps,
                                     const std::vector<double>& elevation_m, const ElevationGradeOptions& opt,
                                     ElevationGrade& stats) {
  CorrectedProfile p = corrected_profile(time_s, speed_mps, elevation_m, opt);
  estimate_white_noise(p, stats);
  const double tolerance_m = kGlitchNoiseSds * std::sqrt(2.0) * stats.noise_sd_m;
  if (tolerance_m > opt.step_tolerance_m) {
    ElevationGradeOptions wider = opt;
    wider.step_tolerance_m = tolerance_m;
    p = corrected_profile(time_s, speed_mps, elevation_m, wider);
    estimate_white_noise(p, stats);
  }
  stats.rejected_steps = p.rejected_steps;
  return p;
}
}  // namespace

namespace {
// Standstills this long show a wandering GPS altitude (a light's red phase; shorter ones hold too few readings).
constexpr double kWanderStandstill_s = 20.0;

// The drift from the standstills' per-lag sums (squared differences `d2`, times apart `dt`, `pairs`), beyond the white
// noise already in `out`.
void fit_drift(const std::vector<double>& d2, const std::vector<double>& dt, const std::vector<double>& pairs,
               ElevationGrade& out) {
  const std::size_t lags = pairs.size() - 1;
  // D(t) = 2 white^2 + 2 sd^2 (1 - exp(-t / time)): sd^2 by weighted least squares at each time of a grid, the time of
  // least squared misfit kept (weights: the pairs, most at short lags).
  // Times beyond twice the longest lag seen are not tried: short stops show how fast the differences grow, not where
  // they level off, and the least misfit among times they cannot tell apart was a matter of chance (a 3 m, 30 s drift
  // seen in 20 s stops at 10 Hz read 1.7 m over 8 s with one noise draw and 15 m over 300 s with another).
  double longest_lag_s = 0.0;
  for (std::size_t lag = 1; lag <= lags; ++lag)
    if (pairs[lag] > 0.0) longest_lag_s = std::max(longest_lag_s, dt[lag] / pairs[lag]);
  const double white2 = 2.0 * out.noise_sd_m * out.noise_sd_m;
  double best = 1e300;
  for (double time : {2.0, 3.0, 5.0, 8.0, 12.0, 20.0, 30.0, 50.0, 80.0, 120.0, 200.0, 300.0}) {
    if (time > 2.0 * longest_lag_s && time > 2.0) break;
    double sxy = 0.0, sxx = 0.0;
    for (std::size_t lag = 1; lag <= lags; ++lag) {
      if (pairs[lag] == 0.0) continue;
      const double x = 2.0 * (1.0 - std::exp(-dt[lag] / pairs[lag] / time));
      sxy += pairs[lag] * x * (d2[lag] / pairs[lag] - white2);
      sxx += pairs[lag] * x * x;
    }
    const double var = sxx > 0.0 ? std::max(0.0, sxy / sxx) : 0.0;
    double sse = 0.0;
    for (std::size_t lag = 1; lag <= lags; ++lag) {
      if (pairs[lag] == 0.0) continue;
      const double e = d2[lag] / pairs[lag] - white2 - var * 2.0 * (1.0 - std::exp(-dt[lag] / pairs[lag] / time));
      sse += pairs[lag] * e * e;
    }
    if (sse < best) best = sse, out.drift_sd_m = std::sqrt(var), out.drift_time_s = time;
  }
}

void estimate_standing_wander(const std::vector<double>& time_s, const std::vector<double>& speed_mps,
                              const std::vector<double>& elevation_m, ElevationGrade& out) {
  const std::size_t n = time_s.size();
  double ss = 0.0, count = 0.0;
  // Per lag (60 of them, a second apart whatever the logger's rate, so a 10 Hz recording's fit sees the same tens of
  // seconds a 1 Hz one does; it had seen 6 s, and read a 3 m drift as 12 m over 300 s): sums of squared differences,
  // of times apart, and pairs.
  constexpr std::size_t kLags = 60;
  const double sample_s = median_step(time_s);
  const std::size_t stride = sample_s > 0.0 ? std::max<std::size_t>(1, std::lround(1.0 / sample_s)) : 1;
  std::vector<double> d2(kLags + 1, 0.0), dt(kLags + 1, 0.0), pairs(kLags + 1, 0.0);
  std::size_t i = 0;
  while (i < n) {
    if (speed_mps[i] != 0.0) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j + 1 < n && speed_mps[j + 1] == 0.0) ++j;
    if (time_s[j] - time_s[i] >= kWanderStandstill_s) {
      double mean = 0.0;
      for (std::size_t k = i; k <= j; ++k) mean += elevation_m[k] / static_cast<double>(j - i + 1);
      for (std::size_t k = i; k <= j; ++k) ss += (elevation_m[k] - mean) * (elevation_m[k] - mean);
      count += static_cast<double>(j - i);  // one degree of freedom per run for its mean
      out.standing_s += time_s[j] - time_s[i];
      for (std::size_t lag = 1; lag <= kLags; ++lag)
        for (std::size_t k = i; k + lag * stride <= j; ++k) {
          const double d = elevation_m[k + lag * stride] - elevation_m[k];
          d2[lag] += d * d, dt[lag] += time_s[k + lag * stride] - time_s[k], pairs[lag] += 1.0;
        }
    }
    i = j + 1;
  }
  out.standing_wander_m = count > 0.0 ? std::sqrt(ss / count) : 0.0;
  if (out.standing_s >= ElevationGrade::kMinStandingForDrift_s) fit_drift(d2, dt, pairs, out);
}
}  // namespace

ElevationGrade grade_from_elevation(const std::vector<double>& time_s, const std::vector<double>& speed_mps,
                                    const std::vector<double>& elevation_m, const ElevationGradeOptions& opt) {
  const std::size_t n = time_s.size();
  ElevationGrade out;
  out.grade.assign(n, 0.0);
  if (n < 2 || speed_mps.size() != n || elevation_m.size() != n) return out;
  const CorrectedProfile p = noise_aware_profile(time_s, speed_mps, elevation_m, opt, out);
  out.grade = grade_of_profile(p.s_m, p.h_m, opt);
  estimate_standing_wander(time_s, speed_mps, elevation_m, out);
  return out;
}

std::vector<std::vector<double>> grade_noise_draws(const std::vector<double>& time_s, const std::vector<double>& speed_mps,
                                                   const std::vector<double>& elevation_m, double noise_sd_m, int draws,
                                                   unsigned seed, double drift_sd_m, double drift_time_s,
                                                   const ElevationGradeOptions& opt) {
  const std::size_t n = time_s.size();
  const bool drift = drift_sd_m > 0.0 && drift_time_s > 0.0;
  if (n < 2 || speed_mps.size() != n || elevation_m.size() != n || !(noise_sd_m > 0.0 || drift) || draws < 1) return {};
  ElevationGrade stats;
  const CorrectedProfile p = noise_aware_profile(time_s, speed_mps, elevation_m, opt, stats);
  const std::vector<double> clean = grade_of_profile(p.s_m, p.h_m, opt);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::vector<std::vector<double>> out;
  std::vector<double> h(n);
  for (int d = 0; d < draws; ++d) {
    double e = 0.0, walk = drift ? drift_sd_m * unit(rng) : 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      if (i > 0 && drift) {
        const double phi = std::exp(-std::max(0.0, time_s[i] - time_s[i - 1]) / drift_time_s);
        walk = phi * walk + drift_sd_m * std::sqrt(1.0 - phi * phi) * unit(rng);
      }
      if (p.own_reading[i]) e = noise_sd_m * unit(rng) + walk;  // a copy (standing, a glitch dropped) keeps its source's
      h[i] = p.h_m[i] + e;
    }
    std::vector<double> g = grade_of_profile(p.s_m, h, opt);
    for (std::size_t i = 0; i < n; ++i) g[i] -= clean[i];
    out.push_back(std::move(g));
  }
  return out;
}

}  // namespace rollsim
