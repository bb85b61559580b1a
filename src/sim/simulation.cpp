#include "rollsim/sim/simulation.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include "rollsim/common/units.hpp"

namespace rollsim {

VehicleModel VehicleModel::assemble(const Vehicle& vehicle) {
  VehicleModel m;
  m.name = vehicle.name;
  m.mass_kg = vehicle.body.test_mass_kg;
  m.rotating_mass_kg = vehicle.body.rotating_mass_kg;
  m.wheel_radius_m = driven_wheel_radius_m(vehicle);
  m.road_load = make_road_load(vehicle);
  m.road_load_description = m.road_load->describe();
  m.powertrain = make_powertrain(vehicle);
  m.effects = vehicle.effects;
  return m;
}

double EnergyBreakdown::wheel_residual_j() const {
  return traction_j + unmet_demand_j - (rolling_j + aero_j + grade_j + other_resistance_j + friction_brake_j + regen_wheel_j +
                       wheel_loss_j + kinetic_change_j);
}

double EnergyBreakdown::powertrain_residual_j(bool electric) const {
  if (electric) return battery_terminal_j - (traction_j - regen_wheel_j + gearbox_loss_j + motor_loss_j + aux_j);
  return fuel_j - (engine_loss_j + traction_j + gearbox_loss_j + clutch_loss_j + aux_j);
}

double SimulationResult::aec_kwh_per_10km() const {
  return units::j_to_kwh(energy.battery_terminal_j) / (distance_m / 10000.0);
}
double SimulationResult::fuel_l_per_100km() const {
  return fuel_volume_m3 / units::kM3PerLitre / (distance_m / 100000.0);
}
double SimulationResult::co2_g_per_km() const { return co2_kg * 1e3 / (distance_m / 1000.0); }
double SimulationResult::range_km() const {
  const double per_m = (energy.battery_terminal_j + energy.battery_loss_j) / distance_m;
  return per_m > 0.0 ? usable_battery_j / per_m / 1000.0 : 0.0;
}

namespace {

// State layout of the forward simulation: kinematics, driver, then one accumulator per energy flow.
enum Idx : int {
  kSpeed, kDistance, kDriverIntegral,
  kTraction, kRolling, kAero, kGrade, kOther, kFriction, kRegen, kWheelLoss,
  kGearbox, kMotor, kBatteryLoss, kAux, kTerminal, kFuelEnergy, kEngineLoss, kClutch, kFuelVolume, kUnmet,
  kBaseStates
};

double grade_force_n(double mass_kg, double grade) {
  return mass_kg * units::kStandardGravity_mps2 * grade / std::sqrt(1.0 + grade * grade);
}

// Road-load coefficients per trace segment: computed once per distinct grade (a tyre preparation each).
struct SegmentRoadLoads {
  std::vector<RoadLoadCoeffs> coeffs;
  std::vector<int> of_segment;
  SegmentRoadLoads(const RoadLoadModel& rl, const DriveCycle& c) {
    std::map<double, int> index;
    of_segment.resize(c.time_s.size());
    for (std::size_t i = 0; i < c.time_s.size(); ++i) {
      const double g = c.grade.empty() ? 0.0 : c.grade[i];
      auto [it, inserted] = index.emplace(g, static_cast<int>(coeffs.size()));
      if (inserted) coeffs.push_back(rl.at_grade(g));
      of_segment[i] = it->second;
    }
  }
};

// Everything at one instant, shared by the forward RHS, the replay and the trace so the three agree.
struct Instant {
  PowerFlow flow;
  double rolling_n = 0.0, aero_n = 0.0, grade_n = 0.0, other_n = 0.0, wheel_loss_w = 0.0;
  double resistance_n() const { return rolling_n + aero_n + grade_n + other_n; }
};

struct Evaluator {
  const VehicleModel& m;
  std::vector<int> effect_state_offset;
  int effect_states = 0;

