// A recorded speed's resolution: a channel on a lattice of a few hundredths of a m/s read as a staircase, and the
// staircase undone where its steps are steep enough to fake accelerations.
#pragma once

#include <vector>

namespace rollsim {

struct SpeedResolution {
  double quantum_mps = 0.0;       ///< the lattice the speeds lie on (0: none found)
  double step_accel_mps2 = 0.0;   ///< one quantum over the median sample interval: the acceleration a step fakes
  bool smoothed = false;          ///< the staircase was replaced (step_accel_mps2 at or above the threshold)
  int half_window = 0;            ///< the smoothing's half width [samples] where smoothed
  std::vector<double> speed_mps;  ///< the speeds the replay should follow (the recorded ones unless smoothed)
};

/// Where the speeds lie on a lattice (95 % of them within 2 % of a quantum of a multiple of the smallest non-zero
/// step) and one quantum per sample interval is at least `threshold_mps2`, each moving sample's speed is a
/// quadratic's value fitted over the fewest samples either side that leave the rounding under 0.02 m/s^2 of
/// acceleration noise (Savitzky-Golay; shortened at the ends); standstills stay exactly zero. A 0.1 km/h channel at
/// 10 Hz steps by 0.28 m/s^2 within a sample, which a replay turns into power spikes an engine's fuel cut-off does not
/// average out.
SpeedResolution read_speed_resolution(const std::vector<double>& time_s, const std::vector<double>& speed_mps,
                                      double threshold_mps2 = 0.1);

}  // namespace rollsim
