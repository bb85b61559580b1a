#include "rollsim/powertrain/conventional.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "rollsim/common/error.hpp"

namespace rollsim {

ConventionalPowertrain::ConventionalPowertrain(const ConventionalPowertrainParams& params) : p_(params), map_(params.engine) {
  const auto& t = p_.transmission;
  if (t.ratios.empty() || (t.kind == TransmissionKind::cvt && t.ratios.size() != 2)) {
    throw ModelDomainError("transmission needs at least one ratio (a CVT exactly two: its lowest and highest)");
  }
}

double ConventionalPowertrain::accessory_torque_nm(double engine_speed_radps) const {
  return p_.aux_power_w / p_.alternator_efficiency / std::max(engine_speed_radps, p_.engine.idle_speed_radps);
}

double ConventionalPowertrain::converter_pump_speed_radps(double turbine_speed_radps, double turbine_torque_nm) const {
  const auto& c = p_.transmission.converter;
  if (turbine_torque_nm <= 0.0) return turbine_speed_radps;
  // Turbine torque TR(SR) phi(SR) (w_p / K)^2 rises monotonically with the pump speed w_p >= w_t: bisection.
  auto turbine_torque = [&](double pump_radps) {
    const double sr = turbine_speed_radps / pump_radps;
    const double tr = sr < c.coupling_speed_ratio ? c.stall_torque_ratio - (c.stall_torque_ratio - 1.0) * sr / c.coupling_speed_ratio : 1.0;
    const double phi = sr <= c.coupling_speed_ratio ? 1.0 : (1.0 - sr) / (1.0 - c.coupling_speed_ratio);
    const double q = pump_radps / c.k_factor_radps_per_sqrt_nm;
    return tr * phi * q * q;
  };
  double lo = turbine_speed_radps, hi = turbine_speed_radps + c.k_factor_radps_per_sqrt_nm * std::sqrt(turbine_torque_nm) + 1.0;
  while (turbine_torque(hi) < turbine_torque_nm) hi *= 2.0;
  for (int i = 0; i < 40 && hi - lo > 1e-6 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (turbine_torque(mid) < turbine_torque_nm ? lo : hi) = mid;
  }
  return hi;
}

ConventionalPowertrain::Operating ConventionalPowertrain::through(double ratio, int gear, double wheel_torque_nm,
                                                                  double wheel_speed_radps) const {
  const auto& t = p_.transmission;
  const auto& e = p_.engine;
  Operating op;
  op.ratio = ratio;
  op.gear = t.kind == TransmissionKind::cvt ? 0 : gear;
  const double turbine_radps = wheel_speed_radps * ratio;
  const double turbine_nm = wheel_torque_nm / (ratio * t.efficiency) + t.spin_loss_nm;
  const bool converter = t.kind != TransmissionKind::clutch;
  op.locked = !converter || (gear >= t.converter.lockup_min_gear && turbine_radps >= t.converter.lockup_min_speed_radps);
  if (op.locked) {
    // Below idle (or, pulling away, below the launch speed) a friction clutch slips: the engine holds that speed
    // while the gearbox input turns slower.
    const double launch_radps = converter || wheel_torque_nm <= 0.0 ? 0.0 : t.launch_engine_speed_radps;
    op.engine_speed_radps = std::max({turbine_radps, e.idle_speed_radps, launch_radps});
    op.engine_torque_nm = turbine_nm;
    op.slip_loss_w = turbine_nm * (op.engine_speed_radps - turbine_radps);
    return op;
  }
  const double pump_radps = converter_pump_speed_radps(turbine_radps, turbine_nm);
  op.engine_speed_radps = std::max(pump_radps, e.idle_speed_radps);
  if (op.engine_speed_radps > pump_radps) {
    // The engine idles faster than the converter needs: the pump absorbs its capacity at idle (creep), and what
    // the turbine passes beyond the demand is held by the brakes; both are booked as converter loss.
    const auto& c = t.converter;
    const double sr = turbine_radps / op.engine_speed_radps;
    const double phi = sr <= c.coupling_speed_ratio ? 1.0 : (1.0 - sr) / (1.0 - c.coupling_speed_ratio);
    const double q = op.engine_speed_radps / c.k_factor_radps_per_sqrt_nm;
    op.engine_torque_nm = std::max(phi * q * q, turbine_nm);
  } else {
    const auto& c = t.converter;
    const double sr = turbine_radps / pump_radps;
    const double tr = sr < c.coupling_speed_ratio ? c.stall_torque_ratio - (c.stall_torque_ratio - 1.0) * sr / c.coupling_speed_ratio : 1.0;
    op.engine_torque_nm = turbine_nm / tr;
  }
  op.slip_loss_w = op.engine_torque_nm * op.engine_speed_radps - turbine_nm * turbine_radps;
  return op;
}

ConventionalPowertrain::Operating ConventionalPowertrain::operate(double wheel_torque_nm, double wheel_speed_radps) const {
  const auto& t = p_.transmission;
  const auto& e = p_.engine;
  auto load_of = [&](const Operating& op) {
    const double full = map_.max_torque_nm(op.engine_speed_radps);
    return full > 0.0 ? (op.engine_torque_nm + accessory_torque_nm(op.engine_speed_radps)) / full : 1e9;
  };
  const double wheel_power_w = wheel_torque_nm * wheel_speed_radps;
  const double min_speed_radps = t.min_engine_speed_radps;
  if (t.kind == TransmissionKind::cvt) {
    // Towards the efficiency island: the engine speed at which the demand takes the chosen share of full load.
    const double power_w = wheel_power_w / t.efficiency + p_.aux_power_w / p_.alternator_efficiency;
    const double target_radps = std::clamp(power_w / (t.max_torque_fraction * e.max_torque_nm), min_speed_radps, e.rated_speed_radps);
    const double ratio = wheel_speed_radps > 0.0 ? std::clamp(target_radps / wheel_speed_radps, t.ratios[1], t.ratios[0]) : t.ratios[0];
    return through(ratio, 1, wheel_torque_nm, wheel_speed_radps);
  }
  const int n = static_cast<int>(t.ratios.size());
  Operating best;
  double best_load = std::numeric_limits<double>::infinity();
  for (int g = n; g >= 1; --g) {
    const Operating op = through(t.ratios[static_cast<std::size_t>(g - 1)], g, wheel_torque_nm, wheel_speed_radps);
    if (op.engine_speed_radps > e.max_speed_radps) continue;
    const double load = load_of(op);
    // Judged on the gearbox input (turbine) speed: a slipping converter would make any gear look fast enough.
    const bool fast_enough = g == 1 || wheel_speed_radps * op.ratio >= min_speed_radps;
    if (fast_enough && load <= t.max_torque_fraction) return op;
    if (load < best_load) {
      best_load = load;
      best = op;
    }
  }
  if (best.ratio == 0.0) best = through(t.ratios.back(), n, wheel_torque_nm, wheel_speed_radps);  // all overspeed
  return best;
}

double ConventionalPowertrain::max_wheel_force_n(int /*gear*/, double speed_mps, double wheel_radius_m) const {
  const auto& t = p_.transmission;
  const auto& e = p_.engine;
  const double wheel_radps = std::max(speed_mps, 0.0) / wheel_radius_m;
  auto force_at = [&](double ratio) {
    const double engine_radps = std::max(wheel_radps * ratio, e.idle_speed_radps);
    if (engine_radps > e.max_speed_radps) return 0.0;
    const double torque_nm = map_.max_torque_nm(engine_radps) - accessory_torque_nm(engine_radps) - t.spin_loss_nm;
    return std::max(torque_nm, 0.0) * ratio * t.efficiency / wheel_radius_m;
  };
  if (t.kind == TransmissionKind::cvt) {
    const double ratio = wheel_radps > 0.0 ? std::clamp(e.rated_speed_radps / wheel_radps, t.ratios[1], t.ratios[0]) : t.ratios[0];
    return force_at(ratio);
  }
  double best = 0.0;
  for (double r : t.ratios) best = std::max(best, force_at(r));
  return best;
}

// The map's fuel at part load rises with brake work at its marginal efficiency, above the gross indicated one
// because the throttle opens as the load grows (camry_2018_map: 0.46 against 0.425).
void ConventionalPowertrain::add_electric_load(double power_w, PowerFlow& flow) const {
  add_alternator_load(power_w, p_.alternator_efficiency, map_.part_load_marginal_efficiency(), p_.fuel, flow);
}

bool ConventionalPowertrain::fuel_cut_off(double speed_mps, double wheel_radius_m, Operating& coasting) const {
  const auto& e = p_.engine;
  coasting = operate(0.0, speed_mps / wheel_radius_m);
  return coasting.locked && coasting.engine_speed_radps > e.fuel_cut_min_speed_radps &&
         speed_mps > e.fuel_cut_min_vehicle_speed_mps;
}

// Where fuel_cut_off changes its answer. Coasting, the gearbox picks its ratio from the speed alone, so the answer
// can change only where the vehicle speed passes its threshold or an input speed in some ratio passes one of the
// engine speeds the choice and the lock-up compare with; of those candidates, the ones where it does change.
std::vector<double> ConventionalPowertrain::braking_regime_speeds_mps(double wheel_radius_m) const {
  const auto& e = p_.engine;
  const auto& t = p_.transmission;
  std::vector<double> candidates{e.fuel_cut_min_vehicle_speed_mps};
  for (double engine_radps : {t.min_engine_speed_radps, t.converter.lockup_min_speed_radps, e.fuel_cut_min_speed_radps,
                              e.idle_speed_radps}) {
    for (double ratio : t.ratios) candidates.push_back(engine_radps * wheel_radius_m / ratio);
  }
  std::sort(candidates.begin(), candidates.end());
  candidates.erase(std::remove_if(candidates.begin(), candidates.end(), [](double v) { return !(v > 0.0); }), candidates.end());
  candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
  // The answer is constant between neighbouring candidates: read it once in each gap, and keep the candidates
  // between two gaps that differ (once per replay of every validate row, so the reading is not doubled).
  std::vector<double> s;
  if (candidates.empty()) return s;
  Operating op;
  bool below = fuel_cut_off(0.5 * candidates.front(), wheel_radius_m, op);
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    const double next = k + 1 < candidates.size() ? 0.5 * (candidates[k] + candidates[k + 1]) : 2.0 * candidates[k];
    const bool above = fuel_cut_off(next, wheel_radius_m, op);
    if (above != below) s.push_back(candidates[k]);
    below = above;
  }
  return s;
}

