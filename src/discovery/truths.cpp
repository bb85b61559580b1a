// Concealed truths that real roads, cars and loggers vary: rolling hills, duty-cycled and cabin loads, rising RRC, lag.
#include "rollsim/discovery/truths.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "rollsim/common/units.hpp"

namespace rollsim {
namespace {

constexpr double kTwoPi = 6.283185307179586;

class DutyCycledAcTruth final : public Effect {
 public:
  explicit DutyCycledAcTruth(DutyCycle s) : s_(std::move(s)) {}
  std::string id() const override { return "truth_duty_cycled_ac"; }
  double extra_electric_power_w(const EffectInputs& in, const double*) const override { return s_.power_w(in.time_s); }

 private:
  DutyCycle s_;
};

class CabinLoadTruth final : public Effect {
 public:
  CabinLoadTruth(double initial_w, double decay_s, double floor) : p0_(initial_w), tau_(decay_s), floor_(floor) {}
  std::string id() const override { return "truth_cabin_load"; }
  double extra_electric_power_w(const EffectInputs& in, const double*) const override {
    if (tau_ <= 0.0) return p0_;
    return p0_ * (floor_ + (1.0 - floor_) * std::exp(-std::max(0.0, in.time_s) / tau_));
  }

 private:
  double p0_, tau_, floor_;
};

// Hidden states: the cabin air's and the interior's (seats, trim, glass) temperatures above ambient [K]. The heater
// holds the air at its set point by a proportional thermostat with feed-forward of the settled holding power,
// saturated at its maximum: flat at the maximum while the air is cold, then falling as the interior soaks up less.
class WinterHeaterTruth final : public Effect {
 public:
  explicit WinterHeaterTruth(const WinterCabin& c) : c_(c) {}
  std::string id() const override { return "truth_winter_heater"; }
  int num_states() const override { return 2; }
  void initial_states(double* x) const override { x[0] = x[1] = 0.0; }  // the car soaked at ambient
  void state_derivatives(const EffectInputs&, const double* x, double* xdot) const override {
    const double to_interior_w = c_.interior_w_per_k * (x[0] - x[1]);
    xdot[0] = (heater_w(x[0]) - c_.ua_w_per_k * x[0] - to_interior_w) / c_.air_j_per_k;
    xdot[1] = to_interior_w / c_.interior_j_per_k;
  }
  double extra_electric_power_w(const EffectInputs&, const double* x) const override { return heater_w(x[0]) + c_.blower_w; }

 private:
  double heater_w(double air_k) const {
    const double gain_w_per_k = c_.max_power_w / c_.band_k;
    return std::clamp(c_.ua_w_per_k * c_.setpoint_excess_k + gain_w_per_k * (c_.setpoint_excess_k - air_k), 0.0, c_.max_power_w);
  }
  WinterCabin c_;
};

class HvacCabinTruth final : public Effect {
 public:
  explicit HvacCabinTruth(double power_w) : p_(power_w) {}
  std::string id() const override { return "truth_hvac_cabin"; }
  double extra_electric_power_w(const EffectInputs&, const double*) const override { return p_; }

 private:
  double p_;
};

class RisingRrcTruth final : public Effect {
 public:
  RisingRrcTruth(double rise, double duration_s, double power) : rise_(rise), t_(duration_s), p_(power) {}
  std::string id() const override { return "truth_rising_rrc"; }
  double rolling_resistance_factor(const EffectInputs& in, const double*) const override {
    return 1.0 + rise_ * std::pow(std::clamp(in.time_s / t_, 0.0, 1.0), p_);
  }

 private:
  double rise_, t_, p_;
};

class SteadyWindTruth final : public Effect {
 public:
  /// `gust_mps`: the wind speed's departure from its mean, one value per second from the start (empty: steady).
  SteadyWindTruth(double speed_mps, double from_deg, WindingRoute route, double rho_cda, std::vector<double> gust_mps = {})
      : w_(speed_mps), from_rad_(from_deg * kTwoPi / 360.0), route_(std::move(route)), k_(0.5 * rho_cda),
        gust_mps_(std::move(gust_mps)) {}
  std::string id() const override { return gust_mps_.empty() ? "truth_steady_wind" : "truth_gusty_wind_on_route"; }
  double extra_resistance_n(const EffectInputs& in, const double*) const override {
    const double v = std::max(in.speed_mps, 0.0);
    if (v <= 0.0) return 0.0;
    double w = w_;
    if (!gust_mps_.empty())
      w += gust_mps_[static_cast<std::size_t>(std::clamp(in.time_s, 0.0, static_cast<double>(gust_mps_.size() - 1)))];
    const double rel = v + w * std::cos(from_rad_ - route_.heading_rad(in.distance_m));
    return k_ * (rel * std::abs(rel) - v * v);
  }

