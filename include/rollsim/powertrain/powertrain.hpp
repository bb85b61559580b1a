// The powertrain interface: turns a requested wheel force at a speed into delivered force, energy flows and losses.
#pragma once

#include <vector>

namespace rollsim {

/// A traction battery: an open-circuit voltage behind an internal resistance, with a usable capacity.
struct BatteryParams {
  double open_circuit_voltage_v = 0.0;
  double internal_resistance_ohm = 0.0;
  double usable_capacity_j = 0.0;
  double initial_soc = 1.0;  ///< fraction of usable capacity at the start
};

/// The fuel a fuel converter burns.
struct FuelParams {
  double density_kg_per_m3 = 0.0;
  double lower_heating_value_j_per_kg = 0.0;
  double co2_kg_per_kg = 0.0;   ///< tank-to-wheel CO2 per kg of fuel burned
  /// Chemical energy per volume [J/m^3]: the power a volumetric fuel flow carries, per m^3/s.
  double energy_j_per_m3() const { return density_kg_per_m3 * lower_heating_value_j_per_kg; }
};

struct PowerFlow;
class EngineMap;

/// Books an electric load of `power_w` carried by an engine through its alternator: the fuel it costs at the
/// engine's marginal efficiency (extra fuel per extra brake work at part load), and the loss that is not the load.
/// On the overrun with the fuel cut off the wheels carry it, booked as braking, as they carry the car's own
/// accessories: no fuel. One rule for every fuel-burning powertrain.
void add_alternator_load(double power_w, double alternator_efficiency, double marginal_efficiency,
                         const FuelParams& fuel, PowerFlow& flow);

/// Powers at one instant, all [W], signed where noted. Everything downstream of the wheel that the energy
/// report and the energy balance need. Fields a powertrain does not have stay zero.
struct PowerFlow {
  double wheel_force_n = 0.0;           ///< force the powertrain and brakes deliver at the wheels (+ propels)
  double traction_power_w = 0.0;        ///< >= 0: propulsive power at the wheels
  double regen_wheel_power_w = 0.0;     ///< >= 0: braking power taken by the motor at the wheels
  double friction_brake_power_w = 0.0;  ///< >= 0: braking power dissipated by friction brakes (and engine drag)
  double gearbox_loss_w = 0.0;          ///< >= 0: reduction/gearbox and final-drive loss
  double motor_loss_w = 0.0;            ///< >= 0: electric machine loss (copper, iron, windage)
  double battery_terminal_power_w = 0.0;  ///< signed: + discharging, at the battery terminals
  double battery_loss_w = 0.0;          ///< >= 0: I^2 R inside the battery
  double aux_power_w = 0.0;             ///< >= 0: auxiliaries (electronics, HVAC), from battery or alternator
  double fuel_power_w = 0.0;            ///< >= 0: fuel chemical power (lower heating value)
  double fuel_rate_m3_per_s = 0.0;      ///< >= 0: fuel volume flow
  double engine_loss_w = 0.0;           ///< >= 0: fuel power not turned into brake work (thermal + friction)
  double clutch_loss_w = 0.0;           ///< >= 0: clutch slip at launch (engine held at idle speed)
  double battery_current_a = 0.0;       ///< signed: + discharging
  double machine_speed_radps = 0.0;     ///< motor or engine speed
  double machine_torque_nm = 0.0;       ///< motor or engine torque
  int engaged_gear = 0;                 ///< the gear a powertrain that picks its own engaged (1 = first); 0 otherwise
  double gear_ratio = 0.0;              ///< the engaged gear's (or a CVT's) input per output speed; 0 when none is
  bool force_limited = false;           ///< true when the request exceeded what the powertrain can deliver
  bool fuel_cut = false;                ///< true while an engine is motored on the overrun with its fuel cut off
};

/// A powertrain. Implementations know their own parameters; the simulator calls only this interface, so the
/// integrator and the vehicle dynamics stay independent of the kind of car. What a powertrain stores or burns is
/// a capability (an optional battery, an optional fuel), not a kind: a hybrid has both.
class Powertrain {
 public:
  virtual ~Powertrain() = default;

  /// Delivers the requested wheel force (+ propel, - brake) at `speed_mps` in discrete mode `gear`, within the
  /// powertrain's limits. `wheel_radius_m` is the driven tyres' effective rolling radius (it sets the gearing).
  virtual PowerFlow deliver(double wheel_force_n, double speed_mps, int gear, double wheel_radius_m) const = 0;

  /// The gear the speed schedule asks for at `speed_mps` coming from `current_gear` (with hysteresis); 0 for
  /// single-speed drives.
  virtual int select_gear(double speed_mps, int current_gear) const = 0;

  /// Number of gears; 1 for single-speed drives (which never shift).
  virtual int num_gears() const { return 1; }

  /// The largest propulsive wheel force [N] available in `gear` at `speed_mps`; 0 where the gear would
  /// overspeed the machine. A driver (or an automatic gearbox) kicks down when the demand exceeds it.
  virtual double max_wheel_force_n(int gear, double speed_mps, double wheel_radius_m) const = 0;

  /// Speeds [m/s] at which `select_gear` changes its answer from `gear`: the integrator finds these crossings as
  /// roots so it never steps over a shift. Empty for single-speed drives.
  virtual std::vector<double> shift_speeds_mps(int gear) const = 0;

  /// Speeds [m/s] at which deliver() changes how it handles a braking force (the regen fade's ends, an overrun fuel
  /// cut-off's road and engine speeds in the gears a braking car is in): kinks or steps of the energies only, which
  /// the speed does not feel, so a simulation splits its steps where a deceleration falls through them. Ascending;
  /// empty by default. `wheel_radius_m` as for deliver().
  virtual std::vector<double> braking_regime_speeds_mps(double /*wheel_radius_m*/) const { return {}; }
  /// Speeds [m/s] at which the most force a gear gives kinks (an engine's limiter cutting in and at its end, a motor's
  /// torque limit giving way to its power limit and its speed limiter's band), for a replay to split an
  /// acceleration's steps there. Empty by default.
  virtual std::vector<double> traction_regime_speeds_mps(double /*wheel_radius_m*/) const { return {}; }
  /// Speeds [m/s] at which a braking force's split kinks without a step (a machine's regenerating torque limit
  /// giving way to its power limit, its speed limiter's band), for a replay to split a deceleration's steps there;
  /// the forward simulation's error control takes them in its stride. Empty by default.
  virtual std::vector<double> braking_kink_speeds_mps(double /*wheel_radius_m*/) const { return {}; }

  /// The traction battery, or nullptr when the powertrain has none.
  virtual const BatteryParams* battery() const { return nullptr; }

  /// The fuel of the powertrain's fuel converter, or nullptr when it has none.
  virtual const FuelParams* fuel() const { return nullptr; }

  /// The engine's fuel map, or nullptr when the powertrain has none (an electric drive, a Willans line).
  virtual const EngineMap* engine_map() const { return nullptr; }

  /// True when the gearbox varies its ratio continuously (a CVT): the engine can slow down while it drives on.
  virtual bool continuously_variable() const { return false; }

  /// Adds an extra electrical load `power_w` (an effect's consumer) to `flow`, drawn where this powertrain
  /// draws its electricity (battery terminals, or an alternator on the engine).
  virtual void add_electric_load(double power_w, PowerFlow& flow) const = 0;

  /// The electrical accessories' load an alternator carries [W] (0 where the traction battery carries it, inside
  /// deliver): what a 12 V battery must supply while the engine is stopped with the accessories on.
  virtual double alternator_accessory_load_w() const { return 0.0; }
};

}  // namespace rollsim
