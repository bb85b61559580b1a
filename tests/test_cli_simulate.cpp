#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

namespace {

struct Output {
  int exit_code;
  std::string text;
};

Output run(const std::string& args) {
  const std::string cmd = std::string(ROLLSIM_BINARY) + " " + args + " 2>&1";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(cmd.c_str(), "r"), pclose);
  std::string text;
  std::array<char, 4096> buf{};
  while (std::size_t n = std::fread(buf.data(), 1, buf.size(), pipe.get())) text.append(buf.data(), n);
  const int status = pclose(pipe.release());
  return {WEXITSTATUS(status), text};
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

TEST(CliSimulate, SeveralTyresGiveOneTableWithDifferences) {
  const auto out = run("simulate --vehicle ice --tyre nominal --tyre low-rrc --cycle nedc");
  ASSERT_EQ(out.exit_code, 0) << out.text;
  EXPECT_NE(out.text.find("l/100 km"), std::string::npos);
  EXPECT_NE(out.text.find("low-rrc"), std::string::npos);
  EXPECT_NE(out.text.find("diff %"), std::string::npos);
}

TEST(CliSimulate, TraceIsWrittenWholeOrNotAtAll) {
  const auto dir = std::filesystem::temp_directory_path() / ("rollsim_cli_sim_" + std::to_string(::getpid()));
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

TEST(CliSimulate, BadInputGivesOneClearErrorAndNonZeroExit) {
  for (const std::string args : {"simulate --vehicle no_such_car", "simulate --vehicle ev --tyre no_such_tyre",
                                 "simulate --vehicle ev --cycle no_such_cycle"}) {
    const auto out = run(args);
    EXPECT_NE(out.exit_code, 0) << args;
    EXPECT_NE(out.text.find("error:"), std::string::npos) << args << ": " << out.text;
    EXPECT_NE(out.text.find("no_such"), std::string::npos) << args << ": " << out.text;
  }
}
