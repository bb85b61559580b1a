// Synthetic recordings with concealed effects for the discovery benchmark: each truth is richer than its catalogue module.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/recording/recording.hpp"
#include "rollsim/vehicle/vehicle.hpp"

namespace rollsim {

/// A concealed effect of the truth, by its truth identifier (see concealed_truths()) and its size in that truth's
/// own unit. The truth's model is its own code (an Effect in generate.cpp, a changed vehicle parameter run through
/// the tyre model or the powertrain, or a road profile), never the catalogue module that the diagnosis fits.
struct ConcealedEffect {
  std::string truth;
  double size = 0.0;
};

/// The energy channel a synthetic recording carries (the logger's artefacts are in that channel's own units).
enum class SyntheticChannel {
  battery_power,  ///< Recording::battery_power_w (electric car)
  fuel_rate,      ///< Recording::fuel_rate_m3ps (combustion car)
  soc,            ///< Recording::soc_fraction, quantised like a BMS display (electric car)
};

/// What each truth is, which catalogue effect an honest diagnosis should name, and a sweep of sizes. Members after
/// `sweep` carry initialisers (also the strings' `{}`): the truth table's rows leave out what they do not use.
struct ConcealedTruthInfo {
  std::string truth;            ///< e.g. "aux_compressor"
  std::string catalogue_id;     ///< the effect it should be named as, e.g. "aux_load"
  std::string size_unit;
  std::string description;      ///< the truth's model, in words
  std::vector<double> sweep;    ///< sizes, smallest effect first
  /// The channel the truth is written to; a fuel-channel truth needs a combustion car (vehicles/ice.yaml).
  SyntheticChannel channel = SyntheticChannel::battery_power;
  /// Across-trip truths (ambient temperature): concealed in several trips at different ambients (generate_trips),
  /// never in one recording.
  bool multi_trip = false;
  /// +1: the truth's physics has a sign (a load draws power, a cold tyre rolls harder), so the expected effect
  /// found with a negative size is a mistake, not a discovery; 0: either sign is physical (wind, grade).
  int sign = 0;
  /// Recorded through a real logger's artefacts (real_logger()): a lag of 0.3-1.7 s that is not a whole number of
  /// samples, and a channel-scale jitter of +-3 %.
  bool real_logger = false;
  /// A null for this catalogue id (e.g. an RRC rising over the trip for tyre_warmup): catalogue_id is empty, and
  /// any finding of this id, of either sign, is the mistake the row counts.
  std::string never_called{};
  /// The trip the truth is concealed in when it needs its own (empty: the bench's WLTC x2): a shipped cycle, twice,
  /// with an engine-off standstill of soak_s between the two (a cold-start test's soak).
  std::string cycle{};
  double soak_s = 0.0;
  /// The trip is driven on a winding route whose latitude and longitude the recording carries.
  bool gps = false;
};
const std::vector<ConcealedTruthInfo>& concealed_truths();
const ConcealedTruthInfo& concealed_truth(const std::string& truth);  ///< throws InputError when unknown

/// One synthetic recording: a speed trace (a shipped cycle repeated, or "steady", an hour of 90 km/h cruising with
/// slow +-1 km/h drift), the concealed effects, and the logger's artefacts in the chosen channel (battery power or
/// SOC of an electric car, fuel rate of a combustion car).
struct SyntheticCase {
  std::string cycle = "wltc";
  /// A real speed trace to use instead of `cycle` (e.g. a shipped recording's, via cycle_of_recording); its grade
  /// is dropped, so the truth drives a flat road at the recorded speeds. `repeats` is ignored.
  std::optional<DriveCycle> trace;
  int repeats = 2;
  /// Between repeats, a standstill of this long with the engine switched off (fuel exactly zero), as the 10-minute
  /// soak between a cold-start test's two UDDS; 0: the repeats follow each other directly.
  double soak_s = 0.0;
  std::vector<ConcealedEffect> effects;
  /// Driven on a winding route (winding_route, drawn per seed), recorded with latitude and longitude (GPS noise
  /// 2 m sd per axis); the steady-wind truth needs it.
  bool gps = false;
  /// The steady-wind truth's bearing (clockwise from north, where it blows from) [deg]; unset: drawn per seed.
  std::optional<double> wind_from_deg;
  double rrc_level_jitter = 0.03;  ///< truth's RRC level, uniform +- (calibration, not a discovery)
  double scale_jitter = 0.02;      ///< measured channel scale, uniform +-
  double noise_w = 400.0;          ///< white sensor noise, standard deviation
  double quantum_w = 100.0;        ///< logger quantisation
  double lag_s = 1.0;              ///< channel lag; the channel is interpolated, so it need not be whole samples
  double lag_max_s = 0.0;          ///< above lag_s: the lag is drawn per seed, uniform in [lag_s, lag_max_s]
  SyntheticChannel channel = SyntheticChannel::battery_power;
  /// Fuel channel: white noise of the fuel power [W] (three times noise_w: at the engine's ~30 % efficiency the
  /// same road-load error is three times the chemical power) and the flow meter's quantum (0.05 l/h).
  double fuel_noise_w = 1200.0;
  double fuel_quantum_m3ps = 0.05e-3 / 3600.0;
  double soc_quantum = 0.001;  ///< SOC channel: the BMS's resolution (0.1 %); the channel is noise-free otherwise
  bool time_reversed = false;      ///< tyre truths: the warm-up decay placed at the end of the trip (a null)
  /// The trip's ambient temperature [degC]: the ambient truths read it, and the recording carries it as
  /// ambient_temp_k (sensor noise 0.3 K, 0.5 K quantum). Unset: no ambient channel.
  std::optional<double> ambient_temp_c;
  std::optional<double> rrc_level;      ///< the truth's RRC level instead of a jitter draw (trips of one car share it)
  std::optional<double> channel_scale;  ///< the channel scale instead of a jitter draw (one logger on every trip)
  unsigned seed = 1;
};
Recording generate_case(const Vehicle& vehicle, const SyntheticCase& c);

/// A real logger's artefacts on top of `c`'s: a lag of 0.3-1.7 s drawn per seed (not a whole number of samples)
/// and a channel-scale jitter of +-3 %.
SyntheticCase real_logger(SyntheticCase c);

/// Several trips of one car and logger at different ambient temperatures (the across-trip truths' proof): one RRC
/// level and one channel scale (drawn once, as SyntheticCase's jitters), a trip-to-trip RRC scatter (tyre pressure,
/// road surface), and ambients stratified over [ambient_min_c, ambient_max_c] (one trip per equal slice, in random
/// order).
struct MultiTripCase {
  std::vector<std::string> cycles{"wltc", "ftp75", "artemis_road", "wltc"};  ///< one trip each
  std::vector<ConcealedEffect> effects;
  double ambient_min_c = -5.0, ambient_max_c = 30.0;
  double trip_rrc_scatter = 0.015;  ///< each trip's RRC level, uniform +- this fraction about the car's
  SyntheticCase artefacts;          ///< noise, quantum, lag, jitters and channel; its cycle and effects are ignored
  unsigned seed = 1;
};
std::vector<Recording> generate_trips(const Vehicle& vehicle, const MultiTripCase& c);

/// Synthetic recording with a concealed effect, for the proof. The truth uses its own models (a two-node tyre
/// thermal network with an exponential RRC law), never the catalogue's modules.
struct SyntheticOptions {
  std::string cycle = "wltc";
  int repeats = 2;
  double tyre_cold_excess = 0.0;   ///< truth's RRC excess of a cold tyre (0: null recording)
  double rrc_level_jitter = 0.03;  ///< truth's RRC level, uniform +- (calibration, not a discovery)
  double scale_jitter = 0.02;      ///< measured channel scale, uniform +-
  double noise_w = 400.0;          ///< white sensor noise, standard deviation
  double quantum_w = 100.0;        ///< logger quantisation
  double lag_s = 1.0;              ///< channel lag
  bool time_reversed = false;      ///< the truth's warm-up decay placed at the end of the trip (a null)
  unsigned seed = 1;
};
Recording generate_recording(const Vehicle& vehicle, const SyntheticOptions& opt);

}  // namespace rollsim
