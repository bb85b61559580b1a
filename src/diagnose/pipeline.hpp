// The diagnosis pipeline's stages and the plain results they pass on (internal to src/diagnose/).
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rollsim/common/format.hpp"
#include "rollsim/diagnose/diagnose.hpp"
#include "rollsim/effects/effect.hpp"

namespace rollsim::diag {

using EffectList = std::vector<std::shared_ptr<const Effect>>;

// ---- windows (windows.cpp) -------------------------------------------------------------------------------------

struct Window {
  std::size_t rec = 0, begin = 0, end = 0;  // sample range [begin, end]
};

/// The measurement cut into energy windows: what every later stage compares against.
struct Observations {
  ChannelKind channel = ChannelKind::soc;
  double window_s = 0.0;
  std::vector<Window> windows;
  std::vector<std::vector<double>> dt_s;        // per recording, per segment
  std::vector<std::vector<double>> measured_w;  // per recording, per sample (empty for SOC)
  std::vector<std::vector<char>> break_before;   // per recording, per sample: no window spans the step into it
  Eigen::VectorXd measured_j;                   // per window
  std::vector<int> fold_of;                     // held-out fold of each window
  double soc_capacity_j = 0.0;
  Eigen::Index n() const { return measured_j.size(); }
};

/// Measured channel power per sample [W] (empty for SOC, which is differenced per window), and its kind.
std::vector<double> measured_power_w(const Vehicle& v, const Recording& r, ChannelKind& kind);

/// Windows of `window_s` (SOC: lengthened until its quantum is small), their measured energies and held-out folds.
Observations build_windows(const Vehicle& vehicle, const std::vector<Recording>& recordings, double window_s,
                           const DiagnoseOptions& opt, std::vector<std::string>& notes);
/// Windows of `window_s` over the same samples, measured energies only (the noise floor's short windows).
Observations rewindow(const Observations& o, const std::vector<Recording>& recordings, double window_s);
/// The coarsest state-of-charge quantum of the recordings (the median non-zero step of each), 0 without one.
double soc_quantum(const std::vector<Recording>& recordings);

// ---- replay (replay.cpp) ---------------------------------------------------------------------------------------

/// Simulated channel power of one model variant: per recording, per sample, and per window (lag applied).
struct Variant {
  std::vector<std::vector<double>> power_w;
  /// A channel read at instants only: per segment, its value at its end at its own acceleration (the point value
  /// at the start is power_w). Empty for interval means, whose lagged window is exactly (1-f) p[k] + f p[k+1].
  std::vector<std::vector<double>> end_w;
  Eigen::VectorXd window_j;
};

/// Every recording's trace knows its direction of travel (latitude and longitude recorded): what wind_heading needs,
/// without which a wind is only a headwind along the trace.
inline bool headings_known(const std::vector<DriveCycle>& cycles) {
  return !cycles.empty() && std::all_of(cycles.begin(), cycles.end(), [](const DriveCycle& c) { return !c.heading_rad.empty(); });
}

/// The simulated channel per recording and sample, read both ways a logger may sample it.
struct ChannelPowers {
  std::vector<std::vector<double>> interval_mean, instantaneous;
};

/// Replays model variants (the base model plus extra effects) on the recordings' traces, in parallel.
struct Replayer {
  const Vehicle& vehicle;
  const std::vector<DriveCycle>& cycles;
  EffectList per_recording;  // known per-recording physics (air density at the recorded ambient), or empty
  bool cells = false;        // SOC: the cells' internal loss counts
  unsigned threads = 0;
  bool point_values = false;  // the channel read at each sample's instant (else its mean over the sample's interval)
  void sample(const EffectList& extra, Variant& out) const;               ///< power_w (and end_w) as `point_values` says
  ChannelPowers both_samplings(const EffectList& extra) const;           ///< one replay, both readings
  std::vector<Variant> run(const std::vector<EffectList>& extras, const Observations& o, double lag_samples) const;
};

/// Window energies of per-sample powers, shifted by a (fractional) channel lag: interval means interpolated linearly
/// between samples; instants, where `end_w` is given, within their segment (start to end at its own acceleration).
Eigen::VectorXd window_energies(const std::vector<std::vector<double>>& power_w, const Observations& o, double lag_samples,
                                const std::vector<std::vector<double>>* end_w = nullptr);
/// The variant's window energies, read as it was sampled (its end_w when it has them).
Eigen::VectorXd window_energies(const Variant& v, const Observations& o, double lag_samples);
/// The variant's power at sample `i` of recording `recording`, shifted by a (fractional) channel lag, read as it was
/// sampled: what the window energies sum, one sample at a time.
double lagged_power_w(const Variant& v, std::size_t recording, std::size_t i, double lag_samples);

/// Channel lag (calibration): the continuous shift of the simulated power, 0-10 samples, that best matches the
/// measured one (interpolated channel), with its profile interval.
struct LagEstimate {
  bool estimated = false;  ///< not for a state of charge, which integrates the power
  double samples = 0.0, low = 0.0, high = 0.0;
  double seconds = 0.0, low_s = 0.0, high_s = 0.0;
  double sse_w2 = 0.0;  ///< sum of squared sample residuals at the best lag
};
LagEstimate estimate_lag(const std::vector<std::vector<double>>& sim_w, const Observations& o,
                         const std::vector<std::vector<double>>* end_w = nullptr);
/// The squared sample residuals at `lag_samples` over estimate_lag's samples, with the channel at its best scale within
/// [1 - scale_bound, 1 + scale_bound]: what tells two channel samplings apart whatever a logger's scale error adds to
/// both alike.
double scaled_lag_sse(const std::vector<std::vector<double>>& sim_w, const std::vector<std::vector<double>>* end_w,
                      const Observations& o, double lag_samples, double scale_bound);

// ---- engine start (engine_start.cpp) ---------------------------------------------------------------------------

/// A fuel-rate recording's engine start from its measured and simulated (warm-model) fuel power per sample: cold
/// unless the early running's excess over the model, relative to the late running's, is ruled out at
/// opt.engine_start_min_cold_excess (its 95 % upper bound below it). Not inferred (cold) when too short to tell.
EngineStartState infer_engine_start(const std::vector<double>& measured_w, const std::vector<double>& sim_w,
                                    const std::vector<double>& dt_s, const DriveCycle& c, const DiagnoseOptions& opt);

// ---- least squares with priors (fit.cpp) -----------------------------------------------------------------------

/// Priors of the calibration columns: Gaussian penalties (rows pulling a coefficient towards `target`) and hard
/// boxes (the channel scale, column 0; the RRC level and aero C, columns 1 and 2).
struct Prior {
  struct Row {
    Eigen::Index column;
    double weight, target;
  };
  struct Box {
    Eigen::Index column;
    double low, high;
  };
  std::vector<Row> rows;
  std::vector<Box> boxes;
};

struct Fit {
  Eigen::VectorXd coef;
  Eigen::MatrixXd cov;
  double rss = 0.0;
};
Fit least_squares(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, const Prior& prior = {});

double lag1_autocorrelation(const Eigen::VectorXd& r);
double rmse(const Eigen::VectorXd& a, const Eigen::VectorXd& b);
double energy_error_pct(const Eigen::VectorXd& pred, const Eigen::VectorXd& meas);
Eigen::MatrixXd hcat(const Eigen::MatrixXd& a, const Eigen::VectorXd& b);
/// Part of `s` not explained by the columns of `basis` (least squares).
Eigen::VectorXd cleaned(const Eigen::MatrixXd& basis, const Eigen::VectorXd& s);

/// The current model of the window energies: design, its fit, and what every test of one more column needs.
struct Model {
  Eigen::MatrixXd x;
  Fit fit;
  Eigen::VectorXd heldout;  // out-of-fold prediction
  const Eigen::VectorXd* y = nullptr;
  const std::vector<int>* fold_of = nullptr;
  Prior prior;
  double n_eff = 0.0, inflate = 1.0;
};

/// The model with one more column: its fit, Delta BIC on the effective n, and out-of-fold prediction.
struct Scored {
  Fit fit;
  double dbic = -1e300;
  Eigen::VectorXd heldout;
  double amplitude() const { return fit.coef[fit.coef.size() - 1] / fit.coef[0]; }  // per channel scale 1
  double amplitude_se(double inflate) const;
};
Eigen::VectorXd heldout_prediction(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, const std::vector<int>& fold_of,
                                   const Prior& prior);
/// The amplitude's 95 % interval (per channel scale 1) of `s`, the model `m` with `signature` as its last column.
/// Without an active box it is the fit's own, +-1.96 amplitude_se. With one (a scale pinned at its prior's bound),
/// the fit's covariance holds the pinned coefficient fixed and its interval is too narrow. This one is the
/// amplitude's profile: every other coefficient is refitted within its box, and the interval is where the penalised
/// criterion rises less than 1.96^2 inflate^2 times the residual variance (without a box, the same interval), or the
/// fit's own where that is wider. It widens where the pinned coefficient could move inward.
std::pair<double, double> amplitude_interval(const Model& m, const Eigen::VectorXd& signature, const Scored& s, double inflate);
double delta_bic(const Model& m, double rss_with);
Scored score_column(const Model& m, const Eigen::VectorXd& signature);
/// True when the candidate fits better out of fold than the model without it.
/// Fills the candidate's out-of-fold prediction (the costly part, done only for candidates that pass).
void add_heldout(const Model& m, const Eigen::VectorXd& signature, Scored& s);
bool improves_heldout(const Model& m, const Scored& s);
Model extended(const Model& m, const Eigen::VectorXd& signature, const Scored& s);
/// Held-out metrics of a finding, from the model before it and the fit with its signature as the last column,
/// and the share of the measured energy that column carries.
void set_finding_metrics(Finding& f, const Model& before, const Eigen::VectorXd& signature, const Scored& after);

// ---- calibration with priors (calibration.cpp) -----------------------------------------------------------------

struct Calibration {
  Model model;                // measured = s sim + a S_rrc + b S_drag, priors applied
  double prior_scale_bound = 0.0;
  Eigen::VectorXd free_coef;   // without the boxes (penalties kept)
  bool at_bound = false;       // a box is active
  double dbic_leave = 0.0;     // how strongly the data want out of the boxes (Delta BIC, free against boxed)
  bool sure = false;           // freeing the boxes passes a discovery's evidence bar
  bool outside_prior = false;  // the scale pinned at its box, RRC level or C beyond theirs by over 1 %, or surely
  std::vector<std::string> beyond;  // which of "channel_scale", "rrc_level", "drag" the free fit puts beyond its box
  double absorbed_j = 0.0;     // energy the free calibration would have absorbed beyond the boxed one
};
Calibration calibrate(const Observations& o, const Variant& base, const Variant& rrc, const Variant& drag,
                      const CalibrationPriors& priors, double bic_threshold);

// ---- candidate signatures (candidates.cpp) ---------------------------------------------------------------------

/// A catalogue effect with its shape parameters fixed (hidden-state effects: one per time constant).
struct Candidate {
  EffectId id{};
  std::string label;
  EffectParameters shape;
  const EffectParameterInfo* amplitude = nullptr;
  Eigen::VectorXd signature;  // window energy per unit amplitude
  /// Across-trip candidates (no own run): ambient_rrc a per-recording RRC level (from the RRC-level variant),
  /// hvac_ambient a per-recording constant electrical load (from aux_load's constant variant) following a law of
  /// the recorded ambient.
  enum class TripLaw { none, rrc_level, aux_level } across_trips = TripLaw::none;
  std::vector<double> trip_law;  // hvac_ambient: per recording, the load per unit amplitude [W per W/K]
  double cool_per_heat = 0.0;    // hvac_ambient: k_cool / k_heat of this candidate (a shape from a small grid)
  Eigen::VectorXd level_signature;  // hvac_ambient: aux_load's constant signature, per W
  /// wind_heading: mixed from the two runs with the wind from the north and from the east (no own run), as
  /// cos(theta) x north + sin(theta) x east: the headwind w cos(theta - psi) is linear in them.
  bool mixed_bearing = false;
  std::vector<std::vector<double>> power_w;  // its variant's per-sample channel power at the nominal amplitude
  double min() const { return amplitude->min; }
  double max() const { return amplitude->max; }
};

/// The force (or power) shapes that describe a residual no catalogue effect explains.
enum class ForceShape { constant, speed, speed_squared, positive_accel };
struct BasisShape {
  enum Kind { force, power } kind = force;
  ForceShape shape = ForceShape::constant;
  double decay_s = 0.0;  // 0: no decay
  Eigen::VectorXd signature;
  std::vector<std::vector<double>> power_w;  // force shapes: the variant's per-sample channel power (1 unit)
};
std::shared_ptr<const Effect> signature_force(ForceShape shape, double decay_s);
/// A force k x 0.5 rho CdA v^2 (the aero calibration's signature; air density per recording).
std::shared_ptr<const Effect> drag_scale(double k, double rho_cda);
/// 1 W at the measured channel, optionally decaying from each recording's start, per window.
Eigen::VectorXd power_signature(const Observations& o, const std::vector<DriveCycle>& cycles, double decay_s);

struct AmbientSetting {
  bool testable = false;
  bool hvac_testable = false;  // also an electric channel and a recording outside hvac_ambient's dead band
  std::vector<double> ambient_k;  // per recording
  double reference_k = 0.0;
};
AmbientSetting ambient_setting(const std::vector<Recording>& recordings, ChannelKind channel, const DiagnoseOptions& opt,
                               std::vector<std::string>& notes);
/// hvac_ambient's law at a recording's ambient, per W/K of heating: max(0, T_heat - T) + r max(0, T - T_cool) [K].
double hvac_law_k(double ambient_k, double cool_per_heat);
/// hvac_ambient's default of a dead-band parameter ("heat_below_c", "cool_above_c") [degC].
double hvac_default_c(const std::string& parameter);

struct Signatures {
  Variant base, rrc, drag;
  std::vector<Candidate> candidates;
  std::vector<BasisShape> basis;
};
/// Every variant (calibration, catalogue candidates, unexplained basis) in one parallel batch.
Signatures compute_signatures(const Replayer& rp, const Observations& o, const Variant& base, double lag_samples,
                              const AmbientSetting& amb, const EffectContext& ctx, const DiagnoseOptions& opt);

// ---- selection (selection.cpp, profile.cpp) --------------------------------------------------------------------

/// low, low 2^(1/k), ... up to high (and `also`, the value already chosen, merged in), ascending.
std::vector<double> log_grid(double low, double high, int per_octave, double also);

/// A time constant's log grid and a way to get the signature at any point of it.
struct TimeProfile {
  std::string parameter;
  double selected = 0.0;
  std::vector<double> grid;
  std::function<std::vector<Eigen::VectorXd>(const std::vector<double>&)> signatures;  // at these grid values
};
/// Profiles the criterion over the grid; adopts the grid's best (returned signature and score) if it also fits
/// better out of fold; the interval always holds the value kept.
struct ProfileResult {
  ProfileInterval interval;
  std::string parameter;
  Eigen::VectorXd signature;
  Scored score;
  std::vector<ParameterEstimate> nuisance;  // shape parameters fitted at the profile's best (aux_load's share)
};
ProfileResult profile_time_constant(const Model& m, const TimeProfile& tp, const Eigen::VectorXd& selected_signature,
                                    const Scored& selected_score, double amp_min, double amp_max);

/// wind_heading's bearing: the criterion profiled in 1 deg steps over the half circle centred on `centre_deg`, each
/// signature interpolated between `replayed`, the wind's replayed signatures every `step_deg` from centre - 90 to
/// centre + 90 deg (per unit of the wind speed's nominal value); its best adopted as profile_time_constant's is,
/// against the centre's. The interval is where n_eff ln(RSS / RSS_min) < 3.84 w, unwrapped (it may pass 0 or 360 deg),
/// open where it reaches +-90 deg; w >= 1 widens it to the bearing's delete-a-block jackknife variance where that is
/// larger than the one the ratio implies.
ProfileResult profile_bearing(const Model& m, double centre_deg, double step_deg, const std::vector<Eigen::VectorXd>& replayed,
                              const Scored& centre_score, double amp_min, double amp_max);

struct SelectionContext {
  const Replayer& replayer;
  const Observations& obs;
  const Variant& base;
  double lag_samples;
  const EffectContext& ctx;
  const AmbientSetting& ambient;
  const std::vector<Recording>& recordings;
  const DiagnoseOptions& opt;
  /// Regime evidence: the calibrated model's mean residual power when standing, its standard error (AR(1)) and
  /// effective number of samples; available only for per-sample channels.
  struct Standing {
    bool available = false;
    double mean_w = 0.0, se_w = 0.0, n_eff = 0.0;
    /// How far the standstills' own mean residuals scatter beyond the noise within them (a normal deviate), over
    /// `standstills` of 5 samples or more, whose means span `low_w` to `high_w`.
    double switching_z = 0.0;
    int standstills = 0;
    double low_w = 0.0, high_w = 0.0;
  } standing;
};

/// Forward selection of catalogue effects; the model grows by each finding.
/// A found constant aux_load (electric channels): whether a share of it decays from the trip's start, P0 + P1
/// exp(-t / tau), with tau profiled over [decay_low_s, decay_high_s] and the share fitted at each grid point; kept
/// (the candidate's shape, signature and `score` changed) only past the BIC threshold for its two extra parameters
/// and with a better held-out fit.
std::optional<ProfileResult> refine_aux_decay(const SelectionContext& sc, Candidate& c, const Model& m, Scored& score,
                                              double decay_low_s, double decay_high_s);

std::vector<Finding> select_effects(const SelectionContext& sc, const std::vector<Candidate>& cands, Model& m,
                                    std::vector<EffectId>& chosen);
std::vector<DetectionLimit> detection_limits(const std::vector<Candidate>& cands, const std::vector<EffectId>& chosen,
                                             const Model& m, const DiagnoseOptions& opt);

// ---- road profile when elevation is withheld (road_profile.cpp) -------------------------------------------------

struct NoiseFloor;
/// The residual inverted into an elevation profile along distance; a road_profile finding (the model grows by its
/// column) when it explains decisively more than any single shape, predicts held-out windows and the residual is
/// quiet standing. One recording without elevation or grade, per-sample channels only; the evidence goes to `notes`.
std::optional<Finding> infer_road_profile(const SelectionContext& sc, const std::vector<DriveCycle>& cycles,
                                          const Signatures& sig, const std::vector<Finding>& found,
                                          const std::vector<EffectId>& chosen, const NoiseFloor& floor, Model& m,
                                          std::vector<std::string>& notes);

// ---- unexplained residual (unexplained.cpp) --------------------------------------------------------------------

std::optional<Finding> describe_unexplained(const SelectionContext& sc, const std::vector<DriveCycle>& cycles,
                                            const std::vector<BasisShape>& basis, Model& m);

// ---- location (locate.cpp) -------------------------------------------------------------------------------------


std::vector<DiagnosisWindow> window_series(const Observations& o, const std::vector<Recording>& recordings,
                                           const Eigen::VectorXd& base_j, const Eigen::VectorXd& calibrated_j,
                                           const Eigen::VectorXd& fitted_j);

// ---- small text helpers (output.cpp) ---------------------------------------------------------------------------
std::string num(double v);
using rollsim::fixed;  // common/format.hpp

}  // namespace rollsim::diag

