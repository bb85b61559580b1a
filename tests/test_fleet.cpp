// Fleet diagnosis: the manifest's groups diagnosed as single diagnoses are, the summary, and the manifest's bad input.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "rollsim/common/error.hpp"
#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/diagnose/fleet.hpp"
#include "test_support.hpp"

using namespace rollsim;

namespace {

const std::string kManifest = std::string(ROLLSIM_SOURCE_DIR) + "/examples/fleet/fleet.csv";
const std::string kRecordings = std::string(ROLLSIM_SHARED_DIR) + "/data/recordings/";

std::string write_manifest(const std::string& name, const std::string& text) {
  const auto path = test::temp_dir() / name;
  std::ofstream(path) << text;
  return path.string();
}

}  // namespace

TEST(Fleet, GroupsFollowTheManifestAndEachEqualsItsOwnDiagnosis) {
  const FleetManifest m = read_fleet_manifest(kManifest);
  ASSERT_EQ(m.groups.size(), 4u);
  EXPECT_EQ(m.groups[0].name, "twizy T1");
  EXPECT_EQ(m.groups[0].recordings.size(), 2u);
  EXPECT_EQ(m.groups[3].recordings.size(), 1u);
  EXPECT_EQ(m.groups[3].recordings[0].line, 7u);
  FleetManifest camry{m.file, {m.groups[2], m.groups[3]}};
  FleetOptions o;
  o.threads = 2;
  const FleetResult r = diagnose_fleet(camry, o);
  ASSERT_EQ(r.entries.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    // The independent path: the diagnose library on the same car and recording, as `rollsim diagnose` runs it.
    const Vehicle v = load_vehicle_file(resolve_data_file("camry_2018", "vehicles", ".yaml", "test"));
    const Diagnosis d = diagnose(v, {load_recording(camry.groups[k].recordings[0].path, camry.groups[k].recordings[0].mapping)}, {});
    EXPECT_EQ(r.entries[k].verdict, d.verdict);
    ASSERT_EQ(r.entries[k].findings.size(), d.findings.size());
    for (std::size_t i = 0; i < d.findings.size(); ++i) {
      EXPECT_EQ(r.entries[k].findings[i].effect, d.findings[i].effect);
      if (!d.findings[i].parameters.empty()) EXPECT_EQ(r.entries[k].findings[i].value, d.findings[i].parameters[0].value);
    }
  }
  // The summary counts each effect once per diagnosis: its share is that count over the diagnoses.
  for (const auto& e : r.effects) {
    std::size_t n = 0;
    for (const auto& entry : r.entries) {
      bool found = false;
      for (const auto& f : entry.findings) found = found || f.effect == e.effect;
      n += found ? 1 : 0;
    }
    EXPECT_EQ(e.groups, n);
    EXPECT_DOUBLE_EQ(e.share_pct, 100.0 * static_cast<double>(n) / 2.0);
  }
}

