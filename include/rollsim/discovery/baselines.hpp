// The discovery benchmark's sparse-regression baseline: what a SINDy user without the physics catalogue would name.
#pragma once

#include <string>
#include <vector>

#include "rollsim/recording/recording.hpp"
#include "rollsim/vehicle/vehicle.hpp"

namespace rollsim {

/// The sparse-regression baseline on one recording: sequential thresholded least squares on window integrals of
/// {1, v, v^2, v^3, a, a v} beside the simulated energy; returns the catalogue ids its selected non-calibration
/// terms map to, largest contribution first ("mass|rotational_inertia" for the inertial term a v). A term is dropped
/// when its contribution is below `threshold` times the measured energy's norm. The measured channel is the
/// recording's battery power, fuel rate (as fuel power) or SOC (window differences x capacity); `window_s` is the
/// window length (the diagnosis lengthens it for a quantised SOC).
std::vector<std::string> sparse_regression_discovery(const Vehicle& vehicle, const Recording& rec, double window_s = 60.0,
                                                     double threshold = 0.01);

/// The thresholds the scorecard sweeps the sparse baseline over (0.003, 0.01, 0.03, 0.1).
const std::vector<double>& sparse_thresholds();

/// The sparse baseline at every threshold of sparse_thresholds(), and at the threshold BIC picks on this recording.
struct SparseSweep {
  std::vector<std::vector<std::string>> by_threshold;  ///< per sparse_thresholds() entry
  std::vector<std::string> bic;                        ///< at the BIC-chosen threshold
  double bic_threshold = 0.0;
};
SparseSweep sparse_regression_sweep(const Vehicle& vehicle, const Recording& rec, double window_s = 60.0);

}  // namespace rollsim