  explicit Evaluator(const VehicleModel& model) : m(model) {
    for (const auto& e : m.effects) {
      effect_state_offset.push_back(effect_states);
      effect_states += e->num_states();
    }
  }

  double rolling_factor(const EffectInputs& in, const double* x) const {
    double f = 1.0;
    for (std::size_t i = 0; i < m.effects.size(); ++i) f *= m.effects[i]->rolling_resistance_factor(in, x + effect_state_offset[i]);
    return f;
  }

  // Resistance at `speed_mps` (rolling scaled by the effects, aero, grade, effects' forces).
  void resistance(const RoadLoadCoeffs& rl, EffectInputs& in, const double* x, Instant& out) const {
    const double v = std::max(in.speed_mps, 0.0);
    in.base_rolling_force_n = rl.rolling_n(v);
    out.rolling_n = in.base_rolling_force_n * rolling_factor(in, x);
    out.aero_n = rl.aero_n(v);
    out.grade_n = grade_force_n(m.mass_kg, in.grade);
    out.other_n = 0.0;
    for (std::size_t i = 0; i < m.effects.size(); ++i) out.other_n += m.effects[i]->extra_resistance_n(in, x + effect_state_offset[i]);
  }

  // Powertrain response to a wheel-force request, with the effects' wheel losses and fuel factors.
  void deliver(double force_request_n, int gear, EffectInputs& in, const double* x, Instant& out) const {
    in.wheel_force_demand_n = force_request_n;
    const double v = std::max(in.speed_mps, 0.0);
    out.wheel_loss_w = 0.0;
    double fuel_factor = 1.0;
    for (std::size_t i = 0; i < m.effects.size(); ++i) {
      out.wheel_loss_w += m.effects[i]->wheel_loss_w(in, x + effect_state_offset[i]);
      fuel_factor *= m.effects[i]->fuel_power_factor(in, x + effect_state_offset[i]);
    }
    // A wheel loss (slip) makes the hub turn faster than the car when driving and slower when braking.
    double hub_speed_mps = v;
    if (out.wheel_loss_w > 0.0 && std::abs(force_request_n) > 1.0) {
      hub_speed_mps = std::max(0.0, v + out.wheel_loss_w / force_request_n);
    } else {
      out.wheel_loss_w = 0.0;
    }
    out.flow = m.powertrain->deliver(force_request_n, hub_speed_mps, gear, m.wheel_radius_m);
    if (fuel_factor != 1.0 && out.flow.fuel_power_w > 0.0) {
      const double extra_w = (fuel_factor - 1.0) * out.flow.fuel_power_w;
      out.flow.fuel_rate_m3_per_s *= fuel_factor;
      out.flow.fuel_power_w += extra_w;
      out.flow.engine_loss_w += extra_w;
    }
    double extra_electric_w = 0.0;
    for (std::size_t i = 0; i < m.effects.size(); ++i) extra_electric_w += m.effects[i]->extra_electric_power_w(in, x + effect_state_offset[i]);
    if (extra_electric_w != 0.0) add_electric_load(extra_electric_w, out.flow);
  }

