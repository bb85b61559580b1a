// rollsim validate: the fuel map's analytic limits, the transmission's energy balance, the EPA list's units and
// FTP weighting against the list's own published bags, hybrid rules, bad rows, and the held-out agreement.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <iostream>
#include <map>
#include <numbers>
#include <optional>
#include <utility>

#include "rollsim/common/error.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/powertrain/conventional.hpp"
#include "rollsim/powertrain/electric.hpp"
#include "rollsim/report/gnuplot.hpp"
#include "rollsim/sim/simulation.hpp"
#include "rollsim/validate/validate.hpp"
#include "test_support.hpp"

namespace rollsim {
namespace {

const std::string kList = std::string(ROLLSIM_SOURCE_DIR) + "/../shared/data/vehicles/epa_test_car_list_2022_part.csv";

EngineMapParams petrol_map() {
  EngineMapParams e;
  e.displacement_m3 = 2.0e-3;
  e.indicated_efficiency = 0.4;
  e.friction_mep0_pa = 0.97e5;
  e.friction_mep1_pa_s_per_rad = 143.0;
  e.friction_mep2_pa_s2_per_rad2 = 0.456;
  e.pumping_mep_closed_pa = 0.9e5;
  e.unthrottled_imep_pa = 11e5;
  e.enrichment_start_fraction = 0.9;
  e.enrichment_max = 0.15;
  e.idle_speed_radps = 73.3;
  e.rated_speed_radps = 628.3;
  e.max_speed_radps = 700.0;
  e.max_torque_nm = 200.0;
  e.max_power_w = 110e3;
  e.fuel_cut_min_speed_radps = 115.0;
  return e;
}

// A list with no row simulated exits 2 after printing its rows' skips (session 27); one with any exits 0.
int exit_for(const test::CmdResult& r) { return r.out.find("\"error_pct\": ") != std::string::npos ? 0 : 2; }

TEST(EngineMap, WithoutPumpingOrEnrichmentItIsAWillansLine) {
  EngineMapParams p = petrol_map();
  p.pumping_mep_closed_pa = 0.0;
  p.enrichment_max = 0.0;
  const EngineMap m(p);
  for (double w : {100.0, 250.0, 400.0}) {
    for (double t : {0.0, 50.0, 120.0}) {
      const double expected = (t * w + m.friction_power_w(w)) / p.indicated_efficiency;
      EXPECT_NEAR(m.fuel_power_w(w, t), expected, 1e-9 * expected) << w << " " << t;
    }
  }
}

TEST(EngineMap, PumpingVanishesAtTheUnthrottledLoadAndEnrichmentAtFullLoad) {
  const EngineMapParams p = petrol_map();
  const EngineMap m(p);
  const double w = 300.0;
  const double fmep = p.friction_mep0_pa + w * (p.friction_mep1_pa_s_per_rad + w * p.friction_mep2_pa_s2_per_rad2);
  const double four_pi = 4.0 * std::numbers::pi;
  // Brake torque at which the gross imep reaches the unthrottled one: no pumping there, continuous on both sides.
  const double t_wot = (p.unthrottled_imep_pa - fmep) * p.displacement_m3 / four_pi;
  const double willans_w = p.unthrottled_imep_pa * p.displacement_m3 * w / four_pi / p.indicated_efficiency;
  EXPECT_NEAR(m.fuel_power_w(w, t_wot), willans_w, 1e-6 * willans_w);
  EXPECT_NEAR(m.fuel_power_w(w, t_wot - 1e-6), m.fuel_power_w(w, t_wot + 1e-6), 1e-2);  // slope ~750 W/(N m)
  // At part load a step of torque costs what part_load_marginal_efficiency says (the pumping falls as it rises).
  const double step_nm = 1.0, step_fuel_w = m.fuel_power_w(w, 41.0) - m.fuel_power_w(w, 40.0);
  EXPECT_NEAR(step_nm * w / step_fuel_w, m.part_load_marginal_efficiency(), 1e-9);
  EXPECT_NEAR(m.part_load_marginal_efficiency(), p.indicated_efficiency * (1.0 + 0.9 / 11.0), 1e-12);
  // At light load the throttle costs fuel beyond the Willans line.
  EngineMapParams open = p;
  open.pumping_mep_closed_pa = 0.0;
  EXPECT_GT(m.fuel_power_w(w, 20.0), EngineMap(open).fuel_power_w(w, 20.0) * 1.05);
  // Full load is run 15 % rich.
  EngineMapParams lean = p;
  lean.enrichment_max = 0.0;
  const double full = m.max_torque_nm(w);
  EXPECT_NEAR(m.fuel_power_w(w, full) / EngineMap(lean).fuel_power_w(w, full), 1.15, 1e-12);
}

TEST(EngineMap, KnockRetardCostsEfficiencyFromItsStartToFullLoad) {
  EngineMapParams p = petrol_map();
  p.knock_start_fraction = 0.6;
  p.knock_efficiency_loss_max = 0.10;
  EngineMapParams clean = p;
  clean.knock_efficiency_loss_max = 0.0;
  const EngineMap m(p), c(clean);
  const double w = 300.0, full = m.max_torque_nm(w);
  // Below the start nothing; at full load the indicated efficiency is 10 % lower, so 1 / 0.9 the fuel; halfway
  // between start and full load half of it.
  EXPECT_DOUBLE_EQ(m.fuel_power_w(w, 0.5 * full), c.fuel_power_w(w, 0.5 * full));
  EXPECT_NEAR(m.fuel_power_w(w, full) / c.fuel_power_w(w, full), 1.0 / 0.9, 1e-12);
  EXPECT_NEAR(m.fuel_power_w(w, 0.8 * full) / c.fuel_power_w(w, 0.8 * full), 1.0 / 0.95, 1e-12);
}

// The idle controller's reserve is air and fuel for torque that is not delivered: at idle speed the map burns
// what it would for the load plus the reserve; off idle, nothing.
TEST(EngineMap, IdleTorqueReserveIsBurntAtIdleSpeedOnly) {
  EngineMapParams p = petrol_map();
  p.idle_torque_reserve_nm = 10.0;
  const EngineMap with(p), without(petrol_map());
  const double idle = p.idle_speed_radps;
  EXPECT_DOUBLE_EQ(with.fuel_power_w(idle, 0.0), without.fuel_power_w(idle, 10.0));
  EXPECT_DOUBLE_EQ(with.fuel_power_w(idle, 8.0), without.fuel_power_w(idle, 18.0));
  EXPECT_DOUBLE_EQ(with.fuel_power_w(1.5 * idle, 8.0), without.fuel_power_w(1.5 * idle, 8.0));
}

validate::EpaTestRow petrol_row(double litres, double hp) {
  validate::EpaTestRow row;
  row.fuel = validate::EpaFuel::petrol;
  row.transmission = validate::EpaTransmission::automatic;
  row.gears = 8;
  row.test_mass_kg = 1600.0;
  row.road_a_n = 150.0;
  row.road_b_n_s_per_m = 2.0;
  row.road_c_n_s2_per_m2 = 0.4;
  row.displacement_m3 = litres * 1e-3;
  row.rated_power_w = hp * 745.69987158;
  row.engine_radps_per_mps = 25.0 * units::kRadpsPerRpm / units::kMpsPerMph;  // 25 rpm/mph
  return row;
}

double indicated_efficiency_of(const validate::EpaTestRow& row) {
  const auto m = validate::car_from_row(row, validate::EpaDefaults{});
  return m.powertrain->engine_map()->params().indicated_efficiency;
}

// A boosted engine (high output per litre) runs a lower compression ratio: 13 up to 85 hp/l, 9 from 200 hp/l.
// The ideal Otto efficiency 1 - r^(1 - 1.3) gives 0.537 at 13 and 0.483 at 9: 0.900 of the reference.
TEST(EpaCar, BoostedEnginesLoseIndicatedEfficiencyWithTheirCompressionRatio) {
  const double reference = validate::EpaDefaults{}.petrol_indicated_efficiency;
  EXPECT_DOUBLE_EQ(indicated_efficiency_of(petrol_row(2.5, 200.0)), reference);  // 80 hp/l
  EXPECT_NEAR(indicated_efficiency_of(petrol_row(2.0, 420.0)) / reference, 0.900, 0.001);  // 210 hp/l
  const double mid = indicated_efficiency_of(petrol_row(2.0, 230.0)) / reference;  // 115 hp/l: ratio 10.5
  EXPECT_NEAR(mid, (1.0 - std::pow(10.5, -0.3)) / (1.0 - std::pow(13.0, -0.3)), 1e-9);
}

double shift_floor_rpm(validate::EpaTestRow row, double nv_rpm_per_mph) {
  row.engine_radps_per_mps = nv_rpm_per_mph * units::kRadpsPerRpm / units::kMpsPerMph;
  const auto m = validate::car_from_row(row, validate::EpaDefaults{});
  return dynamic_cast<const ConventionalPowertrain&>(*m.powertrain).params().transmission.min_engine_speed_radps / units::kRadpsPerRpm;
}

// The shift floor holds its source values (1100 rpm behind a converter, 1400 with a clutch) at and below the
// median gearing (25.7 rpm/mph) and rises as the fourth root of the N/V ratio above it: twice the median's N/V,
// 2^(1/4) = 1.189 times the floor.
TEST(EpaCar, ShiftFloorRisesWithShorterGearingOnly) {
  validate::EpaTestRow row = petrol_row(2.5, 200.0);
  EXPECT_NEAR(shift_floor_rpm(row, 18.0), 1100.0, 1e-9);
  EXPECT_NEAR(shift_floor_rpm(row, 25.7), 1100.0, 1e-9);
  EXPECT_NEAR(shift_floor_rpm(row, 51.4), 1100.0 * std::pow(2.0, 0.25), 1e-9);
  row.transmission = validate::EpaTransmission::clutch;
  row.gears = 6;
  EXPECT_NEAR(shift_floor_rpm(row, 20.0), 1400.0, 1e-9);
  EXPECT_NEAR(shift_floor_rpm(row, 51.4), 1400.0 * std::pow(2.0, 0.25), 1e-9);
}

// The engine's spin-up, worked by hand: 1/2 J (w1^2 - w0^2) with J = 0.2 kg m^2 on each rise under power (5 -> 10
// m/s in a gear of 20 rad per metre: +3000 J; after the upshift to 10, 12 -> 15 m/s: +810 J), given back only while
// the engine drives on in one gear (10 -> 9 m/s under power: -760 J), not at the upshift (-1800 J) nor braking; a
// downshift while coasting (100 -> 120 rad/s, +440 J) is paid by the wheels.
TEST(TransientFuel, EngineSpinUpFromTheTracesEngineSpeed) {
  SimulationResult s;
  s.fuel = FuelFigures{1e-3, 0.0};
  const double samples[][4] = {{5.0, 100.0, 1e4, 20.0}, {10.0, 200.0, 2e4, 20.0}, {9.0, 180.0, 5e3, 20.0}, {12.0, 120.0, 1e4, 10.0},
                               {15.0, 150.0, 1e4, 10.0}, {10.0, 100.0, 0.0, 10.0},  {6.0, 120.0, 0.0, 20.0}};
  for (const auto& x : samples) {
    TracePoint p{};
    p.speed_mps = x[0];
    p.machine_speed_radps = x[1];
    p.traction_power_w = x[2];
    p.gear_ratio = x[3];
    s.trace.push_back(p);
  }
  EXPECT_NEAR(validate::engine_spin_up_j(s, 0.2), 3000.0 - 760.0 + 810.0, 1e-9);
  // Behind a variator the ratio change under power gives its drop back too (-1800 J); braking still does not.
  EXPECT_NEAR(validate::engine_spin_up_j(s, 0.2, true), 3000.0 - 760.0 - 1800.0 + 810.0, 1e-9);
  validate::TransientFuelParams p;
  p.fuel_density_kg_per_m3 = 743.0;
  p.fuel_energy_j_per_m3 = 743.0 * 42.9e6;
  p.engine_inertia_kg_m2 = 0.2;
  p.marginal_efficiency = 0.4;
  EXPECT_NEAR(validate::fuel_with_transients_m3(s, p), 1e-3 + 3050.0 / 0.4 / p.fuel_energy_j_per_m3, 1e-15);
  p.fuel_energy_j_per_m3 = 0.0;
  EXPECT_THROW(validate::fuel_with_transients_m3(s, p), ModelDomainError);
}

// The transient additions read the trace alone: rises of the segment fuel rate, and entries into cut-off.
TEST(TransientFuel, RisesAndCutOffsComeFromTheTrace) {
  SimulationResult s;
  s.fuel = FuelFigures{1e-3, 0.0};
  for (double rate : {1e-6, 3e-6, 0.0, 0.0, 2e-6, 0.0, 1e-6}) {
    TracePoint p{};
    p.segment_fuel_rate_m3_per_s = rate;
    s.trace.push_back(p);
  }
  const auto e = validate::fuel_events(s);
  EXPECT_NEAR(e.rises_m3_per_s, 2e-6 + 2e-6 + 1e-6, 1e-18);
  EXPECT_EQ(e.cut_offs, 2);
  validate::TransientFuelParams p;
  p.idle_fuel_m3_per_s = 0.3e-6;
  p.fuel_density_kg_per_m3 = 743.0;
  EXPECT_NEAR(validate::fuel_with_transients_m3(s, p), 1e-3 + 0.15 * 5e-6 + 2 * (1.5 * p.idle_fuel_m3_per_s + 0.3e-3 / 743.0), 1e-15);
}

ConventionalPowertrainParams car(TransmissionKind kind) {
  ConventionalPowertrainParams p;
  p.engine = petrol_map();
  p.transmission.kind = kind;
  p.transmission.ratios = kind == TransmissionKind::cvt ? std::vector<double>{17.0, 2.4} : std::vector<double>{15.0, 9.0, 6.0, 4.5, 3.5, 2.6};
  p.transmission.efficiency = 0.96;
  p.transmission.spin_loss_nm = 4.0;
  p.transmission.min_engine_speed_radps = 131.0;
  p.transmission.max_torque_fraction = 0.75;
  p.transmission.converter.k_factor_radps_per_sqrt_nm = 251.3 / std::sqrt(200.0);
  p.transmission.converter.lockup_min_gear = 2;
  p.transmission.converter.lockup_min_speed_radps = 104.7;
  p.fuel = {743.0, 42.9e6, 3.17};
  p.aux_power_w = 300.0;
  p.alternator_efficiency = 0.6;
  return p;
}

TEST(ConventionalPowertrain, EveryPointClosesItsEnergyBalance) {
  for (const auto kind : {TransmissionKind::automatic, TransmissionKind::cvt, TransmissionKind::clutch}) {
    const ConventionalPowertrain pt(car(kind));
    for (double v : {0.0, 1.0, 3.0, 8.0, 15.0, 30.0}) {
      for (double f : {-2000.0, 0.0, 100.0, 800.0, 3000.0}) {
        const PowerFlow p = pt.deliver(f, v, 0, 0.33);
        const double uses = p.engine_loss_w + p.traction_power_w + p.gearbox_loss_w + p.clutch_loss_w + p.aux_power_w;
        EXPECT_NEAR(p.fuel_power_w, uses, 1e-9 * std::max(1.0, p.fuel_power_w)) << static_cast<int>(kind) << " " << v << " " << f;
        EXPECT_GE(p.gearbox_loss_w, 0.0);
        EXPECT_GE(p.clutch_loss_w, -1e-9);
        EXPECT_GE(p.engine_loss_w, 0.0);
      }
    }
  }
}

TEST(ConventionalPowertrain, ConverterSlipsAtLaunchAndLocksUpAtSpeed) {
  const ConventionalPowertrain at(car(TransmissionKind::automatic));
  // Pulling away at 1 m/s the converter slips (engine above the turbine); cruising at 20 m/s it is locked.
  const PowerFlow launch = at.deliver(2500.0, 1.0, 0, 0.33);
  EXPECT_GT(launch.clutch_loss_w, 0.1 * launch.traction_power_w);
  const PowerFlow cruise = at.deliver(400.0, 20.0, 0, 0.33);
  EXPECT_NEAR(cruise.clutch_loss_w, 0.0, 1e-9);
  // Overrun above the cut-off speed burns nothing; standing still it idles.
  EXPECT_EQ(at.deliver(-500.0, 20.0, 0, 0.33).fuel_power_w, 0.0);
  EXPECT_GT(at.deliver(0.0, 0.0, 0, 0.33).fuel_power_w, 0.0);
  // Standing in Drive the stalled converter absorbs (w_idle / K)^2 at idle speed; a declutched manual does not.
  const PowerFlow stand = at.deliver(0.0, 0.0, 0, 0.33);
  const auto& p = at.params();
  const double q = p.engine.idle_speed_radps / p.transmission.converter.k_factor_radps_per_sqrt_nm;
  EXPECT_NEAR(stand.clutch_loss_w, q * q * p.engine.idle_speed_radps, 1e-9);
  EXPECT_EQ(ConventionalPowertrain(car(TransmissionKind::clutch)).deliver(0.0, 0.0, 0, 0.33).clutch_loss_w, 0.0);
}

// Deceleration fuel cut-off waits for the road speed it is enabled above (ALPHA: 5 m/s) even where the engine,
// locked up in second gear, turns above its own cut-off speed: at 4.9 m/s the 9:1 gear turns the engine at
// 134 rad/s (> 115), so without the road-speed condition the overrun would burn nothing.
TEST(ConventionalPowertrain, FuelCutOffWaitsForTheRoadSpeedItIsEnabledAbove) {
  auto p = car(TransmissionKind::automatic);
  EXPECT_EQ(ConventionalPowertrain(p).deliver(-500.0, 4.9, 0, 0.33).fuel_power_w, 0.0);
  p.engine.fuel_cut_min_vehicle_speed_mps = 5.0;
  const ConventionalPowertrain at(p);
  const PowerFlow slow = at.deliver(-500.0, 4.9, 0, 0.33);
  EXPECT_GT(slow.fuel_power_w, 0.0);  // it idles until the car stops
  EXPECT_EQ(slow.machine_speed_radps, p.engine.idle_speed_radps);
  EXPECT_EQ(at.deliver(-500.0, 5.1, 0, 0.33).fuel_power_w, 0.0);
}

// Neutral idle control: standing in Drive the converter does not load the engine, which idles as a declutched
// manual does; moving, nothing changes.
TEST(ConventionalPowertrain, NeutralIdleStandsWithoutTheConvertersLoad) {
  auto p = car(TransmissionKind::automatic);
  const ConventionalPowertrain loaded(p);
  p.transmission.converter.neutral_at_standstill = true;
  const ConventionalPowertrain neutral(p);
  const PowerFlow stand = neutral.deliver(0.0, 0.0, 0, 0.33);
  EXPECT_EQ(stand.clutch_loss_w, 0.0);
  EXPECT_NEAR(stand.fuel_power_w, ConventionalPowertrain(car(TransmissionKind::clutch)).deliver(0.0, 0.0, 0, 0.33).fuel_power_w, 1e-9);
  EXPECT_LT(stand.fuel_power_w, loaded.deliver(0.0, 0.0, 0, 0.33).fuel_power_w);
  EXPECT_EQ(neutral.deliver(800.0, 5.0, 0, 0.33).fuel_power_w, loaded.deliver(800.0, 5.0, 0, 0.33).fuel_power_w);
}

// A clutch pulls away with the engine at its launch speed, slipping: the slip is (launch - input speed) x torque,
// and the balance closes. Braking at the same speed it idles (no fuel cut-off at launch speed).
TEST(ConventionalPowertrain, ClutchLaunchHoldsTheEngineAtItsLaunchSpeed) {
  auto p = car(TransmissionKind::clutch);
  p.transmission.launch_engine_speed_radps = 140.0;
  const ConventionalPowertrain pt(p);
  const PowerFlow launch = pt.deliver(1500.0, 1.0, 0, 0.33);
  EXPECT_NEAR(launch.machine_speed_radps, 140.0, 1e-9);
  const double input_radps = 1.0 / 0.33 * p.transmission.ratios.front();
  EXPECT_NEAR(launch.clutch_loss_w, launch.machine_torque_nm * (140.0 - input_radps), 1e-6 * launch.clutch_loss_w);
  EXPECT_GT(launch.fuel_power_w, ConventionalPowertrain(car(TransmissionKind::clutch)).deliver(1500.0, 1.0, 0, 0.33).fuel_power_w);
  EXPECT_NEAR(pt.deliver(-500.0, 1.0, 0, 0.33).machine_speed_radps, p.engine.idle_speed_radps, 1e-9);
  EXPECT_GT(pt.deliver(-500.0, 1.0, 0, 0.33).fuel_power_w, 0.0);
}

// A powertrain with both capabilities (the shape of a hybrid): results carry both figures and one balance holds.
class BothSources final : public Powertrain {
 public:
  PowerFlow deliver(double f, double v, int, double) const override {
    PowerFlow p;
    p.wheel_force_n = f;
    if (f >= 0.0) {
      p.traction_power_w = f * v;
      p.battery_terminal_power_w = 0.5 * f * v;
      p.fuel_power_w = 0.5 * f * v / 0.3;
      p.engine_loss_w = p.fuel_power_w - 0.5 * f * v;
      p.fuel_rate_m3_per_s = p.fuel_power_w / (743.0 * 42.9e6);
    } else {
      p.friction_brake_power_w = -f * v;
    }
    return p;
  }
  int select_gear(double, int) const override { return 0; }
  double max_wheel_force_n(int, double, double) const override { return 1e9; }
  std::vector<double> shift_speeds_mps(int) const override { return {}; }
  const BatteryParams* battery() const override { return &battery_; }
  const FuelParams* fuel() const override { return &fuel_; }
  void add_electric_load(double w, PowerFlow& p) const override {
    p.aux_power_w += w;
    p.battery_terminal_power_w += w;
  }

