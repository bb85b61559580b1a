// Road load as the vehicle sees it: rolling resistance and aerodynamic drag as speed quadratics at a grade.
#pragma once

#include <cmath>
#include <memory>
#include <string>

namespace rollsim {

/// Resistive forces of the whole car at one grade. Rolling: f0 + f1 v + f2 v^2 for v > 0 and zero at
/// standstill (the tyre model has no rolling loss at V = 0); aero: c v^2.
struct RoadLoadCoeffs {
  double rolling_f0_n = 0.0;
  double rolling_f1_n_s_per_m = 0.0;
  double rolling_f2_n_s2_per_m2 = 0.0;
  double aero_n_s2_per_m2 = 0.0;

  double rolling_n(double speed_mps) const {
    return speed_mps > 0.0 ? rolling_f0_n + speed_mps * (rolling_f1_n_s_per_m + speed_mps * rolling_f2_n_s2_per_m2)
                           : 0.0;
  }
  double aero_n(double speed_mps) const { return aero_n_s2_per_m2 * speed_mps * std::abs(speed_mps); }
};

/// The vehicle's only view of its tyres: a source of road-load coefficients at a grade (normal loads change
/// with the grade's cosine). Implementations: the tyre model on each wheel, or published coast-down
/// coefficients.
class RoadLoadModel {
 public:
  virtual ~RoadLoadModel() = default;
  virtual RoadLoadCoeffs at_grade(double grade) const = 0;
  /// One line for reports, e.g. "tyre model: 4 x nominal" or "coast-down A/B/C".
  virtual std::string describe() const = 0;
  /// What its rolling term (the RoadLoadCoeffs' rolling part) holds, for an energy table's row.
  virtual std::string rolling_term() const = 0;
};

}  // namespace rollsim
