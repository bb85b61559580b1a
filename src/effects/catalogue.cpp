// The effect modules: each a small physical model with its parameters in SI.
#include "rollsim/effects/catalogue.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "rollsim/common/error.hpp"
#include "rollsim/common/units.hpp"

namespace rollsim {
namespace {

constexpr double kG = units::kStandardGravity_mps2;
constexpr double kRefSpeed_mps = 100.0 / 3.6;  // rr_speed's coefficient is the RRC change at 100 km/h

// Tyre warm-up, lumped over the four tyres. Hidden state: tyre temperature above ambient, T [K].
//   C dT/dt = eta_heat * P_rr - h(v) T,  h(v) = h0 (1 + g v)  (forced convection grows with speed)
//   RRC factor = 1 + excess * max(0, 1 - T / T_warm)          (linear in temperature below the warm point)
// P_rr is the rolling-resistance power: hysteresis loss is what heats the tyre. The cold excess (+10-30 %)
// and the tens-of-minutes time constant C/h are of the literature (see docs/diagnose.md).
class TyreWarmup final : public Effect {
 public:
  explicit TyreWarmup(const EffectParameters& p)
      : excess_(p.at("cold_rrc_excess")), c_(p.at("heat_capacity_j_per_k")), h0_(p.at("convection_w_per_k")),
        g_(p.at("convection_growth_s_per_m")), warm_(p.at("warm_excess_k")), initial_(p.at("initial_excess_k")) {}
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

// Constant electrical consumer (HVAC, electronics) not in the vehicle file's aux power.
class AuxLoad final : public Effect {
 public:
  explicit AuxLoad(const EffectParameters& p) : p_(p.at("power_w")) {}
  std::string id() const override { return "aux_load"; }
  double extra_electric_power_w(const EffectInputs&, const double*) const override { return p_; }

 private:
  double p_;
};

// Constant headwind u (negative: tailwind): the aero force is 0.5 rho CdA (v + u)^2 instead of 0.5 rho CdA v^2.
class Wind final : public Effect {
 public:
  Wind(const EffectParameters& p, const EffectContext& c) : u_(p.at("headwind_mps")), k_(0.5 * c.rho_cda_kg_per_m) {}
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

// Mass (payload) error dm: inertia, grade and the rolling share, dm (a + g sin theta + g RRC).
class Mass final : public Effect {
 public:
  Mass(const EffectParameters& p, const EffectContext& c) : dm_(p.at("extra_mass_kg")), m_(c.mass_kg) {}
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
  explicit RrSpeed(const EffectParameters& p) : k_(p.at("rrc_change_at_100kmh")) {}
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
  explicit AmbientRrc(const EffectParameters& p)
      : c_(p.at("rrc_change_per_k")), t_(p.at("ambient_temp_c")), ref_(p.at("reference_temp_c")) {}
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
  explicit RotationalInertia(const EffectParameters& p) : dm_(p.at("extra_rotating_mass_kg")) {}
  std::string id() const override { return "rotational_inertia"; }
  double extra_resistance_n(const EffectInputs& in, const double*) const override { return dm_ * in.accel_mps2; }

 private:
  double dm_;
};

// Extra battery internal resistance dR (ageing, cold cells, contactors): loss dR I^2 with I = P_terminal / V_pack,
// in both directions (discharge and regen). It drains the cells, so only state of charge sees it, not the
// terminal power.
class BatteryResistance final : public Effect {
 public:
  explicit BatteryResistance(const EffectParameters& p) : dr_(p.at("extra_resistance_ohm")), v_(p.at("pack_voltage_v")) {}
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
  explicit TyreSlip(const EffectParameters& p) : per_n_(p.at("slip_per_kn") / 1000.0) {}
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
  explicit RegenLimit(const EffectParameters& p) : share_(p.at("friction_share_above_limit")), lim_(p.at("regen_limit_w")) {}
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
// loss grows with its work). Neutral on an electric car: there is no fuel power to scale.
class EngineWarmup final : public Effect {
 public:
  explicit EngineWarmup(const EffectParameters& p)
      : k_(p.at("cold_fuel_excess")), c_(p.at("heat_capacity_j_per_k")), idle_(p.at("idle_heat_w")),
        q_(p.at("heat_per_wheel_work")), h_(p.at("heat_loss_w_per_k")), warm_(p.at("warm_excess_k")) {}
  std::string id() const override { return "engine_warmup"; }
  int num_states() const override { return 1; }
  void state_derivatives(const EffectInputs& in, const double* x, double* xdot) const override {
    const double work_w = std::max(0.0, in.wheel_force_demand_n * std::max(in.speed_mps, 0.0));
    xdot[0] = (idle_ + q_ * work_w - h_ * x[0]) / c_;
  }
  double fuel_power_factor(const EffectInputs&, const double* x) const override {
    return std::max(0.0, 1.0 + k_ * std::max(0.0, 1.0 - x[0] / warm_));
  }

