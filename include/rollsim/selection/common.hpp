// Shared helpers of tyre selection: running a car on a cycle with a given tyre, the car's figure of merit.
#pragma once

#include <string>

#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/sim/simulation.hpp"
#include "rollsim/vehicle/vehicle.hpp"

namespace rollsim::selection {

/// The car's headline figure: fuel per distance for a car that burns fuel, battery energy per distance otherwise.
struct EnergyFigure {
  double value = 0.0;     ///< kWh/10 km or l/100 km
  std::string unit;       ///< "kwh_per_10km" or "l_per_100km"
  double range_km = 0.0;  ///< electric only, 0 otherwise
  /// Not followed: the figure is for a slower drive than the cycle's (or, in replay, leaves out the demand the
  /// powertrain could not meet), and figures of runs that differ in this do not compare.
  TraceFollowing trace;
  /// The battery charged past full (report::overcharge_caveat), or empty: the figure is then too low.
  std::string overcharge;
};

/// "l_per_100km" for a car whose powertrain burns fuel, "kwh_per_10km" otherwise.
std::string energy_unit(const Vehicle& vehicle);
/// "kWh/10 km" / "l/100 km" for tables.
std::string energy_unit_label(const std::string& unit);

/// The headline figure of a simulation result.
EnergyFigure energy_figure(const SimulationResult& result);

/// Assembles `vehicle` and runs it forward (driver + CVODE) over `cycle`.
EnergyFigure run_forward(const Vehicle& vehicle, const DriveCycle& cycle);

/// Runs an assembled car over `cycle`: forward (driver + CVODE), or as a kinematic replay when `replay`.
EnergyFigure run_model(const VehicleModel& model, const DriveCycle& cycle, bool replay);

/// Throws InputError naming the cycle when it covers no distance: every figure tyre selection ranks, sweeps or
/// differentiates is per distance, and would be NaN.
void require_distance(const DriveCycle& cycle);

/// Throws InputError naming the car and `what` it would do when its front and rear tyres differ: selection fits one
/// tyre on all four wheels, so the car's own figure would not be the car as built.
void require_one_tyre_set(const Vehicle& vehicle, const std::string& what);

/// "forward simulation" or "kinematic replay", for the tables' titles.
std::string run_mode_label(bool replay);

}  // namespace rollsim::selection
