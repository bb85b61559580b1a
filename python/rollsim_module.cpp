// The Python module `rollsim`: glue over rollsim_lib. Every figure comes from the library's own --json writers,
// parsed by Python's json module, so the dicts hold the command line's keys and values by construction.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "rollsim/common/atomic_file.hpp"
#include "rollsim/common/csv.hpp"
#include "rollsim/common/error.hpp"
#include "rollsim/common/format.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/diagnose/diagnose.hpp"
#include "rollsim/powertrain/engine_map.hpp"
#include "rollsim/recording/recording.hpp"
#include "rollsim/report/simulation_report.hpp"
#include "rollsim/selection/front_end.hpp"
#include "rollsim/sim/vehicle_run.hpp"
#include "rollsim/tyre/j2452.hpp"
#include "rollsim/tyre/tyre_fit_plan.hpp"
#include "rollsim/tyre/tyre_model.hpp"
#include "rollsim/tyre/tyre_request.hpp"
#include "rollsim/validate/front_end.hpp"
#include "rollsim/vehicle/vehicle.hpp"

namespace py = pybind11;
using namespace rollsim;
using namespace pybind11::literals;

namespace {

py::object from_json(const std::string& text) { return py::module_::import("json").attr("loads")(text); }
std::string to_json(py::handle obj) { return py::module_::import("json").attr("dumps")(obj).cast<std::string>(); }
// What the CLI prints as "warning: ..." on stderr; raises if the user's warning filter turns it into an error.
void warn(const std::string& text) {
  if (PyErr_WarnEx(PyExc_UserWarning, text.c_str(), 1) != 0) throw py::error_already_set();
}

// A path-like object (pathlib.Path, os.DirEntry) as the str os.fspath gives; anything else as it is. A script builds
// its paths with pathlib, and a Path was refused as "expected ... (str)".
py::object fspath_or_self(py::handle x) {
  if (py::isinstance<py::str>(x) || !py::hasattr(x, "__fspath__")) return py::reinterpret_borrow<py::object>(x);
  return py::module_::import("os").attr("fspath")(x);
}

// A keyword argument as T, or the named error a command-line user would get for a malformed option.
template <class T>
T arg_as(py::handle arg, const std::string& where, const std::string& expected) {
  py::object x = py::reinterpret_borrow<py::object>(arg);
  if constexpr (std::is_same_v<T, std::string>) x = fspath_or_self(arg);
  if constexpr (std::is_same_v<T, std::vector<std::string>>) {
    if (py::isinstance<py::list>(arg) || py::isinstance<py::tuple>(arg)) {
      py::list paths;
      for (py::handle item : arg) paths.append(fspath_or_self(item));
      x = paths;
    }
  }
  // A Python type wrapper's cast converts (py::dict from a list of pairs, or from "camry" with a ValueError): check.
  if constexpr (std::is_base_of_v<py::object, T>) {
    if (!py::isinstance<T>(x)) throw InputError(where, "expected " + expected);
  }
  // pybind takes True as the number 1 (session 22's outside testing: pressure_bar=True read 1 bar).
  if constexpr (std::is_arithmetic_v<T>) {
    if (py::isinstance<py::bool_>(x) || py::isinstance(x, py::module_::import("numpy").attr("bool_")))
      throw InputError(where, "a bool is not allowed: expected " + expected);
  }
  T out;
  try {
    out = x.cast<T>();
  } catch (const py::cast_error&) {
    // A str with a lone surrogate (a non-UTF-8 file name from os.listdir) cannot be UTF-8 (session 22).
    if (std::is_same_v<T, std::string> && py::isinstance<py::str>(x)) throw InputError(where, "a str that is not valid Unicode text (a lone surrogate?) is not allowed");
    throw InputError(where, "expected " + expected);
  } catch (const py::error_already_set&) {  // e.g. len() of a 0-d numpy array given for a list (session 22)
    throw InputError(where, "expected " + expected);
  } catch (const py::type_error&) {  // a Python type wrapper (py::sequence, py::dict) given another type
    throw InputError(where, "expected " + expected);
  }
  // A NUL ends a path for the C library: 'ev.yaml\0junk' read ev.yaml, and an output was written elsewhere
  // than named (session 22); Python's own open() refuses it.
  if constexpr (std::is_same_v<T, std::string>) {
    if (out.find('\0') != std::string::npos) throw InputError(where, "a NUL character in a name or path is not allowed");
  } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
    for (const auto& s : out)
      if (s.find('\0') != std::string::npos) throw InputError(where, "a NUL character in a name or path is not allowed");
  }
  return out;
}