 private:
  BatteryParams battery_{360.0, 0.1, 3.6e7, 0.8};
  FuelParams fuel_{743.0, 42.9e6, 3.17};
};

TEST(PowertrainCapabilities, ABatteryAndAFuelTogetherGiveBothFiguresAndOneBalance) {
  validate::EpaTestRow row;
  row.test_mass_kg = 1500.0;
  row.road_a_n = 150.0;
  row.road_b_n_s_per_m = 2.0;
  row.road_c_n_s2_per_m2 = 0.4;
  row.rated_power_w = 100e3;
  row.engine_radps_per_mps = 30.0;
  row.fuel = validate::EpaFuel::electricity;
  VehicleModel m = validate::car_from_row(row, validate::EpaDefaults{});
  m.powertrain = std::make_shared<BothSources>();
  const SimulationResult r = simulate_replay(m, load_cycle("udds"));
  ASSERT_TRUE(r.battery.has_value());
  ASSERT_TRUE(r.fuel.has_value());
  EXPECT_GT(r.fuel->volume_m3, 0.0);
  EXPECT_LT(r.battery->final_soc, r.battery->initial_soc);
  EXPECT_NEAR(r.energy.powertrain_residual_j(), 0.0, 1e-9 * r.source_energy_j());
  EXPECT_NEAR(r.energy.battery_terminal_j, 0.5 * r.energy.traction_j, 1e-6 * r.energy.traction_j);
}

validate::EpaTestRow electric_row(double rated_power_w) {
  validate::EpaTestRow row;
  row.fuel = validate::EpaFuel::electricity;
  row.test_mass_kg = 2000.0;
  row.road_a_n = 150.0;
  row.road_b_n_s_per_m = 2.0;
  row.road_c_n_s2_per_m2 = 0.4;
  row.rated_power_w = rated_power_w;
  row.engine_radps_per_mps = 40.0;
  return row;
}

// The machine's loss at a shaft power, motoring (+) or generating (-), through the powertrain validate builds.
double motor_loss_at(const VehicleModel& m, double shaft_power_w) {
  const auto& pt = dynamic_cast<const ElectricPowertrain&>(*m.powertrain);
  const double eta_red = pt.params().reduction.efficiency;
  const double v_mps = 20.0;
  // Braking: the machine takes its share of the braking force (blending), so ask for the force it must see.
  const double regen_share = pt.params().regen.driven_axle_brake_fraction;
  const double wheel_force_n = shaft_power_w > 0.0 ? shaft_power_w * eta_red / v_mps : shaft_power_w / (eta_red * v_mps * regen_share);
  return pt.deliver(wheel_force_n, v_mps, 0, m.wheel_radius_m).motor_loss_w;
}

// validate's electric machine is FASTSim's default: efficiency against the fraction of peak output power, as in
// FASTSim's BEV files (mcEffMap 0.84 0.86 0.88 0.90 0.91 0.92 0.94 0.95 0.95 0.94 0.93 at 0 2 4 6 8 10 20 40 60 80
// 100 %), and for small machines blended towards its small-motor curve (0.42 at 10 %, weight 1 at 7.5 kW, 0 at 75).
TEST(EpaCar, ElectricMachineLosesWhatFastsimsDefaultCurveGives) {
  const VehicleModel m = validate::car_from_row(electric_row(255e3), validate::EpaDefaults{});
  for (auto [fraction, eta] : {std::pair{0.10, 0.92}, std::pair{0.40, 0.95}, std::pair{0.03, 0.87}, std::pair{0.90, 0.935}}) {
    const double p_w = fraction * 255e3;
    EXPECT_NEAR(motor_loss_at(m, p_w), p_w * (1.0 / eta - 1.0), 1e-6 * p_w) << fraction;  // motoring: P / eta - P
    EXPECT_NEAR(motor_loss_at(m, -p_w), p_w * (1.0 - eta), 1e-6 * p_w) << fraction;       // generating: P - eta P
  }
  // Half-way between 7.5 and 75 kW: the mean of the two curves at 10 %, (0.92 + 0.42) / 2.
  const VehicleModel small = validate::car_from_row(electric_row(41.25e3), validate::EpaDefaults{});
  EXPECT_NEAR(motor_loss_at(small, 4.125e3), 4.125e3 * (1.0 / 0.67 - 1.0), 1e-3);
}

TEST(ElectricPowertrain, RejectsAnEfficiencyCurveThatIsNotARisingFractionWithEfficienciesUpToOne) {
  ElectricPowertrainParams p;
  p.motor.max_power_w = 100e3;
  p.motor.losses.output_fraction = {0.0, 1.0};
  p.motor.losses.efficiency = {0.9, 0.95};
  EXPECT_NO_THROW(ElectricPowertrain{p});
  p.motor.losses.efficiency = {0.9, 1.05};
  EXPECT_THROW(ElectricPowertrain{p}, ModelDomainError);
  p.motor.losses.efficiency = {0.9};
  EXPECT_THROW(ElectricPowertrain{p}, ModelDomainError);
  p.motor.losses.output_fraction = {0.0, 0.5};
  p.motor.losses.efficiency = {0.9, 0.95};
  EXPECT_THROW(ElectricPowertrain{p}, ModelDomainError);
}

TEST(EpaList, ReadsUnitsAsPublished) {
  const auto rows = validate::read_epa_test_car_list(kList);
  ASSERT_EQ(rows.size(), 3114u);
  // First row: Aston Martin DBS, 4500 lb, A 40.94 lbf, B 0.0169 lbf/mph, C 0.0271 lbf/mph^2, N/V 23.0, 715 hp.
  const auto& r = rows.front();
  EXPECT_EQ(r.make, "Aston Martin");
  EXPECT_EQ(r.cycle, validate::EpaCycle::ftp75);
  EXPECT_NEAR(*r.test_mass_kg, 4500 * 0.45359237, 1e-9);
  EXPECT_NEAR(*r.road_a_n, 40.94 * 4.4482216152605, 1e-9);
  EXPECT_NEAR(*r.road_b_n_s_per_m, 0.0169 * 4.4482216152605 / 0.44704, 1e-9);
  EXPECT_NEAR(*r.road_c_n_s2_per_m2, 0.0271 * 4.4482216152605 / (0.44704 * 0.44704), 1e-9);
  EXPECT_NEAR(*r.engine_radps_per_mps * 0.44704 * 60.0 / (2.0 * std::numbers::pi), 23.0, 1e-9);
  EXPECT_NEAR(*r.rated_power_w / 745.69987158, 715.0, 1e-9);
}

// An analytically derived row (the list's MCRX10070956, Grand Cherokee L 4X2 FTP, 24.3 mpg): the row's own
// 5000 lb, 26.4 rpm/mph and coefficients are its base test MCRX10068353's (23.7 mpg); the result is for the ADFE
// configuration, 4750 lb, 26.4 rpm/mph and 15.3 hp of road load at 50 mph.
TEST(EpaList, AnAnalyticallyDerivedRowIsTheConfigurationItsResultIsFor) {
  const auto rows = validate::read_epa_test_car_list(kList);
  const auto it = std::find_if(rows.begin(), rows.end(), [](const auto& r) { return r.test_number == "MCRX10070956"; });
  ASSERT_NE(it, rows.end());
  ASSERT_TRUE(it->derived);
  EXPECT_EQ(it->derived->base_test, "MCRX10068353");
  EXPECT_NEAR(*it->test_mass_kg, 5000 * 0.45359237, 1e-9);
  const auto c = validate::result_configuration(*it);
  EXPECT_NEAR(*c.test_mass_kg, 4750 * 0.45359237, 1e-9);
  EXPECT_NEAR(*c.engine_radps_per_mps * 0.44704 * 60.0 / (2.0 * std::numbers::pi), 26.4, 1e-9);
  const double v = 50 * 0.44704;
  auto power_hp = [v](const validate::EpaTestRow& r) {
    return (*r.road_a_n + v * (*r.road_b_n_s_per_m + v * *r.road_c_n_s2_per_m2)) * v / 745.69987158;
  };
  EXPECT_NEAR(power_hp(c), 15.3, 1e-9);
  // The tested curve's shape is kept: (36.39 + 50 x 0.1536 + 2500 x 0.02955) lbf at 50 mph is 15.73 hp.
  EXPECT_NEAR(power_hp(*it), 15.73, 0.01);
  EXPECT_NEAR(*c.road_b_n_s_per_m / *c.road_a_n, *it->road_b_n_s_per_m / *it->road_a_n, 1e-12);
  const auto car = validate::car_from_row(*it, validate::EpaDefaults{});
  EXPECT_NEAR(car.mass_kg, 4750 * 0.45359237, 1e-9);
  // A measured row is its own configuration; a derived row without its ADFE weight is skipped naming the column.
  EXPECT_FALSE(rows.front().derived);
  EXPECT_NEAR(*validate::result_configuration(rows.front()).test_mass_kg, *rows.front().test_mass_kg, 0.0);
  auto broken = *it;
  broken.derived->test_mass_kg.reset();
  std::string detail;
  EXPECT_EQ(validate::check_car_fields(broken, detail), validate::SkipReason::missing_field);
  EXPECT_NE(detail.find("ADFE Equiv. Test Weight"), std::string::npos) << detail;
  broken = *it;
  broken.derived->road_load_power_w = 0.0;
  EXPECT_EQ(validate::check_car_fields(broken, detail), validate::SkipReason::absurd_field);
  // The ADFE field itself, not the scaled curve's "target C = 0" (session 22's outside testing).
  EXPECT_NE(detail.find("ADFE Total Road Load HP = 0 (allowed more than 0 hp)"), std::string::npos) << detail;
}

// The regulation's weighting reproduces the list's own composite from its own bags (UDDS bag distances from the
// shipped trace). The published composite uses each test's measured distances and carbon balance, so agreement is
// to a fraction of a per cent, not exact; a 0.5/0.5 weighting would shift the median by about 1 %.
// The UDDS's bag 1 (0-505 s) and bag 2 distances [mile], trapezoids of the shipped trace.
std::pair<double, double> udds_bag_miles() {
  const DriveCycle udds = load_cycle("udds");
  double d1 = 0.0, d2 = 0.0;
  for (std::size_t i = 0; i + 1 < udds.time_s.size(); ++i) {
    const double d = 0.5 * (udds.speed_mps[i] + udds.speed_mps[i + 1]) * (udds.time_s[i + 1] - udds.time_s[i]) / 1609.344;
    (udds.time_s[i] < 505.0 ? d1 : d2) += d;
  }
  return {d1, d2};
}

TEST(EpaList, FtpWeightingReproducesThePublishedCompositeFromTheBags) {
  const auto rows = validate::read_epa_test_car_list(kList);
  const auto [d1, d2] = udds_bag_miles();
  std::vector<double> dev;
  for (const auto& r : rows) {
    if (r.cycle != validate::EpaCycle::ftp75 || r.fuel != validate::EpaFuel::petrol || !r.measured || *r.measured <= 0.0) continue;
    if (!r.bag_mpg[0] || !r.bag_mpg[1] || !r.bag_mpg[2] || *r.bag_mpg[0] <= 0.0 || *r.bag_mpg[1] <= 0.0 || *r.bag_mpg[2] <= 0.0) continue;
    if (r.bag4_mpg && *r.bag4_mpg > 0.0) continue;  // a four-bag (hybrid) FTP is weighted otherwise
    const double mpg = validate::ftp75_weighted_mpg(d1 / *r.bag_mpg[0], d2 / *r.bag_mpg[1], d1 / *r.bag_mpg[2], d1, d2);
    dev.push_back(mpg / *r.measured - 1.0);
  }
  ASSERT_GT(dev.size(), 500u);
  std::vector<double> abs_dev;
  for (double d : dev) abs_dev.push_back(std::abs(d));
  std::sort(abs_dev.begin(), abs_dev.end());
  const double within_1pct = static_cast<double>(std::upper_bound(abs_dev.begin(), abs_dev.end(), 0.01) - abs_dev.begin()) /
                             static_cast<double>(abs_dev.size());
  std::nth_element(dev.begin(), dev.begin() + static_cast<std::ptrdiff_t>(dev.size() / 2), dev.end());
  // The README's figures (session 24's outside testing recomputed them on the three-bag FTPs alone).
  std::printf("three-bag petrol FTPs: %zu, median deviation %+.3f %%, %.1f %% within 1 %%\n", dev.size(),
              100.0 * dev[dev.size() / 2], 100.0 * within_1pct);
  EXPECT_LT(std::abs(dev[dev.size() / 2]), 0.001);
  EXPECT_GT(within_1pct, 0.95);
}

// Pearson's correlation of two equally long samples.
double pearson(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = static_cast<double>(x.size());
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) mx += x[i] / n, my += y[i] / n;
  double sxy = 0.0, sxx = 0.0, syy = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
    syy += (y[i] - my) * (y[i] - my);
  }
  return sxy / std::sqrt(sxx * syy);
}

