// Synthetic recordings with concealed effects: each truth is a richer model than the catalogue's, on its own code.
#include "rollsim/discovery/generate.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "rollsim/common/error.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/discovery/truths.hpp"
#include "rollsim/sim/simulation.hpp"

namespace rollsim {
namespace {

constexpr double kG = units::kStandardGravity_mps2;
constexpr double kTwoPi = 6.283185307179586;

// The truth's RRC level (within the tyres' spec tolerance): a calibration quantity, never a discovery.
class RrcLevelTruth final : public Effect {
 public:
  explicit RrcLevelTruth(double level) : level_(level) {}
  std::string id() const override { return "truth_rrc_level"; }
  double rolling_resistance_factor(const EffectInputs&, const double*) const override { return level_; }

 private:
  double level_;
};

// Truth tyre: two thermal nodes (tread, carcass). Hysteresis loss heats both (60/40); the tread convects to air
// with h ~ (1 + v/v0)^0.8 (turbulent forced convection) and conducts to the carcass; the carcass loses little.
// RRC follows an exponential law in a weighted temperature (not the catalogue's linear-to-warm law). The
// time_reversed option warms the tyre at the start and lets it cool (RRC rises) towards the end instead.
class TwoNodeTyreTruth final : public Effect {
 public:
  TwoNodeTyreTruth(double excess, bool reversed, double duration_s) : excess_(excess), reversed_(reversed), duration_s_(duration_s) {}
  std::string id() const override { return "truth_two_node_tyre"; }
  int num_states() const override { return 2; }
  void state_derivatives(const EffectInputs& in, const double* x, double* xdot) const override {
    const double v = std::max(in.speed_mps, 0.0);
    const double p = in.base_rolling_force_n * rolling_resistance_factor(in, x) * v;
    const double h_tread = 18.0 * std::pow(1.0 + v / 8.0, 0.8);
    const double g_tc = 25.0;  // tread-carcass conductance [W/K]
    xdot[0] = (0.6 * p - h_tread * x[0] - g_tc * (x[0] - x[1])) / 22000.0;
    xdot[1] = (0.4 * p + g_tc * (x[0] - x[1]) - 4.0 * x[1]) / 40000.0;
  }
  double rolling_resistance_factor(const EffectInputs& in, const double* x) const override {
    double cold = std::exp(-(0.4 * x[0] + 0.6 * x[1]) / 12.0);
    // Reversed null: the same-sized transient mirrored in time (decay placed at the end).
    if (reversed_) cold = std::exp(-std::max(0.0, duration_s_ - in.time_s) / 700.0);
    return 1.0 + excess_ * cold;
  }

 private:
  double excess_;
  bool reversed_;
  double duration_s_;
};

// Truth ambient temperature on RRC, per tyre compound: ln RRC falls with the tyre's temperature along a WLF-like
// curve, ln f = -c C2 dT / (C2 + dT) (slope -c at the reference, steeper when cold: not the catalogue's linear
// 1 + c (T_ref - T_amb)), with dT the tyre's temperature above its reference (20 degC ambient, 20 K running rise).
// Preconditioned (cold_start false): the tyre runs at ambient + 20 K from the start, as after a warm-up drive. Cold
// start: the tyre starts at ambient and warms by a one-node heat balance (30 kJ/K, 90 % of the rolling loss in,
// convection 40 (1 + v/8)^0.8 W/K out), so a cold ambient also brings a larger warm-up: the two are confounded.
class AmbientCompoundTruth final : public Effect {
 public:
  AmbientCompoundTruth(double c_per_k, double c2_k, double ambient_c, bool cold_start)
      : c_(c_per_k), c2_(c2_k), ambient_c_(ambient_c), cold_start_(cold_start) {}
  std::string id() const override { return "truth_ambient_compound"; }
  int num_states() const override { return cold_start_ ? 1 : 0; }
  void state_derivatives(const EffectInputs& in, const double* x, double* xdot) const override {
    if (!cold_start_) return;  // preconditioned: no state (the simulator still calls every effect)
    const double v = std::max(in.speed_mps, 0.0);
    const double p = in.base_rolling_force_n * rolling_resistance_factor(in, x) * v;
    xdot[0] = (0.9 * p - 40.0 * std::pow(1.0 + v / 8.0, 0.8) * x[0]) / 30000.0;
  }
  double rolling_resistance_factor(const EffectInputs&, const double* x) const override {
    constexpr double kRefAmbientC = 20.0, kRunningRiseK = 20.0;
    const double rise = cold_start_ ? x[0] : kRunningRiseK;
    const double dt = std::max(ambient_c_ + rise - kRefAmbientC - kRunningRiseK, -0.9 * c2_);
    return std::exp(-c_ * c2_ * dt / (c2_ + dt));
  }

 private:
  double c_, c2_, ambient_c_;
  bool cold_start_;
};

// Truth air: density at the trip's ambient and barometric pressure, rho = p / (R T), against the vehicle's at 20 degC
// and 1013 hPa; the extra (or missing) aero force 0.5 (rho - rho_20) CdA v^2.
class AirDensityTruth final : public Effect {
 public:
  AirDensityTruth(double rho_cda_20, double ambient_c, double pressure_ratio)
      : k_(0.5 * rho_cda_20 * (pressure_ratio * 293.15 / (ambient_c + units::kKelvinOffset) - 1.0)) {}
  std::string id() const override { return "truth_air_density"; }
  double extra_resistance_n(const EffectInputs& in, const double*) const override {
    const double v = std::max(in.speed_mps, 0.0);
    return k_ * v * v;
  }

