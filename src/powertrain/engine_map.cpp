#include "rollsim/powertrain/engine_map.hpp"

#include <algorithm>
#include <numbers>

namespace rollsim {

namespace {
// A four-stroke engine fires each cylinder every second revolution: power = mep * V_d * w / (4 pi).
constexpr double kFourStroke = 4.0 * std::numbers::pi;
}  // namespace

double EngineMap::max_torque_nm(double speed_radps) const {
  if (speed_radps > p_.max_speed_radps) return 0.0;
  double t = p_.max_torque_nm;
  if (speed_radps > 0.0) t = std::min(t, p_.max_power_w / speed_radps);
  // Below about half the rated speed the cylinders fill less: 70 % of the plateau at idle, full at half rated
  // speed (a boosted engine's plateau starts near there too, once the turbine spools).
  const double knee_radps = 0.5 * p_.rated_speed_radps;
  if (speed_radps < knee_radps && knee_radps > p_.idle_speed_radps) {
    const double s = std::clamp((speed_radps - p_.idle_speed_radps) / (knee_radps - p_.idle_speed_radps), 0.0, 1.0);
    t *= 0.7 + 0.3 * s;
  }
  return t;
}

double EngineMap::friction_power_w(double speed_radps) const {
  const double w = std::max(speed_radps, 0.0);
  const double fmep_pa = p_.friction_mep0_pa + w * (p_.friction_mep1_pa_s_per_rad + w * p_.friction_mep2_pa_s2_per_rad2);
  return fmep_pa * p_.displacement_m3 * w / kFourStroke;
}

double EngineMap::part_load_marginal_efficiency() const {
  const double pc = p_.pumping_mep_closed_pa, a = p_.unthrottled_imep_pa;
  return p_.indicated_efficiency * (pc > 0.0 && a > 0.0 ? 1.0 + pc / a : 1.0);
}

double EngineMap::fuel_power_w(double speed_radps, double brake_torque_nm) const {
  const double w = std::max(speed_radps, p_.idle_speed_radps);
  const bool idling = speed_radps <= p_.idle_speed_radps;
  const double torque_nm = std::max(brake_torque_nm, 0.0) + (idling ? p_.idle_torque_reserve_nm : 0.0);
  const double bmep_pa = kFourStroke * torque_nm / p_.displacement_m3;
  const double fmep_pa = p_.friction_mep0_pa + w * (p_.friction_mep1_pa_s_per_rad + w * p_.friction_mep2_pa_s2_per_rad2);
  // Pumping falls linearly from its closed-throttle value to zero at the unthrottled imep; solved for the gross
  // imep it belongs to: imep = bmep + fmep + pc (1 - imep / a).
  double imep_pa = bmep_pa + fmep_pa;
  const double pc = p_.pumping_mep_closed_pa, a = p_.unthrottled_imep_pa;
  if (pc > 0.0 && imep_pa < a) imep_pa = (bmep_pa + fmep_pa + pc) / (1.0 + pc / a);
  double fuel_w = imep_pa * p_.displacement_m3 * w / kFourStroke / p_.indicated_efficiency;
  const double full_nm = max_torque_nm(w);
  const double load = full_nm > 0.0 ? torque_nm / full_nm : 1.0;
  // Share of the way from a threshold load to full load: 0 below it, 1 at full load.
  auto above = [load](double start_fraction) {
    return start_fraction < 1.0 ? std::clamp((load - start_fraction) / (1.0 - start_fraction), 0.0, 1.0) : 0.0;
  };
  fuel_w *= 1.0 + p_.enrichment_max * above(p_.enrichment_start_fraction);
  fuel_w /= 1.0 - p_.knock_efficiency_loss_max * above(p_.knock_start_fraction);
  return fuel_w;
}

}  // namespace rollsim