// The whole list once (a few seconds of CPU): skips by name, the split, and the held-out agreement.
TEST(EpaList, WholeListSkipsByNameAndAgreesAsReportedOnTheHeldOutHalf) {
  const auto rows = validate::read_epa_test_car_list(kList);
  const auto v = validate::validate_epa_list(rows, 2);
  int hybrids = 0, absurd = 0, kwh_rows = 0;
  for (const auto& o : v.rows) {
    EXPECT_FALSE(o.nominal_constants) << o.row->line;  // the whole list fits every constant it predicts with
    const std::string m = o.row->model;
    if (m.find("HYBRID") != std::string::npos || m.find("FHEV") != std::string::npos || m.find("PHEV") != std::string::npos) {
      const bool other_reason = o.row->cycle == validate::EpaCycle::sc03 || o.row->cycle == validate::EpaCycle::cold;
      if (!other_reason) {
        EXPECT_EQ(o.skip, validate::SkipReason::hybrid) << m;
        ++hybrids;
      }
    }
    // The list's RC F FTP of 4599 "mpg" and McLaren Artura's 9999.9: named, not simulated.
    if (o.row->measured && *o.row->measured > 1000.0 && o.row->cycle == validate::EpaCycle::ftp75) {
      EXPECT_EQ(o.skip, validate::SkipReason::absurd_measured_result) << m;
      ++absurd;
    }
    if (o.row->cycle == validate::EpaCycle::sc03) EXPECT_EQ(o.skip, validate::SkipReason::air_conditioning_test);
    // Electric rows of 8-60 "MPG" are read as kWh per 100 miles, unless the same vehicle's other results are in
    // MPGe: the EQS 450+ reads 138 on the UDDS and 38.1 on the highway (88.5 MPGe if read so), so it is skipped.
    if (o.measured_from_kwh_per_100mi && o.skip == validate::SkipReason::none) ++kwh_rows;
    if (o.row->test_number == "NMBX10071481") EXPECT_EQ(o.skip, validate::SkipReason::absurd_measured_result);
    // Lexus's hybrids say so only by an h after the number.
    if ((m == "LC 500h" || m == "ES 300h") && o.row->cycle != validate::EpaCycle::sc03 && o.row->cycle != validate::EpaCycle::cold)
      EXPECT_EQ(o.skip, validate::SkipReason::hybrid) << m;
    if (o.skip == validate::SkipReason::none) {
      EXPECT_TRUE(std::isfinite(o.predicted) && o.predicted > 0.0) << o.row->test_number;
    }
  }
  EXPECT_GT(hybrids, 10);
  EXPECT_GE(absurd, 1);
  // Outside testing (session 19) found three things in the list that no name says:
  // - A test is repeated on one line per aftertreatment device (80 tests, 119 extra lines, most of them diesel):
  //   each counts once, and the repeats name the line that counts.
  std::map<std::string, int> counted;
  for (const auto& o : v.rows) {
    if (o.repeat_of_line == 0) {
      ++counted[o.row->test_number];
    } else {
      EXPECT_NE(o.skip, validate::SkipReason::none) << o.row->test_number;
      EXPECT_LT(o.repeat_of_line, o.row->line);
    }
  }
  for (const auto& [test, n] : counted) EXPECT_EQ(n, 1) << test;
  EXPECT_EQ(v.rows.size() - counted.size(), 119u);
  // - An FTP run with four bags (FE Bag 4 given) is the hybrids' procedure (SAE J1711, 40 CFR 600.115-11(c)), and
  //   the 48 V mild hybrids that no name flags are tested so: BMW's M340i, Mercedes' E 450, Volvo's B5. Every
  //   liquid-fuel test of such a vehicle is skipped as a hybrid.
  int four_bag = 0;
  for (const auto& o : v.rows) {
    const bool other_reason = o.row->cycle == validate::EpaCycle::sc03 || o.row->cycle == validate::EpaCycle::cold ||
                              o.row->fuel == validate::EpaFuel::electricity;
    if (o.row->bag4_mpg && *o.row->bag4_mpg > 0.0 && !other_reason) {
      EXPECT_EQ(o.skip, validate::SkipReason::hybrid) << o.row->test_number << " " << o.row->model;
      ++four_bag;
    }
    for (const char* mild : {"M340i xDrive", "E 450 4MATIC", "XC60 B5"}) {
      if (o.row->model == mild && !other_reason) EXPECT_EQ(o.skip, validate::SkipReason::hybrid) << o.row->test_number << " " << mild;
    }
  }
  EXPECT_GT(four_bag, 100);
  // - The Ferrari Portofino M's four results are 13.7 % below what their own HC, CO and CO2 give (40 CFR 600.113's
  //   carbon balance, which every other petrol row meets within a few per cent): not that test's results, skipped.
  int inconsistent = 0;
  for (const auto& o : v.rows) {
    if (o.skip != validate::SkipReason::inconsistent_result) continue;
    ++inconsistent;
    EXPECT_EQ(o.row->make, "Ferrari") << o.row->test_number << " " << o.skip_detail;
  }
  EXPECT_EQ(inconsistent, 4);
  EXPECT_EQ(kwh_rows, 16);  // Hyundai, Ford and Rivian: both cycles of each vehicle in the same unit
  // The split keeps every test of a model on one side.
  for (const auto& o : v.rows) EXPECT_EQ(o.fitting_half, validate::in_fitting_half(*o.row));

  // The FTP's predicted bags: their regulation weighting is the predicted composite, the cold bag 1 burns more than
  // the hot bag 3 on the same trace, and the cold-start excess fitted on the fitting half's bag 1 / bag 3 ratios
  // carries over to the held-out half's measured ratios (median within 2 %; 0.3 % at this commit).
  const auto [d1, d2] = udds_bag_miles();
  std::vector<double> cold_ratio;
  for (const auto& o : v.rows) {
    if (o.skip != validate::SkipReason::none || o.row->cycle != validate::EpaCycle::ftp75) continue;
    const double* p = o.predicted_bag_mpg;
    EXPECT_NEAR(validate::ftp75_weighted_mpg(d1 / p[0], d2 / p[1], d1 / p[2], d1, d2) / o.predicted, 1.0, 1e-3) << o.row->test_number;
    EXPECT_LT(p[0], p[2]) << o.row->test_number;
    const auto& m = o.row->bag_mpg;
    if (!o.fitting_half && o.powertrain == "petrol" && m[0] && m[2] && *m[0] > 0.0 && *m[2] > 0.0)
      cold_ratio.push_back((p[2] / p[0]) / (*m[2] / *m[0]));
  }
  ASSERT_GT(cold_ratio.size(), 300u);
  std::sort(cold_ratio.begin(), cold_ratio.end());
  EXPECT_NEAR(cold_ratio[cold_ratio.size() / 2], 1.0, 0.02);

  // Analytically derived rows against their base tests: EPA derived each result from the base test for another
  // weight, road load and N/V, so the model's predicted change between the two configurations must follow the
  // list's (an independent derivation: EPA's, from its own equations). Before the rows were read as their
  // configurations the model predicted no change at all; now it follows the list's change (median 1.7 %) at a
  // correlation of 0.98 with a median difference of 0.5 % over 251 pairs.
  std::map<std::pair<std::string, std::string>, const validate::RowOutcome*> by_test;
  for (const auto& o : v.rows) by_test[{o.row->test_number, o.row->procedure}] = &o;
  std::vector<double> model_change, listed_change, difference;
  for (const auto& o : v.rows) {
    if (!o.row->derived || o.skip != validate::SkipReason::none) continue;
    const auto base = by_test.find({o.row->derived->base_test, o.row->procedure});
    if (base == by_test.end() || base->second->skip != validate::SkipReason::none) continue;
    model_change.push_back(std::log(o.predicted / base->second->predicted));
    listed_change.push_back(std::log(o.measured / base->second->measured));
    difference.push_back(std::abs(model_change.back() - listed_change.back()));
  }
  ASSERT_GT(model_change.size(), 200u);
  EXPECT_GT(pearson(model_change, listed_change), 0.9);
  std::vector<double> listed_size;
  for (double c : listed_change) listed_size.push_back(std::abs(c));
  std::sort(difference.begin(), difference.end());
  std::sort(listed_size.begin(), listed_size.end());
  EXPECT_LT(difference[difference.size() / 2], 0.5 * listed_size[listed_size.size() / 2]);

  // Judged on the half the constants were not fitted on (README, "Validation"). The targets where they
  // are met (petrol HWFET and US06: median |error| <= 5 %, 90th percentile <= 12 %; electric highway <= 6 % and <= 12 %); elsewhere
  // what the model does today, as a floor that catches a regression (README says what is not met).
  const auto c = validate::coverage(v, false);
  EXPECT_GE(c.simulated, 0.8 * c.eligible);
  for (const auto& s : validate::summarise(v)) {
    if (s.half != "held-out" || s.count < 30) continue;
    if (s.powertrain == "petrol" && s.cycle == "HWFET") {
      EXPECT_LE(s.physics.median_abs_error_pct, 5.0);
      EXPECT_LE(s.physics.p90_abs_error_pct, 12.0);
    }
    if (s.powertrain == "petrol" && s.cycle == "US06") {
      EXPECT_LE(s.physics.median_abs_error_pct, 5.0);
      EXPECT_LE(s.physics.p90_abs_error_pct, 12.0);
    }
    if (s.powertrain == "petrol") EXPECT_LT(s.physics.median_abs_error_pct, 7.0) << s.cycle;
    if (s.powertrain == "electric" && s.cycle == "CD HWFET") {
      EXPECT_LE(s.physics.median_abs_error_pct, 6.0);
      EXPECT_LE(s.physics.p90_abs_error_pct, 12.0);
    }
    if (s.powertrain == "electric") EXPECT_LT(s.physics.median_abs_error_pct, 8.0) << s.cycle;
  }
  // The maker calibration (README, "The maker calibration"), judged on models it never saw: on the held-out half as
  // split it meets every target the physics alone misses (at this commit petrol FTP-75 4.6 / 11.0 %, electric CD
  // UDDS 1.9 / 10.4 %) and keeps those it meets. Many of those models are trims of nameplates the fitting half
  // holds; for a new nameplate it does not meet them (scripts/validate-nameplates, README). It leaves the physics'
  // prediction as it was, and a fitting row's factor is learned without its own model.
  for (const auto& s : validate::summarise(v)) {
    if (s.half != "held-out" || s.count < 30) continue;
    const bool petrol = s.powertrain == "petrol", electric = s.powertrain == "electric";
    if (!petrol && !electric) continue;
    EXPECT_LE(s.maker_calibrated.median_abs_error_pct, petrol ? 5.0 : 6.0) << s.powertrain << " " << s.cycle;
    EXPECT_LE(s.maker_calibrated.p90_abs_error_pct, 12.0) << s.powertrain << " " << s.cycle;
  }
  for (const auto& o : v.rows) {
    if (o.skip != validate::SkipReason::none) continue;
    const auto own_model = o.fitting_half ? std::optional<std::string>(o.row->model) : std::nullopt;
    EXPECT_EQ(o.maker_factor, v.maker_calibration.factor(o.row->fuel, o.row->cycle, o.row->make, own_model)) << o.row->test_number;
  }

  // The fitted constants stay physical: gross indicated efficiency 0.3-0.5, charge efficiency below 1.
  EXPECT_GT(v.fitted.defaults.petrol_indicated_efficiency, 0.3);
  EXPECT_LT(v.fitted.defaults.petrol_indicated_efficiency, 0.5);
  EXPECT_LT(v.fitted.defaults.charge_efficiency, 1.0);
}