  // An extra electrical load: from the battery terminals (its own I^2 R is neglected: under 1 % of it at these
  // currents), or from the alternator at the engine's marginal (Willans) efficiency, even in fuel cut-off.
  void add_electric_load(double p_w, PowerFlow& flow) const {
    flow.aux_power_w += p_w;
    if (m.powertrain->is_electric()) {
      flow.battery_terminal_power_w += p_w;
      return;
    }
    if (const auto* c = dynamic_cast<const CombustionPowertrain*>(m.powertrain.get())) {
      const auto& cp = c->params();
      const double fuel_w = p_w / (cp.alternator_efficiency * cp.engine.indicated_efficiency);
      flow.fuel_power_w += fuel_w;
      flow.engine_loss_w += fuel_w - p_w;
      flow.fuel_rate_m3_per_s += fuel_w / (cp.fuel.lower_heating_value_j_per_kg * cp.fuel.density_kg_per_m3);
    }
  }
};

void accumulate(const Instant& s, double speed_mps, double* d) {
  const double v = std::max(speed_mps, 0.0);
  d[kTraction] = s.flow.traction_power_w;
  d[kRolling] = s.rolling_n * v;
  d[kAero] = s.aero_n * v;
  d[kGrade] = s.grade_n * v;
  d[kOther] = s.other_n * v;
  d[kFriction] = s.flow.friction_brake_power_w;
  d[kRegen] = s.flow.regen_wheel_power_w;
  d[kWheelLoss] = s.wheel_loss_w;
  d[kGearbox] = s.flow.gearbox_loss_w;
  d[kMotor] = s.flow.motor_loss_w;
  d[kBatteryLoss] = s.flow.battery_loss_w;
  d[kAux] = s.flow.aux_power_w;
  d[kTerminal] = s.flow.battery_terminal_power_w;
  d[kFuelEnergy] = s.flow.fuel_power_w;
  d[kEngineLoss] = s.flow.engine_loss_w;
  d[kClutch] = s.flow.clutch_loss_w;
  d[kFuelVolume] = s.flow.fuel_rate_m3_per_s;
}

EnergyBreakdown breakdown_from(const double* y) {
  EnergyBreakdown e;
  e.traction_j = y[kTraction];
  e.rolling_j = y[kRolling];
  e.aero_j = y[kAero];
  e.grade_j = y[kGrade];
  e.other_resistance_j = y[kOther];
  e.friction_brake_j = y[kFriction];
  e.regen_wheel_j = y[kRegen];
  e.wheel_loss_j = y[kWheelLoss];
  e.gearbox_loss_j = y[kGearbox];
  e.motor_loss_j = y[kMotor];
  e.battery_loss_j = y[kBatteryLoss];
  e.aux_j = y[kAux];
  e.battery_terminal_j = y[kTerminal];
  e.fuel_j = y[kFuelEnergy];
  e.engine_loss_j = y[kEngineLoss];
  e.clutch_loss_j = y[kClutch];
  e.unmet_demand_j = y[kUnmet];
  return e;
}

double fuel_mass_per_volume(const VehicleModel& m) {
  if (const auto* c = dynamic_cast<const CombustionPowertrain*>(m.powertrain.get())) return c->params().fuel.density_kg_per_m3;
  return 0.0;
}
double co2_per_fuel_mass(const VehicleModel& m) {
  if (const auto* c = dynamic_cast<const CombustionPowertrain*>(m.powertrain.get())) return c->params().fuel.co2_kg_per_kg;
  return 0.0;
}
double initial_soc(const VehicleModel& m) {
  if (const auto* e = dynamic_cast<const ElectricPowertrain*>(m.powertrain.get())) return e->params().battery.initial_soc;
  return 0.0;
}

void finish_result(const VehicleModel& m, const DriveCycle& c, const double* y, double v_start, double v_end,
                   SimulationResult& r) {
  r.vehicle = m.name;
  r.road_load = m.road_load_description;
  r.cycle = c.name;
  r.electric = m.powertrain->is_electric();
  r.duration_s = c.duration_s();
  r.distance_m = y[kDistance];
  r.energy = breakdown_from(y);
  r.energy.kinetic_change_j = 0.5 * m.inertial_mass_kg() * (v_end * v_end - v_start * v_start);
  r.fuel_volume_m3 = y[kFuelVolume];
  r.co2_kg = r.fuel_volume_m3 * fuel_mass_per_volume(m) * co2_per_fuel_mass(m);
  r.usable_battery_j = m.powertrain->usable_battery_energy_j();
  r.initial_soc = initial_soc(m);
  r.final_soc = r.usable_battery_j > 0.0
                    ? r.initial_soc - (r.energy.battery_terminal_j + r.energy.battery_loss_j) / r.usable_battery_j
                    : 0.0;
}

TracePoint trace_point(const VehicleModel& m, double t, double target_mps, double v, double a, double grade,
                       const Instant& s, int gear, double soc) {
  TracePoint p{};
  p.time_s = t;
  p.target_speed_mps = target_mps;
  p.speed_mps = v;
  p.accel_mps2 = a;
  p.grade = grade;
  p.rolling_force_n = s.rolling_n;
  p.aero_force_n = s.aero_n;
  p.grade_force_n = s.grade_n;
  p.wheel_force_n = s.flow.wheel_force_n;
  p.traction_power_w = s.flow.traction_power_w;
  p.battery_power_w = s.flow.battery_terminal_power_w;
  p.battery_current_a = s.flow.battery_current_a;
  p.fuel_rate_m3_per_s = s.flow.fuel_rate_m3_per_s;
  const double normal_n = m.mass_kg * units::kStandardGravity_mps2 / std::sqrt(1.0 + grade * grade);
  p.rrc = s.rolling_n / normal_n;
  p.soc = soc;
  p.gear = gear;
  return p;
}

// The forward model as an ODE system for CVODE.
class ForwardSystem final : public OdeSystem {
 public:
  ForwardSystem(const VehicleModel& m, const DriveCycle& c, const SimulationOptions& o)
      : m_(m), c_(c), o_(o), eval_(m), loads_(*m.road_load, c) {
    standstill_.resize(c.time_s.size(), false);
    for (std::size_t i = 0; i + 1 < c.time_s.size(); ++i) standstill_[i] = c.speed_mps[i] == 0.0 && c.speed_mps[i + 1] == 0.0;
  }
  bool standstill_segment(double t) const { return standstill_[c_.segment_index(t, hint_)]; }
  int size() const override { return kBaseStates + eval_.effect_states; }
  // Only gear shifts are roots: they switch the right-hand side discontinuously. Regen regime speeds are kinks
  // (continuous force), which error control handles; as roots they chatter when the car hovers near them.
  int num_roots() const override { return 2; }

