// The effect modules: each a small physical model with typed parameters in SI, and the registry of them.
#include "rollsim/effects/catalogue.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "rollsim/common/error.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/effects/road_profile.hpp"

namespace rollsim {
namespace {

constexpr double kG = units::kStandardGravity_mps2;
constexpr double kRefSpeed_mps = units::kmh_to_mps(100.0);  // rr_speed's coefficient is the RRC change at 100 km/h

// Typed parameters of each module; their names, units, neutral values and bounds are declared once, in the
// module's registry row below, beside the member each one fills.
struct TyreWarmupParams {
  double cold_rrc_excess, heat_capacity_j_per_k, convection_w_per_k, convection_growth_s_per_m, warm_excess_k,
      initial_excess_k;
};
struct AuxLoadParams {
  double power_w, duty_cycle, period_s, decay_s, decaying_share;
};
struct WindParams {
  double headwind_mps;
};
struct MassParams {
  double extra_mass_kg;
};
struct RrSpeedParams {
  double rrc_change_at_100kmh;
};
struct AmbientRrcParams {
  double rrc_change_per_k, ambient_temp_c, reference_temp_c;
};
struct RotationalInertiaParams {
  double extra_rotating_mass_kg;
};
struct BatteryResistanceParams {
  double extra_resistance_ohm, pack_voltage_v;
};
struct TyreSlipParams {
  double slip_per_kn;
};
struct RegenLimitParams {
  double friction_share_above_limit, regen_limit_w;
};
struct EngineWarmupParams {
  double cold_fuel_excess, heat_capacity_j_per_k, idle_heat_w, heat_per_wheel_work, heat_loss_w_per_k, warm_excess_k,
      soak_cooling_s, initial_excess_k;
};
struct WindHeadingParams {
  double wind_speed_mps, wind_from_deg;
};
struct HvacAmbientParams {
  double heat_w_per_k, cool_w_per_k, heat_below_c, cool_above_c, ambient_temp_c;
};
struct RoadGradeParams {
  double grade_offset, profile_wavelength_m;
};

// Tyre warm-up, lumped over the four tyres. Hidden state: tyre temperature above ambient, T [K].
//   C dT/dt = eta_heat * P_rr - h(v) T,  h(v) = h0 (1 + g v)  (forced convection grows with speed)
//   RRC factor = 1 + excess * max(0, 1 - T / T_warm)          (linear in temperature below the warm point)
// P_rr is the rolling-resistance power: hysteresis loss is what heats the tyre. The cold excess (+10-30 %)
// and the tens-of-minutes time constant C/h are of the literature (see docs/diagnose.md).
class TyreWarmup final : public Effect {
 public:
  TyreWarmup(const TyreWarmupParams& p, const EffectContext&)
      : excess_(p.cold_rrc_excess), c_(p.heat_capacity_j_per_k), h0_(p.convection_w_per_k),
        g_(p.convection_growth_s_per_m), warm_(p.warm_excess_k), initial_(p.initial_excess_k) {}
  std::string id() const override { return "tyre_warmup"; }
  int num_states() const override { return 1; }
  void initial_states(double* x) const override { x[0] = initial_; }
  void state_derivatives(const EffectInputs& in, const double* x, double* xdot) const override {
    const double v = std::max(in.speed_mps, 0.0);
    const double p_rr = in.base_rolling_force_n * rolling_resistance_factor(in, x) * v;
    xdot[0] = (p_rr - h0_ * (1.0 + g_ * v) * x[0]) / c_;
  }
  double rolling_resistance_factor(const EffectInputs&, const double* x) const override {
    return 1.0 + excess_ * std::max(0.0, 1.0 - x[0] / warm_);
  }

