#include <gtest/gtest.h>

#include "test_support.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <tuple>

#include "rollsim/common/error.hpp"
#include "rollsim/sim/simulation.hpp"

using namespace rollsim;

namespace {

std::string shipped(const std::string& rel) { return std::string(ROLLSIM_SOURCE_DIR) + "/" + rel; }

VehicleModel model_of(const std::string& vehicle_file) { return VehicleModel::assemble(load_vehicle_file(shipped(vehicle_file))); }

DriveCycle constant_speed_cycle(double speed_mps, double duration_s) {
  DriveCycle c;
  c.name = "constant";
  for (double t = 0.0; t <= duration_s; t += 10.0) {
    c.time_s.push_back(t);
    c.speed_mps.push_back(speed_mps);
    c.grade.push_back(0.0);
  }
  return c;
}

std::string temp_file(const std::string& name, const std::string& text) {
  const auto p = rollsim::test::temp_dir() / name;
  std::ofstream(p) << text;
  return p.string();
}

}  // namespace

// The platform study's figures (Redrouthu & Das 2014) for its two cars on NEDC: the shipped cars are built
// to reproduce them, so a change to any model that moves them fails here.
TEST(Simulation, ShippedCarsReproduceThePlatformStudyOnNedc) {
  const auto nedc = load_cycle("nedc");
  const auto ev = simulate_forward(model_of("vehicles/ev.yaml"), nedc);
  EXPECT_NEAR(ev.aec_kwh_per_10km(), 1.64, 0.05);
  const auto ice = simulate_forward(model_of("vehicles/ice.yaml"), nedc);
  EXPECT_NEAR(ice.fuel_l_per_100km(), 6.24, 0.2);
  EXPECT_NEAR(ev.distance_m, nedc.distance_m(), 5.0);
}

TEST(Simulation, EnergyBalanceClosesOnEveryCycle) {
  for (const char* vehicle : {"vehicles/ev.yaml", "vehicles/ice.yaml"}) {
    const auto m = model_of(vehicle);
    for (const char* cycle : {"nedc", "wltc", "udds", "us06"}) {
      for (bool forward : {true, false}) {
        const auto c = load_cycle(cycle);
        const auto r = forward ? simulate_forward(m, c) : simulate_replay(m, c);
        SCOPED_TRACE(std::string(vehicle) + " " + cycle + (forward ? " forward" : " replay"));
        EXPECT_LT(std::abs(r.energy.wheel_residual_j()) / r.energy.traction_j, 1e-3);
        const double source_j = r.source_energy_j();
        EXPECT_LT(std::abs(r.energy.powertrain_residual_j()) / source_j, 1e-9);
        EXPECT_GT(r.energy.rolling_j, 0.0);
        EXPECT_GT(r.energy.aero_j, 0.0);
      }
    }
  }
}

TEST(Simulation, ForwardAndReplayAgreeOnNedc) {
  const auto nedc = load_cycle("nedc");
  for (const char* vehicle : {"vehicles/ev.yaml", "vehicles/ice.yaml"}) {
    const auto m = model_of(vehicle);
    const auto f = simulate_forward(m, nedc);
    const auto r = simulate_replay(m, nedc);
    const double ef = f.fuel ? f.fuel->volume_m3 : f.energy.battery_terminal_j;
    const double er = r.fuel ? r.fuel->volume_m3 : r.energy.battery_terminal_j;
    EXPECT_LT(std::abs(ef / er - 1.0), 0.005) << vehicle;
    EXPECT_LT(f.max_speed_error_mps * 3.6, 2.0) << vehicle;  // the regulation's tolerance
    EXPECT_TRUE(f.shortfalls.empty()) << vehicle;
  }
}

// Analytic limit: at constant speed on the flat with coast-down road load, the wheels deliver exactly
// (A + B v + C v^2) times the distance.
TEST(Simulation, ConstantSpeedMatchesCoastdownRoadLoadExactly) {
  Vehicle v = load_vehicle_file(shipped("vehicles/ev.yaml"));
  v.coastdown = CoastdownParams{150.0, 2.0, 0.4};
  const auto m = VehicleModel::assemble(v);
  const double speed_mps = 25.0;
  const auto c = constant_speed_cycle(speed_mps, 600.0);
  const double expected_j = (150.0 + 2.0 * speed_mps + 0.4 * speed_mps * speed_mps) * speed_mps * 600.0;
  for (const auto& r : {simulate_forward(m, c), simulate_replay(m, c)}) {
    EXPECT_NEAR(r.energy.traction_j / expected_j, 1.0, 1e-4) << r.mode;
    EXPECT_NEAR(r.distance_m, speed_mps * 600.0, 0.05) << r.mode;
  }
}

// At standstill only the auxiliaries draw: energy is aux power times time, and the tyres add nothing.
TEST(Simulation, StandstillCostsOnlyAuxiliaries) {
  const auto m = model_of("vehicles/ev.yaml");
  const auto r = simulate_forward(m, constant_speed_cycle(0.0, 300.0));
  const double aux_w = std::get<ElectricPowertrainParams>(load_vehicle_file(shipped("vehicles/ev.yaml")).powertrain).aux_power_w;
  EXPECT_NEAR(r.energy.battery_terminal_j, aux_w * 300.0, 1e-6 * aux_w * 300.0);
  EXPECT_EQ(r.energy.rolling_j, 0.0);
}

// On a slope too, forward and replay: the car stands on its brakes. The replay held it with the powertrain, which
// drew the machine's constant loss (800 W on ev.yaml) at every uphill stop: a withheld climb then looked, at the
// stops, like an auxiliary load to the diagnosis (which replays its truths and its model alike).
TEST(Simulation, StandstillOnASlopeCostsOnlyAuxiliaries) {
  const auto m = model_of("vehicles/ev.yaml");
  const double aux_w = std::get<ElectricPowertrainParams>(load_vehicle_file(shipped("vehicles/ev.yaml")).powertrain).aux_power_w;
  for (double grade : {0.05, -0.05}) {
    DriveCycle c = constant_speed_cycle(0.0, 300.0);
    c.grade.assign(c.time_s.size(), grade);
    for (const auto& r : {simulate_forward(m, c), simulate_replay(m, c)}) {
      EXPECT_NEAR(r.energy.battery_terminal_j, aux_w * 300.0, 1e-6 * aux_w * 300.0) << r.mode << " grade " << grade;
      EXPECT_EQ(r.energy.friction_brake_j, 0.0) << r.mode;
    }
  }
}

