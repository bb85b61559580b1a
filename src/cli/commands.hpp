// The subcommands of the rollsim executable; each lives in its own cmd_*.cpp and only glues CLI to library.
#pragma once

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

#include "rollsim/common/distribute.hpp"
#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/vehicle/vehicle.hpp"

namespace rollsim::cli {

/// `group`: the processes the distributed commands (sweep, compare, validate, diagnose-bench, diagnose --fleet) use.
void register_commands(CLI::App& app, const ProcessGroup& group);
void register_simulate_command(CLI::App& app);
void register_tyre_command(CLI::App& app);
void register_tyre_fit_command(CLI::App& tyre);
void register_diagnose_command(CLI::App& app, const ProcessGroup& group);
void register_diagnose_bench_command(CLI::App& app, const ProcessGroup& group);
void register_compare_command(CLI::App& app, const ProcessGroup& group);
void register_sweep_command(CLI::App& app, const ProcessGroup& group);
void register_sensitivity_command(CLI::App& app);
void register_regress_command(CLI::App& app);
void register_validate_command(CLI::App& app, const ProcessGroup& group);

/// The files a vehicle was read from (its file and its tyres' files), for an output's check that it is no input.
std::vector<std::string> vehicle_input_files(const Vehicle& vehicle);

/// load_cycle, and on stderr what the user should hear of it: a note naming the file's columns that were not read
/// (ignored_columns_note) and a warning for each of DriveCycle::notes (a long interval driven while moving).
DriveCycle load_cycle_noted(const std::string& name_or_path, const std::string& option = "--cycle");

}  // namespace rollsim::cli
