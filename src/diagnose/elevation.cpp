// Road grade from recorded elevation: glitch rejection, distance-domain filtering, derivative over distance.
#include "rollsim/diagnose/elevation.hpp"

#include <algorithm>
#include <cmath>

namespace rollsim {

ElevationGrade grade_from_elevation(const std::vector<double>& time_s, const std::vector<double>& speed_mps,
                                    const std::vector<double>& elevation_m, const ElevationGradeOptions& opt) {
  const std::size_t n = time_s.size();
  ElevationGrade out;
  out.grade.assign(n, 0.0);
  if (n < 2 || speed_mps.size() != n || elevation_m.size() != n) return out;
  std::vector<double> s(n, 0.0), h(n, elevation_m[0]);
  for (std::size_t i = 1; i < n; ++i) {
    const double ds = 0.5 * (speed_mps[i] + speed_mps[i - 1]) * (time_s[i] - time_s[i - 1]);
    s[i] = s[i - 1] + ds;
    const double dh = elevation_m[i] - elevation_m[i - 1];
    // A step no road could climb over that distance is a GPS glitch: drop the step, so an offset glitch does not
    // shift the rest of the trip and a spike (up then down) vanishes.
    if (std::abs(dh) > opt.max_step_grade * ds + opt.step_tolerance_m) {
      h[i] = h[i - 1];
      ++out.rejected_steps;
    } else {
      h[i] = h[i - 1] + dh;
    }
  }
  const double total = s.back();
  if (total < 2.0 * opt.grid_m) return out;
  // Average onto a distance grid: standing still gives many samples at one place, which must weigh as one place.
  const std::size_t cells = static_cast<std::size_t>(std::floor(total / opt.grid_m)) + 1;
  std::vector<double> sum(cells, 0.0), count(cells, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = std::min(cells - 1, static_cast<std::size_t>(s[i] / opt.grid_m));
    sum[c] += h[i];
    count[c] += 1.0;
  }
  std::vector<double> prof(cells, 0.0);
  std::size_t last = cells;  // last filled cell
  for (std::size_t c = 0; c < cells; ++c) {
    if (count[c] == 0.0) continue;
    prof[c] = sum[c] / count[c];
    if (last == cells) {
      for (std::size_t k = 0; k < c; ++k) prof[k] = prof[c];
    } else {
      for (std::size_t k = last + 1; k < c; ++k)
        prof[k] = prof[last] + (prof[c] - prof[last]) * static_cast<double>(k - last) / static_cast<double>(c - last);
    }
    last = c;
  }
  for (std::size_t k = last + 1; k < cells; ++k) prof[k] = prof[last];
  // Moving average over distance (prefix sums), window shrinking at the ends.
  const auto half = static_cast<std::ptrdiff_t>(std::max(1.0, std::round(0.5 * opt.filter_length_m / opt.grid_m)));
  std::vector<double> prefix(cells + 1, 0.0);
  for (std::size_t c = 0; c < cells; ++c) prefix[c + 1] = prefix[c] + prof[c];
  std::vector<double> smooth(cells);
  const auto nc = static_cast<std::ptrdiff_t>(cells);
  for (std::ptrdiff_t c = 0; c < nc; ++c) {
    const std::ptrdiff_t a = std::max<std::ptrdiff_t>(0, c - half), b = std::min(nc - 1, c + half);
    smooth[static_cast<std::size_t>(c)] = (prefix[static_cast<std::size_t>(b + 1)] - prefix[static_cast<std::size_t>(a)]) / static_cast<double>(b - a + 1);
  }
  // Derivative over +-half the filter length: a central difference over a short baseline would turn metre-level
  // noise left in the averaged profile into grade noise of a few per cent.
  std::vector<double> g(cells, 0.0);
  for (std::ptrdiff_t c = 0; c < nc; ++c) {
    const std::ptrdiff_t a = std::max<std::ptrdiff_t>(0, c - half), b = std::min(nc - 1, c + half);
    if (b > a)
      g[static_cast<std::size_t>(c)] = std::clamp((smooth[static_cast<std::size_t>(b)] - smooth[static_cast<std::size_t>(a)]) /
                                                      (static_cast<double>(b - a) * opt.grid_m),
                                                  -opt.max_grade, opt.max_grade);
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
