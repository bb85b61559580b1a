// The energy regression baseline: strict reading, forward runs of every case, and the rewritten file for --update.
#include "rollsim/selection/regress.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <regex>
#include <sstream>

#include "rollsim/common/error.hpp"
#include "rollsim/common/input_file.hpp"
#include "rollsim/common/json.hpp"
#include "rollsim/common/text.hpp"
#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/selection/common.hpp"
#include "rollsim/vehicle/vehicle.hpp"
#include "rollsim/common/format.hpp"

namespace rollsim::selection {

namespace {

Baseline load_baseline_text(const std::string& text, const std::string& path, bool allow_new_cases) {
  Baseline b;
  b.text = text;
  YamlMap root = YamlMap::load_text(b.text, path);
  b.file = path;
  const std::string shape = "a baseline needs a list 'cases' of {name, vehicle, tyre, cycle, expected, tolerance_pct, "
                            "unit (optional)}";
  // A misspelt 'cases' is named as such, and one that is not a list is not called missing (session 25).
  if (!root.has("cases")) {
    root.accept("cases");
    root.finish();
    throw InputError(root.where("cases"), "missing: " + shape);
  }
  if (!root.node()["cases"].IsSequence()) throw InputError(root.where("cases"), "is not a list: " + shape);
  root.accept("cases");
  root.finish();
  const YAML::Node list = root.node()["cases"];
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string item = "cases[" + std::to_string(i) + "]";
    if (!list[i].IsMap()) {
      throw InputError(path + ": line " + std::to_string(list[i].Mark().line + 1) + ": " + item,
                       "expected a mapping {name, vehicle, tyre, cycle, expected, tolerance_pct, unit (optional)}");
    }
    YamlMap m(list[i], path, item + ".");
    RegressCase c;
    c.case_line = list[i].Mark().line;
    c.case_column = list[i].Mark().column;
    c.name = m.string("name");
    // A case is named in every message about it: an empty or blank name read "case '' drifted", a line break in it
    // forged a line of its own on stderr, and a byte that is no UTF-8 became U+FFFD on --update (session 23).
    const bool blank = c.name.find_first_not_of(" \t") == std::string::npos;
    const bool control = std::any_of(c.name.begin(), c.name.end(), [](char ch) { return static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f; });
    if (blank || control || valid_utf8(c.name) != c.name)
      throw InputError(m.where("name"), "'" + display_name(valid_utf8(c.name)) + "' is not allowed: a case's name must be UTF-8 text " +
                                            "with something besides spaces and no control characters (line breaks, tabs)");
    c.vehicle = m.string("vehicle");
    c.tyre = m.string("tyre");
    c.cycle = m.string("cycle");
    // The unit is the car's (energy for a battery car, fuel for an engine): given, it is checked against the car.
    c.unit = m.string_or("unit", "");
    if (!c.unit.empty() && c.unit != "kwh_per_10km" && c.unit != "l_per_100km") {
      throw InputError(m.where("unit"), "'" + c.unit + "' is not allowed: must be kwh_per_10km or l_per_100km (or left out: the car's)");
    }
    // A new case has no value yet: --update fills it in (a user had to invent placeholders: session 25). The bound
    // is far above any car's (a value of 1e300 was printed as 301 digits).
    if (m.has("expected") || !allow_new_cases) {
      try {
        c.expected = m.number("expected", Range::open_low(0.0, 1e4));
      } catch (const InputError& e) {
        // A misspelt key is not a new case: --update would fail on it too (session 27's outside tester).
        if (m.has("expected") || e.problem().find("misspelt") != std::string::npos) throw;
        throw InputError(e.where(), e.problem() + "; 'rollsim regress " + path + " --update' fills in a new case's value");
      }
      c.expected_line = list[i]["expected"].Mark().line;
      c.expected_column = list[i]["expected"].Mark().column;
    }
    // --update writes `expected` to 6 significant digits (up to 0.0005 % off): a tolerance must hold that rounding.
    c.tolerance_pct = m.number("tolerance_pct", Range::closed(0.001, 100.0));
    m.finish();
    for (const auto& other : b.cases) {
      if (other.name == c.name) throw InputError(m.where("name"), "case '" + c.name + "' appears twice");
    }
    b.cases.push_back(c);
  }
  if (b.cases.empty()) throw InputError(root.where("cases"), "the list is empty: nothing to check");
  return b;
}

}  // namespace

