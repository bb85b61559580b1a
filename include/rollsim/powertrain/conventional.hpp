// Engine with a fuel map behind an automatic (torque converter), CVT, dual-clutch or manual transmission that
// chooses its own ratio from speed and demand.
#pragma once

#include <vector>

#include "rollsim/powertrain/engine_map.hpp"
#include "rollsim/powertrain/powertrain.hpp"

namespace rollsim {

enum class TransmissionKind {
  automatic,  ///< planetary automatic behind a torque converter with lock-up clutch
  cvt,        ///< belt or chain CVT behind a torque converter
  clutch,     ///< manual, automated manual or dual clutch: a friction clutch slips at launch
};

/// Torque converter (Kotwicki's model reduced to its two regimes): pump torque (w_pump / K)^2 phi(SR) and turbine
/// torque TR(SR) times it, with speed ratio SR = w_turbine / w_pump; torque ratio falls linearly from the stall
/// ratio to 1 at the coupling point, above which the capacity phi falls to 0 at SR = 1.
struct TorqueConverterParams {
  double k_factor_radps_per_sqrt_nm = 0.0;  ///< K: pump speed per square root of pump torque at stall
  double stall_torque_ratio = 2.0;
  double coupling_speed_ratio = 0.85;
  int lockup_min_gear = 2;                  ///< lock-up clutch closes from this gear up (CVT: always when above speed)
  double lockup_min_speed_radps = 0.0;      ///< ... and above this turbine speed
  /// Neutral idle control: standing in Drive with the brake on, the controller opens a clutch so the stalled
  /// converter does not load the idling engine (Mazda's 2018 Skyactiv-Drive, GM's and Ford's "neutral idle").
  bool neutral_at_standstill = false;
};

struct TransmissionParams {
  TransmissionKind kind = TransmissionKind::automatic;
  /// Overall ratios (engine speed / wheel speed, final drive included), first gear first. A CVT gives its two
  /// ends, lowest ratio (overdrive) last.
  std::vector<double> ratios;
  double efficiency = 1.0;           ///< gear mesh, final drive and driveshafts, both directions
  double spin_loss_nm = 0.0;         ///< drag torque at the input (oil pump, clutch packs, belt clamping)
  /// The ratio chosen: the highest gear (lowest ratio) in which the engine turns at least this fast and needs at
  /// most `max_torque_fraction` of its full-load torque. A CVT runs at the speed where the demand takes
  /// `max_torque_fraction` of the full-load torque, but not below this speed.
  double min_engine_speed_radps = 0.0;
  double max_torque_fraction = 0.8;
  /// A friction clutch's launch: while the gearbox input turns slower than this and the wheels are driven, the
  /// engine runs at this speed and the clutch slips (a driver or a dual-clutch controller raises the engine above
  /// idle to pull away). Zero: the clutch slips with the engine at idle.
  double launch_engine_speed_radps = 0.0;
  TorqueConverterParams converter;   ///< automatic and CVT
};

struct ConventionalPowertrainParams {
  EngineMapParams engine;
  TransmissionParams transmission;
  FuelParams fuel;
  double aux_power_w = 0.0;          ///< electrical load carried by the alternator
  double alternator_efficiency = 1.0;
};

/// The transmission picks its ratio inside deliver() from the speed and the demand, so the simulator sees one
/// mode (num_gears() is 1) and the replay can memoise segments.
class ConventionalPowertrain final : public Powertrain {
 public:
  explicit ConventionalPowertrain(const ConventionalPowertrainParams& params);
  PowerFlow deliver(double wheel_force_n, double speed_mps, int gear, double wheel_radius_m) const override;
  int select_gear(double, int) const override { return 0; }
  std::vector<double> shift_speeds_mps(int) const override { return {}; }
  std::vector<double> braking_regime_speeds_mps(double wheel_radius_m) const override;
  double max_wheel_force_n(int gear, double speed_mps, double wheel_radius_m) const override;
  const FuelParams* fuel() const override { return &p_.fuel; }
  const EngineMap* engine_map() const override { return &map_; }
  bool continuously_variable() const override { return p_.transmission.kind == TransmissionKind::cvt; }
  void add_electric_load(double power_w, PowerFlow& flow) const override;
  double alternator_accessory_load_w() const override { return p_.aux_power_w; }
  const ConventionalPowertrainParams& params() const { return p_; }

 private:
  struct Operating {
    double engine_speed_radps = 0.0;
    double engine_torque_nm = 0.0;   ///< brake torque at the crank for the driveline (accessories excluded)
    double slip_loss_w = 0.0;        ///< converter or clutch slip
    double ratio = 0.0;
    int gear = 0;                    ///< the stepped gear engaged (1 = first); 0 for a CVT
    bool locked = true;
  };
  /// Coasting or braking at `speed_mps`: the gearbox's choice at no torque, and whether the engine is cut off there.
  bool fuel_cut_off(double speed_mps, double wheel_radius_m, Operating& coasting) const;
  Operating operate(double wheel_torque_nm, double wheel_speed_radps) const;
  Operating through(double ratio, int gear, double wheel_torque_nm, double wheel_speed_radps) const;
  double converter_pump_speed_radps(double turbine_speed_radps, double turbine_torque_nm) const;
  double accessory_torque_nm(double engine_speed_radps) const;
  ConventionalPowertrainParams p_;
  EngineMap map_;
};

}  // namespace rollsim
