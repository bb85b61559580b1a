// Benchmarks of many small runs: a sweep of WLTC replays of the EV, the throughput issue 15 asks for.
#include <benchmark/benchmark.h>

#include <string>

#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/selection/sweep.hpp"

namespace {

// A pressure x width grid of `state.range(0)` points with the EV on WLTC, replayed, on `state.range(1)` threads.
// The rate counter is WLTC replays per minute of wall time (the target: >= 100,000 on this machine's 2 cores).
void BM_SweepReplayWltcEv(benchmark::State& state) {
  using namespace rollsim;
  const Vehicle ev = load_vehicle_file(resolve_data_file("ev", "vehicles", ".yaml", "bench"));
  const TyreSpec tyre = load_tyre_file(resolve_data_file("nominal", "tyres", ".yaml", "bench"));
  const DriveCycle wltc = load_cycle("wltc");
  selection::SweepOptions o;
  const int points = static_cast<int>(state.range(0));
  o.axes.push_back({selection::SweepParam::Pressure, 1.8, 3.2, points / 10});
  o.axes.push_back({selection::SweepParam::Width, 165.0, 195.0, 10});
  o.replay = true;
  o.threads = static_cast<unsigned>(state.range(1));
  std::size_t done = 0;
  for (auto _ : state) {
    const auto r = selection::sweep_vehicle(ev, tyre, wltc, o);
    done = r.points.size();
    benchmark::DoNotOptimize(r);
  }
  if (done != static_cast<std::size_t>(points)) state.SkipWithError("the sweep stopped early");
  state.counters["replays_per_min"] =
      benchmark::Counter(60.0 * static_cast<double>(points), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_SweepReplayWltcEv)->Args({1000, 1})->Args({1000, 2})->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
