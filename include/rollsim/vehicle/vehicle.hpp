// Vehicle description (body, tyres, road load, powertrain) and its strict YAML file format.
#pragma once

#include <memory>
#include <vector>
#include <optional>
#include <string>
#include <variant>

#include "rollsim/powertrain/combustion.hpp"
#include "rollsim/powertrain/conventional.hpp"
#include "rollsim/powertrain/electric.hpp"
#include "rollsim/effects/catalogue.hpp"
#include "rollsim/tyre/tyre_spec.hpp"
#include "rollsim/vehicle/road_load.hpp"

namespace rollsim {

enum class DrivenAxle { front, rear, all };

struct BodyParams {
  double test_mass_kg = 0.0;
  double rotating_mass_kg = 0.0;        ///< equivalent translational mass of wheels, driveline and motor
  double drag_coefficient = 0.0;
  double frontal_area_m2 = 0.0;
  double air_density_kg_per_m3 = 1.2;
  double front_axle_load_fraction = 0.5;  ///< static share of weight on the front axle
  DrivenAxle driven_axle = DrivenAxle::front;
  double wheel_radius_m = 0.0;          ///< used only when no tyre is given (coast-down road load)
};

/// Published coast-down road load F = A + B v + C v^2 (SI), as type-approval authorities publish it.
struct CoastdownParams {
  double a_n = 0.0;
  double b_n_s_per_m = 0.0;
  double c_n_s2_per_m2 = 0.0;
};

/// One alternative per vehicle-file powertrain type: electric, combustion (Willans line, scheduled gearbox) and
/// engine_map (fuel map behind a self-shifting transmission). Code that needs the fuel or the battery asks
/// Vehicle::fuel() / battery(), so a new type is added here, in its reader and in make_powertrain only.
using PowertrainParams = std::variant<ElectricPowertrainParams, CombustionPowertrainParams, ConventionalPowertrainParams>;

struct Vehicle {
  std::string name;
  std::string source;
  BodyParams body;
  std::optional<TyreSpec> front_tyre;  ///< both present or both absent
  std::optional<TyreSpec> rear_tyre;
  std::optional<CoastdownParams> coastdown;  ///< when set, it is the road load; tyres only gear the car
  PowertrainParams powertrain;
  std::vector<EffectSpec> effects;  ///< the file's `effects:` block; models are built by the simulation's assembly
  std::vector<std::string> warnings;  ///< values allowed but implausible in the file (a unit slip?), said by simulate

  bool is_electric() const { return std::holds_alternative<ElectricPowertrainParams>(powertrain); }
  /// The fuel the powertrain burns, or nullptr when it burns none.
  const FuelParams* fuel() const;
  /// The traction battery, or nullptr when it has none.
  const BatteryParams* battery() const;
};

/// Loads a vehicle file; tyre files named in it are found beside it or in the shipped tyres/.
Vehicle load_vehicle_file(const std::string& path);
/// The same for YAML text in memory (e.g. a Python dict as JSON); `name` stands for the file in errors, and tyre
/// files it names are found relative to the working folder or in the shipped tyres/.
Vehicle load_vehicle_text(const std::string& text, const std::string& name);
/// The same for a mapping already read; its file() names the source.
Vehicle load_vehicle(YamlMap root);
/// A vehicle file's `powertrain.engine` block (type engine_map) in SI, read as load_vehicle reads it: one place for
/// its key names, defaults, bounds and unit conversions (the Python module's engine_map evaluates it too).
EngineMapParams read_engine_block(YamlMap engine);

/// What the effect models need to know of this car (its test mass and air density x drag area).
EffectContext effect_context(const Vehicle& vehicle);

/// Replaces the tyres of all four wheels (the `--tyre` option).
void fit_tyres(Vehicle& vehicle, const TyreSpec& tyre);

/// Checks that each axle's tyre carries its static wheel load (the model has no solution past the rim); throws
/// InputError naming `where`, the axle and the tyre. Returns a warning for each tyre loaded above its rating
/// (allowed, but worth saying), empty when none is.
std::vector<std::string> check_tyre_loads(const Vehicle& vehicle, const std::string& where, bool own_tyres = true);

/// Static normal load on one tyre of each axle [N] on a grade (front, rear).
struct AxleWheelLoads {
  double front_n = 0.0;
  double rear_n = 0.0;
};
AxleWheelLoads wheel_loads(const BodyParams& body, double grade);

/// Effective rolling radius of the driven wheels [m]: R - dz/3 of the tyre at its static load (the usual
/// approximation between free and loaded radius), or body.wheel_radius_m without tyres.
double driven_wheel_radius_m(const Vehicle& vehicle);

/// Builds the road-load model of the vehicle: the tyre model on every wheel plus body aero, or coast-down.
std::unique_ptr<RoadLoadModel> make_road_load(const Vehicle& vehicle);

/// Road load of the tyre model at the wheels: the tyres' share of a coast-down A term at speed -> 0.
double tyre_rolling_force_at_standstill_limit_n(const Vehicle& vehicle);

std::unique_ptr<Powertrain> make_powertrain(const Vehicle& vehicle);

}  // namespace rollsim
