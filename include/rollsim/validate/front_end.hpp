// What `rollsim validate --json` writes, shared by the command line and the Python API.
#pragma once

#include "rollsim/common/json.hpp"
#include "rollsim/validate/validate.hpp"

namespace rollsim::validate {

/// One row: test_number, make, model, fuel, cycle, procedure, line, half; then `skipped` with its reason, or
/// measured, predicted, unit and error_pct, the maker calibration's maker_factor, maker_calibrated and
/// maker_calibrated_error_pct (and an FTP-75's predicted bags, the physics').
JsonObject row_json(const RowOutcome& outcome);

/// What the results rest on that a reader must know, one line each without "warning:": rows predicted with nominal
/// constants.
std::vector<std::string> validation_warnings(const Validation& v);

/// The constants fitted on the fitting half and how many rows set each (a constant with none keeps its nominal
/// value: its count is 0).
JsonObject fitted_json(const FittedConstants& fitted);

/// Per energy source: the maker calibration's shrinkage (null: none), its rows and (make, cycle) groups, and the
/// fitting half's mean |log error| without and with it (leave one model out).
JsonObject maker_calibration_json(const MakerCalibration& calibration);

/// One summary line (powertrain, cycle, half, count, median error, median and 90th percentile of |error|; the
/// same three with the maker calibration, keys prefixed maker_calibrated_).
JsonObject summary_line_json(const SummaryLine& line);

}  // namespace rollsim::validate
