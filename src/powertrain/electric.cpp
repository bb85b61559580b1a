#include "rollsim/powertrain/electric.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "rollsim/common/error.hpp"

namespace rollsim {

namespace {

// Linear interpolation in a table whose x rises; clamped at both ends.
double interpolate(const std::vector<double>& x, const std::vector<double>& y, double at) {
  if (at <= x.front()) return y.front();
  if (at >= x.back()) return y.back();
  const auto hi = static_cast<std::size_t>(std::upper_bound(x.begin(), x.end(), at) - x.begin());
  const double t = (at - x[hi - 1]) / (x[hi] - x[hi - 1]);
  return y[hi - 1] + t * (y[hi] - y[hi - 1]);
}

}  // namespace

ElectricPowertrain::ElectricPowertrain(const ElectricPowertrainParams& params) : p_(params) {
  const auto& x = p_.motor.losses.output_fraction;
  const auto& eta = p_.motor.losses.efficiency;
  if (eta.empty() && x.empty()) return;
  bool ok = x.size() == eta.size() && x.size() >= 2 && x.front() == 0.0 && x.back() == 1.0 && p_.motor.max_power_w > 0.0;
  for (std::size_t i = 0; ok && i < x.size(); ++i) ok = (i == 0 || x[i] > x[i - 1]) && eta[i] > 0.0 && eta[i] <= 1.0;
  if (!ok) {
    throw ModelDomainError("motor efficiency curve: output fractions must rise from 0 to 1, one efficiency in (0, 1] each, "
                                "and the machine needs a rated power");
  }
}

double ElectricPowertrain::motor_loss_w(double torque_nm, double speed_radps) const {
  const auto& l = p_.motor.losses;
  if (speed_radps <= 0.0 && torque_nm == 0.0) return 0.0;  // switched off at standstill
  if (!l.efficiency.empty()) {
    const double shaft_w = torque_nm * speed_radps;
    const double eta = interpolate(l.output_fraction, l.efficiency, std::abs(shaft_w) / p_.motor.max_power_w);
    return shaft_w >= 0.0 ? shaft_w * (1.0 / eta - 1.0) : -shaft_w * (1.0 - eta);
  }
  return l.copper_w_per_nm2 * torque_nm * torque_nm + l.iron_w_s_per_rad * speed_radps +
         l.windage_w_s3_per_rad3 * speed_radps * speed_radps * speed_radps + l.constant_w;
}

// The physical model's speed terms (iron, windage, constant) cancel, leaving the current's (copper) part; a table
// loses nothing at zero torque, so all of its loss is added. Evaluated on every braking call, hence not as a
// difference of two motor_loss_w.
double ElectricPowertrain::torque_loss_w(double torque_nm, double speed_radps) const {
  const auto& l = p_.motor.losses;
  if (!l.efficiency.empty()) return motor_loss_w(torque_nm, speed_radps);
  return l.copper_w_per_nm2 * torque_nm * torque_nm;
}

double ElectricPowertrain::max_battery_power_w() const {
  const double r = p_.battery.internal_resistance_ohm;
  const double voc = p_.battery.open_circuit_voltage_v;
  return r > 0.0 ? voc * voc / (4.0 * r) * (1.0 - 1e-9) : std::numeric_limits<double>::infinity();
}

double ElectricPowertrain::battery_current_a(double terminal_power_w) const {
  const double voc = p_.battery.open_circuit_voltage_v;
  const double r = p_.battery.internal_resistance_ohm;
  if (r <= 0.0) return terminal_power_w / voc;
  // P = (Voc - I R) I, the smaller root: the battery's operating branch.
  const double disc = voc * voc - 4.0 * r * terminal_power_w;
  if (disc < 0.0) {
    throw ModelDomainError("battery cannot deliver " + format_value(terminal_power_w / 1e3) +
                           " kW (maximum Voc^2/4R = " + format_value(voc * voc / (4.0 * r) / 1e3) + " kW)");
  }
  return (voc - std::sqrt(disc)) / (2.0 * r);
}

double ElectricPowertrain::speed_limit_factor(double speed_radps) const {
  const double w_max = p_.motor.max_speed_radps;
  const double band_radps = p_.motor.speed_limit_band_fraction * w_max;
  if (speed_radps >= w_max) return 0.0;
  if (!(band_radps > 0.0) || speed_radps <= w_max - band_radps) return 1.0;
  return (w_max - speed_radps) / band_radps;
}

double ElectricPowertrain::max_wheel_force_n(int /*gear*/, double speed_mps, double wheel_radius_m) const {
  const double ratio = p_.reduction.ratio;
  const double eta = p_.reduction.efficiency;
  const double v = std::max(speed_mps, 0.0);
  double force_n = p_.motor.max_torque_nm * ratio * eta / wheel_radius_m;
  if (v > 0.0) force_n = std::min(force_n, p_.motor.max_power_w * eta / v);
  return force_n * speed_limit_factor(v / wheel_radius_m * ratio);
}

PowerFlow ElectricPowertrain::deliver(double wheel_force_n, double speed_mps, int gear,
                                      double wheel_radius_m) const {
  const double ratio = p_.reduction.ratio;
  const double eta = p_.reduction.efficiency;
  const double v = std::max(speed_mps, 0.0);
  const double motor_speed_radps = v / wheel_radius_m * ratio;
  PowerFlow out;
  out.machine_speed_radps = motor_speed_radps;
  double shaft_power_w = 0.0;
  double torque_nm = 0.0;

  if (wheel_force_n >= 0.0) {
    const double max_force_n = max_wheel_force_n(gear, v, wheel_radius_m);
    const double force_n = std::min(wheel_force_n, max_force_n);
    out.force_limited = wheel_force_n > max_force_n * (1.0 + 1e-12);
    out.wheel_force_n = force_n;
    out.traction_power_w = force_n * v;
    shaft_power_w = out.traction_power_w / eta;
    out.gearbox_loss_w = shaft_power_w - out.traction_power_w;
    torque_nm = force_n * wheel_radius_m / (ratio * eta);
  } else {
    const double brake_force_n = -wheel_force_n;
    const auto& rg = p_.regen;
    double fade = 1.0;
    if (v <= rg.min_speed_mps) {
      fade = 0.0;
    } else if (v < rg.fade_speed_mps) {
      fade = (v - rg.min_speed_mps) / (rg.fade_speed_mps - rg.min_speed_mps);
    }
    double regen_force_n = brake_force_n * rg.driven_axle_brake_fraction * fade;
    // The speed limiter derates generating torque as it does motoring torque: past max_speed (only a replayed
    // trace gets there) the machine gives nothing and the friction brakes take it all.
    const double limiter = speed_limit_factor(motor_speed_radps);
    regen_force_n = std::min(regen_force_n, limiter * p_.motor.max_torque_nm * ratio / (wheel_radius_m * eta));
    if (v > 0.0) {
      // Mechanical power reaching the motor is limited by the motor rating, derated near top speed as motoring is, and
      // by what the battery accepts, which the machine's speed does not derate (the fade scaled both: at 146 km/h ev.yaml
      // took 5.3 kW of a 15.4 kW braking demand where its 20 kW regen limit allows all: session 23's outside testing).
      const double max_shaft_w = std::min(limiter * p_.motor.max_power_w, rg.max_power_w);
      regen_force_n = std::min(regen_force_n, max_shaft_w / (v * eta));
    } else {
      regen_force_n = 0.0;
    }
    torque_nm = -regen_force_n * wheel_radius_m * eta / ratio;
    // Regenerating must recover energy; where the loss it adds would exceed it, the controller leaves it to
    // friction. The machine's no-load loss (iron, windage) is paid at this speed either way, so it does not count.
    if (regen_force_n > 0.0 && -regen_force_n * v * eta + torque_loss_w(torque_nm, motor_speed_radps) >= 0.0) {
      regen_force_n = 0.0;
      torque_nm = 0.0;
    }
    out.wheel_force_n = wheel_force_n;
    out.regen_wheel_power_w = regen_force_n * v;
    out.friction_brake_power_w = (brake_force_n - regen_force_n) * v;
    out.gearbox_loss_w = out.regen_wheel_power_w * (1.0 - eta);
    shaft_power_w = -(out.regen_wheel_power_w - out.gearbox_loss_w);
  }
  out.machine_torque_nm = torque_nm;
  out.motor_loss_w = motor_loss_w(torque_nm, motor_speed_radps);
  out.aux_power_w = p_.aux_power_w;
  out.battery_terminal_power_w = shaft_power_w + out.motor_loss_w + out.aux_power_w;
  // A battery gives at most Voc^2 / 4R (at half its open-circuit voltage): beyond it the car is power-limited,
  // like at the motor's own limit, and falls behind the trace instead of asking the impossible.
  const double max_terminal_w = max_battery_power_w();
  if (wheel_force_n > 0.0 && out.battery_terminal_power_w > max_terminal_w) {
    double lo = 0.0, hi = out.wheel_force_n;
    for (int i = 0; i < 40; ++i) {
      const double mid = 0.5 * (lo + hi);
      const double p = mid * v / eta + motor_loss_w(mid * wheel_radius_m / (ratio * eta), motor_speed_radps) + out.aux_power_w;
      (p > max_terminal_w ? hi : lo) = mid;
    }
    PowerFlow limited = deliver(lo, speed_mps, gear, wheel_radius_m);
    limited.force_limited = true;
    return limited;
  }
  out.battery_current_a = battery_current_a(out.battery_terminal_power_w);
  out.battery_loss_w = out.battery_current_a * out.battery_current_a * p_.battery.internal_resistance_ohm;
  return out;
}

void ElectricPowertrain::add_electric_load(double power_w, PowerFlow& flow) const {
  flow.aux_power_w += power_w;
  flow.battery_terminal_power_w += power_w;
}

namespace {

// Road speed [m/s] of a motor speed [rad/s] through the reduction and the wheel.
double road_speed_mps(double motor_radps, double ratio, double wheel_radius_m) { return motor_radps * wheel_radius_m / ratio; }

// Sorted, without repeats or non-positive speeds.
std::vector<double> ascending(std::vector<double> s) {
  s.erase(std::remove_if(s.begin(), s.end(), [](double v) { return !(v > 0.0) || !std::isfinite(v); }), s.end());
  std::sort(s.begin(), s.end());
  s.erase(std::unique(s.begin(), s.end()), s.end());
  return s;
}

}  // namespace

// The speed limiter's band, where the machine's force and power derate, is a kink of motoring and regenerating alike.
std::vector<double> ElectricPowertrain::speed_band_speeds_mps(double wheel_radius_m) const {
  const double w_max = p_.motor.max_speed_radps, band = p_.motor.speed_limit_band_fraction * w_max;
  if (!(w_max > 0.0)) return {};
  return {road_speed_mps(w_max - band, p_.reduction.ratio, wheel_radius_m), road_speed_mps(w_max, p_.reduction.ratio, wheel_radius_m)};
}

std::vector<double> ElectricPowertrain::braking_regime_speeds_mps(double /*wheel_radius_m*/) const {
  std::vector<double> s;
  if (p_.regen.min_speed_mps > 0.0) s.push_back(p_.regen.min_speed_mps);
  if (p_.regen.fade_speed_mps > p_.regen.min_speed_mps) s.push_back(p_.regen.fade_speed_mps);
  return s;
}

// Where the regenerating force turns from the torque limit to the power limit (the motor's or the battery's
// acceptance) and the limiter's band: a 1 Hz replay stepped across them with two Gauss points, 0.65 % off the
// regeneration from the limiter's band and 1.25 % off the battery energy of a hard 20 -> 0 km/h stop (session 25's
// outside testing).
std::vector<double> ElectricPowertrain::braking_kink_speeds_mps(double wheel_radius_m) const {
  std::vector<double> s = speed_band_speeds_mps(wheel_radius_m);
  const double regen_power_w = std::min(p_.motor.max_power_w, p_.regen.max_power_w);
  if (p_.motor.max_torque_nm > 0.0 && regen_power_w > 0.0)
    s.push_back(regen_power_w * wheel_radius_m / (p_.motor.max_torque_nm * p_.reduction.ratio));
  return ascending(s);
}

// Where the motoring force turns from the torque limit to the power limit, and the limiter's band.
std::vector<double> ElectricPowertrain::traction_regime_speeds_mps(double wheel_radius_m) const {
  std::vector<double> s = speed_band_speeds_mps(wheel_radius_m);
  if (p_.motor.max_torque_nm > 0.0 && p_.motor.max_power_w > 0.0)
    s.push_back(p_.motor.max_power_w * wheel_radius_m / (p_.motor.max_torque_nm * p_.reduction.ratio));
  return ascending(s);
}

}  // namespace rollsim
