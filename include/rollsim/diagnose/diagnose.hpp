// Diagnosis of a recording against the model: locate the mismatch, name the missing catalogue effect, fit it.
#pragma once

#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/effects/catalogue.hpp"
#include "rollsim/recording/recording.hpp"
#include "rollsim/vehicle/vehicle.hpp"

namespace rollsim {

/// The measured energy channel a recording carries (the first present, in this order).
enum class ChannelKind { battery_power, battery_voltage_x_current, fuel_rate, soc };
std::string to_string(ChannelKind k);

/// Physical priors of the calibration, per channel kind (docs/diagnose.md, "Calibration"). The channel
/// scale is bounded (a hard box about 1): a battery's terminal voltage and current, or a dynamometer's direct fuel
/// meter, are calibrated to a few per cent; a state of charge carries the usable capacity's uncertainty. RRC level
/// and aero C carry Gaussian penalties at their published uncertainty. Settable in a vehicle file's
/// `calibration_priors:` block (calibration_priors_from_yaml).
struct CalibrationPriors {
  double terminal_scale_bound = 0.05;  ///< battery power, or voltage x current: scale within 1 +- this
  double fuel_scale_bound = 0.05;      ///< direct fuel flow
  double soc_scale_bound = 0.10;       ///< state of charge: usable capacity +- 10 %
  double rrc_level_sd = 0.10;  ///< RRC level: a tyre label class's width, +-0.2 bar of pressure; boxed at 2 sd
  double drag_sd = 0.10;       ///< aero C: CdA from published figures, coast-down repeatability; boxed at 2 sd
  double scale_bound(ChannelKind k) const;
};
/// Reads a vehicle file's optional `calibration_priors:` block (keys as the fields above, fractions), marking it
/// read on `file`; errors name the file and key.
CalibrationPriors calibration_priors_from_yaml(YamlMap& file);

/// Fixed in advance (not tuned per recording), so that the null case's false-discovery rate is what it is.
/// A recording's engine at its start: cold at ambient (a cold-start test, the first trip of the day), hot, or
/// inferred from the recording's first minutes of fuel flow.
enum class EngineStart { cold, hot, infer };
std::string to_string(EngineStart s);

struct DiagnoseOptions {
  double window_s = 60.0;          ///< energy windows
  int block_windows = 3;           ///< one recording: held-out folds alternate in blocks of this many windows
                                   ///< (several recordings: each recording is a fold)
  double bic_threshold = 10.0;     ///< "very strong" evidence on the Kass-Raftery scale
  double collinear_corr = 0.9;     ///< |corr| of calibration-cleaned signatures above which effects are confounded
  int max_effects = 2;
  CalibrationPriors priors;
  /// Adequacy against the recording's own noise: the noise floor comes from windows of this length (at least two
  /// samples; their second differences), and the residual is tested against it aggregated at each scale below.
  double noise_window_s = 2.0;
  std::vector<double> adequacy_scales_s{30.0, 60.0, 120.0, 300.0};
  double adequacy_z = 3.3;          ///< one-sided, per scale (about 0.05 % each)
  double adequacy_min_ratio = 2.0;  ///< and at least this variance ratio over the floor
  /// A standing residual counts as an auxiliary load's evidence at this BIC-equivalent (z^2 - ln n_eff).
  double standing_bic_threshold = 10.0;
  /// Or, on an electrical power channel, where the standstills' mean residuals scatter beyond the noise within them by
  /// this normal deviate (Wilson-Hilferty of their chi-square): a consumer switching on and off, which nothing else
  /// does to a standing car. Session 27's outside tester's 30 nulls (5 with a 100 W sensor drift over 30 s): at most
  /// 3.5; its switching loads of 0.5-3 kW: 8-42.
  double standing_switch_z = 6.0;
  /// SOC channels: windows are lengthened until the SOC quantisation error of a window's energy (sd q / sqrt 6
  /// for two quantised readings) is at most this fraction of the mean window energy.
  double soc_quantisation_fraction = 0.02;
  /// Unexplained-residual basis: time constants of the early-trip decay shapes [s].
  std::vector<double> unexplained_decay_s{300.0, 600.0, 1200.0, 2400.0};
  /// Profile grids (log-spaced, points per factor of two) refining a found effect's time constant: the unexplained
  /// basis' decay over 150-4800 s, tyre_warmup's heat capacity over 10-320 kJ/K, engine_warmup's over 25-800 kJ/K.
  int profile_points_per_octave = 2;
  /// ambient_rrc is tested only across recordings whose mean recorded ambients span at least this much [K].
  double ambient_min_spread_k = 5.0;
  /// Trip-to-trip scatter (sd) of the RRC level at one ambient (tyre pressure +-0.1 bar, road surface): ambient_rrc
  /// must explain the trips' RRC levels beyond it.
  double trip_rrc_scatter = 0.01;
  /// Trip-to-trip scatter (sd) of a car's constant electrical load at one ambient [W] (lights, wipers, seat heaters
  /// on some trips and not others): hvac_ambient must explain the trips' load levels beyond it.
  double trip_aux_scatter_w = 50.0;
  /// Trip-to-trip scatter (sd) of the air density that the recorded ambient does not explain (barometric pressure,
  /// about +-10 hPa day to day), projected onto each trip's RRC level and added to the scatter above.
  double trip_air_density_scatter = 0.01;
  /// Where ambient_rrc is tested, each recording is replayed with the air density of its recorded ambient.
  bool air_density_from_ambient = true;
  unsigned threads = 0;  ///< simulator runs in parallel (0: hardware concurrency)
  /// Invert the residual into a road profile where elevation is not recorded (road_profile). On one pass a profile
  /// along distance also absorbs a drift in time (a gusty headwind, an RRC rising over the trip), so it is named
  /// only with a descent steeper than the car's whole rolling resistance, which no loss can mimic (README, "Road
  /// profile"). `--no-road-profile` switches the stage off.
  bool infer_road_profile = true;
  /// A fuel-channel recording's engine is taken as switched off where it stands still with exactly zero fuel
  /// flow for at least this long (a soak between two tests, start-stop at a light): the replay burns no fuel there
  /// and a cold engine cools instead of idling warm. Shorter runs of zeros are read as the flow meter's noise.
  double engine_off_min_s = 5.0;
  /// Each recording's engine at its start, in the recordings' order (missing entries: inferred): a hot test pooled
  /// with a cold one is not warmed up again.
  std::vector<EngineStart> engine_start;
  /// Inferring a fuel-rate recording's start: the fuel its first `engine_start_early_s` of running burn, against
  /// the model's, relative to the same ratio after `engine_start_late_s` of running (60 s blocks). Hot only when the
  /// data rule out (95 %, one-sided by the upper bound) an early excess of `engine_start_min_cold_excess`: a cold
  /// guess costs nothing on a hot engine (the warm-up's fit is then zero), a hot guess hides a real warm-up.
  double engine_start_early_s = 300.0;
  double engine_start_late_s = 900.0;
  double engine_start_min_cold_excess = 0.05;
};

struct ParameterEstimate {
  std::string name, unit;
  double value = 0.0, ci_low = 0.0, ci_high = 0.0;  ///< 95 %
  /// A time constant (or heat capacity) from a profile over a log-spaced grid: the interval is where
  /// n_eff ln(RSS / RSS_min) < 3.84; an end of it that reached the grid's end is open ("< ci_low", "> ci_high").
  bool profiled = false;
  bool ci_low_open = false, ci_high_open = false;
};

/// Profile-likelihood interval over an ascending grid of a positive parameter: the grid point of least RSS, and the
/// contiguous range about it where n_eff ln(RSS / RSS_min) stays below `critical` (3.84: chi^2 with one degree of
/// freedom, 95 %), its ends interpolated linearly in log(parameter) between the last point inside and the first
/// outside; an end still inside at the grid's end is that end, flagged open.
struct ProfileInterval {
  std::size_t best = 0;  ///< index of the least RSS
  double value = 0.0, low = 0.0, high = 0.0;
  bool low_open = false, high_open = false;
};
ProfileInterval profile_likelihood_interval(const std::vector<double>& grid, const std::vector<double>& rss, double n_eff,
                                            double critical = 3.84);

/// A road profile recovered from the residual (road_profile findings): elevation along the distance driven, relative
/// to the start, at the profile's knots, with its 95 % band (it widens along the trip: an elevation is a sum of grades).
struct RecoveredProfile {
  std::vector<double> distance_m, elevation_m, elevation_ci_low_m, elevation_ci_high_m;
};

struct Finding {
  std::string effect;  ///< catalogue identifier, or "unexplained" (described by its signature)
  std::string description;  ///< in words, with the fitted numbers (unexplained findings)
  /// For each effect it is confounded with, the measurement that would tell the two apart.
  std::vector<std::string> separating_tests;
  std::vector<ParameterEstimate> parameters;
  std::vector<std::string> confounded_with;
  double delta_bic = 0.0;
  /// The fitted effect's energy over all windows (in-sample) as a share of the measured energy; negative when the
  /// effect returns energy. Not a number for a finding that is no fitted effect (a residual left above the noise).
  double energy_share_pct = std::numeric_limits<double>::quiet_NaN();
  double heldout_rmse_before_j = 0.0, heldout_rmse_after_j = 0.0;  ///< per window
  double heldout_energy_error_pct_before = 0.0, heldout_energy_error_pct_after = 0.0;
  /// Whiteness of the held-out window residual: its lag-1 autocorrelation (0 for white noise), before and after.
  double heldout_lag1_autocorrelation_before = 0.0, heldout_lag1_autocorrelation_after = 0.0;
  /// The held-out figures above were computed: a fitted effect or road profile. A finding that fits nothing (the
  /// residual left above the noise floor, a shape with the impossible sign) has none, and they are not printed.
  bool heldout_scored = false;
  /// A catalogue shape fitted with the impossible sign: described by its shape, never named as the effect.
  bool wrong_sign = false;
  EffectParameters fitted;  ///< for --write-vehicle
  std::optional<RecoveredProfile> road_profile;  ///< road_profile findings: the profile itself
};

struct RegimeResidual {
  std::string regime;
  int samples = 0;
  double mean_w = 0.0, ci_low_w = 0.0, ci_high_w = 0.0;  ///< measured minus calibrated model, 95 % (effective n)
};

/// One energy window, for figures: what was measured and what the model said before and after the findings.
struct DiagnosisWindow {
  int recording = 0;
  double start_s = 0.0, end_s = 0.0;  ///< since the start of its recording
  double mean_speed_mps = 0.0;
  double mean_positive_accel_mps2 = 0.0;  ///< mean of max(0, a) over the window
  double measured_j = 0.0;
  double simulated_j = 0.0;   ///< uncalibrated model
  double calibrated_j = 0.0;  ///< calibrated model (in-sample)
  double fitted_j = 0.0;      ///< calibrated model with the findings' effects (in-sample)
};

/// For a catalogue effect that was not found: the smallest size of its catalogue shape that would have passed the
/// same test on this data. A lower bound: a real effect's shape differs, and the benchmark measures 1-3 times it.
struct DetectionLimit {
  std::string effect;
  std::string parameter, unit;
  double smallest_detectable = 0.0;  ///< amplitude at which Delta BIC would reach the threshold
  bool within_bounds = true;         ///< false: even the largest allowed size would not have been detected
};

/// A fuel-rate recording's engine start as the diagnosis took it, and the evidence where it was inferred: the early
/// running's fuel excess over the model, relative to the rest of the recording, with its 95 % interval.
struct EngineStartState {
  std::string recording;
  EngineStart start = EngineStart::cold;  ///< cold or hot
  bool inferred = false;                  ///< false: set (--engine-start), or too short to infer (then cold)
  double early_excess = 0.0, early_excess_ci_low = 0.0, early_excess_ci_high = 0.0;
  /// The same read on the standstills alone (engine idling), where the first minutes hold two or more.
  bool idle_inferred = false;
  double idle_excess = 0.0, idle_excess_ci_low = 0.0, idle_excess_ci_high = 0.0;
};

struct Diagnosis {
  std::string verdict;   ///< missing_physics, nothing_missing, confounded
  std::string channel;   ///< which measured channel was compared
  int windows = 0;
  double effective_windows = 0.0;
  double lag1_autocorrelation = 0.0;
  int lag_samples = 0;                     ///< calibration: the lag rounded to whole samples
  double lag_s = 0.0, lag_ci_low_s = 0.0, lag_ci_high_s = 0.0;  ///< continuous lag and its 95 % profile interval
  /// False for a state of charge (the lag is not estimated: the figures above are 0). The search runs from 0 up, so
  /// a channel that leads the speed (its clock ahead) reads 0 too.
  bool lag_estimated = false;
  /// How the logger sampled the channel, as the data chose: "interval_mean" (each sample integrates its interval,
  /// the replay's segment means) or "instantaneous" (read at the sample's instant, the replay's point values).
  std::string channel_sampling = "interval_mean";
  /// Squared residual read as interval means over read at the instants, each at its own best lag: above 1.05 the
  /// instant is chosen.
  double channel_sampling_sse_ratio = 1.0;
  double raw_trip_energy_error_pct = 0.0;  ///< uncalibrated model against measured, whole data
  double channel_scale = 1.0;              ///< calibration: measured / simulated
  double rrc_level_change = 0.0;           ///< calibration: fractional RRC change
  double drag_change = 0.0;                ///< calibration: fractional aero (C term) change
  /// The channel scale's prior (a box) and what the data alone wanted; outside, the scale is held at the bound and
  /// the energy it would have absorbed is left for the effects (and reported in a finding).
  double channel_scale_prior_low = 0.0, channel_scale_prior_high = 0.0;
  double channel_scale_free = 1.0, rrc_level_change_free = 0.0, drag_change_free = 0.0;  ///< without the boxes
  /// The calibration refitted beside the findings (NaN without findings): what the channel scale, RRC level and aero C
  /// read once the findings take their share, where the fields above are the calibration before them.
  double channel_scale_with_findings = std::nan(""), rrc_level_change_with_findings = std::nan(""),
         drag_change_with_findings = std::nan("");
  double calibration_delta_bic_leaving_prior = 0.0;  ///< free against boxed calibration
  /// A box is active and the data significantly want out of it; `calibration_beyond_prior` names which of
  /// "channel_scale", "rrc_level" and "drag" the free calibration puts beyond its box.
  bool calibration_outside_prior = false;
  std::vector<std::string> calibration_beyond_prior;
  double scale_absorbed_energy_pct = 0.0;  ///< of the measured energy
  /// Adequacy: the calibrated residual's variance over the noise floor at the worst scale, and that scale.
  double noise_floor_j = 0.0;              ///< sd of one noise window's energy (successive differences)
  double residual_to_noise_ratio = 0.0, residual_to_noise_z = 0.0, adequacy_scale_s = 0.0;
  double final_residual_to_noise_ratio = 0.0, final_residual_to_noise_z = 0.0;  ///< after the findings
  double heldout_rmse_calibrated_j = 0.0;
  double heldout_energy_error_pct_calibrated = 0.0;
  std::vector<Finding> findings;
  std::vector<RegimeResidual> located;
  std::vector<DetectionLimit> detection_limits;  ///< catalogue effects not found, with what would have been
  double window_s = 0.0;            ///< window length used (SOC: lengthened by the quantum)
  std::vector<std::string> notes;   ///< preparation done on the data (grade from elevation, SOC quantum)
  std::vector<EngineStartState> engine_starts;  ///< fuel-rate recordings only, in the recordings' order
  std::vector<DiagnosisWindow> series;
};

/// The measurement that tells effect `a` from effect `b` where one trip cannot (docs/diagnose.md's confusions).
std::string separating_test(const std::string& a, const std::string& b);

/// The trace a recording is replayed on: its speed, time from the recording's start (effects that decay from
/// the start of a trip read it), and its grade, or one derived robustly from its elevation, quantised to 0.05 %.
/// With `engine_off_min_s` > 0, a fuel-rate recording's engine-off runs (standing with no fuel flow, zero or a meter's zero offset below it
/// for at least that long) become the cycle's engine_off segments; `start` sets its engine_hot_start.
DriveCycle cycle_of_recording(const Recording& r, double engine_off_min_s = 0.0, EngineStart start = EngineStart::cold);
/// Per sample: the direction of travel clockwise from north [rad], from recorded latitude and longitude [deg]: the
/// bearing to the first later point at least `baseline_m` away (a local flat-earth projection; GPS jitter of a few
/// metres turns a shorter chord at random), held at the end of the route.
std::vector<double> heading_from_gps(const std::vector<double>& latitude_deg, const std::vector<double>& longitude_deg,
                                     double baseline_m = 20.0);
/// Per sample of `r`: standing with no fuel flow (zero or below) in a run lasting at least `min_s` (all false without a
/// fuel channel).
std::vector<bool> engine_off_samples(const Recording& r, double min_s);

/// Replays each recording's speed (and grade) through the vehicle, compares energies per window, calibrates,
/// and tests each catalogue effect (see docs/diagnose.md for the method).
Diagnosis diagnose(const Vehicle& vehicle, const std::vector<Recording>& recordings, const DiagnoseOptions& opt = {});

std::string diagnosis_json(const Diagnosis& d);
std::string diagnosis_text(const Diagnosis& d);
/// The channel lag as the text and the report say it: its value and 95 % interval [s], where 0 is also what a channel
/// leading the speed reads, or that a state of charge's lag is not estimated.
std::string lag_text(const Diagnosis& d);

/// The vehicle file at `vehicle_path` with an `effects:` block holding the findings' fitted effects.
/// Throws InputError naming the file when the vehicle file already has an effects block (which --write-vehicle
/// would have to merge with the fitted one); called before the diagnosis, and again when the file is written.
void check_no_effects_block(const YamlMap& vehicle_file, const std::string& vehicle_path);
std::string fitted_vehicle_yaml(const std::string& vehicle_path, const Diagnosis& d);

}  // namespace rollsim