 private:
  double w_, from_rad_;
  WindingRoute route_;
  double k_;
  std::vector<double> gust_mps_;
};

}  // namespace

double WindingRoute::heading_rad(double s) const {
  double h = heading0_rad;
  for (std::size_t k = 0; k < amplitude_rad.size(); ++k) h += amplitude_rad[k] * std::sin(kTwoPi * s / wavelength_m[k] + phase_rad[k]);
  return h;
}

WindingRoute winding_route(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  WindingRoute r;
  r.heading0_rad = kTwoPi * u(rng);
  const double total = 1.2 + 0.6 * u(rng);
  std::vector<double> w(3);
  double sum = 0.0;
  for (double& x : w) sum += (x = 0.5 + u(rng));
  for (int k = 0; k < 3; ++k) {
    r.amplitude_rad.push_back(total * w[k] / sum);
    r.wavelength_m.push_back(1000.0 * std::pow(4.0, u(rng)));
    r.phase_rad.push_back(kTwoPi * u(rng));
  }
  return r;
}

std::shared_ptr<const Effect> steady_wind_truth(double speed_mps, double from_deg, WindingRoute route, double rho_cda_kg_per_m) {
  return std::make_shared<SteadyWindTruth>(speed_mps, from_deg, std::move(route), rho_cda_kg_per_m);
}

std::shared_ptr<const Effect> gusty_wind_truth(double mean_speed_mps, double from_deg, WindingRoute route,
                                               double rho_cda_kg_per_m, double duration_s, std::mt19937& rng) {
  // Along-wind gusts as an Ornstein-Uhlenbeck process sampled each second (sd 1.5 m/s, 15 s), as wind_gusty's.
  std::normal_distribution<double> n(0.0, 1.0);
  const double tau_s = 15.0, sd_mps = 1.5, a = std::exp(-1.0 / tau_s);
  std::vector<double> gust;
  double g = 0.0;
  for (int i = 0; i <= static_cast<int>(duration_s) + 2; ++i) gust.push_back(g = a * g + sd_mps * std::sqrt(1.0 - a * a) * n(rng));
  return std::make_shared<SteadyWindTruth>(mean_speed_mps, from_deg, std::move(route), rho_cda_kg_per_m, std::move(gust));
}

void route_gps(const WindingRoute& route, const std::vector<double>& distance_m, double lat0_deg, double lon0_deg,
               std::vector<double>& latitude_deg, std::vector<double>& longitude_deg) {
  const double north_m_per_deg = units::kEarthRadius_m * kTwoPi / 360.0;
  const double east_m_per_deg = north_m_per_deg * std::cos(lat0_deg * kTwoPi / 360.0);
  latitude_deg.assign(distance_m.size(), lat0_deg);
  longitude_deg.assign(distance_m.size(), lon0_deg);
  double s = 0.0, north = 0.0, east = 0.0;
  for (std::size_t i = 0; i < distance_m.size(); ++i) {
    while (s + 1.0 <= distance_m[i]) {  // 1 m steps at the step's middle heading
      const double h = route.heading_rad(s + 0.5);
      north += std::cos(h), east += std::sin(h), s += 1.0;
    }
    const double rest = distance_m[i] - s, h = route.heading_rad(s + 0.5 * rest);
    latitude_deg[i] = lat0_deg + (north + rest * std::cos(h)) / north_m_per_deg;
    longitude_deg[i] = lon0_deg + (east + rest * std::sin(h)) / east_m_per_deg;
  }
}

double RollingHills::elevation_m(double s) const {
  double h = 0.0;
  for (std::size_t k = 0; k < amplitude_m.size(); ++k) h += amplitude_m[k] * std::sin(kTwoPi * s / wavelength_m[k] + phase_rad[k]);
  return h;
}

double RollingHills::grade(double s) const {
  double g = 0.0;
  for (std::size_t k = 0; k < amplitude_m.size(); ++k)
    g += amplitude_m[k] * kTwoPi / wavelength_m[k] * std::cos(kTwoPi * s / wavelength_m[k] + phase_rad[k]);
  return g;
}

RollingHills rolling_hills(double amplitude_m, std::mt19937& rng, double max_grade) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  RollingHills h;
  double norm2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    h.wavelength_m.push_back(500.0 * std::pow(6.0, u(rng)));  // log-uniform 0.5-3 km
    h.phase_rad.push_back(kTwoPi * u(rng));
    norm2 += h.wavelength_m.back() * h.wavelength_m.back();
  }
  double peak_grade = 0.0;
  for (double l : h.wavelength_m) {
    h.amplitude_m.push_back(amplitude_m * l / std::sqrt(norm2));
    peak_grade += h.amplitude_m.back() * kTwoPi / l;
  }
  if (peak_grade > max_grade)
    for (double& l : h.wavelength_m) l *= peak_grade / max_grade;
  return h;
}

