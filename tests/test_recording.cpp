// Recordings: the shipped real recordings read through the presets against their published facts, and
// every kind of broken input.
#include <gtest/gtest.h>

#include "test_support.hpp"
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "rollsim/common/error.hpp"
#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/recording/recording.hpp"

namespace fs = std::filesystem;
using rollsim::ColumnMapping;
using rollsim::InputError;
using rollsim::load_recording;
using rollsim::Recording;

namespace {

const std::string kRec = std::string(ROLLSIM_SHARED_DIR) + "/data/recordings/";

double integral(const std::vector<double>& t, const std::vector<double>& y) {
  double s = 0.0;
  for (std::size_t i = 0; i + 1 < t.size(); ++i) s += 0.5 * (y[i] + y[i + 1]) * (t[i + 1] - t[i]);
  return s;
}

::testing::AssertionResult has(const std::string& msg, const std::string& part) {
  return msg.find(part) != std::string::npos ? ::testing::AssertionSuccess()
                                             : ::testing::AssertionFailure() << "'" << part << "' not in: " << msg;
}

class RecordingFiles : public rollsim::test::FileFixture {
 protected:
  // A valid 1 Hz recording of `seconds` + 1 rows: time_s, speed_kmh, soc_pct; `edit(t)` may replace a row.
  static std::string trip(int seconds, const std::function<std::string(int)>& edit = nullptr) {
    std::string s = "time_s,speed_kmh,soc_pct\n";
    for (int t = 0; t <= seconds; ++t) {
      std::string row = edit ? edit(t) : "";
      s += row.empty() ? std::to_string(t) + ",36," + std::to_string(90.0 - 0.01 * t) + "\n" : row + "\n";
    }
    return s;
  }
  std::string error_of(const std::string& text, const ColumnMapping& m = {}) {
    const std::string path = write("bad.csv", text);
    try {
      load_recording(path, m);
    } catch (const InputError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no InputError";
    return "";
  }
};

}  // namespace

// SOURCES.md: 61811012 7.48 mi and 733 cm3 (a hot-start UDDS: 7.45 mi published), 61811013 20.5 mi and
// 1369 cm3 (two HWFETs, 2 x 10.26 mi), 61811014 16.0 mi and 1804 cm3 (two US06s, 2 x 8.01 mi).
TEST(RecordingShipped, ArgonneCamryDistancesAndFuel) {
  struct Row {
    const char* file;
    std::size_t rows;
    double miles, fuel_cm3;
  };
  const Row rows[] = {{"61811012_test_data.csv", 1404, 7.48, 733},
                      {"61811013_test_data.csv", 1575, 20.5, 1369},
                      {"61811014_test_data.csv", 1320, 16.0, 1804}};
  const ColumnMapping m = rollsim::preset_mapping("anl_d3");
  for (const auto& r : rows) {
    SCOPED_TRACE(r.file);
    const Recording rec = load_recording(kRec + "anl_d3_2018_toyota_camry/" + r.file, m);
    EXPECT_EQ(rec.time_s.size(), r.rows);
    EXPECT_EQ(rec.time_s.front(), 0.0);  // written "-0.0"
    EXPECT_NEAR(rec.distance_m() / 1609.344, r.miles, 0.05 + 0.003 * r.miles);
    ASSERT_TRUE(rec.fuel_rate_m3ps.has_value());
    EXPECT_NEAR(integral(rec.time_s, *rec.fuel_rate_m3ps) * 1e6, r.fuel_cm3, 1.0);  // m3 -> cm3
    EXPECT_FALSE(rec.soc_fraction.has_value());
    EXPECT_FALSE(rec.battery_power_w.has_value());
    EXPECT_TRUE(rec.repairs.empty()) << rec.repairs.front();
  }
}

// SOURCES.md: 1 Hz on-road Twizy trips (light EV, about 6.1 kWh), SOC in %, speed in km/h, GPS altitude.
TEST(RecordingShipped, TwizyTripsArePlausible) {
  const ColumnMapping m = rollsim::preset_mapping("rsk_twizy");
  int files = 0;
  for (const auto& entry : fs::directory_iterator(kRec + "rsk_renault_twizy")) {
    if (entry.path().extension() != ".csv") continue;
    SCOPED_TRACE(entry.path().filename().string());
    ++files;
    const Recording rec = load_recording(entry.path().string(), m);
    // Trips of 1 to 3 hours, at 1 Hz without gaps.
    EXPECT_GT(rec.duration_s(), 3600.0);
    EXPECT_LT(rec.duration_s(), 3.0 * 3600.0);
    EXPECT_NEAR(rec.duration_s(), static_cast<double>(rec.time_s.size() - 1), 1e-9);
    ASSERT_TRUE(rec.soc_fraction && rec.elevation_m && rec.ambient_temp_k && rec.latitude_deg && rec.longitude_deg);
    // State of charge falls by 40 to 85 points over a trip; a Twizy (80 km/h top speed) covers 30-70 km.
    const double soc_drop = rec.soc_fraction->front() - rec.soc_fraction->back();
    EXPECT_GT(soc_drop, 0.40);
    EXPECT_LT(soc_drop, 0.85);
    EXPECT_GT(rec.distance_m(), 30e3);
    EXPECT_LT(rec.distance_m(), 70e3);
    // Energy per distance from the SOC drop of a 6.1 kWh pack: 50-150 Wh/km for a light quadricycle.
    const double wh_per_km = soc_drop * 6100.0 / (rec.distance_m() / 1000.0);
    EXPECT_GT(wh_per_km, 50.0);
    EXPECT_LT(wh_per_km, 150.0);
    // Rabat-Sale-Kenitra: about 34 N, 6.7 W, near sea level; ambient 10-35 C.
    for (double v : *rec.latitude_deg) EXPECT_NEAR(v, 34.0, 0.3);
    for (double v : *rec.longitude_deg) EXPECT_NEAR(v, -6.75, 0.3);
    for (double v : *rec.ambient_temp_k) EXPECT_NEAR(v - 273.15, 22.5, 12.5);
  }
  EXPECT_EQ(files, 7);
  // Some Twizy files hold corrupted Date cells (e.g. "90/02/2032"): the clock is used and that is reported.
  const Recording rec = load_recording(kRec + "rsk_renault_twizy/T1_03_29_2021.csv", m);
  ASSERT_EQ(rec.repairs.size(), 1u);
  EXPECT_TRUE(has(rec.repairs[0], "90/02/2032"));
  EXPECT_NEAR(rec.time_s.front(), 11 * 3600 + 13 * 60 + 45, 1e-9);  // clock 11:13:45
  // T1_06_30_2021_2 logs latitude 0 for 4 s (lines 3206-3209, no GPS fix): read as missing and bridged.
  const Recording gps = load_recording(kRec + "rsk_renault_twizy/T1_06_30_2021_2.csv", m);
  ASSERT_EQ(gps.repairs.size(), 2u);
  EXPECT_TRUE(has(gps.repairs[0], "4 value(s) of exactly 0"));
  EXPECT_TRUE(has(gps.repairs[1], "4 missing value(s) in 1 run(s)"));
}

TEST(RecordingMapping, OptionsParseAndErrorsNameTheOption) {
  ColumnMapping m;
  rollsim::parse_column_option("speed_kmh=Dyno_Spd[mph]", m);
  rollsim::parse_column_option("battery_current_a='I = pack [A]'", m);  // '=' inside, quotes kept by a shell
  rollsim::parse_scale_option("speed_kmh=1.609344", m);
  rollsim::parse_scale_option("battery_current_a=-1", m);
  EXPECT_EQ(m.source_for_canonical.at("speed_kmh"), "Dyno_Spd[mph]");
  EXPECT_EQ(m.source_for_canonical.at("battery_current_a"), "I = pack [A]");
  EXPECT_DOUBLE_EQ(m.scale_for_canonical.at("speed_kmh"), 1.609344);
  EXPECT_DOUBLE_EQ(m.scale_for_canonical.at("battery_current_a"), -1.0);
  auto column_error = [](const std::string& text) {
    ColumnMapping mm;
    rollsim::parse_column_option("soc_pct=Soc", mm);
    try {
      rollsim::parse_column_option(text, mm);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  auto scale_error = [](const std::string& text) {
    ColumnMapping mm;
    try {
      rollsim::parse_scale_option(text, mm);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_TRUE(has(column_error("speed_kmh"), "--column 'speed_kmh'"));
  EXPECT_TRUE(has(column_error("speed_kmh"), "CANONICAL="));
  EXPECT_TRUE(has(column_error("velocity=Speed"), "'velocity' is not a canonical column"));
  EXPECT_TRUE(has(column_error("velocity=Speed"), "speed_kmh"));
  EXPECT_TRUE(has(column_error("speed_kmh="), "cannot be dropped"));
  EXPECT_TRUE(has(column_error("soc_pct=SOC2"), "already mapped"));
  EXPECT_TRUE(has(scale_error("speed_kmh=fast"), "--scale 'speed_kmh=fast'"));
  EXPECT_TRUE(has(scale_error("speed_kmh=fast"), "not a number"));
  EXPECT_TRUE(has(scale_error("speed_kmh=0"), "non-zero"));
  EXPECT_TRUE(has(scale_error("speed_kmh=nan"), "finite"));
  EXPECT_TRUE(has(scale_error("time_s=2"), "cannot be scaled"));
  EXPECT_TRUE(has(scale_error("speedkmh=2"), "not a canonical column"));
  EXPECT_THROW(rollsim::preset_mapping("camry"), InputError);
  // Options override a preset.
  ColumnMapping over;
  rollsim::parse_column_option("speed_kmh=GpsSpeed", over);
  const auto merged = rollsim::merge_mapping(rollsim::preset_mapping("rsk_twizy"), over);
  EXPECT_EQ(merged.source_for_canonical.at("speed_kmh"), "GpsSpeed");
  EXPECT_EQ(merged.source_for_canonical.at("soc_pct"), "Soc");
}

TEST_F(RecordingFiles, MappingFromVehicleYaml) {
  const std::string path = write("v.yaml",
                                 "recording_columns:\n  speed_kmh: 'Dyno_Spd[mph]'\n  fuel_rate_lph: Fuel\n"
                                 "recording_scale:\n  speed_kmh: 1.609344\n");
  auto y = rollsim::YamlMap::load_file(path);
  const auto m = rollsim::column_mapping_from_yaml(y);
  y.finish();
  EXPECT_EQ(m.source_for_canonical.at("speed_kmh"), "Dyno_Spd[mph]");
  EXPECT_DOUBLE_EQ(m.scale_for_canonical.at("speed_kmh"), 1.609344);
  auto bad = rollsim::YamlMap::load_file(write("b.yaml", "recording_scale:\n  speed: 2\n"));
  try {
    rollsim::column_mapping_from_yaml(bad);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_TRUE(has(e.what(), "b.yaml: key 'recording_scale.speed'"));
  }
  auto bad2 = rollsim::YamlMap::load_file(write("c.yaml", "recording_scale:\n  speed_kmh: fast\n"));
  EXPECT_THROW(rollsim::column_mapping_from_yaml(bad2), InputError);
}

TEST_F(RecordingFiles, UnitsScalesAndSignConventions) {
  // 10 Hz, 70 s: power in kW, V and I with I logged negative when discharging, fuel in l/h, temperature in C.
  std::string s = "t,v_mph,P,U,I,fuel,T,grade_pct\n";
  for (int i = 0; i <= 700; ++i) {
    s += std::to_string(i * 0.1) + ",10,5,400,-12.5,3.6,20,2\n";
  }
  ColumnMapping m;
  for (const char* o : {"time_s=t", "speed_kmh=v_mph", "battery_power_kw=P", "battery_voltage_v=U",
                        "battery_current_a=I", "fuel_rate_lph=fuel", "ambient_temp_c=T"}) {
    rollsim::parse_column_option(o, m);
  }
  rollsim::parse_scale_option("speed_kmh=1.609344", m);
  rollsim::parse_scale_option("battery_current_a=-1", m);
  const Recording r = load_recording(write("ok.csv", s), m);
  EXPECT_NEAR(r.speed_mps[5], 10 * 1609.344 / 3600.0, 1e-12);
  EXPECT_DOUBLE_EQ((*r.battery_power_w)[0], 5000.0);
  EXPECT_DOUBLE_EQ((*r.battery_current_a)[0], 12.5);
  EXPECT_NEAR((*r.fuel_rate_m3ps)[0], 1e-6, 1e-18);  // 3.6 l/h = 1 cm3/s
  EXPECT_DOUBLE_EQ((*r.ambient_temp_k)[0], 293.15);
  EXPECT_DOUBLE_EQ((*r.grade)[0], 0.02);
  EXPECT_NEAR(r.duration_s(), 70.0, 1e-9);
}

TEST_F(RecordingFiles, ShortNanRunsBridgedLongRunsRejected) {
  // Speed missing on 4 rows (t = 10..13) and SOC as "NaN" on 5 (t = 20..24): bridged, linear, reported.
  const std::string ok = trip(100, [](int t) -> std::string {
    if (t >= 10 && t <= 13) return std::to_string(t) + ",," + std::to_string(90.0 - 0.01 * t);
    if (t >= 20 && t <= 24) return std::to_string(t) + ",36,NaN";
    return "";
  });
  const Recording r = load_recording(write("ok.csv", ok), {});
  EXPECT_DOUBLE_EQ(r.speed_mps[11], 10.0);
  EXPECT_NEAR((*r.soc_fraction)[22], 0.90 - 0.0022, 1e-12);
  ASSERT_EQ(r.repairs.size(), 2u);
  EXPECT_TRUE(has(r.repairs[0], "speed_kmh"));
  EXPECT_TRUE(has(r.repairs[0], "4 missing"));
  EXPECT_TRUE(has(r.repairs[1], "soc_pct"));
  // Six missing seconds: an error naming the rows (lines 22-27 hold t = 20..25) and the column.
  const std::string m = error_of(trip(100, [](int t) -> std::string {
    return t >= 20 && t <= 25 ? std::to_string(t) + ",36," : "";
  }));
  EXPECT_TRUE(has(m, "lines 22-27, column 'soc_pct'"));
  EXPECT_TRUE(has(m, "6 missing values"));
}

TEST_F(RecordingFiles, GapsAreKeptAndReported) {
  // Samples 30..39 absent: a 11 s step between t = 29 and t = 40.
  const std::string text = trip(100, [](int t) -> std::string { return t >= 30 && t < 40 ? "#skip" : ""; });
  std::string filtered;
  std::size_t pos = 0;
  while (pos < text.size()) {
    const auto e = text.find('\n', pos);
    const std::string line = text.substr(pos, e - pos);
    if (line != "#skip") filtered += line + "\n";
    pos = e + 1;
  }
  const Recording r = load_recording(write("gap.csv", filtered), {});
  EXPECT_EQ(r.time_s.size(), 91u);
  ASSERT_EQ(r.repairs.size(), 1u);
  EXPECT_TRUE(has(r.repairs[0], "11 s between lines 31-32"));
}

TEST_F(RecordingFiles, ClockTimeAcrossMidnight) {
  auto clock_file = [](bool date_advances) {
    std::string s = "Date,Time,Soc,Speed\n";
    for (int i = 0; i <= 90; ++i) {
      const int c = (23 * 3600 + 59 * 60 + 20 + i) % 86400;
      char buf[64];
      std::snprintf(buf, sizeof buf, "%s,%02d:%02d:%02d,80,20\n",
                    (c >= 23 * 3600 || !date_advances) ? "1/1/2024" : "1/2/2024", c / 3600, c / 60 % 60, c % 60);
      s += buf;
    }
    return s;
  };
  ColumnMapping m;
  for (const char* o : {"time_s=Time", "date=Date", "soc_pct=Soc", "speed_kmh=Speed"}) rollsim::parse_column_option(o, m);
  const Recording r = load_recording(write("mid.csv", clock_file(true)), m);
  EXPECT_DOUBLE_EQ(r.time_s.front(), 23 * 3600 + 59 * 60 + 20);
  EXPECT_DOUBLE_EQ(r.duration_s(), 90.0);  // 23:59:20 -> 00:00:50 next day
  EXPECT_TRUE(r.repairs.empty());
  // The clock wraps but the date does not change: time went backwards.
  const std::string e = error_of(clock_file(false), m);
  EXPECT_TRUE(has(e, "column 'Time'"));
  EXPECT_TRUE(has(e, "backwards"));
  // Without a Date column the wrap alone is read as midnight.
  ColumnMapping no_date;
  for (const char* o : {"time_s=Time", "soc_pct=Soc", "speed_kmh=Speed"}) rollsim::parse_column_option(o, no_date);
  EXPECT_DOUBLE_EQ(load_recording(write("mid2.csv", clock_file(false)), no_date).duration_s(), 90.0);
}

TEST_F(RecordingFiles, BadInputNamesFileRowAndColumn) {
  std::string m;
  // Missing file.
  EXPECT_THROW(load_recording((dir_ / "none.csv").string(), {}), InputError);
  // Missing required column: found columns listed, and the mapping suggested as the front end says it (the library
  // alone names no front end's option: before session 14 a Python user was told to use --column).
  m = error_of("t,speed_kmh,soc_pct\n0,1,2\n");
  EXPECT_TRUE(has(m, "missing required column 'time_s'"));
  EXPECT_TRUE(has(m, "found columns: 't', 'speed_kmh', 'soc_pct'"));
  EXPECT_TRUE(has(m, "map a source column to time_s")) << m;
  EXPECT_FALSE(has(m, "--column")) << m;
  ColumnMapping cli;
  cli.how_to_map = "with --column CANONICAL=SOURCE";
  EXPECT_TRUE(has(error_of("t,speed_kmh,soc_pct\n0,1,2\n", cli), "map a source column to time_s with --column time_s=SOURCE"));
  // A mapping naming a column the file lacks.
  ColumnMapping wrong;
  rollsim::parse_column_option("speed_kmh=Dyno_Spd", wrong);
  m = error_of(trip(70), wrong);
  EXPECT_TRUE(has(m, "'Dyno_Spd' (mapped to speed_kmh) is not in the file"));
  // Text in a number column.
  m = error_of(trip(70, [](int t) -> std::string { return t == 7 ? "7,fast,89" : ""; }));
  EXPECT_TRUE(has(m, "bad.csv: line 9, column 'speed_kmh'"));
  EXPECT_TRUE(has(m, "'fast' is not a number"));
  m = error_of(trip(70, [](int t) -> std::string { return t == 7 ? "7,36,inf" : ""; }));
  EXPECT_TRUE(has(m, "line 9, column 'soc_pct'"));
  // Time repeating and going backwards: both rows named.
  m = error_of(trip(70, [](int t) -> std::string { return t == 7 ? "6,36,89" : ""; }));
  EXPECT_TRUE(has(m, "line 9, column 'time_s'"));
  EXPECT_TRUE(has(m, "the same as 6 on line 8"));
  m = error_of(trip(70, [](int t) -> std::string { return t == 7 ? "6.0,36,89" : ""; }));
  EXPECT_FALSE(has(m, "double precision"));  // one number written two ways
  // Epoch seconds at a fine step read as one double: precision is named as why.
  m = error_of(trip(70, [](int t) -> std::string {
    return t == 6 ? "1e16,36,89" : t == 7 ? "1.0000000000000001e16,36,89" : "";
  }));
  EXPECT_TRUE(has(m, "one number in double precision"));
  m = error_of(trip(70, [](int t) -> std::string { return t == 7 ? "5,36,89" : ""; }));
  EXPECT_TRUE(has(m, "before 6 on line 8"));
  m = error_of(trip(70, [](int t) -> std::string { return t == 7 ? ",36,89" : ""; }));
  EXPECT_TRUE(has(m, "line 9, column 'time_s'"));
  // Shorter than a minute.
  m = error_of(trip(50));
  EXPECT_TRUE(has(m, "lasts 50 s"));
  EXPECT_TRUE(has(m, "at least 60 s"));
  // No energy channel.
  std::string no_energy = "time_s,speed_kmh,elevation_m\n";
  for (int t = 0; t <= 70; ++t) no_energy += std::to_string(t) + ",30,100\n";
  m = error_of(no_energy);
  EXPECT_TRUE(has(m, "no energy channel"));
  EXPECT_TRUE(has(m, "map a source column to one of them")) << m;
  EXPECT_TRUE(has(error_of(no_energy, cli), "one of them with --column CANONICAL=SOURCE"));
  // Voltage without current.
  std::string half = "time_s,speed_kmh,battery_voltage_v\n";
  for (int t = 0; t <= 70; ++t) half += std::to_string(t) + ",30,350\n";
  EXPECT_TRUE(has(error_of(half), "no battery_current_a"));
  // Out of range: SOC above 100 %, clearly negative speed; sample rate outside 1-100 Hz.
  m = error_of(trip(70, [](int t) -> std::string { return t == 3 ? "3,36,140" : ""; }));
  EXPECT_TRUE(has(m, "line 5, column 'soc_pct'"));
  EXPECT_TRUE(has(m, "[0, 100]"));
  m = error_of(trip(70, [](int t) -> std::string { return t == 3 ? "3,-20,89" : ""; }));
  EXPECT_TRUE(has(m, "line 5, column 'speed_kmh'"));
  std::string slow = "time_s,speed_kmh,soc_pct\n";
  for (int t = 0; t <= 100; t += 5) slow += std::to_string(t) + ",30,80\n";
  EXPECT_TRUE(has(error_of(slow), "1 to 100 Hz"));
  // A column with no value at all.
  std::string empty_col = "time_s,speed_kmh,soc_pct\n";
  for (int t = 0; t <= 70; ++t) empty_col += std::to_string(t) + ",30,\n";
  EXPECT_TRUE(has(error_of(empty_col), "holds no value"));
  // Clock text that is not a time.
  std::string bad_clock = "time_s,speed_kmh,soc_pct\n10:00:00,1,80\n10:00:01,1,80\n10:61:02,1,80\n";
  EXPECT_TRUE(has(error_of(bad_clock), "line 4, column 'time_s'"));
  // Slightly negative speed (standstill noise) is set to zero and reported.
  const Recording r = load_recording(write("neg.csv", trip(70, [](int t) -> std::string { return t == 3 ? "3,-0.2,89" : ""; })), {});
  EXPECT_EQ(r.speed_mps[3], 0.0);
  ASSERT_EQ(r.repairs.size(), 1u);
  EXPECT_TRUE(has(r.repairs[0], "set to 0"));
}

// A GPS position the diagnosis does not need: a glitch there is a warning and a missing value, never an abort, and a
// mapping to "" (--column longitude=) drops the column, a preset's included.
TEST_F(RecordingFiles, GpsGlitchIsAWarningAndColumnsCanBeDropped) {
  std::string text = "time_s,speed_kmh,soc_pct,latitude,longitude\n";
  for (int t = 0; t <= 70; ++t)
    text += std::to_string(t) + ",36,80," + (t == 30 ? "48.1,1555.6" : "48.1,11.5") + "\n";
  const Recording r = load_recording(write("gps.csv", text), {});
  ASSERT_TRUE(r.longitude_deg.has_value());
  EXPECT_DOUBLE_EQ((*r.longitude_deg)[30], 11.5);  // bridged from its neighbours
  ASSERT_EQ(r.repairs.size(), 2u);  // the warning, then the bridge
  EXPECT_TRUE(has(r.repairs[0], "warning:"));
  EXPECT_TRUE(has(r.repairs[0], "line 32: '1555.6'"));
  EXPECT_TRUE(has(r.repairs[1], "bridged"));
  // A GPS column too broken to bridge (a 20 s dropout written as text) is dropped with a warning.
  std::string broken = "time_s,speed_kmh,soc_pct,latitude\n";
  for (int t = 0; t <= 70; ++t) broken += std::to_string(t) + ",36,80," + (t >= 20 && t < 40 ? "nofix" : "48.1") + "\n";
  const Recording b = load_recording(write("broken.csv", broken), {});
  EXPECT_FALSE(b.latitude_deg.has_value());
  ASSERT_FALSE(b.repairs.empty());
  EXPECT_TRUE(has(b.repairs.back(), "dropped"));
  // Dropped by mapping: not read at all; the measurement columns stay strict.
  ColumnMapping drop;
  rollsim::parse_column_option("longitude=", drop);
  const Recording d = load_recording(write("gps.csv", text), drop);
  EXPECT_FALSE(d.longitude_deg.has_value());
  const auto twizy_dropped = rollsim::merge_mapping(rollsim::preset_mapping("rsk_twizy"), drop);
  EXPECT_EQ(twizy_dropped.source_for_canonical.at("longitude"), "");
  EXPECT_TRUE(has(error_of(trip(70, [](int t) -> std::string { return t == 3 ? "3,36,140" : ""; })), "[0, 100]"));
}
