// `rollsim tyre`: one tyre at one load and one or more speeds, as a table, JSON lines, or an explanation.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "selection_cli.hpp"
#include "rollsim/common/error.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/report/table.hpp"
#include "rollsim/tyre/explain.hpp"
#include "rollsim/tyre/tyre_model.hpp"
#include "rollsim/tyre/tyre_request.hpp"
#include "rollsim/tyre/tyre_spec.hpp"

namespace rollsim::cli {
namespace {

// Options are taken as text and parsed here so that every bad value gets the same kind of message, naming the
// option, the value and what is allowed (CLI11 would accept "nan" silently for a double).
struct TyreOptions {
  TyreRequest tyre;
  std::vector<std::string> speeds_kmh;
  bool json = false;
  bool explain = false;
};

std::string kg_text(double n) { return fixed(n / units::kStandardGravity_mps2, 0) + " kg"; }

std::string describe_tyre(const TyreSpec& spec) {
  const auto& g = spec.state.geometry;
  std::string s = "tyre " + spec.name;
  if (spec.size && spec.size->designation != spec.name) s += " (" + spec.size->designation + ")";
  s += ": outer radius " + fixed(g.outer_radius_m * 1e3, 1) + " mm, section width " +
       fixed(g.section_width_m * 1e3, 0) + " mm";
  if (g.rim_radius_m > 0.0) s += ", rim radius " + fixed(g.rim_radius_m * 1e3, 1) + " mm";
  s += ", " + fixed(units::pa_to_bar(spec.state.pressure_pa), 2) + " bar";
  if (spec.max_load_n > 0.0) {
    s += ", max load " + fixed(spec.max_load_n, 0) + " N (" + kg_text(spec.max_load_n) + ")";
  } else {
    s += ", max load unknown";
  }
  return s + "\n";
}

std::string explanation_text(const TyreExplanation& x) {
  std::string out = "\nElasticities at " + fixed(x.load_n, 0) + " N, " +
                    fixed(units::mps_to_kmh(x.speed_mps), 1) +
                    " km/h (% change of the output per % change of the parameter; model, central differences)\n";
  report::TextTable t({"parameter", "value", "RRC", "sign", "RR power", "deflection", "contact length"});
  t.set_left_aligned(0);
  t.set_left_aligned(3);
  for (const auto& p : x.parameters) {
    std::string value;
    switch (p.parameter) {
      case TyreParameter::OuterDiameter: value = fixed(p.value_si * 1e3, 1) + " mm"; break;
      case TyreParameter::SectionWidth: value = fixed(p.value_si * 1e3, 1) + " mm"; break;
      case TyreParameter::Pressure: value = fixed(units::pa_to_bar(p.value_si), 2) + " bar"; break;
      case TyreParameter::Load: value = fixed(p.value_si, 0) + " N"; break;
      case TyreParameter::Speed: value = fixed(units::mps_to_kmh(p.value_si), 1) + " km/h"; break;
    }
    t.add_row({p.name, value, fixed(p.rrc_elasticity, 3), elasticity_sign(p.rrc_elasticity),
               fixed(p.power_elasticity, 3), fixed(p.deflection_elasticity, 3),
               fixed(p.contact_length_elasticity, 3)});
  }
  out += t.render() + "\nMechanisms in this model:\n";
  for (const auto& p : x.parameters) out += "- " + p.name + ": " + p.mechanism + "\n";
  return out;
}

void run_tyre(const TyreOptions& o) {
  const TyreSpec spec = build_requested_tyre(o.tyre);
  const TyreLoadChoice load = choose_requested_load(o.tyre, spec);
  if (o.explain && spec.state.model != TyreModelKind::Thesis) {
    throw InputError("--explain", "explains the thesis model's mechanisms; " + spec.source +
                                      " uses the hysteresis model (model: kind: hysteresis)");
  }

  std::vector<double> speeds_kmh;
  for (const auto& given : o.speeds_kmh) {
    // Split here rather than by CLI11, which drops empty items: "1,,2" is a typo, not two speeds.
    std::size_t start = 0;
    while (true) {
      const std::size_t comma = given.find(',', start);
      const std::string item = given.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      if (item.empty()) throw InputError("--speed-kmh '" + given + "'", "an empty value between commas; give e.g. 50,80,120");
      speeds_kmh.push_back(parse_requested_speed_kmh(item));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
  }
  if (speeds_kmh.empty()) speeds_kmh.push_back(80.0);
  // Explaining needs a rolling tyre: at standstill RRC is 0 and has no elasticity.
  if (o.explain) {
    for (std::size_t i = 0; i < speeds_kmh.size(); ++i) {
      if (!(speeds_kmh[i] > 0.0)) {
        throw InputError("--speed-kmh " + format_value(speeds_kmh[i]), "0 is not allowed with --explain: must be > 0");
      }
    }
  }

  std::vector<RollingResistance> results;
  std::vector<TyreExplanation> explanations;
  for (const double v_kmh : speeds_kmh) {
    const double v_mps = units::kmh_to_mps(v_kmh);
    results.push_back(named_tyre_request(o.tyre, spec, load, [&] { return evaluate_rolling_resistance(spec.state, load.load_n, v_mps); }));
    if (o.explain) explanations.push_back(named_tyre_request(o.tyre, spec, load, [&] { return explain_tyre(spec.state, load.load_n, v_mps); }));
  }

  // Warned only once the point is known to be solvable, so a rejected load gets one message, not two.
  if (const std::string w = requested_load_warning(spec, load); !w.empty()) std::cerr << "warning: " << w << "\n";
  const double top_kmh = *std::max_element(speeds_kmh.begin(), speeds_kmh.end());
  if (const std::string w = speed_rating_warning(spec, units::kmh_to_mps(top_kmh), "--speed-kmh"); !w.empty())
    std::cerr << "warning: " << w << "\n";

  const double p_bar = units::pa_to_bar(spec.state.pressure_pa);
  if (o.json) {
    for (std::size_t i = 0; i < results.size(); ++i) {
      const auto& r = results[i];
      JsonObject j = tyre_point_json(spec, load.load_n, speeds_kmh[i], r);
      if (o.explain) {
        for (const auto& p : explanations[i].parameters) {
          // All the table and the text give (the mechanisms were dropped from --json: session 27's outside tester).
          j.add("elasticity_rrc_" + p.key, p.rrc_elasticity).add("elasticity_power_" + p.key, p.power_elasticity);
          j.add("elasticity_deflection_" + p.key, p.deflection_elasticity)
              .add("elasticity_contact_length_" + p.key, p.contact_length_elasticity)
              .add("mechanism_" + p.key, p.mechanism);
        }
      }
      std::cout << j.str() << "\n";
    }
    return;
  }

  std::cout << describe_tyre(spec);
  // The three parts of the RRC: the thesis model's damping mechanisms, or a fitted (hysteresis) tyre's loss at
  // zero speed, its rise with the rotation frequency and its speed-squared loss (the JSON keeps one set of keys).
  const bool thesis = spec.state.model == TyreModelKind::Thesis;
  report::TextTable t({"tyre", "p [bar]", "load [N]", "speed [km/h]", "Kz [N/mm]", "defl [mm]", "contact [mm]",
                       "RRC x1000", thesis ? "Coulomb" : "static", thesis ? "viscous" : "freq. rise",
                       thesis ? "drag" : "V^2 loss", "F_RR [N]", "P_RR [W]"});
  t.set_left_aligned(0);
  for (std::size_t i = 0; i < results.size(); ++i) {
    const auto& r = results[i];
    t.add_row({spec.name, fixed(p_bar, 2), fixed(load.load_n, 0), fixed(speeds_kmh[i], 1),
               fixed(r.stiffness_n_per_m * 1e-3, 1), fixed(r.deflection_m * 1e3, 2),
               fixed(r.contact_length_m * 1e3, 1), fixed(r.rrc * 1e3, 3),
               fixed(r.rrc_coulomb * 1e3, 3), fixed(r.rrc_viscous * 1e3, 3),
               fixed(r.rrc_rotational_drag * 1e3, 3), fixed(r.rr_force_n, 2),
               fixed(r.rr_power_w, 1)});
  }
  std::cout << t.render();
  for (const auto& x : explanations) std::cout << explanation_text(x);
}

}  // namespace

void register_tyre_command(CLI::App& app) {
  auto opts = std::make_shared<TyreOptions>();
  CLI::App* sub = app.add_subcommand(
      "tyre", "Rolling resistance of one tyre at one load and one or more speeds (table, --json, or --explain)");
  sub->add_option("tyre_file", opts->tyre.file,
                  "Tyre YAML file, or a name in the shipped tyres/ folder (e.g. 175-70R14)")
      ->type_name("FILE");
  sub->add_option("--size", opts->tyre.size, "Size designation instead of a file, e.g. \"175/70 R14 84T\"")
      ->type_name("SIZE");
  sub->add_option("--outer-radius-m", opts->tyre.outer_radius_m, "Unloaded outer radius R [m] (with --width-m)")->type_name("M");
  sub->add_option("--width-m", opts->tyre.width_m, "Section width W [m] (with --outer-radius-m)")->type_name("M");
  sub->add_option("--pressure-bar", opts->tyre.pressure_bar, "Inflation pressure [bar]; overrides a file's pressure")
      ->type_name("BAR");
  sub->add_option("--load-n", opts->tyre.load_n, "Normal load per tyre [N]")->type_name("N");
  sub->add_option("--load-pct", opts->tyre.load_pct, "Normal load as % of the tyre's maximum load (default 80)")
      ->type_name("PCT");
  sub->add_option("--speed-kmh", opts->speeds_kmh, "Speed(s) [km/h]: several values, repeated or comma-separated "
                                                    "(default 80)")
      ->type_name("KMH");
  sub->add_flag("--json", opts->json, "One JSON object per operating point per line");
  sub->add_flag("--explain", opts->explain, "Elasticities of RRC and RR power and the mechanism behind each");
  register_tyre_fit_command(*sub);
  sub->callback([opts, sub] {
    if (sub->got_subcommand("fit")) return;  // `rollsim tyre fit` runs its own callback
    run_tyre(*opts);
  });
}

}  // namespace rollsim::cli
