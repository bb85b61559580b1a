#include "rollsim/selection/front_end.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "rollsim/common/error.hpp"
#include "rollsim/common/format.hpp"
#include "rollsim/common/input_file.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/tyre/tyre_request.hpp"
#include "rollsim/report/simulation_report.hpp"
#include "rollsim/selection/common.hpp"

namespace rollsim::selection {

CandidateList load_candidates(const std::vector<std::string>& tyres, bool use_catalogue, const std::string& catalogue) {
  CandidateList out;
  for (const auto& t : tyres) out.tyres.push_back(load_tyre_file(resolve_data_file(t, "tyres", ".yaml", "--tyre")));
  if (!use_catalogue && !tyres.empty()) return out;
  namespace fs = std::filesystem;
  const std::string dir = catalogue.empty() ? data_root() + "/tyres/catalogue" : catalogue;
  if (!is_folder_path(dir)) throw InputError("--catalogue " + dir, "not a folder");
  std::error_code ec;
  std::vector<std::string> files;
  // Non-throwing iteration: a folder that cannot be listed is a named input error, not a system exception.
  for (fs::directory_iterator it(dir, ec), end; it != end; it.increment(ec)) {
    if (it->path().extension() == ".yaml" || it->path().extension() == ".yml") files.push_back(it->path().string());
  }
  if (ec) throw InputError("--catalogue " + dir, "cannot be listed: " + ec.message());
  std::sort(files.begin(), files.end());
  if (files.empty()) throw InputError("--catalogue " + dir, "holds no *.yaml tyre files");
  for (const auto& f : files) {
    try {
      out.tyres.push_back(load_tyre_file(f));
    } catch (const std::exception& e) {
      out.broken.push_back(e.what());
    }
  }
  return out;
}

double parse_diameter_tolerance_pct(const std::string& text) {
  return parse_option_number(text, "--diameter-tolerance-pct", Range::open_low(0.0, 100.0));
}

std::string tyre_size_text(const TyreSpec& t) {
  if (t.size) return t.size->designation;
  // Appended, not "R" + ...: GCC 12 warns falsely (-Wrestrict, its bug 105651) on a literal plus a temporary.
  std::string text = "R";
  text += fixed(t.state.geometry.outer_radius_m * 1e3, 0);
  text += " W";
  text += fixed(t.state.geometry.section_width_m * 1e3, 0);
  return text;
}

std::vector<JsonObject> comparison_json(const Comparison& c) {
  std::vector<JsonObject> out;
  auto emit = [&](const CandidateResult& r, int rank) {
    JsonObject j;
    j.add("vehicle", c.vehicle).add("cycle", c.cycle).add("tyre", r.tyre.name).add("source", r.tyre.source);
    j.add("size", tyre_size_text(r.tyre)).add("own", r.is_own);
    if (rank > 0) j.add("rank", rank); else j.add_null("rank");
    j.add("pressure_bar", units::pa_to_bar(r.tyre.state.pressure_pa))
        .add("wheel_load_n", r.fit.wheel_load_n)
        .add("diameter_change_pct", r.fit.diameter_change_pct);
    // Unknown (a light truck's, whose load range the size does not give) is null, not a capacity of 0 N.
    if (r.fit.capacity_n > 0.0) j.add("capacity_n", r.fit.capacity_n); else j.add_null("capacity_n");
    j
        .add("rrc_80kmh", r.rrc_80)
        .add("rr_power_80kmh_w", r.rr_power_80_w)
        .add(c.unit, r.value)
        .add("diff_pct", r.diff_pct);
    if (c.shows_range) j.add("range_km", r.range_km).add("range_change_km", r.range_change_km);
    if (r.simulated) j.add("followed_trace", r.trace.followed).add("max_deficit_kmh", units::mps_to_kmh(r.trace.max_deficit_mps));
    else j.add_null("followed_trace").add_null("max_deficit_kmh");  // a run that never happened
    j.add("fits", r.fit.fits).add("reason", r.fit.reason);
    out.push_back(j);
  };
  for (std::size_t i = 0; i < c.ranked.size(); ++i) emit(c.ranked[i], static_cast<int>(i + 1));
  for (const auto& r : c.unfit) emit(r, 0);
  return out;
}

std::vector<std::string> trace_warnings(const Comparison& c) {
  std::vector<std::string> out;
  auto check = [&](const CandidateResult& r) {
    if (!r.simulated) return;
    const std::string on = "on " + r.tyre.name + (r.is_own ? " (own)" : "") + ", " + c.cycle + ": ";
    if (!r.overcharge.empty()) out.push_back(on + r.overcharge);
    if (!r.trace.followed) out.push_back(on + report::shortfall_caveat(r.trace));
  };
  for (const auto& r : c.ranked) check(r);
  for (const auto& r : c.unfit) check(r);
  return out;
}

Sensitivity sensitivity_of(const std::optional<Vehicle>& vehicle, const std::optional<TyreSpec>& tyre_given,
                           const DriveCycle& cycle, std::optional<double> load_n, double speed_mps) {
  TyreSpec tyre;
  if (tyre_given) tyre = *tyre_given;
  else if (vehicle && vehicle->front_tyre) {
    require_one_tyre_set(*vehicle, "without --tyre, sensitivity");
    tyre = *vehicle->front_tyre;
  }
  else if (vehicle) throw InputError("--tyre", "missing: the car has no tyre model (coast-down road load); give --tyre");
  else throw InputError("--tyre", "missing: give a tyre and/or --vehicle");
  if (vehicle) require_distance(cycle);
  double at_n = 0.0;
  if (load_n) {
    at_n = *load_n;
  } else if (vehicle) {
    const auto w = wheel_loads(vehicle->body, 0.0);
    at_n = std::max(w.front_n, w.rear_n);
  } else if (tyre.max_load_n > 0.0) {
    at_n = 0.8 * tyre.max_load_n;
  } else {
    throw InputError("--load-n", "missing: the tyre's maximum load is unknown; give --load-n N");
  }
  try {
    return vehicle ? vehicle_sensitivity(*vehicle, tyre, cycle, at_n, speed_mps) : tyre_sensitivity(tyre, at_n, speed_mps);
  } catch (const ModelDomainError& e) {
    throw InputError(tyre.source + " at " + fixed(at_n, 0) + " N", e.what());
  }
}

JsonObject sensitivity_json(const Sensitivity& s) {
  const bool car = !s.energy_unit.empty();  // set in vehicle mode only
  JsonObject j;
  j.add("tyre", s.tyre).add("load_n", s.load_n).add("speed_kmh", units::mps_to_kmh(s.speed_mps))
      .add("relative_step", s.relative_step).add("rr_power_w", s.rr_power_w);
  if (car) j.add("vehicle", s.vehicle).add("cycle", s.cycle).add(s.energy_unit, s.energy).add("followed_trace", s.followed_trace);
  for (const auto& r : s.rows) {
    const ParameterValue v = parameter_value_in_file_units(r);
    j.add("value_" + v.key, v.value).add("elasticity_rr_power_" + r.key, r.power_elasticity).add("elasticity_rrc_" + r.key, r.rrc_elasticity);
    if (r.energy_elasticity) {
      j.add("elasticity_" + s.energy_unit + "_" + r.key, *r.energy_elasticity)
          .add("elasticity_" + s.energy_unit + "_" + r.key + "_double_step", r.energy_elasticity_double_step.value_or(NAN));
    }
  }
  j.add("dominant_rr_power", s.dominant_power);
  if (car) {
    j.add("dominant_energy", s.dominant_energy)
        .add("energy_elasticities_smooth", std::all_of(s.rows.begin(), s.rows.end(), [](const SensitivityRow& r) { return r.energy_smooth; }));
  }
  return j;
}

std::vector<std::string> sensitivity_warnings(const Sensitivity& s) {
  std::vector<std::string> out;
  if (s.max_load_n > 0.0 && s.load_n > s.max_load_n) {
    out.push_back("load " + fixed(s.load_n, 0) + " N is above the tyre's rated maximum " + fixed(s.max_load_n, 0) +
                  " N; the RR power elasticities are outside the tyre's rating");
  }
  if (std::string kg = load_in_kg_hint(s.load_n, s.max_load_n); !kg.empty()) out.push_back(std::move(kg));
  for (const auto& w : s.vehicle_warnings) out.push_back(w);
  if (!s.energy_unit.empty() && !s.followed_trace) {
    out.push_back("the car could not follow the cycle in the base run or a perturbed one: the energy elasticities mix "
                  "the tyre's effect with a change of the drive itself");
  }
  for (const auto& r : s.rows) {
    if (r.energy_smooth || !r.energy_elasticity) continue;
    out.push_back("the car's " + std::string(s.energy_unit == "kwh_per_10km" ? "energy" : "fuel") + " is not smooth in " +
                  r.name + ": steps of +-" + format_value(s.relative_step * 100) + " % give " + fixed(*r.energy_elasticity, 4) +
                  ", steps twice as large " + fixed(*r.energy_elasticity_double_step, 4) +
                  " (a gear, lock-up or fuel cut-off decision changes between the runs); read the trend from a "
                  "`rollsim sweep` over a wider range");
  }
  return out;
}

SweepOptions sweep_options_from_request(const SweepRequest& o) {
  if (o.params.empty()) throw InputError("--param", "missing: pressure, diameter, width, load, load-pct or speed");
  if (o.params.size() > 2) throw InputError("--param", "at most two parameters (a grid)");
  if (o.from.size() != o.params.size() || o.to.size() != o.params.size()) {
    throw InputError("--from/--to", "give one --from and one --to per --param");
  }
  // One --steps per --param or none: a single --steps with two --param went to the first, whichever it was
  // written after (session 20).
  if (!o.steps.empty() && o.steps.size() != o.params.size()) {
    throw InputError("--steps", "give one --steps per --param (" + std::to_string(o.params.size()) + "), or none for " +
                                    std::to_string(SweepAxis{}.steps) + " each; " + std::to_string(o.steps.size()) + " given");
  }
  SweepOptions so;
  for (std::size_t i = 0; i < o.params.size(); ++i) {
    const auto p = parse_sweep_param(o.params[i]);
    const std::string opt = "--param " + o.params[i];
    if (!p) throw InputError(opt, "unknown: must be pressure, diameter, width, load, load-pct or speed");
    SweepAxis a;
    a.param = *p;
    a.from = parse_option_number(o.from[i], "--from", Range{});
    a.to = parse_option_number(o.to[i], "--to", Range{});
    if (i < o.steps.size() && !o.steps[i].empty()) {  // empty: the default (an axis given without steps in Python)
      a.steps = parse_option_count(o.steps[i], "--steps", Range::closed(2, 1e6));
    }
    check_axis(a, opt);
    so.axes.push_back(a);
  }
  if (!o.load_n.empty()) so.load_n = parse_option_number(o.load_n, "--load-n", Range::open_low(0.0, 1e6));
  for (const auto& a : so.axes) {
    if (so.load_n && (a.param == SweepParam::Load || a.param == SweepParam::LoadPct)) {
      throw InputError("--load-n", "not allowed with --param " + sweep_param_key(a.param) + ", which sets the load");
    }
  }
  for (const auto& a : so.axes) {
    // Silently ignored until session 22 (outside testing), where --load-n beside a load axis was refused.
    if (!o.speed_kmh.empty() && a.param == SweepParam::Speed) {
      throw InputError("--speed-kmh", "not allowed with --param speed, which sets the speed");
    }
  }
  if (!o.speed_kmh.empty()) so.speed_kmh = parse_option_number(o.speed_kmh, "--speed-kmh", Range::closed(0.0, 500.0));
  if (!o.threads.empty()) so.threads = static_cast<unsigned>(parse_option_count(o.threads, "--threads", Range::closed(1, 1024)));
  return so;
}

std::vector<JsonObject> sweep_json(const SweepResult& r) {
  std::vector<JsonObject> out;
  for (const auto& p : r.points) {
    JsonObject j;
    for (const auto& [name, value] : sweep_point_columns(r, p)) j.add(name, value);
    j.add("rrc", p.rr.rrc).add("rr_force_n", p.rr.rr_force_n).add("rr_power_w", p.rr.rr_power_w)
        .add("deflection_m", p.rr.deflection_m);
    if (r.vehicle) j.add(r.energy_unit, p.energy).add("followed_trace", p.trace.followed);
    out.push_back(j);
  }
  return out;
}

}  // namespace rollsim::selection