// Issue 13, item 5: the Camry built from its own EPA row (2022 XLE, 203 hp, 3625 lb: the Argonne car's generation)
// with the same maps, on the Argonne D3 traces and their measured fuel flow. The model enters fuel cut-off about
// as often as the car's fuel flow drops to zero; the errors after one calibrated scale are printed for the
// README (they do not meet the 3 %; see there).
TEST(CamryArgonne, CutOffEntriesMatchTheMeasuredFuelFlow) {
  const auto rows = validate::read_epa_test_car_list(std::string(ROLLSIM_SOURCE_DIR) + "/../shared/data/vehicles/epa_2022_toyota_camry.csv");
  const validate::EpaTestRow* row = nullptr;
  for (const auto& r : rows) {
    if (r.model == "CAMRY XLE/XSE" && r.cycle == validate::EpaCycle::ftp75 && std::abs(*r.test_mass_kg - 3625 * 0.45359237) < 1.0) row = &r;
  }
  ASSERT_NE(row, nullptr);
  const VehicleModel car = validate::car_from_row(*row, validate::EpaDefaults{});
  SimulationOptions traced;
  traced.record_trace = true;
  const std::string dir = std::string(ROLLSIM_SOURCE_DIR) + "/../shared/data/recordings/anl_d3_2018_toyota_camry/";
  double measured_sum = 0.0, predicted_sum = 0.0;
  std::vector<std::pair<double, double>> fuel;  // measured, predicted [m3]
  for (const char* file : {"61811012_test_data.csv", "61811013_test_data.csv", "61811014_test_data.csv"}) {
    std::ifstream in(dir + file);
    std::string line;
    std::getline(in, line);  // Time[s],Eng_FuelFlow_Direct_DI[ccps],Dyno_Spd[mph]
    DriveCycle c;
    c.name = file;
    double measured_m3 = 0.0, last_cm3_per_s = 0.0;
    int measured_cut_offs = 0;
    while (std::getline(in, line)) {
      double t = 0.0, cm3_per_s = 0.0, mph = 0.0;
      if (std::sscanf(line.c_str(), "%lf,%lf,%lf", &t, &cm3_per_s, &mph) != 3 || (!c.time_s.empty() && t <= c.time_s.back())) continue;
      c.time_s.push_back(t);
      c.speed_mps.push_back(mph * 0.44704);
      c.grade.push_back(0.0);
      measured_m3 += cm3_per_s * 1e-6;  // 1 Hz samples
      if (mph > 1.0 && cm3_per_s <= 0.02 && last_cm3_per_s > 0.02) ++measured_cut_offs;
      last_cm3_per_s = cm3_per_s;
    }
    const SimulationResult s = simulate_replay(car, c, traced);
    const int model_cut_offs = validate::fuel_events(s).cut_offs;
    const double predicted_m3 = validate::fuel_with_transients_m3(s, validate::transient_fuel_params(car));
    std::cout << file << ": cut-off entries " << model_cut_offs << " (measured " << measured_cut_offs << ")\n";
    // Hot UDDS 67 against 63 measured, two HWFETs 34 against 28, two US06s 43 against 39: within a quarter.
    EXPECT_NEAR(model_cut_offs, measured_cut_offs, 0.25 * measured_cut_offs) << file;
    fuel.emplace_back(measured_m3, predicted_m3);
    measured_sum += measured_m3;
    predicted_sum += predicted_m3;
  }
  const double scale = measured_sum / predicted_sum;  // the Camry's own calibration: one scale on its fuel
  for (const auto& [measured, predicted] : fuel) {
    std::cout << "fuel " << measured * 1e6 << " cm3 measured, " << predicted * 1e6 << " predicted (" << 100.0 * (predicted / measured - 1.0)
              << " %), calibrated x" << scale << ": " << 100.0 * (scale * predicted / measured - 1.0) << " %\n";
  }
}