// A dict's values as json.dumps takes them: numpy scalars become Python numbers and arrays lists (what a script
// computes with numpy; json refused them with a TypeError naming no key). Anything else is named by its key path.
py::object plain(py::handle x, const std::string& what, const std::string& path, int depth = 0) {
  // As deep as a YAML file may nest (the loader's check_keys): a dict that holds itself, or one nested thousands deep,
  // recursed until the interpreter's stack overflowed (session 20).
  if (depth > 64)
    throw InputError(what + ": key '" + path.substr(0, 80) + (path.size() > 80 ? "..." : "") + "'",
                     "nested more than 64 levels deep (a dict or list that holds itself?)");
  if (x.is_none() || py::isinstance<py::str>(x) || py::isinstance<py::bool_>(x) || py::isinstance<py::int_>(x) ||
      py::isinstance<py::float_>(x))
    return py::reinterpret_borrow<py::object>(x);
  const auto np = py::module_::import("numpy");
  if (py::isinstance(x, np.attr("generic")) || py::isinstance<py::array>(x)) {
    if (py::isinstance(x, np.attr("ma").attr("MaskedArray")))
      throw InputError(what + ": key '" + path + "'", "a masked array is not allowed: give plain numbers");
    return plain(x.attr("tolist")(), what, path, depth);  // np.float32(2.5) -> 2.5, an array -> a list
  }
  if (py::isinstance<py::dict>(x)) {
    py::dict out;
    for (auto item : x.cast<py::dict>()) {
      const bool named = py::isinstance<py::str>(item.first) || py::isinstance<py::int_>(item.first);
      const std::string key = py::str(item.first).cast<std::string>();
      const std::string at = path.empty() ? key : path + "." + key;
      if (!named) throw InputError(what + ": key '" + at + "'", "a key must be text (str)");
      out[py::str(key)] = plain(item.second, what, at, depth + 1);
    }
    return out;
  }
  if (py::isinstance<py::list>(x) || py::isinstance<py::tuple>(x)) {
    py::list out;
    std::size_t i = 0;
    for (auto item : x) out.append(plain(item, what, path + "[" + std::to_string(i++) + "]", depth + 1));
    return out;
  }
  throw InputError(what + ": key '" + path + "'",
                   "a " + py::str(py::type::of(x).attr("__name__")).cast<std::string>() +
                       " is not allowed: expected a number, text, a list or a dict (numpy numbers and arrays are taken)");
}
// The JSON text of a dict given for a YAML file (`what`: "vehicle dict"), or InputError naming `argument`.
std::string dict_json(py::handle x, const std::string& what) { return to_json(plain(x, what, "")); }

// A 1-D or scalar array of numbers. numpy's conversion would read a masked array's hidden values and a bool array as
// 0 and 1, driving both silently.
py::array_t<double> number_array(py::handle x, const std::string& where) {
  const auto np = py::module_::import("numpy");
  if (py::isinstance(x, np.attr("ma").attr("MaskedArray")) && np.attr("ma").attr("count_masked")(x).cast<long>() > 0) {
    throw InputError(where, "a masked array with " + py::str(np.attr("ma").attr("count_masked")(x)).cast<std::string>() +
                                " masked value(s) is not allowed: drop or fill them (.filled(), .compressed()) first");
  }
  py::object data;
  try {
    data = np.attr("ma").attr("getdata")(x);  // a plain array of what was given (of objects for anything else)
  } catch (const py::error_already_set&) {  // e.g. a ragged list
    throw InputError(where, "expected a number or an array of numbers");
  }
  const std::string kind = data.attr("dtype").attr("kind").cast<std::string>();
  if (kind == "b") throw InputError(where, "a bool array is not allowed: expected numbers");
  // Only integers and reals: numpy's cast reads '80' as 80, a complex number as its real part and a date as a
  // count of days (session 20), where a number option given text is an error.
  if (kind != "i" && kind != "u" && kind != "f")
    throw InputError(where, "expected a number or an array of numbers, not " + py::str(data.attr("dtype")).cast<std::string>());
  // c_style: a column view (a[:, 0]) or a reversed one was read as if its elements were adjacent, computing every
  // figure at the wrong speeds or from memory past the array (session 22's outside testing); a copy when needed.
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(data);
  if (!a) throw InputError(where, "expected a number or an array of numbers");
  return a;
}

// A Python bool (or numpy's); pybind's own conversion takes any number, 2.5 or None, as a truth value.
bool flag(py::handle x, const std::string& where) {
  const auto np = py::module_::import("numpy");
  if (!py::isinstance<py::bool_>(x) && !py::isinstance(x, np.attr("bool_"))) throw InputError(where, "expected True or False");
  return x.cast<bool>();
}

// A Python number as the text the command line would have been given (shortest round-trip form: exact).
std::string number_text(py::handle x, const std::string& where) {
  if (x.is_none()) return "";
  return format_value(arg_as<double>(x, where, "a number"));
}

constexpr const char* kNameOrDict = "a shipped name or a file path (str), or a dict with the file's keys";

// A file or shipped name (str), or a Python dict with the keys of the YAML file.
std::string vehicle_path(py::handle v) {
  return resolve_data_file(arg_as<std::string>(v, "vehicle", kNameOrDict), "vehicles", ".yaml", "--vehicle");
}
Vehicle vehicle_from(py::handle v) {
  if (py::isinstance<py::dict>(v)) return load_vehicle_text(dict_json(v, "vehicle dict"), "vehicle dict");
  return load_vehicle_file(vehicle_path(v));
}
std::optional<TyreSpec> tyre_from(py::handle t) {
  if (t.is_none()) return std::nullopt;
  if (py::isinstance<py::dict>(t)) return load_tyre_text(dict_json(t, "tyre dict"), "tyre dict");
  return load_tyre_file(resolve_data_file(arg_as<std::string>(t, "tyre", kNameOrDict), "tyres", ".yaml", "--tyre"));
}

