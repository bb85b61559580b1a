// `diagnose --write-vehicle` into another folder: the file loads there, and simulating it on the recording gives the
// energy error the diagnosis reported; columns the diagnosis does not use never abort it (issue 9, items 7 and 8).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "rollsim/diagnose/diagnose.hpp"
#include "rollsim/discovery/generate.hpp"
#include "rollsim/sim/simulation.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;

namespace {

using rollsim::test::json_number;

// A null recording of ev.yaml on WLTC x 2 (no lag, so the diagnosis compares like with like), as a CSV with GPS
// columns; `glitch` puts a longitude of 1555.6 deg on one line.
fs::path write_recording(const fs::path& dir, bool glitch) {
  const rollsim::Vehicle ev = rollsim::load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml");
  rollsim::SyntheticCase c;
  c.lag_s = 0.0;
  c.seed = 21;
  const rollsim::Recording r = rollsim::generate_case(ev, c);
  const fs::path path = dir / (glitch ? "glitch.csv" : "trip.csv");
  std::FILE* f = std::fopen(path.string().c_str(), "w");
  std::fprintf(f, "time_s,speed_kmh,battery_power_kw,latitude,longitude\n");
  for (std::size_t i = 0; i < r.time_s.size(); ++i)
    std::fprintf(f, "%.1f,%.6f,%.6f,48.1,%.4f\n", r.time_s[i], r.speed_mps[i] * 3.6, (*r.battery_power_w)[i] / 1000.0,
                 glitch && i == 1234 ? 1555.6 : 11.5 + 1e-5 * static_cast<double>(i));
  std::fclose(f);
  return path;
}


}  // namespace

TEST(CliWriteVehicle, WrittenElsewhereLoadsAndReproducesTheReportedError) {
  // A user's vehicle in its own folder, with its own tyre file beside it (found beside the vehicle, not shipped).
  const fs::path home = rollsim::test::temp_dir() / "user_car", out = rollsim::test::temp_dir() / "fitted_elsewhere";
  fs::create_directories(home);
  fs::create_directories(out);
  fs::copy_file(std::string(ROLLSIM_SOURCE_DIR) + "/tyres/nominal.yaml", home / "my_tyre.yaml", fs::copy_options::overwrite_existing);
  std::string car = rollsim::test::slurp(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml");
  car.replace(car.find("all: nominal.yaml"), 17, "all: my_tyre.yaml");
  std::ofstream(home / "car.yaml") << car;
  const fs::path rec = write_recording(out, false), fitted = out / "fitted.yaml", json = out / "d.json";
  const auto r = rollsim::test::run_rollsim("diagnose --vehicle '" + (home / "car.yaml").string() + "' --recording '" +
                                            rec.string() + "' --json '" + json.string() + "' --write-vehicle '" + fitted.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const rollsim::Vehicle v = rollsim::load_vehicle_file(fitted.string());  // threw before: my_tyre.yaml not beside it
  // Simulating the written vehicle on the recording: the uncalibrated energy error the diagnosis reported.
  const rollsim::Recording recording = rollsim::load_recording(rec.string(), {});
  const auto sim = rollsim::simulate_replay(rollsim::VehicleModel::assemble(v), rollsim::cycle_of_recording(recording));
  double measured_j = 0.0;
  for (std::size_t i = 0; i + 1 < recording.time_s.size(); ++i)
    measured_j += (*recording.battery_power_w)[i] * (recording.time_s[i + 1] - recording.time_s[i]);
  const double reported = json_number(rollsim::test::slurp(json), "raw_trip_energy_error_pct");
  EXPECT_NEAR(100.0 * (sim.energy.battery_terminal_j - measured_j) / measured_j, reported, 0.1);
}

TEST(CliWriteVehicle, TheTyreTheDiagnosisUsedIsTheOneWritten) {
  const fs::path out = rollsim::test::temp_dir() / "fitted_with_tyre";
  fs::create_directories(out);
  const fs::path rec = write_recording(out, false), fitted = out / "fitted.yaml";
  const auto r = rollsim::test::run_rollsim("diagnose --vehicle ev --tyre low-rrc --recording '" + rec.string() +
                                            "' --write-vehicle '" + fitted.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const rollsim::Vehicle v = rollsim::load_vehicle_file(fitted.string());
  ASSERT_TRUE(v.front_tyre.has_value());
  const rollsim::TyreSpec low = rollsim::load_tyre_file(std::string(ROLLSIM_SOURCE_DIR) + "/tyres/low-rrc.yaml");
  EXPECT_EQ(v.front_tyre->name, low.name);
  EXPECT_EQ(v.rear_tyre->name, low.name);
}

TEST(CliDiagnoseColumns, GpsGlitchInAnUnusedColumnIsAWarningNotAnAbort) {
  const fs::path dir = rollsim::test::temp_dir() / "gps_glitch";
  fs::create_directories(dir);
  const fs::path rec = write_recording(dir, true);
  const auto r = rollsim::test::run_rollsim("diagnose --vehicle ev --recording '" + rec.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("warning:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("1555.6"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("verdict:"), std::string::npos);
  // Dropping the column (a preset's mapping can be dropped the same way) leaves nothing to warn about.
  const auto dropped = rollsim::test::run_rollsim("diagnose --vehicle ev --column longitude= --recording '" + rec.string() + "'");
  ASSERT_EQ(dropped.exit_code, 0) << dropped.err;
  EXPECT_EQ(dropped.err.find("1555.6"), std::string::npos) << dropped.err;
  // The measurement itself stays strict: speed cannot be dropped.
  const auto no_speed = rollsim::test::run_rollsim("diagnose --vehicle ev --column speed_kmh= --recording '" + rec.string() + "'");
  EXPECT_NE(no_speed.exit_code, 0);
  EXPECT_NE(no_speed.err.find("speed_kmh"), std::string::npos) << no_speed.err;
}
