// `rollsim tyre fit`: a tyre's hysteresis-model constants from label points, measurements or J2452 sets.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "rollsim/common/atomic_file.hpp"
#include "rollsim/common/csv.hpp"
#include "rollsim/common/error.hpp"
#include "rollsim/common/format.hpp"
#include "rollsim/common/statistics.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/report/table.hpp"
#include "rollsim/tyre/j2452.hpp"
#include "rollsim/tyre/j2452_evaluation.hpp"
#include "rollsim/tyre/tyre_fit.hpp"
#include "rollsim/tyre/tyre_fit_plan.hpp"
#include "rollsim/tyre/tyre_spec.hpp"

namespace rollsim::cli {
namespace {

struct FitOptions {
  std::string size, label, j2452, measured, output, name, pressure_bar, free, uncertainty_pct, drum_radius_m;
  std::vector<std::string> points;
  std::string evaluate_j2452, held_out_j2452;
  bool json = false;
};

double number_in(const std::string& text, const std::string& where, const std::string& what) {
  const auto v = parse_number(text);
  if (!v || !std::isfinite(*v)) throw InputError(where, what + " '" + text + "' is not a number");
  return *v;
}

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  for (std::string cell; std::getline(ss, cell, sep);) out.push_back(trim(cell));
  // getline drops a last empty field: '0.008,' read as one field and '--free rrc_ref,' as one key (session 22).
  if (!text.empty() && text.back() == sep) out.emplace_back();
  return out;
}

// --point KPA,LOAD_N,KMH,RRC, or --point RRC at the size's ISO 28580 conditions.
RrcPoint parse_point(const std::string& text, const TyreSize& size) {
  const std::string where = "--point " + text;
  const auto f = split(text, ',');
  if (f.size() == 1) return iso28580_point(size, number_in(f[0], where, "RRC"), where);
  if (f.size() != 4) {
    throw InputError(where, "expected KPA,LOAD_N,KMH,RRC (e.g. 210,4000,80,0.0085) or RRC alone (ISO 28580 conditions)");
  }
  return rrc_point_from_file_units(number_in(f[0], where, "pressure [kPa]"), number_in(f[1], where, "load [N]"),
                                   number_in(f[2], where, "speed [km/h]"), number_in(f[3], where, "RRC"), where);
}

std::vector<HysteresisParam> parse_free(const std::string& text) {
  if (text.empty()) return {};
  return free_params_from_keys(split(text, ','), "--free " + text);
}

std::string pct(double x, int d = 2) { return fixed(x * 100.0, d); }

void print_fit(const TyreFit& fit, const TyreFitPlan& plan) {
  report::TextTable t({"constant", "value", "95 % low", "95 % high", "note"});
  t.set_left_aligned(0);
  t.set_left_aligned(4);
  auto g = [](double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%.4g", v);
    return std::string(b);
  };
  for (const auto& e : fit.params) {
    t.add_row({hysteresis_param_key(e.param), g(e.value), e.at_bound ? "-" : g(e.low95), e.at_bound ? "-" : g(e.high95),
               e.at_bound ? "fitted below 0: held at 0" : "fitted"});
  }
  for (auto p : fit.held) {
    t.add_row({hysteresis_param_key(p), g(hysteresis_param_value(fit.tyre.hysteresis, p)), "-", "-", "shared (J2452 sets)"});
  }
  // A constant held at its bound is not free: the degrees of freedom do not count it (session 21).
  const auto held_at_bound = std::count_if(fit.params.begin(), fit.params.end(), [](const auto& e) { return e.at_bound; });
  std::cout << "Hysteresis model fitted to " << fit.residuals.size() << " point(s), "
            << fit.params.size() - static_cast<std::size_t>(held_at_bound) << " constant(s) free"
            << (held_at_bound ? " and " + std::to_string(held_at_bound) + " held at 0" : std::string()) << "; intervals from the Jacobian with " << pct(fit.sigma_relative) << " % relative scatter ("
            << sigma_source(fit) << ")\n"
            << t.render();
  std::cout << "residuals: RMS " << pct(fit.rms_relative_error) << " %";
  double worst = 0.0;
  std::size_t iw = 0;
  for (std::size_t i = 0; i < fit.residuals.size(); ++i) {
    if (std::abs(fit.residuals[i].relative_error) > worst) worst = std::abs(fit.residuals[i].relative_error), iw = i;
  }
  std::cout << ", largest " << pct(worst) << " % (" << fit.residuals[iw].point.where << ")\n";
  if (fit.residuals.size() <= 12) {
    report::TextTable r({"point", "p [kPa]", "load [N]", "speed [km/h]", "RRC x1000", "model x1000", "error %"});
    r.set_left_aligned(0);
    for (const auto& x : fit.residuals) {
      r.add_row({x.point.where, fixed(x.point.pressure_pa / 1e3, 0), fixed(x.point.load_n, 0),
                 fixed(units::mps_to_kmh(x.point.speed_mps), 1), fixed(x.point.rrc * 1e3, 3),
                 fixed(x.model_rrc * 1e3, 3), pct(x.relative_error)});
    }
    std::cout << r.render();
  } else {
    std::cout << "(each point's residual: --json, one residual line per point)\n";
  }
  if (const auto c = label_check(fit, plan)) {
    const LabelBand& band = *plan.band;
    std::cout << "EU label class " << band.label_class << " (C1, Regulation (EU) 2020/740): RRC "
              << fixed(band.rrc_min * 1e3, 2) << (band.open_below ? " (open below)" : "") << " - "
              << fixed(band.rrc_max * 1e3, 2) << (band.open_above ? " (open above)" : "")
              << " kg/t on ISO 28580's 2.0 m drum; the fitted tyre at ISO 28580 conditions: " << fixed(c->drum_rrc * 1e3, 2)
              << " kg/t on the drum (" << fixed(c->flat_rrc * 1e3, 2) << " on a flat road, x " << fixed(c->drum_to_flat, 4)
              << "), " << (c->inside ? "inside" : "OUTSIDE") << " the band\n";
  }
}

std::string tyre_label(const TyreEvaluation& e) { return e.name + (e.flagged ? " *" : ""); }

double worst_of(const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); }

