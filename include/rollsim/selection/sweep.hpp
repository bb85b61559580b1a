// Parameter sweeps of a tyre (RRC, force, power) or of a car on a cycle (energy or fuel), one or two axes.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "rollsim/common/distribute.hpp"
#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/sim/simulation.hpp"
#include "rollsim/tyre/tyre_model.hpp"
#include "rollsim/tyre/tyre_spec.hpp"
#include "rollsim/vehicle/vehicle.hpp"

namespace rollsim::selection {

/// What a sweep varies; values are in the user's units (bar, mm, mm, N, % of max load, km/h).
enum class SweepParam { Pressure, Diameter, Width, Load, LoadPct, Speed };

/// Parses "pressure", "diameter", "width", "load", "load-pct", "speed"; nullopt otherwise.
std::optional<SweepParam> parse_sweep_param(const std::string& text);
std::string sweep_param_key(SweepParam p);   ///< "pressure"
std::string sweep_param_unit(SweepParam p);  ///< "bar"

struct SweepAxis {
  SweepParam param = SweepParam::Pressure;
  double from = 0.0;  ///< user units
  double to = 0.0;
  int steps = 11;     ///< points including both ends, >= 2
  std::vector<double> values() const;
};

/// Most points in one sweep (the product of the axes' steps), checked before the grid is built: about 300 bytes
/// each in memory and 100 in the CSV for the tyre alone; one forward simulation each (about 2 ms) with a car.
inline constexpr std::size_t kMaxTyreSweepPoints = 1000000;
inline constexpr std::size_t kMaxVehicleSweepPoints = 100000;

/// Throws InputError (naming `option`) for an empty or reversed range or steps < 2.
void check_axis(const SweepAxis& axis, const std::string& option);

struct SweepOptions {
  std::vector<SweepAxis> axes;         ///< one or two
  /// Fixed load; default 80 % of the tyre's maximum load, with a car its heavier static wheel load.
  std::optional<double> load_n;
  double speed_kmh = 80.0;             ///< fixed speed
  unsigned threads = 0;                ///< vehicle sweeps: 0 = every core
  bool replay = false;                 ///< vehicle sweeps: kinematic replay instead of the forward simulation
  /// Vehicle sweeps: how the points are spread (over MPI ranks by the CLI); empty = this process's threads.
  CaseMap map_cases;
  /// Called as points finish (done, total), possibly from worker threads; must be thread-safe.
  std::function<void(std::size_t, std::size_t)> progress;
};

struct SweepPoint {
  std::vector<double> values;          ///< one per axis, user units
  double load_n = 0.0;
  double speed_kmh = 0.0;
  RollingResistance rr;                ///< the tyre at (load, speed)
  double energy = 0.0;                 ///< vehicle sweeps: kWh/10 km or l/100 km
  TraceFollowing trace;                ///< vehicle sweeps: whether the car kept to the cycle (EnergyFigure)
  std::string overcharge;              ///< vehicle sweeps: the battery charged past full (EnergyFigure), or empty
};

struct SweepResult {
  std::vector<SweepAxis> axes;
  bool vehicle = false;
  std::string energy_unit;             ///< vehicle sweeps
  std::vector<SweepPoint> points;      ///< valid points in sweep order
  std::size_t planned_points = 0;
  /// Set when points are outside the model's domain (left out; the rest are computed, whichever end of a range or
  /// corner of a grid they are at): how many, the first, and why.
  std::optional<std::string> outside_domain;
  double max_load_n = 0.0;             ///< the tyre's rated maximum load; 0 when unknown
};

/// The sweep's warnings, each one line without a "warning:" prefix: points above the tyre's rated load, and
/// (vehicle sweeps) points whose battery charged past full, and how many points could not follow the cycle and
/// what their figures measured instead (report::shortfall_caveat).
std::vector<std::string> sweep_warnings(const SweepResult& result);

/// The tyre with one parameter set (user units); load/speed parameters leave the tyre unchanged.
TyreSpec with_parameter(const TyreSpec& tyre, SweepParam p, double value);

/// Tyre alone: RRC, force, power at every point. Stops at the first point outside the model's domain
/// (points are visited first axis outer, second inner, each axis from `from` to `to`).
SweepResult sweep_tyre(const TyreSpec& tyre, const SweepOptions& options);

/// The car on `cycle` with the swept tyre on all four wheels (pressure, diameter, width only): forward
/// simulation (or replay) per point, on every core, the car assembled once and only its tyres made per point.
/// Stops like sweep_tyre.
SweepResult sweep_vehicle(const Vehicle& vehicle, const TyreSpec& tyre, const DriveCycle& cycle,
                          const SweepOptions& options);

/// Where a point is, as (column, value) pairs: each axis (pressure_bar, diameter_mm, width_mm, load_n, load_pct,
/// speed_kmh), then the load and speed the tyre was evaluated at unless an axis already is that column, so every
/// column name is unique.
std::vector<std::pair<std::string, double>> sweep_point_columns(const SweepResult& result, const SweepPoint& point);

/// The sweep as CSV (header + one line per point).
std::string sweep_csv(const SweepResult& result);

}  // namespace rollsim::selection