// A grade that changes while the speed holds changes the power, not the speed the driver follows: each change is a
// stop time, or a step across a run of them books the grade of the few points it evaluated (+-4 % every 30 s at
// 60 km/h read a net climb of -1.6 kWh on a level route in session 21's outside testing). Up and down alike, the
// potential energy booked is the route's net climb: 0.
TEST(Simulation, AGradeThatChangesWhileTheSpeedHoldsIsNotSteppedOver) {
  const auto m = model_of("vehicles/ev.yaml");
  DriveCycle c;
  c.name = "rolling hills";
  for (int t = 0; t <= 1800; ++t) {
    c.time_s.push_back(t);
    c.speed_mps.push_back(60.0 / 3.6);
    c.grade.push_back((t / 30) % 2 == 0 ? 0.04 : -0.04);
  }
  const double lift_j = m.mass_kg * 9.80665 * 0.04 / std::sqrt(1.0 + 0.04 * 0.04) * (60.0 / 3.6) * 900.0;
  for (const auto& r : {simulate_forward(m, c), simulate_replay(m, c)}) {
    EXPECT_NEAR(r.energy.grade_j, 0.0, 1e-4 * lift_j) << r.mode;
    EXPECT_NEAR(r.distance_m, 30000.0, 0.5) << r.mode;
  }
}

// Published trend: a higher pressure lowers RRC and so the car's energy; the rolling share moves most.
TEST(Simulation, HigherTyrePressureLowersEnergy) {
  Vehicle v = load_vehicle_file(shipped("vehicles/ev.yaml"));
  const auto nedc = load_cycle("nedc");
  const double low = simulate_replay(VehicleModel::assemble(v), nedc).energy.battery_terminal_j;
  v.front_tyre->state.pressure_pa = v.rear_tyre->state.pressure_pa = 3.0e5;
  const auto high = simulate_replay(VehicleModel::assemble(v), nedc);
  EXPECT_LT(high.energy.battery_terminal_j, low);
}

// A larger tyre turns the motor slower at the same road speed: the gearing part of a tyre change.
TEST(Simulation, WheelRadiusSetsMachineSpeed) {
  Vehicle v = load_vehicle_file(shipped("vehicles/ev.yaml"));
  const double r_small = driven_wheel_radius_m(v);
  fit_tyres(v, load_tyre_file(shipped("tyres/low-rrc.yaml")));
  const double r_large = driven_wheel_radius_m(v);
  ASSERT_GT(r_large, r_small);
  const ElectricPowertrain pt(std::get<ElectricPowertrainParams>(v.powertrain));
  const double w_small = pt.deliver(500.0, 20.0, 0, r_small).machine_speed_radps;
  const double w_large = pt.deliver(500.0, 20.0, 0, r_large).machine_speed_radps;
  EXPECT_NEAR(w_small / w_large, r_large / r_small, 1e-12);
}

// A car too weak for the trace finishes and says where and by how much it fell behind.
TEST(Simulation, UnderpoweredCarReportsShortfallAndFinishes) {
  Vehicle v = load_vehicle_file(shipped("vehicles/ev.yaml"));
  auto& e = std::get<ElectricPowertrainParams>(v.powertrain);
  e.motor.max_power_w = 15e3;
  const auto r = simulate_forward(VehicleModel::assemble(v), load_cycle("us06"));
  ASSERT_FALSE(r.shortfalls.empty());
  EXPECT_GT(r.shortfalls.front().max_deficit_mps * 3.6, 2.0);
  EXPECT_GT(r.distance_m, 5000.0);
}

// A lock-up gear above the top gear: the converter never locked and slipped all the way (NEDC +11 % fuel), in silence
// (session 20).
TEST(Simulation, ALockUpGearAboveTheTopGearIsRefused) {
  std::ifstream in(shipped("vehicles/camry_2018_map.yaml"));
  std::string text((std::istreambuf_iterator<char>(in)), {});
  const auto at = text.find("lockup_min_gear: 2");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, std::string("lockup_min_gear: 2").size(), "lockup_min_gear: 9");
  const auto path = temp_file("lockup9.yaml", text);
  try {
    load_vehicle_file(path);
    FAIL() << "accepted lockup_min_gear 9 on an 8-speed";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("lockup_min_gear': 9 is not allowed: must be in [1, 8]"), std::string::npos) << e.what();
  }
}

// A shipped vehicle file with `from` replaced by `to` is refused, the error holding `said`.
static void expect_vehicle_error(const std::string& shipped_file, const std::string& from, const std::string& to, const std::string& said) {
  std::ifstream in(shipped(shipped_file));
  std::string text((std::istreambuf_iterator<char>(in)), {});
  const auto pos = text.find(from);
  ASSERT_NE(pos, std::string::npos) << from;
  text.replace(pos, from.size(), to);
  const auto tp = text.find("all: nominal.yaml");
  if (tp != std::string::npos) text.replace(tp, std::string("all: nominal.yaml").size(), "all: " + shipped("tyres/nominal.yaml"));
  try {
    load_vehicle_file(temp_file("bad_vehicle.yaml", text));
    FAIL() << "accepted " << to;
  } catch (const InputError& err) {
    EXPECT_NE(std::string(err.what()).find(said), std::string::npos) << err.what();
  }
}

