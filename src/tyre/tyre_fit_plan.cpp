#include "rollsim/tyre/tyre_fit_plan.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "rollsim/common/error.hpp"
#include "rollsim/common/format.hpp"
#include "rollsim/common/json.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/tyre/tyre_request.hpp"
#include "rollsim/tyre/tyre_spec.hpp"

namespace rollsim {

TyreFitPlan plan_tyre_fit(const TyreFitInputs& in) {
  TyreFitPlan plan;
  plan.start.geometry.outer_radius_m = in.size.outer_radius_m;
  plan.start.geometry.section_width_m = in.size.section_width_m;
  plan.start.geometry.rim_radius_m = in.size.rim_diameter_m / 2.0;
  if (in.label_class) {
    plan.band = eu_label_band_c1(*in.label_class, in.label_where);
    plan.iso = iso28580_point(in.size, std::sqrt(plan.band->rrc_min * plan.band->rrc_max), in.label_where);
  }
  plan.request.points = in.points;
  if (in.drum_radius_m && !in.j2452) {
    throw InputError(in.drum_where, "applies to a J2452 set only (its test drum); there is none: an ISO 28580 point or "
                                    "label is on ISO 28580's 2.0 m drum, and --point KPA,LOAD_N,KMH,RRC is a flat-road RRC");
  }
  if (in.j2452) {
    J2452Set set = *in.j2452;
    set.rolling_radius_m = in.size.outer_radius_m;
    const double drum = in.drum_radius_m ? checked_drum_radius_m(*in.drum_radius_m, in.drum_where) : kJ2452DrumRadius_m;
    for (auto& p : sample_j2452(set, j2452_grid(), drum, in.j2452_where + " grid")) plan.request.points.push_back(p);
  }
  if (plan.band && plan.request.points.empty()) {
    plan.request.points.push_back(*plan.iso);
    // The level's interval is symmetric in its logarithm: centred on the band's geometric middle, 1.96 standard
    // errors span 95 % of the band's log width, as a uniform band's 95 % interval does. Half-width / sqrt 3, the
    // uniform's own standard deviation, gave +-1.13 half-widths, wider than the band (session 22's outside testing).
    plan.request.assumed_relative_uncertainty = 0.95 * 0.5 * std::log(plan.band->rrc_max / plan.band->rrc_min) / 1.96;
  }
  if (in.uncertainty_pct) {
    plan.request.assumed_relative_uncertainty =
        checked_number(*in.uncertainty_pct, in.uncertainty_where, Range::open_low(0.0, 50.0)) / 100.0;
  }
  plan.request.free = in.free;
  // The tyre file's own rule for the size's class, so that the file reproduces its points (50-600 kPa for any tyre
  // took 50 kPa for a passenger tyre, whose file then refused it, and refused a light-truck tyre's 655 kPa).
  for (const auto& p : plan.request.points) check_pressure_plausible_kpa(p.pressure_pa / 1e3, in.size, p.where);
  for (const auto& n : in.notes) plan.warnings.push_back(n);
  // A point loaded past the size's rating is allowed but said, as `rollsim tyre` says it (session 22).
  if (in.size.load_index) {
    const double rated_n = *load_index_max_load_kg(*in.size.load_index) * units::kStandardGravity_mps2;
    for (const auto& p : in.points) {
      if (p.load_n > rated_n) {
        plan.warnings.push_back(p.where + ": load " + fixed(p.load_n, 0) + " N is above the tyre's rated maximum " +
                                fixed(rated_n, 0) + " N (load index " + std::to_string(*in.size.load_index) +
                                "); the fit there is outside the tyre's rating");
      }
      if (std::string kg = load_in_kg_hint(p.load_n, rated_n); !kg.empty()) plan.warnings.push_back(p.where + ": " + kg);
    }
  }
  return plan;
}

std::optional<LabelCheck> label_check(const TyreFit& fit, const TyreFitPlan& plan) {
  if (!plan.band || !plan.iso) return std::nullopt;
  TyreState at = fit.tyre;
  at.pressure_pa = plan.iso->pressure_pa;
  LabelCheck c;
  c.flat_rrc = evaluate_rolling_resistance(at, plan.iso->load_n, plan.iso->speed_mps).rrc;
  c.drum_to_flat = drum_to_flat_factor(kIso28580DrumRadius_m, plan.start.geometry.outer_radius_m);
  c.drum_rrc = c.flat_rrc / c.drum_to_flat;
  c.inside = plan.band->contains(c.drum_rrc);
  return c;
}

std::vector<HysteresisParam> free_params_from_keys(const std::vector<std::string>& keys, const std::string& where) {
  std::vector<HysteresisParam> out;
  for (const auto& key : keys) {
    const auto p = hysteresis_param_from_key(key);
    if (!p) {
      throw InputError(where, "'" + key + "' is not a constant of the hysteresis model; allowed: " +
                                  hysteresis_param_keys(all_hysteresis_params()));
    }
    out.push_back(*p);
  }
  if (!out.empty() && std::find(out.begin(), out.end(), HysteresisParam::RrcRef) == out.end()) {
    out.insert(out.begin(), HysteresisParam::RrcRef);  // the level is always the tyre's own
  }
  return out;
}

double fitted_file_pressure_pa(const TyreSize& size, std::optional<double> pressure_bar, const std::string& where) {
  if (!pressure_bar && size.commercial) {
    throw InputError(where, "missing: a light-truck, van or truck tyre ('" + size.designation + "') runs at the pressure "
                            "of its load-inflation table, not a passenger tyre's 2.1 bar; give the pressure to write in bar");
  }
  if (!pressure_bar) return iso28580_passenger_pressure_pa(size);
  // The tyre file's own check, so that every file written here is one the other commands read (0.5-6 bar was taken
  // here and 0.6 bar refused by `rollsim tyre`: session 21).
  check_pressure_plausible(checked_number(*pressure_bar, where, Range::closed(0.0, 1e3)), size, where);
  return units::bar_to_pa(*pressure_bar);
}

std::string fitted_tyre_file_text(const FittedTyreFile& file, const TyreFit& fit) {
  std::ostringstream text;
  write_fitted_tyre_yaml(text, file, fit);
  try {
    load_tyre_text(text.str(), file.name);
  } catch (const InputError& e) {
    throw InputError("tyre fit", "the fitted tyre is not one a tyre file may hold (" + std::string(e.what()) +
                                     "): the points ask for more than the model can give; check their RRCs and "
                                     "conditions, or hold constants with --free; nothing written");
  }
  return text.str();
}

namespace {
// An edge of a label band in kg/t as declared (6.55, not the 6.550000000000001 the product gives).
double kg_per_t(double rrc) { return std::round(rrc * 1e9) / 1e6; }
}  // namespace

void write_tyre_fit_json(std::ostream& out, const TyreFit& fit, const TyreFitPlan& plan) {
  JsonObject head;
  head.add("kind", "fit")
      .add("points", static_cast<int>(fit.residuals.size()))
      .add("degrees_of_freedom", fit.degrees_of_freedom)
      .add("rms_error_pct", 100.0 * fit.rms_relative_error)
      .add("sigma_pct", 100.0 * fit.sigma_relative)
      .add("interval_quantile", fit.interval_quantile)
      .add("sigma_from_residuals", fit.sigma_from_residuals);
  if (const auto c = label_check(fit, plan)) {
    head.add("label_class", std::string(1, plan.band->label_class))
        .add("label_rrc_min_kg_per_t", kg_per_t(plan.band->rrc_min))
        .add("label_rrc_max_kg_per_t", kg_per_t(plan.band->rrc_max))
        .add("label_open_below", plan.band->open_below)  // A and E: the edge given there is our closing one
        .add("label_open_above", plan.band->open_above)
        .add("iso_rrc_kg_per_t", 1e3 * c->drum_rrc)
        .add("iso_flat_rrc_kg_per_t", 1e3 * c->flat_rrc)
        .add("iso_drum_to_flat", c->drum_to_flat)
        .add("inside_label_band", c->inside);
  }
  out << head.str() << '\n';
  for (const auto& p : fit.params) {
    // Held at its bound, a constant has no interval (it was 0 to 0, "95 %", with "free": true; session 21).
    JsonObject j;
    j.add("kind", "param").add("key", hysteresis_param_key(p.param)).add("free", !p.at_bound).add("value", p.value);
    if (p.at_bound) j.add_null("std_error").add_null("low95").add_null("high95");
    else j.add("std_error", p.std_error).add("low95", p.low95).add("high95", p.high95);
    out << j.add("at_bound", p.at_bound).str() << '\n';
  }
  for (const auto p : fit.held) {
    out << JsonObject()
               .add("kind", "param")
               .add("key", hysteresis_param_key(p))
               .add("free", false)
               .add("value", hysteresis_param_value(fit.tyre.hysteresis, p))
               .str()
        << '\n';
  }
  for (const auto& r : fit.residuals) {
    out << JsonObject()
               .add("kind", "residual")
               .add("where", r.point.where)
               .add("pressure_kpa", r.point.pressure_pa / 1e3)
               .add("load_n", r.point.load_n)
               .add("speed_kmh", units::mps_to_kmh(r.point.speed_mps))
               .add("rrc", r.point.rrc)
               .add("model_rrc", r.model_rrc)
               .add("error_pct", 100.0 * r.relative_error)
               .str()
        << '\n';
  }
}

}  // namespace rollsim