namespace rollsim::diag {

// ---- adequacy against the noise floor (adequacy.cpp) -----------------------------------------------------------

struct NoiseFloor {
  double variance_per_s = 0.0;  // of a window's noise energy [J^2], per second of window (white)
  /// Of each reading a window's energy is taken between [J^2]: a state of charge's quantum, (q C)^2 / 12. It does not
  /// grow with a window's length (two readings bound any window), where white noise does.
  double endpoint_variance_j2 = 0.0;
  int triples = 0;
  double window_s = 0.0;
  /// A noise window's energy variance [J^2].
  double window_variance_j2() const { return variance_per_s * window_s + 2.0 * endpoint_variance_j2; }
  /// Per window of the observations, per Monte Carlo draw: the energy the grade's errors from a recorded elevation's
  /// white noise add [J] (errors in the model's input, correlated over the filter's 300 m: no short window sees them).
  /// Empty without an elevation column.
  Eigen::MatrixXd grade_window_j;
};
/// From the calibrated residual of short windows (`short_obs`): the mean squared second difference over 6, less the
/// part the readings' own errors (`endpoint_variance_j2` each) put in it (20 of them in a second difference).
NoiseFloor noise_floor(const Observations& short_obs, const Eigen::VectorXd& resid, double endpoint_variance_j2 = 0.0);

struct Adequacy {
  double ratio = 0.0, z = -1e300, scale_s = 0.0;  // at the scale of largest z
  double grade_share = 0.0;  // of the expected variance there, the recorded elevation's noise
  bool inadequate = false;
  int blocks = 0, flagged = 0;
  double flagged_j = 0.0, first_s = 0.0, last_s = 0.0, first_m = 0.0, last_m = 0.0, flagged_mean_speed_mps = 0.0;
  double flagged_abs_j = 0.0;  ///< the flagged blocks' residuals summed by size, whatever their sign
  std::vector<double> flagged_abs_by_recording_j;  ///< the same per recording
};
Adequacy test_adequacy(const Observations& o, const std::vector<Recording>& recs, const Eigen::VectorXd& resid,
                       const NoiseFloor& nf, const DiagnoseOptions& opt);
/// Mean residual of the calibrated model by regime; per-sample channels also give the standing residual's evidence.
std::vector<RegimeResidual> locate_regimes(const Observations& o, const std::vector<Recording>& recordings,
                                           const std::vector<DriveCycle>& cycles, const Signatures& s,
                                           const Eigen::VectorXd& cal_coef, double lag_samples,
                                           SelectionContext::Standing* standing);
Finding adequacy_finding(const Adequacy& a, const NoiseFloor& nf, const Observations& o, const std::vector<Recording>& recs,
                         const std::vector<RegimeResidual>& located, bool grade_from_elevation);

}  // namespace rollsim::diag