// A gearbox is checked gear by gear, each error naming what is wrong: ratios that do not fall ran silently, upshift
// speeds out of order were blamed on the downshifts, and an idle above the top speed named neither (session 22's
// outside testing).
TEST(Simulation, AGearboxIsCheckedGearByGear) {
  expect_vehicle_error("vehicles/ice.yaml", "ratios: [3.73, 2.05, 1.32, 0.97, 0.76]", "ratios: [3.73, 1.32, 2.05, 0.97, 0.76]",
                       "key 'powertrain.gearbox.ratios': gear 3's 2.05 is not below gear 2's 1.32");
  expect_vehicle_error("vehicles/ice.yaml", "upshift_speeds_kmh: [16, 33, 48, 65]", "upshift_speeds_kmh: [16, 48, 33, 65]",
                       "key 'powertrain.gearbox.upshift_speeds_kmh': upshift 3 at 33 km/h is not above upshift 2 at 48 km/h");
  expect_vehicle_error("vehicles/ice.yaml", "idle_speed_rpm: 800", "idle_speed_rpm: 7000", "6300 must exceed idle_speed_rpm 7000");
  // Unit slips that ran: a displacement in m^3, a heating value in GJ/kg.
  expect_vehicle_error("vehicles/ice.yaml", "displacement_l: 1.6", "displacement_l: 0.0016", "must be in [0.05, 30]");
  expect_vehicle_error("vehicles/ice.yaml", "lower_heating_value_mj_per_kg: 42.9", "lower_heating_value_mj_per_kg: 0.0429",
                       "must be in [10, 150]");
}

TEST(Simulation, BadVehicleFilesAreRejectedWithTheKey) {
  auto expect_error = [](const std::string& from, const std::string& to, const std::string& key) {
    expect_vehicle_error("vehicles/ev.yaml", from, to, key);
  };
  expect_error("test_mass_kg: 1631", "test_mas_kg: 1631", "test_mas_kg");          // misspelt key
  expect_error("test_mass_kg: 1631", "test_mass_kg: -1631", "body.test_mass_kg");  // negative mass
  expect_error("efficiency: 0.95", "efficiency: 1.2", "reduction.efficiency");     // efficiency above 1
  expect_error("usable_capacity_kwh: 21.3", "usable_capacity_kwh: -5", "usable_capacity_kwh");
  expect_error("max_torque_nm: 254", "max_torque_nm: .nan", "max_torque_nm");
  expect_error("    ratio: 7.94", "    ratio_: 7.94", "reduction");                // missing required key
  expect_error("type: electric", "type: steam", "powertrain.type");
  // An axle carrying (almost) nothing: named by the key, not by a tyre file's domain error (session 20).
  expect_error("front_axle_load_fraction: 0.5", "front_axle_load_fraction: 0.999", "body.front_axle_load_fraction");
  // A car's frontal area in ft^2 (20-27) gets its unit hint: a hard 20 m^2 had refused it without one (session 25).
  expect_error("frontal_area_m2: 2.30", "frontal_area_m2: 24.8", "is it in ft^2? (24.8 ft^2 = 2.304 m^2)");
  EXPECT_THROW(load_vehicle_file("/no/such/vehicle.yaml"), InputError);
}

// A car too heavy for its tyres (73.5 kN per tyre deflects the nominal tyre, 200 kN/m at 2.1 bar, by 0.37 m,
// past its 0.305 m radius) is an input error naming the tyre, never a NaN.
TEST(Simulation, TyreThatCannotCarryTheCarIsRejected) {
  std::ifstream in(shipped("vehicles/ev.yaml"));
  std::string text((std::istreambuf_iterator<char>(in)), {});
  text.replace(text.find("test_mass_kg: 1631"), 18, "test_mass_kg: 30000");
  text.replace(text.find("all: nominal.yaml"), 17, "all: " + shipped("tyres/nominal.yaml"));
  try {
    load_vehicle_file(temp_file("heavy.yaml", text));
    FAIL() << "a 30 t car on passenger tyres was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("nominal"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("deflects"), std::string::npos) << e.what();
  }
}

// A car with a speed-only shift schedule cannot climb UDDS, WLTC or US06 accelerations in top gear; the driver
// kicks down, as drivers and automatic gearboxes do, and the car follows within the regulation's 2 km/h.
TEST(Simulation, PetrolCarKicksDownToFollowDemandingCycles) {
  const auto m = model_of("vehicles/ice.yaml");
  for (const char* cycle : {"udds", "wltc", "us06"}) {
    const auto c = load_cycle(cycle);
    const auto f = simulate_forward(m, c);
    // US06 asks more than the 88 kW engine has for a few seconds. Until session 18 the kick-down took first gear at
    // 47 km/h, 0.4 % past the engine's top speed, to keep within 2 km/h; within its top speed the car falls 2.2 km/h
    // behind for a second at 574 s, inside the 2 mph an EPA dynamometer driver is allowed off the trace.
    const bool us06 = std::string(cycle) == "us06";
    EXPECT_LT(f.max_speed_error_mps * 3.6, us06 ? 2.0 * 1.609344 : 2.0) << cycle;
    EXPECT_TRUE(us06 || f.shortfalls.empty()) << cycle;
    // The replay books that demand, but only a sliver.
    const auto r = simulate_replay(m, c);
    EXPECT_LT(r.energy.unmet_demand_j, 0.005 * r.energy.traction_j) << cycle;
    EXPECT_LT(std::abs(f.fuel->volume_m3 / r.fuel->volume_m3 - 1.0), 0.005) << cycle;
  }
}

// A battery that cannot give what the trace asks (Voc^2 / 4R = 9 kW at 60 V and 0.1 ohm) limits the car, which
// falls behind and says so, like at the motor's limit; the run finishes and the balance still closes.
TEST(Simulation, WeakBatteryLimitsTheCarInsteadOfFailing) {
  Vehicle v = load_vehicle_file(shipped("vehicles/ev.yaml"));
  std::get<ElectricPowertrainParams>(v.powertrain).battery.open_circuit_voltage_v = 60.0;
  const auto r = simulate_forward(VehicleModel::assemble(v), load_cycle("nedc"));
  EXPECT_FALSE(r.shortfalls.empty());
  EXPECT_LT(std::abs(r.energy.wheel_residual_j()) / r.energy.traction_j, 1e-3);
}

namespace {
// An effect whose model breaks down after 100 s: stands for any model error inside the integration.
struct FailingEffect final : Effect {
  std::string id() const override { return "failing"; }
  double extra_resistance_n(const EffectInputs& in, const double*) const override {
    if (in.time_s > 100.0) throw ModelDomainError("test model out of its domain");
    return 0.0;
  }
};
}  // namespace

