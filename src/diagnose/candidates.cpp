// Diagnosis stage 4: candidate signatures: each catalogue effect's (and the unexplained basis') change in window
// energy per unit size, from the full simulator with the effect on.
#include <algorithm>
#include <cmath>

#include "pipeline.hpp"
#include "rollsim/common/units.hpp"

namespace rollsim::diag {
namespace {

// Calibration signature of the aero (C) term: a force k * 0.5 rho CdA v^2 (k = fractional change).
class DragScale final : public Effect {
 public:
  DragScale(double k, double rho_cda) : k_(k), half_rho_cda_(0.5 * rho_cda) {}
  std::string id() const override { return "calibration_drag"; }
  double extra_resistance_n(const EffectInputs& in, const double*) const override {
    const double v = std::max(in.speed_mps, 0.0);
    return k_ * half_rho_cda_ * v * v;
  }

 private:
  double k_, half_rho_cda_;
};

// Calibration signature of the RRC level: a constant factor on rolling resistance.
class RrcLevel final : public Effect {
 public:
  explicit RrcLevel(double k) : k_(k) {}
  std::string id() const override { return "calibration_rrc"; }
  double rolling_resistance_factor(const EffectInputs&, const double*) const override { return 1.0 + k_; }

 private:
  double k_;
};

// Basis of the unexplained-residual description (not a catalogue effect): a force of one shape, per unit
// amplitude, optionally decaying from the start of the trip. Run through the simulator so that the powertrain's
// efficiency, regen and fuel cut weigh it as they would weigh a real force.
class SignatureForce final : public Effect {
 public:
  SignatureForce(ForceShape shape, double decay_s) : shape_(shape), decay_s_(decay_s) {}
  std::string id() const override { return "signature_force"; }
  double extra_resistance_n(const EffectInputs& in, const double*) const override {
    constexpr double kV100 = units::kmh_to_mps(100.0);
    const double v = std::max(in.speed_mps, 0.0);
    double f = 0.0;
    switch (shape_) {
      case ForceShape::constant: f = v > 0.1 ? 1.0 : 0.0; break;  // 1 N while moving
      case ForceShape::speed: f = v / kV100; break;               // 1 N at 100 km/h
      case ForceShape::speed_squared: f = (v / kV100) * (v / kV100); break;
      case ForceShape::positive_accel: f = std::max(in.accel_mps2, 0.0); break;  // 1 kg x a
    }
    return decay_s_ > 0.0 ? f * std::exp(-in.time_s / decay_s_) : f;
  }

