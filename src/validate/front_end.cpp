#include "rollsim/validate/front_end.hpp"

#include <cmath>

namespace rollsim::validate {

JsonObject row_json(const RowOutcome& o) {
  const auto& r = *o.row;
  JsonObject j;
  j.add("test_number", r.test_number).add("make", r.make).add("model", r.model).add("fuel", o.powertrain);
  j.add("cycle", to_string(r.cycle)).add("procedure", r.procedure).add("line", static_cast<int>(r.line));
  j.add("half", o.fitting_half ? "fitting" : "held-out");
  if (r.derived) j.add("analytically_derived", true).add("adfe_base_test", r.derived->base_test);
  if (o.skip != SkipReason::none) {
    j.add("skipped", to_string(o.skip) + (o.skip_detail.empty() ? "" : ": " + o.skip_detail));
    return j;
  }
  j.add("measured", o.measured).add("predicted", o.predicted).add("unit", o.unit).add("error_pct", o.error_pct());
  j.add("maker_factor", o.maker_factor).add("maker_calibrated", o.maker_factor * o.predicted);
  j.add("maker_calibrated_error_pct", o.maker_calibrated_error_pct());
  if (o.measured_from_kwh_per_100mi) j.add("measured_read_as", "kWh/100 mi");
  if (o.nominal_constants) j.add("constants", "nominal");
  if (r.cycle == EpaCycle::ftp75) {
    for (int b = 0; b < 3; ++b) j.add("predicted_bag" + std::to_string(b + 1) + "_mpg", o.predicted_bag_mpg[b]);
  }
  return j;
}

std::vector<std::string> validation_warnings(const Validation& v) {
  std::size_t nominal = 0;
  for (const auto& o : v.rows) nominal += o.skip == SkipReason::none && o.nominal_constants ? 1 : 0;
  if (nominal == 0) return {};
  // A one-maker list predicted the Vantage V8 21 % low with nothing in --json to say why (session 24).
  return {std::to_string(nominal) + " simulated row(s) are predicted with nominal constants (the fitting half has no "
          "row of their fuel, or no FTP's bags, to fit them; --json marks them \"constants\": \"nominal\"): their errors "
          "judge no fitted model"};
}

JsonObject fitted_json(const FittedConstants& f) {
  auto count = [](std::size_t n) { return static_cast<int>(n); };
  JsonObject j;
  j.add("petrol_indicated_efficiency", f.defaults.petrol_indicated_efficiency).add("petrol_rows", count(f.petrol_rows));
  j.add("diesel_indicated_efficiency", f.defaults.diesel_indicated_efficiency).add("diesel_rows", count(f.diesel_rows));
  j.add("charge_efficiency", f.defaults.charge_efficiency).add("electric_rows", count(f.electric_rows));
  j.add("cold_fuel_excess", f.defaults.cold_fuel_excess).add("cold_start_rows", count(f.cold_start_rows));
  return j;
}

JsonObject maker_calibration_json(const MakerCalibration& c) {
  JsonObject j;
  for (const auto& [fuel, choice] : c.choices()) {
    JsonObject one;
    // Infinite shrinkage (no calibration) is written as null: JSON has no infinity.
    if (std::isinf(choice.shrinkage_rows)) one.add_null("shrinkage_rows");
    else one.add("shrinkage_rows", choice.shrinkage_rows);
    one.add("rows", static_cast<int>(choice.rows)).add("groups", static_cast<int>(choice.groups));
    one.add("fitting_mean_abs_log_error_physics", choice.mean_abs_log_error_uncalibrated);
    one.add("fitting_mean_abs_log_error_calibrated", choice.mean_abs_log_error_calibrated);
    j.add(to_string(fuel), one);
  }
  return j;
}

JsonObject summary_line_json(const SummaryLine& s) {
  JsonObject j;
  j.add("powertrain", s.powertrain).add("cycle", s.cycle).add("half", s.half).add("count", static_cast<int>(s.count));
  j.add("median_error_pct", s.physics.median_error_pct).add("median_abs_error_pct", s.physics.median_abs_error_pct);
  j.add("p90_abs_error_pct", s.physics.p90_abs_error_pct);
  j.add("maker_calibrated_median_error_pct", s.maker_calibrated.median_error_pct);
  j.add("maker_calibrated_median_abs_error_pct", s.maker_calibrated.median_abs_error_pct);
  j.add("maker_calibrated_p90_abs_error_pct", s.maker_calibrated.p90_abs_error_pct);
  return j;
}

}  // namespace rollsim::validate