TEST(Fleet, AMissingRecordingNamesTheManifestLineAndColumn) {
  const std::string path = write_manifest("missing.csv", "group,vehicle,recording\na,ev,nowhere.csv\n");
  const auto r = test::run_rollsim("diagnose --fleet '" + path + "'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("missing.csv: line 2, column 'recording'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("nowhere.csv' not found"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

// A misspelt column was ignored: 'Tyre' and 'scale' named nothing and the group ran without them (session 22's
// outside testing). Every column is one the manifest reads.
TEST(Fleet, AMisspeltColumnIsRefusedNotIgnored) {
  const std::string path = write_manifest("misspelt.csv", "vehicle,recording,preset,Tyre\ntwizy,nowhere.csv,rsk_twizy,x\n");
  const auto r = test::run_rollsim("diagnose --fleet '" + path + "'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("misspelt.csv: line 1: unknown column 'Tyre' (misspelt?); allowed: vehicle, recording, group, tyre"),
            std::string::npos) << r.err;
}

// --json was checked against the manifest alone: a recording or vehicle file it names was overwritten with the
// fleet's JSON, exit 0 (session 21's outside testing). Refused before any diagnosis, as a single diagnosis refuses.
TEST(Fleet, JsonOntoAFileTheManifestNamesIsRefused) {
  const auto dir = test::temp_dir() / "fleet_clobber";
  std::filesystem::create_directories(dir);
  std::filesystem::copy_file(kRecordings + "anl_d3_2018_toyota_camry/61811012_test_data.csv", dir / "a.csv",
                             std::filesystem::copy_options::overwrite_existing);
  std::filesystem::copy_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/camry_2018.yaml", dir / "car.yaml",
                             std::filesystem::copy_options::overwrite_existing);
  std::ofstream(dir / "m.csv") << "vehicle,recording,preset\ncar.yaml,a.csv,anl_d3\n";
  const std::string recording = test::slurp(dir / "a.csv"), car = test::slurp(dir / "car.yaml");
  for (const std::string target : {"a.csv", "car.yaml"}) {
    const auto r = test::run_rollsim("diagnose --fleet '" + (dir / "m.csv").string() + "' --json '" + (dir / target).string() + "'");
    EXPECT_EQ(r.exit_code, 2) << target;
    EXPECT_NE(r.err.find("the same file as"), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
  EXPECT_EQ(test::slurp(dir / "a.csv"), recording);
  EXPECT_EQ(test::slurp(dir / "car.yaml"), car);
}

TEST(Fleet, ABadColumnMappingNamesTheManifestAndTheGroupsLine) {
  const std::string camry = kRecordings + "anl_d3_2018_toyota_camry/61811012_test_data.csv";
  const std::string path = write_manifest(
      "badcol.csv", "group,vehicle,recording,columns\nok,camry_2018," + camry + ",\nbad,camry_2018," + camry +
                        ",speed_kmh=No Such Column\n");
  const auto r = test::run_rollsim("diagnose --fleet '" + path + "'");
  // Bad input met inside a group is bad input: exit 2 and its own message (before session 14: exit 1, "case 2 of 2
  // failed: ...").
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
  EXPECT_EQ(r.err.find("case 2 of 2"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("badcol.csv: group 'bad' (line 3)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("No Such Column"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  // A recording read without its preset lacks the canonical columns: the hint names the manifest's way to map them,
  // not only --column, which --fleet does not take (session 13).
  const std::string twizy = kRecordings + "rsk_renault_twizy/T2_04_26_2021.csv";
  const auto n = test::run_rollsim("diagnose --fleet '" + write_manifest("nopreset.csv", "vehicle,recording\ntwizy," + twizy + "\n") + "'");
  EXPECT_NE(n.exit_code, 0);
  EXPECT_NE(n.err.find("missing required column 'time_s'"), std::string::npos) << n.err;
  EXPECT_NE(n.err.find("map a source column to time_s in the manifest's columns cell (time_s=SOURCE) or with its preset"),
            std::string::npos) << n.err;
  EXPECT_EQ(n.err.find("--column"), std::string::npos) << n.err;
}

TEST(Fleet, PerRecordingOptionsAreRefusedNotIgnored) {
  // The manifest names each group's files; an option meant for one diagnosis must not be dropped silently.
  const std::string path = write_manifest("options.csv", "group,vehicle,recording\na,ev,nowhere.csv\n");
  for (const std::string option : {"--engine-start hot", "--vehicle ev", "--preset anl_d3"}) {
    const auto r = test::run_rollsim("diagnose --fleet '" + path + "' " + option);
    EXPECT_EQ(r.exit_code, 2) << option;
    EXPECT_NE(r.err.find(option.substr(0, option.find(' ')) + ": not allowed with --fleet"), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
}

TEST(Fleet, AManifestWithoutTheRecordingColumnIsRefusedAtItsHeader) {
  const std::string path = write_manifest("nocol.csv", "vehicle,trip\nev,a.csv\n");
  try {
    read_fleet_manifest(path);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("nocol.csv: line 1: missing column 'recording'"), std::string::npos) << e.what();
  }
}

// The summary's median was of whichever first parameter the first diagnosis in the manifest reported: two
// unexplained findings leading with different figures gave a different line in each order (outside testing).
TEST(Fleet, TheSummaryDoesNotDependOnTheManifestsOrder) {
  auto entry = [](const std::string& group, std::vector<FleetFinding> findings) {
    FleetEntry e;
    e.group = group;
    e.findings = std::move(findings);
    return e;
  };
  const FleetEntry a = entry("a", {{"unexplained", "opposite_extra_resistance_ohm", "ohm", -19.757, 0.0}});
  const FleetEntry b = entry("b", {{"unexplained", "residual_to_noise_variance_ratio", "1", 5.383, 0.0}});
  const FleetEntry c = entry("c", {{"unexplained", "residual_to_noise_variance_ratio", "1", 2.0, 0.0}});
  const auto ab = summarise_fleet({a, b, c});
  const auto ba = summarise_fleet({c, b, a});
  ASSERT_EQ(ab.size(), 1u);
  ASSERT_EQ(ba.size(), 1u);
  EXPECT_EQ(ab[0].groups, 3u);
  // Two of the three report the variance ratio first: its median is the fleet's figure, in either order.
  EXPECT_EQ(ab[0].parameter, "residual_to_noise_variance_ratio");
  EXPECT_EQ(ba[0].parameter, ab[0].parameter);
  EXPECT_DOUBLE_EQ(ab[0].median_value, (5.383 + 2.0) / 2.0);
  EXPECT_DOUBLE_EQ(ba[0].median_value, ab[0].median_value);
}

// One diagnosis can name an effect twice (two unexplained findings, each with its own figure). Keyed by effect, the
// fleet's JSON wrote the key twice and every parser kept only the last (outside testing, session 20): it is a list.
TEST(Fleet, JsonKeepsEveryFindingOfADiagnosis) {
  FleetResult r;
  FleetEntry e;
  e.group = "g";
  e.findings = {{"unexplained", "opposite_power_w", "W", -184.4, 0.0}, {"unexplained", "residual_to_noise_variance_ratio", "1", 2.5, 0.0}};
  r.entries.push_back(e);
  const auto json = fleet_json(r);
  ASSERT_EQ(json.size(), 1u);
  const std::string line = json[0].str();
  const auto list = line.find("\"findings\": [{\"effect\": \"unexplained\", \"parameter\": \"opposite_power_w\", \"value\": -184.4");
  EXPECT_NE(list, std::string::npos) << line;
  EXPECT_NE(line.find("}, {\"effect\": \"unexplained\", \"parameter\": \"residual_to_noise_variance_ratio\", \"value\": 2.5", list),
            std::string::npos) << line;
  EXPECT_EQ(line.find("\"unexplained\": {"), std::string::npos) << line;
}

// A group whose recordings carry the ambient column only in part cannot test the ambient laws, and the fleet said
// only nothing_missing (session 27's outside tester): the group's warning goes where warnings go, and into its JSON.
TEST(Fleet, AGroupsWarningsAreSaidBesideItsVerdict) {
  const std::string a = kRecordings + "rsk_renault_twizy/T1_06_30_2021_1.csv", b = kRecordings + "rsk_renault_twizy/T1_06_30_2021_2.csv";
  const std::string m = write_manifest("partial_ambient.csv", "group,vehicle,recording,preset,columns\nt,twizy," + a +
                                                                 ",rsk_twizy,\nt,twizy," + b + ",rsk_twizy,ambient_temp_c=\n");
  const auto json = test::temp_dir() / "partial_ambient.json";
  const test::CmdResult r = test::run_rollsim("diagnose --fleet '" + m + "' --json '" + json.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string said = "ambient_rrc and hvac_ambient not tested: " + b + " has no ambient_temp_c column, where the other 1 "
                           "recording does";
  EXPECT_NE(r.err.find("warning: t: " + said), std::string::npos) << r.err;
  std::ifstream in(json);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\"warnings\": ["), std::string::npos) << text;
  EXPECT_NE(text.find("\"" + said), std::string::npos) << text;
}

// Small figures keep four significant digits (an ambient law's 0.0075 /K printed as 0.007: session 27's outside
// tester); from 1 up, three decimals as before.
TEST(Fleet, SmallFiguresKeepTheirDigits) {
  FleetResult r;
  r.manifest = "m.csv";
  r.entries.push_back({"a", "car", "missing_physics", "battery_power", 4, {{"ambient_rrc", "rrc_change_per_k", "1/K", 0.0075, 0.0}}, {}});
  r.entries.push_back({"b", "car", "missing_physics", "battery_power", 4, {{"unexplained", "ratio", "1", 6.4851, 0.0}}, {}});
  r.effects = summarise_fleet(r.entries);
  const std::string text = fleet_text(r);
  EXPECT_NE(text.find("ambient_rrc (0.0075 1/K)"), std::string::npos) << text;
  EXPECT_NE(text.find("unexplained (6.485 1)"), std::string::npos) << text;
  EXPECT_NE(text.find("0.0075  1/K"), std::string::npos) << text;
}
