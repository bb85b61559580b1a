#include "rollsim/validate/epa_test_car.hpp"

#include <algorithm>
#include <cmath>

#include "rollsim/common/csv.hpp"
#include "rollsim/common/error.hpp"
#include "rollsim/common/text.hpp"
#include "rollsim/common/units.hpp"

namespace rollsim::validate {

namespace {

constexpr double kKgPerLb = 0.45359237;
using units::kNPerLbf;
using units::kMpsPerMph;

bool has(const std::string& text, const char* part) { return text.find(part) != std::string::npos; }

EpaCycle cycle_of(const std::string& procedure) {
  const std::string p = lower_ascii(procedure);
  if (has(p, "20 degree") || has(p, "cold co")) return EpaCycle::cold;
  if (has(p, "charge depleting udds")) return EpaCycle::cd_udds;
  if (has(p, "charge depleting highway")) return EpaCycle::cd_highway;
  if (has(p, "charge depleting us06")) return EpaCycle::cd_us06;
  if (has(p, "sc03")) return EpaCycle::sc03;
  if (has(p, "us06")) return EpaCycle::us06;
  if (p == "hwfe") return EpaCycle::hwfet;
  if (has(p, "federal fuel") || has(p, "cvs 75")) return EpaCycle::ftp75;
  return EpaCycle::other;
}

EpaFuel fuel_of(const std::string& text) {
  const std::string f = lower_ascii(text);
  if (has(f, "cold co")) return EpaFuel::cold_test_fuel;
  if (f == "electricity") return EpaFuel::electricity;
  if (has(f, "hydrogen")) return EpaFuel::hydrogen;
  if (has(f, "e85")) return EpaFuel::e85;
  if (has(f, "diesel")) return EpaFuel::diesel;
  if (has(f, "gasoline")) return EpaFuel::petrol;
  return EpaFuel::other;
}

EpaTransmission transmission_of(const std::string& text) {
  const std::string t = lower_ascii(text);
  if (has(t, "continuously variable")) return EpaTransmission::cvt;
  if (has(t, "manual")) return EpaTransmission::clutch;  // manual, automated manual (incl. dual clutch)
  if (has(t, "automatic")) return EpaTransmission::automatic;  // incl. semi-automatic (with a manual mode)
  return EpaTransmission::other;
}

constexpr const char* kAdfeWeight = "ADFE Equiv. Test Weight (lbs.)";
constexpr const char* kAdfeNv = "ADFE N/V Ratio";
constexpr const char* kAdfePower = "ADFE Total Road Load HP";

}  // namespace

std::string field_problem(const EpaTestRow& row, const std::string& column) {
  const auto it = row.unusable.find(column);
  return column + (it == row.unusable.end() ? " is empty" : " " + it->second);
}

const char* missing_derived_field(const EpaTestRow& row) {
  if (!row.derived) return nullptr;
  if (!row.derived->test_mass_kg) return kAdfeWeight;
  if (!row.derived->engine_radps_per_mps) return kAdfeNv;
  if (!row.derived->road_load_power_w) return kAdfePower;
  return nullptr;
}

double target_road_load_n(const EpaTestRow& row, double speed_mps) {
  return *row.road_a_n + speed_mps * (*row.road_b_n_s_per_m + speed_mps * *row.road_c_n_s2_per_m2);
}

EpaTestRow result_configuration(const EpaTestRow& row) {
  if (!row.derived || missing_derived_field(row) || !row.road_a_n || !row.road_b_n_s_per_m || !row.road_c_n_s2_per_m2) return row;
  const double tested_power_w = target_road_load_n(row, kRoadLoadPowerSpeed_mps) * kRoadLoadPowerSpeed_mps;
  if (!(tested_power_w > 0.0)) return row;
  EpaTestRow r = row;
  r.test_mass_kg = row.derived->test_mass_kg;
  r.engine_radps_per_mps = row.derived->engine_radps_per_mps;
  const double scale = *row.derived->road_load_power_w / tested_power_w;
  *r.road_a_n *= scale;
  *r.road_b_n_s_per_m *= scale;
  *r.road_c_n_s2_per_m2 *= scale;
  return r;
}

std::string to_string(EpaCycle c) {
  switch (c) {
    case EpaCycle::ftp75: return "FTP-75";
    case EpaCycle::hwfet: return "HWFET";
    case EpaCycle::us06: return "US06";
    case EpaCycle::cd_udds: return "CD UDDS";
    case EpaCycle::cd_highway: return "CD HWFET";
    case EpaCycle::cd_us06: return "CD US06";
    case EpaCycle::sc03: return "SC03";
    case EpaCycle::cold: return "cold";
    case EpaCycle::other: return "other";
  }
  return "other";
}

std::string to_string(EpaFuel f) {
  switch (f) {
    case EpaFuel::petrol: return "petrol";
    case EpaFuel::diesel: return "diesel";
    case EpaFuel::e85: return "E85";
    case EpaFuel::electricity: return "electric";
    case EpaFuel::hydrogen: return "hydrogen";
    case EpaFuel::cold_test_fuel: return "cold-test fuel";
    case EpaFuel::other: return "other";
  }
  return "other";
}

std::string to_string(SkipReason r) {
  switch (r) {
    case SkipReason::none: return "";
    case SkipReason::no_measured_result: return "no measured result";
    case SkipReason::absurd_measured_result: return "measured result outside any car of its kind";
    case SkipReason::air_conditioning_test: return "SC03 air-conditioning test: no cabin or air-conditioning model";
    case SkipReason::cold_test: return "cold-ambient test (-7 degC): no cold-ambient model";
    case SkipReason::other_procedure: return "test procedure not simulated";
    case SkipReason::hybrid: return "hybrid or plug-in hybrid: no hybrid model";
    case SkipReason::duplicate_test: return "the same test as an earlier line (counted once)";
    case SkipReason::conflicting_repeat: return "test number repeated with a different vehicle or result";
    case SkipReason::inconsistent_result: return "measured result contradicts the row's own exhaust carbon";
    case SkipReason::fuel_cell: return "hydrogen fuel cell: no fuel-cell model";
    case SkipReason::unsupported_fuel: return "fuel without properties here";
    case SkipReason::unknown_unit: return "result in a unit not given for its fuel";
    case SkipReason::missing_field: return "missing or unreadable field";
    case SkipReason::absurd_field: return "field outside its physical range";
    case SkipReason::cannot_follow_cycle: return "the car from the row cannot follow the cycle (the driver keeps within 2 mph)";
    case SkipReason::simulation_failed: return "simulation failed";
  }
  return "";
}

std::vector<EpaTestRow> read_epa_test_car_list(const std::string& path) {
  const CsvTable t = read_csv(path);
  auto col = [&](const std::string& name) {
    const auto c = t.column(name);
    if (!c) throw InputError(path, "no column '" + name + "' (an EPA Test Car List file has it); found: " + t.columns_list());
    return *c;
  };
  const std::size_t c_test = col("Test Number"), c_make = col("Represented Test Veh Make"),
                    c_model = col("Represented Test Veh Model"), c_id = col("Test Vehicle ID"),
                    c_proc = col("Test Procedure Description"), c_fuel = col("Test Fuel Type Description"),
                    c_trans = col("Tested Transmission Type"), c_drive = col("Drive System Description"),
                    c_etw = col("Equivalent Test Weight (lbs.)"), c_disp = col("Test Veh Displacement (L)"),
                    c_hp = col("Rated Horsepower"), c_gears = col("# of Gears"), c_nv = col("N/V Ratio"),
                    c_a = col("Target Coef A (lbf)"), c_b = col("Target Coef B (lbf/mph)"),
                    c_c = col("Target Coef C (lbf/mph**2)"), c_fe = col(kResultColumn),
                    c_adfe = col("Analytically Derived FE?"), c_adfe_test = col("ADFE Test Number"),
                    c_adfe_power = col(kAdfePower), c_adfe_etw = col(kAdfeWeight), c_adfe_nv = col(kAdfeNv);
  const std::size_t c_bag[3] = {col("FE Bag 1"), col("FE Bag 2"), col("FE Bag 3")};
  // Required too, though optional until session 21: without them the four-bag hybrid rule and the exhaust-carbon
  // check were switched off in silence, and FE_UNIT was not read at all.
  const std::size_t c_bag4 = col(kFeBag4Column), c_hc = col(kExhaustColumns[0]), c_co = col(kExhaustColumns[1]),
                    c_co2 = col(kExhaustColumns[2]), c_unit = col("FE_UNIT");
  // Optional: only the figure's title reads it.
  const std::optional<std::size_t> c_year = t.column("Model Year");
  if (t.rows.empty()) throw InputError(path, "no test rows: the file has the list's columns but no data line");
  std::vector<EpaTestRow> rows;
  rows.reserve(t.rows.size());
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    const auto& cells = t.rows[i];
    // Two lists joined with `cat` carry the second's header as a row, which was read as a test skipped for its
    // procedure 'Test Procedure Description' (session 24's outside testing).
    if (trim(cells[c_test]) == "Test Number" && trim(cells[c_proc]) == "Test Procedure Description")
      throw InputError(path + ": line " + std::to_string(t.row_line[i]),
                       "repeats the header (two lists joined?): remove the line, or give the lists one by one");
    EpaTestRow r;
    // A cell that is not a finite number leaves its field empty, and its text is kept for the skip to quote (a
    // weight of '4,500' was "empty or not a number" without the text: session 22's outside testing).
    auto unusable = [&](std::size_t c, const std::string& why) {
      r.unusable[t.header[c]] = "'" + trim(cells[c]) + "' " + why;
      return std::nullopt;
    };
    auto number = [&](std::size_t c) -> std::optional<double> {
      const auto v = parse_number(cells[c]);
      if (trim(cells[c]).empty()) return std::nullopt;
      if (!v) return unusable(c, "is not a number");
      if (!std::isfinite(*v)) return unusable(c, "is not a finite number");
      return v;
    };
    // An amount that cannot be negative (a bag's economy, an exhaust mass): a negative one is as unusable as text,
    // not "none" (a negative FE Bag 4 read as no fourth bag, a negative CO2 switched the carbon check off).
    auto amount = [&](std::size_t c) -> std::optional<double> {
      const auto v = number(c);
      if (v && *v < 0.0) return unusable(c, "is negative");
      return v;
    };
    r.line = t.row_line[i];
    r.test_number = trim(cells[c_test]);
    r.make = trim(cells[c_make]);
    r.model = trim(cells[c_model]);
    r.vehicle_id = trim(cells[c_id]);
    r.procedure = trim(cells[c_proc]);
    if (c_year) r.model_year = trim(cells[*c_year]);
    r.cycle = cycle_of(r.procedure);
    r.fuel_text = trim(cells[c_fuel]);
    r.fuel = fuel_of(r.fuel_text);
    r.transmission_text = trim(cells[c_trans]);
    r.transmission = transmission_of(r.transmission_text);
    r.drive_text = trim(cells[c_drive]);
    const std::string d = lower_ascii(r.drive_text);
    r.all_wheel_drive = has(d, "all wheel") || has(d, "4-wheel");
    r.drive_known = d == "2-wheel drive, front" || d == "2-wheel drive, rear" || d == "all wheel drive" ||
                    d == "4-wheel drive" || d == "part-time 4-wheel drive";
    r.fe_unit = trim(cells[c_unit]);
    if (const auto v = number(c_etw)) r.test_mass_kg = *v * kKgPerLb;
    if (const auto v = number(c_disp)) r.displacement_m3 = *v * units::kM3PerLitre;
    if (const auto v = number(c_hp)) r.rated_power_w = *v * units::kWPerHp;
    // Any whole number is kept, so that a negative count is skipped as outside its range, not as missing.
    // (100 gears read as "missing" until session 21: only whole numbers under 100 were kept.)
    if (const auto v = number(c_gears)) {
      if (*v == std::floor(*v) && std::abs(*v) < 1e6) r.gears = static_cast<int>(*v);
      else unusable(c_gears, *v != std::floor(*v) ? "is not a whole number" : "is far outside any gearbox's count");
    }
    if (const auto v = number(c_nv)) r.engine_radps_per_mps = *v * units::kRadpsPerRpm / kMpsPerMph;
    if (const auto v = number(c_a)) r.road_a_n = *v * kNPerLbf;
    if (const auto v = number(c_b)) r.road_b_n_s_per_m = *v * kNPerLbf / kMpsPerMph;
    if (const auto v = number(c_c)) r.road_c_n_s2_per_m2 = *v * kNPerLbf / (kMpsPerMph * kMpsPerMph);
    r.measured = number(c_fe);
    for (int b = 0; b < 3; ++b) r.bag_mpg[b] = number(c_bag[b]);
    r.bag4_mpg = amount(c_bag4);
    r.hc_g_per_mi = amount(c_hc);
    r.co_g_per_mi = amount(c_co);
    r.co2_g_per_mi = amount(c_co2);
    r.adfe_flag = trim(cells[c_adfe]);
    if (lower_ascii(r.adfe_flag) == "yes") {
      EpaTestRow::DerivedConfiguration d;
      d.base_test = trim(cells[c_adfe_test]);
      if (const auto v = number(c_adfe_etw)) d.test_mass_kg = *v * kKgPerLb;
      if (const auto v = number(c_adfe_nv)) d.engine_radps_per_mps = *v * units::kRadpsPerRpm / kMpsPerMph;
      if (const auto v = number(c_adfe_power)) d.road_load_power_w = *v * units::kWPerHp;
      r.derived = std::move(d);
    }
    rows.push_back(std::move(r));
  }
  return rows;
}

}  // namespace rollsim::validate
