// Road grade from recorded elevation: glitch rejection, then a Savitzky-Golay (cubic) derivative over distance.
#include "rollsim/cycle/elevation.hpp"

#include <algorithm>
#include <cmath>

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
}  // namespace

ElevationGrade grade_from_elevation(const std::vector<double>& time_s, const std::vector<double>& speed_mps,
                                    const std::vector<double>& elevation_m, const ElevationGradeOptions& opt) {
  const std::size_t n = time_s.size();
  ElevationGrade out;
  out.grade.assign(n, 0.0);
  if (n < 2 || speed_mps.size() != n || elevation_m.size() != n) return out;
  std::vector<double> s(n, 0.0), h(n, elevation_m[0]);
  // Each step is read from the last sample the car had moved to (`ref`), not the previous one: while it stands the
  // elevation cannot change, so a GPS drifting 6 m in small steps during a stop and snapping back as it moves off was
  // booked as a 6 m climb per stop, the snap-back being the one step dropped as a glitch (11 % more energy on a level
  // route with six stops: session 23's outside testing).
  std::size_t ref = 0;
  for (std::size_t i = 1; i < n; ++i) {
    const double ds = 0.5 * (speed_mps[i] + speed_mps[i - 1]) * (time_s[i] - time_s[i - 1]);
    s[i] = s[i - 1] + ds;
    if (s[i] - s[ref] < kStandingStep_m) {
      h[i] = h[i - 1];
      continue;
    }
    const double dh = elevation_m[i] - elevation_m[ref];
    // A step no road could climb over that distance is a GPS glitch: drop the step, so an offset glitch does not
    // shift the rest of the trip and a spike (up then down) vanishes.
    if (std::abs(dh) > opt.max_step_grade * (s[i] - s[ref]) + opt.step_tolerance_m) {
      h[i] = h[i - 1];
      ++out.rejected_steps;
    } else {
      h[i] = h[i - 1] + dh;
    }
    ref = i;
  }
  const double total = s.back();
  if (total < 2.0 * opt.grid_m) return out;
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
  for (std::size_t i = 0; i < n; ++i) {
    const double x = s[i] / opt.grid_m;  // cell centres are at (c + 0.5) grid; interpolate between them
    const double u = std::clamp(x - 0.5, 0.0, static_cast<double>(cells - 1));
    const auto c0 = static_cast<std::size_t>(std::floor(u));
    const std::size_t c1 = std::min(cells - 1, c0 + 1);
    const double f = u - static_cast<double>(c0);
    out.grade[i] = (1.0 - f) * g[c0] + f * g[c1];
  }
  return out;
}

}  // namespace rollsim