// Each tyre from one point against the baselines, with the exponents each gives.
void print_one_point_table(const J2452Evaluation& ev) {
  report::TextTable t({"tyre", "RRC kg/t", "one-point", "max", "full fit", "thesis", "constant", "median J2452", "p exp meas",
                       "p exp 1pt", "p exp full", "Z exp meas", "Z exp 1pt", "Z exp full", "rise meas %",
                       "rise 1pt %", "rise full %"});
  t.set_left_aligned(0);
  std::vector<double> cols[6];
  for (const auto& e : ev.tyres) {
    t.add_row({tyre_label(e), fixed(e.reference_rrc * 1e3, 2), pct(e.one_point_rms), pct(e.one_point_max), pct(e.full_fit_rms), pct(e.thesis_rms, 1),
               pct(e.constant_rms, 1), pct(e.median_shape_rms), fixed(e.measured.pressure_exponent, 3),
               fixed(e.one_point.pressure_exponent, 3), fixed(e.full_fit.pressure_exponent, 3),
               fixed(e.measured.load_exponent, 3), fixed(e.one_point.load_exponent, 3),
               fixed(e.full_fit.load_exponent, 3), pct(e.measured.speed_rise, 1), pct(e.one_point.speed_rise, 1),
               pct(e.full_fit.speed_rise, 1)});
    const double v[6] = {e.one_point_rms, e.one_point_max, e.full_fit_rms, e.thesis_rms, e.constant_rms, e.median_shape_rms};
    for (int k = 0; k < 6; ++k) cols[k].push_back(v[k]);
  }
  std::vector<std::string> med{"median", ""}, wst{"worst", ""};
  for (int k = 0; k < 6; ++k) {
    med.push_back(pct(median(cols[k]), k >= 3 && k <= 4 ? 1 : 2));
    wst.push_back(pct(worst_of(cols[k]), k >= 3 && k <= 4 ? 1 : 2));
  }
  for (int k = 0; k < 9; ++k) med.push_back(""), wst.push_back("");
  t.add_row(med);
  t.add_row(wst);
  std::cout << t.render();
  if (std::any_of(ev.tyres.begin(), ev.tyres.end(), [](const TyreEvaluation& e) { return e.flagged; })) {
    std::cout << "* value_flagged in the file: a value read with the correction its source note gives\n";
  }
  std::cout << "thesis model's own exponents (scaled): pressure " << fixed(ev.tyres.front().thesis.pressure_exponent, 3)
            << ", load " << fixed(ev.tyres.front().thesis.load_exponent, 3) << ", rise "
            << pct(ev.tyres.front().thesis.speed_rise, 1) << " % (" << ev.tyres.front().name << ")\n";
  const CommonShapeBound& b = ev.common_shape;
  std::cout << "best common shape in hindsight (all tyres seen, level set at the one point): worst tyre >= "
            << pct(b.worst_log_rms) << " % (RMS of the log ratio); the best such shape's relative RMS error per tyre, as the table's:";
  for (std::size_t i = 0; i < b.rms.size(); ++i) std::cout << (i ? ", " : " ") << pct(b.rms[i]);
  std::cout << " %\n";
  std::cout << "best mix of the shapes seen in hindsight (each tyre's nearest mix of the "
            << (ev.leave_one_out ? "other tyres'" : "training sets'")
            << " shapes, level free, chosen with its own grid in hand: no prediction that stays among the shapes seen does "
               "better), relative RMS error per tyre, as the table's:";
  for (std::size_t i = 0; i < ev.tyres.size(); ++i) std::cout << (i ? ", " : " ") << pct(ev.tyres[i].seen_shapes.rms);
  const auto hardest = std::max_element(ev.tyres.begin(), ev.tyres.end(), [](const TyreEvaluation& a, const TyreEvaluation& b) {
    return a.seen_shapes.log_rms < b.seen_shapes.log_rms;
  });
  std::cout << " %; worst " << hardest->name << " >= " << pct(hardest->seen_shapes.log_rms) << " % (RMS of the log ratio)\n";
}

