// Size designations, the load-index table, tyre files, and the thesis' published trends on shipped tyres.
#include <gtest/gtest.h>

#include "test_support.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "rollsim/common/error.hpp"
#include "rollsim/tyre/tyre_model.hpp"
#include "rollsim/tyre/tyre_spec.hpp"

using namespace rollsim;

namespace {

constexpr double kInch = 0.0254;

std::string tyre_path(const std::string& name) { return std::string(ROLLSIM_SOURCE_DIR) + "/tyres/" + name; }

// Writes `text` to a fresh file in the temp folder and returns its path.
std::string temp_yaml(const std::string& stem, const std::string& text) {
  const auto path = rollsim::test::temp_dir() / (stem + ".yaml");
  std::ofstream(path) << text;
  return path.string();
}

// The InputError message of loading `text`, or "" if it loads.
std::string load_error(const std::string& stem, const std::string& text) {
  try {
    load_tyre_file(temp_yaml(stem, text));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

}  // namespace

TEST(TyreSize, ParsesPlainDesignationsWithAndWithoutSpaces) {
  const TyreSize a = parse_tyre_size("155/70 R19 84Q", "t");
  EXPECT_DOUBLE_EQ(a.section_width_m, 0.155);
  EXPECT_DOUBLE_EQ(a.aspect_ratio, 0.70);
  EXPECT_DOUBLE_EQ(a.rim_diameter_m, 19 * kInch);
  EXPECT_NEAR(a.outer_radius_m, 19 * kInch / 2 + 0.155 * 0.70, 1e-12);
  EXPECT_EQ(a.load_index, 84);
  EXPECT_EQ(a.speed_symbol, "Q");
  EXPECT_EQ(a.prefix, SizePrefix::none);
  EXPECT_FALSE(a.extra_load);

  const TyreSize b = parse_tyre_size("175/65R15 84H", "t");
  EXPECT_DOUBLE_EQ(b.section_width_m, 0.175);
  EXPECT_DOUBLE_EQ(b.aspect_ratio, 0.65);
  EXPECT_EQ(b.load_index, 84);
  EXPECT_EQ(b.speed_symbol, "H");

  // The thesis' 175/70 R14 is "about 0.60 m" in diameter: 14 in rim + 2 x 122.5 mm sidewall = 600.6 mm.
  EXPECT_NEAR(2 * parse_tyre_size("175/70 R14 84T", "t").outer_radius_m, 0.6006, 1e-9);

  const TyreSize c = parse_tyre_size("205/55 r16 91v", "t");  // case does not matter
  EXPECT_EQ(c.load_index, 91);
  EXPECT_EQ(c.speed_symbol, "V");
}

TEST(TyreSize, LoadIndexAndSpeedSymbolAreOptional) {
  const TyreSize a = parse_tyre_size("205/55 R16", "t");
  EXPECT_FALSE(a.load_index.has_value());
  EXPECT_FALSE(a.speed_symbol.has_value());
  const TyreSize b = parse_tyre_size("205/55 R16 91", "t");
  EXPECT_EQ(b.load_index, 91);
  EXPECT_FALSE(b.speed_symbol.has_value());
}

TEST(TyreSize, ParsesPrefixesConstructionAndExtraLoad) {
  const TyreSize p = parse_tyre_size("P205/55R16 91V XL", "t");
  EXPECT_EQ(p.prefix, SizePrefix::passenger);
  EXPECT_DOUBLE_EQ(p.section_width_m, 0.205);
  EXPECT_TRUE(p.extra_load);

  const TyreSize lt = parse_tyre_size("LT245/75R16 121/118S", "t");
  EXPECT_EQ(lt.prefix, SizePrefix::light_truck);
  EXPECT_EQ(lt.load_index, 121);  // single-wheel rating comes first
  EXPECT_EQ(lt.speed_symbol, "S");

  const TyreSize zr = parse_tyre_size("225/45 ZR17 91W", "t");
  EXPECT_DOUBLE_EQ(zr.rim_diameter_m, 17 * kInch);
  EXPECT_EQ(zr.load_index, 91);
  const TyreSize zr2 = parse_tyre_size("225/45ZR17 (94Y)", "t");
  EXPECT_EQ(zr2.load_index, 94);
  EXPECT_EQ(zr2.speed_symbol, "Y");

  EXPECT_TRUE(parse_tyre_size("215/45 R17 91W Reinforced", "t").extra_load);
}

TEST(TyreSize, RejectsWhatDoesNotParseNamingWhereAndValue) {
  for (const std::string bad : {"", "205/55", "205-55R16", "205/55 D16 91V", "205/55 R16 91X", "20/55 R16",
                                "205/55 R", "205/55 R16 91V 92V"}) {
    try {
      parse_tyre_size(bad, "--size");
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const InputError& e) {
      EXPECT_EQ(e.where(), "--size");
      EXPECT_TRUE(contains(e.what(), "'" + bad + "'")) << e.what();
      EXPECT_TRUE(contains(e.what(), "205/55 R16 91V")) << "names the allowed form: " << e.what();
    }
  }
}

TEST(TyreSize, RejectsLoadIndexOutsideTheTable) {
  try {
    parse_tyre_size("175/70 R14 200T", "f.yaml: key 'size'");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_TRUE(contains(e.what(), "200")) << e.what();
    EXPECT_TRUE(contains(e.what(), "outside")) << e.what();
  }
}

// Published ETRTO/ISO values (kg), from the standard table printed on every tyre maker's load-index chart.
TEST(LoadIndex, MatchesPublishedTableValues) {
  const std::pair<int, double> published[] = {{60, 250}, {65, 290}, {70, 335}, {75, 387}, {80, 450},
                                              {84, 500}, {88, 560}, {91, 615}, {94, 670}, {99, 775},
                                              {100, 800}, {105, 925}, {110, 1060}, {115, 1215}, {120, 1400},
                                              {121, 1450}, {125, 1650}};
  for (const auto& [index, kg] : published) {
    ASSERT_TRUE(load_index_max_load_kg(index).has_value()) << index;
    EXPECT_DOUBLE_EQ(*load_index_max_load_kg(index), kg) << "load index " << index;
  }
}

TEST(LoadIndex, CoversAtLeast60To125AndIsSmoothlyIncreasing) {
  // The table is a rounded geometric series: each step adds about 2.5-3 % (x10 every ~90 indices).
  for (int i = 61; i <= 125; ++i) {
    ASSERT_TRUE(load_index_max_load_kg(i - 1) && load_index_max_load_kg(i)) << i;
    const double ratio = *load_index_max_load_kg(i) / *load_index_max_load_kg(i - 1);
    EXPECT_GT(ratio, 1.01) << i;
    EXPECT_LT(ratio, 1.045) << i;
  }
  EXPECT_FALSE(load_index_max_load_kg(-1).has_value());
  EXPECT_FALSE(load_index_max_load_kg(500).has_value());
}

TEST(TyreFile, LoadsADesignatedTyreWithRimAndRating) {
  const TyreSpec t = load_tyre_file(tyre_path("175-70R14.yaml"));
  EXPECT_EQ(t.name, "175-70R14");
  ASSERT_TRUE(t.size.has_value());
  EXPECT_NEAR(t.state.geometry.outer_radius_m, 0.3003, 1e-9);
  EXPECT_NEAR(t.state.geometry.section_width_m, 0.175, 1e-12);
  EXPECT_NEAR(t.state.geometry.rim_radius_m, 7 * kInch, 1e-12);
  EXPECT_NEAR(t.state.pressure_pa, 2.1e5, 1e-6);
  EXPECT_NEAR(t.max_load_n, 500 * 9.80665, 1e-9);
}

TEST(TyreFile, EveryShippedTyreLoads) {
  for (const char* f : {"155-70R19.yaml", "175-65R15.yaml", "175-70R14.yaml", "185-65R15.yaml", "nominal.yaml",
                        "low-rrc.yaml"}) {
    const TyreSpec t = load_tyre_file(tyre_path(f));
    EXPECT_GT(t.max_load_n, 0.0) << f;
    // Every shipped tyre carries the study car's ~4000 N per tyre inside its rating and its domain.
    EXPECT_LT(4000.0, t.max_load_n) << f;
    EXPECT_NO_THROW(evaluate_rolling_resistance(t.state, 4000.0, 80 / 3.6)) << f;
  }
  const TyreSpec nominal = load_tyre_file(tyre_path("nominal.yaml"));
  EXPECT_DOUBLE_EQ(nominal.state.geometry.outer_radius_m, 0.305);
  EXPECT_DOUBLE_EQ(nominal.state.geometry.section_width_m, 0.195);
  const TyreSpec low = load_tyre_file(tyre_path("low-rrc.yaml"));
  EXPECT_DOUBLE_EQ(low.state.geometry.outer_radius_m, 0.330);
  EXPECT_NEAR(low.state.pressure_pa, 3.0e5, 1e-6);
}

TEST(TyreFile, CatalogueHoldsAtLeastTenSizesOfOneLoadClass) {
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(tyre_path("catalogue"))) {
    if (entry.path().extension() != ".yaml") continue;
    const TyreSpec t = load_tyre_file(entry.path().string());
    ASSERT_TRUE(t.size && t.size->load_index) << entry.path();
    EXPECT_GE(*t.size->load_index, 91) << entry.path();
    EXPECT_LE(*t.size->load_index, 94) << entry.path();
    const double p_bar = t.state.pressure_pa / 1e5;
    EXPECT_GE(p_bar, 2.2) << entry.path();
    EXPECT_LE(p_bar, 2.6) << entry.path();
    ++count;
  }
  EXPECT_GE(count, 10);
}

TEST(TyreFile, ExplicitGeometryMeasuredDiameterAndModelOverrides) {
  const std::string path = temp_yaml("explicit", R"(
outer_radius_m: 0.31
section_width_m: 0.2
rim_diameter_in: 16
pressure_bar: 2.4
max_load_kg: 600
model:
  coulomb_damping_n: 150
  elements: 200
)");
  const TyreSpec t = load_tyre_file(path);
  EXPECT_DOUBLE_EQ(t.state.geometry.outer_radius_m, 0.31);
  EXPECT_DOUBLE_EQ(t.state.geometry.rim_radius_m, 8 * kInch);
  EXPECT_DOUBLE_EQ(t.state.constants.coulomb_damping_n, 150);
  EXPECT_EQ(t.state.constants.elements, 200);
  EXPECT_DOUBLE_EQ(t.state.constants.viscous_damping_ns_per_m, 0.5);  // not overridden: the thesis' default
  EXPECT_NEAR(t.max_load_n, 600 * 9.80665, 1e-9);
  EXPECT_EQ(t.name, "explicit");

  const TyreSpec m = load_tyre_file(temp_yaml("measured", "size: \"175/70 R14 84T\"\npressure_bar: 2.1\n"
                                                          "outer_diameter_mm: 598\nload_index: 88\n"));
  EXPECT_DOUBLE_EQ(m.state.geometry.outer_radius_m, 0.299);
  EXPECT_NEAR(m.max_load_n, 560 * 9.80665, 1e-9);  // the file's load index wins over the designation's
}

TEST(TyreFile, BadFilesNameFileKeyValueAndWhatIsAllowed) {
  struct Case {
    const char* stem;
    const char* text;
    const char* must_mention;
  };
  const Case cases[] = {
      {"misspelt", "size: \"175/70 R14 84T\"\npresure_bar: 2.1\n", "presure_bar"},
      {"nopressure", "size: \"175/70 R14 84T\"\n", "pressure_bar"},
      {"zeropressure", "size: \"175/70 R14 84T\"\npressure_bar: 0\n", "must be in [1, 5] bar"},
      {"negpressure", "size: \"175/70 R14 84T\"\npressure_bar: -2\n", "-2"},
      {"nanpressure", "size: \"175/70 R14 84T\"\npressure_bar: .nan\n", "NaN"},
      {"badsize", "size: \"175/70 X14\"\npressure_bar: 2\n", "175/70 X14"},
      {"badindex", "size: \"175/70 R14 201T\"\npressure_bar: 2\n", "201"},
      {"badindex2", "size: \"175/70 R14\"\npressure_bar: 2\nload_index: 300\n", "load_index"},
      {"both", "size: \"175/70 R14\"\nouter_radius_m: 0.3\npressure_bar: 2\n", "outer_radius_m"},
      {"nogeometry", "pressure_bar: 2\n", "size"},
      {"nowidth", "outer_radius_m: 0.3\npressure_bar: 2\n", "section_width_m"},
      {"zerowidth", "outer_radius_m: 0.3\nsection_width_m: 0\npressure_bar: 2\n", "section_width_m"},
      {"negradius", "outer_radius_m: -0.3\nsection_width_m: 0.2\npressure_bar: 2\n", "outer_radius_m"},
      {"bigrim", "outer_radius_m: 0.3\nsection_width_m: 0.2\nrim_diameter_in: 24\npressure_bar: 2\n", "rim"},
      {"modelkey", "size: \"175/70 R14\"\npressure_bar: 2\nmodel:\n  coulomb_damping: 100\n", "model.coulomb_damping"},
      {"oddelements", "size: \"175/70 R14\"\npressure_bar: 2\nmodel:\n  elements: 501\n", "elements"},
  };
  for (const auto& c : cases) {
    const std::string msg = load_error(c.stem, c.text);
    EXPECT_FALSE(msg.empty()) << c.stem << " was accepted";
    EXPECT_TRUE(contains(msg, std::string(c.stem) + ".yaml")) << c.stem << ": names the file: " << msg;
    EXPECT_TRUE(contains(msg, c.must_mention)) << c.stem << ": " << msg;
  }
}

// Plausibility by the size's class (ETRTO/ISO): what a real tyre of the class runs at loads, a unit slip does not.
TEST(TyreFile, PressureAndRatingArePlausibleForTheTyresClass) {
  EXPECT_EQ(load_error("lt", "size: \"LT245/75 R16 120/116S\"\npressure_bar: 5.5\n"), "");
  EXPECT_EQ(load_error("truck", "size: \"315/80 R22.5\"\npressure_bar: 9\n"), "");
  EXPECT_EQ(load_error("geometry", "outer_radius_m: 0.5\nsection_width_m: 0.3\npressure_bar: 9\n"), "");
  EXPECT_EQ(load_error("spare", "size: \"125/70 R16\"\npressure_bar: 4.2\n"), "");
  EXPECT_EQ(load_error("low", "size: \"205/55 R16 91V\"\npressure_bar: 1.2\n"), "");
  EXPECT_EQ(load_error("rating", "size: \"205/55 R16 91V\"\npressure_bar: 2.3\nmax_load_kg: 650\n"), "");
  EXPECT_TRUE(contains(load_error("car", "size: \"205/55 R16 91V\"\npressure_bar: 5.5\n"), "must be in [1, 5] bar"));
  EXPECT_TRUE(contains(load_error("ltpsi", "size: \"LT245/75 R16 120/116S\"\npressure_bar: 10\n"), "must be in [1, 8] bar"));
  EXPECT_TRUE(contains(load_error("truckmpa", "size: \"315/80 R22.5\"\npressure_bar: 0.85\n"), "is it in MPa? (0.85 MPa = 8.5 bar)"));
  EXPECT_TRUE(contains(load_error("index", "size: \"175/70 R14\"\npressure_bar: 2.1\nload_index: 84\nmodel:\n"
                                           "  stiffness_pressure_coeff: 0.00001\n"), "key 'load_index': a rated load of 500 kg"));
}

// The thesis' constants have ranges of their own: 1e300 for a damping printed negative RRCs, and for a stiffness read
// as a rigid wheel that simulated 19 % less energy than the tyre, with or without a rated load (session 25).
TEST(TyreFile, TheThesisConstantsHaveUpperBounds) {
  const std::string head = "size: \"155/70 R19 84Q\"\npressure_bar: 2.5\nmodel:\n";
  for (const char* key : {"viscous_damping_ns_per_m", "coulomb_damping_n", "rotational_drag_kg_per_m2"}) {
    const std::string msg = load_error("damp", head + "  " + key + ": 1e300\n");
    EXPECT_TRUE(contains(msg, std::string("model.") + key + "': 1e+300 is not allowed: must be in [0, ")) << msg;
  }
  for (const char* key : {"stiffness_pressure_coeff", "stiffness_offset_kgf_per_mm"}) {
    const std::string msg = load_error("stiff", head + "  " + key + ": 1e300\n");
    EXPECT_TRUE(contains(msg, std::string("model.") + key + "': the stiffness constants make the tyre")) << msg;
    EXPECT_TRUE(contains(msg, "allowed 0.125 to 8 times")) << msg;
  }
  const std::string unrated = load_error("unrated", "outer_radius_m: 0.35\nsection_width_m: 0.155\npressure_bar: 2.5\nmodel:\n"
                                                    "  stiffness_pressure_coeff: 1e300\n");
  EXPECT_TRUE(contains(unrated, "times as stiff as the thesis' constants")) << unrated;
  // Within the bounds a stiffer or softer tyre is a tyre: 3.6 and 1.3 times the thesis' stiffness.
  EXPECT_EQ(load_error("stiffer", head + "  stiffness_pressure_coeff: 0.1\n"), "");
  EXPECT_EQ(load_error("offset", head + "  stiffness_offset_kgf_per_mm: 10\n"), "");
  EXPECT_EQ(load_error("damped", head + "  viscous_damping_ns_per_m: 5\n  coulomb_damping_n: 400\n  rotational_drag_kg_per_m2: 0.01\n"), "");
}

TEST(TyreFile, DeflectionReachingTheRimIsRejected) {
  // 175/70 R14: sidewall 122.5 mm; at 2.1 bar Kz is about 190 N/mm, so 30 kN deflects ~158 mm: past the rim
  // but still inside the outer radius (300 mm).
  TyreSpec t = load_tyre_file(tyre_path("175-70R14.yaml"));
  try {
    evaluate_rolling_resistance(t.state, 30000.0, 10.0);
    FAIL();
  } catch (const ModelDomainError& e) {
    EXPECT_TRUE(contains(e.what(), "rim")) << e.what();
  }
  // Without the rim, a third of the outer radius bounds it (session 20: the radius alone let it reach the axle).
  t.state.geometry.rim_radius_m = 0.0;
  try {
    evaluate_rolling_resistance(t.state, 30000.0, 10.0);
    FAIL();
  } catch (const ModelDomainError& e) {
    EXPECT_TRUE(contains(e.what(), "over a third of the outer radius")) << e.what();
  }
  EXPECT_NO_THROW(evaluate_rolling_resistance(t.state, 18000.0, 10.0));
}

// ---- The thesis' published trends (docs/tyre-model.md), on the shipped 175/70 R14 at 2.1 bar, 80 % of
// ---- 500 kg x 9.81, 80 km/h. Each within 0.2 percentage points.
namespace {

struct TrendTyre {
  TyreState state = load_tyre_file(tyre_path("175-70R14.yaml")).state;
  double load_n = 0.8 * 500 * 9.81;
  double speed_mps = 80 / 3.6;
  double rrc() const { return evaluate_rolling_resistance(state, load_n, speed_mps).rrc; }
};

double pct_change(double from, double to) { return 100.0 * (to - from) / from; }

}  // namespace

TEST(PublishedTrends, DiameterSixtyToSixtyFiveCentimetres) {
  TrendTyre a, b;
  a.state.geometry.outer_radius_m = 0.300;
  b.state.geometry.outer_radius_m = 0.325;
  EXPECT_NEAR(pct_change(a.rrc(), b.rrc()), -4.84, 0.2);
}

TEST(PublishedTrends, Pressure) {
  TrendTyre base, low, high;
  low.state.pressure_pa = 1.8e5;
  high.state.pressure_pa = 2.9e5;
  EXPECT_NEAR(pct_change(base.rrc(), low.rrc()), 5.6, 0.2);
  EXPECT_NEAR(pct_change(base.rrc(), high.rrc()), -11.3, 0.2);
}

TEST(PublishedTrends, LoadEightyToNinetyPercentFallsInTheModel) {
  TrendTyre a, b;
  b.load_n = 0.9 * 500 * 9.81;
  // The model's -6.5 % (measured tyres rise about +3 %: the model's known wrong load trend).
  EXPECT_NEAR(pct_change(a.rrc(), b.rrc()), -6.5, 0.2);
}

// 185/65 R15, 2.5 bar, 2500 N. The thesis quotes RRC x 1000 "about" 9.8 / 10.5 / 11.0 / 13.8 at 60 / 100 /
// 120 / 180 km/h, read off its plot. The model (exact against the reference CSV) gives about 9.94 / 10.81 /
// 11.40 / 13.78 with the designation's geometry (R = 310.7 mm): +1.4 %, +3.0 %, +3.6 %, -0.1 %. The published
// points through 60/100/120 km/h imply a slightly negative linear term, which the model (k1 >= 0) cannot have,
// so its rise from 60 to 120 km/h is larger than the plotted one. We do not retune constants to hide this:
// 180 km/h is checked within 1 %, the others within 4 %, plus the curve's shape.
TEST(PublishedTrends, SpeedCurveOf185_65R15) {
  const TyreSpec t = load_tyre_file(tyre_path("185-65R15.yaml"));
  const std::pair<double, double> published[] = {{60, 9.8}, {100, 10.5}, {120, 11.0}, {180, 13.8}};
  double previous = 0.0;
  for (const auto& [v_kmh, rrc1000] : published) {
    const double rrc = evaluate_rolling_resistance(t.state, 2500.0, v_kmh / 3.6).rrc * 1000.0;
    const double tolerance = v_kmh == 180 ? 0.01 : 0.04;
    EXPECT_NEAR(rrc / rrc1000, 1.0, tolerance) << v_kmh << " km/h: model " << rrc << ", published " << rrc1000;
    EXPECT_GT(rrc, previous);
    previous = rrc;
  }
  // Curvature (drag ~ V^2): the mean slope over 120..180 km/h is at least 1.5 times that over 60..100 km/h
  // (the published points give 2.7; a pure V^2 rise would give 150/80 = 1.9).
  auto r = [&](double v) { return evaluate_rolling_resistance(t.state, 2500.0, v / 3.6).rrc; };
  EXPECT_GT((r(180) - r(120)) / 60.0, 1.5 * (r(100) - r(60)) / 40.0);
}