double DutyCycle::power_w(double t) const {
  // The first interval ending after t; on if it has begun.
  const auto it = std::upper_bound(on_until_s.begin(), on_until_s.end(), t);
  if (it == on_until_s.end()) return 0.0;
  return t >= on_from_s[static_cast<std::size_t>(it - on_until_s.begin())] ? on_power_w : 0.0;
}

double DutyCycle::mean_power_w(double duration_s) const {
  double on = 0.0;
  for (std::size_t k = 0; k < on_from_s.size(); ++k)
    on += std::max(0.0, std::min(on_until_s[k], duration_s) - std::max(on_from_s[k], 0.0));
  return duration_s > 0.0 ? on_power_w * on / duration_s : 0.0;
}

DutyCycle compressor_cycles(double on_power_w, double duration_s, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double duty = 0.3 + 0.4 * u(rng), period = 120.0 + 240.0 * u(rng);
  DutyCycle d;
  d.on_power_w = on_power_w;
  double t = -period * u(rng);  // a random phase: the first cycle began before the trip
  while (t < duration_s) {
    const double p = period * (0.75 + 0.5 * u(rng));
    d.on_from_s.push_back(t);
    d.on_until_s.push_back(t + duty * p);
    t += p;
  }
  return d;
}

std::shared_ptr<const Effect> duty_cycled_ac_truth(DutyCycle schedule) { return std::make_shared<DutyCycledAcTruth>(std::move(schedule)); }

std::shared_ptr<const Effect> cabin_load_truth(double initial_w, double decay_s, double floor) {
  return std::make_shared<CabinLoadTruth>(initial_w, decay_s, floor);
}

WinterCabin winter_cabin(double max_power_w, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  WinterCabin c;
  c.max_power_w = max_power_w;
  c.setpoint_excess_k = 21.0 - (-10.0 + 15.0 * u(rng));  // ambient -10 to +5 degC, set point 21 degC
  const double hold_share = 0.25 + 0.25 * u(rng);
  c.ua_w_per_k = hold_share * max_power_w / c.setpoint_excess_k;
  // With the interior still at ambient the heater would need 60-100 % of the rest of its maximum on top.
  c.interior_w_per_k = (0.6 + 0.4 * u(rng)) * (1.0 - hold_share) * max_power_w / c.setpoint_excess_k;
  c.interior_j_per_k = c.interior_w_per_k * (600.0 + 1200.0 * u(rng));
  c.air_j_per_k = 15000.0 + 15000.0 * u(rng);
  c.blower_w = 100.0 + 100.0 * u(rng);
  return c;
}

std::shared_ptr<const Effect> winter_heater_truth(const WinterCabin& cabin) { return std::make_shared<WinterHeaterTruth>(cabin); }

double CabinClimate::power_w(double ambient_c) const {
  if (ambient_c < heat_below_c) return ua_w_per_k * (heat_below_c - ambient_c) + blower_w;
  if (ambient_c <= cool_above_c) return 0.0;
  const double cop = std::max(1.5, cop_at_25c - cop_per_k * (ambient_c - 25.0));
  return (ua_w_per_k * (ambient_c - cool_above_c) + solar_w) / cop + blower_w;
}

