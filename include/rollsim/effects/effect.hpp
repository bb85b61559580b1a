// Extension point for physical effects beyond the base model (tyre warm-up, wind, slip, ...): hooks into the simulator.
#pragma once

#include <string>

namespace rollsim {

/// What an effect may look at, at one instant of a simulation.
struct EffectInputs {
  double time_s = 0.0;
  double speed_mps = 0.0;
  double accel_mps2 = 0.0;
  double grade = 0.0;
  double distance_m = 0.0;
  double base_rolling_force_n = 0.0;  ///< rolling resistance of the base tyre model at this speed
  double wheel_force_demand_n = 0.0;  ///< force the driver asks of the wheels (feed-forward), + propels
  bool engine_off = false;  ///< the trace switches the engine off here (a soak, start-stop): no fuel, no heat
  /// Direction of travel, clockwise from north [rad], where the trace knows it (recorded latitude and longitude).
  double heading_rad = 0.0;
  bool heading_known = false;
  /// With engine_off: the car's electrical accessories stay on, fed by its 12 V battery (start-stop at a light),
  /// not switched off with the key (a soak).
  bool accessories_on = false;
};

/// A physical effect with its own parameters and, optionally, hidden states integrated with the vehicle's
/// (tyre temperature, oil temperature). The neutral value of every hook leaves the base model unchanged, so an
/// effect whose parameters are zero is off.
class Effect {
 public:
  virtual ~Effect() = default;
  virtual std::string id() const = 0;
  virtual int num_states() const { return 0; }
  virtual void initial_states(double* /*x*/) const {}
  /// States at the start of a trace whose engine is already warm (a hot start, DriveCycle::engine_hot_start),
  /// applied over initial_states; effects without an engine state keep theirs.
  virtual void hot_start_states(double* /*x*/) const {}
  virtual void state_derivatives(const EffectInputs&, const double* /*x*/, double* /*xdot*/) const {}
  /// Factor on the tyre model's rolling resistance (tyre temperature, ambient temperature).
  virtual double rolling_resistance_factor(const EffectInputs&, const double* /*x*/) const { return 1.0; }
  /// Extra force opposing motion [N] (wind, unmodelled grade), booked as "other resistance".
  virtual double extra_resistance_n(const EffectInputs&, const double* /*x*/) const { return 0.0; }
  /// Extra loss at the wheels [W] that the powertrain must supply on top of the wheel work (tyre slip).
  virtual double wheel_loss_w(const EffectInputs&, const double* /*x*/) const { return 0.0; }
  /// Factor on the engine's fuel power (cold engine friction).
  virtual double fuel_power_factor(const EffectInputs&, const double* /*x*/) const { return 1.0; }
  /// Extra electrical consumer [W] (HVAC, electronics), booked as auxiliary power: drawn from the battery of an
  /// electric car, or from the alternator (fuel at its marginal efficiency) of a combustion car.
  virtual double extra_electric_power_w(const EffectInputs&, const double* /*x*/) const { return 0.0; }
  /// Extra loss inside the battery [W] at this terminal power (+ discharging): drains the cells (state of charge)
  /// without changing the power at the terminals (extra internal resistance).
  virtual double battery_loss_w(const EffectInputs&, double /*terminal_power_w*/, const double* /*x*/) const { return 0.0; }
};

}  // namespace rollsim
