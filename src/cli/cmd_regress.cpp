// `rollsim regress`: runs the energy baseline's cases and fails naming each drifted case; --update rewrites it.
#include <iostream>
#include <memory>
#include <string>

#include "commands.hpp"
#include "rollsim/common/atomic_file.hpp"
#include "rollsim/report/simulation_report.hpp"
#include "rollsim/report/table.hpp"
#include "rollsim/selection/common.hpp"
#include "rollsim/selection/regress.hpp"
#include "selection_cli.hpp"

namespace rollsim::cli {
namespace {

struct RegressOptionsText {
  std::string file;
  bool update = false;
};

std::string signed_pct(double v) { return (v > 0 ? "+" : "") + fixed(v, 3); }

int run_regress(const RegressOptionsText& o) {
  const selection::Baseline b = selection::load_baseline(o.file, o.update);
  if (o.update) check_output_file(o.file, "--update");
  const auto outcomes = selection::run_baseline(b);
  report::TextTable t({"case", "vehicle", "tyre", "cycle", "expected", "actual", "unit", "drift [%]", "tol [%]", "status"});
  for (std::size_t c : {0u, 1u, 2u, 3u, 6u, 9u}) t.set_left_aligned(c);
  std::size_t drifted = 0;
  for (const auto& r : outcomes) {
    const bool is_new = r.c.is_new();
    t.add_row({r.c.name, r.c.vehicle, r.c.tyre, r.c.cycle, is_new ? "-" : fixed(r.c.expected, 4), fixed(r.actual, 4),
               selection::energy_unit_label(r.c.unit), is_new ? "-" : signed_pct(r.drift_pct), format_value(r.c.tolerance_pct),
               is_new ? "new" : r.drifted ? "DRIFTED" : "ok"});
    drifted += r.drifted;
  }
  std::cout << t.render();
  for (const auto& r : outcomes) {
    if (!r.trace.followed) std::cout << "WARNING: case '" << r.c.name << "': " << report::shortfall_caveat(r.trace) << "\n";
  }
  if (o.update) {
    std::size_t changed = 0;
    for (const auto& r : outcomes) {
      const std::string unit = selection::energy_unit_label(r.c.unit);
      if (r.c.is_new()) {
        ++changed;
        std::cout << "added " << r.c.name << ": " << fixed(r.actual, 4) << " " << unit << "\n";
      } else if (selection::baseline_value_text(r.actual) != selection::baseline_value_text(r.c.expected)) {
        // Changed as the file records it: full-precision noise below its six digits is no change.
        ++changed;
        std::cout << "updated " << r.c.name << ": " << fixed(r.c.expected, 4) << " -> " << fixed(r.actual, 4) << " " << unit
                  << " (" << signed_pct(r.drift_pct) << " %)\n";
      }
    }
    // Nothing changed, nothing written: the file keeps its time stamp (session 25's outside testing).
    if (changed == 0) {
      std::cout << "baseline " << o.file << " unchanged: 0 of " << outcomes.size() << " values changed\n";
      return 0;
    }
    bool rewritten = false;
    write_files_atomically({{o.file, "--update", selection::baseline_yaml(b, outcomes, &rewritten)}});
    if (rewritten)
      std::cerr << "warning: " << o.file << ": a value could not be written where it was read, so the file was written anew "
                << "in rollsim's layout: its comments and key order are not kept\n";
    std::cout << "baseline " << o.file << " rewritten: " << changed << " of " << outcomes.size() << " values changed\n";
    return 0;
  }
  for (const auto& r : outcomes) {
    if (r.drifted) {
      std::cerr << "error: case '" << r.c.name << "' drifted " << signed_pct(r.drift_pct) << " % ("
                << (r.drift_pct > 0 ? "up" : "down") << ": expected " << fixed(r.c.expected, 4) << ", got "
                << fixed(r.actual, 4) << " " << selection::energy_unit_label(r.c.unit) << ", tolerance "
                << format_value(r.c.tolerance_pct) << " %)\n";
    }
  }
  if (drifted) {
    std::cerr << "error: " << drifted << " of " << outcomes.size() << " cases drifted; if the change is deliberate, "
              << "run 'rollsim regress " << o.file << " --update'\n";
    return 1;
  }
  std::cout << (outcomes.size() == 1 ? "the case is" : "all " + std::to_string(outcomes.size()) + " cases") << " within tolerance\n";
  return 0;
}

}  // namespace

void register_regress_command(CLI::App& app) {
  auto o = std::make_shared<RegressOptionsText>();
  CLI::App* sub = app.add_subcommand("regress", "Energy regression: run a baseline's cases, fail on drift (--update rewrites it)");
  sub->add_option("baseline", o->file, "Baseline YAML file (e.g. tests/energy_baseline.yaml)")->required()->type_name("FILE");
  sub->add_flag("--update", o->update, "Rewrite the baseline with the new values (and fill in new cases' 'expected') and print the differences");
  sub->callback([o] {
    const int rc = run_regress(*o);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace rollsim::cli