// A shipped name or CSV path; a dict of arrays named like the CSV columns (time_s, speed_kmh or speed_mps,
// optional grade_pct or elevation_m, heading_deg, engine_on); or a pair (time_s, speed_kmh). Arrays pass the CSV
// file's checks, their errors naming the sample index as the "line".
DriveCycle cycle_arrays(py::handle c);
DriveCycle cycle_from(py::handle c) {
  const py::object path = fspath_or_self(c);
  const DriveCycle cycle = py::isinstance<py::str>(path) ? load_cycle(arg_as<std::string>(path, "cycle", "a cycle name or path (str)"), "--cycle") : cycle_arrays(c);
  // What the trace holds that a user should hear of, as warnings, as the CLI's load_cycle_noted says it on stderr.
  if (const std::string note = ignored_columns_note(cycle); !note.empty()) warn(note);
  for (const auto& n : cycle.notes) warn(n);
  return cycle;
}
DriveCycle cycle_arrays(py::handle c) {
  CsvTable table;
  table.file = "cycle arrays (line = sample index)";
  std::vector<py::array_t<double>> columns;
  if (py::isinstance<py::dict>(c)) {
    for (auto item : c.cast<py::dict>()) {
      table.header.push_back(arg_as<std::string>(item.first, "cycle", "column names (str) as dict keys"));
      columns.push_back(number_array(item.second, "cycle column '" + table.header.back() + "'"));
    }
  } else {
    const py::sequence pair = arg_as<py::sequence>(c, "cycle", "a shipped name or CSV path (str), a dict of arrays, or "
                                                              "a pair (time_s, speed_kmh)");
    if (pair.size() != 2) throw InputError("cycle", "a pair (time_s, speed_kmh) of arrays is expected, or a dict of columns");
    table.header = {"time_s", "speed_kmh"};
    for (auto a : pair) columns.push_back(number_array(a, "cycle column '" + table.header[columns.size()] + "'"));
  }
  for (std::size_t k = 0; k < columns.size(); ++k) {
    if (!columns[k] || columns[k].ndim() != 1 || columns[k].size() != columns.front().size())
      throw InputError("cycle column '" + table.header[k] + "'", "must be a 1-D array of numbers as long as the others");
  }
  const std::size_t n = columns.empty() ? 0 : static_cast<std::size_t>(columns.front().size());
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<std::string> row;
    for (const auto& col : columns) row.push_back(format_value(col.at(i)));
    table.rows.push_back(std::move(row));
    table.row_line.push_back(i);
  }
  return cycle_from_table(table, "user trace");
}

// Speed-indexed tyre results as one dict of arrays: numbers become arrays, text stays text.
py::dict stack(const std::vector<py::dict>& points) {
  auto np = py::module_::import("numpy");
  py::dict out;
  for (auto item : points.front()) {
    py::list values;
    for (const auto& p : points) values.append(p[item.first]);
    const bool numeric = py::isinstance<py::float_>(item.second) || py::isinstance<py::int_>(item.second);
    out[item.first] = numeric ? np.attr("asarray")(values, "dtype"_a = "float64") : py::reinterpret_borrow<py::object>(item.second);
  }
  return out;
}

py::object api_tyre(py::object file, py::object size, py::object outer_radius_m, py::object width_m, py::object pressure_bar,
                py::object load_n, py::object load_pct, py::object speed_kmh) {
  TyreRequest req;
  if (py::isinstance<py::dict>(file)) req.file_text = dict_json(file, "tyre dict");
  else if (!file.is_none()) req.file = arg_as<std::string>(file, "tyre", kNameOrDict);
  if (!size.is_none()) req.size = arg_as<std::string>(size, "size", "a size designation (str)");
  req.outer_radius_m = number_text(outer_radius_m, "outer_radius_m");
  req.width_m = number_text(width_m, "width_m");
  req.pressure_bar = number_text(pressure_bar, "pressure_bar");
  req.load_n = number_text(load_n, "load_n");
  req.load_pct = number_text(load_pct, "load_pct");
  const TyreSpec spec = build_requested_tyre(req);
  const TyreLoadChoice load = choose_requested_load(req, spec);
  const auto speeds = number_array(speed_kmh, "--speed-kmh");
  if (speeds.ndim() > 1) throw InputError("--speed-kmh", "must be a number or a 1-D array of numbers");
  // As sweep's bound: 10^7 speeds took the interpreter down by memory, without a word (session 24's outside testing).
  if (static_cast<std::size_t>(speeds.size()) > selection::kMaxTyreSweepPoints)
    throw InputError("--speed-kmh", std::to_string(speeds.size()) + " speeds is more than the " +
                                        std::to_string(selection::kMaxTyreSweepPoints) + " allowed in one call; split the array");
  std::vector<py::dict> points;
  for (py::ssize_t i = 0; i < speeds.size(); ++i) {
    const double v_kmh = parse_requested_speed_kmh(format_value(speeds.data()[i]));
    const RollingResistance r = named_tyre_request(req, spec, load, [&] {
      return evaluate_rolling_resistance(spec.state, load.load_n, units::kmh_to_mps(v_kmh));
    });
    points.push_back(from_json(tyre_point_json(spec, load.load_n, v_kmh, r).str()).cast<py::dict>());
  }
  if (const std::string w = requested_load_warning(spec, load); !w.empty()) warn(w);
  if (speeds.size() > 0) {  // as `rollsim tyre` says it
    const double top_kmh = *std::max_element(speeds.data(), speeds.data() + speeds.size());
    if (const std::string w = speed_rating_warning(spec, units::kmh_to_mps(top_kmh), "speed_kmh"); !w.empty()) warn(w);
  }
  if (speeds.ndim() == 0) return points.front();
  if (points.empty()) throw InputError("--speed-kmh", "an empty array: give at least one speed");
  return stack(points);
}

py::dict api_simulate(py::object vehicle, py::object tyre, py::object cycle, py::object replay_arg, py::object trace_arg) {
  const bool replay = flag(replay_arg, "replay"), trace = flag(trace_arg, "trace");
  const Vehicle base = vehicle_from(vehicle);
  const std::optional<TyreSpec> tyre_set = tyre_from(tyre);
  const DriveCycle c = cycle_from(cycle);
  SimulationOptions opt;
  opt.record_trace = trace;
  VehicleRun run;
  {
    py::gil_scoped_release released;
    run = run_vehicle(base, tyre_set, c, replay, opt);
  }
  for (const auto& w : run.warnings) warn(w);
  for (const auto& c : report::run_caveats(run.result)) warn(c);  // as the command line's text and --json say them
  py::dict out;
  JsonObject summary = report::to_json(run.result, run.tyre_label);
  // As simulate --json: the files read (the car's own tyres' too), null for a dict or arrays.
  const auto [front_file, rear_file] = tyre_files(run);
  const bool tyre_dict = tyre_set && py::isinstance<py::dict>(tyre);
  report::add_input_files(summary, {py::isinstance<py::dict>(vehicle) ? "" : base.source, tyre_dict ? "" : front_file,
                                    py::isinstance<py::str>(fspath_or_self(cycle)) ? c.source : "", tyre_dict ? "" : rear_file});
  out["summary"] = from_json(summary.str());
  py::dict columns;
  if (trace)
    for (auto& col : report::trace_columns(run.result)) columns[py::str(col.name)] = py::array_t<double>(col.values.size(), col.values.data());
  out["trace"] = columns;
  return out;
}