// A model failure inside the integration stops the run with the time and the cause; no energy figure is
// produced from the failed step.
TEST(Simulation, SolverFailureReportsTimeAndCause) {
  auto m = model_of("vehicles/ev.yaml");
  m.effects.push_back(std::make_shared<FailingEffect>());
  try {
    simulate_forward(m, load_cycle("nedc"));
    FAIL() << "a failing model gave a result";
  } catch (const SolverError& e) {
    // The time is where the last good step ended; the failing step started there.
    EXPECT_GT(e.time_s, 90.0);
    EXPECT_LE(e.time_s, 100.0);
    EXPECT_NE(std::string(e.what()).find("test model out of its domain"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("after t = "), std::string::npos) << e.what();
  }
}

namespace {
// A road that rises and falls along its length with no hidden state: what it costs depends on where the car is.
struct CosineGrade final : Effect {
  double force_n, wavelength_m;
  CosineGrade(double f, double w) : force_n(f), wavelength_m(w) {}
  std::string id() const override { return "cosine_grade"; }
  double extra_resistance_n(const EffectInputs& in, const double*) const override {
    return force_n * std::cos(2.0 * M_PI * in.distance_m / wavelength_m);
  }
};
}  // namespace

// Analytic limit: over whole wavelengths a cosine force does no net work. A replay that reused one cruise
// segment's powers for the next (right only when nothing depends on time or distance) would book
// force x distance instead.
TEST(Simulation, ReplayEvaluatesEveryCruiseSegmentWhenEffectsDependOnDistance) {
  auto m = model_of("vehicles/ev.yaml");
  const double force_n = 300.0, speed_mps = 20.0, duration_s = 1000.0;
  m.effects.push_back(std::make_shared<CosineGrade>(force_n, speed_mps * 50.0));  // 20 wavelengths, 5 segments each
  const auto r = simulate_replay(m, constant_speed_cycle(speed_mps, duration_s));
  EXPECT_NEAR(r.distance_m, speed_mps * duration_s, 1e-6);
  EXPECT_LT(std::abs(r.energy.other_resistance_j), 1e-6 * force_n * r.distance_m);
}

// Invariant: recording the trace changes nothing in the energies. Without a trace (and without effects) the
// replay integrates a repeated segment once and reuses it (NEDC repeats one urban cycle four times); with a
// trace it evaluates every segment. The two must agree to rounding, gear schedule included.
TEST(Simulation, ReplayReuseOfRepeatedSegmentsChangesNoEnergy) {
  SimulationOptions traced;
  traced.record_trace = true;
  for (const char* vehicle : {"vehicles/ev.yaml", "vehicles/ice.yaml"}) {
    const auto m = model_of(vehicle);
    for (const char* cycle : {"nedc", "udds"}) {
      const auto c = load_cycle(cycle);
      const auto reused = simulate_replay(m, c), direct = simulate_replay(m, c, traced);
      SCOPED_TRACE(std::string(vehicle) + " " + cycle);
      EXPECT_NEAR(reused.energy.traction_j, direct.energy.traction_j, 1e-9 * direct.energy.traction_j);
      EXPECT_NEAR(reused.energy.friction_brake_j, direct.energy.friction_brake_j, 1e-9 * direct.energy.traction_j);
      EXPECT_NEAR(reused.energy.battery_terminal_j, direct.energy.battery_terminal_j, 1e-9 * direct.energy.traction_j);
      EXPECT_NEAR(reused.energy.fuel_j, direct.energy.fuel_j, 1e-9 * std::max(direct.energy.fuel_j, 1.0));
      EXPECT_EQ(reused.shortfalls.size(), direct.shortfalls.size());
    }
  }
}

namespace {

// Samples of a piecewise-linear speed [km/h] through the given points, every `step_s` seconds.
DriveCycle sampled(const std::vector<std::pair<double, double>>& points_kmh, double step_s) {
  DriveCycle c;
  c.name = "sampled";
  const double end = points_kmh.back().first;
  const auto n = static_cast<int>(std::lround(end / step_s));
  std::size_t k = 0;
  for (int i = 0; i <= n; ++i) {
    const double t = i == n ? end : i * step_s;
    while (k + 2 < points_kmh.size() && t > points_kmh[k + 1].first) ++k;
    const auto [t0, v0] = points_kmh[k];
    const auto [t1, v1] = points_kmh[k + 1];
    c.time_s.push_back(t);
    c.speed_mps.push_back((v0 + (v1 - v0) * (t - t0) / (t1 - t0)) / 3.6);
    c.grade.push_back(0.0);
  }
  return c;
}

// A trace of the given points [km/h] alone: each ramp between them one segment, as a coarse log or table has it.
DriveCycle points_only(const std::vector<std::pair<double, double>>& points_kmh) {
  DriveCycle c;
  c.name = "points";
  for (const auto& [t, v] : points_kmh) {
    c.time_s.push_back(t);
    c.speed_mps.push_back(v / 3.6);
    c.grade.push_back(0.0);
  }
  return c;
}

}  // namespace

// The regen fade (full above 15 km/h, none below 5) only splits the braking force, so the speed does not feel it:
// a smooth 60-0 km/h deceleration was stepped across whole and booked at 40 % regeneration down to rest (an outside
// check found 83.05 kJ where the fade gives 80.46 kJ, 2 % of the battery energy). The reference is the same
// deceleration replayed in 0.02 s ramps, where two Gauss points on either side of a kink cannot miss it.
TEST(Simulation, RegenFadeIsBookedOnADecelerationWhateverItsSampling) {
  const auto m = model_of("vehicles/ev.yaml");
  const std::vector<std::pair<double, double>> decel{{0.0, 60.0}, {20.0, 60.0}, {36.0, 0.0}, {76.0, 0.0}};
  const double reference_j = simulate_replay(m, sampled(decel, 0.02)).energy.regen_wheel_j;
  for (const DriveCycle& c : {sampled(decel, 1.0), sampled(decel, 4.0), points_only(decel)}) {
    const std::string samples = std::to_string(c.time_s.size()) + " samples";
    for (const auto& r : {simulate_forward(m, c), simulate_replay(m, c)}) {
      EXPECT_NEAR(r.energy.regen_wheel_j / reference_j, 1.0, 1e-4) << r.mode << ", " << samples;
      const double braking_j = r.energy.regen_wheel_j + r.energy.friction_brake_j;
      EXPECT_LT(r.energy.regen_wheel_j / braking_j, 0.395) << r.mode << ", " << samples << ": 40 %, faded below 15 km/h";
    }
  }
}

// A trace that creeps into a standstill (1e-6 km/h on the sample before it, a resampled log's residue) has no kink
// there, so the car was never held on its brakes and drew the motor's 800 W "while moving" loss through a 60 s stop.
TEST(Simulation, ATraceCreepingIntoAStandstillIsHeldThere) {
  const auto m = model_of("vehicles/ev.yaml");
  auto stop = [](double before_kmh) {
    DriveCycle c = sampled({{0.0, 0.0}, {10.0, 36.0}, {20.0, 36.0}, {29.0, 3.6}, {30.0, 0.0}, {90.0, 0.0}}, 1.0);
    c.speed_mps[30] = before_kmh / 3.6;
    return c;
  };
  const double clean_j = simulate_forward(m, stop(0.0)).energy.battery_terminal_j;
  const double creeping_j = simulate_forward(m, stop(1e-6)).energy.battery_terminal_j;
  // The creep's one second at 1e-6 km/h may cost the constant loss for that second, not for the minute after it.
  EXPECT_LT(std::abs(creeping_j - clean_j), 1500.0) << clean_j << " J clean";
}

// A demand beyond the engine's power made the forward kick-down fall through to a gear whose engine was past its top
// speed, and stay there: ice.yaml ran first gear at 96 km/h (12,866 rpm against its 6300) on a 60-100 km/h
// acceleration in 5 s, and camry_2018.yaml 11,816 rpm against 6600 (an outside check). A kicked-down gear now shifts
// up at its engine's top speed, and a kick-down is only to a gear that gives more force.
TEST(Simulation, AKickDownNeverTakesTheEnginePastItsTopSpeed) {
  const std::vector<std::pair<double, double>> hard{{0.0, 0.0}, {20.0, 60.0}, {60.0, 60.0}, {65.0, 100.0}, {90.0, 100.0}};
  for (const auto& [file, top_rpm] : {std::pair{"vehicles/ice.yaml", 6300.0}, std::pair{"vehicles/camry_2018.yaml", 6600.0}}) {
    SimulationOptions opt;
    opt.record_trace = true;
    const auto r = simulate_forward(model_of(file), sampled(hard, 0.2), opt);
    double top_seen_rpm = 0.0;
    for (const auto& p : r.trace) top_seen_rpm = std::max(top_seen_rpm, p.machine_speed_radps * 60.0 / (2.0 * 3.141592653589793));
    EXPECT_LE(top_seen_rpm, top_rpm * (1.0 + 1e-3)) << file;
    EXPECT_GT(top_seen_rpm, 0.9 * top_rpm) << file << ": the hard acceleration uses the engine's range";
  }
}

// The replay integrated a ramp with two Gauss points however long it was: across a 30 s coast from 60 km/h to rest
// they missed the gear shifts and the fuel cut-off, and ice.yaml booked 116 kJ of fuel where the forward simulation
// (and the same coast sampled at 0.05 s) book 73 kJ. A ramp is now integrated in pieces of at most a second.
// A traced replay gives each ramp's end at the ramp's own acceleration (what an instantaneous logger lagging by a
// fraction of a sample reads; session 20). On a steady ramp that is the next sample's start; where the ramp ends in a
// cruise it is not (the acceleration jumps there), and a cruise's end is its start.
TEST(Simulation, ATracedReplayGivesEachRampsEndAtItsOwnAcceleration) {
  SimulationOptions traced;
  traced.record_trace = true;
  traced.record_segment_ends = true;
  for (const char* vehicle : {"vehicles/ev.yaml", "vehicles/ice.yaml"}) {
    SCOPED_TRACE(vehicle);
    const auto m = model_of(vehicle);
    const auto r = simulate_replay(m, points_only({{0.0, 0.0}, {1.0, 10.0}, {2.0, 20.0}, {3.0, 30.0}, {4.0, 30.0}, {5.0, 30.0}}), traced);
    ASSERT_EQ(r.trace.size(), 5u);
    for (std::size_t k : {0u, 1u}) {  // within the steady ramp
      EXPECT_NEAR(r.trace[k].end_battery_power_w, r.trace[k + 1].battery_power_w, 1e-9 * std::abs(r.trace[k + 1].battery_power_w) + 1e-9);
      EXPECT_NEAR(r.trace[k].end_fuel_rate_m3_per_s, r.trace[k + 1].fuel_rate_m3_per_s, 1e-9 * r.trace[k + 1].fuel_rate_m3_per_s + 1e-15);
    }
    // The ramp's last second ends at 30 km/h still accelerating: more than the cruise that follows draws.
    if (r.trace[3].battery_power_w != 0.0) EXPECT_GT(r.trace[2].end_battery_power_w, r.trace[3].battery_power_w);
    else EXPECT_GT(r.trace[2].end_fuel_rate_m3_per_s, r.trace[3].fuel_rate_m3_per_s);
    EXPECT_EQ(r.trace[3].end_battery_power_w, r.trace[3].battery_power_w);  // a cruise
    EXPECT_EQ(r.trace[3].end_fuel_rate_m3_per_s, r.trace[3].fuel_rate_m3_per_s);
    // Not asked for, the ends are the point values: no extra evaluation.
    SimulationOptions plain;
    plain.record_trace = true;
    const auto q = simulate_replay(m, points_only({{0.0, 0.0}, {1.0, 10.0}, {2.0, 20.0}}), plain);
    EXPECT_EQ(q.trace[0].end_battery_power_w, q.trace[0].battery_power_w);
  }
}

TEST(Simulation, ReplayOfACoarseTraceAgreesWithTheSameTraceSampledFinely) {
  const std::vector<std::pair<double, double>> coast{{0.0, 60.0}, {30.0, 0.0}, {40.0, 0.0}};
  for (const char* file : {"vehicles/ice.yaml", "vehicles/camry_2018_map.yaml"}) {
    const auto m = model_of(file);
    const DriveCycle coarse = points_only(coast);
    const double fine_j = simulate_replay(m, sampled(coast, 0.05)).energy.fuel_j;
    EXPECT_NEAR(simulate_replay(m, coarse).energy.fuel_j / fine_j, 1.0, 0.01) << file;
    EXPECT_NEAR(simulate_forward(m, coarse).energy.fuel_j / fine_j, 1.0, 0.01) << file;
  }
}

// A second that falls through a fuel cut-off's road or engine speed, or passes a shift speed, is split there. Uncut,
// two Gauss points booked half a second of idle fuel across camry_2018_map's 18 km/h cut-off where 0.24 s was due
// (session 22's outside testing). Each coarse ramp below crosses one such speed, braking; the reference is the same
// ramps sampled at 1 ms.
TEST(Simulation, ABrakingSecondIsSplitWhereTheFuelIsCutOff) {
  // camry_2018_map: the 18 km/h road-speed cut-off; ice.yaml: 1100 rpm in 2nd (2.05 x 4.06 on 0.298 m: 14.9 km/h).
  for (const auto& [file, from_kmh, to_kmh] : {std::tuple{"vehicles/camry_2018_map.yaml", 20.7, 17.1},
                                               std::tuple{"vehicles/ice.yaml", 15.5, 12.75}}) {
    const auto m = model_of(file);
    const std::vector<std::pair<double, double>> ramp{{0.0, from_kmh}, {1.0, to_kmh}, {3.0, to_kmh}};
    const double fine_j = simulate_replay(m, sampled(ramp, 0.001)).energy.fuel_j;
    EXPECT_NEAR(simulate_replay(m, points_only(ramp)).energy.fuel_j / fine_j, 1.0, 1e-4) << file;
  }
}

// A shipped 1 Hz cycle replayed as it is and resampled at 10 Hz is the same trace, so nearly the same fuel. Before
// the cut-off and shift-speed splits above, NEDC's 1 Hz replay read +0.155 % (camry_2018_map) and the US06's -0.058 %
// (ice.yaml). What is left is the engine-map car's own gear choice, which depends on the load as well as the speed
// and so has no speeds to split at, and its launches from rest through the slipping converter: the two Gauss points
// of a second that holds a shift or a launch, +0.11 % on NEDC (README, "Simulation method").
TEST(Simulation, ReplayOfAShippedCycleEqualsItsTenHertzResample) {
  for (const char* cycle : {"nedc", "us06", "udds"}) {
    const DriveCycle c = load_cycle(cycle);
    std::vector<std::pair<double, double>> points;
    for (std::size_t i = 0; i < c.time_s.size(); ++i) points.emplace_back(c.time_s[i], c.speed_mps[i] * 3.6);
    const DriveCycle fine = sampled(points, 0.1);
    for (const auto& [file, tolerance] : {std::pair{"vehicles/ice.yaml", 1.5e-4}, std::pair{"vehicles/camry_2018.yaml", 1.5e-4},
                                          std::pair{"vehicles/camry_2018_map.yaml", 1.5e-3}}) {
      const auto m = model_of(file);
      EXPECT_NEAR(simulate_replay(m, c).energy.fuel_j / simulate_replay(m, fine).energy.fuel_j, 1.0, tolerance) << file << " " << cycle;
    }
  }
}

// The engine-map car's gearbox picks its gear inside the powertrain; the trace says which (it printed 0 throughout).
TEST(Simulation, TheTraceNamesTheGearAnAutomaticPicks) {
  const auto m = model_of("vehicles/camry_2018_map.yaml");
  SimulationOptions opt;
  opt.record_trace = true;
  for (const auto& r : {simulate_forward(m, constant_speed_cycle(100.0 / 3.6, 300.0), opt),
                        simulate_replay(m, constant_speed_cycle(100.0 / 3.6, 300.0), opt)}) {
    ASSERT_FALSE(r.trace.empty());
    // 100 km/h in the UA80E's 8th (0.673 x 2.80 on a 0.326 m tyre) is 1533 rpm, above the 1100 rpm floor; 7th
    // would be too, at a lower load share, so the schedule's highest gear is the one.
    EXPECT_EQ(r.trace.back().gear, 8) << r.mode;
  }
}

// The vehicle file's reference says a braking car below the cut-off speed burns idle fuel: the engine idles
// declutched. The Willans engine burnt its zero-load fuel at the gear's engine speed instead (camry_2018 in 2nd at
// 16 km/h: 1.01 l/h against 0.64 l/h standing), unlike the engine-map car, which idles.
TEST(Simulation, ABrakingCombustionCarBelowTheCutOffBurnsIdleFuel) {
  for (const char* file : {"vehicles/ice.yaml", "vehicles/camry_2018.yaml", "vehicles/camry_2018_map.yaml"}) {
    const auto m = model_of(file);
    const double r = m.wheel_radius_m;
    const PowerFlow standing = m.powertrain->deliver(0.0, 0.0, 1, r);
    ASSERT_GT(standing.fuel_rate_m3_per_s, 0.0) << file;
    int below_cut_off = 0;
    for (double v = 0.5; v < 15.0; v += 0.25) {
      const PowerFlow f = m.powertrain->deliver(-800.0, v, 2, r);
      if (f.fuel_rate_m3_per_s == 0.0) continue;  // fuel cut off
      ++below_cut_off;
      EXPECT_NEAR(f.fuel_rate_m3_per_s / standing.fuel_rate_m3_per_s, 1.0, 1e-12) << file << " at " << v << " m/s";
      EXPECT_NEAR(f.machine_speed_radps, standing.machine_speed_radps, 1e-9) << file << " at " << v << " m/s";
    }
    EXPECT_GT(below_cut_off, 2) << file << ": 2nd gear brakes below the cut-off at a walking pace";
  }
}

// A trace's running totals are the run's own integrals: their last values are its totals, where point powers summed
// over a 1 Hz trace miss the kinks. The replay's state of charge lagged a second behind through every cruise and
// standstill, because a cruise was booked only when the next segment began.
TEST(Simulation, TheTracesRunningTotalsAreTheRunsOwnAndTheReplaysChargeDoesNotLag) {
  SimulationOptions opt;
  opt.record_trace = true;
  const auto nedc = load_cycle("nedc");
  for (const char* file : {"vehicles/ev.yaml", "vehicles/ice.yaml"}) {
    const auto m = model_of(file);
    const auto fwd = simulate_forward(m, nedc, opt);
    const TracePoint& end = fwd.trace.back();
    EXPECT_DOUBLE_EQ(end.time_s, nedc.time_s.back()) << file;
    EXPECT_NEAR(end.battery_terminal_energy_j, fwd.energy.battery_terminal_j, 1e-9 * (1.0 + std::abs(fwd.energy.battery_terminal_j))) << file;
    const double fuel_m3 = fwd.fuel ? fwd.fuel->volume_m3 : 0.0;
    EXPECT_NEAR(end.fuel_volume_m3, fuel_m3, 1e-12 + 1e-9 * fuel_m3) << file;
    // The replay's rows are segment starts: each row plus its segment's mean gives the next row's total.
    const auto rep = simulate_replay(m, nedc, opt);
    for (std::size_t i = 0; i + 1 < rep.trace.size(); ++i) {
      const TracePoint &a = rep.trace[i], &b = rep.trace[i + 1];
      const double dt = b.time_s - a.time_s;
      ASSERT_NEAR(b.battery_terminal_energy_j - a.battery_terminal_energy_j, a.segment_battery_power_w * dt, 1e-6) << file << " at " << a.time_s;
      ASSERT_NEAR(b.fuel_volume_m3 - a.fuel_volume_m3, a.segment_fuel_rate_m3_per_s * dt, 1e-15) << file << " at " << a.time_s;
    }
  }
  // Standing still on the electric car the charge falls every second, by the standstill's load, in both runs.
  const auto m = model_of("vehicles/ev.yaml");
  const auto rep = simulate_replay(m, nedc, opt), fwd = simulate_forward(m, nedc, opt);
  for (std::size_t i = 1; i < 11; ++i) {
    EXPECT_LT(rep.trace[i].soc, rep.trace[i - 1].soc) << "replay at " << rep.trace[i].time_s << " s";
    EXPECT_NEAR(rep.trace[i].soc, fwd.trace[i].soc, 1e-9) << "at " << rep.trace[i].time_s << " s";
  }
}

// A trace that holds a shift speed: camry_2018's 1->2 upshift is at 15 km/h, NEDC's first cruise. The forward car
// follows the cruise to within the speed's tolerance, and its gear for the whole cruise was whatever side of 15 km/h
// the integrator's error fell on: 1st or 2nd as the car's mass or tyre pressure moved by 1 %, the fuel jumping 0.6 %
// (session 22's outside testing of `sensitivity`). A held shift speed keeps its gear, as the replay, which compares
// the trace's own speed, keeps it.
TEST(Simulation, ACruiseHeldAtAShiftSpeedKeepsItsGear) {
  const std::vector<std::pair<double, double>> hold{{0.0, 0.0}, {5.0, 0.0}, {10.0, 15.0}, {40.0, 15.0}, {45.0, 0.0}, {50.0, 0.0}};
  const DriveCycle c = sampled(hold, 1.0);
  SimulationOptions opt;
  opt.record_trace = true;
  for (int k = -4; k <= 4; ++k) {
    Vehicle v = load_vehicle_file(shipped("vehicles/camry_2018.yaml"));
    v.body.test_mass_kg *= 1.0 + 0.01 * k;
    const auto m = VehicleModel::assemble(v);
    const auto fwd = simulate_forward(m, c, opt);
    const auto rep = simulate_replay(m, c, opt);
    for (const auto& p : fwd.trace) {
      if (p.time_s > 11.0 && p.time_s < 40.0) EXPECT_EQ(p.gear, 1) << "mass x" << 1.0 + 0.01 * k << " at " << p.time_s << " s";
    }
    ASSERT_TRUE(fwd.fuel && rep.fuel);
    EXPECT_NEAR(fwd.fuel->volume_m3 / rep.fuel->volume_m3, 1.0, 5e-4) << "mass x" << 1.0 + 0.01 * k;
  }
}

// An upshift speed the car cannot reach: the file's check takes a gear's top speed on the outer radius (ice.yaml's
// 1st: 47.8 km/h at 6300 rpm), the simulation gears it on the rolling radius (46.7 km/h). With its 1->2 upshift at
// 47.5 km/h the car sat in 1st on the limiter, 23 km/h behind a 70 km/h trace (session 25's outside testing); it
// now shifts up at the limiter, follows the trace, and forward and replay agree.
TEST(Simulation, AnUpshiftSpeedPastTheLimiterIsTakenAtTheLimiter) {
  std::ifstream in(shipped("vehicles/ice.yaml"));
  std::string text((std::istreambuf_iterator<char>(in)), {});
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"upshift_speeds_kmh: [16, 33, 48, 65]", "upshift_speeds_kmh: [47.5, 48, 55, 65]"},
                                 {"all: nominal.yaml", "all: " + shipped("tyres/nominal.yaml")}}) {
    const auto pos = text.find(from);
    ASSERT_NE(pos, std::string::npos) << from;
    text.replace(pos, from.size(), to);
  }
  const auto m = VehicleModel::assemble(load_vehicle_file(temp_file("late_upshift.yaml", text)));
  const DriveCycle c = sampled({{0.0, 0.0}, {20.0, 70.0}, {80.0, 70.0}, {100.0, 0.0}}, 1.0);
  SimulationOptions opt;
  opt.record_trace = true;
  const auto fwd = simulate_forward(m, c, opt);
  const auto rep = simulate_replay(m, c);
  EXPECT_LT(fwd.max_speed_error_mps, 1.0 / 3.6);
  EXPECT_TRUE(fwd.shortfalls.empty());
  for (const auto& p : fwd.trace)
    if (p.speed_mps > 47.0 / 3.6) EXPECT_GE(p.gear, 2) << "at " << p.time_s << " s, " << p.speed_mps * 3.6 << " km/h";
  ASSERT_TRUE(fwd.fuel && rep.fuel);
  EXPECT_NEAR(fwd.fuel->volume_m3 / rep.fuel->volume_m3, 1.0, 5e-3);
}

