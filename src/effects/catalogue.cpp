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
  };
  return kCatalogue;
}

const std::vector<std::string>& effects_not_implemented() {
  static const std::vector<std::string> kMissing{"engine_warmup", "road_grade", "rotational_inertia",
                                                 "battery_resistance", "tyre_slip", "regen_limit"};
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
    auto it = std::find_if(info.parameters.begin(), info.parameters.end(), [&](const auto& pi) { return pi.name == name; });
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
  return std::make_shared<AmbientRrc>(p);
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
