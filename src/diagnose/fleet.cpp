// Fleet diagnosis: the manifest checked up front, one diagnosis per group as a distributed case, the fleet summary.
#include "rollsim/diagnose/fleet.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>
#include <type_traits>

#include "rollsim/common/csv.hpp"
#include "rollsim/common/error.hpp"
#include "rollsim/common/format.hpp"
#include "rollsim/common/input_file.hpp"
#include "rollsim/common/statistics.hpp"
#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/report/table.hpp"

namespace rollsim {
namespace {

std::vector<std::string> split_list(const std::string& cell) {
  std::vector<std::string> out;
  std::stringstream in(cell);
  for (std::string part; std::getline(in, part, ';');)
    if (!trim(part).empty()) out.push_back(trim(part));
  return out;
}

// A path relative to the manifest's folder when that file exists there, else as the diagnose command resolves it.
std::string resolve(const std::string& cell, const std::string& manifest, const char* shipped, const char* ext,
                    const std::string& where) {
  try {
    return resolve_data_file_beside(cell, manifest, shipped, ext, where);
  } catch (const InputError& e) {
    const auto beside = std::filesystem::path(manifest).parent_path() / cell;
    if (const std::string why = why_not_a_file(beside); why != "not found") throw InputError(where, "'" + beside.string() + "' " + why);
    throw InputError(where, "'" + cell + "' not found (relative to the manifest's folder, or a shipped name)");
  }
}

}  // namespace

FleetManifest read_fleet_manifest(const std::string& path) {
  const CsvTable t = read_csv(path);
  auto col = [&](const char* name, bool required) {
    const auto c = t.column(name);
    if (!c && required)
      throw InputError(path + ": line " + std::to_string(t.header_line),
                       std::string("missing column '") + name + "' (found: " + t.columns_list() + ")");
    return c;
  };
  const auto vehicle = col("vehicle", true), recording = col("recording", true);
  // A column the manifest does not know is a misspelling, not a note: 'Tyre' or 'scale' was ignored, and the groups
  // diagnosed without the tyre or scales they named (session 22's outside testing).
  constexpr const char* kColumns[] = {"vehicle", "recording", "group", "tyre", "preset", "columns", "scales"};
  for (const auto& h : t.header) {
    if (std::find(std::begin(kColumns), std::end(kColumns), h) == std::end(kColumns))
      throw InputError(path + ": line " + std::to_string(t.header_line),
                       "unknown column '" + h + "' (misspelt?); allowed: vehicle, recording, group, tyre, preset, columns, scales");
  }
  const auto group = col("group", false), tyre = col("tyre", false), preset = col("preset", false),
             columns = col("columns", false), scales = col("scales", false);
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  FleetManifest m{path, {}};
  std::map<std::string, std::size_t> index;
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    const auto& row = t.rows[r];
    auto cell = [&](const std::optional<std::size_t>& c) { return c ? trim(row[*c]) : std::string(); };
    auto where = [&](const std::optional<std::size_t>& c) { return t.where(r, *c); };
    if (cell(vehicle).empty()) throw InputError(where(vehicle), "empty: give a vehicle file or shipped name");
    if (cell(recording).empty()) throw InputError(where(recording), "empty: give a recording CSV");
    const std::string vehicle_path = resolve(cell(vehicle), path, "vehicles", ".yaml", where(vehicle));
    const std::string tyre_path = cell(tyre).empty() ? "" : resolve(cell(tyre), path, "tyres", ".yaml", where(tyre));
    const std::filesystem::path rec = dir / cell(recording);
    if (const std::string why = why_not_a_file(rec); !why.empty()) throw InputError(where(recording), "file '" + rec.string() + "' " + why);
    FleetRecording fr{rec.string(), {}, t.row_line[r]};
    try {
      YamlMap vehicle_file = YamlMap::load_file(vehicle_path);
      fr.mapping = assemble_mapping(cell(preset), vehicle_file, split_list(cell(columns)), split_list(cell(scales)),
                                    "columns", "scales");
      fr.mapping.how_to_map = "in the manifest's columns cell (CANONICAL=SOURCE) or with its preset";
    } catch (const InputError& e) {
      throw InputError(path + ": line " + std::to_string(fr.line), e.what());
    }
    const std::string name = group && !cell(group).empty() ? cell(group) : cell(vehicle);
    auto [it, fresh] = index.try_emplace(name, m.groups.size());
    if (fresh) m.groups.push_back({name, vehicle_path, tyre_path, {}});
    FleetGroup& g = m.groups[it->second];
    if (g.vehicle_path != vehicle_path || g.tyre_path != tyre_path)
      throw InputError(where(vehicle), "group '" + name + "' already has vehicle '" + g.vehicle_path +
                                           (g.tyre_path.empty() ? "" : "' with tyre '" + g.tyre_path) +
                                           "': one diagnosis is one car; give this row another group");
    g.recordings.push_back(std::move(fr));
  }
  if (m.groups.empty()) throw InputError(path, "no recordings listed (a header line and one row per recording)");
  return m;
}