// A 1 Hz replay splits a braking second where the regenerating force turns from its torque to its power limit and at
// the motor's speed-limiter band: stepped across with two Gauss points, a 141 -> 69 km/h stop from inside the band
// read the regeneration 0.65 % high against the same trace at 100 Hz (session 25's outside testing).
TEST(Simulation, AReplayBrakingThroughTheMotorsKinksIsSplitThere) {
  const std::string car =
      "name: ev1\nbody:\n  test_mass_kg: 1500\n  drag_coefficient: 0.3\n  frontal_area_m2: 2.2\n  wheel_radius_m: 0.3\n"
      "coastdown: {a_n: 150, b_n_per_kmh: 0.0, c_n_per_kmh2: 0.03}\npowertrain:\n  type: electric\n  motor:\n"
      "    max_torque_nm: 250\n    max_power_kw: 80\n    max_speed_rpm: 10000\n    speed_limit_band_pct: 3\n"
      "    copper_loss_w_per_nm2: 0.05\n    iron_loss_w_per_radps: 2.0\n    constant_loss_w: 500\n"
      "  reduction: {ratio: 8.0, efficiency: 0.95}\n"
      "  battery: {open_circuit_voltage_v: 360, internal_resistance_ohm: 0.1, usable_capacity_kwh: 40}\n"
      "  regen: {max_power_kw: 30, driven_axle_brake_fraction: 1.0, min_speed_kmh: 5, fade_speed_kmh: 15}\n";
  const auto m = VehicleModel::assemble(load_vehicle_file(temp_file("ev_kinks.yaml", car)));
  const std::vector<std::pair<double, double>> stop{{0.0, 141.0}, {10.0, 69.0}, {11.0, 69.0}};
  const double coarse = simulate_replay(m, sampled(stop, 1.0)).energy.regen_wheel_j;
  const double fine = simulate_replay(m, sampled(stop, 0.01)).energy.regen_wheel_j;
  EXPECT_NEAR(coarse / fine, 1.0, 5e-4);  // 0.03 % now, +0.65 % before
}