// The list's first `lines` lines (its header and lines - 1 rows) written to `to`.
std::filesystem::path first_lines_of_list(const std::filesystem::path& to, int lines) {
  std::ifstream in(kList);
  std::ofstream out(to);
  std::string line;
  for (int i = 0; i < lines && std::getline(in, line); ++i) out << line << "\n";
  return to;
}

TEST(CliValidate, JsonRowsAndANamedErrorForAFileWithoutTheColumns) {
  const auto dir = test::temp_dir();
  const auto bad = dir / "not_epa.csv";
  std::ofstream(bad) << "time_s,speed_kmh\n0,0\n";
  const auto r = test::run_rollsim("validate --epa-test-car-list " + bad.string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("not_epa.csv"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("Test Number"), std::string::npos) << r.err;
  // The list's header alone: a named error, not an empty summary.
  const auto header_only = dir / "header_only.csv";
  {
    std::ifstream in(kList);
    std::string line;
    std::getline(in, line);
    std::ofstream(header_only) << line << "\n";
  }
  const auto e = test::run_rollsim("validate --epa-test-car-list " + header_only.string());
  EXPECT_NE(e.exit_code, 0);
  EXPECT_NE(e.err.find("header_only.csv"), std::string::npos) << e.err;
  EXPECT_NE(e.err.find("no test rows"), std::string::npos) << e.err;
  EXPECT_TRUE(e.out.empty()) << e.out;
  // The list's first 40 rows: one JSON object per row, simulated or skipped.
  const auto part = first_lines_of_list(dir / "first_rows.csv", 41);
  const auto j = test::run_rollsim("validate --json --threads 2 --epa-test-car-list " + part.string());
  ASSERT_EQ(j.exit_code, 0) << j.err;
  const auto rows = test::lines(j.out);
  EXPECT_EQ(rows.size(), 40u);
  EXPECT_NE(rows.front().find("\"test_number\": \"KASX10055440\""), std::string::npos) << rows.front();
  EXPECT_NE(rows.front().find("\"error_pct\": "), std::string::npos);
  // An FTP row (the first is the Aston Martin DBS's) carries its three predicted bags; a HWFET row none.
  for (const char* key : {"\"predicted_bag1_mpg\": ", "\"predicted_bag2_mpg\": ", "\"predicted_bag3_mpg\": "}) {
    EXPECT_NE(rows.front().find(key), std::string::npos) << rows.front();
    EXPECT_EQ(rows[1].find(key), std::string::npos) << rows[1];
  }
  // Its summary: the first 40 rows hold petrol cars only, so the diesel and charge efficiencies are not fitted and
  // the summary says they are nominal instead of printing them as fitted on 0 rows.
  const auto s = test::run_rollsim("validate --threads 2 --epa-test-car-list " + part.string());
  ASSERT_EQ(s.exit_code, 0) << s.err;
  for (const char* constant : {"diesel ", "charge efficiency "}) {
    const auto at = s.out.find(constant);
    ASSERT_NE(at, std::string::npos) << s.out;
    EXPECT_EQ(s.out.find(" (nominal: no rows to fit it)", at), at + std::string(constant).size() + 5) << s.out;
  }
  EXPECT_EQ(s.out.find("(0 rows)"), std::string::npos) << s.out;
  // The list's first two rows are one model's, so one half has nothing to judge: it says so instead of "0 of 0
  // (0.0 %)" (session 13).
  const auto two = first_lines_of_list(dir / "first_two.csv", 3);
  const auto t = test::run_rollsim("validate --epa-test-car-list " + two.string());
  ASSERT_EQ(t.exit_code, 0) << t.err;
  EXPECT_NE(t.out.find("simulated 0 of 0 FTP-75, HWFET, US06 and charge-depleting rows (none in this half)"),
            std::string::npos) << t.out;
  // The list's third and fourth rows, the Aston Martin DBX's, are held out: with no fitting row there is no maker
  // calibration to learn, and the summary says so; every row keeps the physics' prediction.
  const auto held_out = dir / "held_out_only.csv";
  {
    std::ifstream in(kList);
    std::ofstream out(held_out);
    std::string line;
    for (int i = 0; i < 5 && std::getline(in, line); ++i) {
      if (i == 0 || i >= 3) out << line << "\n";
    }
  }
  const auto h = test::run_rollsim("validate --epa-test-car-list " + held_out.string());
  ASSERT_EQ(h.exit_code, 0) << h.err;
  EXPECT_NE(h.out.find("fitting: simulated 0 of 0"), std::string::npos) << h.out;
  EXPECT_NE(h.out.find("  none: the fitting half has no simulated row\n"), std::string::npos) << h.out;
  const auto hj = test::run_rollsim("validate --json --epa-test-car-list " + held_out.string());
  ASSERT_EQ(hj.exit_code, 0) << hj.err;
  for (const auto& row : test::lines(hj.out)) EXPECT_NE(row.find("\"maker_factor\": 1,"), std::string::npos) << row;
}

// A line of the list cut into its fields (a quoted field keeps its commas and quotes), and put back together.
std::vector<std::string> csv_fields(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (const char ch : line) {
    if (ch == '"') quoted = !quoted;
    if (ch == ',' && !quoted) out.emplace_back();
    else out.back() += ch;
  }
  return out;
}
std::string csv_join(const std::vector<std::string>& f) {
  std::string out;
  for (std::size_t i = 0; i < f.size(); ++i) out += (i ? "," : "") + f[i];
  return out;
}

// A car the row's power cannot drive round the cycle was predicted in silence (a Colorado ZR2 diesel, line 1021,
// set to 41 hp: 31.2 mpg on the US06 where its own 181 hp gives 21.2; session 21's outside testing). The dynamometer
// driver keeps within 2 mph, so the row is skipped, naming the shortfall; the list's own rows all drive their cycles.
TEST(CliValidate, ACarTooWeakForItsCycleIsSkippedNotPredicted) {
  const auto fields = csv_fields;
  std::ifstream in(kList);
  std::string header, line;
  std::getline(in, header);
  for (int n = 2; n <= 1021 && std::getline(in, line); ++n) {
  }
  std::vector<std::string> head = fields(header), row = fields(line);
  const auto hp = std::find(head.begin(), head.end(), "Rated Horsepower");
  ASSERT_NE(hp, head.end());
  ASSERT_EQ(row.size(), head.size());
  ASSERT_NE(line.find("COLORADO"), std::string::npos) << line;
  const std::size_t k = static_cast<std::size_t>(hp - head.begin());
  for (const std::string power : {std::string("181"), std::string("41")}) {
    row[k] = power;
    std::string joined;
    for (std::size_t i = 0; i < row.size(); ++i) joined += (i ? "," : "") + row[i];
    const auto file = test::temp_dir() / "weak_car.csv";
    std::ofstream(file) << header << "\n" << joined << "\n";
    const auto r = test::run_rollsim("validate --json --threads 1 --epa-test-car-list " + file.string());
    ASSERT_EQ(r.exit_code, exit_for(r)) << r.err;
    if (power == "181") {
      EXPECT_NE(r.out.find("\"error_pct\": "), std::string::npos) << r.out;
    } else {
      EXPECT_EQ(r.out.find("\"error_pct\": "), std::string::npos) << r.out;
      EXPECT_NE(r.out.find("cannot follow the cycle"), std::string::npos) << r.out;
      EXPECT_NE(r.out.find("% of the wheel work undelivered"), std::string::npos) << r.out;
    }
  }
}

// Fields the rules read, checked as the car's fields are (session 21's outside testing): an unknown drive was read
// as two-wheel drive, an FE_UNIT other than MPG as mpg, an unknown ADFE flag as "No", and a list without the FE Bag 4
// or exhaust columns switched the four-bag hybrid rule and the exhaust-carbon check off in silence.
TEST(CliValidate, TheFieldsTheRulesReadAreCheckedNotAssumed) {
  const auto fields = csv_fields;
  const auto join = csv_join;
  std::ifstream in(kList);
  std::string header, line;
  std::getline(in, header);
  std::getline(in, line);  // line 2: an Aston Martin DBS FTP, simulated
  const std::vector<std::string> head = fields(header), row = fields(line);
  auto at = [&](const std::string& name) { return static_cast<std::size_t>(std::find(head.begin(), head.end(), name) - head.begin()); };
  const auto file = test::temp_dir() / "fields.csv";
  auto run_with = [&](const std::string& column, const std::string& value) {
    std::vector<std::string> changed = row;
    changed.at(at(column)) = value;
    std::ofstream(file) << header << "\n" << join(changed) << "\n";
    return test::run_rollsim("validate --json --threads 1 --epa-test-car-list " + file.string());
  };
  const auto plain = run_with("FE_UNIT", "MPG");
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_NE(plain.out.find("\"error_pct\": "), std::string::npos) << plain.out;
  for (const auto& [column, value, said] :
       {std::tuple<std::string, std::string, std::string>{"Drive System Description", "Banana", "Drive System Description 'Banana'"},
        {"FE_UNIT", "gpm", "FE_UNIT 'gpm'"},
        {"Analytically Derived FE?", "maybe", "Analytically Derived FE? 'maybe'"},
        {"# of Gears", "100", "# of Gears of a stepped transmission = 100 (allowed 2-10)"},
        {"Tested Transmission Type", "CVT", "the list's Automatic, Semi-Automatic, Continuously Variable"},
        {"FE Bag 4", "n/a", "FE Bag 4 'n/a' is not a number"}}) {
    const auto r = run_with(column, value);
    ASSERT_EQ(r.exit_code, exit_for(r)) << r.err;
    EXPECT_EQ(r.out.find("\"error_pct\": "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(said), std::string::npos) << r.out;
  }
  for (const std::string column : {"FE Bag 4", "CO2 (g/mi)", "FE_UNIT"}) {
    std::vector<std::string> h = head, f = row;
    h.erase(h.begin() + static_cast<std::ptrdiff_t>(at(column)));
    f.erase(f.begin() + static_cast<std::ptrdiff_t>(at(column)));
    std::ofstream(file) << join(h) << "\n" << join(f) << "\n";
    const auto r = test::run_rollsim("validate --threads 1 --epa-test-car-list " + file.string());
    EXPECT_EQ(r.exit_code, 2) << column;
    EXPECT_NE(r.err.find("no column '" + column + "'"), std::string::npos) << r.err;
  }
}

// The hybrid name rule reads whole words ("DBX CHEV" was a HEV and "DBX PRIMEVAL" a PRIME), and an electric "60 MPG"
// is read as kWh per 100 miles as 59.9 is (it was taken as 60 MPGe and predicted +154 %); session 21.
// A flex-fuel car's E85 highway economy against its petrol city economy read as a hybrid's: the rule compares the
// two on one fuel. Without its petrol HWFET line the Ford Transit RWD's three other tests were skipped as hybrids
// (E85 HWFET 20.3 < 1.1 x petrol FTP 18.6 mpg); on E85 alone it reads 20.3 / 13.9 (session 22's outside testing).
// And a bag 3 a car cannot have leaves the cold-start fit, as such a bag 1 does (a bag 3 of 0 moved it in silence).
TEST(CliValidate, TheHybridRuleComparesOneFuelAndTheColdFitImplausibleBags) {
  std::ifstream in(kList);
  std::string header, line, transit;
  std::getline(in, header);
  std::string first;
  std::getline(in, first);  // line 2: an Aston Martin DBS FTP, fitting half, simulated
  for (int n = 3; std::getline(in, line); ++n) {
    if (n >= 840 && n <= 842) transit += line + "\n";  // its petrol FTP and the E85 FTP and HWFET; line 843 left out
  }
  const auto file = test::temp_dir() / "transit.csv";
  std::ofstream(file) << header << "\n" << transit;
  const auto r = test::run_rollsim("validate --json --threads 1 --epa-test-car-list " + file.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.find("city economy as good as highway"), std::string::npos) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 3) << r.out;
  EXPECT_NE(r.out.find("\"error_pct\": "), std::string::npos) << r.out;

  const auto head = csv_fields(header);
  const auto bag3 = static_cast<std::size_t>(std::find(head.begin(), head.end(), "FE Bag 3") - head.begin());
  for (const std::string& bad : {"0", "-20.9", "999"}) {
    auto row = csv_fields(first);
    row.at(bag3) = bad;
    std::ofstream(file) << header << "\n" << csv_join(row) << "\n";
    const auto t = test::run_rollsim("validate --threads 1 --epa-test-car-list " + file.string());
    ASSERT_EQ(t.exit_code, 0) << t.err;
    EXPECT_NE(t.out.find("no FTPs' bag 1 vs bag 3 to fit it"), std::string::npos) << bad << ": " << t.out;
  }
  std::ofstream(file) << header << "\n" << first << "\n";
  const auto plain = test::run_rollsim("validate --threads 1 --epa-test-car-list " + file.string());
  EXPECT_NE(plain.out.find("(1 FTPs' bag 1 vs bag 3)"), std::string::npos) << plain.out;
}

TEST(CliValidate, NamesAreReadByWordAndSixtyIsInTheKwhRange) {
  std::ifstream in(kList);
  std::vector<std::string> lines_of_list;
  for (std::string line; std::getline(in, line) && lines_of_list.size() < 107;) lines_of_list.push_back(line);
  ASSERT_EQ(lines_of_list.size(), 107u);
  const std::string header = lines_of_list[0], dbx = lines_of_list[3], i4 = lines_of_list[106];
  ASSERT_NE(dbx.find(",DBX,"), std::string::npos) << dbx;
  ASSERT_NE(i4.find(",154.8,"), std::string::npos) << i4;
  const auto file = test::temp_dir() / "names.csv";
  auto run_rows = [&](const std::vector<std::string>& rows) {
    std::ofstream out(file);
    out << header << "\n";
    for (const auto& r : rows) out << r << "\n";
    out.close();
    return test::run_rollsim("validate --json --threads 1 --epa-test-car-list " + file.string());
  };
  for (const std::string name : {"DBX CHEV", "DBX PRIMEVAL", "DBX 4XE2"}) {
    std::string row = dbx;
    row.replace(row.find(",DBX,"), 5, "," + name + ",");
    const auto r = run_rows({row});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.out.find("hybrid"), std::string::npos) << name << ": " << r.out;
  }
  for (const std::string name : {"DBX HEV", "DBX PRIME", "DBX 4XE"}) {
    std::string row = dbx;
    row.replace(row.find(",DBX,"), 5, "," + name + ",");
    EXPECT_NE(run_rows({row}).out.find("named so"), std::string::npos) << name;
  }
  std::string sixty = i4;
  sixty.replace(sixty.find(",154.8,"), 7, ",60,");
  const auto r = run_rows({sixty});
  ASSERT_EQ(r.exit_code, exit_for(r)) << r.err;
  EXPECT_EQ(r.out.find("\"error_pct\": "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"skipped\": \"measured result outside any car of its kind"), std::string::npos) << r.out;
}

