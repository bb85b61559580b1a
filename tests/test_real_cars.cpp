// The shipped real cars' vehicle files against their recordings (issue 13, item 5): the Camry with the fuel map
// on the Argonne dynamometer tests.
#include <gtest/gtest.h>

#include <array>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "rollsim/common/error.hpp"
#include "rollsim/common/statistics.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/diagnose/diagnose.hpp"
#include "rollsim/recording/recording.hpp"
#include "rollsim/sim/simulation.hpp"
#include "rollsim/validate/validate.hpp"
#include "rollsim/vehicle/vehicle.hpp"

namespace rollsim {
namespace {

const std::string kCamryDir = std::string(ROLLSIM_SOURCE_DIR) + "/../shared/data/recordings/anl_d3_2018_toyota_camry/";

struct CamryTest {
  std::string file;
  double measured_m3 = 0.0, predicted_m3 = 0.0;
  double measured_idle_m3_per_s = 0.0;  ///< median fuel flow standing with the engine running
  /// Fuel [m3] by regime, measured and modelled (steady-state map, before the transient terms): standing,
  /// accelerating, braking, cruising below and above 54 km/h.
  std::array<double, 5> regime_measured_m3{}, regime_model_m3{};
};

int regime(const Recording& r, std::size_t i) {
  const double v = r.speed_mps[i], dv = r.speed_mps[i + 1] - v;
  if (v == 0.0 && r.speed_mps[i + 1] == 0.0) return 0;
  if (dv > 0.2) return 1;
  if (dv < -0.2) return 2;
  return v < 15.0 ? 3 : 4;
}

// Each Argonne test replayed as `rollsim diagnose` replays it (engine-off standstills of 5 s or more without
// fuel), its fuel with what the steady-state map leaves out (validate::fuel_with_transients_m3).
std::vector<CamryTest> camry_on_argonne(const Vehicle& vehicle) {
  const VehicleModel car = VehicleModel::assemble(vehicle);
  SimulationOptions traced;
  traced.record_trace = true;
  std::vector<CamryTest> out;
  for (const char* file : {"61811012_test_data.csv", "61811013_test_data.csv", "61811014_test_data.csv"}) {
    const Recording rec = load_recording(kCamryDir + file, preset_mapping("anl_d3"));
    const DriveCycle c = cycle_of_recording(rec, 5.0, EngineStart::hot);
    CamryTest t;
    t.file = file;
    const SimulationResult s = simulate_replay(car, c, traced);
    std::vector<double> idle;
    for (std::size_t i = 0; i + 1 < rec.time_s.size(); ++i) {
      const double f = (*rec.fuel_rate_m3ps)[i], dt = rec.time_s[i + 1] - rec.time_s[i];
      t.measured_m3 += f * dt;
      if (rec.speed_mps[i] == 0.0 && f > 0.0) idle.push_back(f);
      const int k = regime(rec, i);
      t.regime_measured_m3[k] += f * dt;
      if (i < s.trace.size()) t.regime_model_m3[k] += s.trace[i].segment_fuel_rate_m3_per_s * dt;
    }
    t.measured_idle_m3_per_s = median(idle);
    t.predicted_m3 = validate::fuel_with_transients_m3(s, validate::transient_fuel_params(car));
    out.push_back(t);
  }
  return out;
}

Vehicle camry() { return load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/camry_2018_map.yaml"); }

TEST(CamryFuelMap, VehicleFileSelectsTheFuelMapAndItsConvertersNeutralIdle) {
  const Vehicle v = camry();
  ASSERT_NE(std::get_if<ConventionalPowertrainParams>(&v.powertrain), nullptr);
  const auto& p = std::get<ConventionalPowertrainParams>(v.powertrain);
  EXPECT_EQ(p.transmission.ratios.size(), 8u);
  EXPECT_NEAR(p.transmission.ratios.back(), 0.673 * 2.80, 1e-12);
  ASSERT_NE(v.fuel(), nullptr);
  EXPECT_EQ(v.battery(), nullptr);
}

// The engine_map type's bad input: one error naming the file, the key, the value and what is allowed.
TEST(CamryFuelMap, BadEngineMapKeysAreNamedErrors) {
  std::ifstream in(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/camry_2018_map.yaml");
  const std::string good((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto error_of = [&](const std::string& from, const std::string& to) {
    std::string text = good;
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    try {
      load_vehicle_text(text, "camry_bad.yaml");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  auto expect_has = [](const std::string& msg, std::initializer_list<const char*> parts) {
    for (const char* p : parts) EXPECT_NE(msg.find(p), std::string::npos) << "'" << p << "' not in: " << msg;
  };
  expect_has(error_of("kind: automatic", "kind: powerglide"), {"camry_bad.yaml", "transmission.kind", "powerglide", "automatic, cvt, manual"});
  expect_has(error_of("gross_indicated_efficiency: 0.425", "gross_indicated_efficiency: 0.9"), {"gross_indicated_efficiency", "0.9"});
  expect_has(error_of("ratios: [5.250, 3.029", "ratios: [3.029, 5.250"), {"transmission.ratios", "must fall"});
  expect_has(error_of("rated_speed_rpm: 6600", "rated_speed_rpm: 600"), {"rated_speed_rpm", "must exceed idle_speed_rpm"});
  expect_has(error_of("kind: automatic", "kind: manual"), {"converter", "no torque converter"});
  expect_has(error_of("stall_speed_rpm: 2400", "stall_sped_rpm: 2400"), {"stall_speed_rpm"});
  expect_has(error_of("type: engine_map", "type: rotary"), {"powertrain.type", "rotary", "engine_map"});
  expect_has(error_of("lockup_min_gear: 2 ", "lockup_min_gear: 2.5 "), {"lockup_min_gear", "2.5", "gear number"});
  expect_has(error_of("max_load_pct: 60", "max_load_pct: 60\n    launch_engine_speed_rpm: 1400"), {"launch_engine_speed_rpm", "slipping clutch"});
  expect_has(error_of("fuel_cut_min_vehicle_speed_kmh: 18 ", "fuel_cut_min_vehicle_speed_kmh: 500 "),
             {"fuel_cut_min_vehicle_speed_kmh", "500"});
  expect_has(error_of("inertia_kg_m2: 0.144 ", "inertia_kg_m2: -0.144 "), {"inertia_kg_m2", "-0.144"});
  expect_has(error_of("idle_torque_reserve_nm: 10 ", "idle_torque_reserve_nm: 1000 "), {"idle_torque_reserve_nm", "1000"});
}

// The file's map against EPA's published map of its engine (the A25A-FKS Tier 2 ALPHA map package, 2020-07: brake
// thermal efficiency at speed and torque, on the lower heating value the file uses), at points across its range:
// light and part load, the best-efficiency island and the knock-limited top of each speed. The file's keys are
// fitted to the whole published map (scripts/fit_engine_map.py, 254 points); validate's class values miss the
// light-load points by 2.0-4.4 points of efficiency (friction and pumping 2.4 bar at 2000 rpm against the map's 1.5).
TEST(CamryFuelMap, EfficiencyAgainstEpasPublishedMapOfTheA25A) {
  struct Point {
    double speed_rpm, torque_nm, published_pct;
    double tolerance_pct = 2.5;  ///< points of efficiency
  };
  // At 1040 rpm the full-load curve (EngineMap's: 70 % of the plateau at idle, all of it at half the rated speed)
  // reaches 185 N m where the engine's highest published point is 161 N m, so there the model is at 87 % of its
  // full load, not at the knock-limited top, and 3.8 points too efficient.
  const Point published[] = {{1040, 32.56, 24.8},  {1040, 87.07, 34.5},  {1040, 130.46, 36.7}, {1040, 161.29, 31.7, 4.0},
                             {2017, 17.70, 17.3},  {2017, 45.70, 28.6},  {2017, 87.07, 35.2},  {2017, 161.29, 39.8},
                             {2017, 204.97, 33.8}, {3571, 45.70, 25.8},  {3571, 130.46, 36.7}, {3571, 215.87, 35.7},
                             {5414, 87.07, 28.9},  {5414, 230.18, 31.7}, {6510, 45.70, 20.8},  {6510, 215.87, 30.7}};
  const Vehicle v = camry();
  const EngineMap map(std::get<ConventionalPowertrainParams>(v.powertrain).engine);
  const double displacement_m3 = map.params().displacement_m3;
  std::cout << "speed rpm, bmep bar, published BTE %, model BTE %\n";
  for (const Point& p : published) {
    const double w = p.speed_rpm * units::kRadpsPerRpm;
    const double model_pct = 100.0 * p.torque_nm * w / map.fuel_power_w(w, p.torque_nm);
    std::cout << p.speed_rpm << ", " << 4.0 * units::kPi * p.torque_nm / displacement_m3 / units::kPaPerBar << ", " << p.published_pct
              << ", " << model_pct << "\n";
    EXPECT_NEAR(model_pct, p.published_pct, p.tolerance_pct) << p.speed_rpm << " rpm, " << p.torque_nm << " N m";
  }
}

// Issue 13, item 5: after the Camry's own calibration (one scale on its fuel, from its three tests together),
// the issue asks each test within 3 % of its measured fuel. With the map read off EPA's published map of the
// engine (validate's class values had the UDDS at +3.5 %, too much fuel cruising slowly) and EPA ALPHA's idle
// torque reserve and engine inertia for it, all three are, out of sample within 4 %. And the engine idles at its
// stops in neutral, as the car does.
TEST(CamryFuelMap, ArgonneHotUddsHwfetUs06AfterItsOwnCalibration) {
  const Vehicle v = camry();
  const auto tests = camry_on_argonne(v);
  double measured = 0.0, predicted = 0.0;
  for (const auto& t : tests) {
    measured += t.measured_m3;
    predicted += t.predicted_m3;
  }
  const double scale = measured / predicted;
  const VehicleModel car = VehicleModel::assemble(v);
  const double idle_m3_per_s = scale * car.powertrain->deliver(0.0, 0.0, 0, car.wheel_radius_m).fuel_rate_m3_per_s;
  Vehicle stalled = v;  // the same car with its converter loading the engine at a stop
  std::get<ConventionalPowertrainParams>(stalled.powertrain).transmission.converter.neutral_at_standstill = false;
  const VehicleModel stalled_car = VehicleModel::assemble(stalled);
  const double stalled_idle_m3_per_s =
      scale * stalled_car.powertrain->deliver(0.0, 0.0, 0, stalled_car.wheel_radius_m).fuel_rate_m3_per_s;
  std::cout << "calibration x" << scale << ", idle " << idle_m3_per_s * 1e6 << " cm3/s (stalled converter " << stalled_idle_m3_per_s * 1e6
            << ")\n";
  for (const auto& t : tests) {
    const double err_pct = 100.0 * (scale * t.predicted_m3 / t.measured_m3 - 1.0);
    // Judged out of sample too: the scale from the other two tests.
    const double loo_scale = (measured - t.measured_m3) / (predicted - t.predicted_m3);
    const double loo_err_pct = 100.0 * (loo_scale * t.predicted_m3 / t.measured_m3 - 1.0);
    std::cout << t.file << ": measured " << t.measured_m3 * 1e6 << " cm3, nominal " << t.predicted_m3 * 1e6 << " cm3 ("
              << 100.0 * (t.predicted_m3 / t.measured_m3 - 1.0) << " %), calibrated " << err_pct << " %, scale from the other two "
              << loo_err_pct << " %; standing idle measured " << t.measured_idle_m3_per_s * 1e6 << " cm3/s (median)\n  by regime "
              << "(standing, accelerating, braking, cruise < 54 km/h, cruise > 54 km/h), measured / steady-state model cm3:";
    for (std::size_t k = 0; k < 5; ++k) std::cout << " " << std::lround(t.regime_measured_m3[k] * 1e6) << "/" << std::lround(scale * t.regime_model_m3[k] * 1e6);
    std::cout << "\n";
    EXPECT_LT(std::abs(err_pct), 3.0) << t.file;
    EXPECT_LT(std::abs(loo_err_pct), 4.0) << t.file;
    // Neutral idle: nearer the car's standstill fuel flow than a stalled converter's load, and within 15 % of it.
    // The published map's friction and pumping alone idle 19 % low; the file's idle torque reserve (EPA ALPHA's
    // 10 N m held on spark) is what the map burns at its idle corner, 0.204 cm3/s at 774 rpm and 2.2 N m.
    const double neutral = idle_m3_per_s / t.measured_idle_m3_per_s, loaded = stalled_idle_m3_per_s / t.measured_idle_m3_per_s;
    EXPECT_LT(std::abs(neutral - 1.0), std::abs(loaded - 1.0)) << t.file;
    EXPECT_NEAR(neutral, 1.0, 0.15) << t.file;
  }
}

// Issue 13, item 5, the Twizy: where its trips' energy goes in the model, and what of the measured (state-of-
// charge) energy is left when the 58 V drive's losses come from published figures (vehicles/twizy_58v.yaml).
// Prints per trip; returns the median of the model's energy error [%] over the seven trips.
double twizy_budget(const std::string& vehicle_file) {
  namespace fs = std::filesystem;
  const Vehicle v = load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/" + vehicle_file);
  const VehicleModel car = VehicleModel::assemble(v);
  const double capacity_j = v.battery()->usable_capacity_j;
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(std::string(ROLLSIM_SOURCE_DIR) + "/../shared/data/recordings/rsk_renault_twizy/")) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  EXPECT_EQ(files.size(), 7u);
  SimulationOptions traced;
  traced.record_trace = true;
  std::vector<double> errors_pct;
  std::cout << vehicle_file << "\n";
  for (const auto& f : files) {
    const Recording rec = load_recording(f.string(), preset_mapping("rsk_twizy"));
    const SimulationResult s = simulate_replay(car, cycle_of_recording(rec), traced);
    const auto& soc = *rec.soc_fraction;
    const double measured_j = (soc.front() - soc.back()) * capacity_j;
    const double model_j = s.energy.battery_terminal_j + s.energy.battery_loss_j;
    // The integral of I^2 over the trip: each extra milliohm in the current's path costs 1e-3 x this.
    double i2_a2s = 0.0, moving_s = 0.0;
    for (std::size_t i = 0; i + 1 < s.trace.size(); ++i) {
      const double dt = s.trace[i + 1].time_s - s.trace[i].time_s;
      i2_a2s += s.trace[i].battery_current_a * s.trace[i].battery_current_a * dt;
      if (s.trace[i].speed_mps > 0.0) moving_s += dt;
    }
    const double gap_j = measured_j - model_j, km = s.distance_m / 1e3;
    errors_pct.push_back(100.0 * (model_j / measured_j - 1.0));
    std::cout << "  " << f.filename().string() << ": " << km << " km, measured " << units::j_to_kwh(measured_j) * 1e3 / km << " Wh/km, model "
              << units::j_to_kwh(model_j) * 1e3 / km << " Wh/km (" << errors_pct.back() << " %); of the model's energy: motor and inverter "
              << 100.0 * s.energy.motor_loss_j / model_j << " %, battery I^2R " << 100.0 * s.energy.battery_loss_j / model_j << " %, reduction "
              << 100.0 * s.energy.gearbox_loss_j / model_j << " %, auxiliaries " << 100.0 * s.energy.aux_j / model_j
              << " %; the gap is the I^2R of " << 1e3 * gap_j / i2_a2s << " mOhm more, or a capacity of "
              << units::j_to_kwh(capacity_j * model_j / measured_j) << " kWh, or " << gap_j / moving_s << " W more while moving\n";
    EXPECT_NEAR(s.energy.powertrain_residual_j(), 0.0, 1e-6 * std::abs(model_j));
  }
  return median(errors_pct);
}

TEST(TwizyGap, PublishedDriveLossesAndCapacityAgainstTheSevenTrips) {
  // The sourced file's drive takes the SEVCON's 18 kW of electrical input at the motor's 13 kW peak (57 N m).
  const Vehicle v = load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/twizy_58v.yaml");
  const auto& p = std::get<ElectricPowertrainParams>(v.powertrain);
  const double base_radps = p.motor.max_power_w / p.motor.max_torque_nm;
  const double wheel_radius_m = driven_wheel_radius_m(v);
  const ElectricPowertrain drive(p);
  const PowerFlow peak = drive.deliver(p.motor.max_torque_nm * p.reduction.ratio * p.reduction.efficiency / wheel_radius_m,
                                       base_radps / p.reduction.ratio * wheel_radius_m, 0, wheel_radius_m);
  EXPECT_NEAR((peak.battery_terminal_power_w - peak.aux_power_w) / 18e3, 1.0, 0.02);
  const double assumed = twizy_budget("twizy.yaml"), sourced = twizy_budget("twizy_58v.yaml");
  std::cout << "median error over the seven trips: twizy.yaml " << assumed << " %, twizy_58v.yaml " << sourced << " %\n";
  // What is left is still an under-prediction (README: the induction machine's light-load loss and the SOC of an aged
  // pack are the candidates; neither is absorbed).
  EXPECT_LT(sourced, 0.0);
}

}  // namespace
}  // namespace rollsim
