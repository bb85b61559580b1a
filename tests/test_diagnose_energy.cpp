// One energy: diagnose's uncalibrated model energy is simulate's on the same trace (issue 9, item 6).
#include <gtest/gtest.h>

#include <cmath>

#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/diagnose/diagnose.hpp"
#include "rollsim/sim/simulation.hpp"

namespace rollsim {
namespace {

// The first 22 minutes of UDDS at 1 Hz (22 whole windows: the windows cover the trace), with a channel 10 % above
// the model's point values plus 300 W (so that no lag but 0 fits it).
Recording udds_recording(const Vehicle& v, double j_per_unit) {
  const DriveCycle c = load_cycle("udds");
  Recording r;
  r.source = "udds test";
  for (std::size_t i = 0; i <= 22 * 60; ++i) {
    r.time_s.push_back(c.time_s[i] - c.time_s.front());
    r.speed_mps.push_back(c.speed_mps[i]);
  }
  SimulationOptions so;
  so.record_trace = true;
  const SimulationResult sim = simulate_replay(VehicleModel::assemble(v), cycle_of_recording(r), so);
  std::vector<double> ch(r.time_s.size());
  for (std::size_t i = 0; i < ch.size(); ++i) {
    const TracePoint& p = sim.trace[std::min(i, sim.trace.size() - 1)];
    ch[i] = (300.0 + 1.1 * (v.is_electric() ? p.battery_power_w : p.fuel_rate_m3_per_s * j_per_unit)) / j_per_unit;
  }
  (v.is_electric() ? r.battery_power_w : r.fuel_rate_m3ps) = ch;
  return r;
}

double measured_j(const Recording& r, double j_per_unit) {
  const auto& x = r.fuel_rate_m3ps ? *r.fuel_rate_m3ps : *r.battery_power_w;
  double e = 0.0;
  for (std::size_t i = 0; i + 1 < x.size(); ++i) e += x[i] * (r.time_s[i + 1] - r.time_s[i]) * j_per_unit;
  return e;
}

TEST(DiagnoseEnergy, UncalibratedModelEnergyIsSimulatesOnTheSameTrace) {
  for (const char* car : {"ice", "ev"}) {
    const Vehicle v = load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/" + car + ".yaml");
    const bool fuel = !v.is_electric();
    double j_per_unit = 1.0;
    if (fuel) {
      const auto& cp = std::get<CombustionPowertrainParams>(v.powertrain);
      j_per_unit = cp.fuel.density_kg_per_m3 * cp.fuel.lower_heating_value_j_per_kg;
    }
    const Recording rec = udds_recording(v, j_per_unit);
    // `simulate --replay` on the recording's trace: its integrated totals.
    const SimulationResult sim = simulate_replay(VehicleModel::assemble(v), cycle_of_recording(rec));
    const double model_j = fuel ? sim.fuel->volume_m3 * j_per_unit : sim.energy.battery_terminal_j;
    const Diagnosis d = diagnose(v, {rec});
    ASSERT_EQ(d.lag_samples, 0);
    ASSERT_NEAR(d.windows * d.window_s, rec.duration_s(), 1e-9);  // the windows cover the trace
    double windows_j = 0.0;
    for (const auto& w : d.series) windows_j += w.simulated_j;
    EXPECT_NEAR(windows_j / model_j, 1.0, 1e-3) << car;
    const double meas = measured_j(rec, j_per_unit);
    EXPECT_NEAR(d.raw_trip_energy_error_pct, 100.0 * (model_j - meas) / meas, 0.1) << car;
  }
}

}  // namespace
}  // namespace rollsim