// Each series of the --plot figure holds its own powertrain's points: gnuplot's SVG puts a series' title and its
// points in one group. Until session 20 the data files were numbered by first appearance in the list and titled in
// alphabetical order, so the list's petrol cars were drawn under "E85 (mpg)" and its electric ones under "diesel".
TEST(CliValidate, ThePlotsSeriesAreTitledByTheirOwnPoints) {
  if (report::find_gnuplot().empty()) GTEST_SKIP() << "gnuplot not installed";
  const auto dir = test::temp_dir();
  const auto part = first_lines_of_list(dir / "petrol_and_electric.csv", 130);  // the BMW i4 rows are from line 107
  const auto svg = dir / "pred.svg";
  const auto r = test::run_rollsim("validate --json --threads 2 --epa-test-car-list " + part.string() + " --plot " + svg.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::map<std::string, int> expected;
  for (const auto& row : test::lines(r.out)) {
    if (row.find("\"error_pct\": ") == std::string::npos) continue;
    const auto fuel_at = row.find("\"fuel\": \"") + 9;
    const auto unit_at = row.find("\"unit\": \"") + 9;
    ++expected[row.substr(fuel_at, row.find('"', fuel_at) - fuel_at) + " (" + row.substr(unit_at, row.find('"', unit_at) - unit_at) + ")"];
  }
  ASSERT_GE(expected.size(), 2u);
  ASSERT_TRUE(expected.count("petrol (mpg)") && expected.count("electric (mpge)"));
  std::ifstream in(svg);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::map<std::string, int> drawn;
  for (std::size_t at = text.find("<g id=\"gnuplot_plot_"); at != std::string::npos;) {
    const std::size_t next = text.find("<g id=\"gnuplot_plot_", at + 1);
    const std::string group = text.substr(at, next == std::string::npos ? std::string::npos : next - at);
    const auto t0 = group.find("<text>"), t1 = group.find("</text>");
    if (t0 != std::string::npos && t1 != std::string::npos) {
      int points = 0;
      for (std::size_t p = group.find("<use xlink:href='#gpPt"); p != std::string::npos; p = group.find("<use xlink:href='#gpPt", p + 1)) ++points;
      drawn[group.substr(t0 + 6, t1 - t0 - 6)] = points;
    }
    at = next;
  }
  for (const auto& [title, n] : expected) {
    ASSERT_TRUE(drawn.count(title)) << title;
    // A series' key may carry one sample point beside its data.
    EXPECT_GE(drawn[title], n) << title;
    EXPECT_LE(drawn[title], n + 1) << title;
  }
}

// The list's first `n` lines (header first), for tests that edit a line.
std::vector<std::string> list_head(std::size_t n) {
  std::ifstream in(kList);
  std::vector<std::string> out;
  for (std::string line; out.size() < n && std::getline(in, line);) out.push_back(line);
  return out;
}

// Line `number` of the list (lines from list_head) with the named columns set to new text.
std::string list_line_with(const std::vector<std::string>& lines, std::size_t number,
                           const std::vector<std::pair<std::string, std::string>>& changes) {
  const auto head = csv_fields(lines.at(0));
  auto row = csv_fields(lines.at(number - 1));
  for (const auto& [column, value] : changes) {
    const auto at = std::find(head.begin(), head.end(), column);
    EXPECT_NE(at, head.end()) << column;
    if (at != head.end()) row.at(static_cast<std::size_t>(at - head.begin())) = value;
  }
  return csv_join(row);
}

// `validate` on the list's header and these lines: the JSON rows, or the summary.
test::CmdResult validate_lines(const std::vector<std::string>& lines, const std::vector<std::string>& rows,
                               const std::string& options = "--json --threads 1") {
  const auto file = test::temp_dir() / "edited_list.csv";
  std::ofstream out(file);
  out << lines.at(0) << "\n";
  for (const auto& r : rows) out << r << "\n";
  out.close();
  return test::run_rollsim("validate " + options + " --epa-test-car-list " + file.string());
}

bool simulated(const test::CmdResult& r) { return r.out.find("\"error_pct\": ") != std::string::npos; }

// A negative or unreadable THC, CO or CO2 switched the exhaust-carbon check off, and the row was simulated in silence
// (d_co2neg.csv, d_co2txt.csv); a negative FE Bag 4 was read as "no fourth bag" (d_bag4neg.csv). Session 22's
// outside testing. Each is now the row's skip, naming the column and the text; FE Bag 4 = 0 stays the list's "none".
// Line 2 of the list with one cell replaced is skipped, its reason starting with `said`.
void expect_line_2_skipped(const std::vector<std::string>& lines, const std::string& column, const std::string& value,
                           const std::string& said) {
  const auto r = validate_lines(lines, {list_line_with(lines, 2, {{column, value}})});
  ASSERT_EQ(r.exit_code, exit_for(r)) << r.err;
  EXPECT_FALSE(simulated(r)) << column << " " << value << ": " << r.out;
  EXPECT_NE(r.out.find("\"skipped\": \"" + said), std::string::npos) << column << " " << value << ": " << r.out;
}

TEST(CliValidate, AnUnusableExhaustOrFourthBagIsANamedSkipNotASilentRow) {
  const auto lines = list_head(2);  // line 2: an Aston Martin DBS FTP, simulated
  const auto plain = validate_lines(lines, {lines[1]});
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_TRUE(simulated(plain)) << plain.out;
  EXPECT_TRUE(simulated(validate_lines(lines, {list_line_with(lines, 2, {{"FE Bag 4", "0"}})})));
  for (const auto& [column, value, said] :
       {std::tuple<std::string, std::string, std::string>{"CO2 (g/mi)", "-499", "CO2 (g/mi) '-499' is negative, so the result cannot be checked against the row's exhaust carbon"},
        {"CO2 (g/mi)", "abc", "CO2 (g/mi) 'abc' is not a number, so the result cannot"},
        {"THC (g/mi)", "-0.04", "THC (g/mi) '-0.04' is negative"},
        {"CO (g/mi)", "n/a", "CO (g/mi) 'n/a' is not a number"},
        {"FE Bag 4", "-5", "its FTP's FE Bag 4 '-5' is negative, so whether it was run with four bags (a hybrid) is unknown"},
        // A zero CO2 had switched the check off as a blank does (session 24's outside testing).
        {"CO2 (g/mi)", "0", "CO2 (g/mi) 0 (an engine that burns fuel emits CO2), so the result cannot be checked"}}) {
    expect_line_2_skipped(lines, column, value, "field outside its physical range: " + said);
  }
}

// A list too small to fit a fuel's constant predicts it with the nominal one: said on stderr and in each row's JSON,
// where a one-maker list had read the Vantage V8 21 % low with nothing to say why. A header repeated inside the file
// (two lists joined) is an error naming its line, not a row skipped for its procedure (session 24's outside testing).
TEST(CliValidate, NominalConstantsAreSaidAndARepeatedHeaderIsNamed) {
  const auto lines = list_head(6);  // line 6: the Vantage V8's FTP, of the held-out half
  const auto r = validate_lines(lines, {lines[5]});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"constants\": \"nominal\""), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("warning: 1 simulated row(s) are predicted with nominal constants"), std::string::npos) << r.err;
  const auto summary = validate_lines(lines, {lines[5]}, "--threads 1");
  EXPECT_NE(summary.out.find("skipped: none"), std::string::npos) << summary.out;
  const auto joined = validate_lines(lines, {lines[5], lines[0]});
  EXPECT_EQ(joined.exit_code, 2) << joined.out;
  EXPECT_NE(joined.err.find("edited_list.csv: line 3: repeats the header (two lists joined?)"), std::string::npos) << joined.err;
}

