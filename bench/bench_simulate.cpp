// Benchmarks of the energy simulation: forward (driver + CVODE) and kinematic replay of the shipped cars.
#include <benchmark/benchmark.h>

#include <string>

#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/report/simulation_report.hpp"
#include "rollsim/sim/simulation.hpp"
#include "rollsim/sim/vehicle_run.hpp"

namespace {

rollsim::VehicleModel shipped_model(const std::string& file) {
  return rollsim::VehicleModel::assemble(rollsim::load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/" + file));
}

void BM_SimulateForward(benchmark::State& state, const std::string& vehicle, const std::string& cycle_name) {
  const auto model = shipped_model(vehicle);
  const auto cycle = rollsim::load_cycle(cycle_name);
  rollsim::OdeStats stats;
  const rollsim::SimulationOptions opt;
  for (auto _ : state) {
    auto r = rollsim::simulate_forward(model, cycle, opt);
    stats = r.solver;
    benchmark::DoNotOptimize(r);
  }
  state.counters["steps"] = static_cast<double>(stats.steps);
  state.counters["rhs_evals"] = static_cast<double>(stats.rhs_evals);
  state.counters["err_test_fails"] = static_cast<double>(stats.error_test_failures);
  state.counters["restarts"] = static_cast<double>(stats.restarts);
  if (stats.root_evals > 0) state.counters["root_evals"] = static_cast<double>(stats.root_evals);
}
BENCHMARK_CAPTURE(BM_SimulateForward, NedcEv, "ev.yaml", "nedc")->Unit(benchmark::kMillisecond);
// The petrol car: five gears, shifts and kick-downs located as roots.
BENCHMARK_CAPTURE(BM_SimulateForward, NedcIce, "ice.yaml", "nedc")->Unit(benchmark::kMillisecond);

void BM_SimulateReplay(benchmark::State& state, const std::string& vehicle, const std::string& cycle_name) {
  const auto model = shipped_model(vehicle);
  const auto cycle = rollsim::load_cycle(cycle_name);
  for (auto _ : state) {
    auto r = rollsim::simulate_replay(model, cycle);
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK_CAPTURE(BM_SimulateReplay, NedcEv, "ev.yaml", "nedc")->Unit(benchmark::kMicrosecond);
// The replay reuses a repeated segment's integrals, and NEDC repeats its urban cycle four times: WLTC, which
// repeats nothing, shows the cost per evaluated segment (1800 s).
BENCHMARK_CAPTURE(BM_SimulateReplay, WltcEv, "ev.yaml", "wltc")->Unit(benchmark::kMicrosecond);

// One `rollsim simulate --json` run as the CLI and the Python API do it: load the vehicle and the cycle, assemble,
// simulate, write the summary. The Python call's overhead is judged against this (python/bench_python.py).
void BM_RunVehicleFiles(benchmark::State& state, const std::string& vehicle, const std::string& cycle_name) {
  for (auto _ : state) {
    const auto v = rollsim::load_vehicle_file(rollsim::resolve_data_file(vehicle, "vehicles", ".yaml", "--vehicle"));
    const auto cycle = rollsim::load_cycle(cycle_name);
    auto run = rollsim::run_vehicle(v, std::nullopt, cycle, false, {});
    benchmark::DoNotOptimize(rollsim::report::to_json(run.result, run.tyre_label).str());
  }
}
BENCHMARK_CAPTURE(BM_RunVehicleFiles, NedcEv, "ev", "nedc")->Unit(benchmark::kMillisecond);

}  // namespace
