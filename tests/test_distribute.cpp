// Many small runs: replay in sweeps and comparisons against single runs, and the case distribution's contract.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "rollsim/common/distribute.hpp"
#include "rollsim/common/error.hpp"
#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/selection/compare.hpp"
#include "rollsim/selection/sweep.hpp"
#include "rollsim/sim/vehicle_run.hpp"

using namespace rollsim;
using namespace rollsim::selection;

namespace {

TyreSpec tyre(const std::string& name) { return load_tyre_file(resolve_data_file(name, "tyres", ".yaml", "test")); }
Vehicle vehicle(const std::string& name) { return load_vehicle_file(resolve_data_file(name, "vehicles", ".yaml", "test")); }

SweepOptions pressure_axis(double from, double to, int steps, bool replay) {
  SweepOptions o;
  o.axes.push_back({SweepParam::Pressure, from, to, steps});
  o.replay = replay;
  o.threads = 2;
  return o;
}

// The independent path: one car assembled from scratch with the tyre fitted, run as `rollsim simulate` runs it.
double single_run_kwh_per_10km(const Vehicle& car, const TyreSpec& t, const DriveCycle& cycle, bool replay) {
  return run_vehicle(car, t, cycle, replay, {}).result.aec_kwh_per_10km();
}

}  // namespace

TEST(SweepReplay, EveryPointEqualsASingleReplayOfTheSameTyre) {
  const Vehicle ev = vehicle("ev");
  const TyreSpec nominal = tyre("nominal");
  const DriveCycle wltc = load_cycle("wltc");
  const SweepResult r = sweep_vehicle(ev, nominal, wltc, pressure_axis(1.8, 3.2, 5, true));
  ASSERT_EQ(r.points.size(), 5u);
  for (const auto& p : r.points) {
    const TyreSpec t = with_parameter(nominal, SweepParam::Pressure, p.values[0]);
    // The sweep shares the car's powertrain and effects and remakes only its tyres: the same model, so the same
    // arithmetic to the last bit, not merely close.
    EXPECT_EQ(p.energy, single_run_kwh_per_10km(ev, t, wltc, true)) << "at " << p.values[0] << " bar";
  }
}

TEST(SweepReplay, AgreesWithTheForwardSweepWithinTheReadmesReplayTolerance) {
  // README, "Kinematic replay": forward and replay agree within 0.05 % on UDDS and WLTC.
  const Vehicle ev = vehicle("ev");
  const DriveCycle wltc = load_cycle("wltc");
  const SweepResult replay = sweep_vehicle(ev, tyre("nominal"), wltc, pressure_axis(1.8, 3.2, 3, true));
  const SweepResult forward = sweep_vehicle(ev, tyre("nominal"), wltc, pressure_axis(1.8, 3.2, 3, false));
  ASSERT_EQ(replay.points.size(), 3u);
  ASSERT_EQ(forward.points.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(replay.points[i].energy / forward.points[i].energy, 1.0, 5e-4);
    EXPECT_EQ(sweep_csv(replay).substr(0, 40), sweep_csv(forward).substr(0, 40));  // the same grid and header
  }
}

TEST(CompareReplay, EveryCandidateEqualsASingleReplayAndForwardAgreesWithin005Pct) {
  const Vehicle ev = vehicle("ev");
  const DriveCycle nedc = load_cycle("nedc");
  CompareOptions o;
  o.diameter_tolerance_pct = 10.0;
  o.replay = true;
  const std::vector<TyreSpec> candidates{tyre("low-rrc"), tyre("175-65R15")};
  const Comparison replay = compare_tyres(ev, candidates, nedc, o);
  o.replay = false;
  const Comparison forward = compare_tyres(ev, candidates, nedc, o);
  ASSERT_EQ(replay.ranked.size() + replay.unfit.size(), 3u);
  for (const auto& c : replay.ranked) {
    EXPECT_EQ(c.value, single_run_kwh_per_10km(ev, c.tyre, nedc, true)) << c.tyre.name;
    for (const auto& f : forward.ranked)
      if (f.tyre.name == c.tyre.name) EXPECT_NEAR(c.value / f.value, 1.0, 5e-4) << c.tyre.name;
  }
}

