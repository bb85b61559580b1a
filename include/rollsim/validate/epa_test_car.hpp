// The EPA Test Car List as rollsim reads it: one dynamometer test per row, in SI, with the test it is and what it measured.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "rollsim/common/units.hpp"

namespace rollsim::validate {

enum class EpaCycle { ftp75, hwfet, us06, cd_udds, cd_highway, cd_us06, sc03, cold, other };
enum class EpaFuel { petrol, diesel, e85, electricity, hydrogen, cold_test_fuel, other };
enum class EpaTransmission { automatic, cvt, clutch, other };

/// Why a row is not simulated. `none` for a simulated row.
enum class SkipReason {
  none,
  no_measured_result,     ///< RND_ADJ_FE empty or not a number
  absurd_measured_result, ///< outside what any car of its kind achieves (e.g. 4599 mpg)
  air_conditioning_test,  ///< SC03: no cabin or air-conditioning model
  cold_test,              ///< Cold CO and the 20 degF charge-depleting FTP: no cold-ambient model
  other_procedure,        ///< a test procedure rollsim does not know
  hybrid,                 ///< hybrid or plug-in hybrid (identified by rule, see README)
  duplicate_test,         ///< a test the list already gave on an earlier line (one line per aftertreatment device)
  conflicting_repeat,     ///< an earlier line's test number on another vehicle or with another result
  inconsistent_result,    ///< the measured economy contradicts the row's own exhaust carbon (the carbon balance)
  fuel_cell,              ///< hydrogen fuel cell
  unsupported_fuel,       ///< a fuel the list does not use, so without properties here
  unknown_unit,           ///< FE_UNIT is not a unit the row's fuel's results are given in
  missing_field,          ///< a field the car needs is empty or not a number
  absurd_field,           ///< a field outside its physical range
  cannot_follow_cycle,    ///< the car built from the row cannot deliver what the trace demands (its power is absurd)
  simulation_failed,      ///< the model could not be evaluated (its message is the detail)
};

std::string to_string(EpaCycle c);
std::string to_string(EpaFuel f);
std::string to_string(SkipReason r);

/// One test row, converted to SI where it is a physical quantity.
struct EpaTestRow {
  std::size_t line = 0;       ///< 1-based line in the file
  std::string test_number;
  std::string make, model, vehicle_id;
  std::string procedure;      ///< as written
  std::string model_year;     ///< "Model Year" as written; empty where the list has no such column
  std::string fuel_text;      ///< "Test Fuel Type Description" as written
  EpaCycle cycle = EpaCycle::other;
  EpaFuel fuel = EpaFuel::other;
  EpaTransmission transmission = EpaTransmission::other;
  std::string transmission_text;
  std::string drive_text;
  bool all_wheel_drive = false;
  bool drive_known = false;   ///< drive_text is one the list uses (2- or 4-wheel, all-wheel, part-time 4-wheel)
  std::string fe_unit;        ///< FE_UNIT as written: the list gives "MPG" on every row (MPGe for electric cars)
  std::string adfe_flag;      ///< "Analytically Derived FE?" as written: Yes or No
  std::optional<double> test_mass_kg;     ///< equivalent test weight
  std::optional<double> displacement_m3;
  std::optional<double> rated_power_w;
  std::optional<int> gears;
  std::optional<double> engine_radps_per_mps;  ///< N/V ratio (top gear), converted
  std::optional<double> road_a_n, road_b_n_s_per_m, road_c_n_s2_per_m2;  ///< target coefficients
  std::optional<double> measured;         ///< RND_ADJ_FE as published (mpg or mpge)
  std::optional<double> bag_mpg[3];       ///< FE Bag 1..3 (FTP rows)
  /// FE Bag 4: given only where the FTP was run with four bags (the hot start as a whole UDDS), the hybrids'
  /// procedure of SAE J1711 (40 CFR 600.115-11(c)).
  std::optional<double> bag4_mpg;
  /// THC, CO and CO2 [g/mi] as measured over the row's test; empty where the row gives none.
  std::optional<double> hc_g_per_mi, co_g_per_mi, co2_g_per_mi;
  /// "Analytically Derived FE?" Yes: the result was not measured on the vehicle the row describes. EPA derived it
  /// from that vehicle's test (`base_test`) for another configuration, and the ADFE columns hold that
  /// configuration's test weight, N/V ratio and road-load power at 50 mph; the row's own weight, N/V and target
  /// coefficients stay the tested vehicle's (docs/validate-history.md: the list's 305 derived rows whose base test
  /// it also holds). Empty for a measured row.
  struct DerivedConfiguration {
    std::string base_test;
    std::optional<double> test_mass_kg, engine_radps_per_mps, road_load_power_w;
  };
  std::optional<DerivedConfiguration> derived;
  /// The number columns the row fills with something the field cannot be, by column name: "'4,500' is not a number",
  /// "'-5' is negative" (for amounts that cannot be). Such a field is left empty, and a skip quotes this.
  std::map<std::string, std::string> unusable;
};

inline constexpr const char* kResultColumn = "RND_ADJ_FE";
inline constexpr const char* kFeBag4Column = "FE Bag 4";
inline constexpr const char* kExhaustColumns[] = {"THC (g/mi)", "CO (g/mi)", "CO2 (g/mi)"};

/// "COLUMN '4,500' is not a number" where the row gives the column something unusable, "COLUMN is empty" otherwise.
std::string field_problem(const EpaTestRow& row, const std::string& column);

/// The row's target road load [N] at `speed_mps`, A + B v + C v^2; the row must hold all three coefficients.
double target_road_load_n(const EpaTestRow& row, double speed_mps);

/// EPA's road-load horsepower is the target road load's power at this speed, 50 mph.
inline constexpr double kRoadLoadPowerSpeed_mps = 50.0 * units::kMpsPerMph;

/// The row as the car its result belongs to: a measured row as it is; an analytically derived one with the ADFE
/// test mass and N/V ratio, and its target coefficients scaled together so the road load at 50 mph takes the
/// ADFE road-load power (the list gives the derived configuration that one figure, not a curve). A derived row
/// needs its three ADFE fields and a tested road load that is positive at 50 mph (check_car_fields checks both);
/// without them the row is returned as it is.
EpaTestRow result_configuration(const EpaTestRow& row);

/// The first ADFE column a derived row lacks (empty or not a number), or nullptr when it has all three.
const char* missing_derived_field(const EpaTestRow& row);

/// Reads the list (CSV with the EPA's column names). Throws InputError naming the file for a missing file, a
/// missing column or no data line; a bad cell does not throw, it leaves the field empty so the row is skipped by
/// name.
std::vector<EpaTestRow> read_epa_test_car_list(const std::string& path);

}  // namespace rollsim::validate
