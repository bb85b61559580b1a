// Combustion powertrain: Willans-line engine, stepped gearbox with shift schedule, clutch, fuel properties.
#pragma once

#include <vector>

#include "rollsim/powertrain/powertrain.hpp"

namespace rollsim {

/// Willans-line engine (Guzzella & Sciarretta, Vehicle Propulsion Systems, ch. 4): fuel power
/// P_fuel = (P_brake + P_friction) / e, with friction from a mean effective pressure that rises with speed,
/// P_friction = (p_me0 + p_me0_speed * w) * V_d * w / (4 pi) for a four-stroke engine.
struct EngineParams {
  double displacement_m3 = 0.0;
  double indicated_efficiency = 0.0;          ///< e, the Willans slope's inverse
  double friction_mep_pa = 0.0;               ///< p_me0 at zero speed
  double friction_mep_pa_s_per_rad = 0.0;     ///< growth of friction mean effective pressure with speed
  double idle_speed_radps = 0.0;
  double max_speed_radps = 0.0;
  double max_torque_nm = 0.0;
  double max_power_w = 0.0;
  /// Overrun fuel cut-off: no fuel while the wheels drive the engine above this speed.
  double fuel_cut_min_speed_radps = 0.0;
};

struct GearboxParams {
  std::vector<double> ratios;          ///< engine speed / gearbox output speed, first gear first
  double final_drive_ratio = 1.0;
  double efficiency = 1.0;             ///< gearbox and final drive together, both directions
  std::vector<double> upshift_speeds_mps;    ///< speed to leave gear i for i+1 (size = gears - 1)
  std::vector<double> downshift_speeds_mps;  ///< speed to leave gear i+1 for i (size = gears - 1)
};

struct CombustionPowertrainParams {
  EngineParams engine;
  GearboxParams gearbox;
  FuelParams fuel;
  double aux_power_w = 0.0;      ///< electrical load carried by the alternator
  double alternator_efficiency = 1.0;
};

class CombustionPowertrain final : public Powertrain {
 public:
  explicit CombustionPowertrain(const CombustionPowertrainParams& params) : p_(params) {}
  PowerFlow deliver(double wheel_force_n, double speed_mps, int gear, double wheel_radius_m) const override;
  int select_gear(double speed_mps, int current_gear) const override;
  std::vector<double> shift_speeds_mps(int gear) const override;
  std::vector<double> braking_regime_speeds_mps(double wheel_radius_m) const override;
  std::vector<double> traction_regime_speeds_mps(double wheel_radius_m) const override;
  int num_gears() const override { return static_cast<int>(p_.gearbox.ratios.size()); }
  double max_wheel_force_n(int gear, double speed_mps, double wheel_radius_m) const override;
  const FuelParams* fuel() const override { return &p_.fuel; }
  /// From the alternator at the engine's marginal (Willans) efficiency, even in fuel cut-off.
  void add_electric_load(double power_w, PowerFlow& flow) const override;
  double alternator_accessory_load_w() const override { return p_.aux_power_w; }
  const CombustionPowertrainParams& params() const { return p_; }

 private:
  double friction_power_w(double speed_radps) const;
  CombustionPowertrainParams p_;
};

}  // namespace rollsim