 private:
  double excess_, c_, h0_, g_, warm_, initial_;
};

// Electrical consumer (HVAC, electronics) not in the vehicle file's aux power: constant, duty-cycled, or decaying.
// Duty-cycled (an A/C compressor or heater cycling on and off every few minutes): on for the first duty_cycle x
// period_s of each period, at power_w / duty_cycle, so power_w is always the mean; period 0 is a constant load.
// Decaying (a winter heater bringing a cold cabin to temperature, then holding it): a share of power_w falls with
// time constant decay_s from the start of the trace, P(t) = power_w (1 - share + share exp(-t / decay_s)), so
// power_w is the power at the start (P0 + P1) and 1 - share its level once the cabin is warm; decay_s 0: no decay.
class AuxLoad final : public Effect {
 public:
  AuxLoad(const AuxLoadParams& p, const EffectContext&)
      : p_(p.power_w), duty_(p.duty_cycle), period_(p.period_s), decay_s_(p.decay_s), share_(p.decaying_share) {}
  std::string id() const override { return "aux_load"; }
  double extra_electric_power_w(const EffectInputs& in, const double*) const override {
    const double level = decay_s_ > 0.0 ? 1.0 - share_ + share_ * std::exp(-std::max(0.0, in.time_s) / decay_s_) : 1.0;
    if (period_ <= 0.0 || duty_ >= 1.0) return p_ * level;
    const double phase = std::fmod(std::max(0.0, in.time_s), period_) / period_;
    return phase < duty_ ? p_ * level / duty_ : 0.0;
  }

 private:
  double p_, duty_, period_, decay_s_, share_;
};

// Constant headwind u (negative: tailwind): the aero force is 0.5 rho CdA (v + u)^2 instead of 0.5 rho CdA v^2.
class Wind final : public Effect {
 public:
  Wind(const WindParams& p, const EffectContext& c) : u_(p.headwind_mps), k_(0.5 * c.rho_cda_kg_per_m) {}
  std::string id() const override { return "wind"; }
  double extra_resistance_n(const EffectInputs& in, const double*) const override {
    const double v = std::max(in.speed_mps, 0.0);
    if (v <= 0.0) return 0.0;  // standing still: the brakes hold the car
    const double rel = v + u_;
    return k_ * (rel * std::abs(rel) - v * v);
  }

 private:
  double u_, k_;
};

// A steady wind of speed w blowing from the bearing theta (clockwise from north, as a weather report gives it): the
// headwind on a car heading psi is u = w cos(theta - psi), so it turns with the road. Where the trace has no
// heading the effect is off (a steady wind is a headwind only relative to the heading; `wind` is the headwind).
class WindHeading final : public Effect {
 public:
  WindHeading(const WindHeadingParams& p, const EffectContext& c)
      : w_(p.wind_speed_mps), from_rad_(units::deg_to_rad(p.wind_from_deg)), k_(0.5 * c.rho_cda_kg_per_m) {}
  std::string id() const override { return "wind_heading"; }
  double extra_resistance_n(const EffectInputs& in, const double*) const override {
    const double v = std::max(in.speed_mps, 0.0);
    if (v <= 0.0 || !in.heading_known) return 0.0;
    const double rel = v + w_ * std::cos(from_rad_ - in.heading_rad);
    return k_ * (rel * std::abs(rel) - v * v);
  }

 private:
  double w_, from_rad_, k_;
};

// Mass (payload) error dm: inertia, grade and the rolling share, dm (a + g sin theta + g RRC).
class Mass final : public Effect {
 public:
  Mass(const MassParams& p, const EffectContext& c) : dm_(p.extra_mass_kg), m_(c.mass_kg) {}
  std::string id() const override { return "mass"; }
  double extra_resistance_n(const EffectInputs& in, const double*) const override {
    const double rolling_per_kg = m_ > 0.0 ? in.base_rolling_force_n / m_ : 0.0;
    return dm_ * (in.accel_mps2 + kG * std::sin(std::atan(in.grade)) + rolling_per_kg);
  }

 private:
  double dm_, m_;
};

// Speed dependence of rolling resistance the tyre model lacks (pressure, wrong tyre): factor 1 + k (v/v100)^2.
class RrSpeed final : public Effect {
 public:
  RrSpeed(const RrSpeedParams& p, const EffectContext&) : k_(p.rrc_change_at_100kmh) {}
  std::string id() const override { return "rr_speed"; }
  double rolling_resistance_factor(const EffectInputs& in, const double*) const override {
    const double r = std::max(in.speed_mps, 0.0) / kRefSpeed_mps;
    return std::max(0.0, 1.0 + k_ * r * r);
  }

