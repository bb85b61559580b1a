#include "rollsim/cycle/drive_cycle.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>

#include "rollsim/common/csv.hpp"
#include "rollsim/common/error.hpp"
#include "rollsim/common/format.hpp"
#include "rollsim/common/input_file.hpp"
#include "rollsim/common/text.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/cycle/elevation.hpp"

namespace rollsim {

namespace {

// Slopes that differ by less than this are one straight line: the shipped traces are rounded to 1e-6 km/h,
// which makes the slope of a straight ramp jitter by about 1e-6 m/s^2. A spurious kink would only add a
// harmless stop time; a true kink this small does not matter to an integrator.
constexpr double kKinkTolerance_mps2 = 1e-5;

double lerp(const std::vector<double>& t, const std::vector<double>& y, std::size_t i, double at) {
  const double w = (at - t[i]) / (t[i + 1] - t[i]);
  return y[i] + w * (y[i + 1] - y[i]);
}

double value_at(const DriveCycle& c, const std::vector<double>& y, double t, std::size_t& hint) {
  if (t <= c.time_s.front()) return y.front();
  if (t >= c.time_s.back()) return y.back();
  hint = c.segment_index(t, hint);
  return lerp(c.time_s, y, hint, t);
}

}  // namespace

bool DriveCycle::any_engine_off() const { return std::find(engine_off.begin(), engine_off.end(), true) != engine_off.end(); }

void DriveCycle::set_engine_off(std::vector<bool> off_per_segment) {
  engine_off = std::move(off_per_segment);
  if (!any_engine_off()) engine_off.clear();
}

double DriveCycle::duration_s() const { return time_s.empty() ? 0.0 : time_s.back() - time_s.front(); }

double DriveCycle::distance_m() const {
  double s = 0.0;
  for (std::size_t i = 0; i + 1 < time_s.size(); ++i) s += 0.5 * (speed_mps[i] + speed_mps[i + 1]) * (time_s[i + 1] - time_s[i]);
  return s;
}

std::size_t DriveCycle::segment_index(double t, std::size_t hint) const {
  const std::size_t n = time_s.size();
  if (n < 2) return 0;
  const std::size_t last = n - 2;
  if (hint <= last && time_s[hint] <= t && (t < time_s[hint + 1] || hint == last)) return hint;
  // Integrators mostly move forward by less than a segment: try the next one before searching.
  if (hint + 1 <= last && time_s[hint + 1] <= t && (t < time_s[hint + 2] || hint + 1 == last)) return hint + 1;
  auto it = std::upper_bound(time_s.begin(), time_s.end(), t);
  if (it == time_s.begin()) return 0;
  const std::size_t i = static_cast<std::size_t>(it - time_s.begin()) - 1;
  return std::min(i, last);
}

double DriveCycle::speed_mps_at(double t, std::size_t& hint) const { return value_at(*this, speed_mps, t, hint); }
double DriveCycle::grade_at(double t, std::size_t& hint) const { return value_at(*this, grade, t, hint); }

double DriveCycle::accel_mps2_at(double t, std::size_t& hint) const {
  if (t < time_s.front() || t >= time_s.back()) return 0.0;
  hint = segment_index(t, hint);
  return (speed_mps[hint + 1] - speed_mps[hint]) / (time_s[hint + 1] - time_s[hint]);
}

double DriveCycle::speed_mps_at(double t) const {
  std::size_t h = 0;
  return speed_mps_at(t, h);
}
double DriveCycle::accel_mps2_at(double t) const {
  std::size_t h = 0;
  return accel_mps2_at(t, h);
}
double DriveCycle::grade_at(double t) const {
  std::size_t h = 0;
  return grade_at(t, h);
}

std::vector<double> breakpoints_s(const DriveCycle& c) {
  std::vector<double> out;
  for (std::size_t i = 1; i + 1 < c.time_s.size(); ++i) {
    const double a0 = (c.speed_mps[i] - c.speed_mps[i - 1]) / (c.time_s[i] - c.time_s[i - 1]);
    const double a1 = (c.speed_mps[i + 1] - c.speed_mps[i]) / (c.time_s[i + 1] - c.time_s[i]);
    // A standstill's start is a stop whatever the slope before it: a trace that creeps in at 1e-6 km/h (a resampled
    // log's residue) has no kink there, and the car then never came to be held on its brakes.
    const bool standstill_starts = c.speed_mps[i] == 0.0 && c.speed_mps[i + 1] == 0.0 && c.speed_mps[i - 1] != 0.0;
    // What a segment holds besides its speed changes here too: the power jumps while the speed, which the driver
    // holds on the trace, does not, so error control saw nothing and a step across a run of grade changes booked the
    // grade of the few points it evaluated (+-4 % every 30 s at 60 km/h read -1.6 kWh of net climb on a level
    // route: session 21's outside testing).
    const bool grade_changes = i < c.grade.size() && c.grade[i] != c.grade[i - 1];
    const bool engine_changes = c.engine_off_at(i) != c.engine_off_at(i - 1) || c.accessories_on_at(i) != c.accessories_on_at(i - 1);
    const bool heading_changes = i < c.heading_rad.size() && c.heading_rad[i] != c.heading_rad[i - 1];
    if (std::abs(a1 - a0) > kKinkTolerance_mps2 || standstill_starts || grade_changes || engine_changes || heading_changes)
      out.push_back(c.time_s[i]);
  }
  return out;
}

std::vector<double> crossing_times_s(const DriveCycle& c, double speed_mps, bool falling_only) {
  std::vector<double> out;
  for (std::size_t i = 0; i + 1 < c.time_s.size(); ++i) {
    const double v0 = c.speed_mps[i], v1 = c.speed_mps[i + 1];
    if (falling_only && !(v1 < v0)) continue;
    if ((v0 < speed_mps && v1 > speed_mps) || (v0 > speed_mps && v1 < speed_mps))
      out.push_back(c.time_s[i] + (speed_mps - v0) / (v1 - v0) * (c.time_s[i + 1] - c.time_s[i]));
    else if (v1 == speed_mps && v0 != speed_mps && i + 2 < c.time_s.size())
      out.push_back(c.time_s[i + 1]);
  }
  return out;
}

std::vector<std::string> shipped_cycle_names() {
  return {"nedc",         "wltc_class3b",  "udds",          "ftp75",
          "hwfet",        "us06",          "artemis_urban", "artemis_road",
          "artemis_motorway_130", "artemis_motorway_150", "nedc_fastsim"};
}

DriveCycle load_cycle(const std::string& name_or_path, const std::string& option) {
  std::string key = lower_ascii(name_or_path);
  if (key == "wltc" || key == "wltc3b" || key == "wltc_3b") key = "wltc_class3b";
  const auto names = shipped_cycle_names();
  if (std::find(names.begin(), names.end(), key) != names.end()) {
    return read_cycle_csv(resolve_data_file(key, "cycles", ".csv", option), key);
  }
  namespace fs = std::filesystem;
  if (is_folder_path(name_or_path)) throw InputError(option + " '" + name_or_path + "'", "is a folder; a file is expected here");
  std::error_code ec;
  if (!is_regular_file_path(name_or_path) && fs::exists(fs::path(name_or_path), ec)) {
    throw InputError(option + " '" + name_or_path + "'", "is not a regular file (a device, pipe or socket?)");
  }
  if (!is_regular_file_path(name_or_path)) {
    std::string list;
    for (std::size_t i = 0; i < names.size(); ++i) list += (i ? ", " : "") + names[i];
    throw InputError(option + " '" + name_or_path + "'",
                     "no such file, and not a shipped cycle name; shipped cycles: " + list + " (wltc = wltc_class3b)");
  }
  return read_cycle_csv(name_or_path, fs::path(name_or_path).stem().string());
}

DriveCycle read_cycle_csv(const std::string& path, const std::string& name) {
  return cycle_from_table(read_csv(path), name);
}

namespace {

// The direction of travel over the segment starting at this sample, clockwise from north, as a compass gives it.
double heading_rad(const CsvTable& table, std::size_t row, std::size_t col, double deg) {
  if (!(deg >= 0.0 && deg <= 360.0))
    throw InputError(table.where(row, col), format_value(deg) + " deg is not allowed: a heading is in [0, 360] deg, clockwise from north");
  return units::deg_to_rad(deg);
}

// 1: the engine runs over the segment starting here; 0: switched off (a soak, start-stop), no fuel, cooling.
bool engine_off(const CsvTable& table, std::size_t row, std::size_t col, double on) {
  if (on != 0.0 && on != 1.0) throw InputError(table.where(row, col), format_value(on) + " is not allowed: engine_on is 1 (running) or 0 (off)");
  return on == 0.0;
}

// 1: with the engine off, the electrical accessories stay on from the 12 V battery (start-stop); 0: off with the key.
bool accessories_on(const CsvTable& table, std::size_t row, std::size_t col, double on) {
  if (on != 0.0 && on != 1.0)
    throw InputError(table.where(row, col), format_value(on) + " is not allowed: accessories_on is 1 (on while the engine is off) or 0 (off)");
  return on == 1.0;
}

// The simulator switches an engine off only on a standing segment (a moving car's engine-off flag would be ignored,
// a silently wrong number): both ends of an off segment must stand still.
void check_engine_off_standing(const CsvTable& table, std::size_t col, const std::vector<double>& speed_mps,
                               const std::vector<bool>& off) {
  for (std::size_t r = 0; r < off.size(); ++r) {
    if (!off[r]) continue;
    const std::size_t next = std::min(r + 1, speed_mps.size() - 1);
    if (speed_mps[r] > 0.0 || speed_mps[next] > 0.0)
      throw InputError(table.where(r, col), "0 (off) is not allowed while moving (" + format_value(units::mps_to_kmh(std::max(speed_mps[r], speed_mps[next]))) +
                                                " km/h over the segment from here): the engine may be off only standing still");
  }
}

// Long intervals between samples where the car moves at either end: the trace drives them as a straight line, which
// for a logger's dropout is distance that was never driven. Said, not refused: a hand-written trace may mean it.
std::vector<std::string> moving_gap_notes(const CsvTable& table, const DriveCycle& c) {
  constexpr std::size_t kNamed = 3;  // a trace in milliseconds has one per sample: name a few, count the rest
  std::vector<std::string> out;
  const double total_m = c.distance_m();
  std::size_t more = 0;
  double more_m = 0.0;
  for (std::size_t r = 1; r < c.time_s.size(); ++r) {
    const double dt = c.time_s[r] - c.time_s[r - 1];
    if (!(dt > kNotedMovingGap_s) || (c.speed_mps[r] == 0.0 && c.speed_mps[r - 1] == 0.0)) continue;
    const double gap_m = 0.5 * (c.speed_mps[r] + c.speed_mps[r - 1]) * dt;
    if (out.size() == kNamed) {
      ++more;
      more_m += gap_m;
      continue;
    }
    out.push_back(table.file + ": lines " + std::to_string(table.row_line[r - 1]) + "-" + std::to_string(table.row_line[r]) +
                  ": " + fixed(dt, 0) + " s between samples at " + fixed(units::mps_to_kmh(c.speed_mps[r - 1]), 1) +
                  " and " + fixed(units::mps_to_kmh(c.speed_mps[r]), 1) + " km/h, driven as a straight line between them (" +
                  fixed(gap_m / 1000.0, 3) + " of the trace's " + fixed(total_m / 1000.0, 3) +
                  " km); if the log has a gap there, that distance was never driven");
  }
  if (more > 0) {
    out.push_back(table.file + ": " + std::to_string(more) + " more such intervals (" + fixed(more_m / 1000.0, 3) +
                  " km more); so many that the time column may not be in seconds (milliseconds?)");
  }
  return out;
}

// A km/h log under a speed_mps header drives 3.6 times too fast and is refused only past 500 km/h; before this
// note the one sign was the car failing to follow. A test track's top-speed run reaches 250 km/h, no drive cycle does.
std::optional<std::string> fast_mps_note(const CsvTable& table, std::size_t col, const DriveCycle& c) {
  const auto top = std::max_element(c.speed_mps.begin(), c.speed_mps.end());
  if (top == c.speed_mps.end() || !(units::mps_to_kmh(*top) > kNotedCycleSpeed_kmh)) return std::nullopt;
  const auto r = static_cast<std::size_t>(top - c.speed_mps.begin());
  return table.where(r, col) + ": " + fixed(*top, 1) + " m/s is " + fixed(units::mps_to_kmh(*top), 0) +
         " km/h, faster than any drive cycle; if the column holds km/h, name it speed_kmh";
}

bool is_cycle_column(const std::string& h) {
  return h == "time_s" || h == "speed_kmh" || h == "speed_mps" || h == "grade_pct" || h == "elevation_m" ||
         h == "heading_deg" || h == "engine_on" || h == "accessories_on";
}

// Exports carry more columns than a cycle (phase, gear, distance), ignored as a recording's are. A name that
// resembles a cycle column is refused instead: 'Grade_pct' or 'grade_deg' ignored would drive a flat road, and
// 'Time_s' beside time_s would hide which one the user meant.
bool resembles_cycle_column(const std::string& h) {
  const std::string l = lower_ascii(h);
  for (const char* stem : {"time", "speed", "veloc", "grade", "slope", "elev", "alt", "height", "head", "engine"})
    if (l.find(stem) != std::string::npos) return true;
  return false;
}

}  // namespace

std::string ignored_columns_note(const DriveCycle& c) {
  if (c.ignored_columns.empty()) return "";
  std::string list;
  for (std::size_t i = 0; i < c.ignored_columns.size(); ++i) list += (i ? ", " : "") + c.ignored_columns[i];
  return c.source + ": " + (c.ignored_columns.size() == 1 ? "column " : "columns ") + list +
         " not read; cycle columns are time_s, speed_kmh or speed_mps, grade_pct or elevation_m, heading_deg, engine_on, accessories_on";
}

DriveCycle cycle_from_table(const CsvTable& table, const std::string& name) {
  const std::string& path = table.file;
  const std::string allowed = "time_s, speed_kmh or speed_mps, optional grade_pct or elevation_m, heading_deg, engine_on, accessories_on";
  const std::string found = "found columns: " + table.columns_list();
  // A header of numbers means the file has none, and its first sample would otherwise be lost or misread.
  bool header_numeric = !table.header.empty();
  for (const auto& h : table.header) header_numeric = header_numeric && parse_number(h).has_value();
  if (header_numeric) {
    throw InputError(path + ": line " + std::to_string(table.header_line),
                     "holds numbers, but the first line must be a header naming the columns (" + allowed + ")");
  }
  std::vector<std::string> ignored;
  for (std::size_t i = 0; i < table.header.size(); ++i) {
    const std::string& h = table.header[i];
    if (!is_cycle_column(h)) {
      if (resembles_cycle_column(h)) {
        throw InputError(path + ": line " + std::to_string(table.header_line) + ", column " + std::to_string(i + 1),
                         "unknown column '" + h + "' (misspelt?); allowed: " + allowed +
                             "; other columns are ignored, but not one named like these; " + found);
      }
      ignored.push_back(h.empty() ? "column " + std::to_string(i + 1) + " (no name)" : "'" + h + "'");
      continue;
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (table.header[j] == h) {
        throw InputError(path + ": line " + std::to_string(table.header_line), "column '" + h + "' appears twice");
      }
    }
  }
  const auto col_t = table.column("time_s");
  const auto col_kmh = table.column("speed_kmh");
  const auto col_mps = table.column("speed_mps");
  const auto col_grade = table.column("grade_pct");
  const auto col_elev = table.column("elevation_m");
  const auto col_heading = table.column("heading_deg");
  const auto col_engine = table.column("engine_on");
  const auto col_accessories = table.column("accessories_on");
  if (col_accessories && !col_engine)
    throw InputError(path + ": column 'accessories_on'", "says whether the accessories stay on while the engine is off: it needs an engine_on column");
  if (!col_t) throw InputError(path, "missing column 'time_s'; " + found);
  if (!col_kmh && !col_mps) throw InputError(path, "missing a speed column, 'speed_kmh' or 'speed_mps'; " + found);
  if (col_kmh && col_mps) throw InputError(path, "has both 'speed_kmh' and 'speed_mps'; give exactly one");
  if (col_grade && col_elev) throw InputError(path, "has both 'grade_pct' and 'elevation_m'; give at most one");
  const std::size_t col_v = col_kmh ? *col_kmh : *col_mps;
  if (table.rows.size() < 2) {
    throw InputError(path, "has " + std::to_string(table.rows.size()) + " sample(s); a cycle needs at least 2");
  }

  auto number = [&](std::size_t row, std::size_t col) {
    const std::string& cell = table.rows[row][col];
    if (cell.empty()) throw InputError(table.where(row, col), "is empty; expected a number");
    const auto v = parse_number(cell);
    if (!v) throw InputError(table.where(row, col), not_a_number(cell));
    if (!std::isfinite(*v)) throw InputError(table.where(row, col), "'" + cell + "' is not allowed: must be a finite number");
    return *v;
  };

  DriveCycle c;
  c.name = name;
  c.source = path;
  c.ignored_columns = std::move(ignored);
  const std::size_t n = table.rows.size();
  c.time_s.resize(n);
  c.speed_mps.resize(n);
  c.grade.assign(n, 0.0);
  std::vector<double> elevation;
  std::vector<bool> off;
  for (std::size_t r = 0; r < n; ++r) {
    c.time_s[r] = number(r, *col_t);
    if (r > 0 && !(c.time_s[r] > c.time_s[r - 1])) {
      throw InputError(table.where(r, *col_t),
                       format_value(c.time_s[r]) + " s is not after " + format_value(c.time_s[r - 1]) + " s on line " +
                           std::to_string(table.row_line[r - 1]) + ": time must be strictly increasing" +
                           same_in_double_precision(table.rows[r][*col_t], table.rows[r - 1][*col_t], c.time_s[r], c.time_s[r - 1]));
    }
    const double dt = r > 0 ? c.time_s[r] - c.time_s[r - 1] : 0.0;
    // A relative tolerance, so that times written 1 ms apart (0.008, 0.009: 0.00099999999999999 in binary) pass.
    if (r > 0 && !(dt >= kMinCycleTimeStep_s * (1.0 - 1e-9) && dt <= kMaxCycleTimeStep_s)) {
      throw InputError(table.where(r, *col_t),
                       format_value(c.time_s[r]) + " s is " + format_value(dt) + " s after the sample on line " +
                           std::to_string(table.row_line[r - 1]) + "; allowed: 0.001 to 86400 s between samples");
    }
    const double v = number(r, col_v);
    const double v_max = col_kmh ? kMaxCycleSpeed_kmh : units::kmh_to_mps(kMaxCycleSpeed_kmh);
    if (!(v >= 0.0 && v <= v_max * (1.0 + 1e-12))) {
      throw InputError(table.where(r, col_v), format_value(v) + " is not allowed: speed must be in " +
                                                  (col_kmh ? std::string("[0, 500] km/h") : std::string("[0, 138.9] m/s (500 km/h)")));
    }
    c.speed_mps[r] = col_kmh ? units::kmh_to_mps(v) : v;
    if (r > 0 && std::abs(c.speed_mps[r] - c.speed_mps[r - 1]) / dt > kMaxCycleAccel_mps2) {
      throw InputError(table.where(r, col_v),
                       "the speed changes from line " + std::to_string(table.row_line[r - 1]) + " at " +
                           format_value((c.speed_mps[r] - c.speed_mps[r - 1]) / dt) +
                           " m/s^2; allowed: within +-19.6 m/s^2 (2 g, beyond any tyre's grip)");
    }
    if (col_grade) {
      const double g = number(r, *col_grade);
      if (std::abs(g) > kMaxCycleGrade * 100.0) {
        throw InputError(table.where(r, *col_grade), format_value(g) + " % is not allowed: must be in [-30, 30]");
      }
      c.grade[r] = g / 100.0;
    }
    if (col_elev) elevation.push_back(number(r, *col_elev));
    if (col_heading) c.heading_rad.push_back(heading_rad(table, r, *col_heading, number(r, *col_heading)));
    if (col_engine) off.push_back(engine_off(table, r, *col_engine, number(r, *col_engine)));
    if (col_accessories) c.accessories_on.push_back(accessories_on(table, r, *col_accessories, number(r, *col_accessories)));
  }
  if (col_engine) check_engine_off_standing(table, *col_engine, c.speed_mps, off);
  c.set_engine_off(std::move(off));
  c.notes = moving_gap_notes(table, c);
  if (col_mps)
    if (auto note = fast_mps_note(table, *col_mps, c)) c.notes.push_back(*note);

  if (col_elev) {
    // Grade from the elevation as the diagnosis reads a recording's (cycle/elevation.hpp): glitches dropped, the
    // profile smoothed over 300 m of distance by a cubic's slope. A GPS or map elevation is noisy at the metre scale,
    // and blocks of 10 m (sessions 21-22) read +-1 m of noise on a flat route as +-7 % grades: the climbs cost more
    // than the descents gave back, and a flat stop-and-go route used 38-46 % more energy (session 22's outside
    // testing); a re-fix of 3 m at a standstill was a 25 % ramp into the light.
    std::vector<double> s(n, 0.0);
    for (std::size_t i = 1; i < n; ++i) {
      s[i] = s[i - 1] + 0.5 * (c.speed_mps[i] + c.speed_mps[i - 1]) * (c.time_s[i] - c.time_s[i - 1]);
    }
    ElevationGradeOptions opt;
    opt.max_grade = std::numeric_limits<double>::infinity();  // refused beyond the cycle's limit below, not clamped
    if (s.back() < 2.0 * opt.grid_m) {
      throw InputError(path + ": column 'elevation_m'",
                       "the cycle travels only " + format_value(s.back()) +
                           " m, too little to turn elevation into grade (needs " + format_value(2.0 * opt.grid_m) + " m)");
    }
    const ElevationGrade eg = grade_from_elevation(c.time_s, c.speed_mps, elevation, opt);
    for (std::size_t i = 0; i < n; ++i) {
      if (std::abs(eg.grade[i]) > kMaxCycleGrade) {
        throw InputError(path + ": line " + std::to_string(table.row_line[i]) + ", column 'elevation_m'",
                         "the elevation rises " + format_value(100.0 * eg.grade[i]) +
                             " % over the road there (a cubic's slope over 300 m); allowed: within +-30 %");
      }
    }
    c.grade = eg.grade;
    if (eg.rejected_steps > 0) {
      c.notes.push_back(path + ": column 'elevation_m': " + std::to_string(eg.rejected_steps) +
                        " elevation step(s) steeper than 20 % over the distance driven (plus 5 m) dropped as glitches");
    }
  }
  return c;
}

}  // namespace rollsim
