// An empirical maker calibration beside the physics: how far each make's cars on each cycle sit from the model,
// learned on the fitting half and judged on models it never saw.
//
// It explains nothing. The list does not say which shift map, stop-start strategy or electric drive (induction or
// permanent magnet, one or two speeds) a car has; a make's other models carry some of that, and this factor is
// how much. It is kept apart from the physics (`predicted` stays the model's) so the two can be read side by side.
#pragma once

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "rollsim/validate/epa_test_car.hpp"

namespace rollsim::validate {

/// One simulated row of the fitting half as the calibration sees it.
struct CalibrationSample {
  EpaFuel fuel = EpaFuel::petrol;
  EpaCycle cycle = EpaCycle::ftp75;
  std::string make, model;       ///< as the list spells them; compared lower-cased
  double log_error = 0.0;        ///< ln(predicted / measured) of the physics
};

/// Per energy source: the shrinkage chosen by leave-one-model-out on the fitting half, and what it scored there.
struct CalibrationChoice {
  /// A group's factor is exp(-median log error x n / (n + shrinkage_rows)) for its n rows; infinite: no calibration.
  double shrinkage_rows = 0.0;
  double mean_abs_log_error_uncalibrated = 0.0;  ///< fitting half, the physics alone
  double mean_abs_log_error_calibrated = 0.0;    ///< fitting half, each row calibrated without its own model
  std::size_t rows = 0, groups = 0;               ///< samples, and (make, cycle) groups with a factor
};

class MakerCalibration {
 public:
  /// Learns the factors from the fitting half's samples (a blank make or a log error that is not finite teaches
  /// nothing and is passed over). For each energy source, the shrinkage is the one of
  /// kShrinkageCandidates (or none) that gives the smallest mean |log error| when every fitting row is calibrated
  /// from the other models of its make (leave one model out, as the held-out half is models the fit never saw);
  /// a tie keeps the larger shrinkage.
  static MakerCalibration fit(const std::vector<CalibrationSample>& fitting);

  /// The factor on the physics' prediction (predicted x factor) for a row of this make on this cycle; 1 for a make
  /// or cycle the fitting half does not hold, and for a blank make (rows without a make are not one maker's). `leave_out_model`: learn it without that model's rows (what a fitting
  /// row is given, so no printed figure is in-sample; a model the list leaves blank is one model, as in the split).
  double factor(EpaFuel fuel, EpaCycle cycle, const std::string& make,
                const std::optional<std::string>& leave_out_model = std::nullopt) const;

  const std::map<EpaFuel, CalibrationChoice>& choices() const { return choices_; }

 private:
  using GroupKey = std::tuple<EpaFuel, EpaCycle, std::string>;  // make lower-cased
  struct ModelErrors {
    std::string model;  // lower-cased
    double log_error;
  };
  std::map<GroupKey, std::vector<ModelErrors>> groups_;
  std::map<EpaFuel, CalibrationChoice> choices_;
};

/// The shrinkages (in rows) leave-one-model-out chooses from, beside no calibration at all.
inline constexpr double kShrinkageCandidates[] = {0.0, 1.0, 2.0, 3.0, 5.0, 10.0, 20.0, 40.0};

}  // namespace rollsim::validate
