// Drive cycles: published figures of every shipped cycle, the rebuilt NEDC, lookups and bad input.
#include <gtest/gtest.h>

#include "test_support.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <unistd.h>

#include "rollsim/common/error.hpp"
#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/sim/simulation.hpp"

namespace fs = std::filesystem;
using rollsim::DriveCycle;
using rollsim::InputError;
using rollsim::load_cycle;
using rollsim::load_vehicle_file;
using rollsim::simulate_forward;
using rollsim::VehicleModel;

namespace {

// A fresh folder per test for small bad-input files.
class DriveCycleFiles : public rollsim::test::FileFixture {
 protected:
  // Loads `text` as a cycle and returns the error message, failing the test if none is thrown.
  std::string error_of(const std::string& text) {
    const std::string path = write("bad.csv", text);
    try {
      load_cycle(path);
    } catch (const InputError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no InputError for:\n" << text;
    return "";
  }
};

double km(double m) { return m / 1000.0; }
double distance_between_m(const DriveCycle& c, double t0, double t1) {
  double s = 0.0;
  for (std::size_t i = 0; i + 1 < c.time_s.size(); ++i) {
    if (c.time_s[i] >= t0 && c.time_s[i + 1] <= t1) s += 0.5 * (c.speed_mps[i] + c.speed_mps[i + 1]) * (c.time_s[i + 1] - c.time_s[i]);
  }
  return s;
}
double max_kmh(const DriveCycle& c) {
  double m = 0.0;
  for (double v : c.speed_mps) m = std::max(m, v * 3.6);
  return m;
}

}  // namespace

// Published duration and integrated distance of each shipped trace (table of ../shared/data/cycles/SOURCES.md;
// WLTC and Artemis figures are also the regulation's / Artemis project's published ones).
TEST(DriveCycleShipped, PublishedDurationsAndDistances) {
  struct Row {
    const char* name;
    double duration_s, distance_km, max_kmh;
  };
  const Row rows[] = {
      {"wltc_class3b", 1800, 23.266, 131.3},    {"udds", 1369, 11.990, 91.25},
      {"ftp75", 1874, 17.769, 91.25},           {"hwfet", 765, 16.507, 96.40},
      {"us06", 600, 12.888, 129.23},            {"artemis_urban", 993, 4.870, 57.7},
      {"artemis_road", 1081, 17.273, 111.5},    {"artemis_motorway_150", 1067, 29.545, 150.4},
      {"artemis_motorway_130", 1067, 28.736, 131.8}, {"nedc_fastsim", 1179, 11.022, 120.0},
  };
  for (const auto& r : rows) {
    SCOPED_TRACE(r.name);
    const DriveCycle c = load_cycle(r.name);
    EXPECT_DOUBLE_EQ(c.duration_s(), r.duration_s);
    EXPECT_NEAR(km(c.distance_m()), r.distance_km, 0.0006);  // published to 1 m
    EXPECT_NEAR(max_kmh(c), r.max_kmh, 0.01);
    EXPECT_EQ(c.grade.size(), c.time_s.size());
    for (double g : c.grade) EXPECT_EQ(g, 0.0);
  }
}

TEST(DriveCycleShipped, WltcPhasesMatchGtr15AndAliasesWork) {
  const DriveCycle c = load_cycle("WLTC");  // alias, case-insensitive
  EXPECT_EQ(c.name, "wltc_class3b");
  // GTR 15 class 3b phase distances.
  EXPECT_NEAR(km(distance_between_m(c, 0, 589)), 3.095, 0.0006);
  EXPECT_NEAR(km(distance_between_m(c, 589, 1022)), 4.756, 0.0006);
  EXPECT_NEAR(km(distance_between_m(c, 1022, 1477)), 7.162, 0.0006);
  EXPECT_NEAR(km(distance_between_m(c, 1477, 1800)), 8.254, 0.0006);
  EXPECT_EQ(load_cycle("Us06").name, "us06");
  EXPECT_GE(rollsim::shipped_cycle_names().size(), 10u);
  for (const auto& n : rollsim::shipped_cycle_names()) EXPECT_NO_THROW(load_cycle(n)) << n;
}

// The rebuilt NEDC against the regulation's published figures.
TEST(DriveCycleNedc, RegulationFigures) {
  const DriveCycle c = load_cycle("nedc");
  EXPECT_EQ(c.time_s.size(), 1181u);
  EXPECT_DOUBLE_EQ(c.duration_s(), 1180.0);
  EXPECT_DOUBLE_EQ(max_kmh(c), 120.0);
  EXPECT_NEAR(km(c.distance_m()), 11.028, 0.0005);                 // SOURCES.md: regulation trace 11.028 km
  EXPECT_NEAR(km(c.distance_m()) / 1180.0 * 3600.0, 33.6, 0.05);  // published average speed
  EXPECT_NEAR(km(distance_between_m(c, 780, 1180)), 6.955, 0.0005);  // EUDC, regulation: 6.955 km
  // ECE-15: the regulation states 1.013 km per elementary cycle; the table integrates to 1.018 km (see
  // cycles/SOURCES.md, open point), so this holds it to within 0.6 %. The four repeats are identical.
  const double ece_km = km(distance_between_m(c, 0, 195));
  EXPECT_NEAR(ece_km, 1.013, 0.006);
  for (int k = 1; k < 4; ++k) EXPECT_NEAR(km(distance_between_m(c, 195 * k, 195 * (k + 1))), ece_km, 1e-12);
  // Operation checks from the table: 0-15 km/h in 4 s from t = 11 s (1.04 m/s^2), gear-change hold 54-56 s,
  // 120 -> 80 km/h over 1126-1142 s.
  EXPECT_NEAR(c.speed_mps_at(15.0) * 3.6, 15.0, 1e-9);
  EXPECT_NEAR(c.accel_mps2_at(12.5), 15.0 / 3.6 / 4.0, 1e-6);
  EXPECT_NEAR(c.speed_mps_at(55.0) * 3.6, 15.0, 1e-9);
  EXPECT_NEAR(c.speed_mps_at(1126.0) * 3.6, 120.0, 1e-9);
  EXPECT_NEAR(c.speed_mps_at(1142.0) * 3.6, 80.0, 1e-9);
  EXPECT_NEAR(c.speed_mps_at(1180.0), 0.0, 1e-12);
}

// SOURCES.md: FASTSim's NEDC differs from the regulation trace by at most 5 km/h, 0.48 km/h on average,
// and by more than 1 km/h during 228 s.
TEST(DriveCycleNedc, DiffersFromFastSimAsDocumented) {
  const DriveCycle reg = load_cycle("nedc");
  const DriveCycle fs = load_cycle("nedc_fastsim");
  ASSERT_EQ(fs.time_s.size(), 1180u);
  double max_diff = 0.0, sum = 0.0;
  int over_1 = 0;
  for (std::size_t i = 0; i < fs.time_s.size(); ++i) {
    const double d = std::abs(reg.speed_mps_at(fs.time_s[i]) - fs.speed_mps[i]) * 3.6;
    max_diff = std::max(max_diff, d);
    sum += d;
    over_1 += d > 1.0;
  }
  EXPECT_NEAR(max_diff, 5.0, 0.01);
  EXPECT_NEAR(sum / 1180.0, 0.48, 0.005);
  EXPECT_EQ(over_1, 228);
}

TEST(DriveCycleLookup, InterpolationAccelerationAndHints) {
  DriveCycle c;
  c.time_s = {0, 10, 20, 30};
  c.speed_mps = {0, 10, 10, 0};
  c.grade = {0, 0.02, 0.02, 0};
  EXPECT_DOUBLE_EQ(c.speed_mps_at(5.0), 5.0);
  EXPECT_DOUBLE_EQ(c.speed_mps_at(25.0), 5.0);
  EXPECT_DOUBLE_EQ(c.speed_mps_at(-1.0), 0.0);  // held before the start
  EXPECT_DOUBLE_EQ(c.speed_mps_at(99.0), 0.0);  // and after the end
  EXPECT_DOUBLE_EQ(c.accel_mps2_at(5.0), 1.0);
  EXPECT_DOUBLE_EQ(c.accel_mps2_at(10.0), 0.0);   // at a sample: the following segment
  EXPECT_DOUBLE_EQ(c.accel_mps2_at(20.0), -1.0);
  EXPECT_DOUBLE_EQ(c.accel_mps2_at(30.0), 0.0);   // after the end the speed is held
  EXPECT_DOUBLE_EQ(c.grade_at(5.0), 0.01);
  EXPECT_DOUBLE_EQ(c.distance_m(), 50.0 + 100.0 + 50.0);
  // Any hint gives the same segment as a search.
  for (double t : {-3.0, 0.0, 0.5, 9.999, 10.0, 19.0, 29.9, 30.0, 31.0}) {
    const std::size_t ref = c.segment_index(t);
    for (std::size_t hint : {0u, 1u, 2u, 3u, 7u, 1000u}) EXPECT_EQ(c.segment_index(t, hint), ref) << t << " " << hint;
  }
  std::size_t hint = 0;
  double last = -1.0;
  for (double t = 0.0; t <= 30.0; t += 0.25) {  // sequential sweep with a running hint
    const double v = c.speed_mps_at(t, hint);
    EXPECT_DOUBLE_EQ(v, c.speed_mps_at(t));
    last = v;
  }
  EXPECT_DOUBLE_EQ(last, 0.0);
}

TEST(DriveCycleLookup, BreakpointsAreTheKinks) {
  DriveCycle c;
  c.time_s = {0, 1, 2, 3, 4, 5, 6};
  c.speed_mps = {0, 1, 2, 2, 2, 1, 0};  // kinks at 2 (ramp -> hold) and 4 (hold -> ramp)
  c.grade.assign(7, 0.0);
  EXPECT_EQ(rollsim::breakpoints_s(c), (std::vector<double>{2, 4}));
  // NEDC: every operation boundary inside the cycle is a kink. ECE-15 has 23 interior breakpoints where the
  // slope changes (25 listed, of which 176 -> 178 is a continuation of the 35 km/h hold: 24 kinks), times 4,
  // plus the joins, plus EUDC's 20.
  const auto nedc = load_cycle("nedc");
  const auto bp = rollsim::breakpoints_s(nedc);
  for (std::size_t i = 1; i < bp.size(); ++i) EXPECT_LT(bp[i - 1], bp[i]);
  for (double t : {11.0, 15.0, 23.0, 25.0, 28.0, 178.0, 185.0, 1126.0, 1142.0, 1150.0, 1160.0}) {
    EXPECT_NE(std::find(bp.begin(), bp.end(), t), bp.end()) << t;
  }
  EXPECT_EQ(std::find(bp.begin(), bp.end(), 176.0), bp.end());  // 35 km/h continues through the gear change
  EXPECT_EQ(std::find(bp.begin(), bp.end(), 12.0), bp.end());   // inside a straight ramp
  // The WLTC, a 1 Hz trace, has kinks at most samples but never at the ends.
  const auto w = load_cycle("wltc");
  const auto wb = rollsim::breakpoints_s(w);
  EXPECT_GT(wb.size(), 1000u);
  EXPECT_GT(wb.front(), 0.0);
  EXPECT_LT(wb.back(), 1800.0);
}

TEST(DriveCycleLookup, AStandstillsStartIsABreakpointWithoutAKink) {
  DriveCycle c;
  c.time_s = {0, 1, 2, 3, 4, 5};
  c.speed_mps = {3, 2, 1, 1e-9, 0, 0};  // creeps in: the slope from 1 to 1e-9 and on to 0 differs by 1e-9 m/s^2
  c.grade.assign(6, 0.0);
  EXPECT_EQ(rollsim::breakpoints_s(c), (std::vector<double>{3, 4}));
}

TEST(DriveCycleLookup, CrossingTimesOfASpeed) {
  DriveCycle c;
  c.time_s = {0, 10, 20, 30, 40};
  c.speed_mps = {0, 20, 10, 5, 15};
  c.grade.assign(5, 0.0);
  EXPECT_EQ(rollsim::crossing_times_s(c, 15.0), (std::vector<double>{7.5, 15.0}));  // the last sample does not count
  EXPECT_EQ(rollsim::crossing_times_s(c, 15.0, true), (std::vector<double>{15.0}));
  EXPECT_EQ(rollsim::crossing_times_s(c, 10.0, true), (std::vector<double>{20.0}));  // reached at a sample
  EXPECT_EQ(rollsim::crossing_times_s(c, 30.0), (std::vector<double>{}));
}

TEST_F(DriveCycleFiles, UserCsvWithGradeAndSpeedMps) {
  const auto c = load_cycle(write("hill.csv", "time_s,speed_mps,grade_pct\n0,0,0\n10,10,5\n20,10,-5\n"));
  EXPECT_EQ(c.name, "hill");
  EXPECT_DOUBLE_EQ(c.speed_mps_at(15.0), 10.0);
  EXPECT_DOUBLE_EQ(c.grade_at(10.0), 0.05);
  EXPECT_DOUBLE_EQ(c.grade_at(15.0), 0.0);
}

TEST_F(DriveCycleFiles, ElevationBecomesGradeOverDistance) {
  // A 10 % road: elevation rises 0.1 m per metre travelled (5 m in each 0 <-> 10 m/s second, 10 m per second
  // at 10 m/s). Standing at both ends must not divide by the zero distance travelled there.
  std::string text = "time_s,speed_kmh,elevation_m\n0,0,100\n1,0,100\n";
  double s = 0.0;
  for (int t = 2; t <= 101; ++t) {
    s += (t == 2) ? 5.0 : 10.0;
    text += std::to_string(t) + ",36," + std::to_string(100 + 0.1 * s) + "\n";
  }
  s += 5.0;
  text += "102,0," + std::to_string(100 + 0.1 * s) + "\n103,0," + std::to_string(100 + 0.1 * s) + "\n";
  const auto c = load_cycle(write("climb.csv", text));
  // 0.1 m per metre along the road is the slope's sine; the cycle's grade is its tangent, rise over run.
  const double tangent = 0.10 / std::sqrt(1.0 - 0.10 * 0.10);
  for (double t : {0.0, 5.0, 50.0, 95.0, 103.0}) EXPECT_NEAR(c.grade_at(t), tangent, 1e-9) << t;
  for (double g : c.grade) {
    EXPECT_TRUE(std::isfinite(g));
    EXPECT_NEAR(g, tangent, 1e-9);
  }
}

// The climb a grade books along a cycle [m]: the sine of each segment's grade times the road it travels.
double net_climb_m(const DriveCycle& c) {
  double climb_m = 0.0;
  for (std::size_t i = 0; i + 1 < c.time_s.size(); ++i) {
    const double run_m = 0.5 * (c.speed_mps[i] + c.speed_mps[i + 1]) * (c.time_s[i + 1] - c.time_s[i]);
    climb_m += run_m * c.grade[i] / std::sqrt(1.0 + c.grade[i] * c.grade[i]);
  }
  return climb_m;
}

// A route that ends where it began climbs next to nothing net, and its hill and dip are kept: the elevation is
// smoothed over 300 m of road, so what the ends' off-centre windows leave is centimetres against the route's +-20 m.
TEST_F(DriveCycleFiles, AClosedRouteBooksNoNetClimb) {
  std::string text = "time_s,speed_kmh,elevation_m\n";
  for (int t = 0; t <= 400; ++t) {
    const double hill_m = 20.0 * std::sin(3.14159265358979 * t / 200.0) + 0.3 * ((t * 7919) % 11 - 5) / 5.0;
    text += std::to_string(t) + ",36," + std::to_string(t == 0 || t == 400 ? 0.0 : hill_m) + "\n";
  }
  const auto c = load_cycle(write("loop.csv", text));
  double max_grade = 0.0;
  for (double g : c.grade) max_grade = std::max(max_grade, std::abs(g));
  EXPECT_NEAR(net_climb_m(c), 0.0, 0.25);
  EXPECT_GT(max_grade, 0.025);  // the hill and the dip are there (+-20 m over 4 km: up to 3.1 %)
}

// A constant 5 % climb over a 300 m trip from rest to rest, its elevation the road's sine times the distance: each
// grid cell's mean elevation sat at the cell's centre while the accelerating car's samples bunched at its start, so
// the grade read 4.70-5.10 % and the trip booked 0.56 % less climb than its 15 m (session 25's outside testing).
TEST_F(DriveCycleFiles, AConstantClimbFromRestIsReadAsItsGrade) {
  const double sine = 0.05 / std::sqrt(1.0 + 0.05 * 0.05);
  std::string text = "time_s,speed_kmh,elevation_m\n";
  double s_m = 0.0, v_prev = 0.0;
  for (int t = 0; t <= 40; ++t) {
    const double kmh = t <= 10 ? 3.6 * t : t <= 30 ? 36.0 : 3.6 * (40 - t);
    if (t > 0) s_m += 0.5 * (v_prev + kmh / 3.6);
    v_prev = kmh / 3.6;
    char line[96];
    std::snprintf(line, sizeof line, "%d,%.6f,%.9f\n", t, kmh, sine * s_m);
    text += line;
  }
  const auto c = load_cycle(write("climb.csv", text));
  for (std::size_t i = 0; i < c.grade.size(); ++i) EXPECT_NEAR(c.grade[i], 0.05, 1e-5) << "sample " << i;
  EXPECT_NEAR(net_climb_m(c), sine * s_m, 1e-4);
}

// GPS-like elevation on a level stop-and-go route: +-1 m of noise each second and a 3 m re-fix while standing at a
// light. Read in blocks of 10 m (sessions 21-22) the noise was +-7 % grades whose climbs cost more than their descents
// gave back (+38-46 % energy for ev.yaml) and the re-fix a 25 % ramp into the light: session 22's outside testing.
TEST_F(DriveCycleFiles, GpsNoiseOnALevelRouteIsNoClimb) {
  std::string level = "time_s,speed_kmh\n", noisy = "time_s,speed_kmh,elevation_m\n";
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> noise(-1.0, 1.0);
  for (int t = 0; t <= 1200; ++t) {
    const int phase = t % 120;  // 0-20 s up to 50 km/h, 60 s cruise, 20 s down, 20 s standing
    const double kmh = phase < 20 ? 2.5 * phase : phase < 80 ? 50.0 : phase < 100 ? 50.0 - 2.5 * (phase - 80) : 0.0;
    const double refix_m = t >= 1100 ? 3.0 : 0.0;  // the last stop's re-fix, kept to the end
    level += std::to_string(t) + "," + std::to_string(kmh) + "\n";
    noisy += std::to_string(t) + "," + std::to_string(kmh) + "," + std::to_string(200.0 + refix_m + noise(rng)) + "\n";
  }
  const auto c = load_cycle(write("gps.csv", noisy));
  double max_grade = 0.0;
  for (double g : c.grade) max_grade = std::max(max_grade, std::abs(g));
  EXPECT_LT(max_grade, 0.03);                 // the re-fix spread over 300 m of road, not a 25 % ramp
  EXPECT_NEAR(net_climb_m(c), 3.0, 1.0);      // the re-fix is in the data: booked as the 3 m it is
  const auto ev = VehicleModel::assemble(load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml"));
  const double flat_j = simulate_forward(ev, load_cycle(write("level.csv", level))).energy.battery_terminal_j;
  EXPECT_NEAR(simulate_forward(ev, c).energy.battery_terminal_j / flat_j, 1.0, 0.02);
}

// A GPS drifting up 6 m in small steps while the car stands, and snapping back as it moves off: each snap-back was the
// one step dropped as a glitch, so every stop booked a 6 m climb (session 23's outside testing: +11 % energy on a
// level route with six stops). Drifting up or down, snapping back while standing or on the first moving sample.
TEST_F(DriveCycleFiles, AnElevationDriftingWhileStandingIsNoClimb) {
  for (const double drift_m : {6.0, -6.0, 4.0}) {
    for (const int snap_at : {119, 120}) {  // the stop's last standing sample, or the first moving one
      std::string text = "time_s,speed_kmh,elevation_m\n";
      for (int t = 0; t <= 720; ++t) {
        const int phase = t % 120;  // 0-20 s up to 50 km/h, 60 s cruise, 20 s down, 20 s standing
        const double kmh = phase < 20 ? 2.5 * phase : phase < 80 ? 50.0 : phase < 100 ? 50.0 - 2.5 * (phase - 80) : 0.0;
        const bool drifting = phase >= 100 && phase < snap_at;  // back at 150 m from phase snap_at (120: the next 0)
        const double h_m = 150.0 + (drifting ? drift_m * (phase - 99) / 20.0 : 0.0);
        text += std::to_string(t) + "," + std::to_string(kmh) + "," + std::to_string(h_m) + "\n";
      }
      const auto c = load_cycle(write("drift.csv", text));
      EXPECT_NEAR(net_climb_m(c), 0.0, 0.25) << drift_m << " m, snapping back at " << snap_at;  // six stops: 36 m before
    }
  }
}

TEST_F(DriveCycleFiles, BadInputNamesFileLineColumnAndValue) {
  auto has = [](const std::string& msg, const std::string& part) {
    return msg.find(part) != std::string::npos ? ::testing::AssertionSuccess()
                                               : ::testing::AssertionFailure() << "'" << part << "' not in: " << msg;
  };
  std::string m;
  // Missing file, and a name that is neither a file nor a shipped cycle.
  try {
    load_cycle((dir_ / "nope.csv").string());
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_TRUE(has(e.what(), "nope.csv"));
    EXPECT_TRUE(has(e.what(), "shipped cycles"));
  }
  EXPECT_THROW(rollsim::read_cycle_csv((dir_ / "nope.csv").string(), "x"), InputError);
  m = error_of("");
  EXPECT_TRUE(has(m, "empty"));
  m = error_of("0,0\n1,5\n");  // no header
  EXPECT_TRUE(has(m, "line 1"));
  EXPECT_TRUE(has(m, "header"));
  m = error_of("time_s,velocity\n0,0\n1,5\n");  // unknown column, found columns listed
  EXPECT_TRUE(has(m, "'velocity'"));
  EXPECT_TRUE(has(m, "time_s"));
  m = error_of("time_s,grade_pct\n0,0\n1,5\n");  // no speed column
  EXPECT_TRUE(has(m, "speed_kmh"));
  EXPECT_TRUE(has(m, "found columns: 'time_s', 'grade_pct'"));
  m = error_of("speed_kmh\n0\n5\n");
  EXPECT_TRUE(has(m, "missing column 'time_s'"));
  m = error_of("time_s,speed_kmh,speed_mps\n0,0,0\n1,1,1\n");
  EXPECT_TRUE(has(m, "both"));
  // A speed out of range says its range as every other key does (it read "must be in >= 0 and <= 500 km/h").
  m = error_of("time_s,speed_kmh\n0,0\n1,-5\n2,0\n");
  EXPECT_TRUE(has(m, "line 3, column 'speed_kmh': -5 is not allowed: speed must be in [0, 500] km/h"));
  m = error_of("time_s,speed_mps\n0,0\n1,200\n2,0\n");
  EXPECT_TRUE(has(m, "200 is not allowed: speed must be in [0, 138.9] m/s (500 km/h)"));
  m = error_of("time_s,speed_kmh\n0,0\n1,fast\n2,3\n");  // text in a number column
  EXPECT_TRUE(has(m, "bad.csv: line 3, column 'speed_kmh'"));
  EXPECT_TRUE(has(m, "'fast' is not a number"));
  m = error_of("time_s,speed_kmh\n0,0\n1,\n2,3\n");
  EXPECT_TRUE(has(m, "line 3, column 'speed_kmh'"));
  EXPECT_TRUE(has(m, "empty"));
  m = error_of("time_s,speed_kmh\n0,0\n1,nan\n2,3\n");
  EXPECT_TRUE(has(m, "line 3"));
  EXPECT_TRUE(has(m, "'nan'"));
  EXPECT_TRUE(has(m, "finite"));
  m = error_of("time_s,speed_kmh\n0,0\n1,inf\n");
  EXPECT_TRUE(has(m, "'inf'"));
  m = error_of("time_s,speed_kmh\n0,0\n1,1e999\n");  // overflows to infinity: rejected, not clamped
  EXPECT_TRUE(has(m, "finite"));
  m = error_of("time_s,speed_kmh\n0,0\n1,-2\n");
  EXPECT_TRUE(has(m, "line 3"));
  EXPECT_TRUE(has(m, "-2"));
  EXPECT_TRUE(has(m, "[0, 500] km/h"));
  m = error_of("time_s,speed_kmh\n0,0\n1,5\n1,6\n");  // time repeats: both lines named
  EXPECT_TRUE(has(m, "line 4, column 'time_s'"));
  EXPECT_TRUE(has(m, "line 3"));
  EXPECT_TRUE(has(m, "strictly increasing"));
  // Epoch-like times a fine step apart are one double: the message says precision is why, not "1e+16 is not after
  // 1e+16" alone; times that are the same number written twice get no such sentence.
  m = error_of("time_s,speed_kmh\n1e16,0\n1.0000000000000001e16,5\n");
  EXPECT_TRUE(has(m, "one number in double precision"));
  EXPECT_TRUE(has(m, "'1.0000000000000001e16'"));
  EXPECT_FALSE(has(error_of("time_s,speed_kmh\n0,0\n1,5\n1.0,6\n"), "double precision"));
  m = error_of("time_s,speed_kmh\n0,0\n2,5\n1,6\n");  // time goes backwards
  EXPECT_TRUE(has(m, "line 4"));
  EXPECT_TRUE(has(m, "1 s is not after 2 s"));
  m = error_of("time_s,speed_kmh\n0,0\n");
  EXPECT_TRUE(has(m, "at least 2"));
  m = error_of("time_s,speed_kmh,grade_pct\n0,0,0\n1,5,31\n");
  EXPECT_TRUE(has(m, "line 3, column 'grade_pct'"));
  EXPECT_TRUE(has(m, "31 %"));
  EXPECT_TRUE(has(m, "[-30, 30]"));
  m = error_of("time_s,speed_kmh\n0,0\n1,5,7\n");  // ragged row
  EXPECT_TRUE(has(m, "line 3"));
  EXPECT_TRUE(has(m, "3 cells"));
  m = error_of("time_s,speed_kmh\n0,\"5\n");  // unterminated quote
  EXPECT_TRUE(has(m, "never closed"));
  // Elevation implying a road too steep to drive: 35 % along the road for 600 m, metre by metre.
  std::string steep = "time_s,speed_mps,elevation_m\n";
  for (int t = 0; t <= 600; ++t) steep += std::to_string(t) + ",1," + std::to_string(0.35 * t) + "\n";
  m = error_of(steep);
  EXPECT_TRUE(has(m, "column 'elevation_m'"));
  EXPECT_TRUE(has(m, "+-30 %"));
  EXPECT_TRUE(has(m, ": line "));
}

// A quote left open swallows the lines up to the next quote in the file; the reader stopped there and named that line
// (d_unterm.csv: "line 59: text after a closing quote" for a quote opened on line 51; session 22's outside testing).
// Every CSV reader shares the one reader, so a cycle file shows it as the EPA list does.
TEST_F(DriveCycleFiles, AnUnclosedQuoteIsNamedAtTheLineWhereItOpened) {
  std::string m = error_of("time_s,speed_kmh,note\n0,0,a\n1,\"5,b\n2,6,c\n3,7,\"d\"\n");
  EXPECT_NE(m.find("bad.csv: line 3: a quoted cell opens here and runs over 3 lines to line 5"), std::string::npos) << m;
  EXPECT_NE(m.find("is a closing quote missing on line 3?"), std::string::npos) << m;
  m = error_of("time_s,speed_kmh,note\n0,0,a\n1,\"5\n\",\"b\n2,6,c\n");  // the record opens on line 3, the quote on 4
  EXPECT_NE(m.find("bad.csv: line 4: a quoted cell opens here and is never closed"), std::string::npos) << m;
  m = error_of("time_s,speed_kmh\n0,0\n\"1\",\"5\"x\n");  // on one line: that line, as before
  EXPECT_NE(m.find("bad.csv: line 3: text after a closing quote"), std::string::npos) << m;
}

// A step no road could climb over the distance driven (20 m in 10 m: a GPS glitch) is dropped, and said.
TEST_F(DriveCycleFiles, AnElevationGlitchIsDroppedAndSaid) {
  std::string text = "time_s,speed_mps,elevation_m\n";
  for (int t = 0; t <= 100; ++t) text += std::to_string(t) + ",10," + (t == 50 ? "120" : "100") + "\n";
  const auto c = load_cycle(write("glitch.csv", text));
  for (double g : c.grade) EXPECT_NEAR(g, 0.0, 1e-12);
  ASSERT_FALSE(c.notes.empty());
  EXPECT_NE(c.notes.back().find("2 elevation step(s)"), std::string::npos) << c.notes.back();
  EXPECT_NE(c.notes.back().find("dropped as glitches"), std::string::npos) << c.notes.back();
}

TEST_F(DriveCycleFiles, CsvDetailsQuotesCrlfAndBlankLines) {
  const auto c = load_cycle(write("q.csv", "\xEF\xBB\xBF\"time_s\",\"speed_kmh\"\r\n0,0\r\n\r\n1,\"3.6\"\r\n2,+7.2\r\n"));
  ASSERT_EQ(c.time_s.size(), 3u);
  EXPECT_DOUBLE_EQ(c.speed_mps[1], 1.0);
  EXPECT_DOUBLE_EQ(c.speed_mps[2], 2.0);
}
