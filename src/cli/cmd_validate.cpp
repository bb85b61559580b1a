// `rollsim validate`: the EPA Test Car List simulated row by row and compared with its measured results.
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <set>
#include <memory>
#include <sstream>
#include <string>

#include "commands.hpp"
#include "rollsim/common/atomic_file.hpp"
#include "rollsim/common/json.hpp"
#include "rollsim/report/gnuplot.hpp"
#include "rollsim/report/table.hpp"
#include "rollsim/validate/front_end.hpp"
#include "rollsim/validate/validate.hpp"
#include "selection_cli.hpp"

namespace rollsim::cli {
namespace {

struct ValidateOptionsText {
  std::string list, plot, threads;
  bool json = false;
};

std::string table(const std::vector<validate::SummaryLine>& lines, validate::ErrorStats validate::SummaryLine::*stats) {
  report::TextTable t({"powertrain", "cycle", "half", "count", "median err %", "median |err| %", "p90 |err| %"});
  t.set_left_aligned(0);
  t.set_left_aligned(1);
  t.set_left_aligned(2);
  for (const auto& s : lines) {
    const validate::ErrorStats& e = s.*stats;
    t.add_row({s.powertrain, s.cycle, s.half, std::to_string(s.count), fixed(e.median_error_pct, 1),
               fixed(e.median_abs_error_pct, 1), fixed(e.p90_abs_error_pct, 1)});
  }
  return t.render();
}

void print_summary(const validate::Validation& v) {
  const auto& f = v.fitted;
  std::cout << "EPA Test Car List: " << v.rows.size() << " rows; split by the hash of make|model: fitting half sets "
            << "the constants, held-out half judges them\n";
  // A constant with no row to fit it keeps its nominal value; say so rather than print it as fitted.
  auto constant = [](const std::string& name, double value, std::size_t rows, const std::string& what) {
    return name + " " + fixed(value, 3) + " (" +
           (rows ? std::to_string(rows) + " " + what : "nominal: no " + what + " to fit it") + ")";
  };
  std::cout << "fitted on the fitting half: "
            << constant("petrol indicated efficiency", f.defaults.petrol_indicated_efficiency, f.petrol_rows, "rows")
            << ", " << constant("diesel", f.defaults.diesel_indicated_efficiency, f.diesel_rows, "rows") << ", "
            << constant("charge efficiency", f.defaults.charge_efficiency, f.electric_rows, "rows") << ", "
            << constant("cold-start fuel excess", f.defaults.cold_fuel_excess, f.cold_start_rows,
                        "FTPs' bag 1 vs bag 3")
            << "\n";
  for (const bool fitting : {false, true}) {
    const auto c = validate::coverage(v, fitting);
    std::cout << (fitting ? "fitting" : "held-out") << ": simulated " << c.simulated << " of " << c.eligible
              << " FTP-75, HWFET, US06 and charge-depleting rows ("
              << (c.eligible ? fixed(100.0 * static_cast<double>(c.simulated) / static_cast<double>(c.eligible), 1) + " %"
                             : std::string("none in this half"))
              << ")\n";
  }
  std::size_t derived = 0, derived_simulated = 0;
  for (const auto& o : v.rows) {
    if (!o.row->derived) continue;
    ++derived;
    if (o.skip == validate::SkipReason::none) ++derived_simulated;
  }
  std::cout << "analytically derived results (ADFE): " << derived << " rows, " << derived_simulated
            << " simulated as the configuration the result is for (the ADFE columns' weight, N/V and road-load power), "
               "not the tested vehicle the row describes\n";
  auto lines = validate::summarise(v);
  std::stable_sort(lines.begin(), lines.end(), [](const auto& a, const auto& b) { return a.half > b.half; });
  std::cout << "the physics (each car from its row alone, with the constants above):\n"
            << table(lines, &validate::SummaryLine::physics);
  std::cout << "maker calibration, learned on the fitting half (empirical: it explains nothing): each make's median "
               "log error on each cycle, shrunk by n / (n + k) over its n rows, k chosen by leaving one model out\n";
  if (v.maker_calibration.choices().empty()) std::cout << "  none: the fitting half has no simulated row\n";
  for (const auto& [fuel, c] : v.maker_calibration.choices()) {
    std::cout << "  " << validate::to_string(fuel) << ": "
              << (std::isinf(c.shrinkage_rows) ? "none (no k improves on the physics)"
                                               : "k = " + fixed(c.shrinkage_rows, 0) + " (" + std::to_string(c.groups) + " make-and-cycle groups)")
              << "; mean |ln(predicted / measured)| over the fitting half's " << c.rows << " rows, each without its own model: "
              << fixed(c.mean_abs_log_error_uncalibrated, 4) << " -> " << fixed(c.mean_abs_log_error_calibrated, 4) << "\n";
  }
  std::cout << "with the maker calibration (a fitting-half row calibrated without its own model):\n"
            << table(lines, &validate::SummaryLine::maker_calibrated);
  std::map<std::string, std::size_t> skipped;
  for (const auto& o : v.rows) {
    if (o.skip != validate::SkipReason::none) ++skipped[validate::to_string(o.skip)];
  }
  std::cout << "skipped:" << (skipped.empty() ? " none" : "") << "\n";
  for (const auto& [why, n] : skipped) std::cout << "  " << n << "  " << why << "\n";
}

// "EPA Test Car List 2022" (or "2021-2023") from the rows' Model Year: the title said 2022 whatever the file held
// (session 22's outside testing). A year that is not four digits, or no Model Year column, leaves the year out.
std::string list_title(const validate::Validation& v) {
  std::set<std::string> years;
  for (const auto& o : v.rows) {
    const std::string& y = o.row->model_year;
    if (y.size() == 4 && std::all_of(y.begin(), y.end(), [](unsigned char c) { return std::isdigit(c); })) years.insert(y);
  }
  if (years.empty()) return "EPA Test Car List";
  return "EPA Test Car List " + *years.begin() + (years.size() > 1 ? "-" + *years.rbegin() : "");
}

// The figure's path and gnuplot, checked before the list is run (a missing folder was refused after the whole list,
// its results lost: session 23's outside testing); returns gnuplot.
std::string check_plot_target(const std::string& file) {
  namespace fs = std::filesystem;
  const std::string ext = fs::path(file).extension().string();
  if (ext != ".svg" && ext != ".png") throw InputError("--plot " + file, "must end in .svg or .png");
  const std::string gnuplot = report::find_gnuplot();
  if (gnuplot.empty()) throw InputError("--plot " + file, "gnuplot is not installed or not on PATH (Debian: apt-get install gnuplot-nox)");
  const fs::path target(file);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec) || access(dir.c_str(), W_OK) != 0) throw InputError("--plot " + file, "cannot write here (folder missing or not writable)");
  return gnuplot;
}