// An electric row whose FE_UNIT says MPGe was refused with a message saying MPGe is allowed, and filed under "field
// outside its physical range" (d_mpge.csv; session 22's outside testing). SOURCES.md: an electric result is miles per
// gallon equivalent, so MPGe is read on an electric row, and as MPGe: its 8-60 is not taken for kWh per 100 miles.
TEST(CliValidate, AnElectricRowMayGiveMpgeAndAUnitIsNotAPhysicalRange) {
  const auto lines = list_head(107);  // line 107: a BMW i4 on the charge-depleting highway, 154.8
  const auto mpge = validate_lines(lines, {list_line_with(lines, 107, {{"FE_UNIT", "MPGe"}})});
  ASSERT_EQ(mpge.exit_code, 0) << mpge.err;
  EXPECT_TRUE(simulated(mpge)) << mpge.out;
  const auto thirty = validate_lines(lines, {list_line_with(lines, 107, {{"FE_UNIT", "MPGe"}, {"RND_ADJ_FE", "30"}})});
  EXPECT_NE(thirty.out.find("measured result outside any car of its kind: 30 mpge (allowed for an electric car: 60-250 mpge)"),
            std::string::npos) << thirty.out;
  const auto petrol = validate_lines(lines, {list_line_with(lines, 2, {{"FE_UNIT", "MPGe"}})});
  EXPECT_NE(petrol.out.find("\"skipped\": \"result in a unit not given for its fuel: FE_UNIT 'MPGe' on a petrol row (allowed: "
                            "MPG for petrol, diesel and E85 rows; MPG or MPGe for electric rows)"),
            std::string::npos) << petrol.out;
  const auto summary = validate_lines(lines, {list_line_with(lines, 2, {{"FE_UNIT", "gpm"}})}, "--threads 1");
  EXPECT_NE(summary.out.find("  1  result in a unit not given for its fuel\n"), std::string::npos) << summary.out;
  EXPECT_EQ(summary.out.find("physical range"), std::string::npos) << summary.out;
}

