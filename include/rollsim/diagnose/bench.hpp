// Discovery benchmark: blind diagnosis of synthetic recordings with concealed effects, against two baselines.
#pragma once

#include <string>
#include <vector>

#include "rollsim/diagnose/generate.hpp"
#include "rollsim/vehicle/vehicle.hpp"

namespace rollsim {

struct BenchOptions {
  int seeds = 20;          ///< per effect case
  int null_seeds = 200;    ///< null and time-reversed null
  bool quick = false;      ///< the CI subset: warm-up at 30 %, the null, the time-reversed null, one pair
  unsigned threads = 0;    ///< 0: every core
  bool progress = false;   ///< one line on stderr per finished recording count (terminals only)
  /// Real speed traces (replay cycles of shipped recordings) on which the null and tyre warm-up are also concealed.
  std::vector<DriveCycle> real_traces;
  /// The combustion car of the fuel-channel cases (engine warm-up, fuel null), a shipped name or a path; not
  /// loaded in the quick subset, which has no fuel case.
  std::string combustion_vehicle = "ice";
};

/// How one method fared on one case, over its seeds.
struct Score {
  int named = 0;        ///< the expected effect named first, alone
  int confounded = 0;   ///< the expected effect among the first finding's confounded set
  int missed = 0;       ///< nothing found (or only an "unexplained" signature)
  int mistaken = 0;     ///< a different effect named first
  int n() const { return named + confounded + missed + mistaken; }
};

struct BenchRow {
  std::string group;       ///< "single", "pair", "two", "null", "reversed"
  std::string label;       ///< e.g. "aux_compressor 300 W (mean)"
  std::vector<std::string> expected;  ///< catalogue ids an honest answer names (empty for nulls)
  Score rollsim, calibration, sparse;
  int rollsim_unexplained = 0;  ///< seeds whose first finding was an unexplained signature
};

struct BenchResult {
  std::vector<BenchRow> rows;
  double seconds = 0.0;
  unsigned threads = 1;
};

/// Runs the cases on `vehicle` (electric: battery power and SOC channels) and, for the fuel-channel cases, on
/// opt.combustion_vehicle. Seeds are fixed, so runs are reproducible.
BenchResult run_discovery_bench(const Vehicle& vehicle, const BenchOptions& opt);

/// The scorecard as plain text (false-discovery rates with Wilson 95 % intervals).
std::string bench_text(const BenchResult& r);

/// Wilson score interval (95 %) for k successes in n trials.
std::pair<double, double> wilson_interval(int k, int n);

/// The sparse-regression baseline on one recording: sequential thresholded least squares on window integrals of
/// {1, v, v^2, v^3, a, a v} beside the simulated energy; returns the catalogue ids its selected non-calibration
/// terms map to, largest contribution first ("mass|rotational_inertia" for the inertial term a v). The measured
/// channel is the recording's battery power, fuel rate (as fuel power) or SOC (window differences x capacity);
/// `window_s` is the window length (the diagnosis lengthens it for a quantised SOC).
std::vector<std::string> sparse_regression_discovery(const Vehicle& vehicle, const Recording& rec, double window_s = 60.0);

}  // namespace rollsim
