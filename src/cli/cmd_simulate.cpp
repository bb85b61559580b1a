// `rollsim simulate`: a car over one or more drive cycles with one or more tyre sets; CLI glue only.
#include <CLI/CLI.hpp>

#include <cmath>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/common/atomic_file.hpp"
#include "rollsim/common/error.hpp"
#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/report/simulation_report.hpp"
#include "rollsim/sim/simulation.hpp"
#include "rollsim/sim/vehicle_run.hpp"

namespace rollsim::cli {
namespace {

struct SimulateOptions {
  std::string vehicle;
  std::vector<std::string> tyres;
  std::vector<std::string> cycles;
  std::string trace_path;
  bool json = false;
  bool replay = false;
  bool stats = false;
};

struct Run {
  std::string tyre_label;
  SimulationResult result;
  std::string tyre_file;       ///< the front tyres' file (the set given, or the car's own); empty: none
  std::string rear_tyre_file;  ///< the rear tyres' file
  std::string cycle_file;
};

void run_simulate(const SimulateOptions& o) {
  // It printed nothing in silence (session 22's notes).
  if (o.stats && o.replay) throw InputError("--stats", "reports CVODE's work, and --replay runs no ODE solver: give one of them");
  const Vehicle base = load_vehicle_file(resolve_data_file(o.vehicle, "vehicles", ".yaml", "--vehicle"));
  std::vector<std::string> inputs = vehicle_input_files(base);
  std::vector<std::optional<TyreSpec>> tyre_sets;
  for (const auto& t : o.tyres) {
    inputs.push_back(resolve_data_file(t, "tyres", ".yaml", "--tyre"));
    tyre_sets.emplace_back(load_tyre_file(inputs.back()));
  }

  if (tyre_sets.empty()) tyre_sets.emplace_back(std::nullopt);
  std::vector<DriveCycle> cycles;
  for (const auto& c : o.cycles.empty() ? std::vector<std::string>{"nedc"} : o.cycles) cycles.push_back(load_cycle_noted(c, "--cycle"));
  for (const auto& c : cycles) inputs.push_back(c.source);
  if (!o.trace_path.empty() && tyre_sets.size() * cycles.size() > 1)
    throw InputError("--trace", "writes the time series of one run; give one --tyre and one --cycle with it");
  if (!o.trace_path.empty()) check_output_file(o.trace_path, "--trace", inputs);

  SimulationOptions sim_opt;
  sim_opt.record_trace = !o.trace_path.empty();
  std::vector<Run> runs;
  for (const auto& cycle : cycles) {
    for (const auto& tyre : tyre_sets) {
      VehicleRun run = run_vehicle(base, tyre, cycle, o.replay, sim_opt);
      // Once per tyre set (the first cycle): an overloaded tyre is allowed but said.
      if (&cycle == &cycles.front()) {
        for (const auto& w : run.warnings) std::cerr << "warning: " << w << "\n";
      }
      const Vehicle& v = run.vehicle;
      // With coast-down road load, say how much of A the tyres account for (the rest is driveline drag).
      if (v.coastdown && v.front_tyre && !o.json) {
        const double tyre_a_n = tyre_rolling_force_at_standstill_limit_n(v);
        std::cout << "tyres' share of coast-down A: " << fixed(tyre_a_n, 1) << " N of "
                  << fixed(v.coastdown->a_n, 1) << " N (" << fixed(100.0 * tyre_a_n / v.coastdown->a_n, 1)
                  << " %)\n";
        // More than the whole A term: these tyres roll harder than the tested car's tyres and driveline together,
        // which its coast-down cannot show (the road load stays the coast-down's).
        if (tyre_a_n > v.coastdown->a_n)
          std::cerr << "warning: " << run.tyre_label << ": these tyres alone need " << fixed(tyre_a_n, 1)
                    << " N at standstill, more than the coast-down's whole A of " << fixed(v.coastdown->a_n, 1)
                    << " N (tyres and driveline): the figures keep the coast-down's road load, so they do not show "
                       "these tyres' rolling resistance\n";
      }
      const auto [front_file, rear_file] = tyre_files(run);
      runs.push_back({run.tyre_label, std::move(run.result), front_file, rear_file, cycle.source});
    }
  }

  if (!o.trace_path.empty()) {
    write_file_atomically(o.trace_path, "--trace", [&](std::ostream& out) { report::write_trace_csv(out, runs.front().result); });
  }
  if (o.json) {
    // The files too: two cycles or tyres of one name (a user's udds.csv beside the shipped one) read alike (session 22).
    for (const auto& run : runs) {
      JsonObject j = report::to_json(run.result, run.tyre_label);
      report::add_input_files(j, {base.source, run.tyre_file, run.cycle_file, run.rear_tyre_file});
      std::cout << j.str() << "\n";
    }
    // The text's warnings (a battery run empty, a trace not followed) go where warnings go: the JSON alone gave a
    // negative state of charge without a word (session 20).
    for (const auto& run : runs)
      for (const auto& c : report::run_caveats(run.result))
        std::cerr << "warning: " << run.result.cycle << ", " << run.tyre_label << ": " << c << "\n";
    return;
  }
  if (runs.size() == 1) {
    std::cout << "tyres: " << runs.front().tyre_label << "\n" << report::summary_text(runs.front().result, o.stats);
    return;
  }
  // Several runs: one table, each against the first run on the same cycle.
  const std::string unit = report::headline_unit(runs.front().result);
  report::TextTable t({"cycle", "tyre", unit, "diff %", "rolling kWh", "rolling diff %",
                       runs.front().result.fuel ? "CO2 g/km" : "range km", "max err km/h"});
  t.set_left_aligned(0);
  t.set_left_aligned(1);
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const auto& r = runs[i].result;
    const auto& ref = runs[i - i % tyre_sets.size()].result;
    const double value = report::headline_value(r), ref_value = report::headline_value(ref);
    // A run that did not move has no per-distance figure (and no rolling energy to compare): "-", not inf or NaN.
    auto shown = [](double x, int digits) { return std::isfinite(x) ? fixed(x, digits) : std::string("-"); };
    t.add_row({r.cycle, runs[i].tyre_label, shown(value, 3), shown(100.0 * (value / ref_value - 1.0), 2),
               fixed(units::j_to_kwh(r.energy.rolling_j), 4),
               shown(100.0 * (r.energy.rolling_j / ref.energy.rolling_j - 1.0), 2),
               shown(r.fuel ? r.co2_g_per_km() : r.range_km(), 1), fixed(units::mps_to_kmh(r.max_speed_error_mps), 2)});
  }
  std::cout << base.name << " (" << (o.replay ? "replay" : "forward") << " simulation)\n" << t.render();
  std::cout << "diff %: against the first tyre on the same cycle\n";
  for (const auto& run : runs) {
    for (const auto& c : report::run_caveats(run.result)) {
      std::cout << "WARNING: " << run.result.cycle << ", " << run.tyre_label << ": " << c << "\n";
    }
  }
}

}  // namespace

void register_simulate_command(CLI::App& app) {
  auto opts = std::make_shared<SimulateOptions>();
  auto* sub = app.add_subcommand("simulate", "Drive a car over drive cycles and report energy or fuel use");
  sub->add_option("--vehicle", opts->vehicle, "Vehicle file (YAML); a bare name is looked up in vehicles/")->required();
  sub->add_option("--tyre", opts->tyres, "Tyre file for all four wheels, overriding the vehicle's; repeat to compare");
  sub->add_option("--cycle", opts->cycles, "Cycle name (nedc, wltc, udds, ftp75, hwfet, us06, artemis_*) or CSV; repeat to compare (default nedc)");
  sub->add_flag("--replay", opts->replay, "Kinematic replay: follow the trace exactly, no driver and no ODE solver");
  sub->add_flag("--json", opts->json, "One JSON object per run per line");
  sub->add_flag("--stats", opts->stats, "Print CVODE's statistics (steps, right-hand-side calls, failures)");
  sub->add_option("--trace", opts->trace_path, "Write the time series of the run to this CSV file");
  sub->callback([opts] { run_simulate(*opts); });
}

}  // namespace rollsim::cli