// What more measured points buy: one row per measurement plan.
void print_plans_table(const J2452Evaluation& ev) {
  std::cout << "\nMore points measured on the held-out tyre besides the one point, the rest as above (RMS %):\n";
  std::vector<std::string> head{"measured besides", "fitted", "median", "worst"};
  for (const auto& e : ev.tyres) head.push_back(tyre_label(e));
  report::TextTable m(head);
  m.set_left_aligned(0);
  m.set_left_aligned(1);
  for (std::size_t k = 0; k < ev.plans.size(); ++k) {
    const std::vector<double> rms = plan_rms_column(ev, k);
    std::vector<std::string> cells{ev.plans[k].name, hysteresis_param_keys(ev.plans[k].fitted), pct(median(rms)),
                                   pct(worst_of(rms))};
    for (const double x : rms) cells.push_back(pct(x));
    m.add_row(cells);
  }
  std::cout << m.render();
}

void print_shared_constants(const J2452Evaluation& ev, std::size_t sets, const std::string& path, bool held_out) {
  std::cout << "\nShared constants fitted on all " << sets << " sets of " << path
            << (held_out ? ":\n" : " and, leave-one-tyre-out, without each:\n");
  report::TextTable s({held_out ? "fitted on" : "fitted without", "frequency_slope_per_hz", "deflection_exponent", "load_exponent",
                       "speed_loss_rrc_per_hz2", "speed_loss_load_exponent"});
  s.set_left_aligned(0);
  auto row = [&](const std::string& name, const HysteresisConstants& c) {
    char b[5][32];
    std::snprintf(b[0], 32, "%.5g", c.frequency_slope_per_hz);
    std::snprintf(b[1], 32, "%.5g", c.deflection_exponent);
    std::snprintf(b[2], 32, "%.5g", c.load_exponent);
    std::snprintf(b[3], 32, "%.5g", c.speed_loss_rrc_per_hz2);
    std::snprintf(b[4], 32, "%.5g", c.speed_loss_load_exponent);
    s.add_row({name, b[0], b[1], b[2], b[3], b[4]});
  };
  row(held_out ? "all sets" : "(none: all sets)", ev.shared_all);
  if (!held_out) {
    for (const auto& e : ev.tyres) row(e.name, e.shared);
  }
  std::cout << s.render();
}