  void roots(double, const double* y, double* g) override {
    // Index 0: upshift speed, 1: downshift speed of the current gear (a constant 1 where there is none).
    g[0] = shifts_up_ > 0.0 ? y[kSpeed] - shifts_up_ : 1.0;
    g[1] = shifts_down_ > 0.0 ? y[kSpeed] - shifts_down_ : 1.0;
  }

  void set_gear(int new_gear) {
    gear = new_gear;
    shifts_up_ = shifts_down_ = -1.0;
    const int n_up = m_.powertrain->select_gear(1e9, gear);
    if (n_up != gear) shifts_up_ = upshift_speed(gear);
    if (gear > 1) shifts_down_ = downshift_speed(gear);
  }

  int rhs(double t, const double* y, double* ydot) override {
    Instant s;
    evaluate(t, y, s, ydot);
    return 0;
  }

  // Evaluates the instant at (t, y); fills ydot when given.
  double evaluate(double t, const double* y, Instant& s, double* ydot) {
    const std::size_t i = c_.segment_index(t, hint_);
    hint_ = i;
    const double dt = c_.time_s[i + 1] - c_.time_s[i];
    const double a_ref = (c_.speed_mps[i + 1] - c_.speed_mps[i]) / dt;
    const double v_ref = c_.speed_mps[i] + a_ref * (t - c_.time_s[i]);
    const double grade = c_.grade.empty() ? 0.0 : c_.grade[i];
    const RoadLoadCoeffs& rl = loads_.coeffs[loads_.of_segment[i]];
    const double* x = y + kBaseStates;
    const double v = y[kSpeed];
    const double m_eff = m_.inertial_mass_kg();

    // Feed-forward: what the trace needs at its own speed; feedback: PI on the speed error.
    EffectInputs in{t, v_ref, a_ref, grade, y[kDistance], 0.0, 0.0};
    Instant ff;
    eval_.resistance(rl, in, x, ff);
    const double error_mps = v_ref - v;
    const double request_n = m_eff * (a_ref + o_.driver_kp_per_s * error_mps + o_.driver_ki_per_s2 * y[kDriverIntegral]) +
                             ff.resistance_n();

    in.speed_mps = v;
    eval_.resistance(rl, in, x, s);
    double accel = 0.0;
    if (standstill_[i]) {
      // The trace stands still over this whole segment: the car is held on its brakes (restarted at v = 0),
      // so only the standing consumers (auxiliaries, idling engine) draw power. Integrating a brake clamp at
      // v = 0 instead would make CVODE chatter on the discontinuity.
      eval_.deliver(0.0, gear, in, x, s);
      s.flow.wheel_force_n = s.resistance_n();
    } else {
      eval_.deliver(request_n, gear, in, x, s);
      accel = (s.flow.wheel_force_n - s.resistance_n()) / m_eff;
      if (v <= 0.0 && accel < 0.0) accel = 0.0;  // cannot roll backwards under braking
    }
    last_limited_ = s.flow.force_limited;
    if (ydot) {
      std::fill(ydot, ydot + size(), 0.0);
      ydot[kSpeed] = accel;
      ydot[kDistance] = std::max(v, 0.0);
      // Anti-windup: the integral stops growing while the powertrain is at its limit.
      ydot[kDriverIntegral] = (standstill_[i] || (s.flow.force_limited && error_mps > 0.0)) ? 0.0 : error_mps;
      accumulate(s, v, ydot);
      in.accel_mps2 = accel;
      for (std::size_t k = 0; k < m_.effects.size(); ++k) {
        m_.effects[k]->state_derivatives(in, x + eval_.effect_state_offset[k], ydot + kBaseStates + eval_.effect_state_offset[k]);
      }
    }
    return accel;
  }

