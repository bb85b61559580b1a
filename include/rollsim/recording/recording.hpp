// Recordings of real vehicles (speed plus a measured energy channel) read from loggers' CSV files, in SI.
#pragma once

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "rollsim/common/yaml_reader.hpp"

namespace rollsim {

/// One recorded trip, SI inside. time_s is strictly increasing (gaps kept, see repairs); every present
/// channel has time_s.size() samples and holds no NaN (short NaN runs are bridged and reported in repairs).
struct Recording {
  std::string source;  ///< path read
  std::vector<double> time_s;     ///< file's own time base; clock times are seconds since midnight of day one
  std::vector<double> speed_mps;  ///< >= 0
  std::optional<std::vector<double>> battery_power_w;    ///< positive when discharging
  std::optional<std::vector<double>> battery_voltage_v;  ///< > 0
  std::optional<std::vector<double>> battery_current_a;  ///< positive when discharging
  std::optional<std::vector<double>> soc_fraction;       ///< state of charge, [0, 1]
  std::optional<std::vector<double>> fuel_rate_m3ps;     ///< fuel volume flow, >= 0
  std::optional<std::vector<double>> elevation_m;
  std::optional<std::vector<double>> grade;  ///< rise over run
  std::optional<std::vector<double>> ambient_temp_k;
  std::optional<std::vector<double>> latitude_deg;
  std::optional<std::vector<double>> longitude_deg;
  std::vector<std::string> repairs;  ///< every change made to the file's values, and gaps kept, in words

  double duration_s() const { return time_s.empty() ? 0.0 : time_s.back() - time_s.front(); }
  double distance_m() const;  ///< trapezoid integral of speed, gaps (steps over kReportedGap_s) left out
};

/// How a logger's columns map to rollsim's canonical ones. Canonical names, in the file's own units:
/// time_s (s, or clock text HH:MM:SS[.fff]), date (text: confirms a clock passing midnight, and a date moving on across a break in the logging starts a later day),
/// speed_kmh, battery_power_kw (+ discharging), battery_voltage_v, battery_current_a (+ discharging), soc_pct,
/// fuel_rate_lph, elevation_m, grade_pct, ambient_temp_c, latitude, longitude (degrees).
/// A canonical column without a mapping is looked up under its own name. The scale multiplies the source
/// column before its unit is interpreted (mph -> km/h: 1.609344; a current logged negative when discharging: -1).
struct ColumnMapping {
  std::map<std::string, std::string> source_for_canonical;
  std::map<std::string, double> scale_for_canonical;
  /// How the user of a front end maps a column, for the loader's hints, with CANONICAL standing for the column's
  /// name: "with --column CANONICAL=SOURCE" (command line), "with columns={'CANONICAL': SOURCE}" (Python). Each
  /// front end sets its own; empty, a hint names only the column to map.
  std::string how_to_map;
};

/// The canonical column names, in the order above.
const std::vector<std::string>& canonical_recording_columns();

/// Adds one `--column CANONICAL=SOURCE` option to `mapping`; `--column CANONICAL=` (nothing after '=') drops the
/// column (a preset's mapping included; time_s and speed_kmh cannot be dropped). Throws InputError naming the option
/// as its front end calls it (`option`: "--column", a manifest's "columns" cell, Python's "columns").
void parse_column_option(const std::string& text, ColumnMapping& mapping, const std::string& option = "--column");
/// Adds one `--scale CANONICAL=FACTOR` option (finite, non-zero) to `mapping`; throws InputError naming it.
void parse_scale_option(const std::string& text, ColumnMapping& mapping, const std::string& option = "--scale");

/// Reads the optional blocks `recording_columns: {canonical: source}` and `recording_scale: {canonical: factor}`
/// of a vehicle file (both marked read on `file`); errors name the file and key.
ColumnMapping column_mapping_from_yaml(YamlMap& file);

/// Ready-made mappings for the shipped recordings (../shared/data/recordings/):
/// - `anl_d3`: Argonne D3 dynamometer files: time_s = `Time[s]`, speed_kmh = `Dyno_Spd[mph]` x 1.609344,
///   fuel_rate_lph = `Eng_FuelFlow_Direct_DI[ccps]` x 3.6 (cm3/s -> l/h).
/// - `rsk_twizy`: RSK Renault Twizy trips: time_s = `Time` (clock), date = `Date`, soc_pct = `Soc`,
///   speed_kmh = `Speed`, elevation_m = `ALT`, ambient_temp_c = `Temperature`, latitude = `LAT`, longitude = `LON`.
/// Options given after a preset override its entries (merge with merge_mapping).
ColumnMapping preset_mapping(const std::string& name);
std::vector<std::string> preset_mapping_names();
/// Entries of `overrides` replace those of `base`; a column mapped to another source drops its scale from `base`
/// (a scale is its source column's unit) unless `overrides` gives one.
ColumnMapping merge_mapping(ColumnMapping base, const ColumnMapping& overrides);
/// The mapping a diagnosis uses: the preset (if named), then the vehicle file's own logger blocks, then the
/// `--column C=S` and `--scale C=F` options, each overriding the one before.
/// `column_option` and `scale_option` name the two as the front end does (errors quote them).
ColumnMapping assemble_mapping(const std::string& preset, YamlMap& vehicle_file, const std::vector<std::string>& columns,
                               const std::vector<std::string>& scales, const std::string& column_option = "--column",
                               const std::string& scale_option = "--scale");

/// Longest run of missing values (empty cell or NaN) bridged by linear interpolation; longer runs are errors.
inline constexpr double kMaxBridgedRun_s = 5.0;
/// Time steps longer than this are gaps: kept as they are and listed in Recording::repairs.
inline constexpr double kReportedGap_s = 5.0;
/// Shortest recording accepted.
inline constexpr double kMinRecordingDuration_s = 60.0;
/// Lowest fuel rate read as a flow meter's zero offset and kept (listed in Recording::repairs); lower is refused.
inline constexpr double kFuelZeroOffset_lph = -1.0;
/// Most samples in one recording: a loaded sample takes about 600 bytes (channels, replay and diagnosis
/// arrays), so this bounds one recording near 600 MB (28 h at 10 Hz); longer logs are split into trips.
inline constexpr std::size_t kMaxRecordingSamples = 1000000;

/// Reads a recording CSV (header line, RFC 4180 quoting) through `mapping`. Needs time_s, speed_kmh and at
/// least one energy channel (battery_power_kw, battery_voltage_v with battery_current_a, soc_pct or
/// fuel_rate_lph). Sample interval 0.01 to 1 s (1 to 100 Hz, median; 2 % more for a logger's clock). Throws InputError naming file, line
/// and column for: a missing column (found columns listed, --column suggested), text in a number column,
/// infinite or out-of-range values, time repeating or going backwards, NaN runs longer than
/// kMaxBridgedRun_s, a recording shorter than kMinRecordingDuration_s, no energy channel, more than
/// kMaxRecordingSamples rows (checked while reading, before anything else is allocated). GPS latitude and longitude,
/// which the diagnosis does not need, never throw: bad cells are read as missing and a column too broken to bridge is
/// dropped, each with a "warning:" in repairs. A canonical column mapped to "" is not read.
Recording load_recording(const std::string& path, const ColumnMapping& mapping);

}  // namespace rollsim