 private:
  ForceShape shape_;
  double decay_s_;
};

// Shapes tested for each effect (each refined by a profile once found): hidden-state effects one per time constant,
// the regen limit one per limit. A single shape would lose to a neighbour with a grid: an engine warming in minutes
// looked more like a fast tyre warm-up than like the one slow engine shape (and a cold-start test's 3-minute one
// like a decaying constant power until the 15 kJ/K shape was added), and a 4 kW regen cap needed a friction
// share above 1 at the one 10 kW limit, out of bounds, so a force-squared loss took its place.
std::vector<EffectParameters> shapes_of(const EffectInfo& info, ChannelKind channel, bool regenerates, bool any_cold_start) {
  if (info.id == EffectId::tyre_warmup)
    return {{{"heat_capacity_j_per_k", 20000.0}}, {{"heat_capacity_j_per_k", 50000.0}}, {{"heat_capacity_j_per_k", 120000.0}}};
  if (info.id == EffectId::engine_warmup) {
    if (channel != ChannelKind::fuel_rate) return {};  // no fuel power to scale: its signature is zero
    if (!any_cold_start) return {};                    // every engine started hot: nothing warms up
    return {{{"heat_capacity_j_per_k", 15000.0}}, {{"heat_capacity_j_per_k", 40000.0}}, {{"heat_capacity_j_per_k", 100000.0}},
            {{"heat_capacity_j_per_k", 250000.0}}};
  }
  // A car that brakes by friction alone has no regeneration to limit: on the Camry the shape, a wheel loss in hard
  // braking, moved its engine's cut-off and was named "brake blending" (session 23's outside testing).
  if (info.id == EffectId::regen_limit && !regenerates) return {};
  if (info.id == EffectId::regen_limit)
    return {{{"regen_limit_w", 3000.0}}, {{"regen_limit_w", 6000.0}}, {{"regen_limit_w", 12000.0}}};
  if (info.id == EffectId::road_profile) return {};  // inferred from the residual (road_profile.cpp), not one shape
  return {{}};
}

// A steady wind's bearing is a shape on a circle, not on a log grid: candidates every 30 degrees over a half circle
// (a negative speed is the opposite bearing; the headwind's error at the nearest is under 1 - cos 15 = 3.4 %),
// mixed from two runs (north, east) at the nominal speed.
constexpr double kBearingStep_deg = 30.0;

void add_bearing_candidates(const EffectInfo& info, const EffectContext& ctx, std::vector<EffectList>& extras,
                            std::vector<Candidate>& out) {
  const EffectParameterInfo& amp = info.amplitude();
  for (double from : {0.0, 90.0}) extras.push_back({make_effect(info.id, {{amp.name, amp.nominal}, {"wind_from_deg", from}}, ctx)});
  for (double from = 0.0; from < 180.0; from += kBearingStep_deg) {
    Candidate c;
    c.id = info.id;
    c.shape = {{"wind_from_deg", from}};
    c.amplitude = &amp;
    c.mixed_bearing = true;
    c.label = info.name + " (wind_from_deg " + num(from) + ")";
    out.push_back(std::move(c));
  }
}

void mix_bearing(Candidate& c, const Variant& base, const Variant& north, const Variant& east) {
  const double th = units::deg_to_rad(c.shape.at("wind_from_deg")), cn = std::cos(th), ce = std::sin(th);
  c.signature = (cn * (north.window_j - base.window_j) + ce * (east.window_j - base.window_j)) / c.amplitude->nominal;
  c.power_w = base.power_w;
  for (std::size_t r = 0; r < c.power_w.size(); ++r)
    for (std::size_t i = 0; i < c.power_w[r].size(); ++i)
      c.power_w[r][i] += cn * (north.power_w[r][i] - base.power_w[r][i]) + ce * (east.power_w[r][i] - base.power_w[r][i]);
}

}  // namespace

std::shared_ptr<const Effect> signature_force(ForceShape shape, double decay_s) {
  return std::make_shared<SignatureForce>(shape, decay_s);
}

std::shared_ptr<const Effect> drag_scale(double k, double rho_cda) { return std::make_shared<DragScale>(k, rho_cda); }

Eigen::VectorXd power_signature(const Observations& o, const std::vector<DriveCycle>& cycles, double decay_s) {
  Eigen::VectorXd sig(o.n());
  for (Eigen::Index w = 0; w < o.n(); ++w) {
    const auto& win = o.windows[static_cast<std::size_t>(w)];
    double e = 0.0;
    for (std::size_t i = win.begin; i < win.end; ++i)
      e += (decay_s > 0.0 ? std::exp(-cycles[win.rec].time_s[i] / decay_s) : 1.0) * o.dt_s[win.rec][i];
    sig[w] = e;
  }
  return sig;
}

// hvac_ambient's dead band, as the catalogue's defaults (a car's thermostat is not recorded).
double hvac_default_c(const std::string& parameter) {
  for (const auto& p : effect_info(EffectId::hvac_ambient).parameters)
    if (p.name == parameter) return p.neutral;
  return 0.0;
}

double hvac_law_k(double ambient_k, double cool_per_heat) {
  const double t_c = ambient_k - units::kKelvinOffset;
  return std::max(0.0, hvac_default_c("heat_below_c") - t_c) + cool_per_heat * std::max(0.0, t_c - hvac_default_c("cool_above_c"));
}

namespace {

// hvac_ambient needs what ambient_rrc needs, an electrical channel (a combustion car heats its cabin from the
// coolant, and its A/C load is the engine's: a fuel excess, not a battery draw), and at least one recording outside
// the dead band (else its law is zero on every trip).
void note_hvac_setting(AmbientSetting& a, ChannelKind channel, const DiagnoseOptions& opt, std::vector<std::string>& notes) {
  if (!a.testable) {
    notes.push_back("hvac_ambient not tested: the recorded ambients span under " + fixed(opt.ambient_min_spread_k, 1) + " K");
    return;
  }
  if (channel == ChannelKind::fuel_rate) {
    notes.push_back("hvac_ambient not tested: fuel channel (a combustion car heats its cabin from the coolant)");
    return;
  }
  a.hvac_testable = std::any_of(a.ambient_k.begin(), a.ambient_k.end(), [](double t) { return hvac_law_k(t, 1.0) > 0.0; });
  notes.push_back(a.hvac_testable ? "hvac_ambient tested across " + std::to_string(a.ambient_k.size()) +
                                        " recordings: each trip's constant electrical load regressed on its ambient"
                                  : "hvac_ambient not tested: every recorded ambient is within its dead band (" +
                                        fixed(hvac_default_c("heat_below_c"), 0) + " to " +
                                        fixed(hvac_default_c("cool_above_c"), 0) + " degC)");
}

// hvac_ambient: a constant electrical load per trip, k_heat times the law at the trip's ambient, so per unit k_heat
// aux_load's constant signature (per W, run through the powertrain) times the law on each recording's windows. The
// ratio of cooling to heating per K is a shape from a grid: heating only, an A/C at half or at the heater's power
// per K (a heat pump's).
void add_hvac_candidates(const AmbientSetting& amb, const Observations& o, std::vector<Candidate>& cands) {
  const auto aux = std::find_if(cands.begin(), cands.end(), [](const Candidate& c) { return c.id == EffectId::aux_load && c.shape.empty(); });
  if (aux == cands.end()) return;
  const Eigen::VectorXd& per_w = aux->signature;
  const EffectInfo& info = effect_info(EffectId::hvac_ambient);
  for (double ratio : {0.0, 0.5, 1.0}) {
    Candidate c;
    c.id = info.id;
    c.amplitude = &info.amplitude();
    c.across_trips = Candidate::TripLaw::aux_level;
    c.cool_per_heat = ratio;
    c.shape = {{"heat_below_c", hvac_default_c("heat_below_c")}, {"cool_above_c", hvac_default_c("cool_above_c")},
               {"ambient_temp_c", 21.0}};
    c.label = info.name + " (cool_w_per_k " + num(ratio) + " x heat_w_per_k)";
    c.level_signature = per_w;
    for (double t : amb.ambient_k) c.trip_law.push_back(hvac_law_k(t, ratio));
    c.signature.resize(o.n());
    for (Eigen::Index w = 0; w < o.n(); ++w) c.signature[w] = per_w[w] * c.trip_law[o.windows[static_cast<std::size_t>(w)].rec];
    if (c.signature.norm() > 0.0) cands.push_back(std::move(c));
  }
}

}  // namespace

// Ambient temperature on RRC moves the RRC level from trip to trip, never within one: within one trip it is the
// RRC level (a calibration quantity). It is a candidate only across recordings whose recorded ambients differ.
AmbientSetting ambient_setting(const std::vector<Recording>& recordings, ChannelKind channel, const DiagnoseOptions& opt,
                               std::vector<std::string>& notes) {
  AmbientSetting a;
  if (recordings.size() < 2) {
    notes.push_back("ambient_rrc not tested: one recording (within one trip it is the RRC level, a calibration quantity)");
    notes.push_back("hvac_ambient not tested: one recording (within one trip the ambient is constant, and so is its "
                    "load: a constant aux_load)");
    return a;
  }
  if (!std::all_of(recordings.begin(), recordings.end(), [](const Recording& r) { return r.ambient_temp_k.has_value(); })) {
    // Some with it and some without is likely a slip, and leaves the laws the others could show untested: said.
    std::string without;
    std::size_t with = 0;
    for (const auto& r : recordings) {
      if (r.ambient_temp_k) ++with;
      else without += (without.empty() ? "" : ", ") + r.source;
    }
    if (with > 0)
      notes.push_back("warning: ambient_rrc and hvac_ambient not tested: " + without + " ha" +
                      (recordings.size() - with > 1 ? "ve" : "s") + " no ambient_temp_c column, where the other " +
                      std::to_string(with) + " recording" + (with > 1 ? "s do" : " does") +
                      " (give it, or leave those out, to test the ambient laws)");
    notes.push_back("ambient_rrc not tested: not every recording has an ambient_temp_c column");
    notes.push_back("hvac_ambient not tested: not every recording has an ambient_temp_c column");
    return a;
  }
  for (const auto& r : recordings) {
    double sum = 0.0;
    for (double t : *r.ambient_temp_k) sum += t;
    a.ambient_k.push_back(sum / static_cast<double>(std::max<std::size_t>(1, r.ambient_temp_k->size())));
  }
  const auto [lo, hi] = std::minmax_element(a.ambient_k.begin(), a.ambient_k.end());
  a.testable = *hi - *lo >= opt.ambient_min_spread_k;
  notes.push_back(a.testable ? "ambient_rrc tested across " + std::to_string(recordings.size()) + " recordings at " +
                                   fixed(*lo - units::kKelvinOffset, 1) + " to " + fixed(*hi - units::kKelvinOffset, 1) + " degC (one shared RRC level)"
                             : "ambient_rrc not tested: recorded ambients span " + fixed(*hi - *lo, 1) + " K, under " +
                                   fixed(opt.ambient_min_spread_k, 1) + " K (the recordings are at the same ambient)");
  // Reference: the recordings' mean ambient, so that the ambient signature is nearly orthogonal to the shared RRC
  // level (whose prior would otherwise push a level offset into the unpenalised ambient coefficient).
  for (double t : a.ambient_k) a.reference_k += t / static_cast<double>(a.ambient_k.size());
  note_hvac_setting(a, channel, opt, notes);
  return a;
}

Signatures compute_signatures(const Replayer& rp, const Observations& o, const Variant& base, double lag_samples,
                              const AmbientSetting& amb, const EffectContext& ctx, const DiagnoseOptions& opt) {
  Signatures s;
  s.base = base;
  std::vector<EffectList> extras{{std::make_shared<RrcLevel>(0.1)}, {std::make_shared<DragScale>(0.1, ctx.rho_cda_kg_per_m)}};
  std::vector<double> nominal_of_run;
  const bool any_cold_start = std::any_of(rp.cycles.begin(), rp.cycles.end(), [](const DriveCycle& c) { return !c.engine_hot_start; });
  for (const auto& info : effect_catalogue()) {
    const EffectParameterInfo& amp = info.amplitude();
    if (info.id == EffectId::ambient_rrc) {
      if (!amb.testable) continue;
      Candidate c;
      c.id = info.id;
      c.label = info.name;
      c.shape = {{"reference_temp_c", amb.reference_k - units::kKelvinOffset}, {"ambient_temp_c", amb.reference_k - units::kKelvinOffset}};
      c.amplitude = &amp;
      c.across_trips = Candidate::TripLaw::rrc_level;
      s.candidates.push_back(std::move(c));
      continue;
    }
    if (info.id == EffectId::hvac_ambient) continue;  // from aux_load's constant variant, below
    if (info.id == EffectId::wind_heading) {
      if (headings_known(rp.cycles)) add_bearing_candidates(info, ctx, extras, s.candidates);
      continue;
    }
    for (const auto& shape : shapes_of(info, o.channel, rp.vehicle.battery() != nullptr, any_cold_start)) {
      Candidate c;
      c.id = info.id;
      c.shape = shape;
      c.amplitude = &amp;
      c.label = info.name;
      for (const auto& [k, v] : shape) c.label += " (" + k + " " + num(v) + ")";
      EffectParameters p = shape;
      p[amp.name] = amp.nominal;
      extras.push_back({make_effect(info.id, p, ctx)});
      s.candidates.push_back(std::move(c));
    }
  }
  std::vector<double> decays{0.0};
  decays.insert(decays.end(), opt.unexplained_decay_s.begin(), opt.unexplained_decay_s.end());
  for (double tau : decays) {
    for (ForceShape fs : {ForceShape::constant, ForceShape::speed, ForceShape::speed_squared, ForceShape::positive_accel}) {
      s.basis.push_back({BasisShape::force, fs, tau, {}, {}});
      extras.push_back({signature_force(fs, tau)});
    }
    s.basis.push_back({BasisShape::power, ForceShape::constant, tau, {}, {}});  // computed directly, no simulation
  }
  std::vector<Variant> vars = rp.run(extras, o, lag_samples);
  s.rrc = std::move(vars[0]);
  s.drag = std::move(vars[1]);
  std::size_t k = 2;
  std::vector<Candidate> kept;
  for (auto& c : s.candidates) {
    if (c.across_trips == Candidate::TripLaw::rrc_level) {
      // RRC factor 1 + c (T_ref - T_r) on recording r: per unit c, (T_ref - T_r) times the RRC-level signature
      // (the variant is +10 % RRC; rolling energy is linear in the RRC factor to first order).
      c.signature.resize(o.n());
      for (Eigen::Index w = 0; w < o.n(); ++w)
        c.signature[w] = (amb.reference_k - amb.ambient_k[o.windows[static_cast<std::size_t>(w)].rec]) *
                         (s.rrc.window_j[w] - base.window_j[w]) / 0.1;
      kept.push_back(std::move(c));
      continue;
    }
    if (c.mixed_bearing) {
      // The north and east runs are the next two; every bearing's candidate (consecutive) mixes them.
      const Variant& north = vars[k];
      const Variant& east = vars[k + 1];
      mix_bearing(c, base, north, east);
      const bool last = &c == &s.candidates.back() || !(&c + 1)->mixed_bearing;
      if (last) k += 2;
      if (c.signature.norm() > 0.0) kept.push_back(std::move(c));
      continue;
    }
    c.signature = (vars[k].window_j - base.window_j) / c.amplitude->nominal;
    c.power_w = std::move(vars[k++].power_w);
    if (c.signature.norm() > 0.0) kept.push_back(std::move(c));
  }
  s.candidates = std::move(kept);
  if (amb.hvac_testable) add_hvac_candidates(amb, o, s.candidates);
  for (auto& b : s.basis) {
    if (b.kind == BasisShape::force) {
      b.signature = vars[k].window_j - base.window_j;
      b.power_w = std::move(vars[k++].power_w);
    } else {
      b.signature = power_signature(o, rp.cycles, b.decay_s);
    }
  }
  return s;
}

}  // namespace rollsim::diag