 private:
  double k_;
};

// RRC against ambient temperature: factor 1 + c (T_ref - T_amb) (UN R117 / ISO 28580: c about 0.008 /K).
class AmbientRrc final : public Effect {
 public:
  AmbientRrc(const AmbientRrcParams& p, const EffectContext&)
      : c_(p.rrc_change_per_k), t_(p.ambient_temp_c), ref_(p.reference_temp_c) {}
  std::string id() const override { return "ambient_rrc"; }
  double rolling_resistance_factor(const EffectInputs&, const double*) const override {
    return std::max(0.0, 1.0 + c_ * (ref_ - t_));
  }

 private:
  double c_, t_, ref_;
};


// Rotating parts' equivalent mass the vehicle file lacks (wheels, rotor, driveline: J / r^2): a force dm_rot * a
// on acceleration only (no rolling or grade share, unlike a mass error), booked as other resistance. Its energy
// comes back in a deceleration only as far as regen recovers it, so friction braking makes it a net loss.
class RotationalInertia final : public Effect {
 public:
  RotationalInertia(const RotationalInertiaParams& p, const EffectContext&) : dm_(p.extra_rotating_mass_kg) {}
  std::string id() const override { return "rotational_inertia"; }
  double extra_resistance_n(const EffectInputs& in, const double*) const override { return dm_ * in.accel_mps2; }

 private:
  double dm_;
};

// Extra battery internal resistance dR (ageing, cold cells, contactors): loss dR I^2 with I = P_terminal / V_pack,
// in both directions (discharge and regen). It drains the cells, so only state of charge sees it, not the
// terminal power. V_pack is the vehicle's battery voltage unless given: a fixed 360 V read the Twizy's 0.04 ohm as
// 1.6 ohm, and a user who then set the 58 V the documentation asked for got 38 times the loss (session 24).
class BatteryResistance final : public Effect {
 public:
  BatteryResistance(const BatteryResistanceParams& p, const EffectContext& ctx)
      : dr_(p.extra_resistance_ohm), v_(p.pack_voltage_v > 0.0 ? p.pack_voltage_v : ctx.pack_voltage_v > 0.0 ? ctx.pack_voltage_v : 360.0) {}
  std::string id() const override { return "battery_resistance"; }
  double battery_loss_w(const EffectInputs&, double terminal_power_w, const double*) const override {
    const double i = terminal_power_w / v_;
    return dr_ * i * i;
  }

 private:
  double dr_, v_;
};

// Longitudinal tyre slip in the linear range: slip = F_x / C_x, loss = F_x * slip * v = F_x^2 v / C_x, in traction
// and in braking. The parameter is the compliance 1 / C_x of the car's tyres together, in slip per kN.
class TyreSlip final : public Effect {
 public:
  TyreSlip(const TyreSlipParams& p, const EffectContext&) : per_n_(p.slip_per_kn / 1000.0) {}
  std::string id() const override { return "tyre_slip"; }
  double wheel_loss_w(const EffectInputs& in, const double*) const override {
    const double f = in.wheel_force_demand_n, v = std::max(in.speed_mps, 0.0);
    return f * f * per_n_ * v;
  }

 private:
  double per_n_;
};

// A regen limit (brake blending) below the vehicle file's: a share of the braking power above P_lim goes to the
// friction brakes instead of the motor. Booked through the wheel-loss hook: braking, the loss lowers the hub speed
// the motor sees, so the regen power falls by exactly the loss and the energy balance stays closed (the loss is
// booked as wheel loss, not friction braking).
class RegenLimit final : public Effect {
 public:
  RegenLimit(const RegenLimitParams& p, const EffectContext&) : share_(p.friction_share_above_limit), lim_(p.regen_limit_w) {}
  std::string id() const override { return "regen_limit"; }
  double wheel_loss_w(const EffectInputs& in, const double*) const override {
    const double f = in.wheel_force_demand_n, v = std::max(in.speed_mps, 0.0);
    if (f >= 0.0) return 0.0;
    return share_ * std::max(0.0, -f * v - lim_);
  }