void run_evaluate(const std::string& path, const std::string& held_out_path, const std::string& drum_text, bool json) {
  const double drum = drum_text.empty() ? kJ2452DrumRadius_m
                                        : checked_drum_radius_m(number_in(drum_text, "--drum-radius-m", "drum radius"),
                                                                "--drum-radius-m");
  const auto sets = load_j2452_csv(path);
  if (sets.size() < 3) throw InputError(path, "too few sets for leave-one-tyre-out: need 3 or more");
  const bool held_out = !held_out_path.empty();
  const std::vector<J2452Set> judged = held_out ? load_j2452_csv(held_out_path) : std::vector<J2452Set>{};
  const J2452Evaluation ev =
      held_out ? evaluate_j2452_held_out(sets, judged, drum, path, "--held-out-j2452 " + held_out_path) : evaluate_j2452(sets, drum);
  if (json) return write_j2452_evaluation_json(std::cout, ev);
  std::cout << "RMS relative RRC error over 180-300 kPa x 3-6 kN x 15-115 km/h (150 points), %; one point = 210 kPa, "
               "4000 N, 80 km/h; "
            << (held_out ? "shared constants and median J2452 shape fitted once on the " + std::to_string(sets.size()) +
                               " sets of " + path + ", none of the tyres below\n"
                         : std::string("shared constants fitted leave-one-tyre-out\n"));
  print_one_point_table(ev);
  print_plans_table(ev);
  print_shared_constants(ev, sets.size(), path, held_out);
}

void run_fit(const FitOptions& o) {
  if (!o.held_out_j2452.empty() && o.evaluate_j2452.empty()) {
    throw InputError("--held-out-j2452", "needs --evaluate-j2452 FILE: the sets the shared constants are fitted on");
  }
  if (!o.evaluate_j2452.empty()) {
    for (const auto& [given, option] : {std::pair{!o.size.empty(), "--size"}, {!o.points.empty(), "--point"},
                                        {!o.measured.empty(), "--measured"}, {!o.j2452.empty(), "--j2452"},
                                        {!o.label.empty(), "--label"}, {!o.output.empty(), "--output"},
                                        {!o.free.empty(), "--free"}, {!o.pressure_bar.empty(), "--pressure-bar"},
                                        {!o.name.empty(), "--name"}, {!o.uncertainty_pct.empty(), "--rrc-uncertainty-pct"}}) {
      if (given) throw InputError(option, "not allowed with --evaluate-j2452, which judges the model on the file's sets and "
                                          "fits no tyre of its own");
    }
    return run_evaluate(o.evaluate_j2452, o.held_out_j2452, o.drum_radius_m, o.json);
  }
  if (o.size.empty()) throw InputError("--size", "missing: the tyre's size designation, e.g. \"205/55 R16 91V\"");
  if (o.output.empty()) throw InputError("--output", "missing: the tyre file to write, e.g. --output my-tyre.yaml");
  check_output_file(o.output, "--output", {o.measured});
  TyreFitInputs in;
  in.size = parse_tyre_size(o.size, "--size");
  const TyreSize& size = in.size;
  for (const auto& p : o.points) in.points.push_back(parse_point(p, size));
  if (!o.measured.empty()) {
    for (auto& p : load_measured_rrc_csv(o.measured, &in.notes)) in.points.push_back(p);
  }
  if (!o.label.empty()) {
    in.label_class = o.label;
    in.label_where = "--label " + o.label;
  }
  if (!o.j2452.empty()) {
    in.j2452 = parse_j2452_text(o.j2452, "--j2452 " + o.j2452);
    in.j2452_where = "--j2452";
  }
  if (!o.drum_radius_m.empty()) in.drum_radius_m = number_in(o.drum_radius_m, "--drum-radius-m", "drum radius");
  in.drum_where = "--drum-radius-m";
  if (!o.uncertainty_pct.empty()) in.uncertainty_pct = number_in(o.uncertainty_pct, "--rrc-uncertainty-pct", "uncertainty");
  in.uncertainty_where = "--rrc-uncertainty-pct";
  in.free = parse_free(o.free);
  const TyreFitPlan plan = plan_tyre_fit(in);
  const TyreFit fit = fit_hysteresis(plan.start, plan.request);

  FittedTyreFile file;
  file.name = o.name.empty() ? std::filesystem::path(o.output).stem().string() : o.name;
  file.size = o.size;
  file.pressure_pa = fitted_file_pressure_pa(
      size, o.pressure_bar.empty() ? std::nullopt : std::optional(number_in(o.pressure_bar, "--pressure-bar", "pressure")),
      "--pressure-bar");
  std::string src = "rollsim tyre fit";
  if (!o.points.empty()) src += ", " + std::to_string(o.points.size()) + " --point";
  if (!o.measured.empty()) src += ", --measured " + o.measured;
  if (!o.j2452.empty()) src += ", --j2452 " + o.j2452;
  if (!o.label.empty()) src += ", --label " + o.label;
  file.source = src;
  const std::string text = fitted_tyre_file_text(file, fit);  // a fit no file may hold is refused before it is shown
  for (const auto& w : plan.warnings) std::cerr << "warning: " << w << "\n";
  for (const auto& w : fit.warnings) std::cerr << "warning: " << w << "\n";
  if (o.json) {
    write_tyre_fit_json(std::cout, fit, plan);
  } else {
    print_fit(fit, plan);
  }
  write_file_atomically(o.output, "--output", [&](std::ostream& out) { out << text; });
  if (!o.json) std::cout << "wrote " << o.output << "\n";
}

}  // namespace