py::list api_compare(py::object vehicle, py::object tyre_names, py::object cycle, py::object catalogue,
                 py::object diameter_tolerance_pct, py::object replay, py::object threads) {
  const auto tyres = arg_as<std::vector<std::string>>(tyre_names, "tyres", "a list of tyre files or shipped names (str)");
  selection::CompareOptions copt;
  // The command line's --replay and --threads (session 22's notes: Python had neither).
  copt.replay = flag(replay, "replay");
  if (const std::string n = number_text(threads, "threads"); !n.empty())
    copt.threads = static_cast<unsigned>(parse_option_count(n, "threads", Range::closed(1, 1024)));
  copt.diameter_tolerance_pct =
      selection::parse_diameter_tolerance_pct(number_text(diameter_tolerance_pct, "diameter_tolerance_pct"));
  const std::string folder = catalogue.is_none() ? "" : arg_as<std::string>(catalogue, "catalogue", "a folder path (str)");
  // "" compared the shipped catalogue, as None does (session 22's notes).
  if (!catalogue.is_none() && folder.empty())
    throw InputError("catalogue", "'' is no folder; leave catalogue out (None) for the shipped tyres/catalogue");
  const selection::CandidateList list = selection::load_candidates(tyres, !catalogue.is_none(), folder);
  for (const auto& b : list.broken) warn("skipped broken catalogue file: " + b);
  const Vehicle v = vehicle_from(vehicle);
  const DriveCycle c = cycle_from(cycle);
  selection::Comparison cmp;
  std::vector<std::string> left_out;
  const std::vector<TyreSpec> candidates = selection::without_duplicate_files(v, list.tyres, left_out);
  for (const auto& d : left_out) warn("left out " + d);
  {
    py::gil_scoped_release released;
    cmp = selection::compare_tyres(v, candidates, c, copt);
  }
  for (const auto& w : selection::trace_warnings(cmp)) warn(w);
  py::list out;
  for (const auto& j : selection::comparison_json(cmp)) out.append(from_json(j.str()));
  return out;
}

py::list api_sweep(py::object tyre, py::object axes_arg, py::object load_n, py::object speed_kmh, py::object vehicle,
               py::object cycle, py::object threads, py::object replay_arg) {
  const bool replay = flag(replay_arg, "replay");
  if (replay && vehicle.is_none()) throw InputError("replay", "needs vehicle: a tyre alone is not simulated");
  const auto axes = arg_as<std::vector<py::sequence>>(axes_arg, "axes", "a list of (param, from, to[, steps])");
  selection::SweepRequest req;
  for (const auto& a : axes) {
    if (a.size() < 3 || a.size() > 4) throw InputError("axes", "each axis is (param, from, to) or (param, from, to, steps)");
    req.params.push_back(arg_as<std::string>(a[0], "axes", "(param, from, to[, steps]) with param a name (str)"));
    req.from.push_back(number_text(a[1], "axes (from)"));
    req.to.push_back(number_text(a[2], "axes (to)"));
    req.steps.push_back(a.size() == 4 ? number_text(a[3], "axes (steps)") : "");  // each axis its own, or the default
  }
  req.load_n = number_text(load_n, "load_n");
  req.speed_kmh = number_text(speed_kmh, "speed_kmh");
  req.threads = number_text(threads, "threads");
  selection::SweepOptions so = selection::sweep_options_from_request(req);
  so.replay = replay;
  if (!cycle.is_none() && vehicle.is_none()) throw InputError("cycle", "needs vehicle: a tyre alone drives no cycle");
  const std::optional<TyreSpec> given = tyre_from(tyre);
  // None was dereferenced: the interpreter died (session 22's outside testing).
  if (!given) throw InputError("tyre", "missing: give the tyre to sweep, e.g. '175-70R14'");
  const TyreSpec& t = *given;
  selection::SweepResult r;
  if (!vehicle.is_none()) {
    const Vehicle v = vehicle_from(vehicle);
    const DriveCycle c = cycle_from(cycle.is_none() ? py::str("nedc") : cycle);
    py::gil_scoped_release released;
    r = selection::sweep_vehicle(v, t, c, so);
  } else {
    py::gil_scoped_release released;
    r = selection::sweep_tyre(t, so);
  }
  if (r.points.empty()) {  // as the command line refuses it (an empty list and a warning: session 22)
    throw InputError("axes", (r.outside_domain ? *r.outside_domain : std::string("no point was computed")) + " (no valid point of " +
                                 std::to_string(r.planned_points) + ")");
  }
  if (r.outside_domain) {
    warn(*r.outside_domain + " (the " + std::to_string(r.points.size()) + " valid points of " +
         std::to_string(r.planned_points) + " are returned)");
  }
  for (const std::string& w : selection::sweep_warnings(r)) warn(w);
  py::list out;
  for (const auto& j : selection::sweep_json(r)) out.append(from_json(j.str()));
  return out;
}

