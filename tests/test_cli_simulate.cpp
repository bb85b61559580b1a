// `rollsim simulate` end to end: JSON keys, comparison tables, trace output and bad input, through the binary.
#include <gtest/gtest.h>

#include "test_support.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

namespace {

struct Output {
  int exit_code;
  std::string text;  ///< stdout and stderr together
};

Output run(const std::string& args) {
  const auto r = rollsim::test::run_rollsim(args);
  return {r.exit_code, r.out + r.err};
}

}  // namespace

TEST(CliSimulate, JsonHasTheDocumentedKeys) {
  const auto out = run("simulate --vehicle ev.yaml --tyre 155-70R19.yaml --json");
  ASSERT_EQ(out.exit_code, 0) << out.text;
  for (const char* key : {"\"distance_km\"", "\"aec_kwh_per_10km\"", "\"fuel_l_per_100km\"", "\"co2_g_per_km\"",
                          "\"energy_breakdown_kwh\"", "\"max_speed_error_kmh\"", "\"rolling_resistance\"", "\"cvode\""}) {
    EXPECT_NE(out.text.find(key), std::string::npos) << key;
  }
}

// The energy table names what each row holds: a coast-down car's A + B v is its tyres and its driveline together, and
// an automatic's slip is its torque converter's (both read "rolling resistance (tyres)" and "clutch slip at launch"
// until session 22's outside testing).
TEST(CliSimulate, TheEnergyTableNamesWhatTheRoadLoadAndTheSlipAre) {
  const auto coastdown = run("simulate --vehicle camry_2018_map");
  ASSERT_EQ(coastdown.exit_code, 0) << coastdown.text;
  EXPECT_NE(coastdown.text.find("  rolling and driveline (coast-down A + B v)"), std::string::npos) << coastdown.text;
  EXPECT_NE(coastdown.text.find("  clutch or converter slip"), std::string::npos) << coastdown.text;
  EXPECT_EQ(coastdown.text.find("(tyres)"), std::string::npos) << coastdown.text;
  const auto tyres = run("simulate --vehicle ice");
  EXPECT_NE(tyres.text.find("  rolling resistance (tyres)"), std::string::npos) << tyres.text;
}

TEST(CliSimulate, SeveralTyresGiveOneTableWithDifferences) {
  const auto out = run("simulate --vehicle ice --tyre nominal --tyre low-rrc --cycle nedc");
  ASSERT_EQ(out.exit_code, 0) << out.text;
  EXPECT_NE(out.text.find("l/100 km"), std::string::npos);
  EXPECT_NE(out.text.find("low-rrc"), std::string::npos);
  EXPECT_NE(out.text.find("diff %"), std::string::npos);
}

TEST(CliSimulate, TraceIsWrittenWholeOrNotAtAll) {
  const auto dir = rollsim::test::temp_dir() / "simulate";
  std::filesystem::create_directories(dir);
  const auto trace = (dir / "trace.csv").string();
  auto out = run("simulate --vehicle ev --cycle udds --trace " + trace);
  ASSERT_EQ(out.exit_code, 0) << out.text;
  EXPECT_TRUE(std::filesystem::file_size(trace) > 1000);
  out = run("simulate --vehicle ev --trace " + (dir / "missing_dir" / "t.csv").string());
  EXPECT_NE(out.exit_code, 0);
  EXPECT_NE(out.text.find("--trace"), std::string::npos) << out.text;
  EXPECT_FALSE(std::filesystem::exists(dir / "missing_dir"));
  std::filesystem::remove_all(dir);
}

