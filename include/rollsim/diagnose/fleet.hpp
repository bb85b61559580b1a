// Fleet diagnosis: a manifest of vehicles and recordings, one diagnosis per group, and what the fleet has in common.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "rollsim/common/distribute.hpp"
#include "rollsim/common/json.hpp"
#include "rollsim/diagnose/diagnose.hpp"
#include "rollsim/recording/recording.hpp"

namespace rollsim {

/// One recording of the manifest, its files resolved and its column mapping assembled.
struct FleetRecording {
  std::string path;
  ColumnMapping mapping;
  std::size_t line = 0;  ///< the manifest line that names it
};

/// One diagnosis: the recordings of one group (or of one vehicle, where the manifest has no group column).
struct FleetGroup {
  std::string name;
  std::string vehicle_path, tyre_path;  ///< tyre_path empty: the vehicle's own tyres
  std::vector<FleetRecording> recordings;
};

struct FleetManifest {
  std::string file;
  std::vector<FleetGroup> groups;  ///< in order of first appearance
};

/// Reads a fleet manifest CSV. Columns: `vehicle` and `recording` (required), `group`, `tyre`, `preset`,
/// `columns` and `scales` (semicolon-separated CANONICAL=SOURCE / CANONICAL=FACTOR, as diagnose's --column and
/// --scale). Paths are relative to the manifest's folder (then as diagnose resolves them). Every file and mapping
/// is checked here, before any diagnosis: an error names the manifest, the line, the column and the value.
FleetManifest read_fleet_manifest(const std::string& path);

struct FleetFinding {
  std::string effect;     ///< catalogue id or "unexplained"
  std::string parameter;  ///< its first fitted parameter ("" for none)
  std::string unit;
  double value = 0.0;
  double energy_share_pct = 0.0;  ///< NaN for a finding that is no fitted effect
};

struct FleetEntry {
  std::string group, vehicle, verdict, channel;
  std::size_t recordings = 0;
  std::vector<FleetFinding> findings;
  std::vector<std::string> warnings;  ///< the diagnosis' warnings (a verdict to be read with them)
};

/// One effect across the fleet: in how many diagnoses it was found, and its median size there.
struct FleetEffect {
  std::string effect, parameter, unit;
  std::size_t groups = 0;
  double share_pct = 0.0;    ///< of all diagnoses
  double median_value = 0.0;  ///< of `parameter`: the first parameter most of its diagnoses report, in `unit`
};

/// The fleet summary of `entries`, most frequent effect first (ties: by id). It does not depend on the entries'
/// order.
std::vector<FleetEffect> summarise_fleet(const std::vector<FleetEntry>& entries);

struct FleetResult {
  std::string manifest;
  std::vector<FleetEntry> entries;  ///< in manifest order
  std::vector<FleetEffect> effects;  ///< most frequent first (ties: by id)
};

struct FleetOptions {
  DiagnoseOptions diagnose;
  unsigned threads = 0;  ///< 0: every core
  /// How the groups are spread (over MPI ranks by the CLI); empty = this process's threads.
  CaseMap map_cases;
};

/// Diagnoses every group (its vehicle and recordings loaded by the process that runs it) and summarises the fleet.
/// A group that cannot be read or diagnosed ends the run with its manifest line named.
FleetResult diagnose_fleet(const FleetManifest& manifest, const FleetOptions& options);

std::string fleet_text(const FleetResult& result);
/// One object per diagnosis, then one per effect of the summary.
std::vector<JsonObject> fleet_json(const FleetResult& result);

}  // namespace rollsim
