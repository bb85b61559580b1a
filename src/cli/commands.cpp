#include "commands.hpp"

namespace rollsim::cli {

void register_commands(CLI::App& app) {
  register_tyre_command(app);
  register_diagnose_command(app);
  register_diagnose_bench_command(app);
  register_compare_command(app);
  register_sweep_command(app);
  register_sensitivity_command(app);
  register_regress_command(app);
  register_simulate_command(app);
  register_validate_command(app);
}

}  // namespace rollsim::cli
