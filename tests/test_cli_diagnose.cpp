// `rollsim diagnose` end to end: the vehicle file's logger mapping, and bad mappings named with file and key.
#include <gtest/gtest.h>

#include "test_support.hpp"

#include <filesystem>
#include <fstream>
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