// Predicted against measured, one series per powertrain, with the line of perfect agreement.
// Labelled ticks for a log axis over [a, b]: a list within one decade (19-55 mpg) had none, gnuplot's log ticks being
// the powers of ten (session 27's outside tester). Over a factor 3 or more, 1, 2, 3 and 5 of each decade; below it,
// evenly spaced at 1, 2 or 5 of a power of ten, some five of them.
std::vector<double> tick_values(double a, double b) {
  std::vector<double> at;
  if (b / a >= 3.0) {
    for (double decade = std::pow(10.0, std::floor(std::log10(a))); decade <= b; decade *= 10.0)
      for (double m : {1.0, 2.0, 3.0, 5.0})
        if (m * decade >= a && m * decade <= b) at.push_back(m * decade);
    return at;
  }
  const double raw = (b - a) / 5.0, power = std::pow(10.0, std::floor(std::log10(raw)));
  const double step = raw <= power ? power : raw <= 2.0 * power ? 2.0 * power : raw <= 5.0 * power ? 5.0 * power : 10.0 * power;
  for (double t = std::ceil(a / step) * step; t <= b; t += step) at.push_back(t);
  return at;
}

void plot(const validate::Validation& v, const std::string& file) {
  namespace fs = std::filesystem;
  const std::string gnuplot = check_plot_target(file);
  const report::ScratchDir scratch("rollsim_validate_");
  const fs::path& work = scratch.path();
  // Each series' points, in the legend's (alphabetical) order; a file is named by its place in that order, so the
  // title given to a file is its own (until session 20 the files were numbered by first appearance in the list and
  // the titles alphabetically: the petrol cars were drawn as "E85").
  std::map<std::string, std::ostringstream> series;
  double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
  for (const auto& o : v.rows) {
    if (o.skip != validate::SkipReason::none) continue;
    series[o.powertrain + " (" + o.unit + ")"] << o.measured << " " << o.predicted << "\n";
    lo = std::min({lo, o.measured, o.predicted});
    hi = std::max({hi, o.measured, o.predicted});
  }
  // gnuplot draws in the scratch folder, and the figure is then written as every output is (atomically, under the
  // user's path as given): a path with a line break was turned into another name by gnuplot's quoting, and a stray
  // temporary file was left beside it (session 21).
  const std::string ext = fs::path(file).extension().string();
  const fs::path figure = work / ("figure" + ext);
  std::ofstream gp(work / "plot.gp");
  gp << report::gnuplot_terminal(ext == ".svg" ? "svg size 800,700 dynamic font 'Sans,12'" : "pngcairo size 800,700 font 'Sans,11'")
     << "set output " << report::gnuplot_string(figure.string()) << "\n"
     << "set title " << report::gnuplot_string(list_title(v) + ": rollsim from certification data against the dynamometer") << "\n"
     << "set xlabel 'measured [mpg or mpge]'\nset ylabel 'predicted [mpg or mpge]'\n"
     << "set logscale xy\nset grid\nset key top left\nset size square\n";
  // Both axes over the data's own span (gnuplot's log autoscale widens to whole decades: 1-1000 for 9-200 mpg).
  if (lo > 0.0 && hi >= lo) {  // one row (or all on the line) still has a span about it
    gp << "set xrange [" << lo / 1.1 << ":" << hi * 1.1 << "]\nset yrange [" << lo / 1.1 << ":" << hi * 1.1 << "]\n";
    const std::vector<double> at = tick_values(lo / 1.1, hi * 1.1);
    std::ostringstream ticks;
    for (std::size_t k = 0; k < at.size(); ++k) ticks << (k ? ", " : "") << at[k];
    if (!at.empty()) gp << "set xtics (" << ticks.str() << ")\nset ytics (" << ticks.str() << ")\n";
  }
  gp << "plot x title 'predicted = measured' lc rgb 'black'";
  std::size_t i = 0;
  for (const auto& [name, points] : series) {
    const fs::path data = work / ("s" + std::to_string(i++) + ".dat");
    std::ofstream(data) << points.str();
    gp << ", " << report::gnuplot_string(data.string()) << " with points pt 7 ps 0.4 title " << report::gnuplot_string(name);
  }
  gp << "\n";
  gp.close();
  const std::string err = report::run_gnuplot_script(gnuplot, (work / "plot.gp").string());
  if (!err.empty()) throw InputError("--plot " + file, "gnuplot failed: " + err);
  std::ifstream in(figure, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  write_file_atomically(file, "--plot", [&](std::ostream& out) { out << bytes.str(); });
}

void run_validate(const ValidateOptionsText& o, const ProcessGroup& group) {
  if (o.list.empty()) throw InputError("--epa-test-car-list", "missing: give the EPA Test Car List CSV");
  unsigned threads = 0;
  if (!o.threads.empty()) threads = static_cast<unsigned>(parse_option_count(o.threads, "--threads", Range::closed(1, 1024)));
  if (!o.plot.empty()) check_plot_target(o.plot);
  const auto rows = validate::read_epa_test_car_list(o.list);
  const auto v = validate::validate_epa_list(rows, threads, group.mapper());
  const bool any = std::any_of(v.rows.begin(), v.rows.end(), [](const auto& r) { return r.skip == validate::SkipReason::none; });
  if (any && !o.plot.empty() && group.is_root()) plot(v, o.plot);
  if (o.json) {
    for (const auto& r : v.rows) std::cout << validate::row_json(r).str() << "\n";
  } else {
    print_summary(v);
  }
  for (const auto& w : validate::validation_warnings(v)) std::cerr << "warning: " << w << "\n";
  // Nothing validated is not a result (it exited 0 and drew an empty figure: session 27's outside tester).
  if (!any)
    throw InputError(o.list, "none of its " + std::to_string(v.rows.size()) + " rows was simulated (each row's skip reason is " +
                                 (o.json ? "in its JSON" : "in the summary above") + ")" + (o.plot.empty() ? "" : "; no figure drawn"));
}

}  // namespace

void register_validate_command(CLI::App& app, const ProcessGroup& group) {
  auto o = std::make_shared<ValidateOptionsText>();
  auto* sub = app.add_subcommand("validate", "Simulate every car of the EPA Test Car List from its certification data and compare with its measured result");
  sub->add_option("--epa-test-car-list", o->list, "EPA Test Car List CSV (e.g. ../shared/data/vehicles/epa_test_car_list_2022_part.csv)")->type_name("FILE");
  sub->add_flag("--json", o->json, "One JSON object per row instead of the summary");
  sub->add_option("--plot", o->plot, "Draw predicted against measured (gnuplot)")->type_name("FILE.svg|.png");
  sub->add_option("--threads", o->threads, "Worker threads (default: every core)")->type_name("N");
  sub->callback([o, &group] { run_validate(*o, group); });
}

}  // namespace rollsim::cli
