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
  std::string unit;           ///< "kwh_per_10km" or "l_per_100km"
  double expected = 0.0;
  double tolerance_pct = 0.5;
  int expected_line = -1;    ///< where `expected`'s value sits in the file (0-based), for an update in place
  int expected_column = -1;
};

struct Baseline {
  std::string file;
  std::string text;  ///< the file as read: --update changes its values in place, keeping comments and order
  std::vector<RegressCase> cases;
};

/// Reads a baseline file (strict keys, see tests/energy_baseline.yaml). Throws InputError.
Baseline load_baseline(const std::string& path);

struct RegressOutcome {
  RegressCase c;
  double actual = 0.0;
  double drift_pct = 0.0;  ///< (actual - expected) / expected, %
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
