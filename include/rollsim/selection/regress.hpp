// The energy regression baseline: cases (vehicle, tyre, cycle) with expected energy or fuel, run and compared.
#pragma once

#include <string>
#include <vector>

#include "rollsim/sim/simulation.hpp"

namespace rollsim::selection {

struct RegressCase {
  std::string name;
  std::string vehicle;        ///< path or shipped name
  std::string tyre;           ///< path or shipped name
  std::string cycle;          ///< shipped name or path
  std::string unit;           ///< "kwh_per_10km" or "l_per_100km"; empty where the file leaves it to the car
  double expected = 0.0;      ///< 0 for a new case (no value yet; only with --update)
  double tolerance_pct = 0.5;
  int expected_line = -1;    ///< where `expected`'s value sits in the file (0-based), for an update in place
  int expected_column = -1;
  int case_line = -1;        ///< where the case's mapping starts (0-based line and column): a new value goes there
  int case_column = -1;
  bool is_new() const { return expected_line < 0; }
};

struct Baseline {
  std::string file;
  std::string text;  ///< the file as read: --update changes its values in place, keeping comments and order
  std::vector<RegressCase> cases;
};

/// Reads a baseline file (strict keys, see tests/energy_baseline.yaml). A case without `expected` is new, allowed
/// only with `allow_new_cases` (--update fills it in). Throws InputError.
Baseline load_baseline(const std::string& path, bool allow_new_cases = false);

struct RegressOutcome {
  RegressCase c;  ///< the case, its unit the car's
  double actual = 0.0;
  double drift_pct = 0.0;  ///< (actual - expected) / expected, %; NaN for a new case (never drifted)
  bool drifted = false;    ///< |drift| > tolerance
  TraceFollowing trace;  ///< not followed: the car fell behind the case's cycle (its figure guards a slower drive)
};

/// Runs every case forward. A missing vehicle, tyre or cycle, or a unit that does not match the car, throws
/// InputError naming the file and the case.
std::vector<RegressOutcome> run_baseline(const Baseline& baseline);

/// The baseline text with every expected value replaced by the actual one: in place in the file's own text where
/// each value is found where it was read (comments, order, quoting and line ends kept), else the whole file written
/// anew in rollsim's layout, `rewritten` then set true.
std::string baseline_yaml(const Baseline& baseline, const std::vector<RegressOutcome>& outcomes, bool* rewritten = nullptr);

/// A baseline value as the file writes it (six significant digits): an update changes a case only when this does.
std::string baseline_value_text(double value);

}  // namespace rollsim::selection
