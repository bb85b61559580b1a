#include "rollsim/recording/recording.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <limits>
#include <set>

#include "rollsim/common/csv.hpp"
#include "rollsim/common/error.hpp"
#include "rollsim/common/format.hpp"
#include "rollsim/common/statistics.hpp"
#include "rollsim/common/text.hpp"
#include "rollsim/common/units.hpp"

namespace rollsim {

namespace {

// "; map a source column to CANONICAL" and how the front end says it (ColumnMapping::how_to_map); `target` in
// place of a single column's name (e.g. "one of them") keeps the placeholder in the how.
std::string map_hint(const ColumnMapping& m, const std::string& canonical, const std::string& target = "") {
  std::string how = m.how_to_map;
  if (target.empty()) {
    for (auto at = how.find("CANONICAL"); at != std::string::npos; at = how.find("CANONICAL", at + canonical.size()))
      how.replace(at, 9, canonical);
  }
  return "; map a source column to " + (target.empty() ? canonical : target) + (how.empty() ? "" : " " + how);
}

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kSecondsPerDay = 86400.0;
// A clock falling by more than half a day between two samples is read as passing midnight; a smaller fall
// is time going backwards. No logger at 1-100 Hz leaves a 12 h hole inside one recording.
constexpr double kMidnightFall_s = 43200.0;
// Speeds this little below zero are sensor offset at standstill, set to zero and reported; below it, an error.
constexpr double kSpeedNoise_kmh = 1.0;

const std::vector<std::string> kCanonical = {
    "time_s",   "date",       "speed_kmh",   "battery_power_kw", "battery_voltage_v", "battery_current_a",
    "soc_pct",  "fuel_rate_lph", "elevation_m", "grade_pct",     "ambient_temp_c",    "latitude",
    "longitude"};

std::string canonical_list() {
  std::string out;
  for (std::size_t i = 0; i < kCanonical.size(); ++i) out += (i ? ", " : "") + kCanonical[i];
  return out;
}

bool is_canonical(const std::string& name) {
  return std::find(kCanonical.begin(), kCanonical.end(), name) != kCanonical.end();
}

// Splits "CANONICAL=VALUE" of an option, checking the canonical name.
std::pair<std::string, std::string> split_option(const std::string& option, const std::string& text,
                                                 const std::string& example, bool allow_empty = false) {
  const std::string where = option + " '" + text + "'";
  const auto eq = text.find('=');
  if (eq == std::string::npos) throw InputError(where, "expected CANONICAL=" + example);
  std::string canonical = trim(text.substr(0, eq));
  std::string value = trim(text.substr(eq + 1));
  if (!is_canonical(canonical)) {
    throw InputError(where, "'" + canonical + "' is not a canonical column; allowed: " + canonical_list());
  }
  if (value.empty() && !allow_empty) throw InputError(where, "nothing after '='; expected CANONICAL=" + example);
  return {canonical, value};
}

bool is_missing(const std::string& cell) {
  if (cell.empty()) return true;
  const std::string l = lower_ascii(cell);
  return l == "nan" || l == "-nan" || l == "na" || l == "n/a" || l == "null";
}

// "HH:MM:SS" or "HH:MM:SS.fff" -> seconds since midnight.
std::optional<double> parse_clock(const std::string& text) {
  const std::string s = trim(text);
  const auto c1 = s.find(':');
  const auto c2 = c1 == std::string::npos ? std::string::npos : s.find(':', c1 + 1);
  if (c2 == std::string::npos) return std::nullopt;
  auto all_digits = [](const std::string& p) {
    return !p.empty() && p.size() <= 2 && std::all_of(p.begin(), p.end(), [](unsigned char ch) { return std::isdigit(ch); });
  };
  const std::string hh = s.substr(0, c1), mm = s.substr(c1 + 1, c2 - c1 - 1), ss = s.substr(c2 + 1);
  if (!all_digits(hh) || !all_digits(mm) || ss.empty() || !std::isdigit(static_cast<unsigned char>(ss[0]))) return std::nullopt;
  const auto sec = parse_number(ss);
  if (!sec) return std::nullopt;
  const int h = std::stoi(hh), m = std::stoi(mm);
  if (h > 23 || m > 59 || *sec < 0.0 || *sec >= 61.0) return std::nullopt;  // 60.x: a leap second
  return h * units::kSPerHour + m * 60.0 + *sec;
}

// Days since 1970-01-01 of a civil date (Howard Hinnant's days_from_civil, proleptic Gregorian).
long days_from_civil(long y, unsigned m, unsigned d) {
  y -= m <= 2;
  const long era = (y >= 0 ? y : y - 399) / 400;
  const auto yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (m > 2 ? m - 3 : m + 9) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<long>(doe) - 719468;
}

// The three numbers of a date cell split at '/', '-' or '.', or nothing.
std::optional<std::array<long, 3>> date_fields(const std::string& text) {
  std::array<long, 3> f{};
  std::size_t k = 0, i = 0;
  const std::string s = trim(text);
  while (k < 3) {
    std::size_t j = i;
    while (j < s.size() && std::isdigit(static_cast<unsigned char>(s[j]))) ++j;
    if (j == i || j - i > 4) return std::nullopt;
    f[k++] = std::stol(s.substr(i, j - i));
    if (k < 3) {
      if (j >= s.size() || (s[j] != '/' && s[j] != '-' && s[j] != '.')) return std::nullopt;
      i = j + 1;
    } else if (j != s.size()) {
      return std::nullopt;
    }
  }
  return f;
}

// Day numbers of a date column, where every cell reads as one date: year first (2021-07-01), or the year last with
// the day first if any first field exceeds 12 or the separator is '.' (01.07.2021), else the month first (7/1/2021,
// the US loggers'). Empty when the column does not read so throughout.
std::vector<long> date_day_numbers(const CsvTable& table, std::size_t col) {
  std::vector<std::array<long, 3>> f;
  bool day_first = false;
  for (const auto& row : table.rows) {
    const auto d = date_fields(row[col]);
    if (!d) return {};
    if ((*d)[2] >= 1000 && ((*d)[0] > 12 || row[col].find('.') != std::string::npos)) day_first = true;
    f.push_back(*d);
  }
  std::vector<long> days;
  for (const auto& d : f) {
    long y = 0, m = 0, dd = 0;
    if (d[0] >= 1000) y = d[0], m = d[1], dd = d[2];
    else if (d[2] >= 1000) y = d[2], m = day_first ? d[1] : d[0], dd = day_first ? d[0] : d[1];
    else return {};
    if (m < 1 || m > 12 || dd < 1 || dd > 31) return {};
    days.push_back(days_from_civil(y, static_cast<unsigned>(m), static_cast<unsigned>(dd)));
  }
  return days;
}

std::string lines_text(const CsvTable& t, std::size_t r0, std::size_t r1) {
  return r0 == r1 ? "line " + std::to_string(t.row_line[r0])
                  : "lines " + std::to_string(t.row_line[r0]) + "-" + std::to_string(t.row_line[r1]);
}

struct Channel {
  std::string canonical;
  std::size_t col = 0;
  std::vector<double> values;  // NaN where missing
};

}  // namespace

double Recording::distance_m() const {
  double s = 0.0;
  for (std::size_t i = 0; i + 1 < time_s.size(); ++i) {
    const double dt = time_s[i + 1] - time_s[i];
    // What happened in a gap was not recorded: twenty trips two hours apart counted each trip's last speed for the
    // two hours, 1418 km against the GPS track's 854 (session 23's outside testing). The windows skip gaps alike.
    if (dt > kReportedGap_s) continue;
    s += 0.5 * (speed_mps[i] + speed_mps[i + 1]) * dt;
  }
  return s;
}

const std::vector<std::string>& canonical_recording_columns() { return kCanonical; }

void parse_column_option(const std::string& text, ColumnMapping& mapping, const std::string& option) {
  auto [canonical, source] = split_option(option, text, "SOURCE, e.g. speed_kmh=Dyno_Spd[mph]", true);
  const std::string where = option + " '" + text + "'";
  if (source.empty() && (canonical == "time_s" || canonical == "speed_kmh")) {
    throw InputError(where, "'" + canonical + "' is required and cannot be dropped; map it to a column");
  }
  // Shells keep quotes typed inside a single-quoted argument; a source name never starts and ends with one.
  if (source.size() >= 2 && (source.front() == '\'' || source.front() == '"') && source.back() == source.front()) {
    source = source.substr(1, source.size() - 2);
  }
  if (mapping.source_for_canonical.count(canonical)) {
    throw InputError(where, "'" + canonical + "' is already mapped to '" + mapping.source_for_canonical[canonical] +
                                "'; give it once");
  }
  mapping.source_for_canonical[canonical] = source;
}

namespace {
// A power's sign is a logger's convention, a speed's is not: a negative speed scale was blamed on the recording's
// line 23 (session 27's outside tester).
void check_scale_sign(const std::string& canonical, double factor, const std::string& where) {
  if (factor < 0.0 && canonical.rfind("speed_", 0) == 0)
    throw InputError(where, format_value(factor) + " is not allowed: a speed's scale must be positive");
}
}  // namespace

void parse_scale_option(const std::string& text, ColumnMapping& mapping, const std::string& option) {
  const auto [canonical, value] = split_option(option, text, "FACTOR, e.g. speed_kmh=1.609344");
  const std::string where = option + " '" + text + "'";
  if (canonical == "time_s" || canonical == "date") {
    throw InputError(where, "'" + canonical + "' cannot be scaled; scale the value columns only");
  }
  const auto f = parse_number(value);
  if (!f) throw InputError(where, "'" + value + "' is not a number");
  if (!std::isfinite(*f) || *f == 0.0) throw InputError(where, format_value(*f) + " is not allowed: must be finite and non-zero");
  check_scale_sign(canonical, *f, where);
  if (mapping.scale_for_canonical.count(canonical)) throw InputError(where, "'" + canonical + "' is already scaled; give it once");
  mapping.scale_for_canonical[canonical] = *f;
}

ColumnMapping column_mapping_from_yaml(YamlMap& file) {
  ColumnMapping m;
  if (auto cols = file.optional_map("recording_columns")) {
    for (const auto& kv : cols->node()) {
      const std::string key = kv.first.as<std::string>();
      if (!is_canonical(key)) {
        throw InputError(cols->where(key), "'" + key + "' is not a canonical column; allowed: " + canonical_list());
      }
      m.source_for_canonical[key] = cols->string(key);
    }
    cols->finish();
  }
  if (auto scales = file.optional_map("recording_scale")) {
    for (const auto& kv : scales->node()) {
      const std::string key = kv.first.as<std::string>();
      if (!is_canonical(key) || key == "time_s" || key == "date") {
        throw InputError(scales->where(key), "'" + key + "' cannot be scaled; allowed: canonical value columns (" +
                                                 canonical_list() + ", except time_s and date)");
      }
      const double f = scales->number(key, Range{});
      if (f == 0.0) throw InputError(scales->where(key), "0 is not allowed: must be non-zero");
      check_scale_sign(key, f, scales->where(key));
      m.scale_for_canonical[key] = f;
    }
    scales->finish();
  }
  return m;
}

std::vector<std::string> preset_mapping_names() { return {"anl_d3", "rsk_twizy"}; }

ColumnMapping preset_mapping(const std::string& name) {
  ColumnMapping m;
  const std::string key = lower_ascii(name);
  if (key == "anl_d3") {
    m.source_for_canonical = {{"time_s", "Time[s]"},
                              {"speed_kmh", "Dyno_Spd[mph]"},
                              {"fuel_rate_lph", "Eng_FuelFlow_Direct_DI[ccps]"}};
    m.scale_for_canonical = {{"speed_kmh", units::kMpsPerMph / units::kMpsPerKmh},  // mph -> km/h
                             {"fuel_rate_lph", units::kM3PerCm3 / units::kM3PerLitre * units::kSPerHour}};  // cm3/s -> l/h
    return m;
  }
  if (key == "rsk_twizy") {
    m.source_for_canonical = {{"time_s", "Time"},        {"date", "Date"},        {"soc_pct", "Soc"},
                              {"speed_kmh", "Speed"},    {"elevation_m", "ALT"},  {"ambient_temp_c", "Temperature"},
                              {"latitude", "LAT"},       {"longitude", "LON"}};
    return m;
  }
  throw InputError("recording preset '" + name + "'", "unknown; allowed: anl_d3, rsk_twizy");
}

ColumnMapping assemble_mapping(const std::string& preset, YamlMap& vehicle_file, const std::vector<std::string>& columns,
                               const std::vector<std::string>& scales, const std::string& column_option,
                               const std::string& scale_option) {
  ColumnMapping mapping;
  if (!preset.empty()) mapping = preset_mapping(preset);
  mapping = merge_mapping(mapping, column_mapping_from_yaml(vehicle_file));
  ColumnMapping overrides;
  for (const auto& c : columns) parse_column_option(c, overrides, column_option);
  for (const auto& s : scales) parse_scale_option(s, overrides, scale_option);
  return merge_mapping(mapping, overrides);
}

ColumnMapping merge_mapping(ColumnMapping base, const ColumnMapping& overrides) {
  for (const auto& [k, v] : overrides.source_for_canonical) {
    // A scale is the unit of its source column: one mapped to another column leaves it behind (the Camry file's mph
    // and cm3/s factors were applied to columns mapped to km/h and l/h, -41 % in silence: session 23's outside testing).
    const auto was = base.source_for_canonical.find(k);
    if (was != base.source_for_canonical.end() && was->second != v && !overrides.scale_for_canonical.count(k))
      base.scale_for_canonical.erase(k);
    base.source_for_canonical[k] = v;
  }
  for (const auto& [k, v] : overrides.scale_for_canonical) base.scale_for_canonical[k] = v;
  if (!overrides.how_to_map.empty()) base.how_to_map = overrides.how_to_map;
  return base;
}

Recording load_recording(const std::string& path, const ColumnMapping& mapping) {
  const CsvTable table = read_csv(path, ',', kMaxRecordingSamples, "samples");
  const std::string found = "found columns: " + table.columns_list();
  const std::size_t n = table.rows.size();

  auto source_of = [&](const std::string& canonical) {
    auto it = mapping.source_for_canonical.find(canonical);
    return it != mapping.source_for_canonical.end() ? it->second : canonical;
  };
  // Column index of a canonical column, nullopt if absent; a mapping naming a column the file lacks is an error.
  auto find = [&](const std::string& canonical) -> std::optional<std::size_t> {
    const std::string src = source_of(canonical);
    if (src.empty()) return std::nullopt;  // dropped (--column CANONICAL=)
    const auto col = table.column(src);
    if (!col && mapping.source_for_canonical.count(canonical)) {
      throw InputError(path, "column '" + src + "' (mapped to " + canonical + ") is not in the file; " + found);
    }
    return col;
  };
  for (const auto& [canonical, factor] : mapping.scale_for_canonical) {
    (void)factor;
    if (source_of(canonical).empty()) continue;  // dropped: its scale has nothing to scale
    if (!find(canonical)) {
      throw InputError(path, "a scale is given for " + canonical + " but the file has no column '" + source_of(canonical) +
                                 "'; " + found + map_hint(mapping, canonical));
    }
  }
  auto require = [&](const std::string& canonical) {
    const auto col = find(canonical);
    if (!col) {
      throw InputError(path, "missing required column '" + canonical + "'; " + found + map_hint(mapping, canonical));
    }
    return *col;
  };
  const std::size_t col_t = require("time_s");
  const std::size_t col_v = require("speed_kmh");
  if (n < 2) throw InputError(path, "has " + std::to_string(n) + " data row(s); a recording needs at least a minute of samples");

  Recording rec;
  rec.source = path;

  // Time: seconds, or clock text (detected from the first row) with midnight crossings unwrapped.
  rec.time_s.resize(n);
  const bool clock = table.rows[0][col_t].find(':') != std::string::npos;
  const auto col_date = find("date");
  std::vector<std::size_t> date_disagrees;
  std::size_t day = 0;
  std::string current_date = col_date ? table.rows[0][*col_date] : "";
  // A logger writing one file over several days: a date that moves on across a break in the logging starts a later
  // day, which the clock alone cannot tell (10:34 on 7/2 after 11:50 on 7/1 was "time goes backwards": session 23's
  // outside testing). Within continuous logging the clock rules, so a date kept in another time zone than the clock
  // only earns a note (date_disagrees).
  const std::vector<long> day_numbers = clock && col_date ? date_day_numbers(table, *col_date) : std::vector<long>{};
  for (std::size_t r = 0; r < n; ++r) {
    const std::string& cell = table.rows[r][col_t];
    if (is_missing(cell)) throw InputError(table.where(r, col_t), "time is missing; every row needs a time");
    double t = 0.0;
    if (clock) {
      const auto c = parse_clock(cell);
      if (!c) throw InputError(table.where(r, col_t), "'" + cell + "' is not a clock time HH:MM:SS (as on line " +
                                                          std::to_string(table.row_line[0]) + ")");
      if (r > 0) {
        const double prev_clock = rec.time_s[r - 1] - static_cast<double>(day) * kSecondsPerDay;
        const long days_on = day_numbers.empty() ? 0 : day_numbers[r] - day_numbers[r - 1];
        const bool a_break = *c < prev_clock || *c - prev_clock > kReportedGap_s;
        if (days_on > 0 && a_break) {
          day += static_cast<std::size_t>(days_on);
          current_date = table.rows[r][*col_date];
        } else if (*c < prev_clock - kMidnightFall_s) {
          ++day;
          if (col_date) {
            const std::string& d = table.rows[r][*col_date];
            if (d == table.rows[r - 1][*col_date]) {
              throw InputError(table.where(r, col_t), "the clock goes from " + table.rows[r - 1][col_t] + " (line " +
                                                          std::to_string(table.row_line[r - 1]) + ") to " + cell +
                                                          " but the date stays " + d + ": time goes backwards");
            }
            current_date = d;
          }
        }
      }
      t = *c + static_cast<double>(day) * kSecondsPerDay;
      if (col_date && table.rows[r][*col_date] != current_date) date_disagrees.push_back(r);
    } else {
      const auto v = parse_number(cell);
      if (!v) throw InputError(table.where(r, col_t), "'" + cell + "' is not a number (seconds) nor a clock time HH:MM:SS");
      if (!std::isfinite(*v)) throw InputError(table.where(r, col_t), "'" + cell + "' is not allowed: must be finite");
      t = *v;
    }
    if (r > 0 && !(t > rec.time_s[r - 1])) {
      throw InputError(table.where(r, col_t),
                       "time " + cell + " is " + (t == rec.time_s[r - 1] ? "the same as" : "before") + " " +
                           table.rows[r - 1][col_t] + " on line " + std::to_string(table.row_line[r - 1]) +
                           ": time must increase from row to row" +
                           same_in_double_precision(cell, table.rows[r - 1][col_t], t, rec.time_s[r - 1]));
    }
    rec.time_s[r] = t;
  }
  if (!date_disagrees.empty()) {
    rec.repairs.push_back(std::to_string(date_disagrees.size()) + " row(s) have a '" + source_of("date") +
                          "' value that differs from the day the clock implies (first: line " +
                          std::to_string(table.row_line[date_disagrees.front()]) + ", '" +
                          table.rows[date_disagrees.front()][*col_date] + "'); the clock was used and those dates ignored");
  }

  // Sample interval: the median step must be 0.01-1 s (1-100 Hz), with 2 % for a logger's clock (a 1 Hz logger 0.05 %
  // slow, or one whose stamps jitter by 20 ms, was refused).
  std::vector<double> steps(n - 1);
  for (std::size_t i = 0; i + 1 < n; ++i) steps[i] = rec.time_s[i + 1] - rec.time_s[i];
  const double dt = median(steps);
  if (dt < 0.0098 || dt > 1.02) {
    throw InputError(path + ": column '" + table.header[col_t] + "'",
                     "the typical (median) sample interval is " + format_value(dt) +
                         " s; supported: 0.01 to 1 s (1 to 100 Hz, within 2 % for the logger's clock)");
  }
  if (rec.duration_s() < kMinRecordingDuration_s) {
    throw InputError(path, "lasts " + format_value(rec.duration_s()) + " s (" + lines_text(table, 0, n - 1) +
                               "); a recording must last at least " + format_value(kMinRecordingDuration_s) + " s");
  }
  {
    std::size_t count = 0;
    std::string listed;
    for (std::size_t i = 0; i + 1 < n; ++i) {
      if (steps[i] > kReportedGap_s) {
        if (++count <= 10) {
          listed += (count > 1 ? "; " : "") + format_value(steps[i]) + " s between " + lines_text(table, i, i + 1);
        }
      }
    }
    if (count) {
      rec.repairs.push_back(std::to_string(count) + " gap(s) in time longer than " + format_value(kReportedGap_s) +
                            " s kept, not bridged (no energy window spans one): " + listed + (count > 10 ? "; ..." : ""));
    }
  }

  // Value channels: read, scale, check range, bridge short NaN runs.
  auto read_channel = [&](const std::string& canonical, std::size_t col) {
    Channel ch{canonical, col, std::vector<double>(n, kNaN)};
    auto it = mapping.scale_for_canonical.find(canonical);
    const double scale = it != mapping.scale_for_canonical.end() ? it->second : 1.0;
    for (std::size_t r = 0; r < n; ++r) {
      const std::string& cell = table.rows[r][col];
      if (is_missing(cell)) continue;
      const auto v = parse_number(cell);
      if (!v) throw InputError(table.where(r, col), not_a_number(cell));
      if (!std::isfinite(*v)) throw InputError(table.where(r, col), "'" + cell + "' is not allowed: must be finite");
      ch.values[r] = *v * scale;
    }
    return ch;
  };
  auto check_range = [&](Channel& ch, double lo, double hi, const std::string& unit) {
    for (std::size_t r = 0; r < n; ++r) {
      const double v = ch.values[r];
      if (std::isnan(v)) continue;
      if (v < lo || v > hi) {
        const auto it = mapping.scale_for_canonical.find(ch.canonical);
        const std::string scaled = it != mapping.scale_for_canonical.end() ? " after scale " + format_value(it->second) : "";
        throw InputError(table.where(r, ch.col), format_value(v) + " " + unit + scaled + " is not allowed for " +
                                                     ch.canonical + ": must be in [" + format_value(lo) + ", " +
                                                     format_value(hi) + "]");
      }
    }
  };
  auto bridge = [&](Channel& ch) {
    std::size_t runs = 0, missing = 0;
    double longest = 0.0;
    std::size_t r = 0;
    while (r < n) {
      if (!std::isnan(ch.values[r])) {
        ++r;
        continue;
      }
      std::size_t e = r;
      while (e + 1 < n && std::isnan(ch.values[e + 1])) ++e;
      if (r == 0 && e == n - 1) {
        throw InputError(path + ": column '" + table.header[ch.col] + "'", "holds no value at all (" + ch.canonical + ")");
      }
      // Duration the missing samples cover: from the first to the last, plus one sample interval.
      const double run_s = rec.time_s[e] - rec.time_s[r] + dt;
      if (run_s > kMaxBridgedRun_s + 1e-9) {
        throw InputError(path + ": " + lines_text(table, r, e) + ", column '" + table.header[ch.col] + "'",
                         std::to_string(e - r + 1) + " missing values in a row (" + format_value(run_s) +
                             " s); only runs up to " + format_value(kMaxBridgedRun_s) + " s are bridged");
      }
      for (std::size_t i = r; i <= e; ++i) {
        if (r == 0) {
          ch.values[i] = ch.values[e + 1];  // leading run: hold the first value (no interpolation possible)
        } else if (e == n - 1) {
          ch.values[i] = ch.values[r - 1];  // trailing run: hold the last value
        } else {
          const double w = (rec.time_s[i] - rec.time_s[r - 1]) / (rec.time_s[e + 1] - rec.time_s[r - 1]);
          ch.values[i] = ch.values[r - 1] + w * (ch.values[e + 1] - ch.values[r - 1]);
        }
      }
      ++runs;
      missing += e - r + 1;
      longest = std::max(longest, run_s);
      r = e + 1;
    }
    if (runs) {
      rec.repairs.push_back("column '" + table.header[ch.col] + "' (" + ch.canonical + "): " + std::to_string(missing) +
                            " missing value(s) in " + std::to_string(runs) +
                            " run(s) bridged by linear interpolation (held at the ends), longest " +
                            format_value(longest) + " s");
    }
  };
  auto optional_channel = [&](const std::string& canonical, double lo, double hi, const std::string& unit,
                              double to_si, double offset = 0.0) -> std::optional<std::vector<double>> {
    const auto col = find(canonical);
    if (!col) return std::nullopt;
    Channel ch = read_channel(canonical, *col);
    check_range(ch, lo, hi, unit);
    bridge(ch);
    for (double& v : ch.values) v = v * to_si + offset;
    return std::move(ch.values);
  };
  // GPS position: the diagnosis reads it only to describe a trip, so a bad cell (text, out of range: a longitude of
  // 1555.6 on one line) is read as missing and reported, and a column too broken to bridge is dropped with a note.
  // A glitch there never stops a run.
  auto gps_channel = [&](const std::string& canonical, double limit_deg) -> std::optional<std::vector<double>> {
    const auto col = find(canonical);
    if (!col) return std::nullopt;
    const std::string name = "column '" + table.header[*col] + "' (" + canonical + ")";
    auto it = mapping.scale_for_canonical.find(canonical);
    const double scale = it != mapping.scale_for_canonical.end() ? it->second : 1.0;
    Channel ch{canonical, *col, std::vector<double>(n, kNaN)};
    std::size_t zeros = 0, bad = 0;
    std::string first_bad;
    for (std::size_t r = 0; r < n; ++r) {
      const std::string& cell = table.rows[r][*col];
      if (is_missing(cell)) continue;
      const auto v = parse_number(cell);
      // GPS loggers write exactly 0 when they have no fix (the Twizy files do, for a few seconds); a trip on
      // the equator or the prime meridian to the last logged digit is not plausible, so 0 is read as missing.
      if (v && *v == 0.0) {
        ++zeros;
        continue;
      }
      if (!v || !std::isfinite(*v * scale) || std::abs(*v * scale) > limit_deg) {
        if (bad++ == 0) first_bad = "line " + std::to_string(table.row_line[r]) + ": '" + cell + "'";
        continue;
      }
      ch.values[r] = *v * scale;
    }
    if (zeros) rec.repairs.push_back(name + ": " + std::to_string(zeros) + " value(s) of exactly 0 read as 'no GPS fix', i.e. missing");
    if (bad) {
      rec.repairs.push_back("warning: " + name + ": " + std::to_string(bad) + " value(s) not a number in [-" +
                            format_value(limit_deg) + ", " + format_value(limit_deg) + "] deg read as missing (first: " +
                            first_bad + ")");
    }
    try {
      bridge(ch);
    } catch (const InputError& e) {
      rec.repairs.push_back("warning: " + name + " dropped, the diagnosis does not need it: " + e.what());
      return std::nullopt;
    }
    return std::move(ch.values);
  };

  {
    Channel speed = read_channel("speed_kmh", col_v);
    std::size_t clipped = 0;
    for (std::size_t r = 0; r < n; ++r) {
      double& v = speed.values[r];
      if (std::isnan(v) || v >= 0.0) continue;
      if (v < -kSpeedNoise_kmh) {
        throw InputError(table.where(r, col_v), format_value(v) + " km/h is not allowed: speed must be >= 0 (values down to -" +
                                                    format_value(kSpeedNoise_kmh) + " are read as standstill noise)");
      }
      v = 0.0;
      ++clipped;
    }
    if (clipped) {
      rec.repairs.push_back("column '" + table.header[col_v] + "' (speed_kmh): " + std::to_string(clipped) +
                            " slightly negative value(s) (> -1 km/h) set to 0");
    }
    check_range(speed, 0.0, 500.0, "km/h");
    bridge(speed);
    rec.speed_mps.resize(n);
    for (std::size_t r = 0; r < n; ++r) rec.speed_mps[r] = units::kmh_to_mps(speed.values[r]);
  }
  const double big = 1e12;
  rec.battery_power_w = optional_channel("battery_power_kw", -big, big, "kW", 1000.0);
  rec.battery_voltage_v = optional_channel("battery_voltage_v", 1e-9, 2000.0, "V", 1.0);
  rec.battery_current_a = optional_channel("battery_current_a", -big, big, "A", 1.0);
  rec.soc_fraction = optional_channel("soc_pct", 0.0, 100.0, "%", 0.01);
  // A flow meter reads a little below zero when its zero drifts: down to kFuelZeroOffset_lph it is kept as measured
  // (a run stopped at -0.07 l/h) and said; below, it is not a fuel flow.
  if (const auto col = find("fuel_rate_lph")) {
    const Channel ch = read_channel("fuel_rate_lph", *col);
    std::size_t below = 0, lowest_row = 0;
    for (std::size_t r = 0; r < n; ++r) {
      if (!(ch.values[r] < 0.0)) continue;
      if (below++ == 0 || ch.values[r] < ch.values[lowest_row]) lowest_row = r;
    }
    if (below)
      rec.repairs.push_back("fuel_rate_lph: " + std::to_string(below) + " value(s) below 0 (lowest " +
                            significant(ch.values[lowest_row], 3) + " l/h, line " +
                            std::to_string(table.row_line[lowest_row]) + "), kept as measured: a flow meter's zero offset; below " + format_value(kFuelZeroOffset_lph) +
                            " l/h is refused");
  }
  rec.fuel_rate_m3ps = optional_channel("fuel_rate_lph", kFuelZeroOffset_lph, 1000.0, "l/h", units::kM3PerLitre / units::kSPerHour);
  rec.elevation_m = optional_channel("elevation_m", -500.0, 9000.0, "m", 1.0);
  rec.grade = optional_channel("grade_pct", -30.0, 30.0, "%", 0.01);
  rec.ambient_temp_k = optional_channel("ambient_temp_c", -60.0, 70.0, "C", 1.0, units::kKelvinOffset);
  rec.latitude_deg = gps_channel("latitude", 90.0);
  rec.longitude_deg = gps_channel("longitude", 180.0);

  if (rec.battery_voltage_v.has_value() != rec.battery_current_a.has_value() && rec.battery_power_w) {
    // A lone current (or voltage) beside a power channel is not needed: simulate's own --trace holds
    // battery_current_a with battery_power_kw, and was refused (session 21).
    const std::string have = rec.battery_voltage_v ? "battery_voltage_v" : "battery_current_a";
    rec.repairs.push_back(have + " without its pair: not used; battery_power_kw is the battery's channel");
    rec.battery_voltage_v.reset();
    rec.battery_current_a.reset();
  }
  if (rec.battery_voltage_v.has_value() != rec.battery_current_a.has_value()) {
    const std::string have = rec.battery_voltage_v ? "battery_voltage_v" : "battery_current_a";
    const std::string lack = rec.battery_voltage_v ? "battery_current_a" : "battery_voltage_v";
    throw InputError(path, "has " + have + " ('" + source_of(have) + "') but no " + lack +
                               "; battery power needs both; " + found + map_hint(mapping, lack));
  }
  if (!rec.battery_power_w && !rec.battery_voltage_v && !rec.soc_fraction && !rec.fuel_rate_m3ps) {
    throw InputError(path, "has no energy channel: need one of battery_power_kw, battery_voltage_v with "
                           "battery_current_a, soc_pct or fuel_rate_lph; " + found +
                               map_hint(mapping, "", "one of them"));
  }
  return rec;
}

}  // namespace rollsim
