// Cabin conditioning as a law of the ambient (issue 10): the hvac_ambient module and its errors, the hvac_cabin truth,
// and the benchmark's truths against each other (the vehicle-file switch is in test_effects.cpp, the exact law across
// trips in test_diagnose_trips.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "rollsim/common/error.hpp"
#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/diagnose/diagnose.hpp"
#include "rollsim/discovery/generate.hpp"
#include "rollsim/discovery/truths.hpp"
#include "rollsim/effects/catalogue.hpp"
#include "rollsim/sim/simulation.hpp"

namespace rollsim {
namespace {

Vehicle ev() { return load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml"); }

double hvac_w(double heat, double cool, double ambient_c) {
  const auto e = make_effect("hvac_ambient", {{"heat_w_per_k", heat}, {"cool_w_per_k", cool}, {"ambient_temp_c", ambient_c}}, {});
  return e->extra_electric_power_w(EffectInputs{}, nullptr);
}

const Finding* finding(const Diagnosis& d, const std::string& id) {
  for (const auto& f : d.findings)
    if (f.effect == id) return &f;
  return nullptr;
}

TEST(HvacAmbient, LawIsZeroInTheDeadBandAndGrowsLinearlyOutsideIt) {
  // Defaults: heating below 18 degC, cooling above 24 degC.
  EXPECT_DOUBLE_EQ(hvac_w(100.0, 50.0, 21.0), 0.0);
  EXPECT_DOUBLE_EQ(hvac_w(100.0, 50.0, 18.0), 0.0);
  EXPECT_DOUBLE_EQ(hvac_w(100.0, 50.0, 24.0), 0.0);
  EXPECT_NEAR(hvac_w(100.0, 50.0, -5.0), 100.0 * 23.0, 1e-9);
  EXPECT_NEAR(hvac_w(100.0, 50.0, 34.0), 50.0 * 10.0, 1e-9);
  EXPECT_NEAR(hvac_w(0.0, 50.0, -5.0), 0.0, 1e-12);  // a car with A/C only draws nothing in the cold
}

TEST(HvacAmbient, OnAnElectricCarItCostsExactlyItsPowerOverTheTrip) {
  const Vehicle v = ev();
  const DriveCycle c = load_cycle("wltc");
  VehicleModel base = VehicleModel::assemble(v), with = base;
  with.effects.push_back(make_effect("hvac_ambient", {{"heat_w_per_k", 80.0}, {"ambient_temp_c", -2.0}}, effect_context(v)));
  const SimulationResult r0 = simulate_replay(base, c), r1 = simulate_replay(with, c);
  EXPECT_NEAR(r1.energy.battery_terminal_j - r0.energy.battery_terminal_j, 80.0 * 20.0 * r0.duration_s, 1e-6 * r1.energy.battery_terminal_j);
}

TEST(HvacAmbient, BadParametersGiveOneNamedError) {
  EXPECT_THROW(make_effect("hvac_ambient", {{"heat_w_per_k", -5.0}}, {}), InputError);
  try {
    make_effect("hvac_ambient", {{"heat_below_c", 22.0}, {"cool_above_c", 20.0}}, {});
    FAIL() << "a dead band upside down was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cool_above_c"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("heat_below_c"), std::string::npos) << e.what();
  }
}

TEST(HvacAmbient, CabinTruthHeatsBelowAndCoolsAboveItsThresholds) {
  CabinClimate c;
  c.ua_w_per_k = 40.0, c.heat_below_c = 18.0, c.cool_above_c = 24.0, c.solar_w = 200.0, c.blower_w = 150.0;
  c.cop_at_25c = 3.0, c.cop_per_k = 0.05;
  EXPECT_DOUBLE_EQ(c.power_w(21.0), 0.0);
  EXPECT_NEAR(c.power_w(-2.0), 40.0 * 20.0 + 150.0, 1e-9);              // PTC: COP 1
  EXPECT_NEAR(c.power_w(35.0), (40.0 * 11.0 + 200.0) / 2.5 + 150.0, 1e-9);  // COP 3 - 0.05 x 10 K
  std::mt19937 rng(5);
  for (int k = 0; k < 50; ++k) {
    const CabinClimate d = cabin_climate(40.0, rng);
    EXPECT_GE(d.heat_below_c, 17.0);
    EXPECT_LE(d.cool_above_c, 25.0);
    EXPECT_GT(d.power_w(35.0), d.power_w(26.0));
    EXPECT_GT(d.power_w(-5.0), d.power_w(10.0));
  }
  EXPECT_THROW(generate_case(ev(), [] {
                 SyntheticCase s;
                 s.effects = {{"hvac_cabin", 40.0}};
                 return s;
               }()),
               InputError);  // the truth needs the trip's ambient
}

TEST(HvacAmbient, ConcealedCabinIsNamedAndTheTyreLawIsNotTakenForIt) {
  // The benchmark's truths against each other: a cabin load is hvac_ambient and not ambient_rrc; a tyre compound's
  // law is ambient_rrc and never hvac_ambient (a force over the distance against a power in time).
  const Vehicle v = ev();
  for (unsigned seed : {113001u, 113002u}) {
    MultiTripCase m;
    m.seed = seed;
    m.ambient_max_c = 35.0;
    m.effects = {{"hvac_cabin", 40.0}};
    const Diagnosis d = diagnose(v, generate_trips(v, m));
    ASSERT_FALSE(d.findings.empty()) << diagnosis_text(d);
    EXPECT_EQ(d.findings.front().effect, "hvac_ambient") << diagnosis_text(d);
    EXPECT_EQ(finding(d, "ambient_rrc"), nullptr) << diagnosis_text(d);
    m.effects = {{"ambient_compound", 0.008}};
    const Diagnosis t = diagnose(v, generate_trips(v, m));
    ASSERT_FALSE(t.findings.empty()) << diagnosis_text(t);
    EXPECT_EQ(t.findings.front().effect, "ambient_rrc") << diagnosis_text(t);
    EXPECT_EQ(finding(t, "hvac_ambient"), nullptr) << diagnosis_text(t);
  }
}

}  // namespace
}  // namespace rollsim