// Where the car was behind is read at the solver's steps too, not only at the trace's samples: on a three-row trace
// the car behind from the start until it caught up was said to be behind "from t = 5 to 5 s" (session 25's outside
// testing). ev.yaml cannot reach 100 km/h in 5 s.
TEST(Simulation, AShortfallIsPlacedBetweenTheTracesSamples) {
  const auto r = simulate_forward(model_of("vehicles/ev.yaml"), points_only({{0.0, 0.0}, {5.0, 100.0}, {25.0, 100.0}}));
  ASSERT_EQ(r.shortfalls.size(), 1u);
  EXPECT_LT(r.shortfalls.front().start_s, 2.0);
  EXPECT_GT(r.shortfalls.front().end_s, 6.0);
  EXPECT_LT(r.shortfalls.front().end_s, 25.0);
}

// A kicked-down gear shifts up at its limiter too. ice.yaml cannot reach 100 km/h in 12 s: it kicks down, and the
// kicked-down gear settled on its limiter (the force there only tends to zero, so the top-speed root never fired),
// holding 2nd at 84.9 km/h for the whole minute at 100 km/h, 11.3 l/100 km where the replay reads 8.47 (session 25's
// outside testing). It now falls behind only on the ramp and follows the hold.
TEST(Simulation, AKickedDownGearShiftsUpAtItsLimiter) {
  SimulationOptions opt;
  opt.record_trace = true;
  const auto r = simulate_forward(model_of("vehicles/ice.yaml"), points_only({{0.0, 0.0}, {12.0, 100.0}, {72.0, 100.0}}), opt);
  for (const auto& p : r.trace)
    if (p.time_s >= 30.0) EXPECT_NEAR(p.speed_mps * 3.6, 100.0, 0.5) << "at " << p.time_s << " s, gear " << p.gear;
  for (const auto& s : r.shortfalls) EXPECT_LT(s.end_s, 30.0);
}