py::object api_diagnose(py::object vehicle, py::object recording_paths, py::object columns_arg, py::object scales_arg,
                    py::object preset_arg, py::object tyre) {
  // A str is a sequence too: recordings='trip.csv' would have been read letter by letter.
  if (py::isinstance<py::str>(recording_paths)) throw InputError("recordings", "expected a list of CSV paths (str), not one str");
  const auto recordings = arg_as<std::vector<std::string>>(recording_paths, "recordings", "a list of CSV paths (str)");
  for (std::size_t k = 0; k < recordings.size(); ++k)
    if (recordings[k].empty())
      throw InputError("recordings[" + std::to_string(k) + "]", "an empty path is not allowed: give a recording's CSV path");
  const auto columns = arg_as<py::dict>(columns_arg, "columns", "a dict of canonical name (str) to source column (str)");
  const auto scales = arg_as<py::dict>(scales_arg, "scales", "a dict of canonical name (str) to factor (number)");
  const auto preset = arg_as<std::string>(preset_arg, "preset", "a preset name (str): 'anl_d3' or 'rsk_twizy'");
  YamlMap vehicle_file = py::isinstance<py::dict>(vehicle)
                             ? YamlMap::load_text(dict_json(vehicle, "vehicle dict"), "vehicle dict")
                             : YamlMap::load_file(vehicle_path(vehicle));
  Vehicle v = load_vehicle(vehicle_file);
  if (const auto t = tyre_from(tyre)) fit_tyres(v, *t);
  DiagnoseOptions options;
  options.priors = calibration_priors_from_yaml(vehicle_file);
  std::vector<std::string> column_options, scale_options;
  const std::string column_pairs = "a dict of canonical name (str) to source column (str)";
  for (auto item : columns) {
    column_options.push_back(arg_as<std::string>(item.first, "columns", column_pairs) + "=" +
                             arg_as<std::string>(item.second, "columns", column_pairs));
  }
  for (auto item : scales) {
    const std::string key = arg_as<std::string>(item.first, "scales", "a dict of canonical name (str) to factor (number)");
    scale_options.push_back(key + "=" + number_text(item.second, "scales['" + key + "']"));
  }
  ColumnMapping mapping = assemble_mapping(preset, vehicle_file, column_options, scale_options, "columns", "scales");
  mapping.how_to_map = "with columns={'CANONICAL': SOURCE}";
  std::vector<Recording> recs;
  for (const auto& r : recordings) recs.push_back(load_recording(r, mapping));
  for (const auto& r : recs)
    for (const auto& rep : r.repairs) warn(r.source + ": " + rep);
  std::string json;
  {
    py::gil_scoped_release released;
    json = diagnosis_json(diagnose(v, recs, options));
  }
  return from_json(json);
}

// py::vectorize's own mismatch error names neither argument and is no InputError.
void check_broadcast(const py::array& a, const py::array& b, const std::string& a_name, const std::string& b_name) {
  try {
    py::module_::import("numpy").attr("broadcast")(a, b);
  } catch (const py::error_already_set& e) {
    if (!e.matches(PyExc_ValueError)) throw;
    throw InputError(a_name + ", " + b_name, "shapes " + py::str(a.attr("shape")).cast<std::string>() + " and " +
                                                 py::str(b.attr("shape")).cast<std::string>() +
                                                 " do not broadcast: give arrays of one shape, or a number for either");
  }
}

// The library's EngineMap built by the vehicle reader from a dict of the `powertrain.engine` block's keys, at each
// (speed, torque) pair; numpy broadcasts the two, scalars give scalars.
py::dict api_engine_map(py::object engine, py::object speed_rpm, py::object torque_nm) {
  const auto block = arg_as<py::dict>(engine, "engine", "a dict with the powertrain.engine block's keys");
  const EngineMap map(read_engine_block(YamlMap::load_text(dict_json(block, "engine dict"), "engine dict")));
  const Range rpm_range = Range::closed(0.0, 3e4), torque_range = Range::closed(0.0, 1e5);
  // Beyond full load the engine has no operating point; the map's formula still gives a figure there, which a fit to
  // a published map's top rows uses (scripts/fit_engine_map.py). It was returned without a word (session 20): now
  // with a warning counting such points.
  std::size_t beyond_full_load = 0;
  auto fuel = py::vectorize([&](double rpm, double torque) {
    const double w = checked_number(rpm, "speed_rpm", rpm_range) * units::kRadpsPerRpm;
    const double t = checked_number(torque, "torque_nm", torque_range);
    if (t > map.max_torque_nm(w) * (1.0 + 1e-12)) ++beyond_full_load;
    return map.fuel_power_w(w, t);
  });
  auto full_load = py::vectorize([&](double rpm) {
    return map.max_torque_nm(checked_number(rpm, "speed_rpm", rpm_range) * units::kRadpsPerRpm);
  });
  const auto speeds = number_array(speed_rpm, "speed_rpm");
  const auto torques = number_array(torque_nm, "torque_nm");
  check_broadcast(speeds, torques, "speed_rpm", "torque_nm");
  py::dict out;
  out["fuel_power_w"] = fuel(speeds, torques);
  out["max_torque_nm"] = full_load(speeds);
  if (beyond_full_load > 0)
    warn(std::to_string(beyond_full_load) + " point(s) beyond the engine's full-load torque (max_torque_nm): no operating "
         "point there; fuel_power_w is the map's formula extrapolated");
  return out;
}

// A measured point: (pressure_kpa, load_n, speed_kmh, rrc), or an RRC alone at the size's ISO 28580 conditions.
RrcPoint fit_point(py::handle p, const TyreSize& size, const std::string& where) {
  try {
    if (py::isinstance<py::sequence>(p) && !py::isinstance<py::str>(p)) {
      const auto v = p.cast<std::vector<double>>();
      if (v.size() == 4) return rrc_point_from_file_units(v[0], v[1], v[2], v[3], where);
    } else if (!py::isinstance<py::str>(p)) {
      return iso28580_point(size, p.cast<double>(), where);
    }
  } catch (const py::cast_error&) {
  }
  throw InputError(where, "expected (pressure_kpa, load_n, speed_kmh, rrc) or an RRC alone (ISO 28580 conditions)");
}