namespace {

FleetEntry diagnose_group(const FleetGroup& g, const DiagnoseOptions& o) {
  YamlMap vehicle_file = YamlMap::load_file(g.vehicle_path);
  Vehicle v = load_vehicle(vehicle_file);
  if (!g.tyre_path.empty()) fit_tyres(v, load_tyre_file(g.tyre_path));
  std::vector<Recording> recs;
  for (const auto& r : g.recordings) recs.push_back(load_recording(r.path, r.mapping));
  DiagnoseOptions group_options = o;
  group_options.priors = calibration_priors_from_yaml(vehicle_file);  // each car's own calibration bounds
  const Diagnosis d = diagnose(v, recs, group_options);
  FleetEntry e{g.name, v.name, d.verdict, d.channel, recs.size(), {}, {}};
  for (const auto& note : d.notes)
    if (note.rfind("warning: ", 0) == 0) e.warnings.push_back(note.substr(9));
  for (const auto& f : d.findings) {
    FleetFinding ff{f.effect, "", "", 0.0, f.energy_share_pct};
    if (!f.parameters.empty()) {
      ff.parameter = f.parameters.front().name;
      ff.unit = f.parameters.front().unit;
      ff.value = f.parameters.front().value;
    }
    e.findings.push_back(ff);
  }
  return e;
}

// Every field of an entry, in one order, for both directions of the gather's serialisation.
template <class Entry, class Field>
void each_field(Entry& e, Field&& field) {
  for (auto* s : {&e.group, &e.vehicle, &e.verdict, &e.channel}) field(*s);
  field(e.recordings);
  std::size_t n = e.findings.size();
  field(n);
  if constexpr (!std::is_const_v<Entry>) e.findings.resize(n);
  for (auto& f : e.findings) {
    for (auto* s : {&f.effect, &f.parameter, &f.unit}) field(*s);
    field(f.value);
    field(f.energy_share_pct);
  }
  std::size_t w = e.warnings.size();
  field(w);
  if constexpr (!std::is_const_v<Entry>) e.warnings.resize(w);
  for (auto& s : e.warnings) field(s);
}

std::string to_bytes(const FleetEntry& e) {
  std::string b;
  each_field(e, [&](const auto& x) { put(b, x); });
  return b;
}

FleetEntry from_bytes(std::string_view in) {
  FleetEntry e;
  each_field(e, [&](auto& x) { take(in, x); });
  return e;
}

}  // namespace

// Per effect: how many diagnoses found it, and the median of the parameter most of them report first (ties: the
// name first in order), so that the summary does not depend on the manifest's order when the first parameter
// differs between diagnoses (an unexplained finding's first figure depends on what it found).
std::vector<FleetEffect> summarise_fleet(const std::vector<FleetEntry>& entries) {
  std::map<std::string, FleetEffect> by_id;
  std::map<std::string, std::map<std::string, std::vector<const FleetFinding*>>> by_parameter;
  for (const auto& e : entries) {
    std::vector<std::string> seen;  // an effect found twice in one diagnosis counts once
    for (const auto& f : e.findings) {
      if (std::find(seen.begin(), seen.end(), f.effect) != seen.end()) continue;
      seen.push_back(f.effect);
      FleetEffect& s = by_id[f.effect];
      s.effect = f.effect;
      ++s.groups;
      if (!f.parameter.empty()) by_parameter[f.effect][f.parameter].push_back(&f);
    }
  }
  std::vector<FleetEffect> out;
  for (auto& [id, s] : by_id) {
    s.share_pct = 100.0 * static_cast<double>(s.groups) / static_cast<double>(entries.size());
    const std::vector<const FleetFinding*>* most = nullptr;
    for (const auto& [name, found] : by_parameter[id])
      if (!most || found.size() > most->size()) most = &found;
    if (most) {
      s.parameter = most->front()->parameter;
      s.unit = most->front()->unit;
      std::vector<double> values;
      for (const FleetFinding* f : *most) values.push_back(f->value);
      s.median_value = median(values);
    }
    out.push_back(s);
  }
  std::stable_sort(out.begin(), out.end(), [](const FleetEffect& a, const FleetEffect& b) { return a.groups > b.groups; });
  return out;
}