// A climb the next gear cannot hold: ice.yaml's 2nd reaches its 6300 rpm at 85 km/h, where its 3rd gives 2618 N
// against 2745 N of road load on 15 %. The top-speed upshift and the kick-down then undid each other at one instant
// for ever (session 22's outside testing: no output after 300 s). The car now settles near 2nd's limit, falling
// behind, and says so.
TEST(Simulation, AClimbTheNextGearCannotHoldEndsAndIsReported) {
  DriveCycle c = points_only({{0.0, 0.0}, {60.0, 100.0}, {120.0, 100.0}});
  std::fill(c.grade.begin(), c.grade.end(), 0.15);
  const auto r = simulate_forward(model_of("vehicles/ice.yaml"), c);
  ASSERT_FALSE(r.shortfalls.empty());
  EXPECT_LT(r.solver.restarts, 200);
  EXPECT_GT(r.max_speed_error_mps, 10.0 / 3.6);
}

// No gear pulls past its engine's top speed: the limiter gives no force there, in the top gear too. A two-gear ice.yaml
// followed NEDC's 120 km/h in 2nd at 8,880 rpm against its 6,300 rpm limit, unwarned (session 22's outside testing);
// it now falls behind at about 2nd's limit, 6300 rpm x 2 pi / 60 x r / (2.05 x final drive).
TEST(Simulation, NoGearPullsPastItsEnginesTopSpeed) {
  Vehicle v = load_vehicle_file(shipped("vehicles/ice.yaml"));
  auto& p = std::get<CombustionPowertrainParams>(v.powertrain);
  p.gearbox.ratios = {p.gearbox.ratios[0], p.gearbox.ratios[1]};
  p.gearbox.upshift_speeds_mps = {p.gearbox.upshift_speeds_mps[0]};
  p.gearbox.downshift_speeds_mps = {p.gearbox.downshift_speeds_mps[0]};
  const auto m = VehicleModel::assemble(v);
  const double limit_mps = p.engine.max_speed_radps * m.wheel_radius_m / (p.gearbox.ratios[1] * p.gearbox.final_drive_ratio);
  SimulationOptions opt;
  opt.record_trace = true;
  for (const auto& r : {simulate_forward(m, load_cycle("nedc"), opt), simulate_replay(m, load_cycle("nedc"), opt)}) {
    double top = 0.0;
    for (const auto& t : r.trace) top = std::max(top, t.speed_mps);
    if (r.mode == "forward") {
      EXPECT_FALSE(r.shortfalls.empty());
      EXPECT_LE(top, limit_mps) << top * 3.6 << " km/h";
      EXPECT_GT(top, 0.97 * limit_mps) << top * 3.6 << " km/h";
    } else {
      EXPECT_GT(r.energy.unmet_demand_j, 0.0);  // the replay keeps to the trace and books what the engine could not give
    }
  }
}
