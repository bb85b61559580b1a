#include "rollsim/tyre/tyre_request.hpp"

#include "rollsim/common/format.hpp"

#include "rollsim/common/units.hpp"
#include "rollsim/common/yaml_reader.hpp"

namespace rollsim {

TyreSpec build_requested_tyre(const TyreRequest& o) {
  TyreSpec spec;
  const bool has_geometry = !o.outer_radius_m.empty() || !o.width_m.empty();
  if (!o.file.empty() || !o.file_text.empty()) {
    if (!o.size.empty()) throw InputError("--size '" + o.size + "'", "not allowed together with a tyre file");
    if (has_geometry) {
      throw InputError(o.outer_radius_m.empty() ? "--width-m" : "--outer-radius-m",
                       "not allowed together with a tyre file (the file gives the geometry)");
    }
    spec = o.file_text.empty() ? load_tyre_file(resolve_data_file(o.file, "tyres", ".yaml", "tyre file"))
                               : load_tyre_text(o.file_text, "tyre dict");
  } else if (!o.size.empty()) {
    if (has_geometry) {
      throw InputError(o.outer_radius_m.empty() ? "--width-m" : "--outer-radius-m",
                       "not allowed together with --size (the designation gives the geometry)");
    }
    spec.size = parse_tyre_size(o.size, "--size");
    spec.name = o.size;
    spec.source = "--size '" + o.size + "'";
    spec.state.geometry.outer_radius_m = spec.size->outer_radius_m;
    spec.state.geometry.section_width_m = spec.size->section_width_m;
    spec.state.geometry.rim_radius_m = spec.size->rim_diameter_m / 2.0;
    if (spec.size->load_index) {
      spec.max_load_n = *load_index_max_load_kg(*spec.size->load_index) * units::kStandardGravity_mps2;
    }
  } else {
    if (o.outer_radius_m.empty() || o.width_m.empty()) {
      throw InputError(o.outer_radius_m.empty() ? "--outer-radius-m" : "--width-m",
                       "missing: give a tyre file (e.g. 'rollsim tyre 175-70R14'), --size \"175/70 R14 84T\", or both "
                       "--outer-radius-m and --width-m");
    }
    spec.name = "R " + o.outer_radius_m + " m, W " + o.width_m + " m";
    spec.source = "command line";
    spec.state.geometry.outer_radius_m = parse_option_number(o.outer_radius_m, "--outer-radius-m", Range::open_low(0.0, 1.5));
    spec.state.geometry.section_width_m = parse_option_number(o.width_m, "--width-m", Range::open_low(0.0, 1.0));
  }
  if (!o.pressure_bar.empty()) {
    const double bar = parse_option_number(o.pressure_bar, "--pressure-bar", Range::finite());  // range and units: below
    check_pressure_plausible(bar, spec.size, "--pressure-bar");
    spec.state.pressure_pa = units::bar_to_pa(bar);
  } else if (o.file.empty() && o.file_text.empty()) {
    throw InputError("--pressure-bar", "missing: the inflation pressure in bar is needed (e.g. --pressure-bar 2.1)");
  }
  return spec;
}

TyreLoadChoice choose_requested_load(const TyreRequest& o, const TyreSpec& spec) {
  if (!o.load_n.empty() && !o.load_pct.empty()) {
    throw InputError("--load-pct", "not allowed together with --load-n: give one of them");
  }
  if (!o.load_n.empty()) {
    return {parse_option_number(o.load_n, "--load-n", Range::open_low(0.0, 1e6)), "--load-n " + o.load_n};
  }
  const bool pct_given = !o.load_pct.empty();
  const double pct = pct_given ? parse_option_number(o.load_pct, "--load-pct", Range::open_low(0.0, 300.0)) : 80.0;
  if (!(spec.max_load_n > 0.0)) {
    throw InputError(pct_given ? "--load-pct " + o.load_pct : "--load-n",
                     pct_given ? "the tyre's maximum load is unknown (no load index): give --load-n N instead"
                               : "missing: the tyre's maximum load is unknown (no load index), so the default 80 % "
                                 "of it cannot be used; give --load-n N");
  }
  return {pct / 100.0 * spec.max_load_n,
          pct_given ? "--load-pct " + o.load_pct : "the default load (80 % of the maximum load)"};
}

std::string requested_load_warning(const TyreSpec& spec, const TyreLoadChoice& load) {
  const double max_n = spec.max_load_n, n = load.load_n;
  if (!(max_n > 0.0)) return "";
  const int d = decimals_apart(n, max_n, 0, 3);
  if (n > max_n)
    return "load " + fixed(n, d) + " N is above the tyre's rated maximum " + fixed(max_n, d) + " N (" +
           fixed(max_n / units::kStandardGravity_mps2, 0) + " kg); results are outside the tyre's rating";
  return load.where.rfind("--load-n", 0) == 0 ? load_in_kg_hint(n, max_n) : "";
}

std::string load_in_kg_hint(double load_n, double max_load_n) {
  constexpr double kLeastShare = 0.15;
  if (!(max_load_n > 0.0) || !(load_n < kLeastShare * max_load_n)) return "";
  return "load " + format_value(load_n) + " N is " + fixed(100.0 * load_n / max_load_n, 0) + " % of the tyre's rated " +
         fixed(max_load_n, 0) + " N; is it in kg? (" + format_value(load_n) + " kg = " +
         fixed(load_n * units::kStandardGravity_mps2, 0) + " N)";
}

double parse_requested_speed_kmh(const std::string& text) {
  return parse_option_number(text, "--speed-kmh", Range::closed(0.0, 500.0));
}

JsonObject tyre_point_json(const TyreSpec& spec, double load_n, double speed_kmh, const RollingResistance& r) {
  JsonObject j;
  j.add("tyre", spec.name).add("source", spec.source);
  j.add("model", spec.state.model == TyreModelKind::Thesis ? "thesis" : "hysteresis");
  if (spec.size) j.add("size", spec.size->designation);
  j.add("outer_radius_m", spec.state.geometry.outer_radius_m)
      .add("section_width_m", spec.state.geometry.section_width_m)
      .add("pressure_bar", units::pa_to_bar(spec.state.pressure_pa))
      .add("load_n", load_n);
  // An unknown rim is null, as an unknown rated load is (it read 0 m).
  if (spec.state.geometry.rim_radius_m > 0.0) j.add("rim_radius_m", spec.state.geometry.rim_radius_m); else j.add_null("rim_radius_m");
  if (spec.max_load_n > 0.0) j.add("max_load_n", spec.max_load_n); else j.add_null("max_load_n");
  j.add("speed_kmh", speed_kmh)
      .add("rrc", r.rrc)
      .add("rr_force_n", r.rr_force_n)
      .add("rr_power_w", r.rr_power_w)
      .add("stiffness_n_per_m", r.stiffness_n_per_m)
      .add("deflection_m", r.deflection_m)
      .add("contact_length_m", r.contact_length_m)
      .add("offset_e_m", r.offset_e_m)
      .add("rrc_coulomb", r.rrc_coulomb)
      .add("rrc_viscous", r.rrc_viscous)
      .add("rrc_rotational_drag", r.rrc_rotational_drag);
  return j;
}

}  // namespace rollsim