// A trace's time and speed are a cycle rollsim reads back (the integrator's -0.0003 km/h at the NEDC's stops was
// refused as a negative speed; session 27's outside tester), and the same car over it gives the same energy.
TEST(CliSimulate, ATracesSpeedIsACycleItReadsBack) {
  const auto dir = rollsim::test::temp_dir() / "simulate_roundtrip";
  std::filesystem::create_directories(dir);
  const auto trace = (dir / "trace.csv").string(), cycle = (dir / "cycle.csv").string();
  ASSERT_EQ(run("simulate --vehicle ev --trace " + trace).exit_code, 0);
  std::ifstream in(trace);
  std::ofstream out(cycle);
  std::string line;
  std::getline(in, line);
  out << "time_s,speed_kmh\n";
  int negative = 0;
  while (std::getline(in, line)) {
    const auto a = line.find(','), b = line.find(',', a + 1), c = line.find(',', b + 1);
    const std::string speed = line.substr(b + 1, c - b - 1);
    negative += std::stod(speed) < 0.0;
    out << line.substr(0, a) << "," << speed << "\n";
  }
  out.close();
  EXPECT_EQ(negative, 0);
  const auto again = run("simulate --vehicle ev --cycle " + cycle);
  EXPECT_EQ(again.exit_code, 0) << again.text;
  std::filesystem::remove_all(dir);
}

// A trace carries the car's own sources only (a petrol car printed a state of charge of 0), and its running totals
// end at the run's totals: the last row of the forward run is the cycle's last sample.
TEST(CliSimulate, TraceColumnsAreTheCarsOwnAndItsTotalsEndAtTheRunsTotals) {
  const auto dir = rollsim::test::temp_dir() / "simulate_columns";
  std::filesystem::create_directories(dir);
  for (const std::string car : {"ev", "ice"}) {
    const auto trace = (dir / (car + ".csv")).string();
    const auto out = run("simulate --vehicle " + car + " --cycle udds --json --trace " + trace);
    ASSERT_EQ(out.exit_code, 0) << out.text;
    std::ifstream in(trace);
    std::string header, line, last;
    std::getline(in, header);
    while (std::getline(in, line)) last = line;
    const bool electric = car == "ev";
    EXPECT_EQ(header.find("soc_pct") != std::string::npos, electric) << header;
    EXPECT_EQ(header.find("battery_energy_kwh") != std::string::npos, electric) << header;
    EXPECT_EQ(header.find("fuel_rate_lph") != std::string::npos, !electric) << header;
    EXPECT_EQ(header.find("fuel_l,") != std::string::npos || header.ends_with("fuel_l"), !electric) << header;
    // The last cell is the running total (battery_energy_kwh or fuel_l), against the JSON's total.
    const double total = std::stod(last.substr(last.rfind(',') + 1));
    using rollsim::test::json_number;
    const double expected = electric ? json_number(out.text, "battery_terminals")
                                     : json_number(out.text, "fuel_l_per_100km") * json_number(out.text, "distance_km") / 100.0;
    ASSERT_TRUE(std::isfinite(expected)) << out.text;
    EXPECT_NEAR(total / expected, 1.0, 1e-6) << car;
  }
  std::filesystem::remove_all(dir);
}

// Writing a trace is output only. The trace's sample at each segment's start stepped the shift schedule's hysteresis,
// so a combustion car upshifted a segment early where a sample sat just above a shift speed: ice.yaml's WLTC replay
// read 6.2494 l/100 km with --trace and 6.2510 without (and Python, whose trace is on by default, differed from
// compare and sweep). Session 21's outside testing.
TEST(CliSimulate, WritingATraceDoesNotChangeTheFigure) {
  using rollsim::test::json_number;
  const auto trace = (rollsim::test::temp_dir() / "trace_only.csv").string();
  for (const std::string args : {"--vehicle ice --cycle wltc --replay", "--vehicle camry_2018 --cycle artemis_urban --replay",
                                 "--vehicle ice --cycle wltc"}) {
    const auto plain = run("simulate " + args + " --json"), traced = run("simulate " + args + " --json --trace " + trace);
    ASSERT_EQ(plain.exit_code, 0) << plain.text;
    ASSERT_EQ(traced.exit_code, 0) << traced.text;
    EXPECT_NEAR(json_number(traced.text, "fuel_l_per_100km") / json_number(plain.text, "fuel_l_per_100km"), 1.0, 1e-12) << args;
  }
}

