// A car built from one EPA Test Car List row alone: test mass, target road load, and a powertrain scaled from its numbers.
#pragma once

#include <string>

#include "rollsim/powertrain/conventional.hpp"
#include "rollsim/powertrain/electric.hpp"
#include "rollsim/sim/simulation.hpp"
#include "rollsim/validate/epa_test_car.hpp"

namespace rollsim::validate {

/// The constants every car shares. Class values with their sources are in epa_car.cpp and the README; the four
/// marked "fitted" are set once from the fitting half of the list (validate.hpp) and judged on the other half.
struct EpaDefaults {
  double petrol_indicated_efficiency = 0.38;  ///< fitted (nominal: Heywood's 0.36-0.40 gross indicated)
  double diesel_indicated_efficiency = 0.45;  ///< fitted
  /// AC energy from the wall per DC energy into the cells, charger and charging losses together (fitted; nominal
  /// 0.88: Level 2 on-board chargers are 85-90 % efficient).
  double charge_efficiency = 0.88;
  /// Cold-start fuel excess of the engine warm-up effect (fitted to the fitting half's measured bag 1 against
  /// bag 3, the same trace cold and hot).
  double cold_fuel_excess = 0.3;
};

/// Checks that the row holds what a car needs, within physical ranges, for the configuration its result belongs
/// to (result_configuration: an analytically derived row's ADFE columns). Returns the reason a row cannot be
/// built (`none` when it can) and fills `detail` with the field and value.
SkipReason check_car_fields(const EpaTestRow& row, std::string& detail);

/// The car of a checked row, in the configuration its result belongs to (result_configuration): inertial mass,
/// target road load and the powertrain of its kind (engine with fuel map and the row's transmission, or electric
/// drive). The fuel-converter or charge constants come from `d`.
VehicleModel car_from_row(const EpaTestRow& row, const EpaDefaults& d);

/// The engine warm-up effect's parameters for the row's engine with a given cold fuel excess (FTP bag 1), built
/// against `car`, the row's car (car_from_row).
std::shared_ptr<const Effect> cold_start_effect(const EpaTestRow& row, const VehicleModel& car, double cold_fuel_excess);

/// Fuel properties of the row's test fuel.
FuelParams test_fuel(EpaFuel fuel);

}  // namespace rollsim::validate
