// Benchmarks of the energy simulation: NEDC forward (driver + CVODE) and kinematic replay of ev.yaml.
#include <benchmark/benchmark.h>

#include <string>

#include "rollsim/sim/simulation.hpp"

namespace {

rollsim::VehicleModel ev_model() {
  return rollsim::VehicleModel::assemble(rollsim::load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml"));
}

void BM_SimulateForwardNedcEv(benchmark::State& state) {
  const auto model = ev_model();
  const auto cycle = rollsim::load_cycle("nedc");
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
}
BENCHMARK(BM_SimulateForwardNedcEv)->Unit(benchmark::kMillisecond);

void BM_SimulateReplayNedcEv(benchmark::State& state) {
  const auto model = ev_model();
  const auto cycle = rollsim::load_cycle("nedc");
  for (auto _ : state) {
    auto r = rollsim::simulate_replay(model, cycle);
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK(BM_SimulateReplayNedcEv)->Unit(benchmark::kMicrosecond);

// The replay reuses a repeated segment's integrals, and NEDC repeats its urban cycle four times: WLTC, which
// repeats nothing, shows the cost per evaluated segment (1800 s).
void BM_SimulateReplayWltcEv(benchmark::State& state) {
  const auto model = ev_model();
  const auto cycle = rollsim::load_cycle("wltc");
  for (auto _ : state) {
    auto r = rollsim::simulate_replay(model, cycle);
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK(BM_SimulateReplayWltcEv)->Unit(benchmark::kMicrosecond);

void BM_SimulateForwardNedcIce(benchmark::State& state) {
  const auto model =
      rollsim::VehicleModel::assemble(rollsim::load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ice.yaml"));
  const auto cycle = rollsim::load_cycle("nedc");
  rollsim::OdeStats stats;
  for (auto _ : state) {
    auto r = rollsim::simulate_forward(model, cycle);
    stats = r.solver;
    benchmark::DoNotOptimize(r);
  }
  state.counters["steps"] = static_cast<double>(stats.steps);
  state.counters["rhs_evals"] = static_cast<double>(stats.rhs_evals);
  state.counters["roots"] = static_cast<double>(stats.root_evals);
  state.counters["restarts"] = static_cast<double>(stats.restarts);
}
BENCHMARK(BM_SimulateForwardNedcIce)->Unit(benchmark::kMillisecond);

}  // namespace