void register_tyre_fit_command(CLI::App& tyre) {
  auto o = std::make_shared<FitOptions>();
  CLI::App* sub = tyre.add_subcommand(
      "fit", "Fit a tyre's hysteresis-model constants to label points, measurements or a J2452 set; write a tyre file");
  sub->add_option("--size", o->size, "Size designation, e.g. \"205/55 R16 91V\" (load index needed for ISO points)")
      ->type_name("SIZE");
  sub->add_option("--point", o->points, "Measured point KPA,LOAD_N,KMH,RRC, or RRC alone at ISO 28580 conditions; "
                                        "repeatable")
      ->type_name("P,Z,V,RRC")
      ->take_all();
  sub->add_option("--measured", o->measured, "CSV with columns pressure_kpa, load_n, speed_kmh, rrc")->type_name("FILE");
  sub->add_option("--j2452", o->j2452, "SAE J2452 set: F[N] = P[kPa]^ALPHA Z[N]^BETA (A + B V + C V^2), V in km/h, "
                                       "on a drum; sampled on the 150-point grid, corrected to a flat road")
      ->type_name("ALPHA,BETA,A,B,C");
  sub->add_option("--drum-radius-m", o->drum_radius_m, "Drum radius of the J2452 test (default 0.85)")->type_name("M");
  sub->add_option("--label", o->label, "EU tyre label fuel-efficiency class A-E (C1): its RRC band")->type_name("CLASS");
  sub->add_option("--free", o->free, "Constants to fit (comma list; default: what the points determine)")
      ->type_name("LIST");
  sub->add_option("--rrc-uncertainty-pct", o->uncertainty_pct,
                  "Relative scatter of a point for intervals when no degrees of freedom are left (default 2)")
      ->type_name("PCT");
  sub->add_option("--pressure-bar", o->pressure_bar, "Inflation pressure written to the file (default: ISO 28580's)")
      ->type_name("BAR");
  sub->add_option("--name", o->name, "Name in the tyre file (default: the output's file name)");
  sub->add_option("--output", o->output, "Tyre file to write")->type_name("T.yaml");
  sub->add_option("--evaluate-j2452", o->evaluate_j2452,
                  "Instead of fitting: judge the model on a CSV of J2452 sets, leave-one-tyre-out, with baselines")
      ->type_name("FILE");
  sub->add_flag("--json", o->json,
                "JSON lines instead of tables: the fit, each constant, each point's residual (with --evaluate-j2452: "
                "each tyre, each measurement plan, the common-shape bound, the shared constants)");
  sub->add_option("--held-out-j2452", o->held_out_j2452,
                  "With --evaluate-j2452: fit the shared constants once on its sets and judge them on these instead")
      ->type_name("FILE");
  sub->callback([o] { run_fit(*o); });
}

}  // namespace rollsim::cli