// A test number given again on another vehicle, or with another result, was "the same test as an earlier line
// (counted once)" (d_duptn.csv; session 22's outside testing). Only the list's own kind of repeat, the same vehicle
// and result on another aftertreatment line, is that test.
TEST(CliValidate, ARepeatedTestNumberIsTheSameTestOnlyWithTheSameVehicleAndResult) {
  const auto lines = list_head(4);  // lines 2 and 4: the DBS's and the DBX's FTPs
  const std::string dbs = lines[1], test_number = "KASX10055440";
  ASSERT_NE(dbs.find(test_number), std::string::npos) << dbs;
  const auto dbx = list_line_with(lines, 4, {{"Test Number", test_number}});
  const auto other_car = validate_lines(lines, {dbs, dbx});
  ASSERT_EQ(other_car.exit_code, 0) << other_car.err;
  const auto rows = test::lines(other_car.out);
  ASSERT_EQ(rows.size(), 2u) << other_car.out;
  EXPECT_TRUE(simulated(test::CmdResult{0, rows[0], ""})) << rows[0];
  EXPECT_NE(rows[1].find("\"skipped\": \"test number repeated with a different vehicle or result: line 2 gives test " + test_number +
                         " as Aston Martin DBS (7002PT7056) at 17.7 MPG, this line as Aston Martin DBX (8001PT8342) at 17.2 MPG"),
            std::string::npos) << rows[1];
  const auto other_result = validate_lines(lines, {dbs, list_line_with(lines, 2, {{"RND_ADJ_FE", "18.4"}})});
  EXPECT_NE(other_result.out.find("this line as Aston Martin DBS (7002PT7056) at 18.4 MPG"), std::string::npos) << other_result.out;
  const auto same = validate_lines(lines, {dbs, list_line_with(lines, 2, {{"Aftertreatment Device Desc", "Other"}})});
  EXPECT_NE(same.out.find("the same test as an earlier line (counted once): test " + test_number + " is line 2"), std::string::npos)
      << same.out;
}

// Skips that left out the value or what is allowed (session 22's outside testing: d_etwtxt.csv, d_fe177.csv, d_fuel.csv,
// d_adfehp0.csv, d_coefA.csv): each now quotes the text found, or gives the range, and names the field.
TEST(CliValidate, ASkipQuotesTheValueAndWhatIsAllowed) {
  const auto lines = list_head(341);
  for (const auto& [column, value, said] :
       {std::tuple<std::string, std::string, std::string>{"Equivalent Test Weight (lbs.)", "\"4,500\"", "missing or unreadable field: Equivalent Test Weight (lbs.) '4,500' is not a number"},
        {"Equivalent Test Weight (lbs.)", "abc", "missing or unreadable field: Equivalent Test Weight (lbs.) 'abc' is not a number"},
        {"RND_ADJ_FE", "abc", "no measured result: RND_ADJ_FE 'abc' is not a number"},
        {"RND_ADJ_FE", "inf", "no measured result: RND_ADJ_FE 'inf' is not a finite number"},
        {"RND_ADJ_FE", "", "no measured result: RND_ADJ_FE is empty"},
        {"RND_ADJ_FE", "177", "measured result outside any car of its kind: 177 mpg (allowed for a petrol, diesel or E85 car: 5-100 mpg)"},
        {"Test Fuel Type Description", "Kerosene", "fuel without properties here: Test Fuel Type Description 'Kerosene' (known: "},
        {"Target Coef A (lbf)", "-200", "field outside its physical range: target road load at 7.2 km/h [N] = "}}) {
    expect_line_2_skipped(lines, column, value, said);
  }
  const auto derived = validate_lines(lines, {list_line_with(lines, 341, {{"ADFE Total Road Load HP", "0"}})});
  ASSERT_EQ(derived.exit_code, exit_for(derived)) << derived.err;
  EXPECT_NE(derived.out.find("\"skipped\": \"field outside its physical range: ADFE Total Road Load HP = 0 (allowed more than 0 hp)"),
            std::string::npos) << derived.out;
}

// --threads 100000 was refused as "1e+05 is not allowed" (session 22's outside testing): said as typed.
TEST(CliValidate, AnOptionOutOfRangeIsSaidAsTyped) {
  const auto r = test::run_rollsim("validate --epa-test-car-list " + kList + " --threads 100000");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--threads: 100000 is not allowed"), std::string::npos) << r.err;
}

// The figure's title said "EPA Test Car List 2022" whatever the file's Model Year (d_y2023.csv; session 22's
// outside testing).
TEST(CliValidate, ThePlotsTitleGivesTheListsModelYears) {
  if (report::find_gnuplot().empty()) GTEST_SKIP() << "gnuplot not installed";
  const auto lines = list_head(4);
  const auto svg = test::temp_dir() / "years.svg";
  auto title_of = [&](const std::vector<std::string>& rows) {
    const auto r = validate_lines(lines, rows, "--threads 1 --plot " + svg.string());
    EXPECT_EQ(r.exit_code, 0) << r.err;
    std::ifstream in(svg);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto at = text.find("EPA Test Car List");
    return at == std::string::npos ? text : text.substr(at, text.find(':', at) - at);
  };
  EXPECT_EQ(title_of({list_line_with(lines, 2, {{"Model Year", "2023"}})}), "EPA Test Car List 2023");
  EXPECT_EQ(title_of({list_line_with(lines, 2, {{"Model Year", "2021"}}), list_line_with(lines, 4, {{"Model Year", "2023"}})}),
            "EPA Test Car List 2021-2023");
  EXPECT_EQ(title_of({list_line_with(lines, 2, {{"Model Year", ""}})}), "EPA Test Car List");
}

// A figure for a slide or a report: `--plot F.png` draws a PNG (it took only .svg, session 27's outside testing);
// other endings are refused naming the option.
TEST(CliValidate, ThePlotIsAPngWhereItsNameSaysSo) {
  if (report::find_gnuplot().empty()) GTEST_SKIP() << "gnuplot not installed";
  const auto lines = list_head(4);
  const auto png = test::temp_dir() / "figure.png";
  std::filesystem::remove(png);
  auto r = validate_lines(lines, {list_line_with(lines, 2, {})}, "--threads 1 --plot " + png.string());
  EXPECT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(png, std::ios::binary);
  std::string magic(8, '\0');
  in.read(magic.data(), 8);
  EXPECT_EQ(magic, std::string("\x89PNG\r\n\x1a\n", 8));
  r = validate_lines(lines, {list_line_with(lines, 2, {})}, "--threads 1 --plot " + (test::temp_dir() / "figure.pdf").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("must end in .svg or .png"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace rollsim
