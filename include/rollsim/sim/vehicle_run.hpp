// One car with one tyre set on one cycle, as `rollsim simulate` and the Python API run it.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/sim/simulation.hpp"
#include "rollsim/vehicle/vehicle.hpp"  // also TyreSpec: the sim layer reaches tyres only through the vehicle

namespace rollsim {

struct VehicleRun {
  Vehicle vehicle;                    ///< the car as run (with the tyre set fitted)
  std::string tyre_label;             ///< the tyre set's name, the car's own tyre's, or "coast-down"
  std::vector<std::string> warnings;  ///< overloaded tyres (allowed, but said)
  SimulationResult result;
};

/// The files the run's front and rear tyres were read from ("" for a car without tyres): the tyre set given, or
/// the car's own, which a JSON result names (a same-named file beside the vehicle file was read unsaid: session 25).
std::pair<std::string, std::string> tyre_files(const VehicleRun& run);

/// Fits `tyre` (if given) to all four wheels and runs the car forward (driver + CVODE) or as a kinematic replay.
/// A solver failure becomes a std::runtime_error naming the car and cycle: no result is reported.
VehicleRun run_vehicle(const Vehicle& base, const std::optional<TyreSpec>& tyre, const DriveCycle& cycle, bool replay,
                       const SimulationOptions& options);

}  // namespace rollsim
