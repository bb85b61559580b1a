// The subcommands of the rollsim executable; each lives in its own cmd_*.cpp and only glues CLI to library.
#pragma once

#include <CLI/CLI.hpp>

namespace rollsim::cli {

void register_commands(CLI::App& app);
void register_simulate_command(CLI::App& app);
void register_tyre_command(CLI::App& app);
void register_tyre_fit_command(CLI::App& tyre);
void register_diagnose_command(CLI::App& app);
void register_diagnose_bench_command(CLI::App& app);
void register_compare_command(CLI::App& app);
void register_sweep_command(CLI::App& app);
void register_sensitivity_command(CLI::App& app);
void register_regress_command(CLI::App& app);
void register_validate_command(CLI::App& app);

}  // namespace rollsim::cli
