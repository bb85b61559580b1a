#include "rollsim/vehicle/vehicle.hpp"
#include "rollsim/effects/catalogue.hpp"

#include <cmath>
#include <filesystem>
#include <numbers>

#include "rollsim/common/error.hpp"
#include "rollsim/common/text.hpp"
#include "rollsim/common/format.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/tyre/tyre_model.hpp"
#include "rollsim/vehicle/vehicle_file.hpp"
#include "powertrain_readers.hpp"

namespace rollsim {
namespace {

constexpr double kRadPerSPerRpm = 2.0 * std::numbers::pi / 60.0;

// A tyre named in a vehicle file: relative to the vehicle file first, then the shipped tyres/ folder.
TyreSpec load_tyre_named(const std::string& name, const YamlMap& m, const std::string& key) {
  return load_tyre_file(resolve_tyre_path(name, m.file(), m.where(key)));
}

// A value no road vehicle has (from a 350 kg quadricycle to a 60 t road train) is a unit slip. It is refused at its
// own key, naming what is physical and the unit it would fit in, before a check combining it with another key
// (rotating mass, the tyres' domain, the battery's power) would blame that key instead.
double for_road_vehicle(const YamlMap& m, const std::string& key, double v, Range physical, const std::string& unit,
                        const std::string& why, std::initializer_list<UnitSlip> slips) {
  check_physical(v, physical, unit, why, slips, m.where(key));
  return v;
}

BodyParams read_body(YamlMap m) {
  BodyParams b;
  b.test_mass_kg = m.number("test_mass_kg", Range::open_low(0.0, 1e5));
  for_road_vehicle(m, "test_mass_kg", b.test_mass_kg, Range::closed(100.0, 1e5), "kg",
                   "no four-wheeled road vehicle is that light (a light quadricycle with its driver weighs 350 kg or more)", {{"t", 1e3}});
  b.rotating_mass_kg = m.number_or("rotating_mass_kg", 0.0, Range::closed(0.0, b.test_mass_kg));
  b.drag_coefficient = m.number("drag_coefficient", Range::open_low(0.0, 2.0));
  // Bounded by the physical check alone, whose unit hint a hard 20 m^2 had hidden from a car's 20-27 ft^2 (session 25).
  b.frontal_area_m2 = m.number("frontal_area_m2", Range::positive());
  for_road_vehicle(m, "frontal_area_m2", b.frontal_area_m2, Range::open_low(0.0, 12.0), "m^2",
                   "no road vehicle is that large in front (2.6 m wide and 4.6 m high at most: 12 m^2)", {{"ft^2", 0.09290304}});
  b.air_density_kg_per_m3 = m.number_or("air_density_kg_per_m3", 1.2, Range::open_low(0.0, 2.0));
  b.front_axle_load_fraction = m.number_or("front_axle_load_fraction", 0.5, Range::fraction());
  const std::string axle = m.string_or("driven_axle", "front");
  if (axle == "front") {
    b.driven_axle = DrivenAxle::front;
  } else if (axle == "rear") {
    b.driven_axle = DrivenAxle::rear;
  } else if (axle == "all") {
    b.driven_axle = DrivenAxle::all;
  } else {
    throw InputError(m.where("driven_axle"), "'" + axle + "' is not allowed: must be front, rear or all");
  }
  b.wheel_radius_m = m.number_or("wheel_radius_m", 0.0, Range::closed(0.0, 1.0));
  m.finish();
  return b;
}

// With tyres, the driven tyre's rolling radius gears the car; a wheel radius beside them would be read and ignored,
// and a user who copied it from a coast-down car would believe the gearing used it.
[[noreturn]] void reject_wheel_radius_beside_tyres(const Vehicle& v, const std::string& where) {
  const TyreSpec& driven = v.body.driven_axle == DrivenAxle::rear ? *v.rear_tyre : *v.front_tyre;
  throw InputError(where, format_value(v.body.wheel_radius_m) + " m is not allowed beside tyres: the tyres gear the car "
                          "(the driven tyre '" + driven.name + "', outer radius " + fixed(driven.state.geometry.outer_radius_m, 3) +
                          " m); wheel_radius_m is only for a car without tyres (coast-down road load): remove it, or the tyres");
}

// C is the body's drag, 0.5 rho Cd A: a car's or a van's Cd A is 0.5-2 m^2, a lorry's or a bus's up to ~6 m^2. A C
// typed per (m/s)^2 into c_n_per_kmh2 (13 x too large) read as a car with the drag of three lorries, unwarned
// (session 22's notes). Warned, not refused: the file may describe an odd vehicle.
void warn_implausible_coastdown_c(const YamlMap& m, const CoastdownParams& c, double test_mass_kg, std::vector<std::string>& warnings) {
  constexpr double kAirDensity_kg_per_m3 = 1.2;
  const double cda_m2 = c.c_n_s2_per_m2 / (0.5 * kAirDensity_kg_per_m3);
  const bool light = test_mass_kg < 3500.0;
  const double most_m2 = light ? 2.5 : 10.0;
  if (cda_m2 <= most_m2) return;
  const bool us = m.has("c_lbf_per_mph2");
  const std::string drag = " is the drag of Cd A = " + fixed(cda_m2, 1) + " m^2 at " + format_value(kAirDensity_kg_per_m3) +
                           " kg/m^3, more than any " + (light ? "car or van" : "road vehicle") + " of " +
                           format_value(std::round(test_mass_kg)) + " kg (up to " + format_value(most_m2) + " m^2)";
  if (us) {
    const double lbf_per_mph2 = c.c_n_s2_per_m2 / units::kNPerLbf * units::kMpsPerMph * units::kMpsPerMph;
    warnings.push_back(m.where("c_lbf_per_mph2") + ": " + format_value(lbf_per_mph2) + " lbf/mph^2" + drag);
    return;
  }
  const double per_kmh2 = c.c_n_s2_per_m2 * units::kMpsPerKmh * units::kMpsPerKmh;
  warnings.push_back(m.where("c_n_per_kmh2") + ": " + format_value(per_kmh2) + " N/(km/h)^2" + drag + "; is it per (m/s)^2? (" +
                     format_value(per_kmh2) + " N/(m/s)^2 = " + significant(per_kmh2 * units::kMpsPerKmh * units::kMpsPerKmh, 3) +
                     " N/(km/h)^2)");
}

CoastdownParams read_coastdown(YamlMap m) {
  CoastdownParams c;
  const bool us = m.has("a_lbf") || m.has("b_lbf_per_mph") || m.has("c_lbf_per_mph2");
  if (us) {
    using units::kNPerLbf, units::kMpsPerMph;
    c.a_n = m.number("a_lbf", Range::closed(0.0, 1e4)) * kNPerLbf;
    c.b_n_s_per_m = m.number("b_lbf_per_mph", Range::closed(-50.0, 50.0)) * kNPerLbf / kMpsPerMph;
    c.c_n_s2_per_m2 = m.number("c_lbf_per_mph2", Range::closed(0.0, 10.0)) * kNPerLbf / (kMpsPerMph * kMpsPerMph);
  } else {
    c.a_n = m.number("a_n", Range::closed(0.0, 5e4));
    c.b_n_s_per_m = m.number("b_n_per_kmh", Range::closed(-50.0, 50.0)) / units::kMpsPerKmh;
    c.c_n_s2_per_m2 = m.number("c_n_per_kmh2", Range::closed(0.0, 1.0)) / (units::kMpsPerKmh * units::kMpsPerKmh);
  }
  m.finish();
  return c;
}

// A battery gives at most Voc^2 / 4R. One that cannot carry the auxiliaries and the machine's no-load loss at its
// top speed leaves no drive the car could follow there, not even coasting (a replay had no power flow to report).
void check_battery_carries_no_load(const ElectricPowertrainParams& p, const std::string& resistance_key) {
  const double r = p.battery.internal_resistance_ohm;
  if (r <= 0.0) return;
  const auto& l = p.motor.losses;
  const double w = p.motor.max_speed_radps;
  const double no_load_w = l.efficiency.empty() ? l.iron_w_s_per_rad * w + l.windage_w_s3_per_rad3 * w * w * w + l.constant_w : 0.0;
  const double needed_w = p.aux_power_w + no_load_w;
  const double voc = p.battery.open_circuit_voltage_v;
  if (voc * voc / (4.0 * r) > needed_w) return;
  throw InputError(resistance_key, format_value(r) + " ohm is not allowed: at " + format_value(voc) +
                                       " V the battery gives at most Voc^2/4R = " + fixed(voc * voc / (4.0 * r) / 1e3, 2) +
                                       " kW, not even the auxiliaries and the machine's no-load loss at its top speed (" +
                                       fixed(needed_w / 1e3, 2) + " kW); allowed: below " +
                                       significant(voc * voc / (4.0 * needed_w), 3) + " ohm");
}

ElectricPowertrainParams read_electric(YamlMap& pt, std::vector<std::string>& warnings) {
  ElectricPowertrainParams p;
  {
    YamlMap m = pt.map("motor");
    p.motor.max_torque_nm = m.number("max_torque_nm", Range::open_low(0.0, 1e5));
    p.motor.max_power_w = m.number("max_power_kw", Range::open_low(0.0, 5000.0)) * 1e3;
    p.motor.max_speed_radps = m.number("max_speed_rpm", Range::open_low(0.0, 1e5)) * kRadPerSPerRpm;
    p.motor.speed_limit_band_fraction = m.number_or("speed_limit_band_pct", 3.0, Range::closed(0.0, 50.0)) / 100.0;
    p.motor.losses.copper_w_per_nm2 = m.number("copper_loss_w_per_nm2", Range::closed(0.0, 100.0));
    p.motor.losses.iron_w_s_per_rad = m.number("iron_loss_w_per_radps", Range::closed(0.0, 1e4));
    p.motor.losses.windage_w_s3_per_rad3 = m.number_or("windage_loss_w_per_radps3", 0.0, Range::closed(0.0, 1.0));
    p.motor.losses.constant_w = m.number_or("constant_loss_w", 0.0, Range::closed(0.0, 1e5));
    m.finish();
  }
  {
    YamlMap m = pt.map("reduction");
    p.reduction.ratio = m.number("ratio", Range::closed(0.1, 100.0));
    p.reduction.efficiency = m.number("efficiency", Range::efficiency());
    m.finish();
  }
  std::string resistance_key;
  {
    YamlMap m = pt.map("battery");
    p.battery.open_circuit_voltage_v = m.number("open_circuit_voltage_v", Range::open_low(0.0, 2000.0));
    for_road_vehicle(m, "open_circuit_voltage_v", p.battery.open_circuit_voltage_v, Range::closed(2.0, 2000.0), "V",
                     "below a single cell's voltage (2-4 V); a traction battery has tens to hundreds of volts", {{"kV", 1e3}});
    p.battery.internal_resistance_ohm = m.number("internal_resistance_ohm", Range::closed(0.0, 100.0));
    resistance_key = m.where("internal_resistance_ohm");
    const double capacity_kwh = m.number("usable_capacity_kwh", Range::open_low(0.0, 1e4));
    for_road_vehicle(m, "usable_capacity_kwh", capacity_kwh, Range::closed(0.1, 1e4), "kWh",
                     "below any traction battery (a hybrid car's holds 0.5-2 kWh, a light quadricycle's 6)", {{"MWh", 1e3}});
    p.battery.usable_capacity_j = units::kwh_to_j(capacity_kwh);
    const double initial_pct = m.number_or("initial_soc_pct", 100.0, Range::closed(0.0, 100.0));
    p.battery.initial_soc = initial_pct / 100.0;
    // A start below 1 % is possible (a drive to empty) but is far more often a fraction typed for a percentage. (The
    // figures are the value as given: 0.9 printed as 0.9000000000000001 through the fraction.)
    if (initial_pct > 0.0 && initial_pct <= 1.0)
      warnings.push_back(m.where("initial_soc_pct") + ": " + format_value(initial_pct) +
                         " % is a battery all but empty at the start; is it a fraction? (" + format_value(initial_pct) +
                         " = " + format_value(100.0 * initial_pct) + " %)");
    m.finish();
  }
  {
    YamlMap m = pt.map("regen");
    p.regen.max_power_w = m.number("max_power_kw", Range::closed(0.0, 5000.0)) * 1e3;
    p.regen.driven_axle_brake_fraction = m.number("driven_axle_brake_fraction", Range::fraction());
    p.regen.min_speed_mps = units::kmh_to_mps(m.number_or("min_speed_kmh", 0.0, Range::closed(0.0, 100.0)));
    p.regen.fade_speed_mps = units::kmh_to_mps(m.number_or("fade_speed_kmh", units::mps_to_kmh(p.regen.min_speed_mps), Range::closed(0.0, 200.0)));
    if (p.regen.fade_speed_mps < p.regen.min_speed_mps)
      throw InputError(m.where("fade_speed_kmh"), format_value(units::mps_to_kmh(p.regen.fade_speed_mps)) + " km/h must be >= min_speed_kmh " +
                                                     format_value(units::mps_to_kmh(p.regen.min_speed_mps)) + " km/h");
    m.finish();
  }
  p.aux_power_w = read_aux_power_w(pt);
  check_battery_carries_no_load(p, resistance_key);
  return p;
}

// The road speed at which the engine reaches its rated speed in `ratio` (gear times final drive), on a wheel of
// `radius_m` (the driven tyre's unloaded radius: its rolling radius is smaller, so the engine is slower here).
double top_speed_in_gear_mps(double max_speed_radps, double ratio, double radius_m) { return max_speed_radps * radius_m / ratio; }

// `driven_radius_m`: the driven wheels' radius, which with the gearing says where each gear runs out of revs.
CombustionPowertrainParams read_combustion(YamlMap& pt, double driven_radius_m, std::vector<std::string>& warnings) {
  CombustionPowertrainParams p;
  std::string max_power_where;
  {
    YamlMap m = pt.map("engine");
    auto& e = p.engine;
    // From a 50 cc moped's to a heavy truck's: 0.0016 (m^3 typed as litres) ran at a bmep of 12,000 bar (session 22).
    e.displacement_m3 = m.number("displacement_l", Range::closed(0.05, 30.0)) * units::kM3PerLitre;
    e.indicated_efficiency = m.number("indicated_efficiency", Range::open_low(0.0, 0.6));
    e.friction_mep_pa = m.number("friction_mep_bar", Range::closed(0.0, 20.0)) * units::kPaPerBar;
    // A running engine's friction mep is 0.4-2.5 bar at low speed (Heywood fig. 13-13; EPA's A25A-FKS map: 0.45
    // without pumping); 0.097 ran as a tenth of the friction, unwarned (session 22's notes). 0 stays silent: a Willans
    // line with the friction left out on purpose.
    if (const double bar = e.friction_mep_pa / units::kPaPerBar; bar > 0.0 && bar < 0.3)
      warnings.push_back(m.where("friction_mep_bar") + ": " + format_value(bar) +
                         " bar is below any running engine's friction (0.4-2.5 bar at low speed); is it in MPa? (" +
                         format_value(bar) + " MPa = " + format_value(10.0 * bar) + " bar)");
    e.friction_mep_pa_s_per_rad =
        m.number_or("friction_mep_bar_per_1000rpm", 0.0, Range::closed(0.0, 10.0)) * units::kPaPerBar / (1000.0 * kRadPerSPerRpm);
    e.idle_speed_radps = m.number("idle_speed_rpm", Range::open_low(0.0, 1e4)) * kRadPerSPerRpm;
    e.max_speed_radps = m.number("max_speed_rpm", Range::open_low(0.0, 1e5)) * kRadPerSPerRpm;
    e.max_torque_nm = m.number("max_torque_nm", Range::open_low(0.0, 1e5));
    e.max_power_w = m.number("max_power_kw", Range::open_low(0.0, 5000.0)) * 1e3;
    max_power_where = m.where("max_power_kw");
    e.fuel_cut_min_speed_radps = m.number_or("fuel_cut_min_speed_rpm", 1.2 * e.idle_speed_radps / kRadPerSPerRpm,
                                             Range::closed(0.0, 1e5)) * kRadPerSPerRpm;
    if (e.max_speed_radps <= e.idle_speed_radps)
      throw InputError(m.where("max_speed_rpm"), rpm_text(e.max_speed_radps) + " must exceed idle_speed_rpm " + rpm_text(e.idle_speed_radps));
    m.finish();
  }
  {
    YamlMap m = pt.map("gearbox");
    auto& g = p.gearbox;
    g.ratios = m.numbers("ratios", Range::closed(0.1, 100.0));
    // As the engine-map reader refuses it: [3.73, 1.32, 2.05, ...] ran silently (session 22's outside testing).
    check_ratios_fall(g.ratios, m.where("ratios"));
    g.final_drive_ratio = m.number("final_drive_ratio", Range::closed(0.1, 100.0));
    g.efficiency = m.number("efficiency", Range::efficiency());
    const std::size_t shifts = g.ratios.size() - 1;
    auto up = m.numbers("upshift_speeds_kmh", Range::open_low(0.0, 500.0), shifts);
    auto down = m.numbers("downshift_speeds_kmh", Range::open_low(0.0, 500.0), shifts);
    if (up.size() != shifts || down.size() != shifts)
      throw InputError(m.where(up.size() != shifts ? "upshift_speeds_kmh" : "downshift_speeds_kmh"),
                       "has " + std::to_string(up.size() != shifts ? up.size() : down.size()) + " speeds; " +
                           std::to_string(g.ratios.size()) + " gear ratios have " + std::to_string(shifts) +
                           " shifts, one speed each, up and down");
    for (std::size_t i = 0; i < shifts; ++i) {
      // The upshifts' order first: [16, 48, 33, 65] was blamed on the downshift speeds (session 22).
      if (i > 0 && up[i] <= up[i - 1])
        throw InputError(m.where("upshift_speeds_kmh"), "upshift " + std::to_string(i + 1) + " at " + format_value(up[i]) +
                                                            " km/h is not above upshift " + std::to_string(i) + " at " +
                                                            format_value(up[i - 1]) + " km/h: must increase gear by gear");
      if (down[i] >= up[i])
        throw InputError(m.where("downshift_speeds_kmh"), "downshift speed " + format_value(down[i]) +
                                                              " km/h must be below the upshift speed " + format_value(up[i]) + " km/h");
      // A gear held past its top speed would turn the engine beyond its rated speed (this model has no rev limiter).
      const double top_mps = top_speed_in_gear_mps(p.engine.max_speed_radps, g.ratios[i] * g.final_drive_ratio, driven_radius_m);
      if (units::kmh_to_mps(up[i]) > top_mps) {
        throw InputError(m.where("upshift_speeds_kmh"), "upshift from gear " + std::to_string(i + 1) + " at " +
                                                            format_value(up[i]) + " km/h is past the gear's top speed, " +
                                                            fixed(units::mps_to_kmh(top_mps), 1) + " km/h at max_speed_rpm on the " +
                                                            fixed(driven_radius_m, 3) + " m driven wheel: shift up by then");
      }
      g.upshift_speeds_mps.push_back(units::kmh_to_mps(up[i]));
      g.downshift_speeds_mps.push_back(units::kmh_to_mps(down[i]));
    }
    m.finish();
  }
  p.fuel = read_fuel(pt.map("fuel"));
  p.aux_power_w = read_aux_power_w(pt);
  p.alternator_efficiency = pt.number_or("alternator_efficiency", 1.0, Range::efficiency());
  check_engine_carries_accessories(p.engine.max_power_w, p.aux_power_w, p.alternator_efficiency, max_power_where);
  return p;
}

}  // namespace

void check_ratios_fall(const std::vector<double>& ratios, const std::string& where) {
  for (std::size_t i = 1; i < ratios.size(); ++i) {
    if (ratios[i] >= ratios[i - 1])
      throw InputError(where, "gear " + std::to_string(i + 1) + "'s " + format_value(ratios[i]) + " is not below gear " + std::to_string(i) +
                                  "'s " + format_value(ratios[i - 1]) + ": must fall from first gear to top gear");
  }
}

std::string rpm_text(double radps) { return format_value(std::round(radps / kRadPerSPerRpm)); }

// 0.2 kW against ice.yaml's 500 W of accessory shaft power left a negative force, -1e11 N near standstill, and CVODE
// failed at the first launch (session 22's outside testing).
void check_engine_carries_accessories(double max_power_w, double aux_power_w, double alternator_efficiency, const std::string& where) {
  const double shaft_w = aux_power_w / alternator_efficiency;
  if (max_power_w > shaft_w) return;
  throw InputError(where, format_value(max_power_w / 1e3) + " kW cannot carry the accessories: aux_power_w " + format_value(aux_power_w) +
                              " W through alternator_efficiency " + format_value(alternator_efficiency) + " takes " +
                              fixed(shaft_w / 1e3, 3) + " kW of the engine; allowed: above " + fixed(shaft_w / 1e3, 3) + " kW");
}

// Zero leaves the auxiliaries out; a few watts are no car's electrical load (its control units alone draw tens).
double read_aux_power_w(YamlMap& pt) {
  const double w = pt.number_or("aux_power_w", 0.0, Range::closed(0.0, 1e5));
  if (w == 0.0) return w;
  return for_road_vehicle(pt, "aux_power_w", w, Range::closed(10.0, 1e5), "W",
                          "a car's electrical load is tens of watts at least (its control units alone); 0 leaves it out", {{"kW", 1e3}});
}

FuelParams read_fuel(YamlMap m) {
  FuelParams f;
  f.density_kg_per_m3 = m.number("density_kg_per_l", Range::open_low(0.0, 2.0)) / units::kM3PerLitre;
  // Methanol's 20 MJ/kg to hydrogen's 120: 0.0429 (GJ/kg) read 6238 l/100 km (session 22's outside testing).
  f.lower_heating_value_j_per_kg = m.number("lower_heating_value_mj_per_kg", Range::closed(10.0, 150.0)) * 1e6;
  f.co2_kg_per_kg = m.number("co2_kg_per_kg", Range::closed(0.0, 5.0));
  m.finish();
  return f;
}

Vehicle load_vehicle_file(const std::string& path) { return load_vehicle(YamlMap::load_file(path)); }

Vehicle load_vehicle_text(const std::string& text, const std::string& name) {
  return load_vehicle(YamlMap::load_text(text, name));
}

Vehicle load_vehicle(YamlMap root) {
  const std::string path = root.file();
  Vehicle v;
  v.source = path;
  v.name = display_name(root.string_or("name", std::filesystem::path(path).stem().string()));
  root.accept("description");
  root.accept("sources");
  const YamlMap body = root.map("body");
  v.body = read_body(body);
  if (auto t = root.optional_map("tyres")) {
    // `all` beside `front` or `rear` would leave one of them unused: which tyre did the user mean?
    for (const char* axle : {"front", "rear"}) {
      if (t->has("all") && t->has(axle)) {
        throw InputError(t->where(axle), "not allowed together with 'all': give 'all' (one tyre on all four wheels) or "
                                         "'front' and 'rear' (one per axle), not both");
      }
    }
    if (t->has("all")) {
      v.front_tyre = load_tyre_named(t->string("all"), *t, "all");
      v.rear_tyre = v.front_tyre;
    } else {
      v.front_tyre = load_tyre_named(t->string("front"), *t, "front");
      v.rear_tyre = load_tyre_named(t->string("rear"), *t, "rear");
    }
    t->accept("all");
    t->accept("front");
    t->accept("rear");
    t->finish();
  }
  if (v.front_tyre && body.has("wheel_radius_m")) reject_wheel_radius_beside_tyres(v, body.where("wheel_radius_m"));
  // The tyre model rolls each axle's tyres at their share of the weight: an axle carrying (almost) nothing was refused
  // by the tyre model, naming a tyre file and not this key (session 20). Real cars put 35-65 % on the front axle.
  if (v.front_tyre && (v.body.front_axle_load_fraction < 0.1 || v.body.front_axle_load_fraction > 0.9))
    throw InputError(body.where("front_axle_load_fraction"),
                     format_value(v.body.front_axle_load_fraction) + " is not allowed with tyres: must be in [0.1, 0.9] (each "
                     "axle's tyres roll under their share of the weight; 0 and 1 are for a coast-down car)");
  if (auto c = root.optional_map("coastdown")) {
    v.coastdown = read_coastdown(*c);
    warn_implausible_coastdown_c(*c, *v.coastdown, v.body.test_mass_kg, v.warnings);
  }
  if (!v.front_tyre && !v.coastdown)
    throw InputError(root.where("tyres"), "a vehicle needs tyres (tyres: {all: FILE}) or coastdown coefficients");
  if (!v.front_tyre && !(v.body.wheel_radius_m > 0.0))
    throw InputError(root.where("body"), "without tyres, body.wheel_radius_m must be given (it sets the gearing)");

  YamlMap pt = root.map("powertrain");
  const std::string type = pt.string("type");
  if (type == "electric") {
    v.powertrain = read_electric(pt, v.warnings);
  } else if (type == "combustion") {
    const std::optional<TyreSpec>& driven = v.body.driven_axle == DrivenAxle::rear ? v.rear_tyre : v.front_tyre;
    v.powertrain = read_combustion(pt, driven ? driven->state.geometry.outer_radius_m : v.body.wheel_radius_m, v.warnings);
  } else if (type == "engine_map") {
    v.powertrain = read_engine_map_powertrain(pt);
  } else {
    throw InputError(pt.where("type"), "'" + type + "' is not allowed: must be electric, combustion or engine_map");
  }
  pt.finish();
  if (auto eff = root.optional_map("effects")) v.effects = load_effects(*eff);
  // A vehicle may name its logger's columns; the recording module reads these blocks (rollsim diagnose).
  root.accept("recording_columns");
  root.accept("recording_scale");
  root.accept("calibration_priors");  // read by the diagnosis (calibration_priors_from_yaml)
  root.finish();

  check_tyre_loads(v, path);
  return v;
}

std::vector<std::string> check_tyre_loads(const Vehicle& vehicle, const std::string& where, bool own_tyres) {
  std::vector<std::string> warnings;
  if (!vehicle.front_tyre) return warnings;
  const auto loads = wheel_loads(vehicle.body, 0.0);
  for (const auto& [tyre, load_n, axle] : {std::tuple{*vehicle.front_tyre, loads.front_n, "front"},
                                            std::tuple{*vehicle.rear_tyre, loads.rear_n, "rear"}}) {
    try {
      check_operating_point(tyre.state, load_n, 0.0);
    } catch (const ModelDomainError& e) {
      throw InputError(where + ": " + axle + " tyre '" + tyre.name + "'", e.what());
    }
    if (tyre.max_load_n > 0.0 && load_n > tyre.max_load_n) {
      // The file's own tyres loaded a third beyond their rating that would carry the mass read in pounds: it was typed
      // in pounds. A tyre put on the car (--tyre) is simply rated too low for it (the pound hint had pointed an
      // outside tester at the mass: session 27).
      const double kKgPerLb = 0.45359237;
      const double mass_kg = vehicle.body.test_mass_kg;
      const std::string lb = !own_tyres ? "; the tyre's load rating is too low for this car"
                             : load_n > 1.3 * tyre.max_load_n && load_n * kKgPerLb <= tyre.max_load_n
                                 ? "; is body.test_mass_kg in lb? (" + format_value(mass_kg) + " lb = " + significant(mass_kg * kKgPerLb, 4) + " kg)"
                                 : "";
      warnings.push_back(where + ": " + axle + " tyre '" + tyre.name + "': wheel load " + format_value(std::round(load_n)) +
                         " N exceeds its rated maximum " + format_value(std::round(tyre.max_load_n)) + " N" + lb);
    }
  }
  return warnings;
}

EffectContext effect_context(const Vehicle& vehicle) {
  const BodyParams& b = vehicle.body;
  EffectContext ctx;
  ctx.mass_kg = b.test_mass_kg;
  // A coast-down C is half of rho CdA (F = C v^2 = rho CdA v^2 / 2).
  ctx.rho_cda_kg_per_m = vehicle.coastdown ? 2.0 * vehicle.coastdown->c_n_s2_per_m2
                                           : b.air_density_kg_per_m3 * b.drag_coefficient * b.frontal_area_m2;
  if (const BatteryParams* battery = vehicle.battery()) ctx.pack_voltage_v = battery->open_circuit_voltage_v;
  return ctx;
}

void fit_tyres(Vehicle& vehicle, const TyreSpec& tyre) {
  vehicle.front_tyre = tyre;
  vehicle.rear_tyre = tyre;
}

AxleWheelLoads wheel_loads(const BodyParams& body, double grade) {
  const double normal_n = body.test_mass_kg * units::kStandardGravity_mps2 / std::sqrt(1.0 + grade * grade);
  return {normal_n * body.front_axle_load_fraction / 2.0, normal_n * (1.0 - body.front_axle_load_fraction) / 2.0};
}

double driven_wheel_radius_m(const Vehicle& vehicle) {
  if (!vehicle.front_tyre) return vehicle.body.wheel_radius_m;
  const bool rear = vehicle.body.driven_axle == DrivenAxle::rear;
  const TyreSpec& tyre = rear ? *vehicle.rear_tyre : *vehicle.front_tyre;
  const auto loads = wheel_loads(vehicle.body, 0.0);
  const double load_n = rear ? loads.rear_n : loads.front_n;
  const double deflection_m = load_n / vertical_stiffness_n_per_m(tyre.state);
  return tyre.state.geometry.outer_radius_m - deflection_m / 3.0;
}

namespace {

class TyreRoadLoad final : public RoadLoadModel {
 public:
  TyreRoadLoad(const Vehicle& v) : body_(v.body), front_(*v.front_tyre), rear_(*v.rear_tyre) {}
  RoadLoadCoeffs at_grade(double grade) const override {
    const auto loads = wheel_loads(body_, grade);
    const auto f = prepare(front_, loads.front_n, "front");
    const auto r = prepare(rear_, loads.rear_n, "rear");
    RoadLoadCoeffs c;
    c.rolling_f0_n = 2.0 * (f.k0() * loads.front_n + r.k0() * loads.rear_n);
    c.rolling_f1_n_s_per_m = 2.0 * (f.k1_s_per_m() * loads.front_n + r.k1_s_per_m() * loads.rear_n);
    c.rolling_f2_n_s2_per_m2 = 2.0 * (f.k2_s2_per_m2() * loads.front_n + r.k2_s2_per_m2() * loads.rear_n);
    c.aero_n_s2_per_m2 = 0.5 * body_.air_density_kg_per_m3 * body_.drag_coefficient * body_.frontal_area_m2;
    return c;
  }
  std::string describe() const override {
    return front_.name == rear_.name ? "tyre model, 4 x " + front_.name
                                     : "tyre model, front " + front_.name + ", rear " + rear_.name;
  }
  std::string rolling_term() const override { return "rolling resistance (tyres)"; }