 private:
  double share_, lim_;
};

// Cold engine: hidden oil/block temperature above ambient T [K]; friction raises the fuel power by a factor
// 1 + k max(0, 1 - T / T_warm). Heat balance C dT/dt = Q_idle + q max(0, F v) - h T: the hooks carry no fuel power,
// so the fuel loss reaching the oil is taken as an idle part plus a share q of the wheel work (a Willans engine's
// loss grows with its work). Switched off (a soak), it makes no heat and cools towards ambient by Newton's law with
// its own time constant (the bonnet closed, no coolant flow: far slower than h / C running). It starts at
// initial_excess_k (0: cold at ambient), or warm on a trace that starts hot. Neutral on an electric car: there is no
// fuel power to scale.
class EngineWarmup final : public Effect {
 public:
  EngineWarmup(const EngineWarmupParams& p, const EffectContext&)
      : k_(p.cold_fuel_excess), c_(p.heat_capacity_j_per_k), idle_(p.idle_heat_w), q_(p.heat_per_wheel_work),
        h_(p.heat_loss_w_per_k), warm_(p.warm_excess_k), soak_s_(p.soak_cooling_s), initial_(p.initial_excess_k) {}
  std::string id() const override { return "engine_warmup"; }
  int num_states() const override { return 1; }
  void initial_states(double* x) const override { x[0] = initial_; }
  void hot_start_states(double* x) const override { x[0] = std::max(x[0], warm_); }
  void state_derivatives(const EffectInputs& in, const double* x, double* xdot) const override {
    if (in.engine_off) {
      xdot[0] = -x[0] / soak_s_;
      return;
    }
    const double work_w = std::max(0.0, in.wheel_force_demand_n * std::max(in.speed_mps, 0.0));
    xdot[0] = (idle_ + q_ * work_w - h_ * x[0]) / c_;
  }
  double fuel_power_factor(const EffectInputs&, const double* x) const override {
    return std::max(0.0, 1.0 + k_ * std::max(0.0, 1.0 - x[0] / warm_));
  }

 private:
  double k_, c_, idle_, q_, h_, warm_, soak_s_, initial_;
};

// Cabin conditioning as a law of the ambient (an electric car's heater and A/C): a constant electrical load
//   P = k_heat max(0, T_heat - T_amb) + k_cool max(0, T_amb - T_cool)
// with a dead band between T_heat and T_cool where only ventilation runs (defaults 18 and 24 degC, about the 21 degC
// at which EV fleet data show the least energy per km; sources in docs/diagnose.md). Within one trip the ambient
// is about constant, so the load is too; the law shows only across trips at different ambients.
class HvacAmbient final : public Effect {
 public:
  HvacAmbient(const HvacAmbientParams& p, const EffectContext&)
      : power_w_(p.heat_w_per_k * std::max(0.0, p.heat_below_c - p.ambient_temp_c) +
                 p.cool_w_per_k * std::max(0.0, p.ambient_temp_c - p.cool_above_c)) {
    if (p.cool_above_c < p.heat_below_c)
      throw InputError("effect 'hvac_ambient' parameter 'cool_above_c'",
                       format_value(p.cool_above_c) + " degC is not allowed: must be at least heat_below_c (" +
                           format_value(p.heat_below_c) + " degC), or heater and A/C would run at once");
  }
  std::string id() const override { return "hvac_ambient"; }
  double extra_electric_power_w(const EffectInputs&, const double*) const override { return power_w_; }

 private:
  double power_w_;
};

// Missing or wrong road grade: a grade offset theta(s) = g0 (constant, wavelength 0) or g0 cos(2 pi s / L) (an
// elevation profile error along the distance s); force m g sin(theta), booked as other resistance. On one flat
// trip a constant offset is the RRC level (both a constant force opposing motion); driving the route both ways
// separates them (grade changes sign, RRC does not).
class RoadGrade final : public Effect {
 public:
  RoadGrade(const RoadGradeParams& p, const EffectContext& c)
      : g0_(p.grade_offset), wavelength_(p.profile_wavelength_m), m_(c.mass_kg) {}
  std::string id() const override { return "road_grade"; }
  double extra_resistance_n(const EffectInputs& in, const double*) const override {
    if (std::max(in.speed_mps, 0.0) <= 0.0) return 0.0;  // standing still: the brakes hold the car
    constexpr double kTwoPi = 6.283185307179586;
    const double g = wavelength_ > 0.0 ? g0_ * std::cos(kTwoPi * in.distance_m / wavelength_) : g0_;
    return m_ * kG * std::sin(std::atan(g));
  }