TEST(CliSimulate, BadInputGivesOneClearErrorAndNonZeroExit) {
  for (const std::string args : {"simulate --vehicle no_such_car", "simulate --vehicle ev --tyre no_such_tyre",
                                 "simulate --vehicle ev --cycle no_such_cycle"}) {
    const auto out = run(args);
    EXPECT_NE(out.exit_code, 0) << args;
    EXPECT_NE(out.text.find("error:"), std::string::npos) << args << ": " << out.text;
    EXPECT_NE(out.text.find("no_such"), std::string::npos) << args << ": " << out.text;
  }
}

TEST(CliSimulate, AFileAfterJsonIsToldWhereJsonGoes) {
  // `--json` prints on stdout everywhere but in diagnose, where it names a file; a file after it elsewhere was
  // refused as "The following argument was not expected" alone (session 26's outside testing).
  for (const std::string cmd : {"simulate --vehicle ev --json out.json", "validate --json out.json"}) {
    const auto out = run(cmd);
    EXPECT_EQ(out.exit_code, 2) << cmd;
    EXPECT_NE(out.text.find("takes no file: it prints JSON on stdout"), std::string::npos) << cmd << ": " << out.text;
    EXPECT_NE(out.text.find("rollsim diagnose --json FILE"), std::string::npos) << out.text;
  }
  EXPECT_EQ(run("tyre --json 175-70R14").exit_code, 0);  // a positional after the flag is still one
}

// A tyre loaded above its rating runs, with a warning naming it (load index 75: 387 kg, 3795 N < 4000 N).
TEST(CliSimulate, OverloadedTyreRunsWithAWarning) {
  const auto tyre = rollsim::test::temp_dir() / "li75.yaml";
  std::ofstream(tyre) << "size: \"195/65 R15 75T\"\npressure_bar: 2.5\n";
  const auto r = rollsim::test::run_rollsim("simulate --vehicle ev --tyre '" + tyre.string() + "'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("warning:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("rated maximum"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("kWh/10 km"), std::string::npos);
  // The tyre put on the car is rated too low; the car's mass is not in pounds (its own tyres carry it), which the
  // warning had asked (session 27's outside tester).
  EXPECT_NE(r.err.find("; the tyre's load rating is too low for this car"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find(" in lb?"), std::string::npos) << r.err;
}


// A car with other tyres behind than in front names both: the Twizy's own 125/145 set read "125-80R13" beside a
// --tyre 125-80R13 run of other figures (session 22's outside testing).
TEST(CliSimulate, ACarWithTwoTyreSizesNamesBoth) {
  const auto table = run("simulate --vehicle twizy --cycle nedc --cycle udds");
  ASSERT_EQ(table.exit_code, 0) << table.text;
  EXPECT_NE(table.text.find("nedc   front 125-80R13 / rear 145-80R13"), std::string::npos) << table.text;
  const auto json = run("simulate --vehicle twizy --json");
  EXPECT_NE(json.text.find("\"tyre\": \"front 125-80R13 / rear 145-80R13\""), std::string::npos) << json.text;
  // The files of the car's own tyres are named too: with a same-named tyre file beside a vehicle file, which one was
  // read could not be told (tyre_file was null: session 25's outside testing).
  EXPECT_NE(json.text.find("tyres/125-80R13.yaml\", \"cycle_file\""), std::string::npos) << json.text;
  EXPECT_NE(json.text.find("\"rear_tyre_file\": \""), std::string::npos) << json.text;
  EXPECT_NE(json.text.find("tyres/145-80R13.yaml\"}"), std::string::npos) << json.text;
  const auto one_set = run("simulate --vehicle ev --json");
  EXPECT_NE(one_set.text.find("tyres/nominal.yaml\", \"cycle_file\""), std::string::npos) << one_set.text;
  EXPECT_EQ(one_set.text.find("rear_tyre_file"), std::string::npos) << one_set.text;
}
