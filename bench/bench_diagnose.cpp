// Benchmark of `rollsim diagnose` on a one-hour 10 Hz recording (the speed target: under 10 s).
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <string>

#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/diagnose/diagnose.hpp"
#include "rollsim/effects/catalogue.hpp"
#include "rollsim/sim/simulation.hpp"

namespace {

// WLTC (1800 s) twice, resampled at 10 Hz: 36 000 samples; measured battery power = the model's own replay
// plus 400 W white noise and a 100 W logger quantum. Without a warm-up it is a null recording (the diagnosis
// screens every candidate and finds nothing); with one, a cold tyre (+30 % RRC decaying as it heats) is there to
// be found, so the diagnosis also fits it and profiles its time constant.
rollsim::Recording one_hour_10hz(const rollsim::Vehicle& v, bool hilly, bool warmup) {
  const rollsim::DriveCycle one = rollsim::load_cycle("wltc");
  rollsim::DriveCycle c;
  c.name = "wltc x2 at 10 Hz";
  const double d = one.duration_s();
  for (int k = 0; k < 2; ++k)
    for (int i = 0; i < static_cast<int>(std::lround(d * 10.0)); ++i) {
      const double t = 0.1 * i;
      c.time_s.push_back(k * d + t);
      c.speed_mps.push_back(one.speed_mps_at(one.time_s.front() + t));
    }
  c.grade.assign(c.time_s.size(), 0.0);
  // Hilly: an elevation channel (20 m sine over 1.5 km of road) that the diagnosis turns into a grade; the truth
  // runs on the exact grade of that profile. The label says what was found (a null: nothing). The power is the
  // replay's instantaneous value at each sample, which the diagnosis must recognise as such (channel sampling).
  std::vector<double> elevation(c.time_s.size(), 0.0);
  if (hilly) {
    double s = 0.0;
    for (std::size_t i = 0; i < c.time_s.size(); ++i) {
      if (i > 0) s += 0.5 * (c.speed_mps[i] + c.speed_mps[i - 1]) * (c.time_s[i] - c.time_s[i - 1]);
      elevation[i] = 20.0 * std::sin(2.0 * M_PI * s / 1500.0);
      c.grade[i] = 20.0 * 2.0 * M_PI / 1500.0 * std::cos(2.0 * M_PI * s / 1500.0);
    }
  }
  rollsim::SimulationOptions so;
  so.record_trace = true;
  auto model = rollsim::VehicleModel::assemble(v);
  if (warmup) {
    const rollsim::EffectContext ctx{v.body.test_mass_kg, v.body.air_density_kg_per_m3 * v.body.drag_coefficient * v.body.frontal_area_m2};
    model.effects.push_back(rollsim::make_effect("tyre_warmup", {{"cold_rrc_excess", 0.3}}, ctx));
  }
  const auto s = rollsim::simulate_replay(model, c, so);
  rollsim::Recording r;
  r.source = c.name;
  r.time_s = c.time_s;
  r.speed_mps = c.speed_mps;
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 400.0);
  std::vector<double> p(c.time_s.size());
  for (std::size_t i = 0; i < p.size(); ++i) p[i] = 100.0 * std::round((s.trace[i].battery_power_w + noise(rng)) / 100.0);
  r.battery_power_w = p;
  if (hilly) r.elevation_m = elevation;
  return r;
}

void BM_DiagnoseOneHour10Hz(benchmark::State& state) {
  const auto v = rollsim::load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml");
  const auto rec = one_hour_10hz(v, state.range(1) != 0, state.range(2) != 0);
  rollsim::DiagnoseOptions opt;
  opt.threads = static_cast<unsigned>(state.range(0));
  std::size_t findings = 0;
  std::string first;
  for (auto _ : state) {
    auto d = rollsim::diagnose(v, {rec}, opt);
    findings = d.findings.size();
    first = d.findings.empty() ? "nothing found" : "found " + d.findings.front().effect;
    benchmark::DoNotOptimize(d);
  }
  state.SetLabel(first);
  state.counters["samples"] = static_cast<double>(rec.time_s.size());
  state.counters["findings"] = static_cast<double>(findings);
}
// Arguments: simulator threads (1 = serial, 0 = all cores); hilly (elevation channel, grade inferred) or flat;
// a tyre warm-up to find (1) or nothing (0).
BENCHMARK(BM_DiagnoseOneHour10Hz)->Args({1, 0, 0})->Args({0, 0, 0})->Args({0, 1, 0})->Args({1, 0, 1})->Args({0, 0, 1})->Unit(benchmark::kSecond)->Iterations(1)->Repetitions(5)->ReportAggregatesOnly(true);

}  // namespace
