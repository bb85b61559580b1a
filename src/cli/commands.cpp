#include "commands.hpp"

namespace rollsim::cli {

std::vector<std::string> vehicle_input_files(const Vehicle& vehicle) {
  std::vector<std::string> files{vehicle.source};
  for (const auto* t : {&vehicle.front_tyre, &vehicle.rear_tyre})
    if (*t) files.push_back((*t)->source);
  return files;
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