 private:
  // A tyre outside its model's domain at this car's load is named with its axle and file.
  static TyreAtLoad prepare(const TyreSpec& tyre, double load_n, const char* axle) {
    try {
      return TyreAtLoad::prepare(tyre.state, load_n);
    } catch (const ModelDomainError& e) {
      throw ModelDomainError(std::string(axle) + " tyre '" + tyre.name + "' (" + tyre.source + "): " + e.what());
    }
  }

  BodyParams body_;
  TyreSpec front_, rear_;
};

// Coast-down coefficients already hold rolling, driveline spin loss and aero; A scales with normal load.
class CoastdownRoadLoad final : public RoadLoadModel {
 public:
  explicit CoastdownRoadLoad(const CoastdownParams& c) : c_(c) {}
  RoadLoadCoeffs at_grade(double grade) const override {
    RoadLoadCoeffs r;
    r.rolling_f0_n = c_.a_n / std::sqrt(1.0 + grade * grade);
    r.rolling_f1_n_s_per_m = c_.b_n_s_per_m;
    r.aero_n_s2_per_m2 = c_.c_n_s2_per_m2;
    return r;
  }
  std::string describe() const override { return "coast-down A + B v + C v^2"; }
  // A coast-down's A + B v is the tyres' rolling resistance and the driveline's drag together.
  std::string rolling_term() const override { return "rolling and driveline (coast-down A + B v)"; }

