// Elasticities of a tyre's RR power and of a car's cycle energy or fuel with respect to the tyre parameters.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/tyre/explain.hpp"
#include "rollsim/tyre/tyre_spec.hpp"
#include "rollsim/vehicle/vehicle.hpp"

namespace rollsim::selection {

struct SensitivityRow {
  TyreParameter parameter = TyreParameter::OuterDiameter;
  std::string name;                       ///< "outer diameter"
  std::string key;                        ///< "outer_diameter"
  double value_si = 0.0;
  double rrc_elasticity = 0.0;
  double power_elasticity = 0.0;          ///< % RR power per % parameter at the operating point
  std::optional<double> energy_elasticity;  ///< % cycle energy/fuel per % parameter (vehicle mode)
  /// The same from steps twice as large: where the two differ by more than the truncation a smooth output allows,
  /// a discrete decision (a gear, a lock-up, a fuel cut-off) changed between the runs and the figure is not a slope.
  std::optional<double> energy_elasticity_double_step;
  bool energy_smooth = true;
};

/// A parameter's value in the unit tables and files give it: outer_diameter_mm, section_width_mm, pressure_bar, load_n.
struct ParameterValue {
  std::string key;   ///< "pressure_bar"
  double value = 0.0;
  std::string unit;  ///< "bar"
  int decimals = 0;  ///< as a table prints it
};
ParameterValue parameter_value_in_file_units(const SensitivityRow& row);

struct Sensitivity {
  std::string tyre;
  double max_load_n = 0.0;                ///< the tyre's rated maximum load; 0 when unknown
  std::vector<std::string> vehicle_warnings;  ///< vehicle mode: the car's tyres loaded past their rating
  double load_n = 0.0;
  double speed_mps = 0.0;
  double relative_step = 0.01;
  double rr_power_w = 0.0;
  std::vector<SensitivityRow> rows;       ///< diameter, width, pressure, load
  std::string vehicle, cycle, energy_unit;  ///< vehicle mode
  double energy = 0.0;                    ///< vehicle mode: energy/fuel at the base point
  /// Vehicle mode: false when the car fell behind the cycle in the base run or a perturbed one; the energy
  /// elasticities then mix the tyre's effect with a change of the drive itself.
  bool followed_trace = true;
  std::string dominant_power;             ///< name of the parameter with the largest |power elasticity|
  std::string dominant_energy;            ///< same for energy (vehicle mode)
};

/// Whether an elasticity from central differences of +-h and one from +-2h are the same slope: a smooth output's
/// differ by its curvature's O(h^2), a few per cent, and the forward runs' scatter adds 5e-4 at +-1 %; a discrete
/// decision that changes between the runs moves one of them by far more.
bool elasticities_agree(double at_step, double at_double_step);

/// RR power elasticities at (tyre, load, speed), central differences +-relative_step.
Sensitivity tyre_sensitivity(const TyreSpec& tyre, double load_n, double speed_mps, double relative_step = 0.01);

/// Also the car's energy/fuel elasticities (forward simulation, tyre on all four wheels). "Load" for the
/// car is its test mass (every wheel load scales with it). The RR power point is (load_n, speed_mps).
Sensitivity vehicle_sensitivity(const Vehicle& vehicle, const TyreSpec& tyre, const DriveCycle& cycle, double load_n,
                                double speed_mps, double relative_step = 0.01);

}  // namespace rollsim::selection
