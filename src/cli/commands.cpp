#include "commands.hpp"

#include <iostream>

namespace rollsim::cli {

std::vector<std::string> vehicle_input_files(const Vehicle& vehicle) {
  std::vector<std::string> files{vehicle.source};
  for (const auto* t : {&vehicle.front_tyre, &vehicle.rear_tyre})
    if (*t) files.push_back((*t)->source);
  return files;
}

DriveCycle load_cycle_noted(const std::string& name_or_path, const std::string& option) {
  DriveCycle c = load_cycle(name_or_path, option);
  if (const std::string note = ignored_columns_note(c); !note.empty()) std::cerr << "note: " << note << "\n";
  for (const auto& n : c.notes) std::cerr << "warning: " << n << "\n";
  return c;
}

void register_commands(CLI::App& app, const ProcessGroup& group) {
  register_tyre_command(app);
  register_diagnose_command(app, group);
  register_diagnose_bench_command(app, group);
  register_compare_command(app, group);
  register_sweep_command(app, group);
  register_sensitivity_command(app);
  register_regress_command(app);
  register_simulate_command(app);
  register_validate_command(app, group);
}

}  // namespace rollsim::cli
