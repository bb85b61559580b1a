// What `rollsim validate --json` writes, shared by the command line and the Python API.
#pragma once

#include "rollsim/common/json.hpp"
#include "rollsim/validate/validate.hpp"

namespace rollsim::validate {

/// One row: test_number, make, model, fuel, cycle, procedure, line, half; then `skipped` with its reason, or
/// measured, predicted, unit and error_pct (and an FTP-75's predicted bags).
JsonObject row_json(const RowOutcome& outcome);

/// The constants fitted on the fitting half and how many rows set each (a constant with none keeps its nominal
/// value: its count is 0).
JsonObject fitted_json(const FittedConstants& fitted);

/// One summary line (powertrain, cycle, half, count, median error, median and 90th percentile of |error|).
JsonObject summary_line_json(const SummaryLine& line);

}  // namespace rollsim::validate
