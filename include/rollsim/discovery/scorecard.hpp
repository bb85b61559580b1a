// Discovery benchmark: blind diagnosis of synthetic recordings with concealed effects, against two baselines.
#pragma once

#include <string>
#include <vector>

#include "rollsim/common/distribute.hpp"
#include "rollsim/discovery/baselines.hpp"
#include "rollsim/discovery/generate.hpp"
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
  /// Only the rows whose label contains one of these (empty: every row), e.g. {"real logger"}.
  std::vector<std::string> only;
  bool infer_road_profile = true;  ///< diagnose with the road_profile stage (DiagnoseOptions), on every row
  /// How the recordings are spread (over MPI ranks by the CLI); empty = this process's threads.
  CaseMap map_cases;
  int ranks = 1;           ///< how many processes map_cases spreads over (said beside the threads)
};

/// How one method fared on one case, over its seeds.
struct Score {
  int named = 0;        ///< the expected effect named first, alone
  int confounded = 0;   ///< the expected effect among the first finding's confounded set
  int missed = 0;       ///< nothing found (or only an "unexplained" signature)
  int mistaken = 0;     ///< a different effect named first
  int n() const { return named + confounded + missed + mistaken; }
};

/// One finding as the scorecard reads it: its effect (or "unexplained"), the ids it is confounded with, its size (the
/// first parameter: the catalogue amplitude).
struct FindingSummary {
  std::string effect;
  std::vector<std::string> confounded_with;
  double size = 0.0;
  double wind_from_deg = -1.0;  ///< wind_heading's fitted bearing (negative: none)
  double wind_from_low_deg = 0.0, wind_from_high_deg = 0.0;  ///< its 95 % profile interval (unwrapped ends)
  double decay_s = -1.0;        ///< aux_load's fitted decay from the trip's start (negative: none)
};

/// What a row asks of a diagnosis. `group` as BenchRow's; `sign` +1 where the truth's physics has a sign (the
/// expected effect with a negative size is then a mistake); `never_called` for the "reversed" rows, the effect a
/// null of that kind must never be called (tyre_warmup for an RRC rising over the trip).
struct RowRule {
  std::string group;
  std::vector<std::string> expected;
  int sign = 0;
  std::string never_called;
};

enum class Tally { named, confounded, missed, mistaken };

/// How rollsim's column scores one diagnosis. Effect rows ("single", "pair", "trips"): by the first finding, named
/// when it is an expected id alone, confounded when an expected id is among its confounded set, missed when there is
/// none or it is "unexplained", mistaken otherwise, and mistaken too when it names an expected id with a size of the
/// wrong sign. "two": named when both expected ids are among all findings, confounded when one is. "null": any
/// finding is mistaken (a false discovery). "reversed": any finding of `never_called`, of either sign, is mistaken.
/// `wrong_sign` (optional) is set when the tally is a mistake for the sign alone, or a never_called finding of
/// negative size.
Tally score_findings(const RowRule& rule, const std::vector<FindingSummary>& findings, bool* wrong_sign = nullptr);

struct BenchRow {
  std::string group;       ///< "single", "pair", "two", "trips" (several recordings), "null", "reversed"
  std::string label;       ///< e.g. "aux_compressor 300 W (mean)"
  std::vector<std::string> expected;  ///< catalogue ids an honest answer names (empty for nulls)
  Score rollsim, calibration;
  Score sparse;                            ///< the sparse baseline at the scorecard's best threshold (BenchResult)
  std::vector<Score> sparse_by_threshold;  ///< per sparse_thresholds() entry
  Score sparse_bic;                        ///< at the threshold BIC picks per recording
  int rollsim_unexplained = 0;  ///< seeds whose first finding was an unexplained signature
  /// Steady-wind rows (GPS): seeds named with the truth's bearing within 45 deg (of rollsim.named), and the cases.
  int rollsim_direction_right = 0;
  /// Of those rows' seeds: named, with the bearing's 95 % profile interval holding the truth's bearing.
  int rollsim_interval_holds = 0;
  bool scores_direction = false;
  /// Winter-heater rows: seeds named aux_load with a decay from the trip's start (of rollsim.named).
  int rollsim_decay_found = 0;
  bool scores_decay = false;
  /// Seeds counted mistaken for a size of the wrong sign (effect rows), or a never_called finding of negative size
  /// ("reversed" rows; the rest of that row's mistakes had a positive size).
  int rollsim_wrong_sign = 0;
};

/// The sparse baseline at one threshold, pooled over the scorecard: null rows, and effect rows (single, pair, two).
struct SparseThresholdSummary {
  double threshold = 0.0;  ///< 0: BIC's per-recording choice
  int null_false = 0, null_n = 0;
  int named = 0, confounded = 0, mistaken = 0, effect_n = 0;
};

struct BenchResult {
  std::vector<BenchRow> rows;
  /// Index into sparse_thresholds() of the sparse baseline's best threshold: the most effects named (alone or
  /// confounded) with a pooled null false-discovery rate <= 5 %, or else the lowest null rate.
  int sparse_best = 0;
  std::vector<SparseThresholdSummary> sparse_summary;  ///< per sparse_thresholds() entry
  SparseThresholdSummary sparse_bic_summary;
  double seconds = 0.0;
  unsigned threads = 1;  ///< per rank
  int ranks = 1;
};

/// Runs the cases on `vehicle` (electric: battery power and SOC channels) and, for the fuel-channel cases, on
/// opt.combustion_vehicle. Seeds are fixed, so runs are reproducible.
BenchResult run_discovery_bench(const Vehicle& vehicle, const BenchOptions& opt);

/// The scorecard as plain text (false-discovery rates with Wilson 95 % intervals).
std::string bench_text(const BenchResult& r);

/// Wilson score interval (95 %) for k successes in n trials.
std::pair<double, double> wilson_interval(int k, int n);

}  // namespace rollsim