Baseline load_baseline(const std::string& path, bool allow_new_cases) {
  return load_baseline_text(read_input_file(path, kMaxYamlFileBytes), path, allow_new_cases);
}

std::vector<RegressOutcome> run_baseline(const Baseline& b) {
  std::vector<RegressOutcome> out;
  for (const auto& c : b.cases) {
    const std::string where = b.file + ": case '" + c.name + "'";
    try {
      // A baseline's own files travel with it: names resolve beside the baseline first, as a fleet manifest's do.
      Vehicle v = load_vehicle_file(resolve_data_file_beside(c.vehicle, b.file, "vehicles", ".yaml", "vehicle"));
      fit_tyres(v, load_tyre_file(resolve_data_file_beside(c.tyre, b.file, "tyres", ".yaml", "tyre")));
      const DriveCycle cycle = load_cycle(path_beside(c.cycle, b.file), "cycle");
      require_distance(cycle);
      if (!c.unit.empty() && energy_unit(v) != c.unit) {
        throw InputError("unit", "'" + c.unit + "' does not match the car (" + energy_unit(v) + ")");
      }
      RegressOutcome o;
      o.c = c;
      o.c.unit = energy_unit(v);
      const EnergyFigure e = run_forward(v, cycle);
      o.actual = e.value;
      o.trace = e.trace;
      if (c.is_new()) {
        o.drift_pct = std::nan("");
      } else {
        o.drift_pct = (o.actual / c.expected - 1.0) * 100.0;
        o.drifted = !(std::abs(o.drift_pct) <= c.tolerance_pct);
      }
      out.push_back(o);
    } catch (const InputError& e) {
      throw InputError(where, e.what());
    } catch (const std::exception& e) {
      throw InputError(where, e.what());
    }
  }
  return out;
}

std::string baseline_value_text(double value) { return significant(value, 6); }

namespace {

// A name or path as YAML reads it back: plain where that is unambiguous, else a double-quoted scalar (JSON's
// escapes are YAML's), so that "ev nedc #1" keeps its "#1" and "ratio: 2" stays one string.
std::string yaml_scalar(const std::string& text) {
  // Starting with a letter: a leading digit can make a date, an octal or 1_000 a number to other YAML readers.
  static const std::regex plain(R"([A-Za-z_][A-Za-z0-9_./+-]*)");
  static const std::regex special(R"((?:true|false|yes|no|on|off|null|y|n))", std::regex::icase);
  char* end = nullptr;
  std::strtod(text.c_str(), &end);
  const bool number = !text.empty() && end == text.c_str() + text.size();
  if (std::regex_match(text, plain) && !std::regex_match(text, special) && !number) return text;
  return yaml_double_quoted(text);
}

}  // namespace

