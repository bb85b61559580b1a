// Strict reading of YAML input files: every key is known, every value is checked and named on error.
#pragma once

#include <yaml-cpp/yaml.h>

#include <functional>
#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

namespace rollsim {

/// Allowed range of a number read from input. Bounds are inclusive unless marked open.
struct Range {
  double min = -1e300;
  double max = 1e300;
  bool min_open = false;  ///< true: value must be strictly greater than min
  bool max_open = false;  ///< true: value must be strictly less than max

  static Range positive() { return {0.0, 1e300, true, false}; }
  static Range finite() { return {-1e300, 1e300, false, false}; }  ///< for a check of its own that follows
  static Range non_negative() { return {0.0, 1e300, false, false}; }
  static Range fraction() { return {0.0, 1.0, false, false}; }            ///< [0, 1]
  static Range efficiency() { return {0.0, 1.0, true, false}; }          ///< (0, 1]
  static Range closed(double lo, double hi) { return {lo, hi, false, false}; }
  static Range open_low(double lo, double hi) { return {lo, hi, true, false}; }
  bool contains(double v) const;
  std::string describe() const;  ///< e.g. "must be > 0", "must be in [0, 1]"
  /// describe() for a rejected `v`, also naming the implicit bound it broke (1e308: "at most 1e300").
  std::string describe_for(double v) const;
};

/// `v` if `range` allows it; otherwise an InputError naming `where` (a key, an option, an argument), the value
/// and what is allowed. The one check behind every number a user gives.
double checked_number(double v, const std::string& where, Range range);

/// Another unit a value may have been typed in: its name and the factor from it to the key's own unit.
struct UnitSlip {
  const char* unit;
  double factor;
};

/// "; is it in psi? (19 psi = 1.31 bar)" for the first of `slips` whose reading of `v` lies in `fits` (in `unit`),
/// else "": the end of a message refusing `v` as implausible.
std::string unit_slip_hint(double v, Range fits, const std::string& unit, std::initializer_list<UnitSlip> slips);

/// Refuses at `where` a value outside what is `physical` for its kind: "V unit is not allowed: why; must be in
/// [..] unit", with the unit it would fit in (unit_slip_hint). A vehicle's and a tyre's unit slips alike.
void check_physical(double v, Range physical, const std::string& unit, const std::string& why,
                    std::initializer_list<UnitSlip> slips, const std::string& where);

/// A number given as text on the command line or by the Python API: parsed whole and checked against `range`;
/// throws InputError naming `option`, the text or value, and what is allowed (strtod alone would accept "nan").
double parse_option_number(const std::string& text, const std::string& option, Range range);

/// A whole number given as text (a count: threads, steps), as parse_option_number and also refusing a fraction.
int parse_option_count(const std::string& text, const std::string& option, Range range);

/// A view on one YAML mapping of a file, remembering its path ("vehicle.yaml: body.mass_kg") so that every
/// error names file and key. Keys read are recorded; finish() rejects any key that was never asked for,
/// which catches misspellings ("presure_bar") instead of silently using a default.
class YamlMap {
 public:
  /// Loads `path` and returns its top-level mapping; throws InputError if missing or malformed.
  /// Also rejects a key given twice in one mapping and a key that is not a plain word, at its line.
  static YamlMap load_file(const std::string& path);
  /// The same for YAML text already in memory; `path` names it in errors.
  static YamlMap load_text(const std::string& text, const std::string& path);
  YamlMap(YAML::Node node, std::string file, std::string prefix);

  bool has(const std::string& key) const;
  double number(const std::string& key, Range range);
  double number_or(const std::string& key, double fallback, Range range);
  std::optional<double> optional_number(const std::string& key, Range range);
  std::string string(const std::string& key);
  std::string string_or(const std::string& key, const std::string& fallback);
  std::optional<std::string> optional_string(const std::string& key);
  bool boolean_or(const std::string& key, bool fallback);
  /// A list of numbers, each in range; `min_size` elements at least.
  std::vector<double> numbers(const std::string& key, Range range, std::size_t min_size = 1);
  std::optional<std::vector<double>> optional_numbers(const std::string& key, Range range,
                                                      std::size_t min_size = 1);
  /// A nested mapping; the returned view shares the file name and extends the key path.
  YamlMap map(const std::string& key);
  std::optional<YamlMap> optional_map(const std::string& key);
  /// Marks a key as handled without reading it through this view (e.g. read by a sub-parser).
  void accept(const std::string& key);
  /// Throws InputError naming the first key that was never read, with the allowed keys listed.
  void finish() const;

  const YAML::Node& node() const { return node_; }
  const std::string& file() const { return file_; }
  /// "file: key 'prefix.key'" for error messages about `key` of this mapping.
  std::string where(const std::string& key) const;

 private:
  YAML::Node get(const std::string& key, bool required);
  double to_number(const YAML::Node& n, const std::string& key, Range range) const;

  YAML::Node node_;
  std::string file_;
  std::string prefix_;
  std::vector<std::string> read_keys_;
};

/// Resolves a data file named on the command line, with `.yaml`/`.csv` appended if `extension` is given and missing.
/// A bare name (no folder, no extension: "nedc", "155-70R19") is the shipped file `<data root>/<shipped_dir>/` first,
/// then a file in the current folder; any other name is the path as given first, then the shipped file. Throws
/// InputError naming the option when nothing is found.
std::string resolve_data_file(const std::string& name, const std::string& shipped_dir,
                              const std::string& extension, const std::string& option);

/// resolve_data_file for a name written in another file (a baseline, a manifest): the file of that name beside
/// `referring_file` first, and the not-found error names that folder among the places looked in.
std::string resolve_data_file_beside(const std::string& name, const std::string& referring_file,
                                     const std::string& shipped_dir, const std::string& extension, const std::string& option);

/// The shipped file `name` (or `name` + `extension`) in `<data root>/<shipped_dir>/`, if there is one.
std::optional<std::string> shipped_data_file(const std::string& name, const std::string& shipped_dir,
                                             const std::string& extension);

/// The root folder of shipped data (tyres/, vehicles/, cycles/): ROLLSIM_DATA_DIR if set, else the source dir.
std::string data_root();

}  // namespace rollsim
