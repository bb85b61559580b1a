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
};

struct Sensitivity {
  std::string tyre;
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

/// RR power elasticities at (tyre, load, speed), central differences +-relative_step.
Sensitivity tyre_sensitivity(const TyreSpec& tyre, double load_n, double speed_mps, double relative_step = 0.01);

/// Also the car's energy/fuel elasticities (forward simulation, tyre on all four wheels). "Load" for the
/// car is its test mass (every wheel load scales with it). The RR power point is (load_n, speed_mps).
Sensitivity vehicle_sensitivity(const Vehicle& vehicle, const TyreSpec& tyre, const DriveCycle& cycle, double load_n,
                                double speed_mps, double relative_step = 0.01);

}  // namespace rollsim::selection
