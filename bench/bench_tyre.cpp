// Benchmarks of the tyre model's simulation fast path: preparing a tyre at a load, evaluating RRC at a speed.
#include <benchmark/benchmark.h>

#include "rollsim/tyre/tyre_model.hpp"

namespace {

rollsim::TyreState nominal_tyre() {
  rollsim::TyreState t;
  t.geometry.outer_radius_m = 0.305;
  t.geometry.section_width_m = 0.195;
  t.pressure_pa = 2.1e5;
  return t;
}

void BM_TyrePrepareAtLoad(benchmark::State& state) {
  const auto tyre = nominal_tyre();
  double load_n = 4000.0;
  for (auto _ : state) {
    auto prepared = rollsim::TyreAtLoad::prepare(tyre, load_n);
    benchmark::DoNotOptimize(prepared);
    load_n = load_n == 4000.0 ? 4001.0 : 4000.0;  // defeat hoisting
  }
}
BENCHMARK(BM_TyrePrepareAtLoad);

void BM_TyreRrcAtSpeed(benchmark::State& state) {
  const auto prepared = rollsim::TyreAtLoad::prepare(nominal_tyre(), 4000.0);
  double speed_mps = 10.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(speed_mps);
    double rrc = prepared.rrc(speed_mps);
    benchmark::DoNotOptimize(rrc);
    speed_mps += 1e-6;
  }
}
BENCHMARK(BM_TyreRrcAtSpeed);

void BM_TyreElementSum(benchmark::State& state) {
  const auto tyre = nominal_tyre();
  for (auto _ : state) {
    auto res = rollsim::evaluate_rolling_resistance(tyre, 4000.0, 22.2);
    benchmark::DoNotOptimize(res);
  }
}
BENCHMARK(BM_TyreElementSum);

}  // namespace
