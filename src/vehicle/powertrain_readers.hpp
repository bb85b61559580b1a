// Readers of the vehicle file's powertrain blocks that live beside vehicle.cpp's own (one reader per type).
#pragma once

#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/powertrain/conventional.hpp"

namespace rollsim {

/// A `fuel:` block: density, lower heating value and CO2 per kg, in the file's units.
FuelParams read_fuel(YamlMap m);

/// `aux_power_w` of a powertrain block [W]: 0 (left out) or a road vehicle's electrical load, at least 10 W.
double read_aux_power_w(YamlMap& pt);

/// Refuses at `where` the first gear ratio that is not below the one before it, naming both (a swapped pair ran
/// silently); one rule for the Willans gearbox and the engine map's transmission.
void check_ratios_fall(const std::vector<double>& ratios, const std::string& where);

/// An engine speed [rad/s] as an error message says it: whole rpm.
std::string rpm_text(double radps);

/// Refuses an engine whose `max_power_kw` (at `where`) cannot carry the accessories' shaft power, aux_power_w over the
/// alternator's efficiency: the power left for the wheels would be negative.
void check_engine_carries_accessories(double max_power_w, double aux_power_w, double alternator_efficiency, const std::string& where);

/// `powertrain: {type: engine_map, ...}`: an engine with a fuel map (EngineMap) behind a transmission that picks
/// its own ratio (ConventionalPowertrain). Every key in the file's units, each with its bounds.
ConventionalPowertrainParams read_engine_map_powertrain(YamlMap& pt);

}  // namespace rollsim