namespace rollsim::diag {
/// Monte Carlo draws of a recorded elevation's grade errors: the mean square of 64 has a relative sd of 18 %, weighed
/// in the adequacy test's z by its share.
constexpr int kGradeNoiseDraws = 64;
/// Per recording, per draw, per sample: the grade's errors from its recorded elevation's noise (grade_noise_draws with
/// the noise and drift the recording's own readings show, kGradeNoiseDraws of them); empty for a recording whose grade
/// is not from a recorded elevation.
using GradeNoiseDraws = std::vector<std::vector<std::vector<double>>>;
/// The calibrated model's short-window floor, and the energies the recorded elevations' noise adds through the grade
/// (`mass_kg` the grade force's mass).
NoiseFloor calibrated_noise_floor(const Observations& o, const std::vector<Recording>& recs, const Signatures& s,
                                  const Calibration& cal, double lag_samples, double mass_kg, const GradeNoiseDraws& grade_draws,
                                  const DiagnoseOptions& opt);
std::string calibration_outside_prior_text(const Calibration& c, const Observations& o, const std::vector<Candidate>& cands,
                                           bool with_explanations = true);
}  // namespace rollsim::diag
namespace rollsim::diag {
Eigen::VectorXd per_recording_residual(const Model& m, const Observations& o, std::size_t recordings);
}  // namespace rollsim::diag