FleetResult diagnose_fleet(const FleetManifest& m, const FleetOptions& o) {
  // Each group is read on the rank that diagnoses it; its manifest line names it if that fails.
  const auto body = [&](std::size_t k) {
    const FleetGroup& g = m.groups[k];
    try {
      return to_bytes(diagnose_group(g, o.diagnose));
    } catch (const std::exception& e) {
      throw InputError(m.file + ": group '" + g.name + "' (line " + std::to_string(g.recordings.front().line) + ")",
                       e.what());
    }
  };
  FleetResult r;
  r.manifest = m.file;
  for (const auto& bytes : map_cases(o.map_cases, m.groups.size(), o.threads, body, {})) r.entries.push_back(from_bytes(bytes));
  r.effects = summarise_fleet(r.entries);
  return r;
}

namespace {
// A figure of the fleet's table: three decimals from 1 up, four significant digits below (an ambient law's 0.0075 /K
// read 0.007, one digit: session 27's outside tester).
std::string figure(double v) { return std::abs(v) >= 1.0 ? fixed(v, 3) : significant(v, 4); }
}  // namespace

std::string fleet_text(const FleetResult& r) {
  std::size_t recordings = 0;
  for (const auto& e : r.entries) recordings += e.recordings;
  std::ostringstream out;
  out << "fleet " << r.manifest << ": " << r.entries.size() << " diagnoses of " << recordings << " recordings\n";
  report::TextTable t({"group", "vehicle", "recordings", "channel", "verdict", "findings"});
  for (std::size_t c : {0u, 1u, 3u, 4u, 5u}) t.set_left_aligned(c);
  for (const auto& e : r.entries) {
    std::string found;
    for (const auto& f : e.findings) {
      found += (found.empty() ? "" : ", ") + f.effect;
      if (!f.parameter.empty()) found += " (" + figure(f.value) + " " + f.unit + ")";
    }
    t.add_row({e.group, e.vehicle, std::to_string(e.recordings), e.channel, e.verdict, found.empty() ? "-" : found});
  }
  out << t.render() << "\neffects across the fleet (diagnoses that found each; median of the first parameter most of them report):\n";
  report::TextTable s({"effect", "diagnoses", "share [%]", "parameter", "median", "unit"});
  for (std::size_t c : {0u, 3u, 5u}) s.set_left_aligned(c);
  for (const auto& f : r.effects) {
    s.add_row({f.effect, std::to_string(f.groups), fixed(f.share_pct, 1), f.parameter.empty() ? "-" : f.parameter,
               f.parameter.empty() ? "-" : figure(f.median_value), f.unit.empty() ? "-" : f.unit});
  }
  out << (r.effects.empty() ? "  none: nothing missing in any diagnosis\n" : s.render());
  return out.str();
}

std::vector<JsonObject> fleet_json(const FleetResult& r) {
  std::vector<JsonObject> out;
  for (const auto& e : r.entries) {
    JsonObject j;
    j.add("group", e.group).add("vehicle", e.vehicle).add("recordings", static_cast<int>(e.recordings));
    j.add("channel", e.channel).add("verdict", e.verdict);
    // A list, as the single diagnosis' JSON has it: one diagnosis can name an effect twice (two `unexplained`
    // findings), and keyed by effect the second overwrote the first in every parser (session 20).
    std::vector<JsonObject> findings;
    for (const auto& f : e.findings) {
      JsonObject fj;
      fj.add("effect", f.effect).add("parameter", f.parameter).add("value", f.value).add("unit", f.unit);
      fj.add("energy_share_pct", f.energy_share_pct);
      findings.push_back(fj);
    }
    j.add("findings", findings);
    j.add("warnings", e.warnings);
    out.push_back(j);
  }
  for (const auto& f : r.effects) {
    JsonObject j;
    j.add("fleet_effect", f.effect).add("diagnoses", static_cast<int>(f.groups)).add("share_pct", f.share_pct);
    j.add("parameter", f.parameter).add("median", f.median_value).add("unit", f.unit);
    out.push_back(j);
  }
  return out;
}

}  // namespace rollsim