// `rollsim tyre fit --json` through the same library steps, and the tyre file it writes as a dict (for
// simulate(tyre=...)); the file itself only when `output` is given.
py::dict api_tyre_fit(py::object size_arg, py::object points, py::object label, py::object j2452,
                      py::object drum_radius_m, py::object free, py::object rrc_uncertainty_pct, py::object pressure_bar,
                      py::object name_arg, py::object output, py::object measured) {
  const auto size = arg_as<std::string>(size_arg, "size", "a size designation (str)");
  const auto name = arg_as<std::string>(name_arg, "name", "the tyre's name (str)");
  // Checked before the fit, as `tyre fit --output` is: an existing, writable folder, no folders made (session 20:
  // the module made missing folders where the command line refuses).
  const std::string output_path = output.is_none() ? "" : arg_as<std::string>(output, "output", "a file path (str)");
  if (!output.is_none() && output_path.empty()) throw InputError("output", "an empty path: give a file path, or leave output out");
  const std::string measured_path = measured.is_none() ? "" : arg_as<std::string>(measured, "measured", "a CSV path (str)");
  if (!measured.is_none() && measured_path.empty()) throw InputError("measured", "an empty path is not allowed: give a CSV path or None");
  if (!output_path.empty()) check_output_file(output_path, "output", {measured_path});
  TyreFitInputs in;
  in.size = parse_tyre_size(size, "size");
  if (!points.is_none()) {
    std::size_t i = 0;
    for (const auto p : arg_as<py::sequence>(points, "points", "a list of points")) {
      in.points.push_back(fit_point(p, in.size, "points[" + std::to_string(i) + "]"));
      ++i;
    }
  }
  // The command line's --measured: the same loader, so the same columns and the same errors naming file and line.
  if (!measured_path.empty()) {
    for (auto& p : load_measured_rrc_csv(measured_path, &in.notes)) in.points.push_back(p);
  }
  if (!label.is_none()) in.label_class = arg_as<std::string>(label, "label", "a class 'A'..'E'");
  if (!j2452.is_none()) {
    std::string text;
    for (const double x : arg_as<std::vector<double>>(j2452, "j2452", "(alpha, beta, a, b, c)")) {
      text += (text.empty() ? "" : ",") + format_value(x);
    }
    in.j2452 = parse_j2452_text(text, "j2452");
  }
  if (!drum_radius_m.is_none()) in.drum_radius_m = arg_as<double>(drum_radius_m, "drum_radius_m", "a number [m]");
  if (!rrc_uncertainty_pct.is_none()) {
    in.uncertainty_pct = arg_as<double>(rrc_uncertainty_pct, "rrc_uncertainty_pct", "a number [%]");
  }
  if (!free.is_none()) {
    in.free = free_params_from_keys(arg_as<std::vector<std::string>>(free, "free", "a list of constant names"), "free");
  }
  const TyreFitPlan plan = plan_tyre_fit(in);
  const TyreFit fit = fit_hysteresis(plan.start, plan.request);
  FittedTyreFile file;
  file.name = name;
  file.size = size;
  file.pressure_pa = fitted_file_pressure_pa(
      in.size, pressure_bar.is_none() ? std::nullopt : std::optional(arg_as<double>(pressure_bar, "pressure_bar", "a number [bar]")),
      "pressure_bar");
  file.source = "rollsim.tyre_fit (Python)";
  std::ostringstream json;
  write_tyre_fit_json(json, fit, plan);
  const std::string yaml = fitted_tyre_file_text(file, fit);
  for (const auto& w : plan.warnings) warn(w);
  for (const auto& w : fit.warnings) warn(w);
  py::dict out;
  py::list params, residuals;
  std::istringstream lines(json.str());
  for (std::string line; std::getline(lines, line);) {
    py::dict d = from_json(line).cast<py::dict>();
    const std::string kind = d["kind"].cast<std::string>();
    if (kind == "fit") out["fit"] = d;
    else (kind == "param" ? params : residuals).append(d);
  }
  out["params"] = params;
  out["residuals"] = residuals;
  out["tyre"] = py::module_::import("yaml").attr("safe_load")(yaml);
  if (!output_path.empty()) write_file_atomically(output_path, "output", [&](std::ostream& o) { o << yaml; });
  return out;
}

py::dict api_sensitivity(py::object tyre, py::object vehicle, py::object cycle, py::object load_n, py::object speed_kmh) {
  const double speed_mps = units::kmh_to_mps(speed_kmh.is_none() ? 80.0
      : parse_option_number(number_text(speed_kmh, "speed_kmh"), "--speed-kmh", Range::open_low(0.0, 500.0)));
  std::optional<Vehicle> v;
  if (!vehicle.is_none()) v = vehicle_from(vehicle);
  const std::optional<TyreSpec> t = tyre_from(tyre);
  std::optional<double> at_n;
  if (!load_n.is_none()) at_n = parse_option_number(number_text(load_n, "load_n"), "--load-n", Range::open_low(0.0, 1e6));
  if (!cycle.is_none() && !v) throw InputError("cycle", "needs vehicle: a tyre alone drives no cycle");
  const DriveCycle c = v ? cycle_from(cycle.is_none() ? py::str("nedc") : cycle) : DriveCycle{};
  selection::Sensitivity s;
  {
    py::gil_scoped_release released;
    s = selection::sensitivity_of(v, t, c, at_n, speed_mps);
  }
  for (const auto& w : selection::sensitivity_warnings(s)) warn(w);
  return from_json(selection::sensitivity_json(s).str());
}