 private:
  double g0_, wavelength_, m_;
};

// One parameter: the member it fills and its metadata.
template <class P>
struct Field {
  double P::*member;
  EffectParameterInfo info;
};

// A registry row: metadata, and a factory filling the typed parameters from a complete, checked set.
template <class E, class P>
EffectInfo row(EffectId id, std::string name, std::string description, std::string opposite, std::vector<Field<P>> fields) {
  EffectInfo e{id, std::move(name), std::move(description), {}, std::move(opposite), {}};
  for (const auto& f : fields) e.parameters.push_back(f.info);
  e.make = [fields](const EffectParameters& given, const EffectContext& c) -> std::shared_ptr<const Effect> {
    P p{};
    for (const auto& f : fields) p.*f.member = given.at(f.info.name);
    return std::make_shared<E>(p, c);
  };
  return e;
}

// Amplitude bounds carry the physical sign (a warm-up makes the start costlier, a load draws power, a payload adds
// mass); a fit that needs the other sign is described by `opposite`, never reported as this effect.
std::vector<EffectInfo> build_catalogue() {
  using I = EffectId;
  std::vector<EffectInfo> c;
  c.push_back(row<TyreWarmup, TyreWarmupParams>(
      I::tyre_warmup, "tyre_warmup",
      "tyre thermal state: RRC falls as rolling loss heats the tyres (heat balance with speed-dependent convection)",
      "rolling resistance rising over the trip (the opposite of a tyre warm-up)",
      {{&TyreWarmupParams::cold_rrc_excess, {"cold_rrc_excess", "1", 0.0, 0.2, 0.0, 1.0, true}},
       {&TyreWarmupParams::heat_capacity_j_per_k, {"heat_capacity_j_per_k", "J/K", 50000.0, 50000.0, 5000.0, 500000.0, false}},
       {&TyreWarmupParams::convection_w_per_k, {"convection_w_per_k", "W/K", 20.0, 20.0, 1.0, 500.0, false}},
       {&TyreWarmupParams::convection_growth_s_per_m, {"convection_growth_s_per_m", "s/m", 0.1, 0.1, 0.0, 1.0, false}},
       {&TyreWarmupParams::warm_excess_k, {"warm_excess_k", "K", 30.0, 30.0, 1.0, 100.0, false}},
       {&TyreWarmupParams::initial_excess_k, {"initial_excess_k", "K", 0.0, 0.0, 0.0, 100.0, false}}}));
  c.push_back(row<AuxLoad, AuxLoadParams>(
      I::aux_load, "aux_load",
      "extra electrical load (HVAC, electronics): constant, duty-cycled on and off with its mean power_w, or a share "
      "decaying from the start of the trip (a winter heater: P0 + P1 exp(-t / decay_s), power_w = P0 + P1)",
      "less constant power drawn than the vehicle file's auxiliaries",
      {{&AuxLoadParams::power_w, {"power_w", "W", 0.0, 400.0, 0.0, 8000.0, true}},
       {&AuxLoadParams::duty_cycle, {"duty_cycle", "1", 1.0, 1.0, 0.05, 1.0, false}},
       {&AuxLoadParams::period_s, {"period_s", "s", 0.0, 0.0, 0.0, 3600.0, false}},
       {&AuxLoadParams::decay_s, {"decay_s", "s", 0.0, 0.0, 0.0, 36000.0, false}},
       {&AuxLoadParams::decaying_share, {"decaying_share", "1", 1.0, 1.0, 0.0, 1.0, false}}}));
  c.push_back(row<Wind, WindParams>(I::wind, "wind", "constant headwind (negative: tailwind)", "",
                                    {{&WindParams::headwind_mps, {"headwind_mps", "m/s", 0.0, 3.0, -20.0, 20.0, true}}}));
  c.push_back(row<Mass, MassParams>(I::mass, "mass", "mass or payload missing from the file: inertia, grade and rolling share",
                                    "less mass than the vehicle file's test mass (inertia, grade and rolling share all lighter)",
                                    {{&MassParams::extra_mass_kg, {"extra_mass_kg", "kg", 0.0, 150.0, 0.0, 1000.0, true}}}));
  c.push_back(row<RrSpeed, RrSpeedParams>(
      I::rr_speed, "rr_speed", "speed-dependent rolling resistance: RRC x (1 + k (v / 100 km/h)^2)",
      "rolling resistance falling with speed against the tyre model's",
      {{&RrSpeedParams::rrc_change_at_100kmh, {"rrc_change_at_100kmh", "1", 0.0, 0.2, 0.0, 3.0, true}}}));
  c.push_back(row<AmbientRrc, AmbientRrcParams>(
      I::ambient_rrc, "ambient_rrc", "RRC against ambient temperature: RRC x (1 + c (T_ref - T_amb))",
      "RRC falling in the cold across the trips (against tyre physics)",
      {{&AmbientRrcParams::rrc_change_per_k, {"rrc_change_per_k", "1/K", 0.0, 0.008, 0.0, 0.05, true}},
       {&AmbientRrcParams::ambient_temp_c, {"ambient_temp_c", "degC", 20.0, 20.0, -40.0, 50.0, false}},
       {&AmbientRrcParams::reference_temp_c, {"reference_temp_c", "degC", 20.0, 20.0, -40.0, 50.0, false}}}));
  c.push_back(row<RotationalInertia, RotationalInertiaParams>(
      I::rotational_inertia, "rotational_inertia",
      "rotating parts' equivalent mass missing from the file: force dm_rot a, acceleration only",
      "less force on acceleration than the file's rotating masses imply",
      {{&RotationalInertiaParams::extra_rotating_mass_kg, {"extra_rotating_mass_kg", "kg", 0.0, 80.0, 0.0, 500.0, true}}}));
  c.push_back(row<BatteryResistance, BatteryResistanceParams>(
      I::battery_resistance, "battery_resistance",
      "extra battery internal resistance: loss dR (P / V)^2 inside the cells (SOC only)",
      "less loss in the cells than the model's internal resistance",
      {{&BatteryResistanceParams::extra_resistance_ohm, {"extra_resistance_ohm", "ohm", 0.0, 0.05, 0.0, 2.0, true}},
       {&BatteryResistanceParams::pack_voltage_v, {"pack_voltage_v", "V", 0.0, 0.0, 0.0, 1000.0, false}}}));
  c.push_back(row<TyreSlip, TyreSlipParams>(I::tyre_slip, "tyre_slip", "longitudinal tyre slip, linear range: loss F_x^2 v / C_x",
                                            "less loss in hard traction and braking than the model's",
                                            {{&TyreSlipParams::slip_per_kn, {"slip_per_kn", "1/kN", 0.0, 0.005, 0.0, 0.1, true}}}));
  c.push_back(row<RegenLimit, RegenLimitParams>(
      I::regen_limit, "regen_limit",
      "lower regen limit (brake blending): a share of braking power above the limit goes to friction",
      "more braking energy recovered than the file's regen limit allows",
      {{&RegenLimitParams::friction_share_above_limit, {"friction_share_above_limit", "1", 0.0, 1.0, 0.0, 1.0, true}},
       {&RegenLimitParams::regen_limit_w, {"regen_limit_w", "W", 10000.0, 10000.0, 0.0, 200000.0, false}}}));
  c.push_back(row<EngineWarmup, EngineWarmupParams>(
      I::engine_warmup, "engine_warmup",
      "cold engine: fuel power x (1 + k max(0, 1 - T_oil / T_warm)), oil heated by the engine's losses, cooling to "
      "ambient (time constant soak_cooling_s) while switched off",
      "fuel rate rising over the trip (the opposite of an engine warm-up)",
      {{&EngineWarmupParams::cold_fuel_excess, {"cold_fuel_excess", "1", 0.0, 0.2, 0.0, 2.0, true}},
       {&EngineWarmupParams::heat_capacity_j_per_k, {"heat_capacity_j_per_k", "J/K", 100000.0, 100000.0, 5000.0, 2000000.0, false}},
       {&EngineWarmupParams::idle_heat_w, {"idle_heat_w", "W", 2000.0, 2000.0, 0.0, 50000.0, false}},
       {&EngineWarmupParams::heat_per_wheel_work, {"heat_per_wheel_work", "1", 0.6, 0.6, 0.0, 5.0, false}},
       {&EngineWarmupParams::heat_loss_w_per_k, {"heat_loss_w_per_k", "W/K", 40.0, 40.0, 1.0, 2000.0, false}},
       {&EngineWarmupParams::warm_excess_k, {"warm_excess_k", "K", 60.0, 60.0, 1.0, 150.0, false}},
       {&EngineWarmupParams::soak_cooling_s, {"soak_cooling_s", "s", 3600.0, 3600.0, 60.0, 86400.0, false}},
       {&EngineWarmupParams::initial_excess_k, {"initial_excess_k", "K", 0.0, 0.0, 0.0, 150.0, false}}}));
  c.push_back(row<RoadGrade, RoadGradeParams>(
      I::road_grade, "road_grade",
      "missing grade: constant offset or a cosine elevation-profile error along distance, force m g sin(theta)", "",
      {{&RoadGradeParams::grade_offset, {"grade_offset", "1", 0.0, 0.005, -0.2, 0.2, true}},
       {&RoadGradeParams::profile_wavelength_m, {"profile_wavelength_m", "m", 0.0, 0.0, 0.0, 1e6, false}}}));
  c.push_back(row<RoadProfile, RoadProfileParams>(
      I::road_profile, "road_profile",
      "unrecorded road profile: an elevation along distance (linear between knots), force m g sin(theta(s)); the diagnosis "
      "infers its knots from the residual (a vehicle file's has none and is flat)",
      "",
      {{&RoadProfileParams::profile_scale, {"profile_scale", "1", 0.0, 1.0, 0.0, 3.0, true}},
       {&RoadProfileParams::knot_spacing_m, {"knot_spacing_m", "m", 100.0, 100.0, 10.0, 10000.0, false}}}));
  c.push_back(row<WindHeading, WindHeadingParams>(
      I::wind_heading, "wind_heading",
      "steady wind from a bearing: headwind w cos(theta - heading) on a route whose heading is recorded (latitude, "
      "longitude); a negative speed blows from the opposite bearing",
      "", {{&WindHeadingParams::wind_speed_mps, {"wind_speed_mps", "m/s", 0.0, 3.0, -30.0, 30.0, true}},
           {&WindHeadingParams::wind_from_deg, {"wind_from_deg", "deg", 0.0, 0.0, 0.0, 360.0, false}}}));
  c.push_back(row<HvacAmbient, HvacAmbientParams>(
      I::hvac_ambient, "hvac_ambient",
      "cabin conditioning by the ambient: an electrical load k_heat max(0, T_heat - T_amb) + k_cool max(0, T_amb - "
      "T_cool), constant within a trip (set ambient_temp_c per trip); found only across trips at different ambients",
      "less electrical load on the trips further from the dead band (against a heater's and an A/C's physics)",
      {{&HvacAmbientParams::heat_w_per_k, {"heat_w_per_k", "W/K", 0.0, 100.0, 0.0, 1000.0, true}},
       {&HvacAmbientParams::cool_w_per_k, {"cool_w_per_k", "W/K", 0.0, 50.0, 0.0, 1000.0, false}},
       {&HvacAmbientParams::heat_below_c, {"heat_below_c", "degC", 18.0, 18.0, -10.0, 30.0, false}},
       {&HvacAmbientParams::cool_above_c, {"cool_above_c", "degC", 24.0, 24.0, 10.0, 40.0, false}},
       {&HvacAmbientParams::ambient_temp_c, {"ambient_temp_c", "degC", 21.0, 21.0, -40.0, 50.0, false}}}));
  return c;
}

}  // namespace

const EffectParameterInfo& EffectInfo::amplitude() const {
  for (const auto& p : parameters)
    if (p.amplitude) return p;
  throw InputError("effect '" + name + "'", "has no amplitude parameter");
}

const std::vector<EffectInfo>& effect_catalogue() {
  static const std::vector<EffectInfo> kCatalogue = build_catalogue();
  return kCatalogue;
}

const std::vector<std::string>& effects_not_implemented() {
  // Every identifier the issue lists has a module; elevation inference from a recording (road_grade "inferred as
  // an elevation profile") belongs to the diagnosis, not to this module.
  static const std::vector<std::string> kMissing{};
  return kMissing;
}

const EffectInfo& effect_info(EffectId id) { return effect_catalogue().at(static_cast<std::size_t>(id)); }

const std::string& to_string(EffectId id) { return effect_info(id).name; }

const EffectInfo& effect_info(const std::string& name) {
  for (const auto& e : effect_catalogue())
    if (e.name == name) return e;
  for (const auto& m : effects_not_implemented())
    if (m == name) throw InputError("effect '" + name + "'", "is in the catalogue but not implemented yet");
  throw InputError("effect '" + name + "'", "is not a catalogue effect");
}

EffectSpec effect_spec(EffectId id, const EffectParameters& given) {
  const EffectInfo& info = effect_info(id);
  EffectParameters p;
  for (const auto& pi : info.parameters) p[pi.name] = pi.neutral;
  for (const auto& [name, value] : given) {
    auto it = std::find_if(info.parameters.begin(), info.parameters.end(), [&name = name](const auto& pi) { return pi.name == name; });
    if (it == info.parameters.end()) throw InputError("effect '" + info.name + "'", "has no parameter '" + name + "'");
    if (!(value >= it->min && value <= it->max))
      throw InputError("effect '" + info.name + "' parameter '" + name + "'",
                       format_value(value) + " is not allowed: must be in [" + format_value(it->min) + ", " +
                           format_value(it->max) + "] " + it->unit);
    p[name] = value;
  }
  return {id, std::move(p)};
}

std::shared_ptr<const Effect> make_effect(const EffectSpec& spec, const EffectContext& context) {
  return effect_info(spec.id).make(spec.parameters, context);
}

std::shared_ptr<const Effect> make_effect(EffectId id, const EffectParameters& given, const EffectContext& context) {
  return make_effect(effect_spec(id, given), context);
}

std::shared_ptr<const Effect> make_effect(const std::string& name, const EffectParameters& params, const EffectContext& context) {
  return make_effect(effect_info(name).id, params, context);
}

std::vector<EffectSpec> load_effects(YamlMap effects) {
  std::vector<EffectSpec> out;
  for (const auto& kv : effects.node()) {
    const std::string name = kv.first.as<std::string>();
    const EffectInfo* info = nullptr;
    try {
      info = &effect_info(name);
    } catch (const InputError& e) {
      throw InputError(effects.where(name), e.problem());
    }
    YamlMap m = effects.map(name);
    EffectParameters p;
    for (const auto& pi : info->parameters) {
      if (auto v = m.optional_number(pi.name, Range::closed(pi.min, pi.max))) p[pi.name] = *v;
    }
    m.finish();
    out.push_back(effect_spec(info->id, p));
    // Parameters that constrain each other (hvac_ambient's dead band) are checked by the module itself: build it
    // once here, so the error names the file and the effect, not a later simulation.
    try {
      make_effect(out.back(), EffectContext{});
    } catch (const InputError& e) {
      throw InputError(effects.where(name), e.what());
    }
  }
  effects.finish();
  return out;
}

std::string effects_yaml(const std::vector<std::pair<std::string, EffectParameters>>& effects) {
  std::ostringstream os;
  os.precision(6);
  os << "effects:\n";
  for (const auto& [id, params] : effects) {
    os << "  " << id << ":\n";
    for (const auto& [k, v] : params) os << "    " << k << ": " << v << "\n";
  }
  return os.str();
}

}  // namespace rollsim
