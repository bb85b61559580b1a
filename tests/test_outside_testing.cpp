// Defects an outside sweep found in session 16 (careless and hostile input to diagnose, validate and the outputs
// of every command). Each test failed before its fix.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "test_support.hpp"

namespace rollsim::test {
namespace {

namespace fs = std::filesystem;

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

const std::string kCamryUdds =
    std::string(ROLLSIM_SHARED_DIR) + "/data/recordings/anl_d3_2018_toyota_camry/61811012_test_data.csv";

// The shipped hot UDDS, each data line rewritten by `edit(line number from 1, fields)`.
template <class Edit>
std::string camry_edited(Edit edit) {
  std::ifstream in(kCamryUdds);
  std::ostringstream out;
  std::string line;
  std::getline(in, line);
  out << line << "\n";
  for (int n = 1; std::getline(in, line); ++n) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) f.push_back(cell);
    edit(n, f);
    out << f.at(0) << "," << f.at(1) << "," << f.at(2) << "\n";
  }
  return out.str();
}

std::string line_starting(const std::string& text, const std::string& head) {
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);)
    if (l.rfind(head, 0) == 0) return l;
  return "";
}

class OutsideTesting : public FileFixture {};

// A fuel channel logged as zero throughout read as the model being 10^18 % off, and wrote inf into the JSON.
TEST_F(OutsideTesting, ADeadEnergyChannelIsRefusedNotScored) {
  const std::string dead = write("dead.csv", camry_edited([](int, std::vector<std::string>& f) { f[1] = "0"; }));
  const fs::path json = dir_ / "d.json";
  const CmdResult r = run_rollsim("diagnose --vehicle camry_2018 --preset anl_d3 --recording '" + dead + "' --json '" +
                                  json.string() + "'");
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_TRUE(has(r.err, dead + ": its fuel_rate channel never changes (0 W throughout) while the car covers 12.0")) << r.err;
  EXPECT_FALSE(fs::exists(json));
}

// A car that never moves gives nothing to diagnose (it divided by a measured energy of about zero).
TEST_F(OutsideTesting, ARecordingOfAStandingCarIsRefused) {
  const std::string standing =
      write("standing.csv", camry_edited([](int, std::vector<std::string>& f) { f[2] = "0"; }));
  const CmdResult r = run_rollsim("diagnose --vehicle camry_2018 --preset anl_d3 --recording '" + standing + "'");
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_TRUE(has(r.err, standing + ": the car covers 0 m in the recording; at least 100 m")) << r.err;
}

// A gap in time was integrated as if the last sample had lasted through it: 30000 s of it added 12 l of fuel that
// no one measured. No energy window spans a gap now, so its length changes nothing.
TEST_F(OutsideTesting, AGapsLengthChangesNothing) {
  auto with_gap = [](double gap_s) {
    return camry_edited([gap_s](int n, std::vector<std::string>& f) {
      if (n > 600) f[0] = std::to_string(std::stod(f[0]) + gap_s);
    });
  };
  const std::string a = write("gap300.csv", with_gap(300.0));
  const std::string b = write("gap30000.csv", with_gap(30000.0));
  const CmdResult ra = run_rollsim("diagnose --vehicle camry_2018 --preset anl_d3 --recording '" + a + "'");
  const CmdResult rb = run_rollsim("diagnose --vehicle camry_2018 --preset anl_d3 --recording '" + b + "'");
  ASSERT_EQ(ra.exit_code, 0) << ra.err;
  ASSERT_EQ(rb.exit_code, 0) << rb.err;
  EXPECT_TRUE(has(rb.out + rb.err, "1 gap(s) in time longer than 5 s kept, not bridged (no energy window spans one)"));
  const std::string trip = "uncalibrated trip energy error: ";
  EXPECT_NE(line_starting(ra.out, trip), "");
  EXPECT_EQ(line_starting(ra.out, trip), line_starting(rb.out, trip));
  EXPECT_EQ(line_starting(ra.out, "held-out, calibrated:"), line_starting(rb.out, "held-out, calibrated:"));
}

// JSON has no NaN or infinity: a degenerate (constant-speed) recording's undefined figures are null.
TEST_F(OutsideTesting, DiagnosisJsonHasNoNonFiniteNumbers) {
  std::string rows = "Time[s],Eng_FuelFlow_Direct_DI[ccps],Dyno_Spd[mph]\n";
  for (int t = 0; t <= 1200; ++t) rows += std::to_string(t) + ".0," + (t % 2 ? "0.91" : "0.9") + ",50.0\n";
  const std::string steady = write("steady.csv", rows);
  const fs::path json = dir_ / "s.json";
  const CmdResult r = run_rollsim("diagnose --vehicle camry_2018 --preset anl_d3 --recording '" + steady + "' --json '" +
                                  json.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string text = slurp(json);
  EXPECT_FALSE(std::regex_search(text, std::regex(R"(:\s*-?(inf|nan|NaN|Infinity)\b)"))) << text;
  EXPECT_TRUE(has(text, "null")) << text;
}

}  // namespace
}  // namespace rollsim::test
