// Fitting a tyre's hysteresis-model constants to measured RRC points, with intervals and residuals.
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "rollsim/tyre/tyre_model.hpp"
#include "rollsim/tyre/tyre_spec.hpp"

namespace rollsim {

/// One measured operating point of a tyre (flat road, free rolling).
struct RrcPoint {
  double pressure_pa = 0.0;
  double load_n = 0.0;
  double speed_mps = 0.0;
  double rrc = 0.0;
  std::string where;  ///< option or file line it came from, for errors
};

/// The hysteresis model's constants a fit can free, in the order the automatic choice adds them.
enum class HysteresisParam { RrcRef, FrequencySlope, DeflectionExponent, LoadExponent, SpeedLoss, SpeedLossLoadExponent };
inline constexpr int kHysteresisParamCount = 6;

/// The tyre-file key of a parameter (model.<key>), also its name in --free.
const char* hysteresis_param_key(HysteresisParam p);
/// The keys of `ps`, comma-separated, for messages and tables ("rrc_ref, frequency_slope_per_hz").
std::string hysteresis_param_keys(const std::vector<HysteresisParam>& ps);
/// Every constant a fit can free, in the enum's order.
std::vector<HysteresisParam> all_hysteresis_params();
std::optional<HysteresisParam> hysteresis_param_from_key(const std::string& key);
double hysteresis_param_value(const HysteresisConstants& c, HysteresisParam p);
void set_hysteresis_param(HysteresisConstants& c, HysteresisParam p, double value);
/// A slope or speed loss cannot be negative (RRC would reach 0 at some speed), nor the deflection exponent (a tyre
/// losing less the more it deflects would lose more when pumped up; every measured set loses less, J2452 pressure
/// exponents -0.26 to -0.59): a fit that puts one below 0 holds it at 0 and refits the rest.
bool hysteresis_param_non_negative(HysteresisParam p);

/// Checks a point is physically a passenger/light-truck tyre measurement and solvable for `tyre`: pressure in
/// [50, 600] kPa, speed in (0, 300] km/h, RRC in [0.001, 0.05], a load the tyre carries without its deflection
/// reaching the rim. Throws InputError naming point.where.
void check_rrc_point(const TyreState& tyre, const RrcPoint& point);

/// The parameters `points` can determine: the level always; then, while parameters stay fewer than points,
/// the frequency slope (2+ speeds), the deflection exponent (2+ pressures), the load exponent (2+ loads), the
/// speed-squared loss (3+ speeds) and its load exponent (2+ loads and 3+ speeds).
std::vector<HysteresisParam> identifiable_params(const std::vector<RrcPoint>& points);

struct ParamEstimate {
  HysteresisParam param;
  double value = 0.0;
  double std_error = 0.0;  ///< from the Jacobian: sigma^2 (J^T J)^-1
  double low95 = 0.0;      ///< value -/+ 1.96 std_error (rrc_ref: on its logarithm)
  double high95 = 0.0;
  bool at_bound = false;   ///< held at 0 because the free fit went below it (a slope or loss cannot be negative)
};

struct PointResidual {
  RrcPoint point;
  double model_rrc = 0.0;
  double relative_error = 0.0;  ///< model / measured - 1
};

struct TyreFit {
  TyreState tyre;  ///< the start tyre with the fitted constants, model = Hysteresis
  std::vector<ParamEstimate> params;          ///< free parameters only
  std::vector<HysteresisParam> held;          ///< parameters kept at their shared values
  std::vector<PointResidual> residuals;
  double rms_relative_error = 0.0;
  int degrees_of_freedom = 0;                 ///< points - free parameters
  double sigma_relative = 0.0;                ///< relative measurement scatter used for the intervals
  bool sigma_from_residuals = false;          ///< false: the assumed uncertainty (see sigma_source)
  /// Standard errors each side in a 95 % interval: Student's t at degrees_of_freedom where the scatter came from the
  /// residuals, 1.96 where it was assumed.
  double interval_quantile = 1.96;
  /// What the points made of the tyre that no measured tyre does (the front ends print them as warnings).
  std::vector<std::string> warnings;
};

/// Where the fit's scatter comes from, for its reports: "from the residuals", or why it is the assumed one.
std::string sigma_source(const TyreFit& fit);

struct FitRequest {
  std::vector<RrcPoint> points;
  std::vector<HysteresisParam> free;            ///< empty: identifiable_params(points)
  double assumed_relative_uncertainty = 0.02;   ///< used for intervals when no degrees of freedom remain
};

/// Fits the free constants of `start` (its geometry, and its shared constants for those held) to the points by
/// least squares on relative errors (Eigen's Levenberg-Marquardt). Throws InputError("--free"...) when more
/// parameters are asked than the points can determine ("too few points"), or a point is out of range.
TyreFit fit_hysteresis(const TyreState& start, const FitRequest& request);

/// An EU tyre label fuel-efficiency class and the RRC band it implies.
struct LabelBand {
  char label_class = 'A';
  double rrc_min = 0.0;  ///< lower edge (values are rounded to 0.1 kg/t, so edges are half a digit out)
  double rrc_max = 0.0;
  bool open_below = false;  ///< class A has no lower edge in the regulation; rrc_min is our assumption
  bool open_above = false;  ///< class E has no upper edge; rrc_max is our assumption
  /// Whether an RRC is of this class: an open end has no edge (A holds 5.0 kg/t, E 13.0; our closing edges are for
  /// the label-alone uncertainty only). An edge belongs to the class above it, as a value declared to 0.1 kg/t rounds
  /// (6.55 is 6.6, class B; it had been inside both A and B: session 24's outside testing), and holds a value computed
  /// onto it (6.549999999999998 is 6.55).
  bool contains(double rrc) const {
    constexpr double kEdge = 1e-12;  // RRC; far below the 0.1 kg/t of a declared value
    return (open_below || rrc >= rrc_min - kEdge) && (open_above || rrc < rrc_max - kEdge);
  }
};

/// The C1 (passenger car tyre) band of a class A-E of Regulation (EU) 2020/740; throws InputError(where, ...) for
/// anything else (e.g. F, which the 2020 label no longer has).
LabelBand eu_label_band_c1(const std::string& label_class, const std::string& where);

/// The ISO 28580 test point of a C1 tyre: 80 km/h, 80 % of the load index's load, 210 kPa (standard load)
/// or 250 kPa (extra load). `drum_rrc` is on ISO 28580's 2.0 m drum, as a label or a test report gives it; the
/// point holds the flat-road RRC the model predicts (drum_to_flat_factor with the size's outer radius, as for a
/// J2452 set), and its `where` says so. Throws InputError(where, ...) without a load index.
RrcPoint iso28580_point(const TyreSize& size, double drum_rrc, const std::string& where);

/// A point given in files' units (kPa, N, km/h, RRC) as the fit takes it (SI), named `where`.
RrcPoint rrc_point_from_file_units(double pressure_kpa, double load_n, double speed_kmh, double rrc, std::string where);

/// Measured points from a CSV with columns pressure_kpa, load_n, speed_kmh, rrc (`rollsim tyre fit --measured`),
/// each named by its file and line for the fit's errors. Throws InputError naming the file, line and column of a
/// cell that is not a number, a missing column, or a file without data rows; ranges are the fit's to check. Other
/// columns are not read, and `unread`, when given, receives a line saying so (a temperature_c column changed nothing
/// without a word: session 24's outside testing).
std::vector<RrcPoint> load_measured_rrc_csv(const std::string& path, std::vector<std::string>* unread = nullptr);

}  // namespace rollsim

namespace rollsim {

/// What a fitted tyre file records besides the fit.
struct FittedTyreFile {
  std::string name;
  std::string size;           ///< designation, as given
  double pressure_pa = 0.0;   ///< the file's inflation pressure
  std::string source;         ///< how it was made (the command's data)
};

/// Writes a normal tyre file (tyres/README.md) with `model: kind: hysteresis` and every constant, and the fit's
/// intervals and residual RMS as comments.
void write_fitted_tyre_yaml(std::ostream& out, const FittedTyreFile& file, const TyreFit& fit);

}  // namespace rollsim
