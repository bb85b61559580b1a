// Benchmarks of the energy simulation: forward (driver + CVODE) and kinematic replay of the shipped cars.
#include <benchmark/benchmark.h>

#include <string>

#include "rollsim/sim/simulation.hpp"

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

}  // namespace
