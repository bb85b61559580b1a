// Effects catalogue: neutral parameters change nothing, each effect moves energy the physical way, balances close.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "rollsim/common/error.hpp"
#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/effects/catalogue.hpp"
#include "rollsim/sim/simulation.hpp"
#include "rollsim/vehicle/vehicle.hpp"

namespace rollsim {
namespace {

Vehicle vehicle(const std::string& name) { return load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/" + name); }

EffectContext context(const Vehicle& v) {
  return {v.body.test_mass_kg, v.body.air_density_kg_per_m3 * v.body.drag_coefficient * v.body.frontal_area_m2};
}

SimulationResult run(const Vehicle& v, std::shared_ptr<const Effect> e, bool forward = false) {
  VehicleModel m = VehicleModel::assemble(v);
  if (e) m.effects.push_back(e);
  const DriveCycle c = load_cycle("wltc");
  return forward ? simulate_forward(m, c) : simulate_replay(m, c);
}

double source_j(const SimulationResult& r) { return r.electric ? r.energy.battery_terminal_j : r.energy.fuel_j; }

TEST(EffectCatalogue, NeutralParametersLeaveEnergyUnchanged) {
  for (const char* file : {"ev.yaml", "ice.yaml"}) {
    const Vehicle v = vehicle(file);
    const double base = source_j(run(v, nullptr));
    for (const auto& info : effect_catalogue()) {
      const double e = source_j(run(v, make_effect(info.id, {}, context(v))));
      EXPECT_NEAR(e, base, 1e-9 * base) << file << " " << info.id;
    }
  }
}

TEST(EffectCatalogue, EachEffectMovesEnergyInThePhysicalDirection) {
  for (const char* file : {"ev.yaml", "ice.yaml"}) {
    const Vehicle v = vehicle(file);
    const auto ctx = context(v);
    const SimulationResult base = run(v, nullptr);
    auto more = [&](const std::string& id, EffectParameters p) { return source_j(run(v, make_effect(id, p, ctx))) - source_j(base); };
    EXPECT_GT(more("tyre_warmup", {{"cold_rrc_excess", 0.2}}), 0.0) << file;      // a cold tyre rolls harder
    EXPECT_GT(more("aux_load", {{"power_w", 500}}), 0.0) << file;
    EXPECT_GT(more("wind", {{"headwind_mps", 3}}), 0.0) << file;
    EXPECT_LT(more("wind", {{"headwind_mps", -3}}), 0.0) << file;                 // tailwind helps
    EXPECT_GT(more("mass", {{"extra_mass_kg", 150}}), 0.0) << file;
    EXPECT_GT(more("rr_speed", {{"rrc_change_at_100kmh", 0.2}}), 0.0) << file;
    EXPECT_GT(more("ambient_rrc", {{"rrc_change_per_k", 0.008}, {"ambient_temp_c", 0}}), 0.0) << file;  // cold day
  }
}

TEST(EffectCatalogue, AuxLoadOnAnElectricCarCostsExactlyItsEnergy) {
  // A constant consumer drawn at the terminals adds P x duration to terminal energy (its I^2 R is neglected).
  const Vehicle v = vehicle("ev.yaml");
  const SimulationResult base = run(v, nullptr);
  const SimulationResult with = run(v, make_effect("aux_load", {{"power_w", 400}}, context(v)));
  EXPECT_NEAR(with.energy.battery_terminal_j - base.energy.battery_terminal_j, 400.0 * base.duration_s, 1e-6 * base.energy.battery_terminal_j);
}

TEST(EffectCatalogue, TyreWarmupRollingExcessFadesAsTheTyreHeats) {
  // Over a long trip the cold excess fades: the rolling energy rises by much less than the full excess.
  const Vehicle v = vehicle("ev.yaml");
  const SimulationResult base = run(v, nullptr);
  const SimulationResult w = run(v, make_effect("tyre_warmup", {{"cold_rrc_excess", 0.2}}, context(v)));
  const double rise = w.energy.rolling_j / base.energy.rolling_j - 1.0;
  EXPECT_GT(rise, 0.0);
  EXPECT_LT(rise, 0.2);
}

TEST(EffectCatalogue, EnergyBalancesCloseWithEveryEffectOn) {
  // An effect must not open the balance: its residual stays that of the base model (the combustion replay's own
  // wheel residual, ~0.4 % on WLTC before any effect, belongs to the base model and is compared against).
  for (const char* file : {"ev.yaml", "ice.yaml"}) {
    const Vehicle v = vehicle(file);
    const auto ctx = context(v);
    const SimulationResult base_replay = run(v, nullptr, false), base_forward = run(v, nullptr, true);
    for (const auto& info : effect_catalogue()) {
      EffectParameters p;
      for (const auto& pi : info.parameters)
        if (pi.amplitude) p[pi.name] = pi.nominal;
      for (bool forward : {false, true}) {
        const SimulationResult r = run(v, make_effect(info.id, p, ctx), forward);
        const SimulationResult& b = forward ? base_forward : base_replay;
        EXPECT_NEAR(r.energy.wheel_residual_j(), b.energy.wheel_residual_j(), 2e-3 * r.energy.traction_j) << file << " " << info.id << " fwd " << forward;
        EXPECT_NEAR(r.energy.powertrain_residual_j(r.electric), b.energy.powertrain_residual_j(b.electric), 2e-3 * source_j(r)) << file << " " << info.id;
      }
    }
  }
}

TEST(EffectCatalogue, VehicleFileEffectsBlockIsReadStrictly) {
  const std::string dir = ::testing::TempDir();
  const std::string good = dir + "/ev_effects.yaml";
  {
    std::ifstream in(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml");
    std::stringstream ss;
    ss << in.rdbuf();
    std::string text = ss.str();
    const std::string tyres = std::string("all: ") + ROLLSIM_SOURCE_DIR + "/tyres/nominal.yaml";
    text.replace(text.find("all: nominal.yaml"), std::string("all: nominal.yaml").size(), tyres);
    std::ofstream(good) << text << "effects:\n  aux_load:\n    power_w: 500\n";
    std::ofstream(dir + "/ev_bad.yaml") << text << "effects:\n  aux_load:\n    powr_w: 500\n";
    std::ofstream(dir + "/ev_range.yaml") << text << "effects:\n  wind:\n    headwind_mps: 99\n";
    std::ofstream(dir + "/ev_unknown.yaml") << text << "effects:\n  gremlins:\n    n: 1\n";
  }
  const Vehicle v = load_vehicle_file(good);
  ASSERT_EQ(v.effects.size(), 1u);
  EXPECT_EQ(v.effects[0]->id(), "aux_load");
  EXPECT_GT(source_j(run(v, nullptr)), source_j(run(vehicle("ev.yaml"), nullptr)));
  EXPECT_THROW(load_vehicle_file(dir + "/ev_bad.yaml"), InputError);
  EXPECT_THROW(load_vehicle_file(dir + "/ev_range.yaml"), InputError);
  EXPECT_THROW(load_vehicle_file(dir + "/ev_unknown.yaml"), InputError);
}

}  // namespace
}  // namespace rollsim
