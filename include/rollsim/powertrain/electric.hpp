// Battery-electric powertrain: battery, motor loss model, single-speed reduction, blended regenerative braking.
#pragma once

#include <vector>

#include "rollsim/powertrain/powertrain.hpp"

namespace rollsim {

/// Electric machine losses as a physical loss model instead of a measured map:
/// P_loss = k_cu T^2 + k_fe w + k_w w^3 + P_0. Copper loss grows with torque (current) squared, iron (hysteresis
/// and eddy) loss with speed, windage with speed cubed; P_0 covers the inverter's standby loss. The same model
/// is used in motoring and generating, as the physics is symmetric in torque.
struct MotorLossParams {
  double copper_w_per_nm2 = 0.0;       ///< k_cu [W/(N m)^2]
  double iron_w_s_per_rad = 0.0;       ///< k_fe [W/(rad/s)]
  double windage_w_s3_per_rad3 = 0.0;  ///< k_w  [W/(rad/s)^3]
  double constant_w = 0.0;             ///< P_0 [W], only while the machine turns
  /// Optional efficiency curve against the fraction of rated power at the shaft (FASTSim's form: points
  /// `output_fraction` rising from 0 to 1, `efficiency` in (0, 1] at each). When given, the loss is
  /// |P| (1 / eta - 1) motoring and |P| (1 - eta) generating, eta interpolated linearly at |P| / max_power, and
  /// it replaces the four terms above (a curve of power alone cannot tell torque from speed).
  std::vector<double> output_fraction;
  std::vector<double> efficiency;
};

struct ElectricMotorParams {
  double max_torque_nm = 0.0;
  double max_power_w = 0.0;        ///< continuous-peak mechanical power, both directions
  double max_speed_radps = 0.0;
  /// Speed limiter: over the top band of speed, [1 - band, 1] x max_speed, the controller derates the torque
  /// limit linearly to zero at max_speed (a governor's taper). The force the motor can give is then continuous
  /// in speed: a car at its top speed settles where force meets road load, instead of switching between full
  /// force and none at max_speed, which no error-controlled integrator can step over.
  double speed_limit_band_fraction = 0.03;
  MotorLossParams losses;
};

struct ReductionParams {
  double ratio = 1.0;        ///< motor speed / wheel speed
  double efficiency = 1.0;   ///< (0, 1], both directions
};

/// Regenerative braking and its blending with the friction brakes.
struct RegenParams {
  double max_power_w = 0.0;            ///< electrical power the battery/inverter accept while braking
  /// Share of the total braking force the driven axle's motor may take (brake blending: a front-driven car with
  /// a fixed front/rear brake balance recovers only the front share).
  double driven_axle_brake_fraction = 1.0;
  double min_speed_mps = 0.0;          ///< below this no regeneration (the motor cannot hold the car)
  double fade_speed_mps = 0.0;         ///< regen ramps linearly from zero at min speed to full at this speed
};

struct ElectricPowertrainParams {
  ElectricMotorParams motor;
  ReductionParams reduction;
  BatteryParams battery;
  RegenParams regen;
  double aux_power_w = 0.0;
};

class ElectricPowertrain final : public Powertrain {
 public:
  /// Throws ModelDomainError for an efficiency curve that is not a rising fraction 0..1 with efficiencies in (0, 1].
  explicit ElectricPowertrain(const ElectricPowertrainParams& params);
  PowerFlow deliver(double wheel_force_n, double speed_mps, int gear, double wheel_radius_m) const override;
  int select_gear(double, int) const override { return 0; }
  std::vector<double> shift_speeds_mps(int) const override { return {}; }
  std::vector<double> braking_regime_speeds_mps(double wheel_radius_m) const override;
  std::vector<double> traction_regime_speeds_mps(double wheel_radius_m) const override;
  std::vector<double> braking_kink_speeds_mps(double wheel_radius_m) const override;
  double max_wheel_force_n(int gear, double speed_mps, double wheel_radius_m) const override;
  const BatteryParams* battery() const override { return &p_.battery; }
  /// From the battery terminals (its own I^2 R for the extra current is neglected: under 1 % of the load at
  /// these currents).
  void add_electric_load(double power_w, PowerFlow& flow) const override;
  const ElectricPowertrainParams& params() const { return p_; }

  /// Battery current [A] (+ discharging) for a terminal power [W]; throws ModelDomainError when the battery
  /// cannot deliver it (P > Voc^2 / 4R).
  double battery_current_a(double terminal_power_w) const;
  /// The most the battery can deliver at its terminals [W]: Voc^2 / 4R, at half the open-circuit voltage.
  double max_battery_power_w() const;

 private:
  double motor_loss_w(double torque_nm, double speed_radps) const;
  /// What torque adds to the loss the machine has at this speed anyway (regeneration's cost).
  double torque_loss_w(double torque_nm, double speed_radps) const;
  /// The speed limiter's factor on the torque limit at this motor speed: 1 below the band, 0 at max speed.
  double speed_limit_factor(double speed_radps) const;
  /// Road speeds [m/s] of the speed limiter's band: where it starts and the machine's top speed.
  std::vector<double> speed_band_speeds_mps(double wheel_radius_m) const;
  ElectricPowertrainParams p_;
};

}  // namespace rollsim