 private:
  CoastdownParams c_;
};

}  // namespace

std::unique_ptr<RoadLoadModel> make_road_load(const Vehicle& vehicle) {
  if (vehicle.coastdown) return std::make_unique<CoastdownRoadLoad>(*vehicle.coastdown);
  return std::make_unique<TyreRoadLoad>(vehicle);
}

double tyre_rolling_force_at_standstill_limit_n(const Vehicle& vehicle) {
  if (!vehicle.front_tyre) return 0.0;
  Vehicle tyres_only = vehicle;
  tyres_only.coastdown.reset();
  return TyreRoadLoad(tyres_only).at_grade(0.0).rolling_f0_n;
}

const FuelParams* Vehicle::fuel() const {
  return std::visit([](const auto& p) -> const FuelParams* {
    if constexpr (requires { p.fuel; }) return &p.fuel;
    else return nullptr;
  }, powertrain);
}

const BatteryParams* Vehicle::battery() const {
  return std::visit([](const auto& p) -> const BatteryParams* {
    if constexpr (requires { p.battery; }) return &p.battery;
    else return nullptr;
  }, powertrain);
}

namespace {
std::unique_ptr<Powertrain> make_powertrain_of(const ElectricPowertrainParams& p) { return std::make_unique<ElectricPowertrain>(p); }
std::unique_ptr<Powertrain> make_powertrain_of(const CombustionPowertrainParams& p) { return std::make_unique<CombustionPowertrain>(p); }
std::unique_ptr<Powertrain> make_powertrain_of(const ConventionalPowertrainParams& p) { return std::make_unique<ConventionalPowertrain>(p); }
}  // namespace

std::unique_ptr<Powertrain> make_powertrain(const Vehicle& vehicle) {
  return std::visit([](const auto& p) -> std::unique_ptr<Powertrain> { return make_powertrain_of(p); }, vehicle.powertrain);
}

}  // namespace rollsim
