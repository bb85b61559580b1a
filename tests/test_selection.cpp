// Tyre selection library: sweeps, fit checks, ranking, sensitivities and the regression baseline reader.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <algorithm>
#include <fstream>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "rollsim/common/error.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/selection/common.hpp"
#include "rollsim/selection/compare.hpp"
#include "rollsim/selection/front_end.hpp"
#include "rollsim/selection/regress.hpp"
#include "rollsim/selection/sensitivity.hpp"
#include "rollsim/selection/sweep.hpp"

using namespace rollsim;
using namespace rollsim::selection;

namespace {

TyreSpec tyre(const std::string& name) { return load_tyre_file(resolve_data_file(name, "tyres", ".yaml", "test")); }
Vehicle vehicle(const std::string& name) {
  return load_vehicle_file(resolve_data_file(name, "vehicles", ".yaml", "test"));
}
bool has(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

SweepOptions one_axis(SweepParam p, double from, double to, int steps) {
  SweepOptions o;
  o.axes.push_back({p, from, to, steps});
  return o;
}

}  // namespace

TEST(SelectionSweep, RrcFallsWithPressure) {
  const SweepResult r = sweep_tyre(tyre("175-70R14"), one_axis(SweepParam::Pressure, 1.5, 3.5, 9));
  ASSERT_EQ(r.points.size(), 9u);
  EXPECT_FALSE(r.outside_domain);
  for (std::size_t i = 1; i < r.points.size(); ++i) {
    EXPECT_LT(r.points[i].rr.rrc, r.points[i - 1].rr.rrc) << "at " << r.points[i].values[0] << " bar";
    EXPECT_LT(r.points[i].rr.deflection_m, r.points[i - 1].rr.deflection_m);
  }
  EXPECT_DOUBLE_EQ(r.points.front().values[0], 1.5);
  EXPECT_DOUBLE_EQ(r.points.back().values[0], 3.5);
}

TEST(SelectionSweep, GridVisitsEveryPointAndPowerGrowsWithSpeed) {
  SweepOptions o = one_axis(SweepParam::Pressure, 2.0, 3.0, 3);
  o.axes.push_back({SweepParam::Speed, 40, 120, 5});
  const SweepResult r = sweep_tyre(tyre("175-70R14"), o);
  ASSERT_EQ(r.points.size(), 15u);
  for (std::size_t i = 0; i < r.points.size(); ++i) {
    if (i % 5) {
      EXPECT_GT(r.points[i].rr.rr_power_w, r.points[i - 1].rr.rr_power_w);
    }
  }
}

TEST(SelectionSweep, LeavesOutThePointsWhereTheDeflectionReachesTheRim) {
  const TyreSpec t = tyre("175-70R14");
  const SweepResult r = sweep_tyre(t, one_axis(SweepParam::Load, 1000, 40000, 40));
  ASSERT_TRUE(r.outside_domain.has_value());
  ASSERT_FALSE(r.points.empty());
  EXPECT_LT(r.points.size(), 40u);
  const double sidewall_m = t.state.geometry.outer_radius_m - t.state.geometry.rim_radius_m;
  EXPECT_LT(r.points.back().rr.deflection_m, sidewall_m);
  EXPECT_TRUE(has(*r.outside_domain, "rim")) << *r.outside_domain;
  EXPECT_TRUE(has(*r.outside_domain, std::to_string(40 - r.points.size()) + " of 40 points are outside")) << *r.outside_domain;
}

// A range that leaves the domain as it falls (pressure, diameter, width) keeps its valid points: a sweep stopped at its
// first invalid point, so a pressure range starting at 1 bar under 16 kN gave "no valid point" and a pressure x load
// grid lost the 2 and 3 bar rows after the corner (1 bar, 16 kN) where it stopped (session 22's outside testing).
TEST(SelectionSweep, PointsOutsideTheDomainAreLeftOutWhereverTheyAre) {
  const TyreSpec t = tyre("175-70R14");
  SweepOptions o = one_axis(SweepParam::Pressure, 1.0, 3.5, 6);
  o.load_n = 16000.0;
  const SweepResult one = sweep_tyre(t, o);
  ASSERT_EQ(one.points.size(), 5u);  // 1.5 to 3.5 bar carry 16 kN; 1 bar's deflection reaches the rim
  EXPECT_DOUBLE_EQ(one.points.front().values[0], 1.5);
  ASSERT_TRUE(one.outside_domain.has_value());
  EXPECT_TRUE(has(*one.outside_domain, "1 of 6 points")) << *one.outside_domain;

  SweepOptions grid = one_axis(SweepParam::Pressure, 1.0, 3.0, 3);
  grid.axes.push_back(SweepAxis{SweepParam::Load, 5000.0, 16000.0, 3});
  const SweepResult g = sweep_tyre(t, grid);
  EXPECT_EQ(g.points.size(), 8u);  // all but (1 bar, 16 kN)
  for (const auto& p : g.points) EXPECT_FALSE(p.values[0] == 1.0 && p.values[1] == 16000.0);
}

// A CSV or JSON line with one name twice is read as the last value by most readers; sweeping load or speed made
// "speed_kmh" twice (and "load_N" beside "load_n") until session 13.
TEST(SelectionSweep, EveryColumnNameIsUniqueWhateverIsSwept) {
  const std::vector<SweepParam> all{SweepParam::Pressure, SweepParam::Diameter, SweepParam::Width,
                                    SweepParam::Load,     SweepParam::LoadPct,  SweepParam::Speed};
  const std::vector<std::pair<double, double>> range{{2, 3}, {600, 700}, {150, 200}, {3000, 4000}, {60, 80}, {40, 80}};
  for (std::size_t a = 0; a < all.size(); ++a) {
    for (std::size_t b = 0; b <= all.size(); ++b) {
      if (b == a || (b < all.size() && (all[a] == SweepParam::Load || all[a] == SweepParam::LoadPct) &&
                     (all[b] == SweepParam::Load || all[b] == SweepParam::LoadPct))) {
        continue;
      }
      SweepOptions o = one_axis(all[a], range[a].first, range[a].second, 2);
      if (b < all.size()) o.axes.push_back({all[b], range[b].first, range[b].second, 2});
      const SweepResult r = sweep_tyre(tyre("175-70R14"), o);
      ASSERT_EQ(r.points.size(), b < all.size() ? 4u : 2u);
      const auto columns = sweep_point_columns(r, r.points.back());
      std::set<std::string> names;
      for (const auto& [name, value] : columns) EXPECT_TRUE(names.insert(name).second) << name << " twice";
      for (const char* must : {"load_n", "speed_kmh"}) EXPECT_TRUE(names.count(must)) << must;
      // The evaluated load and speed are what the columns say.
      for (const auto& [name, value] : columns) {
        if (name == "load_n") EXPECT_DOUBLE_EQ(value, r.points.back().load_n);
        if (name == "speed_kmh") EXPECT_DOUBLE_EQ(value, r.points.back().speed_kmh);
      }
      const std::string header = sweep_csv(r).substr(0, sweep_csv(r).find('\n'));
      EXPECT_EQ(std::count(header.begin(), header.end(), ',') + 1, static_cast<long>(columns.size() + 4)) << header;
    }
  }
}

TEST(SelectionSweep, BadRangesAreRejected) {
  EXPECT_THROW(check_axis({SweepParam::Pressure, 2.0, 2.0, 5}, "--param pressure"), InputError);
  EXPECT_THROW(check_axis({SweepParam::Pressure, 3.0, 2.0, 5}, "--param pressure"), InputError);
  EXPECT_THROW(check_axis({SweepParam::Pressure, 2.0, 3.0, 1}, "--param pressure"), InputError);
  EXPECT_THROW(check_axis({SweepParam::Pressure, -1.0, 3.0, 5}, "--param pressure"), InputError);
  EXPECT_NO_THROW(check_axis({SweepParam::Speed, 0.0, 100.0, 5}, "--param speed"));
  try {
    check_axis({SweepParam::Diameter, 700, 600, 5}, "--param diameter");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_TRUE(has(e.what(), "reversed")) << e.what();
  }
  // The car's loads and speeds come from the car and cycle: only tyre parameters may be swept in a car.
  EXPECT_THROW(sweep_vehicle(vehicle("ev"), tyre("nominal"), load_cycle("nedc"), one_axis(SweepParam::Speed, 10, 50, 3)),
               InputError);
}

TEST(SelectionSweep, VehicleEnergyFallsWithPressureAndThreadsDoNotChangeResults) {
  const Vehicle ev = vehicle("ev");
  const DriveCycle nedc = load_cycle("nedc");
  SweepOptions o = one_axis(SweepParam::Pressure, 1.8, 3.0, 4);
  o.threads = 1;
  const SweepResult serial = sweep_vehicle(ev, tyre("nominal"), nedc, o);
  o.threads = 3;
  const SweepResult parallel = sweep_vehicle(ev, tyre("nominal"), nedc, o);
  ASSERT_EQ(serial.points.size(), 4u);
  ASSERT_EQ(parallel.points.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_DOUBLE_EQ(serial.points[i].energy, parallel.points[i].energy);
    if (i) EXPECT_LT(serial.points[i].energy, serial.points[i - 1].energy);
  }
}

TEST(SelectionCompare, LowRrcBeatsNominalOnNedcForTheEvBySeveralPercent) {
  // Thesis: the low-RRC set saves "several per cent" of an EV's energy. The diameter check is widened here
  // because the low-RRC set is deliberately 8 % larger than the nominal one.
  CompareOptions o;
  o.diameter_tolerance_pct = 10.0;
  const Comparison c = compare_tyres(vehicle("ev"), {tyre("low-rrc")}, load_cycle("nedc"), o);
  ASSERT_EQ(c.ranked.size(), 2u);
  EXPECT_EQ(c.ranked.front().tyre.name, "low-rrc");
  EXPECT_LT(c.ranked.front().diff_pct, -2.0);
  EXPECT_GT(c.ranked.front().diff_pct, -10.0);
  EXPECT_GT(c.ranked.front().range_change_km, 0.0);
  EXPECT_TRUE(c.ranked.back().is_own);
  EXPECT_DOUBLE_EQ(c.ranked.back().diff_pct, 0.0);
}

TEST(SelectionCompare, OversizeAndOverloadedTyresAreMarkedNotRanked) {
  const Vehicle ev = vehicle("ev");
  TyreSpec weak = tyre("nominal");
  weak.name = "weak";
  weak.max_load_n = 3000.0;  // below the car's ~4000 N per wheel
  const Comparison c = compare_tyres(ev, {tyre("low-rrc"), weak}, load_cycle("nedc"));
  ASSERT_EQ(c.ranked.size(), 1u);
  EXPECT_TRUE(c.ranked[0].is_own);
  ASSERT_EQ(c.unfit.size(), 2u);
  EXPECT_EQ(c.unfit[0].tyre.name, "low-rrc");
  EXPECT_TRUE(has(c.unfit[0].fit.reason, "diameter")) << c.unfit[0].fit.reason;
  EXPECT_EQ(c.unfit[1].tyre.name, "weak");
  EXPECT_TRUE(has(c.unfit[1].fit.reason, "load")) << c.unfit[1].fit.reason;
  EXPECT_TRUE(has(c.unfit[1].fit.reason, "capacity")) << c.unfit[1].fit.reason;
}

// An own tyre that is overloaded at its pressure is the reference of the differences but is not ranked, as a
// candidate that does not fit is not (session 20: it was ranked first while a stronger candidate was left out).
TEST(SelectionCompare, AnOwnTyreThatDoesNotFitIsTheReferenceButNotRanked) {
  Vehicle heavy = vehicle("ev");
  TyreSpec own = tyre("nominal");
  own.max_load_n = 3000.0;  // below the car's ~4000 N per wheel
  fit_tyres(heavy, own);
  const Comparison c = compare_tyres(heavy, {tyre("175-65R15")}, load_cycle("nedc"));
  ASSERT_EQ(c.ranked.size(), 1u);
  EXPECT_EQ(c.ranked[0].tyre.name, "175-65R15");
  ASSERT_EQ(c.unfit.size(), 1u);
  EXPECT_TRUE(c.unfit[0].is_own);
  EXPECT_TRUE(has(c.unfit[0].fit.reason, "capacity")) << c.unfit[0].fit.reason;
  EXPECT_DOUBLE_EQ(c.unfit[0].diff_pct, 0.0);
  EXPECT_NEAR(c.ranked[0].diff_pct, (c.ranked[0].value / c.own_value - 1.0) * 100.0, 1e-12);
  // The wheel load the table's header names is the car's, whether or not any tyre fits (it read the ranked front's,
  // and 0 N when none fitted).
  EXPECT_DOUBLE_EQ(c.wheel_load_n, c.unfit[0].fit.wheel_load_n);
  EXPECT_GT(c.wheel_load_n, 3900.0);
}

// A light-truck size's load index is rated at its load range's pressure, which its designation does not give: at a
// car's 2.5 bar the passenger reference gave an LT245/75 R16 120/116S its full 1400 kg (session 20).
TEST(SelectionCompare, ALightTruckTyresCapacityIsUnknownNotThePassengerRating) {
  TyreSpec lt = tyre("nominal");
  lt.size = parse_tyre_size("LT245/75 R16 120/116S", "size");
  lt.max_load_n = 1400.0 * 9.80665;
  EXPECT_EQ(load_capacity_at_pressure_n(lt), 0.0);
  const FitCheck f = check_fit(vehicle("ev"), tyre("nominal"), lt, 50.0);
  EXPECT_FALSE(f.fits);
  EXPECT_TRUE(has(f.reason, "light-truck (LT)")) << f.reason;
  // A passenger size keeps its rating scaled from 2.5 bar.
  TyreSpec p = tyre("nominal");
  p.size = parse_tyre_size("245/75 R16 111T", "size");
  p.max_load_n = 1090.0 * 9.80665;
  p.state.pressure_pa = 2.1e5;
  EXPECT_NEAR(load_capacity_at_pressure_n(p), p.max_load_n * std::pow(2.1 / 2.5, 0.585), 1e-9);
}

// A diameter exactly the tolerance larger is within it: 628.3 mm against 610 mm computes as 3.0000000000000027 %, and
// was refused as "+3.0 % from 610 mm (tolerance 3 %)" (session 22's outside testing).
TEST(SelectionCompare, ADiameterChangeOfExactlyTheToleranceFits) {
  TyreSpec bigger = tyre("nominal");
  bigger.state.geometry.outer_radius_m *= 1.03;
  const FitCheck f = check_fit(vehicle("ev"), tyre("nominal"), bigger, 3.0);
  EXPECT_NEAR(f.diameter_change_pct, 3.0, 1e-12);
  EXPECT_TRUE(f.fits) << f.reason;
  bigger.state.geometry.outer_radius_m *= 1.0001;
  EXPECT_FALSE(check_fit(vehicle("ev"), tyre("nominal"), bigger, 3.0).fits);
}

namespace {

// A trace that ramps to `top_kmh` at 2 m/s^2, holds it for 60 s and stops: nothing beyond a car's top speed.
DriveCycle cruise_at(double top_kmh) {
  DriveCycle c;
  c.name = "cruise";
  const double top_mps = units::kmh_to_mps(top_kmh);
  const double ramp_s = std::ceil(top_mps / 2.0);
  for (double t = 0.0; t <= 2.0 * ramp_s + 60.0; t += 1.0) {
    const double v = t < ramp_s ? 2.0 * t : t < ramp_s + 60.0 ? top_mps : std::max(0.0, top_mps - 2.0 * (t - ramp_s - 60.0));
    c.time_s.push_back(t);
    c.speed_mps.push_back(std::min(v, top_mps));
    c.grade.push_back(0.0);
  }
  return c;
}

}  // namespace

TEST(SelectionCompare, AFigureOfACarThatFellBehindTheCycleSaysSo) {
  // The EV's motor turns at most 10390 rpm through a 7.94 reduction on a 0.305 m wheel: 150.4 km/h, whatever
  // its power. On a 200 km/h cruise it must fall at least 200 - 150.4 km/h behind, on every tyre; on NEDC (120 km/h
  // at most) it follows on every tyre. Before, compare ranked both alike and said nothing.
  const Vehicle ev = vehicle("ev");
  const double kinematic_top_kmh = units::mps_to_kmh(10390.0 * 2.0 * M_PI / 60.0 / 7.94 * 0.305);
  CompareOptions o;
  o.diameter_tolerance_pct = 10.0;
  const Comparison fast = compare_tyres(ev, {tyre("low-rrc")}, cruise_at(200.0), o);
  ASSERT_EQ(fast.ranked.size(), 2u);
  for (const auto& r : fast.ranked) {
    EXPECT_FALSE(r.trace.followed) << r.tyre.name;
    EXPECT_GE(units::mps_to_kmh(r.trace.max_deficit_mps), 200.0 - kinematic_top_kmh - 0.5) << r.tyre.name;
  }
  const auto warnings = trace_warnings(fast);
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_TRUE(has(warnings[0], "on nominal (own), cruise: the car could not follow the trace")) << warnings[0];
  EXPECT_TRUE(has(warnings[0], "slower drive")) << warnings[0];
  bool json_says = false;
  for (const auto& j : comparison_json(fast)) json_says = json_says || has(j.str(), "\"followed_trace\": false");
  EXPECT_TRUE(json_says);

  const Comparison nedc = compare_tyres(ev, {tyre("low-rrc")}, load_cycle("nedc"), o);
  for (const auto& r : nedc.ranked) {
    EXPECT_TRUE(r.trace.followed) << r.tyre.name;
    EXPECT_DOUBLE_EQ(r.trace.max_deficit_mps, 0.0);
  }
  EXPECT_TRUE(trace_warnings(nedc).empty());

  // A replay keeps to the trace: it cannot fall behind, and says instead that it left out the unmet demand.
  o.replay = true;
  const Comparison replayed = compare_tyres(ev, {tyre("low-rrc")}, cruise_at(200.0), o);
  for (const auto& r : replayed.ranked) {
    EXPECT_FALSE(r.trace.followed) << r.tyre.name;
    EXPECT_DOUBLE_EQ(r.trace.max_deficit_mps, 0.0);
  }
  ASSERT_EQ(trace_warnings(replayed).size(), 2u);
  EXPECT_TRUE(has(trace_warnings(replayed)[0], "leave out the demand")) << trace_warnings(replayed)[0];

  // The sweep and the sensitivities run the same figure and carry the same flag.
  const SweepResult swept = sweep_vehicle(ev, tyre("nominal"), cruise_at(200.0), one_axis(SweepParam::Pressure, 2.0, 3.0, 2));
  ASSERT_EQ(swept.points.size(), 2u);
  for (const auto& p : swept.points) EXPECT_FALSE(p.trace.followed);
  ASSERT_EQ(sweep_warnings(swept).size(), 1u);
  EXPECT_TRUE(has(sweep_warnings(swept)[0], "at 2 of 2 points (followed_trace no)")) << sweep_warnings(swept)[0];
  EXPECT_TRUE(has(sweep_csv(swept), ",no\n"));
  EXPECT_FALSE(vehicle_sensitivity(ev, tyre("nominal"), cruise_at(200.0), 4000.0, 80 / 3.6).followed_trace);
  EXPECT_TRUE(vehicle_sensitivity(ev, tyre("nominal"), load_cycle("nedc"), 4000.0, 80 / 3.6).followed_trace);
}

TEST(SelectionCompare, LoadCapacityGrowsWithPressureUpToTheRating) {
  TyreSpec t = tyre("catalogue/205-55R16");
  ASSERT_GT(t.max_load_n, 0.0);
  double last = 0.0;
  for (double bar : {1.6, 2.0, 2.4}) {
    t.state.pressure_pa = units::bar_to_pa(bar);
    const double cap = load_capacity_at_pressure_n(t);
    EXPECT_GT(cap, last);
    EXPECT_LT(cap, t.max_load_n);
    last = cap;
  }
  t.state.pressure_pa = units::bar_to_pa(3.2);
  EXPECT_DOUBLE_EQ(load_capacity_at_pressure_n(t), t.max_load_n);
  EXPECT_GT(reference_pressure_pa(tyre("catalogue/215-45R17")), reference_pressure_pa(tyre("catalogue/205-55R16")));  // XL
}

TEST(SelectionSensitivity, SignsOfDiameterPressureAndLoad) {
  const Sensitivity s = vehicle_sensitivity(vehicle("ev"), tyre("nominal"), load_cycle("nedc"), 4000.0, 80 / 3.6);
  ASSERT_EQ(s.rows.size(), 4u);
  for (const auto& r : s.rows) {
    ASSERT_TRUE(r.energy_elasticity.has_value());
    if (r.parameter == TyreParameter::OuterDiameter || r.parameter == TyreParameter::Pressure) {
      EXPECT_LT(r.power_elasticity, 0.0) << r.name;
      EXPECT_LT(*r.energy_elasticity, 0.0) << r.name;
    }
    if (r.parameter == TyreParameter::Load) {
      EXPECT_GT(r.power_elasticity, 0.0);
      EXPECT_GT(*r.energy_elasticity, 0.0);
    }
    // The tyre is only part of the car's losses: its share damps every elasticity.
    if (r.parameter != TyreParameter::Load) EXPECT_LT(std::abs(*r.energy_elasticity), std::abs(r.power_elasticity));
  }
  EXPECT_FALSE(s.dominant_power.empty());
  EXPECT_FALSE(s.dominant_energy.empty());
}

// A power law's elasticity is its exponent at any step: the two differences agree. A step in the output (a gear
// decided on a knife-edge) moves the +-1 % difference by the step's size over 2 % and the +-2 % one by half that.
// camry_2018's fuel elasticity to pressure read -0.23 at +-1 % and -0.11 at +-2 % on NEDC, where a sweep's slope
// is -0.01 (session 22's outside testing); the car is smooth there now and its figures pass the check.
TEST(SelectionSensitivity, AnElasticityThatIsNotASlopeIsSaid) {
  for (double a : {-0.5, -0.01, 0.0, 0.3}) {
    auto e = [&](double h) { return std::log(std::pow(1 + h, a) / std::pow(1 - h, a)) / std::log((1 + h) / (1 - h)); };
    EXPECT_TRUE(elasticities_agree(e(0.01), e(0.02))) << a;
  }
  const double jump = 0.006;  // 0.6 % more fuel above the knife-edge
  auto stepped = [&](double h) { return std::log(1 + jump) / std::log((1 + h) / (1 - h)); };
  EXPECT_FALSE(elasticities_agree(-0.01 + stepped(0.01), -0.01 + stepped(0.02)));

  const Sensitivity s = vehicle_sensitivity(vehicle("camry_2018"), tyre("nominal"), load_cycle("nedc"), 4000.0, 80 / 3.6);
  for (const auto& r : s.rows) {
    EXPECT_TRUE(r.energy_smooth) << r.name << ": " << *r.energy_elasticity << " against " << *r.energy_elasticity_double_step;
    if (r.parameter == TyreParameter::Pressure) EXPECT_NEAR(*r.energy_elasticity, -0.009, 0.003);
  }
  EXPECT_TRUE(sensitivity_warnings(s).empty()) << sensitivity_warnings(s).front();
  const Sensitivity overloaded = tyre_sensitivity(tyre("175-70R14"), 6500.0, 80 / 3.6);
  ASSERT_EQ(sensitivity_warnings(overloaded).size(), 1u);
  EXPECT_TRUE(has(sensitivity_warnings(overloaded)[0], "above the tyre's rated maximum 4903 N")) << sensitivity_warnings(overloaded)[0];
}

TEST(RegressLibrary, MissingVehicleNamesTheCase) {
  const auto dir = std::filesystem::temp_directory_path() / ("rollsim_test_sel_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const auto file = dir / "b.yaml";
  std::ofstream(file) << "cases:\n  - name: ghost-car\n    vehicle: no-such-car\n    tyre: nominal\n    cycle: nedc\n"
                         "    unit: kwh_per_10km\n    expected: 1.6\n    tolerance_pct: 0.5\n";
  const Baseline b = load_baseline(file.string());
  try {
    run_baseline(b);
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_TRUE(has(e.what(), "ghost-car")) << e.what();
    EXPECT_TRUE(has(e.what(), "no-such-car")) << e.what();
  }
  std::filesystem::remove_all(dir);
}

// Session 20's outside testing: a case without `expected` was told its `tolerance_pct` might be a misspelling (every
// key not yet read was named), and a tyre not found did not say it had been looked for beside the baseline.
TEST(RegressLibrary, AMissingKeySuggestsOnlyKeysSpeltLikeItAndNotFoundSaysWhereItLooked) {
  const auto dir = std::filesystem::temp_directory_path() / ("rollsim_test_regress_keys_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string head = "cases:\n  - name: a\n    vehicle: ev\n    tyre: nominal\n    cycle: nedc\n    unit: kwh_per_10km\n";
  auto message = [&](const std::string& body) {
    std::ofstream(dir / "b.yaml") << head << body;
    try {
      run_baseline(load_baseline((dir / "b.yaml").string()));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string missing = message("    tolerance_pct: 0.5\n");
  EXPECT_TRUE(has(missing, "key 'cases[0].expected': required key is missing")) << missing;
  EXPECT_FALSE(has(missing, "tolerance_pct")) << missing;
  const std::string typo = message("    expcted: 1.6\n    tolerance_pct: 0.5\n");
  EXPECT_TRUE(has(typo, "required key is missing (misspelt as 'expcted'?)")) << typo;
  std::ofstream(dir / "b.yaml") << "cases:\n  - name: a\n    vehicle: ev\n    tyre: nosuch\n    cycle: nedc\n"
                                   "    unit: kwh_per_10km\n    expected: 1.6\n    tolerance_pct: 0.5\n";
  const Baseline b = load_baseline((dir / "b.yaml").string());
  try {
    run_baseline(b);
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_TRUE(has(e.what(), "file not found (looked in the referring file's folder " + dir.string() + ", the current folder and ")) << e.what();
  }
  std::filesystem::remove_all(dir);
}

// A case whose car cannot follow its cycle still guards its figure, but the outcome says it is a slower drive's
// (regress prints it under its table; session 14).
TEST(RegressLibrary, ACaseWhoseCarFellBehindSaysSo) {
  const auto dir = std::filesystem::temp_directory_path() / ("rollsim_test_regress_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "fast.csv") << "time_s,speed_kmh\n0,0\n30,200\n120,200\n160,0\n";
  const auto file = dir / "b.yaml";
  std::ofstream(file) << "cases:\n  - name: fast\n    vehicle: ev\n    tyre: nominal\n    cycle: " << (dir / "fast.csv").string()
                      << "\n    unit: kwh_per_10km\n    expected: 2.5\n    tolerance_pct: 50\n"
                         "  - name: nedc\n    vehicle: ev\n    tyre: nominal\n    cycle: nedc\n"
                         "    unit: kwh_per_10km\n    expected: 1.647\n    tolerance_pct: 0.5\n";
  const auto outcomes = run_baseline(load_baseline(file.string()));
  ASSERT_EQ(outcomes.size(), 2u);
  EXPECT_FALSE(outcomes[0].trace.followed);
  EXPECT_GT(units::mps_to_kmh(outcomes[0].trace.max_deficit_mps), 40.0);  // the motor allows 150 km/h (see above)
  EXPECT_TRUE(outcomes[1].trace.followed);
  std::filesystem::remove_all(dir);
}