py::dict api_validate(py::object list_arg, py::object threads) {
  const auto list = arg_as<std::string>(list_arg, "epa_test_car_list", "a CSV path (str)");
  if (list.empty()) throw InputError("epa_test_car_list", "an empty path is not allowed: give the list's CSV path");
  const unsigned n = threads.is_none() ? 0u
                                       : static_cast<unsigned>(parse_option_count(number_text(threads, "threads"), "threads",
                                                                                   Range::closed(1, 1024)));
  const auto rows = validate::read_epa_test_car_list(list);
  validate::Validation v;
  {
    py::gil_scoped_release released;
    v = validate::validate_epa_list(rows, n);
  }
  py::list summary, out_rows;
  for (const auto& s : validate::summarise(v)) summary.append(from_json(validate::summary_line_json(s).str()));
  for (const auto& r : v.rows) out_rows.append(from_json(validate::row_json(r).str()));
  for (const auto& w : validate::validation_warnings(v)) warn(w);
  py::dict out;
  out["fitted"] = from_json(validate::fitted_json(v.fitted).str());
  out["maker_calibration"] = from_json(validate::maker_calibration_json(v.maker_calibration).str());
  out["summary"] = summary;
  out["rows"] = out_rows;
  return out;
}

}  // namespace

PYBIND11_MODULE(rollsim, m) {
  using namespace pybind11::literals;
  m.doc() = R"(rollsim: tyre rolling resistance and vehicle energy on drive cycles (C++ library, Python API).

Results are the dicts `rollsim ... --json` prints, with the same keys and values. Units are SI unless a key or
argument names its unit (speed_kmh, pressure_bar, aec_kwh_per_10km). Bad input raises rollsim.InputError
carrying the command line's message (options are named as on the command line, e.g. '--pressure-bar').)";
  py::register_exception<InputError>(m, "InputError", PyExc_ValueError);

  m.def("tyre", &api_tyre, "tyre"_a = py::none(), py::kw_only(), "size"_a = py::none(), "outer_radius_m"_a = py::none(),
        "width_m"_a = py::none(), "pressure_bar"_a = py::none(), "load_n"_a = py::none(), "load_pct"_a = py::none(),
        "speed_kmh"_a = 80.0,
        R"(Rolling resistance of one tyre at one load and one or more speeds (`rollsim tyre --json`).

tyre: a tyre file or shipped name ('175-70R14') or a dict of its keys (as tyre_fit returns); or
size='175/70 R14 84T'; or outer_radius_m [m] and width_m [m].
pressure_bar [bar] (required without a file; overrides a file's), load_n [N] or load_pct [% of the maximum load,
default 80], speed_kmh [km/h]: a number gives one dict of numbers, an array gives a dict of arrays (one per speed).
Keys: rrc [-], rr_force_n [N], rr_power_w [W], stiffness_n_per_m, deflection_m, contact_length_m, offset_e_m,
rrc_coulomb, rrc_viscous, rrc_rotational_drag (a fitted tyre's static loss, frequency rise and speed-squared loss),
and the tyre's geometry, pressure and load.)");

  m.def("simulate", &api_simulate, "vehicle"_a = "ev", "tyre"_a = py::none(), "cycle"_a = "nedc", "replay"_a = false,
        "trace"_a = true,
        R"(A car over a drive cycle (`rollsim simulate --json` and `--trace`); the GIL is released while it runs.

vehicle: file or shipped name ('ev', 'ice') or a dict with the vehicle file's keys. tyre: None (the car's own),
a file or shipped name ('nominal', 'low-rrc'), or a dict with the tyre file's keys, on all four wheels.
cycle: a shipped name ('nedc', 'wltc', 'udds', ...), a CSV path, a pair (time_s [s], speed_kmh [km/h]) of arrays,
or a dict of arrays named like the CSV columns (time_s, speed_kmh or speed_mps, optional grade_pct or elevation_m,
heading_deg [deg clockwise from north], engine_on [1 or 0, standing only]).
replay: kinematic replay instead of driver + CVODE. Returns {'summary': dict (the --json keys: distance_km,
aec_kwh_per_10km or fuel_l_per_100km, energy_breakdown_kwh, ...), 'trace': dict of numpy arrays (the --trace
columns: time_s, speed_kmh, rolling_force_n, battery_power_kw, ...; empty with trace=False)}.)");

  m.def("compare", &api_compare, "vehicle"_a, "tyres"_a = py::list(), "cycle"_a = "nedc",
        "catalogue"_a = py::none(), "diameter_tolerance_pct"_a = 3.0, "replay"_a = false, "threads"_a = py::none(),
        R"(Tyre selection (`rollsim compare --json`): the car on the cycle with each tyre on all four wheels.

vehicle: file, shipped name or dict; tyres: files or shipped names; catalogue: a folder of tyre files (used when
given, or when tyres is empty: the shipped tyres/catalogue); diameter_tolerance_pct [%]; replay: kinematic replay
instead of the forward simulation; threads (default every core). Returns a list of dicts,
the fitting tyres ranked best first (rank 1..), then the unfit ones (rank None, with the reason). Broken catalogue
files are skipped with a warning. followed_trace is False (with max_deficit_kmh [km/h] and a warning) where the car
could not follow the cycle on that tyre: its figure is then for a slower drive.)");

  m.def("sweep", &api_sweep, "tyre"_a, "axes"_a, py::kw_only(), "load_n"_a = py::none(), "speed_kmh"_a = py::none(),
        "vehicle"_a = py::none(), "cycle"_a = py::none(), "threads"_a = py::none(), "replay"_a = false,
        R"(A sweep of one or two tyre parameters (`rollsim sweep --json`).

tyre: file, shipped name or dict. axes: [(param, from, to[, steps])], param one of pressure [bar], diameter [mm],
width [mm], load [N], load-pct [%], speed [km/h]; steps default 11. load_n [N] (default 80 % of the maximum
load), speed_kmh [km/h] (default 80; not with a speed axis). With vehicle (and cycle, default 'nedc'; a cycle without a vehicle is an error) each
point is a forward simulation of the car, or with replay=True its kinematic replay (on `threads` threads, default
every core). Returns a list of dicts, one
per point: the swept values (pressure_bar, diameter_mm, width_mm, load_n, load_pct, speed_kmh), the load_n and
speed_kmh evaluated at when not swept, rrc,
rr_force_n, rr_power_w, deflection_m, and the car's kwh_per_10km or l_per_100km with followed_trace (False, and a
warning, where the car could not follow the cycle). Points outside the
model's domain are left out with a warning wherever they fall, and the valid ones are returned.)");

  m.def("tyre_fit", &api_tyre_fit, "size"_a, py::kw_only(), "points"_a = py::none(), "label"_a = py::none(),
        "j2452"_a = py::none(), "drum_radius_m"_a = py::none(), "free"_a = py::none(),
        "rrc_uncertainty_pct"_a = py::none(), "pressure_bar"_a = py::none(), "name"_a = "fitted", "output"_a = py::none(),
        "measured"_a = py::none(),
        R"(The hysteresis model fitted to what you have for one tyre (`rollsim tyre fit --json`).

size: designation, e.g. '205/55 R16 91V' (a load index is needed for ISO points and labels). points: a list of
(pressure_kpa [kPa], load_n [N], speed_kmh [km/h], rrc [-]) or of RRCs alone (at ISO 28580 conditions); label: EU
label class 'A'..'E' (alone: one ISO point at the band's geometric middle, on ISO 28580's 2.0 m drum); measured: a CSV path of measured points
(pressure_kpa,load_n,speed_kmh,rrc; the command line's --measured), added to points; j2452: (alpha, beta, a, b, c) of a J2452 set,
sampled and corrected from a drum of drum_radius_m [m, default 0.85]; free: constants to fit (default: what the
points determine); rrc_uncertainty_pct [%]; pressure_bar [bar] and name of the tyre file; output: a path to write
it to (every command takes it). Returns {'fit': dict, 'params': [dict per constant], 'residuals': [dict per
point], 'tyre': the tyre file as a dict, which tyre(...) and simulate(tyre=...) take}. Same keys, values and errors
as the command line.)");

  m.def("sensitivity", &api_sensitivity, "tyre"_a = py::none(), py::kw_only(), "vehicle"_a = py::none(),
        "cycle"_a = py::none(), "load_n"_a = py::none(), "speed_kmh"_a = py::none(),
        R"(Elasticities of a tyre's RR power and RRC, and with a car of its energy or fuel (`rollsim sensitivity --json`).

tyre: file, shipped name or dict (default: the car's own); vehicle: file, shipped name or dict (its energy
elasticities on cycle, default 'nedc', by forward simulation; a cycle without a vehicle is an error); load_n [N]
(default: the car's heaviest wheel load, else 80 % of the tyre's maximum load) and speed_kmh [km/h]: the tyre's
operating point. Returns one dict: elasticity_rr_power_<key>
and, with a car, elasticity_<kwh_per_10km or l_per_100km>_<key> for outer_diameter, section_width, pressure and
load (% per %), the dominant parameters, and the car's figure with followed_trace.)");

  m.def("validate", &api_validate, "epa_test_car_list"_a, py::kw_only(), "threads"_a = py::none(),
        R"(Every car of an EPA Test Car List CSV simulated from its certification row (`rollsim validate --json`).

epa_test_car_list: the list's CSV; threads: worker threads (default every core); the GIL is released while it
runs. Returns {'fitted': the constants fitted on the fitting half with their row counts, 'maker_calibration': per
energy source the empirical maker calibration's shrinkage and its leave-one-model-out score on the fitting half,
'summary': [dict per powertrain, cycle and half: count, median_error_pct, median_abs_error_pct, p90_abs_error_pct,
and the same with the maker calibration, prefixed maker_calibrated_], 'rows': [dict per row, in file order: the
--json keys (test_number, make, model, fuel, cycle, half, measured, predicted, unit, error_pct, maker_factor,
maker_calibrated, maker_calibrated_error_pct, or skipped with its reason)]}. `predicted` is the physics; the maker
calibration explains nothing (README, "Validation").)");

  m.def("engine_map", &api_engine_map, "engine"_a, "speed_rpm"_a, "torque_nm"_a,
        R"(The library's fuel map (EngineMap) of an engine_map vehicle's `powertrain.engine` block.

engine: a dict with that block's keys (displacement_l, gross_indicated_efficiency, friction_mep_bar, ...), read by
the vehicle file's own reader (same defaults, bounds and errors). speed_rpm [rpm] and torque_nm [N m, brake, >= 0]:
numbers or arrays (broadcast); beyond the full-load torque fuel_power_w is the formula extrapolated, with a
warning. Returns {'fuel_power_w': fuel power [W] at the fuel's lower heating value (at or below idle speed the idle
controller's torque reserve is burnt too), 'max_torque_nm': full-load torque [N m] at speed_rpm}.)");

  m.def("diagnose", &api_diagnose, "vehicle"_a, "recordings"_a, "columns"_a = py::dict(), "scales"_a = py::dict(),
        "preset"_a = "", "tyre"_a = py::none(),
        R"(Diagnosis of recordings against the model (`rollsim diagnose --json FILE`).

vehicle: file, shipped name or dict (its recording_columns/recording_scale blocks apply); recordings: CSV paths;
columns: {canonical: source column} ('' drops one), scales: {canonical: factor}, preset: 'anl_d3' or
'rsk_twizy'; tyre: on all four wheels. Returns the diagnosis dict (verdict, findings, located, ...).)");
}
