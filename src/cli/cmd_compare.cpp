// `rollsim compare`: tyre selection for a car: fit checks and a ranking by cycle energy or fuel per cycle.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "rollsim/common/text.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/report/simulation_report.hpp"
#include "rollsim/report/table.hpp"
#include "rollsim/selection/common.hpp"
#include "rollsim/selection/compare.hpp"
#include "rollsim/selection/front_end.hpp"
#include "selection_cli.hpp"

namespace rollsim::cli {
namespace {

struct CompareOptionsText {
  std::vector<std::string> vehicles, tyres, cycles;
  std::string catalogue;
  bool use_catalogue = false;
  std::string diameter_tolerance_pct = "3";
  bool json = false, csv = false, replay = false;
  std::string threads;
};

std::string signed_fixed(double v, int d) { return (v > 0 ? "+" : "") + fixed(v, d); }

void print_table(const selection::Comparison& c, bool replay) {
  const std::string unit = selection::energy_unit_label(c.unit);
  std::cout << c.vehicle << " on " << c.cycle << ": tyres ranked by " << (c.shows_range ? "battery energy" : "fuel")
            << " (" << selection::run_mode_label(replay) << ", tyre on all four wheels; RRC and RR power at 80 km/h and "
            << fixed(c.wheel_load_n, 0) << " N per wheel)\n";  // the ranked front's said 0 N when none fit
  std::vector<std::string> h{"#", "tyre", "size", "p [bar]", "RRC x1000", "P_RR [W]", unit, "vs own [%]"};
  if (c.shows_range) h.push_back("range chg [km]");
  h.push_back("fit");
  report::TextTable t(h);
  t.set_left_aligned(1);
  t.set_left_aligned(2);
  t.set_left_aligned(h.size() - 1);
  auto row = [&](const selection::CandidateResult& r, const std::string& rank) {
    std::vector<std::string> cells{rank, r.tyre.name + (r.is_own ? " (own)" : ""), selection::tyre_size_text(r.tyre),
                                   fixed(units::pa_to_bar(r.tyre.state.pressure_pa), 1),
                                   r.simulated ? fixed(r.rrc_80 * 1e3, 3) : "-", r.simulated ? fixed(r.rr_power_80_w, 1) : "-",
                                   r.simulated ? fixed(r.value, c.shows_range ? 4 : 3) : "-",
                                   r.simulated ? signed_fixed(r.diff_pct, 2) : "-"};
    if (c.shows_range) cells.push_back(r.simulated && std::isfinite(r.range_change_km) ? signed_fixed(r.range_change_km, 1) : "-");
    cells.push_back(r.fit.fits ? "ok (" + signed_fixed(r.fit.diameter_change_pct, 1) + " % dia., load " +
                                     fixed(100.0 * r.fit.wheel_load_n / r.fit.capacity_n, 0) + " %)"
                               : r.fit.reason);
    t.add_row(cells);
  };
  for (std::size_t i = 0; i < c.ranked.size(); ++i) row(c.ranked[i], std::to_string(i + 1));
  for (const auto& r : c.unfit) row(r, "-");
  std::cout << t.render();
  for (const auto& w : selection::trace_warnings(c)) std::cout << "WARNING: " << w << "\n";
  if (c.shows_range) {
    std::cout << "own tyre: " << fixed(c.own_value, 4) << " " << unit << ", range "
              << report::range_text(c.own_range_km, 1)
              << "; range column: gained (+) or lost (-) km\n";
  }
  std::cout << "\n";
}

void print_json(const selection::Comparison& c) {
  for (const auto& j : selection::comparison_json(c)) std::cout << j.str() << "\n";
}

// What is not known is an empty cell (a light truck's capacity, 0 in CandidateFit), as a range is where the car has none.
std::string known_or_empty(double x, int decimals, bool known) { return known && std::isfinite(x) ? fixed(x, decimals) : ""; }

// The JSON's fields, those added after the first release at the end so that a script reading columns by position
// keeps working.
void print_csv(const selection::Comparison& c, bool header) {
  if (header) {
    std::cout << "vehicle,cycle,rank,tyre,size,pressure_bar,rrc_80kmh,rr_power_80kmh_w,value,unit,diff_pct,range_km,"
                 "range_change_km,fits,reason,followed_trace,max_deficit_kmh,own,wheel_load_n,capacity_n,diameter_change_pct\n";
  }
  auto q = [](const std::string& s) {
    std::string o = "\"";
    for (char ch : valid_utf8(s)) o += ch == '"' ? std::string("\"\"") : std::string(1, ch);
    return o + "\"";
  };
  auto emit = [&](const selection::CandidateResult& r, int rank) {
    std::cout << q(c.vehicle) << "," << q(c.cycle) << "," << (rank > 0 ? std::to_string(rank) : "") << "," << q(r.tyre.name)
              << "," << q(selection::tyre_size_text(r.tyre)) << "," << fixed(units::pa_to_bar(r.tyre.state.pressure_pa), 2)
              << "," << known_or_empty(r.rrc_80, 6, r.simulated) << "," << known_or_empty(r.rr_power_80_w, 2, r.simulated) << ","
              << known_or_empty(r.value, 5, r.simulated) << "," << c.unit << "," << known_or_empty(r.diff_pct, 3, r.simulated) << ","
              << (c.shows_range && std::isfinite(r.range_km) ? fixed(r.range_km, 2) : "") << ","
              << (c.shows_range && std::isfinite(r.range_change_km) ? fixed(r.range_change_km, 2) : "") << "," << (r.fit.fits ? "yes" : "no") << ","
              << q(r.fit.reason) << "," << (r.simulated ? (r.trace.followed ? "yes" : "no") : "") << ","
              << known_or_empty(units::mps_to_kmh(r.trace.max_deficit_mps), 2, r.simulated) << "," << (r.is_own ? "yes" : "no") << ","
              << known_or_empty(r.fit.wheel_load_n, 1, true) << ","
              << known_or_empty(r.fit.capacity_n, 1, r.fit.capacity_n > 0.0) << ","
              << known_or_empty(r.fit.diameter_change_pct, 3, true) << "\n";
  };
  for (std::size_t i = 0; i < c.ranked.size(); ++i) emit(c.ranked[i], static_cast<int>(i + 1));
  for (const auto& r : c.unfit) emit(r, 0);
}

void run_compare(const CompareOptionsText& o, const ProcessGroup& group) {
  if (o.vehicles.empty()) throw InputError("--vehicle", "missing: give the car, e.g. --vehicle ev");
  if (o.json && o.csv) throw InputError("--csv", "not allowed together with --json");
  selection::CompareOptions copt;
  copt.diameter_tolerance_pct = selection::parse_diameter_tolerance_pct(o.diameter_tolerance_pct);
  copt.replay = o.replay;
  if (!o.threads.empty()) copt.threads = static_cast<unsigned>(parse_option_count(o.threads, "--threads", Range::closed(1, 1024)));
  copt.map_cases = group.mapper();

  // Candidates: --tyre files, then every *.yaml of the catalogue; a broken file is named and skipped.
  const selection::CandidateList list = selection::load_candidates(o.tyres, o.use_catalogue, o.catalogue);
  for (const auto& b : list.broken) std::cerr << "error: skipped broken catalogue file: " << b << "\n";
  const bool broken = !list.broken.empty();
  const std::vector<TyreSpec>& candidates = list.tyres;
  std::vector<std::string> cycles = o.cycles.empty() ? std::vector<std::string>{"nedc"} : o.cycles;
  bool csv_header = true;
  for (const auto& vname : o.vehicles) {
    const Vehicle v = load_vehicle_file(resolve_data_file(vname, "vehicles", ".yaml", "--vehicle"));
    for (const auto& cname : cycles) {
      const DriveCycle cycle = load_cycle_noted(cname, "--cycle");
      std::vector<std::string> left_out;
      const auto cmp = selection::compare_tyres(v, selection::without_duplicate_files(v, candidates, left_out), cycle, copt);
      for (const auto& d : left_out) std::cerr << "note: left out " << d << "\n";
      if (o.json) print_json(cmp);
      else if (o.csv) print_csv(cmp, csv_header);
      else print_table(cmp, o.replay);
      // The table carries the warnings; beside machine-readable output they go to stderr, not lost in a field.
      if (o.json || o.csv) {
        for (const auto& w : selection::trace_warnings(cmp)) std::cerr << "warning: " << w << "\n";
      }
      csv_header = false;
    }
  }
  if (broken) throw InputError("--catalogue", "some catalogue files were broken (named above); the rest were compared");
}

}  // namespace

void register_compare_command(CLI::App& app, const ProcessGroup& group) {
  auto o = std::make_shared<CompareOptionsText>();
  CLI::App* sub = app.add_subcommand("compare", "Tyre selection: rank tyres for a car by cycle energy or fuel, with fit checks");
  sub->add_option("--vehicle", o->vehicles, "Vehicle file or shipped name (repeatable)")->type_name("FILE");
  sub->add_option("--tyre", o->tyres, "Candidate tyre file or shipped name (repeatable)")->type_name("FILE");
  auto* cat = sub->add_option("--catalogue", o->catalogue,
                              "Compare every *.yaml tyre of a folder (default tyres/catalogue when no --tyre)")
                  ->type_name("DIR")
                  ->expected(0, 1);
  sub->add_option("--cycle", o->cycles, "Drive cycle name or CSV (repeatable; default nedc)")->type_name("CYCLE");
  sub->add_option("--diameter-tolerance-pct", o->diameter_tolerance_pct,
                  "Allowed outer-diameter change from the car's own tyre [%] (default 3)")
      ->type_name("PCT");
  sub->add_flag("--replay", o->replay, "Kinematic replay of the cycle instead of the forward simulation (driver + CVODE)");
  sub->add_option("--threads", o->threads, "Worker threads (default: every core; under mpirun, the node's cores over its ranks)")
      ->type_name("N");
  sub->add_flag("--json", o->json, "One JSON object per tyre per line");
  sub->add_flag("--csv", o->csv, "CSV with a header line");
  sub->callback([o, cat, &group] {
    o->use_catalogue = cat->count() > 0;
    run_compare(*o, group);
  });
}

}  // namespace rollsim::cli