 private:
  double k_;
};

// Truth auxiliary load: an A/C compressor cycling on and off (period 240-360 s, 40 % duty, random phase) plus a
// blower at a quarter of the mean, not the catalogue's constant load. `mean_w` is the time-averaged power.
class CompressorTruth final : public Effect {
 public:
  CompressorTruth(double mean_w, double period_s, double phase_s)
      : blower_w_(0.25 * mean_w), on_w_(0.75 * mean_w / 0.4), period_s_(period_s), phase_s_(phase_s) {}
  std::string id() const override { return "truth_compressor"; }
  double extra_electric_power_w(const EffectInputs& in, const double*) const override {
    const double u = std::fmod(in.time_s + phase_s_, period_s_) / period_s_;
    return blower_w_ + (u < 0.4 ? on_w_ : 0.0);
  }

 private:
  double blower_w_, on_w_, period_s_, phase_s_;
};

// Truth wind: a mean headwind with gusts (Ornstein-Uhlenbeck, sd 1.5 m/s, correlation time 15 s) sampled on a 1 s
// grid, at a road heading that turns slowly (the headwind component is u cos(psi)).
class GustyWindTruth final : public Effect {
 public:
  GustyWindTruth(double mean_mps, double rho_cda, double duration_s, std::mt19937& rng) : k_(0.5 * rho_cda) {
    std::normal_distribution<double> n(0.0, 1.0);
    const double tau = 15.0, sd = 1.5, a = std::exp(-1.0 / tau);
    const double heading_period_s = 1500.0 + 1000.0 * std::uniform_real_distribution<double>(0.0, 1.0)(rng);
    double gust = 0.0;
    for (int i = 0; i <= static_cast<int>(duration_s) + 2; ++i) {
      gust = a * gust + sd * std::sqrt(1.0 - a * a) * n(rng);
      const double heading = 0.5 * std::sin(kTwoPi * i / heading_period_s);  // +-0.5 rad of road bends
      u_.push_back((mean_mps + gust) * std::cos(heading));
    }
  }
  std::string id() const override { return "truth_gusty_wind"; }
  double extra_resistance_n(const EffectInputs& in, const double*) const override {
    const double v = std::max(in.speed_mps, 0.0);
    if (v <= 0.0) return 0.0;
    const auto i = static_cast<std::size_t>(std::clamp(in.time_s, 0.0, static_cast<double>(u_.size() - 1)));
    const double rel = v + u_[i];
    return k_ * (rel * std::abs(rel) - v * v);
  }

 private:
  double k_;
  std::vector<double> u_;
};

// Truth payload: `extra_kg` aboard until the standstill nearest mid-trip, where 60 % of it gets out. Its rolling
// share follows the tyres' load law RR ~ Fz^0.9 (rolling resistance grows less than linearly with load).
class PayloadTruth final : public Effect {
 public:
  PayloadTruth(double extra_kg, double mass_kg, double drop_time_s) : dm_(extra_kg), m_(mass_kg), drop_s_(drop_time_s) {}
  std::string id() const override { return "truth_payload"; }
  double extra_resistance_n(const EffectInputs& in, const double*) const override {
    const double dm = in.time_s < drop_s_ ? dm_ : 0.4 * dm_;
    const double rolling = in.base_rolling_force_n * (std::pow(1.0 + dm / m_, 0.9) - 1.0);
    return dm * (in.accel_mps2 + kG * std::sin(std::atan(in.grade))) + rolling;
  }

 private:
  double dm_, m_, drop_s_;
};

// Truth rotating parts: wheels (60 %) act at the road; the motor rotor (40 %) is spun through the reduction, so its
// kinetic energy passes the gear losses both ways (1/eta accelerating, eta braking).
class RotatingPartsTruth final : public Effect {
 public:
  RotatingPartsTruth(double equivalent_kg, double gear_eff) : wheels_(0.6 * equivalent_kg), rotor_(0.4 * equivalent_kg), eta_(gear_eff) {}
  std::string id() const override { return "truth_rotating_parts"; }
  double extra_resistance_n(const EffectInputs& in, const double*) const override {
    const double a = in.accel_mps2;
    return wheels_ * a + rotor_ * a * (a > 0.0 ? 1.0 / eta_ : eta_);
  }

 private:
  double wheels_, rotor_, eta_;
};

// Truth tyre slip: a Pacejka-like magic formula per tyre, F = D sin(C atan(B s)) (C = 1.65, D = mu Fz, mu = 1),
// saturating, inverted for the slip s at each force; traction on the two driven tyres, braking on all four.
// `compliance_per_kn` is the car's initial slip per kN on the driven axle (the catalogue's slope at F -> 0).
class MagicFormulaSlipTruth final : public Effect {
 public:
  MagicFormulaSlipTruth(double compliance_per_kn, double axle_load_n, double total_load_n)
      : cx_per_tyre_n_(1000.0 / (2.0 * compliance_per_kn)), fz_driven_(axle_load_n / 2.0), fz_all_(total_load_n / 4.0) {}
  std::string id() const override { return "truth_magic_formula_slip"; }
  double wheel_loss_w(const EffectInputs& in, const double*) const override {
    const double f = in.wheel_force_demand_n, v = std::max(in.speed_mps, 0.0);
    if (f == 0.0 || v <= 0.0) return 0.0;
    const int tyres = f > 0.0 ? 2 : 4;
    const double fz = f > 0.0 ? fz_driven_ : fz_all_;
    const double s = slip(std::abs(f) / tyres, fz);
    return std::abs(f) * s * v;
  }