namespace {

// The file's text with each case's expected value replaced where it was read; nullopt where one is not found there
// as the number it read (a BOM or a multi-byte character before it on its line can move yaml-cpp's column).
std::optional<std::string> updated_in_place(const Baseline& b, const std::vector<RegressOutcome>& outcomes) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  for (std::size_t nl; (nl = b.text.find('\n', start)) != std::string::npos; start = nl + 1) lines.push_back(b.text.substr(start, nl - start + 1));
  if (start < b.text.size()) lines.push_back(b.text.substr(start));
  static const std::regex number(R"((["']?)([-+]?[0-9.]+(?:[eE][-+]?[0-9]+)?)\1)");
  // A new case's value goes on a line of its own after the first of its mapping, at its keys' indent; lines are
  // inserted last, from the bottom, so that the lines read stay where they were.
  std::vector<std::pair<std::size_t, std::string>> inserts;
  for (std::size_t i = 0; i < b.cases.size() && i < outcomes.size(); ++i) {
    const RegressCase& c = b.cases[i];
    if (c.is_new()) {
      if (c.case_line < 0 || c.case_line >= static_cast<int>(lines.size()) || c.case_column < 0) return std::nullopt;
      const std::string& first = lines[static_cast<std::size_t>(c.case_line)];
      if (first.size() <= static_cast<std::size_t>(c.case_column) || first[static_cast<std::size_t>(c.case_column)] == '{') return std::nullopt;
      const std::string end = first.size() >= 2 && first[first.size() - 2] == '\r' ? "\r\n" : "\n";
      inserts.emplace_back(static_cast<std::size_t>(c.case_line) + 1,
                           std::string(static_cast<std::size_t>(c.case_column), ' ') + "expected: " + baseline_value_text(outcomes[i].actual) + end);
      continue;
    }
    if (c.expected_line < 0 || c.expected_line >= static_cast<int>(lines.size())) return std::nullopt;
    std::string& line = lines[static_cast<std::size_t>(c.expected_line)];
    const auto col = static_cast<std::size_t>(std::max(0, c.expected_column));
    if (col >= line.size()) return std::nullopt;
    std::smatch m;
    const std::string rest = line.substr(col);
    if (!std::regex_search(rest, m, number, std::regex_constants::match_continuous)) return std::nullopt;
    char* end = nullptr;
    const std::string digits = m[2].str();
    if (std::strtod(digits.c_str(), &end) != c.expected) return std::nullopt;
    line = line.substr(0, col) + m[1].str() + baseline_value_text(outcomes[i].actual) + m[1].str() + rest.substr(static_cast<std::size_t>(m.length(0)));
  }
  if (!inserts.empty() && !lines.empty() && lines.back().back() != '\n') lines.back() += "\n";
  for (auto it = inserts.rbegin(); it != inserts.rend(); ++it) lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(it->first), it->second);
  std::string out;
  for (const auto& l : lines) out += l;
  if (inserts.empty()) return out;
  // An insertion is kept only where the file reads back with every case's value (a block scalar in a case's first
  // line would have taken the new line as its text).
  try {
    const Baseline back = load_baseline_text(out, b.file, false);
    if (back.cases.size() != outcomes.size()) return std::nullopt;
    for (std::size_t i = 0; i < outcomes.size(); ++i)
      if (baseline_value_text(back.cases[i].expected) != baseline_value_text(outcomes[i].actual)) return std::nullopt;
  } catch (const std::exception&) {
    return std::nullopt;
  }
  return out;
}

}  // namespace

std::string baseline_yaml(const Baseline& b, const std::vector<RegressOutcome>& outcomes, bool* rewritten) {
  if (rewritten) *rewritten = false;
  if (const auto in_place = updated_in_place(b, outcomes)) return *in_place;
  if (rewritten) *rewritten = true;
  std::ostringstream y;
  y << "# Energy regression baseline for `rollsim regress` (forward simulation). Each case: the car, the tyre fitted\n"
       "# on all four wheels, the cycle, and the expected battery energy (kwh_per_10km) or fuel (l_per_100km).\n"
       "# Written by `rollsim regress FILE --update`: regenerate it only for a deliberate change of the results.\n"
       "cases:\n";
  for (std::size_t i = 0; i < b.cases.size(); ++i) {
    const RegressCase& c = b.cases[i];
    const double value = i < outcomes.size() ? outcomes[i].actual : c.expected;
    y << "  - name: " << yaml_scalar(c.name) << "\n"
      << "    vehicle: " << yaml_scalar(c.vehicle) << "\n"
      << "    tyre: " << yaml_scalar(c.tyre) << "\n"
      << "    cycle: " << yaml_scalar(c.cycle) << "\n"
      << "    unit: " << (i < outcomes.size() ? outcomes[i].c.unit : c.unit) << "\n"
      << "    expected: " << baseline_value_text(value) << "\n"
      << "    tolerance_pct: " << significant(c.tolerance_pct, 6) << "\n";
  }
  return y.str();
}

}  // namespace rollsim::selection
