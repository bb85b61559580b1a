// Benchmarks of the tyre model's simulation fast path (preparing a tyre at a load, RRC at a speed) and of fitting.
#include <benchmark/benchmark.h>

#include "rollsim/tyre/j2452.hpp"
#include "rollsim/tyre/tyre_fit.hpp"
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

// `rollsim tyre fit` on one label point: the least-squares fit of the level (target: well under a second).
void BM_TyreFitOnePoint(benchmark::State& state) {
  rollsim::FitRequest request;
  request.points = {{2.1e5, 4825.0, 80.0 / 3.6, 0.0085, "bench"}};
  const auto tyre = nominal_tyre();
  for (auto _ : state) {
    auto fit = rollsim::fit_hysteresis(tyre, request);
    benchmark::DoNotOptimize(fit);
  }
}
BENCHMARK(BM_TyreFitOnePoint)->Unit(benchmark::kMicrosecond);

// A full J2452 surface: 150 points, all six constants free.
void BM_TyreFitJ2452Surface(benchmark::State& state) {
  const rollsim::J2452Set set{"bench", "P205/60R15", -0.4815, 1.0051, 0.0682, 2.32e-4, 1.2e-6, 0.304};
  rollsim::FitRequest request;
  request.points = rollsim::sample_j2452(set, rollsim::j2452_grid(), rollsim::kJ2452DrumRadius_m, "bench");
  const auto tyre = nominal_tyre();
  for (auto _ : state) {
    auto fit = rollsim::fit_hysteresis(tyre, request);
    benchmark::DoNotOptimize(fit);
  }
}
BENCHMARK(BM_TyreFitJ2452Surface)->Unit(benchmark::kMillisecond);

}  // namespace
