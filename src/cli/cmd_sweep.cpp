// `rollsim sweep`: one or two tyre parameters swept, tyre alone or in a car on a cycle; CSV and gnuplot figures.
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "rollsim/common/atomic_file.hpp"
#include "rollsim/report/gnuplot.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/report/table.hpp"
#include "rollsim/selection/common.hpp"
#include "rollsim/selection/front_end.hpp"
#include "rollsim/selection/sweep.hpp"
#include "selection_cli.hpp"

namespace rollsim::cli {
namespace {

struct SweepOptionsText {
  std::string tyre, vehicle, cycle;  // cycle: empty for nedc
  selection::SweepRequest request;
  std::string output, plot;
  bool base100 = false, json = false, replay = false;
};


std::string axis_label(selection::SweepParam p) {
  switch (p) {
    case selection::SweepParam::Pressure: return "inflation pressure [bar]";
    case selection::SweepParam::Diameter: return "outer diameter [mm]";
    case selection::SweepParam::Width: return "section width [mm]";
    case selection::SweepParam::Load: return "normal load [N]";
    case selection::SweepParam::LoadPct: return "normal load [% of maximum load]";
    case selection::SweepParam::Speed: return "speed [km/h]";
  }
  return "";
}


const char* const gnuplot_missing =
    "gnuplot is not installed or not on PATH (Debian: apt-get install gnuplot-nox); the CSV output does not need it";

std::string display_unit(selection::SweepParam p) {
  const std::string u = selection::sweep_param_unit(p);
  return u == "kmh" ? "km/h" : u == "pct" ? "%" : u;
}


// Draws RRC against the first swept parameter (one line per value of the second) with gnuplot, in a scratch
// folder; returns the figure's bytes (the caller writes them with the other outputs).
std::string render_plot(const selection::SweepResult& r, const std::string& tyre_name, const std::string& file,
                        bool base100) {
  namespace fs = std::filesystem;
  if (r.points.empty()) throw InputError("--plot " + file, "no valid point to draw");
  const std::string ext = fs::path(file).extension().string();
  const std::string gnuplot = report::find_gnuplot();
  if (gnuplot.empty()) throw InputError("--plot " + file, gnuplot_missing);
  // Series: one per value of the second axis (or one), x = first axis, y = RRC (or base 100 of its first point).
  std::map<double, std::vector<std::pair<double, double>>> series;
  for (const auto& p : r.points) series[p.values.size() > 1 ? p.values[1] : 0.0].push_back({p.values[0], p.rr.rrc});
  for (const auto& [key, pts] : series) {
    // An RRC of 0 (at 0 km/h) as the base: gnuplot's own "all points y value undefined" reached the user (session 20).
    if (base100 && !(pts.front().second > 0.0)) {
      // On a grid the line's own value names it (the 0 km/h line of a pressure x speed grid said "at 1.5 bar").
      const std::string line = r.axes.size() > 1 ? ", " + selection::sweep_param_key(r.axes[1].param) + " " + format_value(key) +
                                                       " " + display_unit(r.axes[1].param)
                                                 : std::string();
      throw InputError("--base100", "the first point's RRC is " + format_value(pts.front().second) + " (at " +
                                        format_value(pts.front().first) + " " + display_unit(r.axes[0].param) + line +
                                        "): there is no base to divide by; start the range elsewhere");
    }
  }
  const report::ScratchDir scratch("rollsim_plot_");
  const fs::path& work = scratch.path();
  std::ofstream data(work / "data.dat");
  for (auto& [key, pts] : series) {
    const double ref = pts.front().second;
    for (auto& [x, y] : pts) data << format_value(x) << " " << (base100 ? 100.0 * y / ref : 1000.0 * y) << "\n";
    data << "\n\n";
  }
  data.close();
  const auto& a0 = r.axes[0];
  std::string load_text = fixed(r.points.front().load_n, 0) + " N";
  std::string title = "RRC of " + tyre_name;
  if (a0.param != selection::SweepParam::Load && a0.param != selection::SweepParam::LoadPct &&
      (r.axes.size() < 2 || (r.axes[1].param != selection::SweepParam::Load &&
                             r.axes[1].param != selection::SweepParam::LoadPct))) {
    title += " at " + load_text;
  }
  if (a0.param != selection::SweepParam::Speed && (r.axes.size() < 2 || r.axes[1].param != selection::SweepParam::Speed)) {
    title += ", " + fixed(r.points.front().speed_kmh, 0) + " km/h";
  }
  const fs::path figure = work / ("figure" + ext);
  std::ofstream gp(work / "plot.gp");
  using report::gnuplot_string;
  gp << report::gnuplot_terminal(ext == ".svg" ? "svg size 800,500 dynamic font 'Sans,12'" : "pngcairo size 800,500 font 'Sans,11'")
     << "set output " << gnuplot_string(figure.string()) << "\n"
     << "set title " << gnuplot_string(title + " (rollsim tyre model)") << "\n"
     << "set xlabel " << gnuplot_string(axis_label(a0.param)) << "\n"
     << "set ylabel "
     << gnuplot_string(base100 ? "RRC, base 100 at " + format_value(r.points.front().values[0]) + " " + display_unit(a0.param)
                               : std::string("RRC x 1000 [-]"))
     << "\nset grid\nset key top right\n";
  gp << "plot ";
  std::size_t i = 0;
  for (auto& [key, pts] : series) {
    std::string label = r.axes.size() > 1 ? selection::sweep_param_key(r.axes[1].param) + " " + format_value(key) + " " +
                                                display_unit(r.axes[1].param)
                                          : tyre_name;
    gp << (i ? ", " : "") << gnuplot_string((work / "data.dat").string()) << " index " << i
       << " with linespoints lw 2 pt 7 ps 0.6 title " << gnuplot_string(label);
    ++i;
  }
  gp << "\n";
  gp.close();
  const std::string err = report::run_gnuplot_script(gnuplot, (work / "plot.gp").string());
  std::ifstream in(figure, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  in.close();
  if (!err.empty()) throw InputError("--plot " + file, "gnuplot failed: " + err);
  return bytes.str();
}

void run_sweep(const SweepOptionsText& o, const ProcessGroup& group) {
  if (o.tyre.empty()) throw InputError("--tyre", "missing: give the tyre to sweep, e.g. --tyre 175-70R14");
  if (o.replay && o.vehicle.empty()) throw InputError("--replay", "needs --vehicle: a tyre alone is not simulated");
  if (!o.cycle.empty() && o.vehicle.empty()) throw InputError("--cycle", "needs --vehicle: a tyre alone drives no cycle");
  // Both were ignored in silence (session 22's notes): a tyre sweep is one thread, and base 100 is a plot's scale.
  if (!o.request.threads.empty() && o.vehicle.empty())
    throw InputError("--threads", "needs --vehicle: only a vehicle sweep runs on threads, a tyre sweep takes milliseconds");
  if (o.base100 && o.plot.empty()) throw InputError("--base100", "needs --plot: it scales the plot, the CSV keeps RRC as it is");
  const std::string cycle = o.cycle.empty() ? "nedc" : o.cycle;
  selection::SweepOptions so = selection::sweep_options_from_request(o.request);
  so.replay = o.replay;
  so.map_cases = group.mapper();
  // The inputs are read first (they are small), so that no output can be one of them.
  const TyreSpec tyre = load_tyre_file(resolve_data_file(o.tyre, "tyres", ".yaml", "--tyre"));
  std::vector<std::string> inputs{tyre.source};
  std::optional<Vehicle> vehicle;
  std::optional<DriveCycle> drive;
  if (!o.vehicle.empty()) {
    vehicle = load_vehicle_file(resolve_data_file(o.vehicle, "vehicles", ".yaml", "--vehicle"));
    warn_if_coastdown(*vehicle, "the energy and fuel columns");
    drive = load_cycle_noted(cycle, "--cycle");
    for (const auto& f : vehicle_input_files(*vehicle)) inputs.push_back(f);
    inputs.push_back(drive->source);
  }
  // Every destination is checked before the sweep, and all are written after it (nothing is left behind).
  check_outputs_distinct({{o.output, "--output"}, {o.plot, "--plot"}});
  if (!o.output.empty()) check_output_file(o.output, "--output", inputs);
  if (!o.plot.empty()) {
    const std::string ext = std::filesystem::path(o.plot).extension().string();
    if (ext != ".svg" && ext != ".png") throw InputError("--plot " + o.plot, "must end in .svg or .png");
    check_output_file(o.plot, "--plot", inputs);
    if (report::find_gnuplot().empty()) throw InputError("--plot " + o.plot, gnuplot_missing);
  }

  Progress progress(!o.json);
  so.progress = [&progress](std::size_t d, std::size_t t) { progress(d, t); };
  const selection::SweepResult r =
      vehicle ? selection::sweep_vehicle(*vehicle, tyre, *drive, so) : selection::sweep_tyre(tyre, so);

  // Nothing valid: the reason, and no file (a header-only CSV was left, and --plot said only "no valid point").
  if (r.points.empty()) {
    throw InputError("--param", (r.outside_domain ? *r.outside_domain : std::string("no point was computed")) +
                                    " (no valid point of " + std::to_string(r.planned_points) + "; nothing written)");
  }
  std::string table;
  if (o.json) {
    std::ostringstream out;
    for (const auto& j : selection::sweep_json(r)) out << j.str() << "\n";
    table = out.str();
  } else {
    table = selection::sweep_csv(r);
  }
  std::vector<OutputFile> files;
  if (!o.output.empty()) files.push_back({o.output, "--output", table});
  if (!o.plot.empty() && group.is_root()) files.push_back({o.plot, "--plot", render_plot(r, tyre.name, o.plot, o.base100)});
  // Under MPI every rank holds the whole result; only rank 0 writes it.
  if (group.is_root()) write_files_atomically(files);
  if (o.output.empty()) std::cout << table;
  if (group.is_root())
    for (const std::string& w : selection::sweep_warnings(r)) std::cerr << "warning: " << w << "\n";
  if (r.outside_domain) {
    throw InputError("--param", *r.outside_domain + " (the " + std::to_string(r.points.size()) + " valid points of " +
                                    std::to_string(r.planned_points) + " were written)");
  }
}

}  // namespace

void register_sweep_command(CLI::App& app, const ProcessGroup& group) {
  auto o = std::make_shared<SweepOptionsText>();
  CLI::App* sub = app.add_subcommand(
      "sweep", "Sweep one or two tyre parameters: RRC, force and power, or a car's energy/fuel on a cycle (CSV)");
  sub->add_option("--tyre", o->tyre, "Tyre file or shipped name")->type_name("FILE");
  sub->add_option("--param", o->request.params, "pressure (bar), diameter (mm), width (mm), load (N), load-pct or speed (km/h); "
                                        "twice for a grid")
      ->type_name("P");
  sub->add_option("--from", o->request.from, "First value of the range (one per --param)")->type_name("X");
  sub->add_option("--to", o->request.to, "Last value of the range (one per --param)")->type_name("X");
  sub->add_option("--steps", o->request.steps, "Points per range including both ends (default 11)")->type_name("N");
  sub->add_option("--load-n", o->request.load_n, "Fixed normal load per tyre [N] (default 80 % of maximum load; with --vehicle, the car's heavier static wheel load)")->type_name("N");
  sub->add_option("--speed-kmh", o->request.speed_kmh, "Fixed speed [km/h] (default 80)")->type_name("KMH");
  sub->add_option("--vehicle", o->vehicle, "Run this car with the swept tyre on all four wheels")->type_name("FILE");
  sub->add_option("--cycle", o->cycle, "Drive cycle for --vehicle (default nedc)")->type_name("CYCLE");
  sub->add_option("--threads", o->request.threads, "Worker threads for vehicle sweeps (default: every core; under "
                  "mpirun, the node's cores over its ranks)")->type_name("N");
  sub->add_flag("--replay", o->replay, "With --vehicle: kinematic replay of the cycle instead of the forward simulation "
                "(driver + CVODE); about 10x faster, within 0.05 % of it where the car follows the cycle (README)");
  sub->add_option("--output", o->output, "Write the CSV here (atomically) instead of stdout")->type_name("FILE.csv");
  sub->add_option("--plot", o->plot, "Draw RRC against the swept parameter with gnuplot")->type_name("FILE.svg|.png");
  sub->add_flag("--base100", o->base100, "Plot RRC as base 100 at the first point of each line");
  sub->add_flag("--json", o->json, "JSON lines instead of CSV (no progress display)");
  sub->callback([o, &group] { run_sweep(*o, group); });
}

}  // namespace rollsim::cli