CabinClimate cabin_climate(double ua_w_per_k, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  CabinClimate c;
  c.ua_w_per_k = ua_w_per_k;
  c.heat_below_c = 17.0 + 2.0 * u(rng);
  c.cool_above_c = 23.0 + 2.0 * u(rng);
  c.solar_w = 100.0 + 300.0 * u(rng);
  c.blower_w = 100.0 + 100.0 * u(rng);
  c.cop_at_25c = 2.5 + u(rng);
  return c;
}

std::shared_ptr<const Effect> hvac_cabin_truth(const CabinClimate& c, double ambient_c) {
  return std::make_shared<HvacCabinTruth>(c.power_w(ambient_c));
}

std::shared_ptr<const Effect> rising_rrc_truth(double rise, double duration_s, double power) {
  return std::make_shared<RisingRrcTruth>(rise, duration_s, power);
}

EngineThermalTruth cold_start_engine(double cold_excess, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  EngineThermalTruth e;
  e.cold_excess = cold_excess;
  e.oil_j_per_k = 5000.0 * std::pow(12.0 / 5.0, u(rng));
  e.block_j_per_k = e.oil_j_per_k * (4.0 + 2.0 * u(rng));
  return e;
}

std::vector<double> engine_thermal_fuel_power_w(const std::vector<double>& time_s, const std::vector<double>& fuel_w,
                                                const std::vector<double>& traction_w, const std::vector<bool>& engine_off,
                                                const EngineThermalTruth& e) {
  constexpr double kToBlock = 0.30, kToOil = 0.10, kOilBlockWPerK = 80.0, kBlockWPerK = 20.0, kRadiatorWPerK = 800.0;
  constexpr double kThermostatK = 85.0, kSumpWPerK = 6.0, kSoakBlockWPerK = 12.0, kViscosityPerK = 0.035, kRefK = 70.0;
  const double norm = std::exp(kViscosityPerK * kRefK) - 1.0;
  double oil_k = e.hot_start ? kRefK + 10.0 : 0.0, block_k = e.hot_start ? kThermostatK : 0.0;
  std::vector<double> p(fuel_w.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double rise = oil_k < kRefK ? (std::exp(kViscosityPerK * (kRefK - oil_k)) - 1.0) / norm : 0.0;
    p[i] = fuel_w[i] * (1.0 + e.cold_excess * rise);
    if (i + 1 == p.size()) break;
    const double dt = time_s[i + 1] - time_s[i];
    const bool off = i < engine_off.size() && engine_off[i];
    const double loss_w = off ? 0.0 : std::max(0.0, p[i] - std::max(0.0, traction_w[i]));
    const double exchange_w = kOilBlockWPerK * (block_k - oil_k);
    double cooling_w = (off ? kSoakBlockWPerK : kBlockWPerK) * block_k;
    if (!off && block_k > kThermostatK) cooling_w += kRadiatorWPerK * (block_k - kThermostatK);
    // Explicit steps of the segment length: stable while dt is well under C / G (oil: 60 s and more).
    block_k += dt * (kToBlock * loss_w - exchange_w - cooling_w) / e.block_j_per_k;
    oil_k += dt * (kToOil * loss_w + exchange_w - kSumpWPerK * oil_k) / e.oil_j_per_k;
  }
  return p;
}

std::vector<double> delayed(const std::vector<double>& time_s, const std::vector<double>& x, double lag_s) {
  std::vector<double> out(x.size());
  std::size_t j = 0;  // x's interval [j, j + 1] holding t - lag, advancing with i
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double t = time_s[i] - lag_s;
    if (t <= time_s.front()) {
      out[i] = x.front();
      continue;
    }
    while (j + 1 < x.size() && time_s[j + 1] <= t) ++j;
    if (j + 1 >= x.size()) {
      out[i] = x.back();
      continue;
    }
    const double f = (t - time_s[j]) / (time_s[j + 1] - time_s[j]);
    out[i] = (1.0 - f) * x[j] + f * x[j + 1];
  }
  return out;
}

}  // namespace rollsim
