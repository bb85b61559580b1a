#include <cmath>

#include "powertrain_readers.hpp"
#include "rollsim/common/error.hpp"
#include "rollsim/common/units.hpp"

namespace rollsim {
namespace {

using units::kRadpsPerRpm;

double rpm(YamlMap& m, const std::string& key) { return m.number(key, Range::open_low(0.0, 3e4)) * kRadpsPerRpm; }
double pct(YamlMap& m, const std::string& key, double fallback_pct) {
  return m.number_or(key, fallback_pct, Range::closed(0.0, 100.0)) / 100.0;
}

}  // namespace

EngineMapParams read_engine_block(YamlMap m) {
  EngineMapParams e;
  e.displacement_m3 = m.number("displacement_l", Range::closed(0.05, 30.0)) * units::kM3PerLitre;  // as vehicle.cpp
  e.indicated_efficiency = m.number("gross_indicated_efficiency", Range::open_low(0.0, 0.6));
  // Friction mep f0 + f1 N + f2 N^2 with N in 1000 rpm, as Heywood writes eq. 13.19.
  const double per_krpm = 1000.0 * kRadpsPerRpm;
  e.friction_mep0_pa = units::bar_to_pa(m.number("friction_mep_bar", Range::closed(0.0, 10.0)));
  e.friction_mep1_pa_s_per_rad = units::bar_to_pa(m.number_or("friction_mep_bar_per_krpm", 0.0, Range::closed(0.0, 5.0))) / per_krpm;
  e.friction_mep2_pa_s2_per_rad2 =
      units::bar_to_pa(m.number_or("friction_mep_bar_per_krpm2", 0.0, Range::closed(0.0, 1.0))) / (per_krpm * per_krpm);
  e.pumping_mep_closed_pa = units::bar_to_pa(m.number_or("pumping_mep_closed_throttle_bar", 0.0, Range::closed(0.0, 1.0)));
  e.unthrottled_imep_pa = units::bar_to_pa(m.number_or("unthrottled_imep_bar", 11.0, Range::open_low(0.0, 40.0)));
  e.enrichment_start_fraction = pct(m, "enrichment_start_load_pct", 100.0);
  e.enrichment_max = pct(m, "enrichment_at_full_load_pct", 0.0);
  e.knock_start_fraction = pct(m, "knock_start_load_pct", 100.0);
  e.knock_efficiency_loss_max = pct(m, "knock_efficiency_loss_at_full_load_pct", 0.0);
  e.idle_speed_radps = rpm(m, "idle_speed_rpm");
  e.rated_speed_radps = rpm(m, "rated_speed_rpm");
  e.max_speed_radps = rpm(m, "max_speed_rpm");
  e.max_torque_nm = m.number("max_torque_nm", Range::open_low(0.0, 1e5));
  e.max_power_w = m.number("max_power_kw", Range::open_low(0.0, 5000.0)) * 1e3;
  e.fuel_cut_min_speed_radps = m.number_or("fuel_cut_min_speed_rpm", 1.2 * e.idle_speed_radps / kRadpsPerRpm,
                                           Range::closed(0.0, 3e4)) * kRadpsPerRpm;
  e.fuel_cut_min_vehicle_speed_mps = units::kmh_to_mps(m.number_or("fuel_cut_min_vehicle_speed_kmh", 0.0, Range::closed(0.0, 200.0)));
  e.idle_torque_reserve_nm = m.number_or("idle_torque_reserve_nm", 0.0, Range::closed(0.0, 100.0));
  e.inertia_kg_m2 = m.number_or("inertia_kg_m2", 0.0, Range::closed(0.0, 5.0));
  // With their values: "must exceed idle_speed_rpm" alone left the reader to look them up (session 23's outside testing).
  if (e.rated_speed_radps <= e.idle_speed_radps)
    throw InputError(m.where("rated_speed_rpm"), rpm_text(e.rated_speed_radps) + " must exceed idle_speed_rpm " + rpm_text(e.idle_speed_radps));
  if (e.max_speed_radps < e.rated_speed_radps)
    throw InputError(m.where("max_speed_rpm"), rpm_text(e.max_speed_radps) + " must be at least rated_speed_rpm " + rpm_text(e.rated_speed_radps));
  if (e.enrichment_start_fraction >= 1.0 && e.enrichment_max > 0.0)
    throw InputError(m.where("enrichment_start_load_pct"), "must be below 100 when enrichment_at_full_load_pct is given");
  if (e.knock_start_fraction >= 1.0 && e.knock_efficiency_loss_max > 0.0)
    throw InputError(m.where("knock_start_load_pct"), "must be below 100 when knock_efficiency_loss_at_full_load_pct is given");
  m.finish();
  return e;
}

namespace {

TransmissionKind transmission_kind(YamlMap& m) {
  const std::string kind = m.string("kind");
  if (kind == "automatic") return TransmissionKind::automatic;
  if (kind == "cvt") return TransmissionKind::cvt;
  if (kind == "manual" || kind == "dual_clutch") return TransmissionKind::clutch;
  throw InputError(m.where("kind"), "'" + kind + "' is not allowed: must be automatic, cvt, manual or dual_clutch");
}

TorqueConverterParams read_converter(YamlMap m, double max_torque_nm) {
  TorqueConverterParams c;
  // K from the stall speed at full-load torque: a stalled pump absorbs (w / K)^2.
  c.k_factor_radps_per_sqrt_nm = rpm(m, "stall_speed_rpm") / std::sqrt(max_torque_nm);
  c.stall_torque_ratio = m.number_or("stall_torque_ratio", 2.0, Range::closed(1.0, 4.0));
  c.coupling_speed_ratio = m.number_or("coupling_speed_ratio", 0.85, Range::open_low(0.0, 0.99));
  const double lockup_gear = m.number_or("lockup_min_gear", 2.0, Range::closed(1.0, 20.0));
  if (lockup_gear != std::floor(lockup_gear)) throw InputError(m.where("lockup_min_gear"), format_value(lockup_gear) + " is not a gear number (1, 2, ...)");
  c.lockup_min_gear = static_cast<int>(lockup_gear);
  c.lockup_min_speed_radps = m.number_or("lockup_min_speed_rpm", 1000.0, Range::closed(0.0, 1e4)) * kRadpsPerRpm;
  c.neutral_at_standstill = m.boolean_or("neutral_at_standstill", false);
  m.finish();
  return c;
}

TransmissionParams read_transmission(YamlMap m, double max_torque_nm) {
  TransmissionParams t;
  t.kind = transmission_kind(m);
  const auto gears = m.numbers("ratios", Range::closed(0.1, 30.0));
  const double final_drive = m.number("final_drive_ratio", Range::closed(0.1, 30.0));
  if (t.kind == TransmissionKind::cvt && gears.size() != 2)
    throw InputError(m.where("ratios"), "a CVT gives exactly two ratios, its lowest gear and its overdrive");
  check_ratios_fall(gears, m.where("ratios"));
  for (double g : gears) t.ratios.push_back(g * final_drive);
  t.efficiency = m.number("efficiency", Range::efficiency());
  t.spin_loss_nm = m.number_or("spin_loss_nm", 0.0, Range::closed(0.0, 200.0));
  t.min_engine_speed_radps = rpm(m, "min_engine_speed_rpm");
  t.max_torque_fraction = m.number("max_load_pct", Range::open_low(0.0, 100.0)) / 100.0;
  if (t.kind == TransmissionKind::clutch) {
    if (m.has("converter")) throw InputError(m.where("converter"), "a manual or dual-clutch gearbox has no torque converter");
    t.launch_engine_speed_radps = m.number_or("launch_engine_speed_rpm", 0.0, Range::closed(0.0, 1e4)) * kRadpsPerRpm;
  } else {
    if (m.has("launch_engine_speed_rpm"))
      throw InputError(m.where("launch_engine_speed_rpm"), "only a manual or dual-clutch gearbox launches on a slipping clutch");
    YamlMap converter = m.map("converter");
    t.converter = read_converter(converter, max_torque_nm);
    // A lock-up gear above the top gear never locks: the converter slips all the way (NEDC +11 % fuel, accepted in
    // silence until session 20). A CVT has one "gear".
    const int top = t.kind == TransmissionKind::cvt ? 1 : static_cast<int>(gears.size());
    if (t.converter.lockup_min_gear > top)
      throw InputError(converter.where("lockup_min_gear"), std::to_string(t.converter.lockup_min_gear) +
                                                              " is not allowed: must be in [1, " + std::to_string(top) +
                                                              "], the gearbox's gears");
  }
  m.finish();
  return t;
}

}  // namespace

ConventionalPowertrainParams read_engine_map_powertrain(YamlMap& pt) {
  ConventionalPowertrainParams p;
  p.engine = read_engine_block(pt.map("engine"));
  p.transmission = read_transmission(pt.map("transmission"), p.engine.max_torque_nm);
  p.fuel = read_fuel(pt.map("fuel"));
  p.aux_power_w = read_aux_power_w(pt);
  p.alternator_efficiency = pt.number_or("alternator_efficiency", 1.0, Range::efficiency());
  check_engine_carries_accessories(p.engine.max_power_w, p.aux_power_w, p.alternator_efficiency, pt.map("engine").where("max_power_kw"));
  return p;
}

}  // namespace rollsim
