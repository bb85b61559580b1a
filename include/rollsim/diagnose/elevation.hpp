// Road grade from a recorded (GPS) elevation: jumps rejected, the profile filtered over distance, then derived.
#pragma once

#include <vector>

namespace rollsim {

/// Fixed in advance for GPS altitude (1 m resolution, glitches of tens to hundreds of metres, 0 for "no fix").
struct ElevationGradeOptions {
  double max_step_grade = 0.20;     ///< a step steeper than this over the distance covered is a glitch
  double step_tolerance_m = 5.0;    ///< allowed on top (1 m resolution, metre noise: 3.5 sd of a step)
  double grid_m = 5.0;              ///< distance grid the profile is averaged onto
  double filter_length_m = 200.0;   ///< moving-average length over distance (GPS noise is metres over ~100 m)
  double max_grade = 0.15;          ///< public roads: anything steeper is residual noise
};

struct ElevationGrade {
  std::vector<double> grade;  ///< rise over run, per sample
  int rejected_steps = 0;     ///< elevation steps treated as glitches
};

/// Grade per sample from elevation: distance from the speed (trapezoid); each sample-to-sample elevation step
/// steeper than max_grade_step over its distance (plus tolerance) is dropped (a glitch shifts nothing after it);
/// the corrected profile is averaged on a distance grid, smoothed by a moving average over filter_length_m, and
/// differentiated over +-filter_length_m / 2. Standing still keeps the grade of where the car stands.
ElevationGrade grade_from_elevation(const std::vector<double>& time_s, const std::vector<double>& speed_mps,
                                    const std::vector<double>& elevation_m, const ElevationGradeOptions& opt = {});

}  // namespace rollsim
