// A recorded speed's lattice found from its smallest step; its staircase smoothed by a local quadratic where one step
// per sample is a real acceleration's size.
#include "rollsim/cycle/speed_resolution.hpp"

#include <algorithm>
#include <cmath>

#include "rollsim/common/statistics.hpp"

namespace rollsim {
namespace {

// The smallest non-zero step, if the moving speeds lie on its lattice (rounding in a unit conversion allowed for;
// standstills, on every lattice, are not counted).
double lattice_quantum(const std::vector<double>& v) {
  double q = 0.0;
  for (std::size_t i = 1; i < v.size(); ++i) {
    const double d = std::abs(v[i] - v[i - 1]);
    if (d > 1e-9 && (q == 0.0 || d < q)) q = d;
  }
  if (!(q > 0.0)) return 0.0;
  std::size_t on = 0, moving = 0;
  for (double x : v) {
    if (x == 0.0) continue;
    ++moving;
    on += std::abs(x / q - std::round(x / q)) < 0.02;
  }
  return moving > 0 && static_cast<double>(on) >= 0.95 * static_cast<double>(moving) ? q : 0.0;
}

}  // namespace

SpeedResolution read_speed_resolution(const std::vector<double>& time_s, const std::vector<double>& speed_mps,
                                      double threshold_mps2) {
  SpeedResolution out;
  out.speed_mps = speed_mps;
  const std::size_t n = std::min(time_s.size(), speed_mps.size());
  if (n < 3) return out;
  out.quantum_mps = lattice_quantum(speed_mps);
  const double dt = median_step(time_s);
  if (!(out.quantum_mps > 0.0) || !(dt > 0.0)) return out;
  out.step_accel_mps2 = out.quantum_mps / dt;
  if (out.step_accel_mps2 < threshold_mps2) return out;
  // A quadratic's value over 2 h + 1 samples: the rounding (uniform, sd q / sqrt 12) leaves a local slope's noise of
  // (q / dt) / 2 sqrt(1 / (h (h + 1)(2h + 1))); h is the least that brings it under kResidualStepAccel_mps2 (3: 0.7 s
  // at 10 Hz for 0.1 km/h, 7 s at 1 Hz for whole km/h).
  constexpr double kResidualStepAccel_mps2 = 0.02;
  int h = 1;
  while (h < 50 && 0.5 * out.step_accel_mps2 * std::sqrt(1.0 / (h * (h + 1.0) * (2.0 * h + 1.0))) > kResidualStepAccel_mps2) ++h;
  out.half_window = h;
  for (std::size_t i = 0; i < n; ++i) {
    if (speed_mps[i] == 0.0) continue;  // a standstill stays exactly zero
    // Symmetric, shortened at the trip's ends: the quadratic Savitzky-Golay smoothing weights.
    const auto hi = static_cast<int>(std::min<std::size_t>({static_cast<std::size_t>(h), i, n - 1 - i}));
    if (hi == 0) continue;
    const double m = hi, norm = (2.0 * m - 1.0) * (2.0 * m + 1.0) * (2.0 * m + 3.0);
    double v = 0.0;
    for (int j = -hi; j <= hi; ++j)
      v += (3.0 * (3.0 * m * m + 3.0 * m - 1.0) - 15.0 * j * j) / norm * speed_mps[static_cast<std::size_t>(static_cast<int>(i) + j)];
    out.speed_mps[i] = std::max(0.0, v);
  }
  out.smoothed = true;
  return out;
}

}  // namespace rollsim