 private:
  double slip(double fx, double fz) const {
    constexpr double c = 1.65;
    const double d = fz, b = cx_per_tyre_n_ / (c * d);
    const double s_peak = std::tan(kTwoPi / 4.0 / c) / b;  // C atan(B s) = pi/2
    if (fx >= d) return s_peak;
    double lo = 0.0, hi = s_peak;
    for (int k = 0; k < 40; ++k) {
      const double mid = 0.5 * (lo + hi);
      (d * std::sin(c * std::atan(b * mid)) < fx ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  }
  double cx_per_tyre_n_, fz_driven_, fz_all_;
};

// Truth cold engine, applied to the simulated fuel power after the run (its own code path, no Effect): two
// thermal nodes above ambient, coolant (engine block and water, 75 kJ/K) and oil (15 kJ/K). The fuel power's
// losses (fuel power minus positive traction power) heat the coolant (30 %) and the oil (8 %), the rest leaves with
// the exhaust; oil and coolant exchange 60 W/K; the coolant loses 15 W/K below the thermostat (80 K above
// ambient) and 600 W/K above it (radiator); the oil sump 5 W/K. Friction follows oil viscosity,
// ~ exp(b (T_ref - T_oil)) with b = 0.035 /K, so the fuel power is multiplied by
// 1 + k (exp(b (T_ref - T_oil)) - 1) / (exp(b T_ref) - 1) below T_ref = 80 K: exactly 1 + k cold, 1 warm.
// The extra fuel's losses heat the engine too (the step uses the multiplied fuel power).
std::vector<double> oil_coolant_fuel_power_w(const SimulationResult& r, double fuel_j_per_m3, double cold_excess) {
  constexpr double kCoolantJPerK = 75000.0, kOilJPerK = 15000.0, kToCoolant = 0.30, kToOil = 0.08;
  constexpr double kOilCoolantWPerK = 60.0, kCoolantWPerK = 15.0, kRadiatorWPerK = 600.0, kThermostatK = 80.0;
  constexpr double kSumpWPerK = 5.0, kViscosityPerK = 0.035, kRefK = 80.0;
  const double norm = std::exp(kViscosityPerK * kRefK) - 1.0;
  double oil_k = 0.0, coolant_k = 0.0;
  std::vector<double> p(r.trace.size());
  for (std::size_t i = 0; i < r.trace.size(); ++i) {
    const double rise = oil_k < kRefK ? (std::exp(kViscosityPerK * (kRefK - oil_k)) - 1.0) / norm : 0.0;
    p[i] = r.trace[i].segment_fuel_rate_m3_per_s * fuel_j_per_m3 * (1.0 + cold_excess * rise);
    if (i + 1 == r.trace.size()) break;
    const double dt = r.trace[i + 1].time_s - r.trace[i].time_s;
    const double loss_w = std::max(0.0, p[i] - std::max(0.0, r.trace[i].traction_power_w));
    const double exchange_w = kOilCoolantWPerK * (coolant_k - oil_k);
    const double cooling_w = coolant_k < kThermostatK ? kCoolantWPerK * coolant_k
                                                      : kCoolantWPerK * coolant_k + kRadiatorWPerK * (coolant_k - kThermostatK);
    coolant_k += dt * (kToCoolant * loss_w - exchange_w - cooling_w) / kCoolantJPerK;
    oil_k += dt * (kToOil * loss_w + exchange_w - kSumpWPerK * oil_k) / kOilJPerK;
  }
  return p;
}

// Truth battery, integrated from the simulated terminal power after the run (its own code path): open-circuit
// voltage falling with SOC (OCV = V_nom (0.92 + 0.16 SOC), a flat NMC-like curve), the vehicle file's resistance
// plus an extra R(SOC) = dR (1 + 2 (1 - SOC)^2) (resistance rises as the cells empty), the current from
// P = OCV I - R I^2, the loss I^2 R drawn from the cells with the terminal power. Returns SOC per sample.
std::vector<double> soc_with_resistance(const SimulationResult& r, const BatteryParams& b, double initial_soc, double extra_ohm) {
  std::vector<double> soc(r.trace.size());
  double x = initial_soc;
  for (std::size_t i = 0; i < r.trace.size(); ++i) {
    soc[i] = x;
    if (i + 1 == r.trace.size()) break;
    const double dt = r.trace[i + 1].time_s - r.trace[i].time_s;
    const double p = r.trace[i].segment_battery_power_w;
    const double ocv = b.open_circuit_voltage_v * (0.92 + 0.16 * std::clamp(x, 0.0, 1.0));
    const double ohm = b.internal_resistance_ohm + extra_ohm * (1.0 + 2.0 * std::pow(1.0 - std::clamp(x, 0.0, 1.0), 2));
    // Discharge root of R I^2 - OCV I + P = 0 (the smaller current); beyond the maximum power, the peak current.
    const double disc = std::max(0.0, ocv * ocv - 4.0 * ohm * p);
    const double i_a = ohm > 0.0 ? (ocv - std::sqrt(disc)) / (2.0 * ohm) : p / ocv;
    x -= dt * (p + i_a * i_a * ohm) / b.usable_capacity_j;
  }
  return soc;
}

DriveCycle steady_cruise(std::mt19937& rng) {
  // An hour at 90 km/h with a slow +-1 km/h drift, 60 s ramps at both ends: speed hardly varies.
  DriveCycle c;
  c.name = "steady";
  const double v0 = 25.0, phase = std::uniform_real_distribution<double>(0.0, kTwoPi)(rng);
  for (int t = 0; t <= 3720; ++t) {
    double v = v0 + units::kmh_to_mps(1.0) * std::sin(kTwoPi * t / 600.0 + phase);
    if (t < 60) v *= t / 60.0;
    if (t > 3660) v *= (3720 - t) / 60.0;
    c.time_s.push_back(t);
    c.speed_mps.push_back(std::max(0.0, v));
    c.grade.push_back(0.0);
  }
  return c;
}

// The time of the standstill nearest the middle of the trace (the middle itself when it never stops).
double middle_stop_s(const DriveCycle& c) {
  const double mid = 0.5 * (c.time_s.front() + c.time_s.back());
  double best = mid, dist = 1e300;
  for (std::size_t i = 0; i < c.time_s.size(); ++i)
    if (c.speed_mps[i] <= 0.0 && std::abs(c.time_s[i] - mid) < dist) dist = std::abs(c.time_s[i] - mid), best = c.time_s[i];
  return best;
}

}  // namespace

const std::vector<ConcealedTruthInfo>& concealed_truths() {
  static const std::vector<ConcealedTruthInfo> kTruths{
      {"tyre_two_node", "tyre_warmup", "1 (cold RRC excess)",
       "two-node (tread, carcass) heat network, convection ~ (1 + v/8)^0.8, exponential RRC law", {0.05, 0.1, 0.2, 0.3},
       SyntheticChannel::battery_power, false, +1},
      {"aux_compressor", "aux_load", "W (mean)", "A/C compressor cycling 40 % duty (period 240-360 s) plus blower", {150, 300, 600},
       SyntheticChannel::battery_power, false, +1},
      {"wind_gusty", "wind", "m/s (mean headwind)", "mean headwind + OU gusts (sd 1.5 m/s, 15 s) on a slowly turning road", {1.5, 3, 5}},
      {"payload_drop", "mass", "kg (before the drop)", "payload, 60 % leaves at the mid-trip stop; rolling share ~ load^0.9", {75, 150, 300},
       SyntheticChannel::battery_power, false, +1},
      {"rotating_parts", "rotational_inertia", "kg (equivalent)", "wheels 60 %, rotor 40 % through the reduction (gear loss both ways)",
       {40, 80, 160}, SyntheticChannel::battery_power, false, +1},
      {"magic_formula_slip", "tyre_slip", "1/kN (initial compliance)", "Pacejka sin(C atan(B s)) per tyre, saturating; braking on four tyres",
       {0.005, 0.01, 0.02}, SyntheticChannel::battery_power, false, +1},
      {"underinflated", "rr_speed", "bar (pressure change)", "tyre pressure lowered in the tyre model (level and speed curve change)", {-0.3, -0.6, -0.9}},
      {"regen_cap", "regen_limit", "W (regen power limit)", "the powertrain's own regen limit lowered from 20 kW", {12000, 8000, 4000}},
      {"hilly_climb", "road_grade", "1 (net grade)", "net climb plus unrecorded hills (1 % amplitude, 0.8-3 km wavelengths)", {0.002, 0.005, 0.01}},
      {"engine_oil_coolant", "engine_warmup", "1 (cold fuel excess)",
       "oil + coolant nodes heated by the fuel losses, thermostat, friction ~ exp(b (T_ref - T_oil)) (fuel channel)",
       {0.1, 0.2, 0.4}, SyntheticChannel::fuel_rate, false, +1},
      {"engine_cold_soak", "engine_warmup", "1 (cold fuel excess)",
       "cold start: oil and block nodes, friction ~ exp(b (T_ref - T_oil)), a 3-10 min warm-up; UDDS, 10 min engine-off "
       "soak (zero fuel), UDDS (fuel channel)",
       {0.2, 0.25, 0.3}, SyntheticChannel::fuel_rate, false, +1, false, "", "udds", 600.0},
      {"wind_steady_gps", "wind_heading", "m/s (steady wind, from a bearing drawn per seed)",
       "steady wind w cos(theta - psi(s)) on a winding route (three 1-4 km bends, +-70-100 deg), latitude and "
       "longitude recorded (2 m GPS noise)",
       {4.0}, SyntheticChannel::battery_power, false, 0, false, "", "", 0.0, true},
      {"battery_r_of_soc", "battery_resistance", "ohm (extra at full charge)",
       "extra cell resistance rising as SOC falls, OCV(SOC), loss I^2 R (SOC channel, 0.1 % quantum)",
       {0.05, 0.1, 0.2}, SyntheticChannel::soc, false, +1},
      {"ambient_compound", "ambient_rrc", "1/K (RRC change per K at 20 degC)",
       "tyre compound law ln RRC = -c C2 dT / (C2 + dT), C2 120-180 K, c +-10 % per car, preconditioned tyres, "
       "trips at -5..30 degC", {0.001, 0.002, 0.004, 0.008, 0.012}, SyntheticChannel::battery_power, true, +1},
      {"ambient_cold_start", "ambient_rrc", "1/K (RRC change per K at 20 degC)",
       "the same compound law on a tyre that starts each trip at ambient and warms (one-node heat balance)",
       {0.008}, SyntheticChannel::battery_power, true, +1},
      // What real roads, cars and loggers vary (issue 9), recorded through a real logger's artefacts.
      {"rolling_hills", "road_profile", "m (hill amplitude, elevation withheld)",
       "three hills along distance, wavelengths 0.5-3 km, amplitude ~ wavelength, peak grade <= 8 %; no elevation recorded",
       {10, 25, 40}, SyntheticChannel::battery_power, false, 0, true},
      {"ac_duty_cycle", "aux_load", "W (compressor on)",
       "A/C compressor on/off, duty 0.3-0.7 and period 2-6 min per trip, each cycle +-25 %, random phase",
       {500, 1000, 1500}, SyntheticChannel::battery_power, false, +1, true},
      {"cabin_load", "aux_load", "W (from the start)",
       "EV cabin conditioning: constant (half the seeds) or decaying to 30-50 % with a 5-15 min time constant",
       {1000, 2000, 3000}, SyntheticChannel::battery_power, false, +1, true},
      {"rising_rrc", "", "1 (RRC rise by the end)", "RRC x (1 + r (t / T)^p), p 0.7-1.5: a null for tyre warm-up",
       {0.1, 0.2, 0.3}, SyntheticChannel::battery_power, false, 0, true, "tyre_warmup"},
      // Issue 10's cabin conditioning: a heater that starts at its maximum and settles (after rising_rrc, so that the
      // rows before keep their seed blocks).
      {"winter_heater", "aux_load", "W (heater's maximum)",
       "EV winter heater: cabin air and interior nodes warmed from -10..+5 degC to 21 degC by a saturated "
       "proportional thermostat, full power then falling over 10-30 min to 25-50 % of it, blower 100-200 W",
       {1000, 2000, 3000}, SyntheticChannel::battery_power, false, +1, true},
      // The same cold-start test's engine started hot (a pooled hot test): a null for engine_warmup, whose start the
      // diagnosis infers from the first minutes.
      {"engine_hot_soak", "", "1 (cold fuel excess, engine started hot)",
       "engine_cold_soak's engine, both nodes at running temperature at the start; UDDS, 10 min soak, UDDS (fuel "
       "channel)",
       {0.25}, SyntheticChannel::fuel_rate, false, 0, false, "engine_warmup", "udds", 600.0},
      // Appended, so that every row above keeps its seed block.
      {"wind_tail", "wind", "m/s (mean tailwind)",
       "mean tailwind + OU gusts (sd 1.5 m/s, 15 s) on a slowly turning road: pushes the road load below the tyres' "
       "loss like a descent does, so road_profile must not take it", {3, 5}},
      {"wind_gusty_gps", "wind_heading", "m/s (mean wind, from a bearing drawn per seed)",
       "the steady GPS wind with along-wind Ornstein-Uhlenbeck gusts (sd 1.5 m/s, 15 s) about its mean, on the same "
       "winding routes",
       {2.0, 4.0, 6.0}, SyntheticChannel::battery_power, false, 0, false, "", "", 0.0, true},
      // Issue 10's HVAC law of the ambient, across trips (appended: multi-trip rows have their own seed blocks).
      {"hvac_cabin", "hvac_ambient", "W/K (cabin heat loss UA)",
       "EV heater (PTC, COP 1) below the driver's 17-19 degC and A/C (COP 2.5-3.5 at 25 degC, falling 0.05 per K, sun "
       "100-400 W) above 23-25 degC, blower 100-200 W while either runs; steady within a trip; trips at -5..35 degC",
       {10, 20, 40}, SyntheticChannel::battery_power, true, +1, false, "", "", 0.0, false},
  };
  return kTruths;
}

const ConcealedTruthInfo& concealed_truth(const std::string& truth) {
  for (const auto& t : concealed_truths())
    if (t.truth == truth) return t;
  throw InputError("concealed truth '" + truth + "'", "is not one of the generator's truths");
}

Recording generate_case(const Vehicle& vehicle, const SyntheticCase& o) {
  std::mt19937 rng(o.seed);
  std::mt19937 truth_rng(o.seed * 7919u + 13u);  // the truths' own randomness, apart from the artefacts' stream
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  DriveCycle c;
  if (o.trace) {
    c = *o.trace;
    c.grade.assign(c.time_s.size(), 0.0);
  } else if (o.cycle == "steady") {
    c = steady_cruise(truth_rng);
  } else {
    const DriveCycle one = load_cycle(o.cycle);
    c.name = o.cycle + " x" + std::to_string(o.repeats);
    for (int k = 0; k < o.repeats; ++k) {
      if (k > 0 && o.soak_s > 0.0) {
        // The engine is switched off from the last sample of the run before to the soak's last sample.
        c.engine_off.resize(c.time_s.size(), false);
        c.engine_off.back() = true;
        for (double t = 1.0; t <= o.soak_s; t += 1.0) {
          c.time_s.push_back(c.time_s.back() + 1.0);
          c.speed_mps.push_back(0.0);
          c.grade.push_back(0.0);
          c.engine_off.push_back(true);
        }
        c.engine_off.back() = false;  // the soak's last sample starts the next run's first segment: restarted
      }
      const double t0 = c.time_s.empty() ? 0.0 : c.time_s.back() + 1.0;
      for (std::size_t i = 0; i < one.time_s.size(); ++i) {
        c.time_s.push_back(t0 + one.time_s[i] - one.time_s.front());
        c.speed_mps.push_back(one.speed_mps[i]);
        c.grade.push_back(0.0);
        if (!c.engine_off.empty()) c.engine_off.push_back(false);
      }
    }
    if (o.soak_s > 0.0) c.name += " with " + std::to_string(static_cast<int>(o.soak_s)) + " s soaks";
  }
  Vehicle truth_vehicle = vehicle;
  DriveCycle truth_cycle = c;
  std::vector<std::shared_ptr<const Effect>> truths;
  const double level_draw = 1.0 + o.rrc_level_jitter * unit(rng);  // drawn always: the artefacts' stream stays put
  const double level = o.rrc_level.value_or(level_draw);
  truths.push_back(std::make_shared<RrcLevelTruth>(level));
  const double rho_cda = vehicle.body.air_density_kg_per_m3 * vehicle.body.drag_coefficient * vehicle.body.frontal_area_m2;
  if (o.ambient_temp_c) {
    // The day's air: density at the trip's ambient, and a barometric pressure of 1013 hPa +-1.5 % (weather), which
    // the recording does not carry. Its own stream, so the other truths' draws stay put.
    std::mt19937 air_rng(o.seed * 15485863u + 11u);
    const double pressure_ratio = 1.0 + 0.015 * std::uniform_real_distribution<double>(-1.0, 1.0)(air_rng);
    const double road_rho_cda = vehicle.coastdown ? 2.0 * vehicle.coastdown->c_n_s2_per_m2 : rho_cda;
    truths.push_back(std::make_shared<AirDensityTruth>(road_rho_cda, *o.ambient_temp_c, pressure_ratio));
  }
  const double weight_n = vehicle.body.test_mass_kg * kG;
  double engine_cold_excess = 0.0, battery_extra_ohm = 0.0;  // post-run truths, applied to the channel below
  std::optional<EngineThermalTruth> engine_soak;
  std::optional<WindingRoute> route;
  if (o.gps) {
    std::mt19937 route_rng(o.seed * 2246822519u + 29u);  // its own stream: the other truths' draws stay put
    route = winding_route(route_rng);
  }
  for (const auto& e : o.effects) {
    const std::string& t = concealed_truth(e.truth).truth;
    if (t == "engine_oil_coolant") {
      if (o.channel != SyntheticChannel::fuel_rate) throw InputError("concealed truth 'engine_oil_coolant'", "needs the fuel channel");
      engine_cold_excess = e.size;
    } else if (t == "engine_cold_soak" || t == "engine_hot_soak") {
      if (o.channel != SyntheticChannel::fuel_rate) throw InputError("concealed truth '" + t + "'", "needs the fuel channel");
      engine_soak = cold_start_engine(e.size, truth_rng);
      engine_soak->hot_start = t == "engine_hot_soak";
    } else if (t == "wind_steady_gps") {
      if (!route) throw InputError("concealed truth 'wind_steady_gps'", "needs a route with GPS (SyntheticCase::gps)");
      const double from = o.wind_from_deg.value_or(360.0 * std::uniform_real_distribution<double>(0.0, 1.0)(truth_rng));
      truths.push_back(steady_wind_truth(e.size, from, *route, rho_cda));
    } else if (t == "wind_gusty_gps") {
      if (!route) throw InputError("concealed truth 'wind_gusty_gps'", "needs a route with GPS (SyntheticCase::gps)");
      const double from = o.wind_from_deg.value_or(360.0 * std::uniform_real_distribution<double>(0.0, 1.0)(truth_rng));
      truths.push_back(gusty_wind_truth(e.size, from, *route, rho_cda, c.duration_s(), truth_rng));
    } else if (t == "battery_r_of_soc") {
      if (o.channel != SyntheticChannel::soc) throw InputError("concealed truth 'battery_r_of_soc'", "needs the SOC channel");
      battery_extra_ohm = e.size;
    } else if (t == "ambient_compound" || t == "ambient_cold_start") {
      if (!o.ambient_temp_c) throw InputError("concealed truth '" + t + "'", "needs the trip's ambient temperature");
      const double c_per_k = e.size * (1.0 + 0.1 * unit(truth_rng));
      const double c2_k = 150.0 + 30.0 * unit(truth_rng);
      truths.push_back(std::make_shared<AmbientCompoundTruth>(c_per_k, c2_k, *o.ambient_temp_c, t == "ambient_cold_start"));
    } else if (t == "hvac_cabin") {
      if (!o.ambient_temp_c) throw InputError("concealed truth 'hvac_cabin'", "needs the trip's ambient temperature");
      if (o.channel == SyntheticChannel::fuel_rate) throw InputError("concealed truth 'hvac_cabin'", "needs an electric channel");
      truths.push_back(hvac_cabin_truth(cabin_climate(e.size, truth_rng), *o.ambient_temp_c));
    } else if (t == "tyre_two_node") {
      truths.push_back(std::make_shared<TwoNodeTyreTruth>(e.size, o.time_reversed, c.duration_s()));
    } else if (t == "aux_compressor") {
      const double period = 300.0 + 60.0 * unit(truth_rng);
      truths.push_back(std::make_shared<CompressorTruth>(e.size, period, period * 0.5 * (1.0 + unit(truth_rng))));
    } else if (t == "wind_gusty") {
      truths.push_back(std::make_shared<GustyWindTruth>(e.size, rho_cda, c.duration_s(), truth_rng));
    } else if (t == "wind_tail") {
      truths.push_back(std::make_shared<GustyWindTruth>(-e.size, rho_cda, c.duration_s(), truth_rng));
    } else if (t == "payload_drop") {
      truths.push_back(std::make_shared<PayloadTruth>(e.size, vehicle.body.test_mass_kg, middle_stop_s(c)));
    } else if (t == "rotating_parts") {
      double eta = 0.95;
      if (const auto* ep = std::get_if<ElectricPowertrainParams>(&vehicle.powertrain)) eta = ep->reduction.efficiency;
      truths.push_back(std::make_shared<RotatingPartsTruth>(e.size, eta));
    } else if (t == "magic_formula_slip") {
      const double driven = vehicle.body.driven_axle == DrivenAxle::front ? vehicle.body.front_axle_load_fraction
                                                                           : 1.0 - vehicle.body.front_axle_load_fraction;
      truths.push_back(std::make_shared<MagicFormulaSlipTruth>(e.size, driven * weight_n, weight_n));
    } else if (t == "underinflated") {
      if (!truth_vehicle.front_tyre) throw InputError("concealed truth 'underinflated'", "needs a vehicle with tyres");
      truth_vehicle.front_tyre->state.pressure_pa += e.size * 1e5;
      truth_vehicle.rear_tyre->state.pressure_pa += e.size * 1e5;
    } else if (t == "regen_cap") {
      auto* ep = std::get_if<ElectricPowertrainParams>(&truth_vehicle.powertrain);
      if (!ep) throw InputError("concealed truth 'regen_cap'", "needs an electric vehicle");
      ep->regen.max_power_w = std::min(ep->regen.max_power_w, e.size);
    } else if (t == "rolling_hills") {
      const RollingHills hills = rolling_hills(e.size, truth_rng);
      double s = 0.0;
      for (std::size_t i = 0; i + 1 < truth_cycle.time_s.size(); ++i) {
        const double ds = 0.5 * (c.speed_mps[i] + c.speed_mps[i + 1]) * (c.time_s[i + 1] - c.time_s[i]);
        truth_cycle.grade[i] += hills.grade(s + 0.5 * ds);  // the segment's grade at its middle
        s += ds;
      }
    } else if (t == "ac_duty_cycle") {
      truths.push_back(duty_cycled_ac_truth(compressor_cycles(e.size, c.duration_s(), truth_rng)));
    } else if (t == "cabin_load") {
      std::uniform_real_distribution<double> u01(0.0, 1.0);
      const bool decaying = u01(truth_rng) < 0.5;
      const double decay_s = 300.0 + 600.0 * u01(truth_rng), floor = 0.3 + 0.2 * u01(truth_rng);
      truths.push_back(cabin_load_truth(e.size, decaying ? decay_s : 0.0, floor));
    } else if (t == "winter_heater") {
      truths.push_back(winter_heater_truth(winter_cabin(e.size, truth_rng)));
    } else if (t == "rising_rrc") {
      const double power = 0.7 + 0.8 * std::uniform_real_distribution<double>(0.0, 1.0)(truth_rng);
      truths.push_back(rising_rrc_truth(e.size, c.duration_s(), power));
    } else if (t == "hilly_climb") {
      // Net grade plus three zero-mean hill components along the distance (random wavelengths and phases).
      double amp[3], len[3], ph[3];
      for (int k = 0; k < 3; ++k) {
        amp[k] = 0.01 / 3.0;
        len[k] = 1900.0 + 1100.0 * unit(truth_rng);
        ph[k] = kTwoPi * 0.5 * (1.0 + unit(truth_rng));
      }
      double s = 0.0;
      for (std::size_t i = 0; i < truth_cycle.time_s.size(); ++i) {
        double g = e.size;
        for (int k = 0; k < 3; ++k) g += amp[k] * std::sin(kTwoPi * s / len[k] + ph[k]);
        truth_cycle.grade[i] = g;
        if (i + 1 < truth_cycle.time_s.size())
          s += 0.5 * (c.speed_mps[i] + c.speed_mps[i + 1]) * (c.time_s[i + 1] - c.time_s[i]);
      }
    }
  }
  VehicleModel model = VehicleModel::assemble(truth_vehicle);
  for (auto& tr : truths) model.effects.push_back(tr);
  SimulationOptions so;
  so.record_trace = true;
  const SimulationResult r = simulate_replay(model, truth_cycle, so);
  const double scale_draw = 1.0 + o.scale_jitter * unit(rng);
  const double scale = o.channel_scale.value_or(scale_draw);
  Recording rec;
  rec.source = "synthetic " + c.name + " seed " + std::to_string(o.seed);
  const std::size_t n = r.trace.size();  // one point per segment start; the last sample is dropped
  double lag_s = std::max(0.0, o.lag_s);
  if (o.lag_max_s > lag_s) {
    std::mt19937 lag_rng(o.seed * 2654435761u + 17u);  // its own stream: the noise draws stay put
    lag_s = std::uniform_real_distribution<double>(lag_s, o.lag_max_s)(lag_rng);
  }
  rec.time_s.assign(c.time_s.begin(), c.time_s.begin() + static_cast<long>(n));
  rec.speed_mps.assign(c.speed_mps.begin(), c.speed_mps.begin() + static_cast<long>(n));
  if (o.ambient_temp_c) {
    // The car's ambient sensor: noise and a 0.5 K quantum, on its own stream (the channel's artefacts stay put).
    std::mt19937 sensor_rng(o.seed * 104729u + 7u);
    std::normal_distribution<double> sensor(0.0, 0.3);
    std::vector<double> t(n);
    for (auto& x : t) x = 0.5 * std::round((*o.ambient_temp_c + units::kKelvinOffset + sensor(sensor_rng)) / 0.5);
    rec.ambient_temp_k = t;
  }
  if (route) {
    // GPS at the trace's distances (the truth's replay follows the trace), with 2 m of noise per axis.
    std::vector<double> dist(n, 0.0);
    for (std::size_t i = 1; i < n; ++i) dist[i] = dist[i - 1] + 0.5 * (c.speed_mps[i - 1] + c.speed_mps[i]) * (c.time_s[i] - c.time_s[i - 1]);
    std::vector<double> lat, lon;
    route_gps(*route, dist, 48.1, 11.6, lat, lon);
    std::mt19937 gps_rng(o.seed * 40503u + 5u);
    std::normal_distribution<double> jitter_m(0.0, 2.0);
    const double m_per_deg = units::kEarthRadius_m * kTwoPi / 360.0;
    for (std::size_t i = 0; i < n; ++i) {
      lat[i] += jitter_m(gps_rng) / m_per_deg;
      lon[i] += jitter_m(gps_rng) / (m_per_deg * std::cos(48.1 * kTwoPi / 360.0));
    }
    rec.latitude_deg = lat;
    rec.longitude_deg = lon;
  }
  // no grade column in any channel: the diagnosis sees a flat road
  if (o.channel == SyntheticChannel::soc) {
    const auto* ep = std::get_if<ElectricPowertrainParams>(&truth_vehicle.powertrain);
    if (!ep) throw InputError("synthetic SOC channel", "needs an electric vehicle");
    // The scale error is the BMS's capacity estimate (the SOC drop is scaled); SOC is a state, so no lag.
    const std::vector<double> soc = soc_with_resistance(r, ep->battery, ep->battery.initial_soc, battery_extra_ohm);
    std::vector<double> q(n);
    for (std::size_t i = 0; i < n; ++i) {
      const double x = soc.front() - scale * (soc.front() - soc[i]);
      q[i] = o.soc_quantum > 0.0 ? o.soc_quantum * std::round(x / o.soc_quantum) : x;
    }
    rec.soc_fraction = q;
    return rec;
  }
  std::vector<double> truth_w(n);
  if (o.channel == SyntheticChannel::fuel_rate) {
    const FuelParams* fuel = truth_vehicle.fuel();
    if (!fuel) throw InputError("synthetic fuel channel", "needs a combustion vehicle");
    const double j_per_m3 = fuel->energy_j_per_m3();
    if (engine_soak) {
      std::vector<double> fuel_w(n), traction_w(n);
      for (std::size_t i = 0; i < n; ++i) {
        fuel_w[i] = r.trace[i].segment_fuel_rate_m3_per_s * j_per_m3;
        traction_w[i] = r.trace[i].traction_power_w;
      }
      truth_w = delayed(rec.time_s, engine_thermal_fuel_power_w(rec.time_s, fuel_w, traction_w, c.engine_off, *engine_soak), lag_s);
    } else {
      truth_w = delayed(rec.time_s, oil_coolant_fuel_power_w(r, j_per_m3, engine_cold_excess), lag_s);
    }
    std::normal_distribution<double> noise(0.0, o.fuel_noise_w);
    std::vector<double> f(n);
    for (std::size_t i = 0; i < n; ++i) {
      // Under fuel cut the injectors are shut and the ECU reports exactly zero; otherwise the reading is noisy but
      // never negative.
      const double w = truth_w[i];
      const double e = noise(rng);
      const double m3ps = w > 0.0 ? std::max(0.0, (w * scale + e) / j_per_m3) : 0.0;
      f[i] = o.fuel_quantum_m3ps > 0.0 ? o.fuel_quantum_m3ps * std::round(m3ps / o.fuel_quantum_m3ps) : m3ps;
    }
    rec.fuel_rate_m3ps = f;
    return rec;
  }
  for (std::size_t i = 0; i < n; ++i) truth_w[i] = r.trace[i].segment_battery_power_w;
  truth_w = delayed(rec.time_s, truth_w, lag_s);
  std::normal_distribution<double> noise(0.0, o.noise_w);
  std::vector<double> p(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double truth = truth_w[i] * scale + noise(rng);
    p[i] = o.quantum_w > 0.0 ? o.quantum_w * std::round(truth / o.quantum_w) : truth;
  }
  rec.battery_power_w = p;
  return rec;
}

SyntheticCase real_logger(SyntheticCase c) {
  c.lag_s = 0.3;
  c.lag_max_s = 1.7;
  c.scale_jitter = 0.03;
  return c;
}

std::vector<Recording> generate_trips(const Vehicle& vehicle, const MultiTripCase& m) {
  if (m.cycles.empty()) throw InputError("multi-trip case", "needs at least one trip");
  if (!(m.ambient_max_c >= m.ambient_min_c)) throw InputError("multi-trip case", "ambient_max_c is below ambient_min_c");
  std::mt19937 rng(m.seed * 6151u + 3u);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), u01(0.0, 1.0);
  const double level = 1.0 + m.artefacts.rrc_level_jitter * unit(rng);
  const double scale = 1.0 + m.artefacts.scale_jitter * unit(rng);
  const std::size_t k = m.cycles.size();
  std::vector<std::size_t> slice(k);
  for (std::size_t i = 0; i < k; ++i) slice[i] = i;
  std::shuffle(slice.begin(), slice.end(), rng);
  std::vector<Recording> out;
  for (std::size_t i = 0; i < k; ++i) {
    SyntheticCase s = m.artefacts;
    s.cycle = m.cycles[i];
    s.repeats = 1;
    s.trace.reset();
    s.effects = m.effects;
    s.ambient_temp_c = m.ambient_min_c + (m.ambient_max_c - m.ambient_min_c) * (static_cast<double>(slice[i]) + u01(rng)) / static_cast<double>(k);
    s.rrc_level = level * (1.0 + m.trip_rrc_scatter * unit(rng));
    s.channel_scale = scale;
    s.seed = m.seed * 16u + static_cast<unsigned>(i);
    out.push_back(generate_case(vehicle, s));
  }
  return out;
}

Recording generate_recording(const Vehicle& vehicle, const SyntheticOptions& opt) {
  SyntheticCase c;
  c.cycle = opt.cycle;
  c.repeats = opt.repeats;
  c.effects.push_back({"tyre_two_node", opt.tyre_cold_excess});
  c.rrc_level_jitter = opt.rrc_level_jitter;
  c.scale_jitter = opt.scale_jitter;
  c.noise_w = opt.noise_w;
  c.quantum_w = opt.quantum_w;
  c.lag_s = opt.lag_s;
  c.time_reversed = opt.time_reversed;
  c.seed = opt.seed;
  return generate_case(vehicle, c);
}

}  // namespace rollsim
