// Tyre descriptions as users give them: size designations, the load-index table, and tyre YAML files.
#pragma once

#include <optional>
#include <string>

#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/tyre/tyre_model.hpp"

namespace rollsim {

/// The service prefix of a size designation: none (metric, "205/55 R16"), "P" (P-metric) or "LT" (light truck,
/// EU class C2, whose ISO 28580 conditions and label bands differ from a passenger tyre's).
enum class SizePrefix { none, passenger, light_truck };

/// What a size designation such as "P205/55 R16 91V XL" says, in SI.
struct TyreSize {
  std::string designation;          ///< as written by the user
  SizePrefix prefix = SizePrefix::none;
  double section_width_m = 0.0;     ///< 205 mm
  double aspect_ratio = 0.0;        ///< 0.55
  double rim_diameter_m = 0.0;      ///< 16 in
  double outer_radius_m = 0.0;      ///< rim/2 + width * aspect
  std::optional<int> load_index;    ///< 91
  std::optional<std::string> speed_symbol;  ///< "V"
  bool extra_load = false;          ///< "XL" / "Reinforced"
  /// A light-truck, van or truck tyre (EU class C2 or C3): "LT", a "C" after the rim ("R16C"), a dual load index
  /// ("107/105") or a truck rim (17.5, 19.5, 22.5 in). Its load index holds at its own load-inflation pressure, and
  /// its ISO 28580 point and label bands are not a passenger tyre's.
  bool commercial = false;
};

/// Parses a designation; throws InputError(where, ...) naming `where` (file key or option) if it does not parse
/// or its load index is outside the table.
TyreSize parse_tyre_size(const std::string& designation, const std::string& where);

/// ISO 28580's inflation for a passenger tyre (C1): 250 kPa for extra load, 210 kPa otherwise.
double iso28580_passenger_pressure_pa(const TyreSize& size);

/// Maximum load [kg] of an ETRTO/ISO load index; std::nullopt outside the table (indices 60..125 at least).
std::optional<double> load_index_max_load_kg(int load_index);

/// What a road tyre measures, from a quadricycle's 12-inch wheel to a lorry's 22.5-inch one: a value outside was typed
/// in another unit. One range for a tyre file's geometry and a sweep's width and diameter.
inline constexpr double kRoadTyreWidthMin_m = 0.08, kRoadTyreWidthMax_m = 0.5;
inline constexpr double kRoadTyreDiameterMin_m = 0.3, kRoadTyreDiameterMax_m = 2.5;

/// The speed [m/s] a speed symbol rates the tyre for (ISO 4000-1 / ETRTO: Q 160 km/h, H 210, V 240, Y 300);
/// std::nullopt for Z ("above 240 km/h", no upper figure) and for what is not a symbol.
std::optional<double> speed_symbol_max_mps(const std::string& symbol);

/// A tyre ready for the model: geometry, inflation, model constants, and what is known of its rating.
struct TyreSpec {
  std::string name;                 ///< file stem or a label, for tables
  std::string source;               ///< file path it came from, or "command line"
  std::string description;          ///< free text from the file's `description`
  std::string reference;            ///< where the data comes from (the file's `source` key)
  std::optional<TyreSize> size;     ///< when described by a designation
  TyreState state;                  ///< geometry, pressure_pa, constants
  double max_load_n = 0.0;          ///< rated maximum load at reference pressure; 0 when unknown
};

/// A warning when `speed_mps` exceeds the tyre's speed rating, naming `what` runs that fast; empty otherwise (and for
/// a tyre without a speed symbol). The model still runs there, but no tyre is built or tested for it.
std::string speed_rating_warning(const TyreSpec& tyre, double speed_mps, const std::string& what);

/// Refuses an inflation pressure [bar] outside what a road tyre of this kind runs at (passenger 1-5 bar, light
/// truck 1-8, truck rims 1-10), naming `where` and the likely unit slip (MPa, psi). One rule for a tyre file's
/// `pressure_bar`, `--pressure-bar`, a pressure sweep's ends and Python's `pressure_bar`.
void check_pressure_plausible(double bar, const std::optional<TyreSize>& size, const std::string& where);
/// The same rule for a pressure given in kPa (a fit's measured points), said in kPa.
void check_pressure_plausible_kpa(double kpa, const std::optional<TyreSize>& size, const std::string& where);

/// Loads and validates a tyre YAML file (strict keys; see tyres/README.md for the format).
TyreSpec load_tyre_file(const std::string& path);
/// The same for YAML text in memory (e.g. a Python dict as JSON); `name` stands for the file in errors.
TyreSpec load_tyre_text(const std::string& text, const std::string& name);
/// The same for a mapping already read; its file() names the source.
TyreSpec load_tyre(YamlMap y);

}  // namespace rollsim
