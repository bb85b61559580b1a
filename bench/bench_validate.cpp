// Benchmark of `rollsim validate` on the shipped part of the EPA Test Car List (3114 rows; target: under a minute on 2 cores).
#include <benchmark/benchmark.h>

#include <string>

#include "rollsim/validate/validate.hpp"

namespace {

// Reading the list, classifying, replaying every simulated row (FTP-75 as three bag replays) and fitting, on
// state.range(0) threads.
void BM_ValidateEpaList(benchmark::State& state) {
  const std::string list = std::string(ROLLSIM_SOURCE_DIR) + "/../shared/data/vehicles/epa_test_car_list_2022_part.csv";
  std::size_t simulated = 0;
  for (auto _ : state) {
    const auto v = rollsim::validate::validate_epa_list(rollsim::validate::read_epa_test_car_list(list), static_cast<unsigned>(state.range(0)));
    simulated = 0;
    for (const auto& o : v.rows) simulated += o.skip == rollsim::validate::SkipReason::none;
    benchmark::DoNotOptimize(v.rows.data());
  }
  state.counters["rows_simulated"] = static_cast<double>(simulated);
}
BENCHMARK(BM_ValidateEpaList)->Arg(1)->Arg(2)->Unit(benchmark::kSecond)->Iterations(1)->Repetitions(3)->ReportAggregatesOnly(true)->UseRealTime();

}  // namespace
