// Road grade from a recorded (GPS) elevation: jumps rejected, the profile filtered over distance, then derived.
#pragma once

#include <cstddef>
#include <vector>

namespace rollsim {

/// Fixed in advance for GPS altitude (1 m resolution, glitches of tens to hundreds of metres, 0 for "no fix").
struct ElevationGradeOptions {
  double max_step_grade = 0.20;     ///< a step steeper than this over the distance covered is a glitch
  double step_tolerance_m = 5.0;    ///< allowed on top (1 m resolution, metre noise: 3.5 sd of a step); at least
                                    ///< 5 sds of a step where the readings' own noise is larger
  double grid_m = 5.0;              ///< distance grid the profile is averaged onto
  /// Savitzky-Golay window over distance: a cubic's slope over 300 m keeps 99.84 % of a 1 km hill's grade (99.97 % at
  /// 1.5 km); white elevation noise of 1 m per 5 m cell becomes grade noise of 0.36 % sd (docs/diagnose.md).
  double filter_length_m = 300.0;
  double max_grade = 0.15;          ///< public roads: anything steeper is residual noise
};

struct ElevationGrade {
  std::vector<double> grade;  ///< rise over run, per sample: over its segment to the next (read at its middle)
  int rejected_steps = 0;     ///< elevation steps treated as glitches
  /// White noise on each reading about the road [m], from each moving reading's deviation from the line through its
  /// neighbours along the road (what a GPS altitude jitters by from fix to fix; noise correlated over tens of seconds
  /// looks like the road and is not in it).
  double noise_sd_m = 0.0;
  int noise_triples = 0;  ///< readings it is estimated from
  /// How far the readings wander while the car stands for 20 s or more [m]: the rms about each standstill's mean,
  /// pooled. White noise wanders by its own sd; a GPS altitude drifting over tens of seconds (noise this module does
  /// not carry) by several times that.
  double standing_wander_m = 0.0;
  double standing_s = 0.0;  ///< the standstills' time it is estimated from
  /// Standing time below which the wander says too little to estimate a drift (three lights' worth) [s].
  static constexpr double kMinStandingForDrift_s = 60.0;
  /// The readings' drift, an AR(1) in time of this sd and correlation time, from how the standstills' differences
  /// between readings grow with their time apart (up to 60 s) beyond twice the white noise's variance: 2 sd^2
  /// (1 - exp(-dt / time)), least squares over a grid of times (0 without 60 s of standstills of 20 s or more).
  double drift_sd_m = 0.0;
  double drift_time_s = 0.0;
};

/// Grade per sample from elevation: distance from the speed (trapezoid); each sample-to-sample elevation step
/// steeper than max_grade_step over its distance (plus tolerance) is dropped (a glitch shifts nothing after it);
/// the corrected profile is averaged on a distance grid and differentiated by a least-squares cubic over
/// filter_length_m (Savitzky-Golay; off-centre at the ends), the slope along the road taken as the sine of the
/// road's angle and the grade given as its tangent. Standing still keeps the grade of where the car stands, and an
/// elevation that drifts while the car stands (a GPS re-fix at a light) is one place's, not a climb. Used by the
/// diagnosis for recordings and by the cycle reader for an `elevation_m` column.
/// Weights w_j, j = first..last, such that sum_j w_j y_j is the slope at j = 0 (per grid step) of the least-squares
/// cubic through the points (j, y_j) (a lower order where there are under four points). Symmetric windows give the
/// Savitzky-Golay first-derivative filter.
std::vector<double> cubic_slope_weights(std::ptrdiff_t first, std::ptrdiff_t last);

ElevationGrade grade_from_elevation(const std::vector<double>& time_s, const std::vector<double>& speed_mps,
                                    const std::vector<double>& elevation_m, const ElevationGradeOptions& opt = {});

/// The grade's errors that white noise of `noise_sd_m` on each reading makes, by Monte Carlo through the same filter:
/// per draw, per sample, the grade of the corrected profile with fresh noise on its moving readings (a standstill's
/// or a dropped glitch's copy keeps its source's) less its grade without. Glitches are dropped where the recording's
/// own were, so the draws carry the filter's noise gain, not more glitches. Empty without noise or samples.
/// With a drift (`drift_sd_m`, `drift_time_s`), an AR(1) in time is added to each reading too (it goes on during
/// standstills, whose readings are not used: the step after a stop carries what it drifted).
std::vector<std::vector<double>> grade_noise_draws(const std::vector<double>& time_s, const std::vector<double>& speed_mps,
                                                   const std::vector<double>& elevation_m, double noise_sd_m, int draws,
                                                   unsigned seed, double drift_sd_m = 0.0, double drift_time_s = 0.0,
                                                   const ElevationGradeOptions& opt = {});

}  // namespace rollsim
