// Engine warm-up with engine-off soaks and start states: the simulator's engine_off, the module's soak cooling and hot
// start, the diagnosis' engine-off detection, and the cold-start truth's own warm-up (issue 10).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/diagnose/diagnose.hpp"
#include "rollsim/discovery/generate.hpp"
#include "rollsim/discovery/truths.hpp"
#include "rollsim/effects/catalogue.hpp"
#include "rollsim/sim/simulation.hpp"
#include "rollsim/vehicle/vehicle_file.hpp"
#include "test_support.hpp"

namespace rollsim {
namespace {

Vehicle ice() { return load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ice.yaml"); }

// UDDS, a standstill of soak_s, UDDS; the standstill's segments switched off when `off`.
DriveCycle udds_soak_udds(double soak_s, bool off) {
  const DriveCycle one = load_cycle("udds");
  DriveCycle c;
  c.name = "udds soak udds";
  auto append = [&] {
    const double t0 = c.time_s.empty() ? 0.0 : c.time_s.back() + 1.0;
    for (std::size_t i = 0; i < one.time_s.size(); ++i) {
      c.time_s.push_back(t0 + one.time_s[i] - one.time_s.front());
      c.speed_mps.push_back(one.speed_mps[i]);
      c.grade.push_back(0.0);
      c.engine_off.push_back(false);
    }
  };
  append();
  c.engine_off.back() = off;
  for (int k = 1; k <= static_cast<int>(soak_s); ++k) {
    c.time_s.push_back(c.time_s.back() + 1.0);
    c.speed_mps.push_back(0.0);
    c.grade.push_back(0.0);
    c.engine_off.push_back(off && k < static_cast<int>(soak_s));
  }
  append();
  return c;
}

double fuel_j(const Vehicle& v, const DriveCycle& c, std::shared_ptr<const Effect> e = nullptr) {
  VehicleModel m = VehicleModel::assemble(v);
  if (e) m.effects.push_back(e);
  return simulate_replay(m, c).energy.fuel_j;
}

TEST(EngineSoak, SwitchedOffEngineBurnsNoFuelAndTheIdledOneBurnsItsIdleFlow) {
  const Vehicle v = ice();
  const DriveCycle off = udds_soak_udds(600.0, true), idled = udds_soak_udds(600.0, false);
  VehicleModel m = VehicleModel::assemble(v);
  SimulationOptions so;
  so.record_trace = true;
  const SimulationResult r_off = simulate_replay(m, off, so), r_idle = simulate_replay(m, idled, so);
  double idle_w = 0.0, off_fuel = 0.0;
  const std::size_t soak_mid = load_cycle("udds").time_s.size() + 300;
  idle_w = r_idle.trace[soak_mid].segment_fuel_rate_m3_per_s;
  for (std::size_t i = 0; i + 1 < off.time_s.size(); ++i)
    if (off.engine_off_at(i)) off_fuel += r_off.trace[i].segment_fuel_rate_m3_per_s;
  EXPECT_EQ(off_fuel, 0.0);
  EXPECT_GT(idle_w, 0.0);
  // Idling through the soak costs exactly the idle flow's energy over the 600 switched-off seconds (the last run sample to the soak's last but one).
  const auto& cp = std::get<CombustionPowertrainParams>(v.powertrain);
  const double j_per_m3 = cp.fuel.density_kg_per_m3 * cp.fuel.lower_heating_value_j_per_kg;
  EXPECT_NEAR(r_idle.energy.fuel_j - r_off.energy.fuel_j, idle_w * 600.0 * j_per_m3, 1e-6 * r_idle.energy.fuel_j);
  // The energy balance still closes with the engine off.
  EXPECT_NEAR(r_off.energy.powertrain_residual_j(), 0.0, 1e-6 * r_off.energy.fuel_j);
  EXPECT_NEAR(r_off.energy.wheel_residual_j(), 0.0, 1e-6 * r_off.energy.fuel_j);
}

TEST(EngineSoak, ModuleCoolsByNewtonWhileOffAndAHotStartIsNotWarmedUpAgain) {
  const Vehicle v = ice();
  const auto warm = make_effect("engine_warmup", {{"cold_fuel_excess", 0.2}, {"soak_cooling_s", 1200.0}}, effect_context(v));
  double x = 30.0, xdot = 0.0;
  EffectInputs in;
  in.engine_off = true;
  warm->state_derivatives(in, &x, &xdot);
  EXPECT_DOUBLE_EQ(xdot, -30.0 / 1200.0);  // Newton's law towards ambient, no heat from a switched-off engine
  double x0 = -1.0;
  warm->initial_states(&x0);
  EXPECT_EQ(x0, 0.0);  // cold at ambient by default
  warm->hot_start_states(&x0);
  EXPECT_EQ(x0, 60.0);  // warm_excess_k: friction back to warm
  DriveCycle hot = load_cycle("udds"), cold = hot;
  hot.engine_hot_start = true;
  const double base = fuel_j(v, cold);
  const double cold_excess = fuel_j(v, cold, warm) / base - 1.0, hot_excess = fuel_j(v, hot, warm) / base - 1.0;
  EXPECT_GT(cold_excess, 0.02);
  EXPECT_LT(hot_excess, 0.1 * cold_excess);
}

TEST(EngineSoak, ACooledEngineCostsMoreAfterALongerSoak) {
  // After the soak the engine restarts part-cooled: the longer it stood, the more the second UDDS costs.
  const Vehicle v = ice();
  const auto warm = make_effect("engine_warmup", {{"cold_fuel_excess", 0.2}, {"heat_capacity_j_per_k", 30000.0},
                                                  {"soak_cooling_s", 1800.0}}, effect_context(v));
  const double short_soak = fuel_j(v, udds_soak_udds(300.0, true), warm) - fuel_j(v, udds_soak_udds(300.0, true));
  const double long_soak = fuel_j(v, udds_soak_udds(3000.0, true), warm) - fuel_j(v, udds_soak_udds(3000.0, true));
  EXPECT_GT(long_soak, short_soak);
}

TEST(EngineSoak, EngineOffIsStandingWithZeroFuelForFiveSeconds) {
  Recording r;
  r.source = "hand-made";
  std::vector<double> fuel;
  auto add = [&](int n, double v, double f) {
    for (int k = 0; k < n; ++k) {
      r.time_s.push_back(static_cast<double>(r.time_s.size()));
      r.speed_mps.push_back(v);
      fuel.push_back(f);
    }
  };
  add(5, 0.0, 1e-7);   // idling
  add(10, 5.0, 0.0);   // moving under fuel cut: the engine turns
  add(3, 0.0, 0.0);    // a 2 s glitch of zeros standing: noise, not a stop
  add(5, 0.0, 1e-7);
  add(12, 0.0, 0.0);   // start-stop at a light: 11 s
  add(5, 5.0, 2e-6);
  r.fuel_rate_m3ps = fuel;
  const std::vector<bool> off = engine_off_samples(r, 5.0);
  for (std::size_t i = 0; i < off.size(); ++i) EXPECT_EQ(off[i], i >= 23 && i < 35) << "sample " << i;
  r.fuel_rate_m3ps.reset();
  for (bool b : engine_off_samples(r, 5.0)) EXPECT_FALSE(b);  // no fuel channel: never off
}

TEST(EngineSoak, TruthWarmsUpInThreeToTenMinutesAndCoolsInTheSoak) {
  // The truth's own warm-up on a UDDS (fuel power from the simulator, engine off in the soak): the fuel factor's
  // excess falls below a tenth of its cold value within 3-10 minutes, and the restart after 10 minutes off is
  // part-cooled (an excess between none and the cold one).
  const Vehicle v = ice();
  const DriveCycle c = udds_soak_udds(600.0, true);
  VehicleModel m = VehicleModel::assemble(v);
  SimulationOptions so;
  so.record_trace = true;
  const SimulationResult r = simulate_replay(m, c, so);
  std::vector<double> t, fuel, traction;
  const auto& cp = std::get<CombustionPowertrainParams>(v.powertrain);
  const double j_per_m3 = cp.fuel.density_kg_per_m3 * cp.fuel.lower_heating_value_j_per_kg;
  for (const auto& p : r.trace) {
    t.push_back(p.time_s);
    fuel.push_back(p.segment_fuel_rate_m3_per_s * j_per_m3);
    traction.push_back(p.traction_power_w);
  }
  const std::size_t restart = load_cycle("udds").time_s.size() + 600;
  std::mt19937 rng(7);
  for (int k = 0; k < 30; ++k) {
    const EngineThermalTruth e = cold_start_engine(0.25, rng);
    const std::vector<double> p = engine_thermal_fuel_power_w(t, fuel, traction, c.engine_off, e);
    double warm_s = -1.0;
    for (std::size_t i = 0; i < restart && warm_s < 0.0; ++i)
      if (fuel[i] > 0.0 && p[i] / fuel[i] - 1.0 < 0.025) warm_s = t[i];
    EXPECT_GE(warm_s, 180.0) << "engine " << k;
    EXPECT_LE(warm_s, 600.0) << "engine " << k;
    std::size_t i = restart;
    while (!(fuel[i] > 0.0)) ++i;
    const double restart_excess = p[i] / fuel[i] - 1.0;
    EXPECT_GE(restart_excess, 0.0) << "engine " << k;
    EXPECT_LT(restart_excess, 0.25) << "engine " << k;
  }
}

TEST(EngineSoak, ColdStartWithASoakIsNamedEngineWarmupWithItsHeatCapacityInterval) {
  const Vehicle v = ice();
  SyntheticCase c;
  c.cycle = "udds";
  c.soak_s = 600.0;
  c.channel = SyntheticChannel::fuel_rate;
  c.effects = {{"engine_cold_soak", 0.25}};
  c.seed = 3;
  const Recording rec = generate_case(v, c);
  const Diagnosis d = diagnose(v, {rec});
  ASSERT_FALSE(d.findings.empty());
  const Finding& f = d.findings.front();
  EXPECT_EQ(f.effect, "engine_warmup");
  bool profiled = false;
  for (const auto& p : f.parameters)
    if (p.name == "heat_capacity_j_per_k") {
      profiled = p.profiled;
      EXPECT_LE(p.ci_low, p.value);  // a 3-minute warm-up may sit at the grid's fast end (an open interval)
      EXPECT_GE(p.ci_high, p.value);
      EXPECT_GT(p.ci_high, p.ci_low);
    }
  EXPECT_TRUE(profiled);
  // The soak's cooling time constant, profiled since the recording switches the engine off: an interval holding its
  // value (open at an end the 10-minute soak cannot bound). The truth's engine cools as oil and block together,
  // (C_oil + C_block) / (6 + 12 W/K): 1400-4700 s.
  bool soak_profiled = false;
  for (const auto& p : f.parameters)
    if (p.name == "soak_cooling_s") {
      soak_profiled = p.profiled;
      EXPECT_LE(p.ci_low, p.value);
      EXPECT_GE(p.ci_high, p.value);
      std::mt19937 truth_rng(3u * 7919u + 13u);
      const EngineThermalTruth e = cold_start_engine(0.25, truth_rng);
      const double truth_s = (e.oil_j_per_k + e.block_j_per_k) / 18.0;
      EXPECT_LE(p.ci_low, truth_s) << p.value << " [" << p.ci_low << ", " << p.ci_high << "] against " << truth_s;
      EXPECT_GE(p.ci_high, truth_s) << p.value << " [" << p.ci_low << ", " << p.ci_high << "] against " << truth_s;
    }
  EXPECT_TRUE(soak_profiled);
  bool noted = false;
  for (const auto& n : d.notes) noted = noted || n.find("switched off 1 times") != std::string::npos;
  EXPECT_TRUE(noted);
}

TEST(EngineSoak, CliRejectsAStartStateThatIsNeitherColdHotNorInfer) {
  const auto csv = test::temp_dir() / "short_trip.csv";
  {
    std::ofstream f(csv);
    f << "time_s,speed_kmh,fuel_rate_lph\n";
    for (int t = 0; t < 120; ++t) f << t << "," << (t < 10 || t > 110 ? 0 : 30) << ",1.2\n";
  }
  const auto r = test::run_rollsim("diagnose --vehicle ice --recording " + csv.string() + " --engine-start warm");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("--engine-start"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("'warm' is not allowed: cold, hot or infer"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace rollsim
