#include "rollsim/powertrain/combustion.hpp"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <numbers>

namespace rollsim {

double CombustionPowertrain::friction_power_w(double speed_radps) const {
  const auto& e = p_.engine;
  const double pme0_pa = e.friction_mep_pa + e.friction_mep_pa_s_per_rad * speed_radps;
  return pme0_pa * e.displacement_m3 * speed_radps / (4.0 * std::numbers::pi);
}

int CombustionPowertrain::select_gear(double speed_mps, int current_gear) const {
  const auto& g = p_.gearbox;
  const int n = static_cast<int>(g.ratios.size());
  int gear = std::clamp(current_gear, 1, n);
  while (gear < n && speed_mps > g.upshift_speeds_mps[gear - 1]) ++gear;
  while (gear > 1 && speed_mps < g.downshift_speeds_mps[gear - 2]) --gear;
  return gear;
}

std::vector<double> CombustionPowertrain::shift_speeds_mps(int gear) const {
  const auto& g = p_.gearbox;
  const int n = static_cast<int>(g.ratios.size());
  std::vector<double> s;
  if (gear < n) s.push_back(g.upshift_speeds_mps[gear - 1]);
  if (gear > 1) s.push_back(g.downshift_speeds_mps[gear - 2]);
  return s;
}

namespace {
constexpr double kLimiterStart = 0.98;  // of the engine's top speed

// The road speeds at which the engine turns at each of `engine_radps` in each gear, ascending.
std::vector<double> road_speeds_mps(const GearboxParams& g, std::initializer_list<double> engine_radps, double wheel_radius_m) {
  std::vector<double> s;
  for (double r : g.ratios)
    for (double w : engine_radps) s.push_back(w * wheel_radius_m / (r * g.final_drive_ratio));
  std::sort(s.begin(), s.end());
  return s;
}
}  // namespace

// Braking in gear g, the engine is cut off above its cut-off speed and idles declutched below it.
std::vector<double> CombustionPowertrain::braking_regime_speeds_mps(double wheel_radius_m) const {
  if (p_.engine.fuel_cut_min_speed_radps <= 0.0) return {};  // cut off at any speed
  return road_speeds_mps(p_.gearbox, {p_.engine.fuel_cut_min_speed_radps}, wheel_radius_m);
}

std::vector<double> CombustionPowertrain::traction_regime_speeds_mps(double wheel_radius_m) const {
  return road_speeds_mps(p_.gearbox, {kLimiterStart * p_.engine.max_speed_radps, p_.engine.max_speed_radps}, wheel_radius_m);
}

double CombustionPowertrain::max_wheel_force_n(int gear, double speed_mps, double wheel_radius_m) const {
  const auto& e = p_.engine;
  const auto& g = p_.gearbox;
  const double ratio = g.ratios[std::clamp(gear, 1, num_gears()) - 1] * g.final_drive_ratio;
  const double v = std::max(speed_mps, 0.0);
  const double engine_radps = v / wheel_radius_m * ratio;
  if (engine_radps >= e.max_speed_radps) return 0.0;
  double force_n = e.max_torque_nm * ratio * g.efficiency / wheel_radius_m;
  // The file reader refuses an engine too weak for its accessories; a power left below zero would brake as -1/v.
  if (v > 0.0) force_n = std::min(force_n, std::max(0.0, e.max_power_w - p_.aux_power_w / p_.alternator_efficiency) * g.efficiency / v);
  // The limiter cuts in over the last 2 % of the top speed, not at once: a force that stepped to zero there held a
  // car in its top gear at the limit by chattering, 1.4 million solver steps for one NEDC (session 22).
  const double cut_from_radps = kLimiterStart * e.max_speed_radps;
  if (engine_radps > cut_from_radps) force_n *= (e.max_speed_radps - engine_radps) / (e.max_speed_radps - cut_from_radps);
  return force_n;
}

void add_alternator_load(double power_w, double alternator_efficiency, double marginal_efficiency,
                         const FuelParams& fuel, PowerFlow& flow) {
  // Cut off, the load burnt fuel the car's own accessories do not: the catalogue's aux_load cost 8.5 % on WLTC where
  // the same 500 W in the vehicle file cost 6.5 %, and a fuel recording's load was fitted at 55-68 % of its truth
  // (session 26's outside testing).
  if (flow.fuel_cut) return;
  // The accessories' row holds the alternator's shaft power, its loss included, as for the accessories a running
  // engine carries (a start-stop recharge put the alternator's loss in the engine's row: session 22's outside testing).
  const double shaft_w = power_w / alternator_efficiency;
  const double fuel_w = shaft_w / marginal_efficiency;
  flow.aux_power_w += shaft_w;
  flow.fuel_power_w += fuel_w;
  flow.engine_loss_w += fuel_w - shaft_w;
  flow.fuel_rate_m3_per_s += fuel_w / fuel.energy_j_per_m3();
}

// A Willans engine's fuel is linear in brake power: its marginal efficiency is the indicated one.
void CombustionPowertrain::add_electric_load(double power_w, PowerFlow& flow) const {
  add_alternator_load(power_w, p_.alternator_efficiency, p_.engine.indicated_efficiency, p_.fuel, flow);
}

PowerFlow CombustionPowertrain::deliver(double wheel_force_n, double speed_mps, int gear,
                                        double wheel_radius_m) const {
  const auto& e = p_.engine;
  const auto& g = p_.gearbox;
  const int n = static_cast<int>(g.ratios.size());
  const double ratio = g.ratios[std::clamp(gear, 1, n) - 1] * g.final_drive_ratio;
  const double eta = g.efficiency;
  const double v = std::max(speed_mps, 0.0);
  const double coupled_speed_radps = v / wheel_radius_m * ratio;
  // Below idle speed the clutch slips: the engine turns at idle while the gearbox input turns slower.
  double engine_speed_radps = std::max(coupled_speed_radps, e.idle_speed_radps);
  const double accessory_power_w = p_.aux_power_w / p_.alternator_efficiency;

  PowerFlow out;
  out.machine_speed_radps = engine_speed_radps;
  out.aux_power_w = accessory_power_w;
  double brake_power_w = accessory_power_w;

  if (wheel_force_n >= 0.0) {
    // Torque and power limit the force, and the engine's top speed: its limiter gives no force beyond it, in any gear
    // (the top gear pulled at 8,880 rpm against a 6,300 rpm limit, the car following the trace unwarned: session
    // 22's outside testing), as max_wheel_force_n says.
    const double max_force_n = max_wheel_force_n(gear, v, wheel_radius_m);
    const double force_n = std::min(wheel_force_n, max_force_n);
    out.force_limited = wheel_force_n > max_force_n * (1.0 + 1e-12);
    out.wheel_force_n = force_n;
    out.traction_power_w = force_n * v;
    const double torque_nm = force_n * wheel_radius_m / (ratio * eta);
    out.gearbox_loss_w = torque_nm * coupled_speed_radps - out.traction_power_w;
    out.clutch_loss_w = torque_nm * (engine_speed_radps - coupled_speed_radps);
    out.machine_torque_nm = torque_nm;
    brake_power_w += torque_nm * engine_speed_radps;
  } else {
    // Braking: friction brakes and engine drag. Above the cut-off speed the engine is motored with no fuel and
    // the wheels also carry the accessories, so all of it is braking energy; below, the engine idles declutched.
    out.wheel_force_n = wheel_force_n;
    out.friction_brake_power_w = -wheel_force_n * v;
    if (coupled_speed_radps > e.fuel_cut_min_speed_radps) {
      out.aux_power_w = 0.0;
      out.fuel_cut = true;
      return out;
    }
    engine_speed_radps = e.idle_speed_radps;
    out.machine_speed_radps = engine_speed_radps;
  }
  out.fuel_power_w = (brake_power_w + friction_power_w(engine_speed_radps)) / e.indicated_efficiency;
  out.engine_loss_w = out.fuel_power_w - brake_power_w;
  out.fuel_rate_m3_per_s = out.fuel_power_w / p_.fuel.lower_heating_value_j_per_kg / p_.fuel.density_kg_per_m3;
  return out;
}

}  // namespace rollsim
