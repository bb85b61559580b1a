// `rollsim diagnose`: replays recordings through a vehicle, locates the mismatch, names and fits missing physics.
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "rollsim/common/atomic_file.hpp"
#include "rollsim/common/error.hpp"
#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/diagnose/diagnose.hpp"
#include "rollsim/diagnose/fleet.hpp"
#include "rollsim/diagnose/report.hpp"
#include "rollsim/recording/recording.hpp"
#include "rollsim/tyre/tyre_spec.hpp"
#include "rollsim/vehicle/vehicle_file.hpp"

namespace rollsim::cli {
namespace {

struct DiagnoseCliOptions {
  std::string vehicle, tyre, preset, json, write_vehicle, report, fleet;
  std::vector<std::string> recordings, columns, scales, engine_start;
  std::string window_s;  // empty: the library default
  bool road_profile = true;
};

double window_s_of(const std::string& text) { return parse_option_number(text, "--window-s", Range::closed(5.0, 3600.0)); }

void run_diagnose(const DiagnoseCliOptions& o) {
  const std::string vehicle_path = resolve_data_file(o.vehicle, "vehicles", ".yaml", "--vehicle");
  // Read once: the car, and (below) the logger mapping and calibration bounds the same file holds.
  YamlMap vehicle_file = YamlMap::load_file(vehicle_path);
  Vehicle v = load_vehicle(vehicle_file);
  const std::string tyre_path = o.tyre.empty() ? "" : resolve_data_file(o.tyre, "tyres", ".yaml", "--tyre");
  if (!o.tyre.empty()) fit_tyres(v, load_tyre_file(tyre_path));
  // Every destination is checked before the diagnosis, and all are written together after it.
  if (!o.report.empty()) check_report_dir(o.report);
  std::vector<std::string> inputs = vehicle_input_files(v);
  inputs.push_back(tyre_path);
  inputs.insert(inputs.end(), o.recordings.begin(), o.recordings.end());
  check_outputs_distinct({{o.json, "--json"}, {o.write_vehicle, "--write-vehicle"}});
  if (!o.json.empty()) check_output_file(o.json, "--json", inputs);
  if (!o.write_vehicle.empty()) check_output_file(o.write_vehicle, "--write-vehicle", inputs);
  // Column mapping: a preset, then the vehicle file's own logger mapping, then the command line's options.
  if (!o.write_vehicle.empty()) check_no_effects_block(vehicle_file, vehicle_path);
  ColumnMapping mapping = assemble_mapping(o.preset, vehicle_file, o.columns, o.scales);
  mapping.how_to_map = "with --column CANONICAL=SOURCE";
  std::vector<Recording> recs;
  for (const auto& r : o.recordings) recs.push_back(load_recording(r, mapping));
  for (const auto& r : recs)
    for (const auto& rep : r.repairs) (rep.rfind("warning:", 0) == 0 ? std::cerr : std::cout) << r.source << ": " << rep << "\n";
  DiagnoseOptions dopt;
  // The vehicle file's calibration bounds (until session 20 the block was accepted and never read).
  dopt.priors = calibration_priors_from_yaml(vehicle_file);
  if (!o.window_s.empty()) dopt.window_s = window_s_of(o.window_s);
  dopt.infer_road_profile = o.road_profile;
  if (!o.engine_start.empty() && !v.fuel()) {
    throw InputError("--engine-start", "applies to a combustion engine's start; '" + o.vehicle + "' burns no fuel");
  }
  if (o.engine_start.size() > recs.size())
    throw InputError("--engine-start", std::to_string(o.engine_start.size()) + " start states given for " +
                                           std::to_string(recs.size()) + " recordings: give at most one per --recording");
  for (const auto& s : o.engine_start) {
    if (s != "cold" && s != "hot" && s != "infer")
      throw InputError("--engine-start", "'" + s + "' is not allowed: cold, hot or infer");
    dopt.engine_start.push_back(s == "hot" ? EngineStart::hot : s == "cold" ? EngineStart::cold : EngineStart::infer);
  }
  const Diagnosis d = diagnose(v, recs, dopt);
  // The diagnosis' warnings (units and mappings a finding would otherwise be read past) also go where warnings go.
  for (const auto& note : d.notes)
    if (note.rfind("warning:", 0) == 0) std::cerr << note << "\n";
  std::cout << diagnosis_text(d);
  std::vector<OutputFile> files;
  if (!o.json.empty()) files.push_back({o.json, "--json", diagnosis_json(d)});
  // The fitted vehicle names its files resolved (and the --tyre used), so it loads from the folder it is written to.
  if (!o.write_vehicle.empty())
    files.push_back({o.write_vehicle, "--write-vehicle", portable_vehicle_yaml(fitted_vehicle_yaml(vehicle_path, d), vehicle_path, tyre_path)});
  std::size_t report_files = 0;
  if (!o.report.empty()) {
    const auto report = render_diagnosis_report(o.report, d, "rollsim diagnose: " + v.name);
    // The report's own names in its folder: a recording or vehicle file kept there as energy.svg or report.html was
    // replaced (session 22's outside testing).
    for (const auto& f : report) check_not_an_input(f.path, "--report", inputs);
    report_files = report.size();
    files.insert(files.end(), report.begin(), report.end());
  }
  write_files_atomically(files);
  if (!o.report.empty()) {
    const auto stale = remove_stale_report_figures(o.report, files);
    std::cout << "report written to " << o.report << " (" << report_files << " files, report.html"
              << (stale.empty() ? "" : "; " + std::to_string(stale.size()) + " figure(s) of an earlier report removed") << ")\n";
  }
  if (!o.write_vehicle.empty()) std::cout << "fitted vehicle written to " << o.write_vehicle << "\n";
}

// One diagnosis per group of the manifest, spread over the processes; rank 0 prints the table or JSON lines.
void run_fleet(const DiagnoseCliOptions& o, const ProcessGroup& group) {
  for (const auto& [given, option] : {std::pair{!o.vehicle.empty(), "--vehicle"}, {!o.recordings.empty(), "--recording"},
                                      {!o.tyre.empty(), "--tyre"}, {!o.preset.empty(), "--preset"},
                                      {!o.columns.empty() || !o.scales.empty(), "--column/--scale"},
                                      {!o.report.empty() || !o.write_vehicle.empty(), "--report/--write-vehicle"},
                                      {!o.engine_start.empty(), "--engine-start"}}) {
    if (given) throw InputError(option, "not allowed with --fleet: the manifest names each group's files and mapping");
  }
  FleetOptions fo;
  if (!o.window_s.empty()) fo.diagnose.window_s = window_s_of(o.window_s);
  fo.diagnose.infer_road_profile = o.road_profile;
  fo.map_cases = group.mapper();
  // The manifest is read first so that --json is checked against every file it names, not only against itself
  // (a recording or vehicle file given as --json was overwritten with the fleet's JSON: session 21).
  const FleetManifest manifest = read_fleet_manifest(o.fleet);
  if (!o.json.empty()) {
    std::vector<std::string> inputs{o.fleet};
    for (const auto& g : manifest.groups) {
      for (const auto& f : vehicle_input_files(load_vehicle_file(g.vehicle_path))) inputs.push_back(f);
      if (!g.tyre_path.empty()) inputs.push_back(g.tyre_path);
      for (const auto& rec : g.recordings) inputs.push_back(rec.path);
    }
    check_output_file(o.json, "--json", inputs);
  }
  const FleetResult r = diagnose_fleet(manifest, fo);
  std::cout << fleet_text(r);
  // Each group's warnings, where a single diagnosis' go: a recording without the ambient column left the across-trip
  // laws untested, and the fleet said only nothing_missing (session 27's outside tester).
  for (const auto& e : r.entries)
    for (const auto& w : e.warnings) std::cerr << "warning: " << e.group << ": " << w << "\n";
  if (o.json.empty()) return;
  std::string lines;
  for (const auto& j : fleet_json(r)) lines += j.str() + "\n";
  if (group.is_root()) write_files_atomically({{o.json, "--json", lines}});
}

}  // namespace

void register_diagnose_command(CLI::App& app, const ProcessGroup& group) {
  auto o = std::make_shared<DiagnoseCliOptions>();
  CLI::App* sub = app.add_subcommand("diagnose", "Compare recordings with the model: locate the mismatch, name and fit missing physics");
  sub->add_option("--vehicle", o->vehicle, "Vehicle YAML file or shipped name (required without --fleet)")->type_name("FILE");
  sub->add_option("--tyre", o->tyre, "Tyre YAML fitted to all four wheels")->type_name("FILE");
  sub->add_option("--recording", o->recordings, "Recording CSV (repeatable; required without --fleet)")->type_name("CSV");
  sub->add_option("--fleet", o->fleet, "Diagnose a fleet: a CSV manifest with columns vehicle, recording, and optionally "
                  "group, tyre, preset, columns, scales (README); one diagnosis per group, then the fleet summary")
      ->type_name("MANIFEST.csv");
  sub->add_option("--preset", o->preset, "Column mapping preset: anl_d3, rsk_twizy")->type_name("NAME");
  sub->add_option("--column", o->columns, "CANONICAL=SOURCE column mapping (repeatable); CANONICAL= drops a column")
      ->type_name("C=S");
  sub->add_option("--scale", o->scales, "CANONICAL=FACTOR scale (repeatable)")->type_name("C=F");
  sub->add_option("--json", o->json, "Write the diagnosis as JSON (with --fleet: one line per diagnosis and per effect)")
      ->type_name("FILE");
  sub->add_option("--window-s", o->window_s, "Energy window length [s], 5-3600 (default 60; SOC channels lengthen it by "
                                             "the quantum)")
      ->type_name("S");
  sub->add_flag("--road-profile,!--no-road-profile", o->road_profile, "Where elevation is not recorded, try an elevation "
                "profile along the route as an explanation (default on; named only with a descent steeper than the rolling "
                "resistance; README)");
  sub->add_option("--engine-start", o->engine_start,
                  "cold, hot or infer per --recording, in order (default infer, from a fuel recording's first minutes): a "
                  "hot test is not warmed up again")
      ->type_name("STATE");
  sub->add_option("--report", o->report, "Write figures (SVG, gnuplot) and report.html into this folder")->type_name("DIR");
  sub->add_option("--write-vehicle", o->write_vehicle, "Write the vehicle with the fitted effects switched on")->type_name("FILE");
  sub->callback([o, &group] {
    if (!o->fleet.empty()) return run_fleet(*o, group);
    // CLI11's own wording, as when these options were marked required.
    if (o->vehicle.empty()) throw CLI::RequiredError("--vehicle");
    if (o->recordings.empty()) throw CLI::RequiredError("--recording");
    run_diagnose(*o);
  });
}

}  // namespace rollsim::cli