TEST(Distribute, LocalMapReturnsEveryCaseInOrderWhateverTheThreads) {
  for (unsigned threads : {1u, 2u, 7u}) {
    std::atomic<std::size_t> calls{0};
    std::size_t last_done = 0;
    const auto out = map_cases_locally(
        100, threads, [&](std::size_t k) { ++calls; return std::to_string(k * k); },
        [&](std::size_t d, std::size_t t) { EXPECT_EQ(t, 100u); last_done = std::max(last_done, d); });
    ASSERT_EQ(out.size(), 100u);
    for (std::size_t k = 0; k < 100; ++k) EXPECT_EQ(out[k], std::to_string(k * k));
    EXPECT_EQ(calls.load(), 100u);
    EXPECT_EQ(last_done, 100u);
  }
}

TEST(Distribute, AFailingCaseIsNamedAndIsTheLowestThatFailed) {
  const CaseBody body = [](std::size_t k) -> CaseBytes {
    if (k == 3 || k == 5) throw std::runtime_error("no solution at point " + std::to_string(k));
    return "ok";
  };
  try {
    map_cases_locally(8, 1, body, {});
    FAIL() << "no failure";
  } catch (const CaseFailure& e) {
    EXPECT_EQ(e.case_index(), 3u);
    EXPECT_STREQ(e.what(), "case 4 of 8 failed: no solution at point 3");
    EXPECT_FALSE(e.bad_input());
  }
  // A case that met bad input says so, for the program to report it as bad input (exit 2, its own message).
  try {
    map_cases_locally(4, 2, [](std::size_t k) -> CaseBytes {
      if (k == 2) throw InputError("fleet.csv: group 'b' (line 3)", "file 'x.csv' not found");
      return "ok";
    }, {});
    FAIL() << "no failure";
  } catch (const CaseFailure& e) {
    EXPECT_TRUE(e.bad_input());
    EXPECT_EQ(e.reason(), "fleet.csv: group 'b' (line 3): file 'x.csv' not found");
  }
}

TEST(Distribute, PlainRunIsOneProcessAndTheMapperMapsLocally) {
  if (launched_by_mpi()) GTEST_SKIP() << "the test binary itself runs under an MPI launcher";
  int argc = 1;
  char name[] = "rollsim_tests";
  char* args[] = {name, nullptr};
  char** argv = args;
  const ProcessGroup group(argc, argv);
  EXPECT_EQ(group.size(), 1);
  EXPECT_TRUE(group.is_root());
  const auto out = group.mapper()(5, 2, [](std::size_t k) { return std::string(k, 'x'); }, {});
  for (std::size_t k = 0; k < 5; ++k) EXPECT_EQ(out[k].size(), k);
  // ...and Open MPI is not in the process: it is a module loaded only under a launcher (linked, its six libraries
  // cost every plain run of the CLI about 6 ms, a third of a `rollsim tyre` query).
  std::ifstream maps("/proc/self/maps");
  std::string line;
  while (std::getline(maps, line)) EXPECT_EQ(line.find("libmpi"), std::string::npos) << line;
}

TEST(Distribute, PutAndTakeRoundTripValuesStringsAndVectorsExactly) {
  std::string bytes;
  const double third = 1.0 / 3.0;
  put(bytes, third);
  put(bytes, std::string("a,b\n\"c\""));
  put(bytes, std::vector<std::string>{"", "x"});
  put(bytes, std::vector<double>{NAN, -0.0, 1e300});
  std::string_view in = bytes;
  double d = 0;
  std::string s;
  std::vector<std::string> vs;
  std::vector<double> vd;
  take(in, d);
  take(in, s);
  take(in, vs);
  take(in, vd);
  EXPECT_EQ(d, third);
  EXPECT_EQ(s, "a,b\n\"c\"");
  EXPECT_EQ(vs, (std::vector<std::string>{"", "x"}));
  ASSERT_EQ(vd.size(), 3u);
  EXPECT_TRUE(std::isnan(vd[0]));
  EXPECT_TRUE(std::signbit(vd[1]));
  EXPECT_EQ(vd[2], 1e300);
  EXPECT_TRUE(in.empty());
  std::string_view short_in = std::string_view(bytes).substr(0, 4);
  EXPECT_THROW(take(short_in, d), std::logic_error);
}
