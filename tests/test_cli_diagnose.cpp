// `rollsim diagnose` end to end: the vehicle file's logger mapping, and bad mappings named with file and key.
#include <gtest/gtest.h>

#include "test_support.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace {

const std::string kCamryRecording =
    std::string(ROLLSIM_SHARED_DIR) + "/data/recordings/anl_d3_2018_toyota_camry/61811012_test_data.csv";

}  // namespace

TEST(CliDiagnose, VehicleFileCarriesItsLoggersColumns) {
  const auto r = rollsim::test::run_rollsim("diagnose --vehicle camry_2018 --recording '" + kCamryRecording + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("channel fuel_rate"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("verdict:"), std::string::npos) << r.out;
}

TEST(CliDiagnose, MisspeltMappingColumnIsNamed) {
  std::ifstream in(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/camry_2018.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), {});
  text.replace(text.find("  fuel_rate_lph: \"Eng"), 15, "  fuel_rate_lhp");
  const auto path = rollsim::test::temp_dir() / "camry_bad_mapping.yaml";
  std::ofstream(path) << text;
  const auto r = rollsim::test::run_rollsim("diagnose --vehicle '" + path.string() + "' --recording '" + kCamryRecording + "'");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("fuel_rate_lhp"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("camry_bad_mapping.yaml"), std::string::npos) << r.err;
}

#include <cstdio>
#include <vector>

#include "rollsim/discovery/generate.hpp"

// Several recordings at different ambients, as CSV files with an ambient_temp_c column: `diagnose` names
// ambient_rrc with its coefficient and interval in the JSON, and `--write-vehicle` switches it on.
TEST(CliDiagnose, AmbientRrcAcrossRecordedAmbients) {
  const rollsim::Vehicle ev = rollsim::load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml");
  rollsim::MultiTripCase m;
  m.seed = 5;
  m.effects = {{"ambient_compound", 0.012}};
  const std::vector<rollsim::Recording> trips = rollsim::generate_trips(ev, m);
  std::string args;
  for (std::size_t k = 0; k < trips.size(); ++k) {
    const auto path = rollsim::test::temp_dir() / ("trip" + std::to_string(k) + ".csv");
    std::FILE* f = std::fopen(path.string().c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fprintf(f, "time_s,speed_kmh,battery_power_kw,ambient_temp_c\n");
    const auto& t = trips[k];
    for (std::size_t i = 0; i < t.time_s.size(); ++i)
      std::fprintf(f, "%.1f,%.4f,%.4f,%.2f\n", t.time_s[i], t.speed_mps[i] * 3.6, (*t.battery_power_w)[i] / 1000.0,
                   (*t.ambient_temp_k)[i] - 273.15);
    std::fclose(f);
    args += " --recording '" + path.string() + "'";
  }
  const auto json = rollsim::test::temp_dir() / "ambient.json";
  const auto fitted = rollsim::test::temp_dir() / "ev_ambient.yaml";
  std::filesystem::remove(fitted);
  const auto r = rollsim::test::run_rollsim("diagnose --vehicle ev" + args + " --json '" + json.string() + "' --write-vehicle '" +
                                            fitted.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("ambient_rrc tested across 4 recordings"), std::string::npos) << r.out;
  const std::string j = rollsim::test::slurp(json);
  const auto at = j.find("\"effect\": \"ambient_rrc\"");
  ASSERT_NE(at, std::string::npos) << j;
  EXPECT_NE(j.find("\"rrc_change_per_k\": {\"value\": ", at), std::string::npos) << j;
  EXPECT_NE(rollsim::test::slurp(fitted).find("ambient_rrc:"), std::string::npos);
}

// The text's detection limits at three decimals read "0.000" for a grade offset of 0.00048, as if any were
// detectable; they are printed to four significant digits, as the JSON's value (session 21's outside testing).
TEST(CliDiagnose, DetectionLimitsAreNotRoundedToZero) {
  const auto dir = rollsim::test::temp_dir();
  const std::string trace = (dir / "ice_wltc_trace.csv").string();
  const auto sim = rollsim::test::run_rollsim("simulate --vehicle ice --cycle wltc --trace '" + trace + "'");
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const auto r = rollsim::test::run_rollsim("diagnose --vehicle ice --recording '" + trace + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto at = r.out.find("smallest size of each effect's catalogue shape");
  ASSERT_NE(at, std::string::npos) << r.out;
  std::istringstream limits(r.out.substr(at));
  std::string line;
  int seen = 0;
  std::getline(limits, line);
  std::getline(limits, line);  // the heading's second line
  while (std::getline(limits, line) && line.rfind("  ", 0) == 0) {
    ++seen;
    EXPECT_EQ(line.find(" 0.000 "), std::string::npos) << line;
  }
  EXPECT_GT(seen, 0) << r.out;
}

// simulate's own --trace of an electric car holds battery_current_a beside battery_power_kw, and diagnose refused
// it ("has battery_current_a but no battery_voltage_v"); the lone current is now left out with a note, and the
// model's own trace, read back, is nothing missing (session 21's outside testing).
TEST(CliDiagnose, SimulatesOwnTraceIsARecordingItReads) {
  const std::string trace = (rollsim::test::temp_dir() / "ev_wltc_trace.csv").string();
  const auto sim = rollsim::test::run_rollsim("simulate --vehicle ev --cycle wltc --trace '" + trace + "'");
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const auto r = rollsim::test::run_rollsim("diagnose --vehicle ev --recording '" + trace + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("battery_current_a without its pair: not used"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("channel battery_power"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("verdict: nothing_missing"), std::string::npos) << r.out;
}
