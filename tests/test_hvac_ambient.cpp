// Cabin conditioning as a law of the ambient (issue 10): the hvac_ambient module, its vehicle-file switch and errors,
// the hvac_cabin truth, and the diagnosis naming the law across trips, apart from ambient_rrc.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <random>
#include <sstream>

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

const ParameterEstimate* parameter(const Finding& f, const std::string& name) {
  for (const auto& p : f.parameters)
    if (p.name == name) return &p;
  return nullptr;
}

bool has_note(const Diagnosis& d, const std::string& text) {
  return std::any_of(d.notes.begin(), d.notes.end(), [&](const std::string& n) { return n.find(text) != std::string::npos; });
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
  // From a vehicle file: switched on in `simulate`, and the same error names the file.
  const std::string dir = ::testing::TempDir();
  std::ifstream in(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  const std::string tyres = std::string("all: ") + ROLLSIM_SOURCE_DIR + "/tyres/nominal.yaml";
  text.replace(text.find("all: nominal.yaml"), std::string("all: nominal.yaml").size(), tyres);
  std::ofstream(dir + "/ev_hvac.yaml") << text << "effects:\n  hvac_ambient:\n    heat_w_per_k: 60\n    ambient_temp_c: 3\n";
  std::ofstream(dir + "/ev_hvac_bad.yaml") << text << "effects:\n  hvac_ambient:\n    heat_below_c: 25\n";
  const Vehicle v = load_vehicle_file(dir + "/ev_hvac.yaml");
  ASSERT_EQ(v.effects.size(), 1u);
  EXPECT_EQ(v.effects[0].id, EffectId::hvac_ambient);
  const DriveCycle c = load_cycle("wltc");
  const SimulationResult r0 = simulate_replay(VehicleModel::assemble(ev()), c), r1 = simulate_replay(VehicleModel::assemble(v), c);
  EXPECT_NEAR(r1.energy.battery_terminal_j - r0.energy.battery_terminal_j, 60.0 * 15.0 * r0.duration_s, 1e-6 * r1.energy.battery_terminal_j);
  try {
    load_vehicle_file(dir + "/ev_hvac_bad.yaml");
    FAIL() << "heat_below_c above cool_above_c was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("ev_hvac_bad.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("cool_above_c"), std::string::npos) << e.what();
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

// A trip whose measured power carries the catalogue's own law at a known k (the analytic limit the fit must recover),
// with white noise, in the vehicle's air (the diagnosis is told so: no density correction).
Recording law_trip(const Vehicle& v, const std::string& cycle, double ambient_c, double heat, double cool, unsigned seed) {
  const DriveCycle c = load_cycle(cycle);
  VehicleModel m = VehicleModel::assemble(v);
  m.effects.push_back(make_effect("hvac_ambient", {{"heat_w_per_k", heat}, {"cool_w_per_k", cool}, {"ambient_temp_c", ambient_c}}, effect_context(v)));
  SimulationOptions so;
  so.record_trace = true;
  const SimulationResult r = simulate_replay(m, c, so);
  Recording rec;
  rec.source = cycle + " at " + std::to_string(ambient_c) + " degC";
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 300.0);
  std::vector<double> p;
  for (std::size_t i = 0; i < r.trace.size(); ++i) {
    rec.time_s.push_back(c.time_s[i] - c.time_s.front());
    rec.speed_mps.push_back(c.speed_mps[i]);
    p.push_back(r.trace[i].battery_power_w + noise(rng));
  }
  rec.battery_power_w = p;
  rec.ambient_temp_k = std::vector<double>(p.size(), ambient_c + 273.15);
  return rec;
}

TEST(HvacAmbient, DiagnosisRecoversTheLawAcrossTripsWithAnInterval) {
  // The exact catalogue law, heating 60 W/K and cooling half that, over four trips at -5, 8, 21 and 33 degC.
  const Vehicle v = ev();
  DiagnoseOptions opt;
  opt.air_density_from_ambient = false;  // the trips' air is the vehicle's here
  const std::vector<Recording> recs{law_trip(v, "wltc", -5.0, 60.0, 30.0, 1), law_trip(v, "ftp75", 8.0, 60.0, 30.0, 2),
                                    law_trip(v, "artemis_road", 21.0, 60.0, 30.0, 3), law_trip(v, "wltc", 33.0, 60.0, 30.0, 4)};
  const Diagnosis d = diagnose(v, recs, opt);
  ASSERT_FALSE(d.findings.empty()) << diagnosis_text(d);
  EXPECT_EQ(d.findings.front().effect, "hvac_ambient") << diagnosis_text(d);
  EXPECT_EQ(finding(d, "ambient_rrc"), nullptr) << diagnosis_text(d);
  const Finding* f = finding(d, "hvac_ambient");
  ASSERT_NE(f, nullptr);
  const ParameterEstimate* heat = parameter(*f, "heat_w_per_k");
  const ParameterEstimate* cool = parameter(*f, "cool_w_per_k");
  ASSERT_NE(heat, nullptr);
  ASSERT_NE(cool, nullptr);
  EXPECT_EQ(heat->unit, "W/K");
  EXPECT_LT(heat->ci_low, 60.0) << diagnosis_text(d);
  EXPECT_GT(heat->ci_high, 60.0) << diagnosis_text(d);
  EXPECT_GT(heat->ci_low, 0.0);
  EXPECT_NEAR(cool->value / heat->value, 0.5, 1e-9);  // the grid's ratio that is the truth's
  EXPECT_TRUE(has_note(d, "hvac_ambient tested across 4 recordings")) << diagnosis_text(d);
}

TEST(HvacAmbient, NotTestedOnOneTripTheSameAmbientOrInTheDeadBand) {
  const Vehicle v = ev();
  const Recording cold = law_trip(v, "wltc", -5.0, 80.0, 0.0, 1);
  const Diagnosis one = diagnose(v, {cold});
  EXPECT_EQ(finding(one, "hvac_ambient"), nullptr);
  EXPECT_TRUE(has_note(one, "hvac_ambient not tested: one recording")) << diagnosis_text(one);
  const Diagnosis band = diagnose(v, {law_trip(v, "wltc", 18.5, 80.0, 80.0, 1), law_trip(v, "ftp75", 23.5, 80.0, 80.0, 2)});
  EXPECT_EQ(finding(band, "hvac_ambient"), nullptr);
  EXPECT_TRUE(has_note(band, "within its dead band")) << diagnosis_text(band);
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