 private:
  double k_, c_, idle_, q_, h_, warm_;
};

// Missing or wrong road grade: a grade offset theta(s) = g0 (constant, wavelength 0) or g0 cos(2 pi s / L) (an
// elevation profile error along the distance s); force m g sin(theta), booked as other resistance. On one flat
// trip a constant offset is the RRC level (both a constant force opposing motion); driving the route both ways
// separates them (grade changes sign, RRC does not).
class RoadGrade final : public Effect {
 public:
  RoadGrade(const EffectParameters& p, const EffectContext& c)
      : g0_(p.at("grade_offset")), wavelength_(p.at("profile_wavelength_m")), m_(c.mass_kg) {}
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

}  // namespace

const std::vector<EffectInfo>& effect_catalogue() {
  static const std::vector<EffectInfo> kCatalogue{
      {"tyre_warmup",
       "tyre thermal state: RRC falls as rolling loss heats the tyres (heat balance with speed-dependent convection)",
       {{"cold_rrc_excess", "1", 0.0, 0.2, -0.5, 1.0, true},
        {"heat_capacity_j_per_k", "J/K", 50000.0, 50000.0, 5000.0, 500000.0, false},
        {"convection_w_per_k", "W/K", 20.0, 20.0, 1.0, 500.0, false},
        {"convection_growth_s_per_m", "s/m", 0.1, 0.1, 0.0, 1.0, false},
        {"warm_excess_k", "K", 30.0, 30.0, 1.0, 100.0, false},
        {"initial_excess_k", "K", 0.0, 0.0, 0.0, 100.0, false}}},
      {"aux_load", "constant extra electrical load (HVAC, electronics)", {{"power_w", "W", 0.0, 400.0, -2000.0, 8000.0, true}}},
      {"wind", "constant headwind (negative: tailwind)", {{"headwind_mps", "m/s", 0.0, 3.0, -20.0, 20.0, true}}},
      {"mass", "mass or payload error: inertia, grade and rolling share", {{"extra_mass_kg", "kg", 0.0, 150.0, -500.0, 1000.0, true}}},
      {"rr_speed", "speed-dependent rolling resistance: RRC x (1 + k (v / 100 km/h)^2)",
       {{"rrc_change_at_100kmh", "1", 0.0, 0.2, -0.9, 3.0, true}}},
      {"ambient_rrc", "RRC against ambient temperature: RRC x (1 + c (T_ref - T_amb))",
       {{"rrc_change_per_k", "1/K", 0.0, 0.008, -0.05, 0.05, true},
        {"ambient_temp_c", "degC", 20.0, 20.0, -40.0, 50.0, false},
        {"reference_temp_c", "degC", 20.0, 20.0, -40.0, 50.0, false}}},
      {"rotational_inertia", "rotating parts' equivalent mass missing from the file: force dm_rot a, acceleration only",
       {{"extra_rotating_mass_kg", "kg", 0.0, 80.0, -300.0, 500.0, true}}},
      {"battery_resistance", "extra battery internal resistance: loss dR (P / V)^2 inside the cells (SOC only)",
       {{"extra_resistance_ohm", "ohm", 0.0, 0.05, -0.5, 2.0, true}, {"pack_voltage_v", "V", 360.0, 360.0, 12.0, 1000.0, false}}},
      {"tyre_slip", "longitudinal tyre slip, linear range: loss F_x^2 v / C_x",
       {{"slip_per_kn", "1/kN", 0.0, 0.005, 0.0, 0.1, true}}},
      {"regen_limit", "lower regen limit (brake blending): a share of braking power above the limit goes to friction",
       {{"friction_share_above_limit", "1", 0.0, 1.0, 0.0, 1.0, true}, {"regen_limit_w", "W", 10000.0, 10000.0, 0.0, 200000.0, false}}},
      {"engine_warmup", "cold engine: fuel power x (1 + k max(0, 1 - T_oil / T_warm)), oil heated by the engine's losses",
       {{"cold_fuel_excess", "1", 0.0, 0.2, -0.5, 2.0, true},
        {"heat_capacity_j_per_k", "J/K", 100000.0, 100000.0, 5000.0, 2000000.0, false},
        {"idle_heat_w", "W", 2000.0, 2000.0, 0.0, 50000.0, false},
        {"heat_per_wheel_work", "1", 0.6, 0.6, 0.0, 5.0, false},
        {"heat_loss_w_per_k", "W/K", 40.0, 40.0, 1.0, 2000.0, false},
        {"warm_excess_k", "K", 60.0, 60.0, 1.0, 150.0, false}}},
      {"road_grade", "missing grade: constant offset or a cosine elevation-profile error along distance, force m g sin(theta)",
       {{"grade_offset", "1", 0.0, 0.005, -0.2, 0.2, true}, {"profile_wavelength_m", "m", 0.0, 0.0, 0.0, 1e6, false}}},
  };
  return kCatalogue;
}

const std::vector<std::string>& effects_not_implemented() {
  // Every identifier the issue lists has a module; elevation inference from a recording (road_grade "inferred as
  // an elevation profile") belongs to the diagnosis, not to this module.
  static const std::vector<std::string> kMissing{};
  return kMissing;
}

const EffectInfo& effect_info(const std::string& id) {
  for (const auto& e : effect_catalogue())
    if (e.id == id) return e;
  for (const auto& m : effects_not_implemented())
    if (m == id) throw InputError("effect '" + id + "'", "is in the catalogue but not implemented yet");
  throw InputError("effect '" + id + "'", "is not a catalogue effect");
}

std::shared_ptr<const Effect> make_effect(const std::string& id, const EffectParameters& given,
                                          const EffectContext& context) {
  const EffectInfo& info = effect_info(id);
  EffectParameters p;
  for (const auto& pi : info.parameters) p[pi.name] = pi.neutral;
  for (const auto& [name, value] : given) {
    auto it = std::find_if(info.parameters.begin(), info.parameters.end(), [&name = name](const auto& pi) { return pi.name == name; });
    if (it == info.parameters.end()) throw InputError("effect '" + id + "'", "has no parameter '" + name + "'");
    if (!(value >= it->min && value <= it->max))
      throw InputError("effect '" + id + "' parameter '" + name + "'",
                       format_value(value) + " is not allowed: must be in [" + format_value(it->min) + ", " +
                           format_value(it->max) + "] " + it->unit);
    p[name] = value;
  }
  if (id == "tyre_warmup") return std::make_shared<TyreWarmup>(p);
  if (id == "aux_load") return std::make_shared<AuxLoad>(p);
  if (id == "wind") return std::make_shared<Wind>(p, context);
  if (id == "mass") return std::make_shared<Mass>(p, context);
  if (id == "rr_speed") return std::make_shared<RrSpeed>(p);
  if (id == "ambient_rrc") return std::make_shared<AmbientRrc>(p);
  if (id == "rotational_inertia") return std::make_shared<RotationalInertia>(p);
  if (id == "battery_resistance") return std::make_shared<BatteryResistance>(p);
  if (id == "tyre_slip") return std::make_shared<TyreSlip>(p);
  if (id == "regen_limit") return std::make_shared<RegenLimit>(p);
  if (id == "engine_warmup") return std::make_shared<EngineWarmup>(p);
  if (id == "road_grade") return std::make_shared<RoadGrade>(p, context);
  throw InputError("effect '" + id + "'", "has no module");  // unreachable while the catalogue and this list agree
}

std::vector<std::shared_ptr<const Effect>> load_effects(YamlMap effects, const EffectContext& context) {
  std::vector<std::shared_ptr<const Effect>> out;
  for (const auto& kv : effects.node()) {
    const std::string id = kv.first.as<std::string>();
    try {
      effect_info(id);
    } catch (const InputError& e) {
      throw InputError(effects.where(id), e.problem());
    }
    YamlMap m = effects.map(id);
    EffectParameters p;
    for (const auto& pi : effect_info(id).parameters) {
      if (auto v = m.optional_number(pi.name, Range::closed(pi.min, pi.max))) p[pi.name] = *v;
    }
    m.finish();
    out.push_back(make_effect(id, p, context));
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
