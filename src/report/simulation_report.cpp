#include "rollsim/report/simulation_report.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "rollsim/common/units.hpp"

namespace rollsim::report {

std::vector<std::pair<std::string, double>> energy_terms_kwh(const SimulationResult& r) {
  const auto& e = r.energy;
  auto k = [](double j) { return units::j_to_kwh(j); };
  std::vector<std::pair<std::string, double>> t{
      {"traction_at_wheels", k(e.traction_j)},
      {"rolling_resistance", k(e.rolling_j)},
      {"aerodynamic_drag", k(e.aero_j)},
      {"grade", k(e.grade_j)},
      {"other_resistance", k(e.other_resistance_j)},
      {"braking_lost", k(e.friction_brake_j)},
      {"regenerated_at_wheels", k(e.regen_wheel_j)},
      {"wheel_slip", k(e.wheel_loss_j)},
      {"kinetic_change", k(e.kinetic_change_j)},
      {"unmet_demand", k(e.unmet_demand_j)},
      {"gearbox", k(e.gearbox_loss_j)},
      {"auxiliaries", k(e.aux_j)},
  };
  if (r.battery) {
    t.push_back({"motor", k(e.motor_loss_j)});
    t.push_back({"battery_internal", k(e.battery_loss_j)});
    t.push_back({"battery_terminals", k(e.battery_terminal_j)});
  }
  if (r.fuel) {
    t.push_back({"engine", k(e.engine_loss_j)});
    t.push_back({"clutch", k(e.clutch_loss_j)});
    t.push_back({"fuel", k(e.fuel_j)});
  }
  return t;
}

// A car that burns fuel is judged by its fuel (a hybrid's battery ends where it started); one without, by its battery.
double headline_value(const SimulationResult& r) { return r.fuel ? r.fuel_l_per_100km() : r.aec_kwh_per_10km(); }
std::string headline_unit(const SimulationResult& r) { return r.fuel ? "l/100 km" : "kWh/10 km"; }

std::string range_text(double range_km, int decimals) {
  return std::isfinite(range_km) ? fixed(range_km, decimals) + " km" : "none to state (the battery ends with more charge)";
}

std::string overcharge_caveat(const SimulationResult& r) {
  if (!r.battery || !(r.battery->max_soc > 1.0 + 1e-9)) return {};
  return "the battery would have charged past full (state of charge up to " + fixed(r.battery->max_soc * 100.0, 1) +
         " %): a full battery takes no charge, so at least " +
         fixed(units::j_to_kwh((r.battery->max_soc - 1.0) * r.battery->usable_j), 3) +
         " kWh of the regeneration booked would have gone to the friction brakes, and the energy figure is that much low";
}

std::string summary_text(const SimulationResult& r, bool solver_stats) {
  std::ostringstream o;
  const auto& e = r.energy;
  const double km = r.distance_m / 1000.0;
  o << r.vehicle << " on " << r.cycle << " (" << r.mode << " simulation; road load: " << r.road_load << ")\n";
  o << "  distance " << fixed(km, 3) << " km in " << fixed(r.duration_s, 0) << " s, mean speed "
    << fixed(km / (r.duration_s / units::kSPerHour), 1) << " km/h\n";
  if (!r.moved()) {
    const std::string what = r.fuel ? "l/100 km, CO2 g/km" : "kWh/10 km, range";
    if (r.distance_m > 0.0 && r.trace_distance_m < SimulationResult::kMinTraceDistance_m) {
      o << "  the trace covers only " << significant(r.trace_distance_m, 3) << " m, under "
        << format_value(SimulationResult::kMinTraceDistance_m) << " m: per-distance figures (" << what << ") are undefined\n";
    } else if (r.distance_m > 0.0) {
      o << "  the car covered only " << fixed(r.distance_m / 1000.0, 3) << " km of the trace's "
        << fixed(r.trace_distance_m / 1000.0, 3) << " km: per-distance figures (" << what
        << ") and the shares of its traction are undefined (the powertrain cannot drive this trace)\n";
    } else {
      o << "  the car did not move: per-distance figures (" << what << ") are undefined\n";
    }
  }
  if (r.battery && r.moved()) {
    o << "  energy at the battery terminals: " << fixed(r.aec_kwh_per_10km(), 3) << " kWh/10 km = "
      << fixed(r.aec_kwh_per_10km() * 10.0, 2) << " kWh/100 km = " << fixed(r.aec_kwh_per_10km() * 100.0, 1) << " Wh/km\n";
    o << "  range on the usable battery (" << fixed(units::j_to_kwh(r.battery->usable_j), 1) << " kWh): "
      << range_text(r.range_km(), 0);
    if (!r.battery_empty) {
      o << "; state of charge " << fixed(r.battery->initial_soc * 100, 1) << " % -> " << fixed(r.battery->final_soc * 100, 1) << " %";
    }
    o << "\n";
  }
  if (r.fuel && r.moved()) {
    o << "  fuel: " << fixed(r.fuel_l_per_100km(), 3) << " l/100 km (" << fixed(r.fuel->volume_m3 * 1e3, 3)
      << " l), CO2 " << fixed(r.co2_g_per_km(), 1) << " g/km\n";
  }
  if (const std::string w = overcharge_caveat(r); !w.empty()) o << "  WARNING: " << w << "\n";
  if (r.battery && r.battery_empty) {
    o << "  WARNING: the usable battery ran empty at t = " << fixed(r.battery_empty->time_s, 0) << " s, after "
      << fixed(r.battery_empty->distance_m / 1000.0, 3) << " km (state of charge "
      << fixed(r.battery->initial_soc * 100, 1) << " % -> 0 %); the rest of the trace was driven on energy the battery "
      << "does not hold (it would need " << fixed(-r.battery->final_soc * 100, 1) << " % of the usable capacity more)\n";
  }
  const double source_j = r.source_energy_j();
  TextTable t({"energy", "kWh", "share %"});
  t.set_left_aligned(0);
  // Shares of the traction mean nothing for a car that hardly moved (millijoules of traction against kilojoules of
  // friction braking): "-" there, as for no traction at all.
  const double traction_scale_j = r.moved() ? e.traction_j : 0.0;
  auto row = [&](const std::string& name, double j, double of_j) {
    t.add_row({name, fixed(units::j_to_kwh(j), 4), of_j != 0.0 ? fixed(100.0 * j / of_j, 1) : "-"});
  };
  row("at the wheels: traction", e.traction_j, traction_scale_j);
  row("  " + r.rolling_term, e.rolling_j, traction_scale_j);
  row("  aerodynamic drag", e.aero_j, traction_scale_j);
  if (e.grade_j != 0.0) row("  grade (net climb)", e.grade_j, traction_scale_j);
  if (e.other_resistance_j != 0.0) row("  other resistance (effects)", e.other_resistance_j, traction_scale_j);
  row("  braking lost (friction)", e.friction_brake_j, traction_scale_j);
  if (r.battery) row("  regenerated at the wheels", e.regen_wheel_j, traction_scale_j);
  if (e.wheel_loss_j != 0.0) row("  tyre slip", e.wheel_loss_j, traction_scale_j);
  row("  kinetic energy change", e.kinetic_change_j, traction_scale_j);
  if (e.unmet_demand_j != 0.0) row("demanded beyond the powertrain (replay)", e.unmet_demand_j, traction_scale_j);
  if (r.battery) {
    row("battery terminals (net)", e.battery_terminal_j, source_j);
    row("  traction - regenerated", e.traction_j - e.regen_wheel_j, source_j);
    row("  reduction gear", e.gearbox_loss_j, source_j);
    row("  motor and inverter", e.motor_loss_j, source_j);
    row("  auxiliaries", e.aux_j, source_j);
    row("battery internal loss (extra)", e.battery_loss_j, source_j);
  }
  if (r.fuel) {
    row("fuel (lower heating value)", e.fuel_j, source_j);
    row("  engine loss (heat, friction)", e.engine_loss_j, source_j);
    row("  traction", e.traction_j, source_j);
    row("  gearbox and final drive", e.gearbox_loss_j, source_j);
    row("  clutch or converter slip", e.clutch_loss_j, source_j);
    row("  accessories (alternator)", e.aux_j, source_j);
  }
  o << t.render();
  // A run with no traction (standing still) has no scale for a relative balance: its residuals are given in J.
  auto closure = [](double residual_j, double scale_j) {
    return scale_j != 0.0 ? fixed(100.0 * std::abs(residual_j) / std::abs(scale_j), 4) + " %"
                          : fixed(std::abs(residual_j), 3) + " J";
  };
  o << "  energy balance closes to " << closure(e.wheel_residual_j(), traction_scale_j) << " at the wheels and "
    << closure(e.powertrain_residual_j(), source_j) << " in the powertrain\n";
  o << "  speed tracking: max error " << fixed(units::mps_to_kmh(r.max_speed_error_mps), 2) << " km/h at t = "
    << fixed(r.max_speed_error_time_s, 1) << " s\n";
  for (const auto& s : r.shortfalls) {
    o << "  WARNING: the car could not follow the trace from t = " << fixed(s.start_s, 0) << " to " << fixed(s.end_s, 0)
      << " s" << (s.max_deficit_mps > 0.0 ? ", falling behind by up to " + fixed(units::mps_to_kmh(s.max_deficit_mps), 1) +
                                                " km/h at t = " + fixed(s.at_s, 0) + " s"
                                          : " (powertrain at its limit)")
      << "\n";
  }
  if (solver_stats && r.mode == "forward") {
    o << "  CVODE: " << r.solver.steps << " steps, " << r.solver.rhs_evals << " right-hand-side calls, "
      << r.solver.error_test_failures << " error-test failures, " << r.solver.nonlinear_failures
      << " nonlinear failures, " << r.solver.root_evals << " root-function calls, " << r.solver.restarts
      << " restarts at discontinuities\n";
  }
  return o.str();
}

std::string shortfall_caveat(const TraceFollowing& trace) {
  // Forward runs fall behind; a replay keeps to the trace and leaves out what the powertrain could not give.
  return trace.max_deficit_mps > 0.0 ? "the car could not follow the trace, falling up to " +
                                     fixed(units::mps_to_kmh(trace.max_deficit_mps), 1) +
                                     " km/h behind: its figures are for a slower drive than the cycle's"
                               : "the trace asks more than the powertrain gives: the replay's figures leave out the "
                                 "demand it could not meet";
}

std::vector<std::string> run_caveats(const SimulationResult& r) {
  std::vector<std::string> out;
  if (const std::string w = overcharge_caveat(r); !w.empty()) out.push_back(w);
  if (const TraceFollowing t = r.trace_following(); !t.followed) out.push_back(shortfall_caveat(t));
  if (r.battery && r.battery_empty) {
    out.push_back("the usable battery ran empty after " + fixed(r.battery_empty->distance_m / 1000.0, 3) +
                  " km: a real car would have stopped there");
  }
  return out;
}

void add_input_files(JsonObject& j, const RunInputFiles& files) {
  for (const auto& [key, path] : {std::pair{"vehicle_file", &files.vehicle}, {"tyre_file", &files.tyre}, {"cycle_file", &files.cycle}}) {
    if (path->empty()) j.add_null(key);
    else j.add(key, *path);
  }
  if (!files.rear_tyre.empty() && files.rear_tyre != files.tyre) j.add("rear_tyre_file", files.rear_tyre);
}

JsonObject to_json(const SimulationResult& r, const std::string& tyre_label) {
  JsonObject j;
  j.add("vehicle", r.vehicle).add("tyre", tyre_label).add("road_load", r.road_load).add("cycle", r.cycle);
  j.add("mode", r.mode).add("powertrain", r.battery && r.fuel ? "hybrid" : r.battery ? "electric" : "combustion");
  j.add("distance_km", r.distance_m / 1000.0).add("duration_s", r.duration_s);
  // Per-distance figures of a run that did not move are undefined: null, never inf or NaN.
  auto per_distance = [&](const std::string& key, double value) {
    if (r.moved()) {
      j.add(key, value);
    } else {
      j.add_null(key);
    }
  };
  j.add("moved", r.moved());
  if (r.battery) {
    per_distance("aec_kwh_per_10km", r.aec_kwh_per_10km());
    per_distance("aec_kwh_per_100km", r.aec_kwh_per_10km() * 10.0);
    per_distance("aec_wh_per_km", r.aec_kwh_per_10km() * 100.0);
    per_distance("range_km", r.range_km());
    j.add("final_soc_pct", r.battery->final_soc * 100.0);
    j.add("max_soc_pct", r.battery->max_soc * 100.0);
    j.add("battery_empty", r.battery_empty.has_value());
    if (r.battery_empty) {
      j.add("battery_empty_at_s", r.battery_empty->time_s).add("battery_empty_at_km", r.battery_empty->distance_m / 1000.0);
    } else {
      j.add_null("battery_empty_at_s").add_null("battery_empty_at_km");
    }
  } else {
    j.add_null("aec_kwh_per_10km");
  }
  if (r.fuel) {
    per_distance("fuel_l_per_100km", r.fuel_l_per_100km());
    per_distance("co2_g_per_km", r.co2_g_per_km());
  } else {
    j.add_null("fuel_l_per_100km");
    per_distance("co2_g_per_km", 0.0);
  }
  JsonObject b;
  for (const auto& [k, v] : energy_terms_kwh(r)) b.add(k, v);
  j.add("energy_breakdown_kwh", b);
  if (r.energy.traction_j != 0.0) {
    j.add("energy_balance_residual_pct", 100.0 * r.energy.wheel_residual_j() / r.energy.traction_j);
  } else {
    j.add_null("energy_balance_residual_pct");
  }
  j.add("energy_balance_residual_j", r.energy.wheel_residual_j());
  j.add("max_speed_error_kmh", units::mps_to_kmh(r.max_speed_error_mps));
  j.add("shortfalls", static_cast<int>(r.shortfalls.size()));
  if (r.mode == "forward") {
    JsonObject s;
    s.add("steps", static_cast<int>(r.solver.steps)).add("rhs_evals", static_cast<int>(r.solver.rhs_evals));
    s.add("error_test_failures", static_cast<int>(r.solver.error_test_failures));
    s.add("nonlinear_failures", static_cast<int>(r.solver.nonlinear_failures));
    s.add("restarts", static_cast<int>(r.solver.restarts));
    j.add("cvode", s);
  }
  return j;
}

std::vector<TraceColumn> trace_columns(const SimulationResult& r) {
  using P = TracePoint;
  using Column = std::pair<std::string, double (*)(const P&)>;
  std::vector<Column> columns{
      {"time_s", [](const P& p) { return p.time_s; }},
      {"target_speed_kmh", [](const P& p) { return units::mps_to_kmh(p.target_speed_mps); }},
      {"speed_kmh", [](const P& p) { return units::mps_to_kmh(p.speed_mps); }},
      {"accel_mps2", [](const P& p) { return p.accel_mps2; }},
      {"grade_pct", [](const P& p) { return p.grade * 100.0; }},
      {"gear", [](const P& p) { return static_cast<double>(p.gear); }},
      {"rolling_force_n", [](const P& p) { return p.rolling_force_n; }},
      {"aero_force_n", [](const P& p) { return p.aero_force_n; }},
      {"grade_force_n", [](const P& p) { return p.grade_force_n; }},
      {"wheel_force_n", [](const P& p) { return p.wheel_force_n; }},
      {"traction_power_kw", [](const P& p) { return p.traction_power_w / 1e3; }},
  };
  // A car's own sources only: a petrol car printed a state of charge of 0 and an electric one a fuel rate of 0.
  if (r.battery) {
    columns.insert(columns.end(), {
        {"battery_power_kw", [](const P& p) { return p.battery_power_w / 1e3; }},
        {"battery_current_a", [](const P& p) { return p.battery_current_a; }},
    });
  }
  if (r.fuel) columns.push_back({"fuel_rate_lph", [](const P& p) { return p.fuel_rate_m3_per_s / units::kM3PerLitre * units::kSPerHour; }});
  columns.push_back({"tyre_rrc", [](const P& p) { return p.rrc; }});
  if (r.battery) {
    columns.insert(columns.end(), {
        {"soc_pct", [](const P& p) { return p.soc * 100.0; }},
        {"battery_energy_kwh", [](const P& p) { return units::j_to_kwh(p.battery_terminal_energy_j); }},
    });
  }
  if (r.fuel) columns.push_back({"fuel_l", [](const P& p) { return p.fuel_volume_m3 / units::kM3PerLitre; }});
  std::vector<TraceColumn> out;
  for (const auto& [name, value] : columns) {
    TraceColumn c{name, {}};
    c.values.reserve(r.trace.size());
    for (const auto& p : r.trace) c.values.push_back(value(p));
    out.push_back(std::move(c));
  }
  return out;
}

void write_trace_csv(std::ostream& out, const SimulationResult& r) {
  const std::vector<TraceColumn> columns = trace_columns(r);
  for (std::size_t c = 0; c < columns.size(); ++c) out << (c ? "," : "") << columns[c].name;
  out << '\n';
  // Eight significant digits, time to the millisecond whatever its origin: a logger's epoch seconds (1.7e9) at 10 Hz
  // read 7 distinct times in 6000 rows at eight digits (session 23's outside testing).
  for (std::size_t i = 0; i < r.trace.size(); ++i) {
    for (std::size_t c = 0; c < columns.size(); ++c) {
      out << (c ? "," : "");
      const double x = columns[c].values[i];
      if (columns[c].name == "time_s" && std::abs(x) >= 1e5) out << std::setprecision(static_cast<int>(std::floor(std::log10(std::abs(x)))) + 4) << x;
      else out << std::setprecision(8) << x;
    }
    out << '\n';
  }
}

}  // namespace rollsim::report