  int gear = 1;
  bool last_limited_ = false;

 private:
  double upshift_speed(int g) const { return m_.powertrain->shift_speeds_mps(g).front(); }
  double downshift_speed(int g) const { return m_.powertrain->shift_speeds_mps(g).back(); }

  const VehicleModel& m_;
  const DriveCycle& c_;
  const SimulationOptions& o_;
  Evaluator eval_;
  SegmentRoadLoads loads_;
  std::vector<bool> standstill_;
  std::size_t hint_ = 0;
  double shifts_up_ = -1.0, shifts_down_ = -1.0;
};

double soc_of(const VehicleModel& m, const double* y) {
  const double cap = m.powertrain->usable_battery_energy_j();
  return cap > 0.0 ? initial_soc(m) - (y[kTerminal] + y[kBatteryLoss]) / cap : 0.0;
}

}  // namespace

SimulationResult simulate_forward(const VehicleModel& m, const DriveCycle& c, const SimulationOptions& opt) {
  ForwardSystem sys(m, c, opt);
  const int n = sys.size();
  std::vector<double> y0(n, 0.0);
  y0[kSpeed] = c.speed_mps.front();
  {
    std::size_t off = 0;
    for (const auto& eff : m.effects) {
      eff->initial_states(y0.data() + kBaseStates + off);
      off += eff->num_states();
    }
  }
  sys.set_gear(m.powertrain->select_gear(y0[kSpeed], 1));

  OdeTolerances tol;
  tol.relative = opt.relative_tolerance;
  // With rtol 1e-5 (the default) these keep the wheel energy balance within 1e-3 on NEDC, WLTC and UDDS and
  // forward and replay energy within 0.3 %, with a third fewer steps than rtol 1e-6 (see README, "Speed").
  tol.absolute.assign(n, 10.0);  // energies [J]: the relative tolerance governs them
  tol.absolute[kSpeed] = 1e-4;
  tol.absolute[kDistance] = 1e-2;
  tol.absolute[kDriverIntegral] = 1e-3;
  tol.absolute[kFuelVolume] = 1e-9;
  for (int i = kBaseStates; i < n; ++i) tol.absolute[i] = 1e-4;

  const double t0 = c.time_s.front();
  const double t_end = c.time_s.back();
  CvodeIntegrator integ(sys, t0, y0, tol);
  std::vector<double> stops = breakpoints_s(c);
  stops.push_back(t_end);

  SimulationResult r;
  r.mode = "forward";
  std::size_t next_sample = 1, next_stop = 0;
  Shortfall open{};
  bool in_shortfall = false;
  auto record = [&](double t, const std::vector<double>& y) {
    Instant s;
    const double accel = sys.evaluate(t, y.data(), s, nullptr);
    const double target = c.speed_mps_at(t);
    const double err = target - y[kSpeed];
    if (std::abs(err) > r.max_speed_error_mps) {
      r.max_speed_error_mps = std::abs(err);
      r.max_speed_error_time_s = t;
    }
    if (err > opt.shortfall_threshold_mps) {
      if (!in_shortfall) open = Shortfall{t, t, 0.0, t};
      in_shortfall = true;
      open.end_s = t;
      if (err > open.max_deficit_mps) {
        open.max_deficit_mps = err;
        open.at_s = t;
      }
    } else if (in_shortfall) {
      r.shortfalls.push_back(open);
      in_shortfall = false;
    }
    if (opt.record_trace) {
      const double grade = c.grade.empty() ? 0.0 : c.grade[c.segment_index(t)];
      r.trace.push_back(trace_point(m, t, target, y[kSpeed], accel, grade, s, sys.gear, soc_of(m, y.data())));
    }
  };
  if (opt.record_trace) record(t0, y0);

  while (integ.time() < t_end) {
    while (next_stop < stops.size() && stops[next_stop] <= integ.time()) ++next_stop;
    while (next_sample < c.time_s.size() && c.time_s[next_sample] <= integ.time()) ++next_sample;
    const double t_stop = stops[next_stop];
    const double t_out = std::min(c.time_s[next_sample], t_stop);
    const bool root = integ.advance(t_out, t_stop);
    const double t = integ.time();
    if (next_sample < c.time_s.size() && t >= c.time_s[next_sample]) record(t, integ.state());
    if (root) {
      // A shift speed was crossed: change gear and restart there.
      const auto& flags = integ.root_flags();
      int gear = sys.gear;
      if (flags[0] > 0) gear = m.powertrain->select_gear(integ.state()[kSpeed] + 1e-9, sys.gear);
      if (flags[1] < 0) gear = m.powertrain->select_gear(integ.state()[kSpeed] - 1e-9, sys.gear);
      sys.set_gear(gear);
      integ.restart(t, integ.state());
    } else if (t >= t_stop && t < t_end) {
      std::vector<double> y = integ.state();
      if (sys.standstill_segment(t)) {
        y[kSpeed] = 0.0;  // stopped and braked: the driver releases the pedal
        y[kDriverIntegral] = 0.0;
      }
      integ.restart(t, y);
    }
  }
  if (in_shortfall) r.shortfalls.push_back(open);
  r.solver = integ.stats();
  finish_result(m, c, integ.state().data(), c.speed_mps.front(), integ.state()[kSpeed], r);
  return r;
}

SimulationResult simulate_replay(const VehicleModel& m, const DriveCycle& c, const SimulationOptions& opt) {
  Evaluator eval(m);
  SegmentRoadLoads loads(*m.road_load, c);
  const double m_eff = m.inertial_mass_kg();
  // 3-point Gauss-Legendre: exact for the kinetic-energy and polynomial road-load integrands of a linear ramp.
  constexpr std::array<double, 3> kNode{0.5 - 0.3872983346207417, 0.5, 0.5 + 0.3872983346207417};
  constexpr std::array<double, 3> kWeight{5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};

  std::vector<double> y(kBaseStates + eval.effect_states, 0.0);
  {
    std::size_t off = 0;
    for (const auto& eff : m.effects) {
      eff->initial_states(y.data() + kBaseStates + off);
      off += eff->num_states();
    }
  }
  std::vector<double> rate(y.size(), 0.0), xdot(eval.effect_states, 0.0), xdot_sum(eval.effect_states, 0.0);
  int gear = m.powertrain->select_gear(c.speed_mps.front(), 1);
  SimulationResult r;
  r.mode = "replay";
  bool limited = false;
  Shortfall open{};
  for (std::size_t i = 0; i + 1 < c.time_s.size(); ++i) {
    const double t0 = c.time_s[i];
    const double dt = c.time_s[i + 1] - t0;
    const double v0 = c.speed_mps[i];
    const double a = (c.speed_mps[i + 1] - v0) / dt;
    const double grade = c.grade.empty() ? 0.0 : c.grade[i];
    const RoadLoadCoeffs& rl = loads.coeffs[loads.of_segment[i]];
    const double* x = y.data() + kBaseStates;
    std::fill(xdot_sum.begin(), xdot_sum.end(), 0.0);
    bool segment_limited = false;
    if (opt.record_trace) {
      EffectInputs in{t0, v0, a, grade, y[kDistance], 0.0, 0.0};
      Instant s;
      eval.resistance(rl, in, x, s);
      eval.deliver(m_eff * a + s.resistance_n(), m.powertrain->select_gear(v0, gear), in, x, s);
      r.trace.push_back(trace_point(m, t0, v0, v0, a, grade, s, gear, soc_of(m, y.data())));
    }
    for (std::size_t k = 0; k < kNode.size(); ++k) {
      const double t = t0 + kNode[k] * dt;
      const double v = v0 + a * kNode[k] * dt;
      gear = m.powertrain->select_gear(v, gear);
      EffectInputs in{t, v, a, grade, y[kDistance] + (v0 + v) / 2.0 * kNode[k] * dt, 0.0, 0.0};
      Instant s;
      eval.resistance(rl, in, x, s);
      const double request_n = m_eff * a + s.resistance_n();
      eval.deliver(request_n, gear, in, x, s);
      segment_limited = segment_limited || s.flow.force_limited;
      accumulate(s, v, rate.data());
      rate[kUnmet] = (request_n - s.flow.wheel_force_n) * v;
      for (int j = kTraction; j < kBaseStates; ++j) y[j] += kWeight[k] * dt * rate[j];
      for (std::size_t e = 0; e < m.effects.size(); ++e) {
        m.effects[e]->state_derivatives(in, x + eval.effect_state_offset[e], xdot.data() + eval.effect_state_offset[e]);
      }
      for (int j = 0; j < eval.effect_states; ++j) xdot_sum[j] += kWeight[k] * xdot[j];
    }
    // Hidden effect states advance with the segment-mean rate (time constants are minutes, segments seconds).
    for (int j = 0; j < eval.effect_states; ++j) y[kBaseStates + j] += dt * xdot_sum[j];
    y[kDistance] += (v0 + c.speed_mps[i + 1]) / 2.0 * dt;
    // The replay cannot fall behind, but it says where the car could not have delivered the trace.
    if (segment_limited && !limited) open = Shortfall{t0, t0 + dt, 0.0, t0};
    if (segment_limited) open.end_s = t0 + dt;
    if (!segment_limited && limited) r.shortfalls.push_back(open);
    limited = segment_limited;
  }
  if (limited) r.shortfalls.push_back(open);
  finish_result(m, c, y.data(), c.speed_mps.front(), c.speed_mps.back(), r);
  return r;
}

}  // namespace rollsim
