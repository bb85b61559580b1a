// Fuel map of a piston engine built from physics (indicated efficiency, friction, pumping, enrichment), not measured.
#pragma once

namespace rollsim {

/// A fuel-consumption map from the mean-effective-pressure decomposition of Heywood (Internal Combustion Engine
/// Fundamentals, 2nd ed., ch. 13) and Guzzella & Sciarretta (Vehicle Propulsion Systems, 3rd ed., sec. 4.2):
/// gross indicated mean effective pressure = brake + friction + pumping, and fuel power = gross indicated power /
/// indicated efficiency x enrichment. A Willans line is the special case of no pumping and no enrichment; here
/// the throttle's pumping loss falls as the load rises (the manifold opens towards the atmosphere), which bends
/// the line into the familiar efficiency island, and full load is run rich.
struct EngineMapParams {
  double displacement_m3 = 0.0;
  double indicated_efficiency = 0.0;  ///< gross indicated efficiency of the combustion (fuel -> piston work)
  /// Friction mean effective pressure fmep = f0 + f1 w + f2 w^2 (w crank speed [rad/s]), rubbing and
  /// auxiliaries the engine drives itself (oil and water pumps, valve train).
  double friction_mep0_pa = 0.0;
  double friction_mep1_pa_s_per_rad = 0.0;
  double friction_mep2_pa_s2_per_rad2 = 0.0;
  /// Pumping mean effective pressure at closed throttle; falls linearly to zero at `unthrottled_imep_pa`
  /// (gross imep at wide-open throttle without boost). Zero for an unthrottled (diesel) engine.
  double pumping_mep_closed_pa = 0.0;
  double unthrottled_imep_pa = 0.0;
  /// Full-load enrichment: fuel x (1 + enrichment_max x s), s rising linearly from 0 at this fraction of the
  /// full-load torque to 1 at full load (component protection; catalysts of 2022 cars allow little of it).
  double enrichment_start_fraction = 1.0;
  double enrichment_max = 0.0;
  /// Knock-limited spark retard: above this fraction of the full-load torque the spark is retarded from its
  /// best-efficiency timing, and the gross indicated efficiency falls linearly to (1 - knock_efficiency_loss_max)
  /// at full load. Zero loss for a compression-ignition engine, which does not knock.
  double knock_start_fraction = 1.0;
  double knock_efficiency_loss_max = 0.0;
  double idle_speed_radps = 0.0;
  /// Torque the idle controller keeps in hand at idle speed: air and fuel for this much more than the load, the
  /// spark retarded so it is not delivered, so a load step does not stall the engine (EPA ALPHA's idle control).
  double idle_torque_reserve_nm = 0.0;
  /// Crank, flywheel and rotating parts: the engine must be spun up through the gear ratio as the car speeds up
  /// (booked by validate::fuel_with_transients_m3 from the trace's engine speed, not by the replay).
  double inertia_kg_m2 = 0.0;
  double rated_speed_radps = 0.0;  ///< speed of rated power
  double max_speed_radps = 0.0;    ///< rev limit
  double max_torque_nm = 0.0;      ///< plateau of the full-load curve
  double max_power_w = 0.0;        ///< rated power
  double fuel_cut_min_speed_radps = 0.0;  ///< overrun fuel cut-off above this speed
  /// ... and only while the car moves faster than this: the controller refuels before the last metres of a stop
  /// so the engine does not stall as the converter or clutch lets go (ALPHA: above 5 m/s).
  double fuel_cut_min_vehicle_speed_mps = 0.0;
};

/// Evaluates the map: no state, so one map serves every thread.
class EngineMap {
 public:
  explicit EngineMap(const EngineMapParams& p) : p_(p) {}
  const EngineMapParams& params() const { return p_; }

  /// Full-load brake torque [N m] at `speed_radps`: the plateau, limited by rated power above its speed and
  /// reduced towards idle (less air at low speed); 0 above the rev limit.
  double max_torque_nm(double speed_radps) const;

  /// Fuel power [W] (lower heating value) at a brake torque >= 0 and a speed >= idle. Fired: a motored engine
  /// (negative torque) is the caller's case (fuel cut-off or idle). At idle speed the idle controller's torque
  /// reserve is burnt on top of the load (read from the speed: the powertrain holds the engine at idle speed only
  /// while idling, creeping on its converter or slipping a clutch at launch, all with the controller on).
  double fuel_power_w(double speed_radps, double brake_torque_nm) const;

  /// Brake work per fuel energy for a small step of torque at part load (throttled, below the knock and enrichment
  /// loads): more torque also opens the throttle, so the pumping falls as the torque rises and the step costs
  /// 1 / (eta (1 + closed-throttle pumping / unthrottled imep)) of fuel, less than 1 / eta.
  double part_load_marginal_efficiency() const;

  /// The friction power [W] at a speed: what the engine absorbs when motored with no fuel.
  double friction_power_w(double speed_radps) const;

 private:
  EngineMapParams p_;
};

}  // namespace rollsim