PowerFlow ConventionalPowertrain::deliver(double wheel_force_n, double speed_mps, int gear, double wheel_radius_m) const {
  const auto& e = p_.engine;
  const double v = std::max(speed_mps, 0.0);
  const double wheel_radps = v / wheel_radius_m;
  const double accessory_w = p_.aux_power_w / p_.alternator_efficiency;
  PowerFlow out;
  out.aux_power_w = accessory_w;
  double engine_radps = e.idle_speed_radps, engine_nm = 0.0;
  if (wheel_force_n > 0.0 && v > 0.0) {
    const double max_force_n = max_wheel_force_n(gear, v, wheel_radius_m);
    const double force_n = std::min(wheel_force_n, max_force_n);
    out.force_limited = wheel_force_n > max_force_n * (1.0 + 1e-12);
    const Operating op = operate(force_n * wheel_radius_m, wheel_radps);
    out.wheel_force_n = force_n;
    out.traction_power_w = force_n * v;
    const double turbine_w = op.engine_torque_nm * op.engine_speed_radps - op.slip_loss_w;
    out.gearbox_loss_w = turbine_w - out.traction_power_w;
    out.clutch_loss_w = op.slip_loss_w;
    engine_radps = op.engine_speed_radps;
    engine_nm = op.engine_torque_nm;
    out.gear_ratio = op.ratio;
    out.engaged_gear = op.gear;
  } else {
    // Braking, coasting or standing: friction brakes hold the car. Coupled above the cut-off speeds (engine and
    // road) the engine is motored without fuel and the wheels carry the accessories too (all booked as braking);
    // otherwise it idles.
    out.wheel_force_n = wheel_force_n;
    out.friction_brake_power_w = -wheel_force_n * v;
    if (v > 0.0) {
      Operating op;
      const bool cut_off = fuel_cut_off(v, wheel_radius_m, op);
      out.engaged_gear = op.gear;
      if (cut_off) {
        out.aux_power_w = 0.0;
        out.fuel_cut = true;
        out.machine_speed_radps = op.engine_speed_radps;
        out.gear_ratio = op.ratio;
        return out;
      }
    } else if (p_.transmission.kind != TransmissionKind::clutch && !p_.transmission.converter.neutral_at_standstill) {
      // Standing in Drive: the converter's pump turns at idle against a stalled turbine and absorbs its capacity
      // (ω_idle / K)^2, all of it heat, while the brakes hold the car.
      const double q = e.idle_speed_radps / p_.transmission.converter.k_factor_radps_per_sqrt_nm;
      engine_nm = q * q;
      out.clutch_loss_w = engine_nm * e.idle_speed_radps;
    }
  }
  out.machine_speed_radps = engine_radps;
  out.machine_torque_nm = engine_nm;
  const double brake_w = engine_nm * engine_radps + accessory_w;
  out.fuel_power_w = map_.fuel_power_w(engine_radps, engine_nm + accessory_torque_nm(engine_radps));
  out.engine_loss_w = out.fuel_power_w - brake_w;
  out.fuel_rate_m3_per_s = out.fuel_power_w / p_.fuel.energy_j_per_m3();
  return out;
}

}  // namespace rollsim
