// Diagnosis proof: a concealed tyre warm-up (richer truth) is named; null and time-reversed recordings are not.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <variant>
#include <fstream>

#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/diagnose/diagnose.hpp"
#include "rollsim/discovery/generate.hpp"
#include "rollsim/sim/simulation.hpp"

namespace rollsim {
namespace {

Vehicle ev() { return load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml"); }

bool names(const Diagnosis& d, const std::string& id) {
  if (d.findings.empty()) return false;
  const auto& f = d.findings.front();
  return f.effect == id || std::find(f.confounded_with.begin(), f.confounded_with.end(), id) != f.confounded_with.end();
}

TEST(Diagnose, NamesAConcealedTyreWarmupAndImprovesTheHeldOutFit) {
  const Vehicle v = ev();
  for (unsigned seed : {1u, 2u, 3u}) {
    SyntheticOptions o;
    o.tyre_cold_excess = 0.3;
    o.seed = seed;
    const Diagnosis d = diagnose(v, {generate_recording(v, o)});
    ASSERT_NE(d.verdict, "nothing_missing") << diagnosis_text(d);
    EXPECT_TRUE(names(d, "tyre_warmup")) << diagnosis_text(d);
    const auto& f = d.findings.front();
    EXPECT_LT(f.heldout_rmse_after_j, f.heldout_rmse_before_j);
    // The cold excess is positive (a cold tyre rolls harder); the truth's is 0.3 in another functional form.
    if (f.effect == "tyre_warmup") EXPECT_GT(f.parameters.front().value, 0.0);
  }
}

TEST(Diagnose, SaysNothingMissingOnNullRecordings) {
  const Vehicle v = ev();
  int discoveries = 0;
  for (unsigned seed = 1; seed <= 6; ++seed) {
    SyntheticOptions o;
    o.seed = seed;
    const Diagnosis d = diagnose(v, {generate_recording(v, o)});
    if (d.verdict != "nothing_missing") ++discoveries;
    EXPECT_EQ(d.verdict, "nothing_missing") << "seed " << seed << "\n" << diagnosis_text(d);
  }
  EXPECT_EQ(discoveries, 0);
}

TEST(Diagnose, TimeReversedDecayIsNotCalledWarmup) {
  const Vehicle v = ev();
  SyntheticOptions o;
  o.tyre_cold_excess = 0.3;
  o.time_reversed = true;
  const Diagnosis d = diagnose(v, {generate_recording(v, o)});
  if (!d.findings.empty()) {
    const auto& f = d.findings.front();
    // A warm-up fitted to a late rise would need a negative cold excess; that is not a warm-up.
    if (f.effect == "tyre_warmup") EXPECT_LT(f.parameters.front().value, 0.0) << diagnosis_text(d);
  }
}

TEST(Diagnose, JsonHasTheIssuesKeys) {
  const Vehicle v = ev();
  SyntheticOptions o;
  o.tyre_cold_excess = 0.3;
  const std::string j = diagnosis_json(diagnose(v, {generate_recording(v, o)}));
  for (const char* key : {"\"verdict\"", "\"findings\"", "\"effect\"", "\"parameters\"", "\"value\"", "\"ci_low\"", "\"ci_high\"",
                          "\"unit\"", "\"confounded_with\"", "\"heldout_rmse_before\"", "\"heldout_rmse_after\"",
                          "\"heldout_energy_error_pct_before\"", "\"heldout_energy_error_pct_after\"", "\"located\""})
    EXPECT_NE(j.find(key), std::string::npos) << key;
}

}  // namespace
}  // namespace rollsim

namespace rollsim {
namespace {

// Ratio of measured to simulated energy over [t0, t1) of a recording.
double measured_over_simulated(const Vehicle& v, const Recording& r, double t0, double t1) {
  const DriveCycle c = cycle_of_recording(r);
  SimulationOptions so;
  so.record_trace = true;
  const SimulationResult s = simulate_replay(VehicleModel::assemble(v), c, so);
  double em = 0.0, es = 0.0;
  for (std::size_t i = 0; i + 1 < r.time_s.size(); ++i) {
    if (r.time_s[i] < t0 || r.time_s[i] >= t1) continue;
    const double dt = r.time_s[i + 1] - r.time_s[i];
    em += (*r.battery_power_w)[i] * dt;
    es += s.trace[i].segment_battery_power_w * dt;  // the segment's mean, as simulate integrates it
  }
  return em / es;
}

TEST(Diagnose, WrittenVehicleReproducesTheWarmupInSimulation) {
  // The fitted vehicle file, loaded like any other, must remove most of the early-versus-late mismatch that the
  // concealed warm-up causes (calibration such as the channel scale cancels in the ratio of ratios).
  const std::string ev_path = std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml";
  const Vehicle v = load_vehicle_file(ev_path);
  SyntheticOptions o;
  o.tyre_cold_excess = 0.3;
  o.seed = 4;
  const Recording rec = generate_recording(v, o);
  const Diagnosis d = diagnose(v, {rec});
  ASSERT_TRUE(names(d, "tyre_warmup")) << diagnosis_text(d);
  const std::string out = ::testing::TempDir() + "/ev_fitted_diag.yaml";
  std::ofstream(out) << fitted_vehicle_yaml(ev_path, d);
  const Vehicle fitted = load_vehicle_file(out);
  ASSERT_FALSE(fitted.effects.empty());
  const double before = measured_over_simulated(v, rec, 0, 600) / measured_over_simulated(v, rec, 1800, 1e9);
  const double after = measured_over_simulated(fitted, rec, 0, 600) / measured_over_simulated(fitted, rec, 1800, 1e9);
  EXPECT_GT(before, 1.0);  // the truth's cold tyres cost energy early
  EXPECT_LT(std::abs(after - 1.0), 0.5 * std::abs(before - 1.0)) << "before " << before << " after " << after;
}

}  // namespace
}  // namespace rollsim

// The detection limit is a lower bound: it is for an effect of exactly the catalogue's shape. The discovery benchmark,
// measured independently with richer concealed truths, names a tyre warm-up in 17 of 20 seeds at 20 % cold excess and
// in none at 5 %; on a null recording of the same kind the limit must be below the first and not absurdly small
// (measured: 5-6 %, and 0.010 /kN for tyre slip, where the benchmark's 50 % point is about 0.012).
TEST(DiagnoseLimits, DetectionLimitIsALowerBoundOfTheScorecard) {
  const rollsim::Vehicle v = rollsim::load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml");
  rollsim::SyntheticOptions o;
  o.tyre_cold_excess = 0.0;
  o.seed = 7;
  const auto d = rollsim::diagnose(v, {rollsim::generate_recording(v, o)});
  ASSERT_EQ(d.verdict, "nothing_missing");
  bool seen = false;
  for (const auto& l : d.detection_limits) {
    if (l.effect != "tyre_warmup") continue;
    seen = true;
    EXPECT_GT(l.smallest_detectable, 0.02);
    EXPECT_LT(l.smallest_detectable, 0.20);
    EXPECT_TRUE(l.within_bounds);
  }
  EXPECT_TRUE(seen);
}

TEST(DiagnoseLimits, ConfoundedPairsNameTheirSeparatingTest) {
  EXPECT_NE(rollsim::separating_test("mass", "rotational_inertia").find("grade"), std::string::npos);
  EXPECT_EQ(rollsim::separating_test("rotational_inertia", "mass"), rollsim::separating_test("mass", "rotational_inertia"));
  EXPECT_NE(rollsim::separating_test("aux_load", "rr_speed").find("standstill"), std::string::npos);
  EXPECT_FALSE(rollsim::separating_test("wind", "tyre_slip").empty());
}

// Where elevation is known, the mismatch is located uphill and downhill too. A recording made on a flat road but
// logged with a hill's elevation: the model then expects climbing power the measurement never had, so the residual
// (measured - model) is negative uphill and positive downhill.
TEST(DiagnoseLimits, LocatesUphillAndDownhillWhereElevationIsKnown) {
  const rollsim::Vehicle v = rollsim::load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml");
  rollsim::SyntheticOptions o;
  o.seed = 3;
  rollsim::Recording r = rollsim::generate_recording(v, o);
  std::vector<double> elevation_m(r.time_s.size(), 0.0);
  double x_m = 0.0;
  for (std::size_t i = 1; i < r.time_s.size(); ++i) {
    x_m += 0.5 * (r.speed_mps[i] + r.speed_mps[i - 1]) * (r.time_s[i] - r.time_s[i - 1]);
    elevation_m[i] = 40.0 * std::sin(2.0 * M_PI * x_m / 4000.0);  // +-40 m over 4 km: grades up to 6 %
  }
  r.elevation_m = elevation_m;
  const auto d = rollsim::diagnose(v, {r});
  double uphill = 0.0, downhill = 0.0;
  bool seen_up = false, seen_down = false;
  for (const auto& l : d.located) {
    if (l.regime.rfind("uphill", 0) == 0) { uphill = l.mean_w; seen_up = true; }
    if (l.regime.rfind("downhill", 0) == 0) { downhill = l.mean_w; seen_down = true; }
  }
  ASSERT_TRUE(seen_up && seen_down);
  EXPECT_LT(uphill, 0.0);
  EXPECT_GT(downhill, 0.0);
}

// A concealed warm-up leaves a slowly decaying, hence autocorrelated, residual; once the effect is found and fitted,
// the held-out residual is whiter.
TEST(DiagnoseLimits, FoundWarmupWhitensTheHeldOutResidual) {
  const rollsim::Vehicle v = rollsim::load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml");
  int checked = 0;
  for (unsigned seed : {1u, 2u, 3u}) {
    rollsim::SyntheticOptions o;
    o.tyre_cold_excess = 0.3;
    o.seed = seed;
    const auto d = rollsim::diagnose(v, {rollsim::generate_recording(v, o)});
    if (d.findings.empty() || d.findings.front().effect != "tyre_warmup") continue;
    const auto& f = d.findings.front();
    EXPECT_LT(f.heldout_lag1_autocorrelation_after, f.heldout_lag1_autocorrelation_before) << "seed " << seed;
    ++checked;
  }
  EXPECT_GE(checked, 2);
}

// State of charge gives energy per window, so the mismatch is located by window. An SOC recording of the model's own
// battery power plus 1.5 kW during the first 10 minutes only: the first-10-min windows carry a clearly positive
// residual, higher than the windows after 30 minutes.
TEST(DiagnoseLimits, LocatesSocRecordingsByWindow) {
  const rollsim::Vehicle v = rollsim::load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml");
  rollsim::DriveCycle c;
  const auto udds = rollsim::load_cycle("udds");
  for (int k = 0; k < 3; ++k) {
    const double t0 = c.time_s.empty() ? 0.0 : c.time_s.back() + 1.0;
    for (std::size_t i = 0; i < udds.time_s.size(); ++i) {
      c.time_s.push_back(t0 + udds.time_s[i]);
      c.speed_mps.push_back(udds.speed_mps[i]);
      c.grade.push_back(0.0);
    }
  }
  rollsim::SimulationOptions so;
  so.record_trace = true;
  const auto sim = rollsim::simulate_replay(rollsim::VehicleModel::assemble(v), c, so);
  const double capacity_j = std::get<rollsim::ElectricPowertrainParams>(v.powertrain).battery.usable_capacity_j;
  rollsim::Recording r;
  r.source = "synthetic_soc";
  std::vector<double> soc;
  double used_j = 0.0;
  for (std::size_t i = 0; i < sim.trace.size(); ++i) {
    r.time_s.push_back(sim.trace[i].time_s);
    r.speed_mps.push_back(sim.trace[i].speed_mps);
    soc.push_back(0.9 - used_j / capacity_j);
    if (i + 1 < sim.trace.size()) {
      const double dt = sim.trace[i + 1].time_s - sim.trace[i].time_s;
      used_j += (sim.trace[i].battery_power_w + (sim.trace[i].time_s < 600.0 ? 1500.0 : 0.0)) * dt;
    }
  }
  r.soc_fraction = soc;
  const auto d = rollsim::diagnose(v, {r});
  ASSERT_EQ(d.channel, "soc");
  double first = 0.0, late = 0.0, first_low = 0.0;
  bool seen_first = false, seen_late = false;
  for (const auto& l : d.located) {
    if (l.regime == "first 10 min (window)") { first = l.mean_w; first_low = l.ci_low_w; seen_first = true; }
    if (l.regime == "after 30 min (window)") { late = l.mean_w; seen_late = true; }
  }
  ASSERT_TRUE(seen_first && seen_late);
  EXPECT_GT(first_low, 0.0);
  EXPECT_GT(first, late + 500.0);
}


// The fuel and SOC channels of the generator: the artefacts are in the channel's own units (a non-negative flow
// on its meter's quantum; SOC on the BMS's 0.1 % steps), and the concealed truths add energy where they should.
TEST(Generate, FuelAndSocChannelsCarryTheirTruths) {
  const rollsim::Vehicle ice = rollsim::load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ice.yaml");
  const rollsim::Vehicle ev = rollsim::load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml");
  auto total = [](const std::vector<double>& x, std::size_t from, std::size_t to) {
    double s = 0.0;
    for (std::size_t i = from; i < to; ++i) s += x[i];
    return s;
  };
  rollsim::SyntheticCase f;
  f.channel = rollsim::SyntheticChannel::fuel_rate;
  const rollsim::Recording nul = rollsim::generate_case(ice, f);
  f.effects = {{"engine_oil_coolant", 0.4}};
  const rollsim::Recording cold = rollsim::generate_case(ice, f);  // same seed: same artefacts' stream
  ASSERT_TRUE(nul.fuel_rate_m3ps && cold.fuel_rate_m3ps);
  EXPECT_FALSE(cold.battery_power_w || cold.soc_fraction);
  const auto& fn = *nul.fuel_rate_m3ps;
  EXPECT_GE(*std::min_element(fn.begin(), fn.end()), 0.0);
  const double q = f.fuel_quantum_m3ps;
  for (double x : fn) EXPECT_NEAR(x / q, std::round(x / q), 1e-6);
  // Cold start: clearly more fuel in the first 5 minutes; warm after an hour: within the noise.
  EXPECT_GT(total(*cold.fuel_rate_m3ps, 0, 300), 1.15 * total(fn, 0, 300));
  const std::size_t n = fn.size();
  EXPECT_NEAR(total(*cold.fuel_rate_m3ps, n - 600, n), total(fn, n - 600, n), 0.01 * total(fn, n - 600, n));

  rollsim::SyntheticCase s;
  s.channel = rollsim::SyntheticChannel::soc;
  const rollsim::Recording base = rollsim::generate_case(ev, s);
  s.effects = {{"battery_r_of_soc", 0.2}};
  const rollsim::Recording worn = rollsim::generate_case(ev, s);
  ASSERT_TRUE(base.soc_fraction && worn.soc_fraction);
  const auto& sb = *base.soc_fraction;
  for (double x : sb) EXPECT_NEAR(x / 0.001, std::round(x / 0.001), 1e-6);
  EXPECT_LT(sb.back(), sb.front() - 0.1);
  EXPECT_LT(worn.soc_fraction->back(), sb.back());  // the extra resistance's loss drains the cells faster
}

// A state of charge's quantum is an error of each reading, not of each second: the floor, read from 2 s windows and
// scaled with a block's length as white noise, was tens of times a long block's (a session 28 outside tester's
// SOC-only nulls read 0.004-0.72 x it, median 0.02). On a null whose only noise is the 0.1 % quantum the residual now
// sits at its floor.
TEST(DiagnoseLimits, AStateOfChargeNullSitsAtItsNoiseFloor) {
  const rollsim::Vehicle v = rollsim::load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml");
  for (unsigned seed : {1u, 2u}) {
    rollsim::SyntheticCase c;
    c.channel = rollsim::SyntheticChannel::soc;
    c.seed = seed;
    const auto d = rollsim::diagnose(v, {rollsim::generate_case(v, c)});
    ASSERT_EQ(d.channel, "soc");
    EXPECT_GT(d.residual_to_noise_ratio, 0.2) << seed;
    EXPECT_LT(d.residual_to_noise_ratio, 3.0) << seed;
    EXPECT_EQ(d.verdict, "nothing_missing") << seed;
  }
}

// A state of charge counts what leaves the cells, so the model side must include the cells' internal loss: then an
// extra internal resistance has a signature and a detection limit on SOC recordings (it had none when the diagnosis
// compared SOC with terminal energy only).
TEST(DiagnoseLimits, BatteryResistanceIsVisibleOnStateOfCharge) {
  const rollsim::Vehicle v = rollsim::load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml");
  rollsim::SyntheticCase c;
  c.channel = rollsim::SyntheticChannel::soc;
  c.seed = 3;
  const auto d = rollsim::diagnose(v, {rollsim::generate_case(v, c)});
  ASSERT_EQ(d.channel, "soc");
  bool seen = false;
  for (const auto& l : d.detection_limits) {
    if (l.effect != "battery_resistance") continue;
    seen = true;
    EXPECT_TRUE(std::isfinite(l.smallest_detectable));
    EXPECT_TRUE(l.within_bounds);
  }
  EXPECT_TRUE(seen);
}

namespace rollsim {
namespace {

// A regen cap of 4 kW (the truth: the powertrain's own regen limit lowered) leaves braking energy unrecovered from a
// lower braking power than the catalogue's default 10 kW limit. With that one limit the fit needed a friction share
// above 1 (out of bounds), so a force-squared tyre slip was named instead; the limit is a shape grid now, profiled.
TEST(DiagnoseLimits, NamesALowRegenCapAsARegenLimit) {
  const Vehicle v = ev();
  // Seed 25090's profile reaches limits above every braking power of its trace, where the signature is zero.
  for (unsigned seed : {1u, 2u, 25090u}) {
    SyntheticCase c;
    c.effects = {{"regen_cap", 4000.0}};
    c.seed = seed;
    const Diagnosis d = diagnose(v, {generate_case(v, c)});
    ASSERT_FALSE(d.findings.empty());
    const Finding& f = d.findings.front();
    EXPECT_EQ(f.effect, "regen_limit") << "seed " << seed;
    EXPECT_TRUE(f.confounded_with.empty()) << "seed " << seed;
    // The residual left after it is at the noise (it was 2.3-2.9 times the floor after tyre slip).
    EXPECT_LT(d.final_residual_to_noise_ratio, 1.5) << "seed " << seed;
  }
}

// An engine warming in minutes (the truth's oil and coolant nodes, fuel channel, 10 % cold excess) is a start-decaying
// excess like a fast tyre warm-up. With one slow engine shape against three tyre shapes, the tyre's 20 kJ/K shape won
// with a cold RRC excess of 50-60 %; with a grid of engine shapes the engine is named (or confounded with the tyre).
TEST(DiagnoseLimits, EngineWarmingInMinutesIsNotNamedATyreWarmup) {
  const Vehicle ice = load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ice.yaml");
  for (unsigned seed : {1u, 3u, 4u}) {
    SyntheticCase c;
    c.channel = SyntheticChannel::fuel_rate;
    c.effects = {{"engine_oil_coolant", 0.1}};
    c.seed = seed;
    const Diagnosis d = diagnose(ice, {generate_case(ice, c)});
    ASSERT_FALSE(d.findings.empty());
    EXPECT_EQ(d.findings.front().effect, "engine_warmup") << "seed " << seed;
  }
}

TEST(Diagnose, AGradeOffsetFoundBesideAPinnedRrcLevelNamesTheTyreAsItsAlternative) {
  // Tyres 0.9 bar under-inflated on a trip without elevation: the RRC level wants beyond its +20 % box, and a climbing
  // grade offset (the same constant force m g) takes the rest. The finding must say that a tyre rolling harder is the
  // other reading, and how to tell them apart. Seed 1 is one where road_grade is found.
  const Vehicle v = ev();
  SyntheticCase c;
  c.effects = {{"underinflated", -0.9}};
  c.seed = 1;
  const Diagnosis d = diagnose(v, {generate_case(v, c)});
  ASSERT_FALSE(d.findings.empty());
  const Finding& f = d.findings.front();
  ASSERT_EQ(f.effect, "road_grade") << diagnosis_text(d);
  const bool says = std::any_of(f.separating_tests.begin(), f.separating_tests.end(), [](const std::string& t) {
    return t.find("RRC level") != std::string::npos && t.find("tyre pressures") != std::string::npos;
  });
  EXPECT_TRUE(says) << diagnosis_text(d);
  // A dragging brake is the same constant force while moving, at the RRC's box or not (session 28's outside tester:
  // a 40 N brake named road_grade in 6 of 10 WLTCs with no word of it).
  const bool brake = std::any_of(f.separating_tests.begin(), f.separating_tests.end(), [](const std::string& t) {
    return t.find("dragging brake") != std::string::npos && t.find("both directions") != std::string::npos;
  });
  EXPECT_TRUE(brake) << diagnosis_text(d);
}

}  // namespace
}  // namespace rollsim
