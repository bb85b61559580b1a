// The energy regression baseline: strict reading, forward runs of every case, and the rewritten file for --update.
#include "rollsim/selection/regress.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <regex>
#include <sstream>

#include "rollsim/common/error.hpp"
#include "rollsim/common/input_file.hpp"
#include "rollsim/common/json.hpp"
#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/selection/common.hpp"
#include "rollsim/vehicle/vehicle.hpp"
#include "rollsim/common/format.hpp"

namespace rollsim::selection {

Baseline load_baseline(const std::string& path) {
  YamlMap root = YamlMap::load_file(path);
  Baseline b;
  b.file = path;
  if (!root.has("cases") || !root.node()["cases"].IsSequence()) {
    throw InputError(root.where("cases"), "missing: a baseline needs a list 'cases' of {name, vehicle, tyre, cycle, "
                                          "unit, expected, tolerance_pct}");
  }
  root.accept("cases");
  root.finish();
  const YAML::Node list = root.node()["cases"];
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string item = "cases[" + std::to_string(i) + "]";
    if (!list[i].IsMap()) {
      throw InputError(path + ": line " + std::to_string(list[i].Mark().line + 1) + ": " + item,
                       "expected a mapping {name, vehicle, tyre, cycle, unit, expected, tolerance_pct}");
    }
    YamlMap m(list[i], path, item + ".");
    RegressCase c;
    c.name = m.string("name");
    c.vehicle = m.string("vehicle");
    c.tyre = m.string("tyre");
    c.cycle = m.string("cycle");
    c.unit = m.string("unit");
    if (c.unit != "kwh_per_10km" && c.unit != "l_per_100km") {
      throw InputError(m.where("unit"), "'" + c.unit + "' is not allowed: must be kwh_per_10km or l_per_100km");
    }
    c.expected = m.number("expected", Range::positive());
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
      if (energy_unit(v) != c.unit) {
        throw InputError("unit", "'" + c.unit + "' does not match the car (" + energy_unit(v) + ")");
      }
      RegressOutcome o;
      o.c = c;
      const EnergyFigure e = run_forward(v, cycle);
      o.actual = e.value;
      o.trace = e.trace;
      o.drift_pct = (o.actual / c.expected - 1.0) * 100.0;
      o.drifted = !(std::abs(o.drift_pct) <= c.tolerance_pct);
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

std::string baseline_yaml(const Baseline& b, const std::vector<RegressOutcome>& outcomes) {
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
      << "    unit: " << c.unit << "\n"
      << "    expected: " << baseline_value_text(value) << "\n"
      << "    tolerance_pct: " << significant(c.tolerance_pct, 6) << "\n";
  }
  return y.str();
}

}  // namespace rollsim::selection
