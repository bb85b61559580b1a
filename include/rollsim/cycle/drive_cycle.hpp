// Drive cycles: speed (and grade) against time, loaded by name or from a user CSV, with fast lookups.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "rollsim/common/csv.hpp"

namespace rollsim {

/// A piecewise-linear speed trace. time_s is strictly increasing, speed_mps >= 0, grade (rise over run,
/// dimensionless) has the same length (all zeros when the file gave none). Between samples every channel is
/// linearly interpolated; outside [time_s.front(), time_s.back()] the end values are held.
struct DriveCycle {
  std::string name;    ///< shipped name ("nedc") or the file's stem
  std::string source;  ///< path the trace was read from
  std::vector<double> time_s;
  std::vector<double> speed_mps;
  std::vector<double> grade;
  /// Per sample: the engine is switched off over the segment starting here (a soak between two tests, start-stop
  /// at a light), so it burns no fuel; empty when the engine runs throughout (every shipped cycle; a CSV file
  /// without an engine_on column or with the engine on throughout).
  std::vector<bool> engine_off;
  /// Per sample: over a segment with the engine off, the electrical accessories stay on, fed by the 12 V battery
  /// (start-stop at a light; the alternator puts the charge back after the restart); empty or false: they are off
  /// with the engine (a soak with the key off). A cycle CSV's accessories_on column.
  std::vector<bool> accessories_on;
  /// The engine is warm when the trace starts (a hot start, e.g. the second half of a test after a short soak);
  /// otherwise it starts cold, at ambient.
  bool engine_hot_start = false;
  /// Per sample: the direction of travel over the segment starting here, clockwise from north [rad] (from a
  /// recording's latitude and longitude, or a cycle CSV's heading_deg); empty where the route's heading is unknown.
  std::vector<double> heading_rad;
  /// What the file holds that a user should hear of, though it is allowed (one line each, no "warning:" prefix):
  /// a long interval between samples of a moving car, which the linear interpolation drives as if it were there.
  std::vector<std::string> notes;
  /// Columns of the file that are not cycle columns (a table's phase, gear), quoted ('phase'), in file order: not
  /// read, and said (ignored_columns_note), so no output implies that they were used.
  std::vector<std::string> ignored_columns;

  bool engine_off_at(std::size_t segment) const { return segment < engine_off.size() && engine_off[segment]; }
  bool accessories_on_at(std::size_t segment) const { return segment < accessories_on.size() && accessories_on[segment]; }
  bool any_engine_off() const;
  /// Stores engine_off's documented form: all-running becomes empty, so readers need not search for a true flag.
  void set_engine_off(std::vector<bool> off_per_segment);
  double duration_s() const;  ///< last time minus first time
  double distance_m() const;  ///< trapezoid integral of speed, exact for the piecewise-linear trace

  /// Index i of the segment [time_s[i], time_s[i+1]) holding t, clamped to [0, size-2]. At a sample time the
  /// following segment is returned. `hint` (e.g. the previous answer) makes sequential calls O(1); any
  /// value is safe, a wrong hint only costs a binary search.
  std::size_t segment_index(double t, std::size_t hint = 0) const;

  double speed_mps_at(double t) const;
  double accel_mps2_at(double t) const;  ///< slope of the segment holding t; 0 outside the trace
  double grade_at(double t) const;
  /// Hinted forms for integrators: `hint` is read and updated with the segment used.
  double speed_mps_at(double t, std::size_t& hint) const;
  double accel_mps2_at(double t, std::size_t& hint) const;
  double grade_at(double t, std::size_t& hint) const;
};

/// Interior sample times where the piecewise-linear speed changes slope (kinks), a standstill begins, or what a
/// segment holds besides its speed changes (grade, engine_off, accessories_on, heading), in increasing order; the first
/// and last sample times are not included. An integrator uses them as stop times so that it never steps across a
/// discontinuity of the power.
std::vector<double> breakpoints_s(const DriveCycle& cycle);
/// Times, in increasing order, where the piecewise-linear speed crosses `speed_mps` (reaching it at an interior
/// sample counts; the last sample does not), only while it falls if `falling_only`: where a powertrain's regime
/// speed lies on the trace.
std::vector<double> crossing_times_s(const DriveCycle& cycle, double speed_mps, bool falling_only = false);

/// Names accepted by load_cycle besides paths, in a stable order ("wltc" is an alias of "wltc_class3b").
std::vector<std::string> shipped_cycle_names();

/// Loads a shipped cycle by name (case-insensitive, see shipped_cycle_names) or a CSV file by path.
/// CSV: a header line, then one sample per line. Columns: `time_s` (increasing by 1 ms to one day per sample),
/// exactly one of `speed_kmh` or `speed_mps` (0 to 500 km/h; at most 2 g between samples), and at most one of
/// `grade_pct` (percent, within +-30) or `elevation_m` (converted to grade over travelled distance); optionally
/// `heading_deg` (direction of travel, clockwise from north, [0, 360]: wind_heading reads it) and `engine_on` (1, or
/// 0 where the engine is switched off over the segment from that sample, standing only: no fuel, a cold engine
/// cools). Other columns are ignored (DriveCycle::ignored_columns), unless named like a cycle column (time, speed,
/// grade, elevation, altitude, heading, engine in any case): those are refused as misspellings. Any bad value
/// throws InputError naming file, line, column, the value and the allowed range.
/// `option` names where the name came from in error messages (e.g. "--cycle").
DriveCycle load_cycle(const std::string& name_or_path, const std::string& option = "--cycle");

/// "FILE: columns 'phase', 'gear' not read (...)" for a cycle with ignored columns (a note for stderr), else "".
std::string ignored_columns_note(const DriveCycle& cycle);

/// Reads a cycle CSV at `path` (no name lookup); `name` becomes DriveCycle::name.
DriveCycle read_cycle_csv(const std::string& path, const std::string& name);

/// A cycle from a table already in memory (e.g. a user's arrays from Python), with the columns and checks of
/// the CSV file; errors name table.file and the line numbers the table carries.
DriveCycle cycle_from_table(const CsvTable& table, const std::string& name);

/// Largest |grade| a cycle may hold: 30 %, steeper than any public road.
inline constexpr double kMaxCycleGrade = 0.30;
/// Fastest a cycle may ask for: 500 km/h, beyond any road car and any tyre's speed rating (a file's unit).
inline constexpr double kMaxCycleSpeed_kmh = 500.0;
/// Largest |acceleration| between two samples [m/s^2]: 2 g, beyond the grip of any tyre on a road.
inline constexpr double kMaxCycleAccel_mps2 = 19.6;
/// Closest and farthest two samples may be [s]: 1 ms (a 1 kHz logger) and one day (a car parked overnight).
inline constexpr double kMinCycleTimeStep_s = 1e-3;
inline constexpr double kMaxCycleTimeStep_s = 86400.0;
/// A longer interval between two samples of a moving car is noted (DriveCycle::notes): a logger's gap is otherwise
/// driven as a straight line between its ends, at speed, for as long as it lasts.
inline constexpr double kNotedMovingGap_s = 30.0;
/// A faster speed in a speed_mps column is noted: beyond every drive cycle, where a km/h log under the wrong
/// header lands (a WLTC's 131 km/h reads as 473 km/h).
inline constexpr double kNotedCycleSpeed_kmh = 250.0;

}  // namespace rollsim
