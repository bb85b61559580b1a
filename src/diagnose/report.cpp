// Diagnosis report: per-window data to gnuplot (SVG), and one HTML page with the SVGs inline.
#include "rollsim/common/units.hpp"
#include "rollsim/diagnose/report.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <regex>
#include <fstream>
#include <sstream>

#include "rollsim/common/atomic_file.hpp"
#include "rollsim/common/error.hpp"
#include "rollsim/report/gnuplot.hpp"
#include "report_html.hpp"

namespace rollsim {
namespace {

namespace fs = std::filesystem;

std::string read_all(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// One gnuplot figure: its file name in DIR, caption (also its title in the page), plot commands, height in pixels.
struct Figure {
  std::string file, caption, script;
  int height_px = 400;
};

}  // namespace

void check_report_dir(const std::string& dir) {
  check_output_dir(dir, "--report");
  if (report::find_gnuplot().empty())
    throw InputError("--report '" + dir + "'", "gnuplot is not installed or not on PATH (Debian: apt-get install gnuplot-nox); "
                                               "the text and --json output do not need it");
}

namespace {

// Columns: 1 time on a concatenated axis [min], 2 measured, 3 simulated, 4 calibrated, 5 fitted mean power [W],
// 6 cumulative residual before [kJ], 7 after [kJ], 8 mean speed [km/h], 9 mean positive accel [m/s^2],
// 10 time since the start of its recording [min], 11 residual power before [W], 12 after [W].
void write_windows(const fs::path& path, const Diagnosis& d) {
  std::ofstream data(path);
  double offset_s = 0.0, prev_end = 0.0, cum_before = 0.0, cum_after = 0.0;
  int rec = d.series.front().recording;
  for (const auto& w : d.series) {
    if (w.recording != rec) {
      offset_s += prev_end;
      rec = w.recording;
    }
    prev_end = w.end_s;
    const double dur = std::max(1e-9, w.end_s - w.start_s);
    cum_before += (w.measured_j - w.calibrated_j) / 1e3;
    cum_after += (w.measured_j - w.fitted_j) / 1e3;
    data << (offset_s + 0.5 * (w.start_s + w.end_s)) / 60.0 << " " << w.measured_j / dur << " " << w.simulated_j / dur << " "
         << w.calibrated_j / dur << " " << w.fitted_j / dur << " " << cum_before << " " << cum_after << " "
         << units::mps_to_kmh(w.mean_speed_mps) << " " << w.mean_positive_accel_mps2 << " " << 0.5 * (w.start_s + w.end_s) / 60.0 << " "
         << (w.measured_j - w.calibrated_j) / dur << " " << (w.measured_j - w.fitted_j) / dur << "\n";
  }
}

std::vector<Figure> residual_figures(const Diagnosis& d, const fs::path& work) {
  write_windows(work / "windows.dat", d);
  using report::gnuplot_string;
  const std::string dat = gnuplot_string((work / "windows.dat").string());
  // An 'unexplained' finding has no effect to fit: with only such, the after line is the before line, and says so.
  const bool fitted = std::any_of(d.findings.begin(), d.findings.end(), [](const auto& f) { return f.effect != "unexplained"; });
  const std::string after = gnuplot_string(d.findings.empty() ? "after (no findings: same as before)"
                                           : fitted           ? "after the findings' effects"
                                                              : "after (no effect fitted: same as before)");
  // Window residuals before and after, as points against one signature variable (a column of windows.dat).
  auto residual_against = [&](const std::string& file, const std::string& what, const std::string& xlabel, int column) {
    std::ostringstream script;
    script << "set xlabel " << gnuplot_string(xlabel) << "\nset ylabel 'residual mean power [W]'\nplot " << dat << " u " << column
           << ":11 w p pt 7 ps 0.6 t 'before', " << dat << " u " << column << ":12 w p pt 6 ps 0.6 t " << after
           << ", 0 w l lc 'black' notitle\n";
    return Figure{file, "Window residual against " + what, script.str(), 400};
  };
  return {
      {"energy.svg", "Measured against simulated mean power per window (" + d.channel + " channel)",
       "set xlabel 'time, recordings one after another [min]'\nset ylabel 'mean power per window [W]'\nplot " + dat +
           " u 1:2 w lp pt 7 ps 0.5 lw 2 t 'measured', " + dat + " u 1:3 w l lw 1 dt 2 t 'simulated (nominal)', " + dat +
           " u 1:4 w l lw 2 t 'calibrated', " + dat + " u 1:5 w l lw 2 t " + after + "\n", 400},
      // A margin above and below: a line ending just under the frame's 0 kJ was read as cut off by it (session 25).
      {"cumulative.svg", "Cumulative residual (measured minus model) over time",
       "set offsets 0, 0, graph 0.05, graph 0.05\nset xlabel 'time, recordings one after another [min]'\nset ylabel 'cumulative residual energy [kJ]'\nplot " + dat +
           " u 1:6 w l lw 2 t 'before (calibrated)', " + dat + " u 1:7 w l lw 2 t " + after + "\n", 400},
      residual_against("residual_speed.svg", "mean speed", "mean speed in the window [km/h]", 8),
      residual_against("residual_accel.svg", "mean positive acceleration", "mean of max(0, a) in the window [m/s^2]", 9),
      residual_against("residual_time.svg", "time since the start of its recording", "time since the start of the recording [min]", 10),
  };
}

// The located regimes as horizontal bars: mean residual power with its 95 % interval, one row per regime, each
// regime's name as a label beside its row. Labels, not explicit tics: gnuplot reads a tic's label as a printf format
// ("uphill (> 1 %)" fails) and truncates it; a label is text as written (through gnuplot_string).
std::vector<Figure> regime_figures(const Diagnosis& d, const fs::path& work) {
  if (d.located.empty()) return {};
  using report::gnuplot_string;
  const std::string dat = gnuplot_string((work / "regimes.dat").string());
  std::ofstream data(work / "regimes.dat");
  std::ostringstream labels;
  std::size_t longest = 0;
  const int n = static_cast<int>(d.located.size());
  for (int k = 0; k < n; ++k) {
    const auto& l = d.located[static_cast<std::size_t>(k)];
    const int y = n - 1 - k;  // first regime on top
    const bool off_zero = l.ci_low_w > 0.0 || l.ci_high_w < 0.0;
    data << y << " " << l.mean_w << " " << l.ci_low_w << " " << l.ci_high_w << " " << (off_zero ? 1 : 0) << "\n";
    const std::string label = l.regime + " (" + std::to_string(l.samples) + ")";
    longest = std::max(longest, label.size());
    labels << "set label " << k + 1 << " " << gnuplot_string(label) << " at graph -0.02, first " << y << " right\n";
  }
  std::ostringstream script;
  // A margin left and right: an interval ending on the frame (the Camry US06's at 14000 W) read as cut off by it.
  script << labels.str() << "unset ytics\nset yrange [-0.7:" << n - 0.3 << "]\nset offsets graph 0.03, graph 0.03, 0, 0\nset grid noytics\n"
         << "set xlabel 'mean residual power, measured minus calibrated model [W]'\nset lmargin " << std::min<std::size_t>(longest, 60) + 2 << "\n"
         << "set arrow from 0, graph 0 to 0, graph 1 nohead lc 'black'\n"
         << "plot " << dat << " u ($5 > 0 ? $2 : 1/0):1:3:4 w xerrorbars pt 7 ps 1 lw 2 lc rgb '#b03a2e' t 'interval excludes 0', "
         << dat << " u ($5 > 0 ? 1/0 : $2):1:3:4 w xerrorbars pt 6 ps 1 lw 2 lc rgb '#666666' t 'interval includes 0'\n";
  return {{"regimes.svg", std::string("Residual by driving regime (") + (d.channel == "soc" ? "windows" : "samples") +
                              " in brackets): mean and 95 % interval", script.str(), 120 + 34 * n}};
}

// Each road_profile finding's recovered elevation along distance, with its 95 % band where the finding has one.
std::vector<Figure> road_figures(const Diagnosis& d, const fs::path& work) {
  std::vector<Figure> out;
  for (const auto& f : d.findings) {
    if (!f.road_profile) continue;
    const RecoveredProfile& p = *f.road_profile;
    const std::size_t n = std::min(p.distance_m.size(), p.elevation_m.size());
    if (n < 2) continue;
    const bool band = p.elevation_ci_low_m.size() >= n && p.elevation_ci_high_m.size() >= n;
    std::string name = "road_profile";
    if (!out.empty()) name.append("_").append(std::to_string(out.size() + 1));
    const std::string dat = report::gnuplot_string((work / (name + ".dat")).string());
    std::ofstream data(work / (name + ".dat"));
    for (std::size_t i = 0; i < n; ++i)
      data << p.distance_m[i] / units::kMPerKm << " " << p.elevation_m[i] << " " << (band ? p.elevation_ci_low_m[i] : 0.0) << " "
           << (band ? p.elevation_ci_high_m[i] : 0.0) << "\n";
    std::string plot = "set xlabel 'distance driven [km]'\nset ylabel 'elevation relative to the start [m]'\nplot ";
    if (band) plot += dat + " u 1:3:4 w filledcurves lc rgb '#c6dbef' t '95 % band', ";
    out.push_back({name + ".svg", "Recovered road profile (" + f.effect + "): elevation along the distance driven",
                   plot + dat + " u 1:2 w l lw 2 lc rgb '#08519c' t 'recovered'\n", 360});
  }
  return out;
}

// Draws each figure through gnuplot into `work`; returns the SVG texts, or throws InputError naming the figure.
std::vector<std::string> draw(const std::vector<Figure>& figs, const fs::path& work, const std::string& where) {
  using report::gnuplot_string;
  const std::string gnuplot = report::find_gnuplot();
  std::vector<std::string> svgs;
  for (const auto& f : figs) {
    const fs::path out = work / f.file;
    {
      std::ofstream gp(work / "plot.gp");
      gp << report::gnuplot_terminal("svg size 720," + std::to_string(f.height_px) + " dynamic font 'Sans,12'") << "set output "
         << gnuplot_string(out.string()) << "\nset grid\nset key outside bottom center horizontal\n" << f.script;
    }
    if (const std::string err = report::run_gnuplot_script(gnuplot, (work / "plot.gp").string()); !err.empty())
      throw InputError(where, "gnuplot failed on " + f.file + ": " + err);
    svgs.push_back(read_all(out));
  }
  return svgs;
}

}  // namespace

std::vector<OutputFile> render_diagnosis_report(const std::string& dir, const Diagnosis& d, const std::string& title) {
  const std::string where = "--report '" + dir + "'";
  check_report_dir(dir);
  if (d.series.empty()) throw InputError(where, "the diagnosis has no windows to draw");
  const report::ScratchDir scratch("rollsim_report_");
  const fs::path& work = scratch.path();
  std::vector<std::vector<Figure>> sections{regime_figures(d, work), residual_figures(d, work), road_figures(d, work)};
  std::vector<std::vector<std::string>> svgs;
  for (const auto& s : sections) svgs.push_back(draw(s, work, where));

  std::vector<OutputFile> files;
  diag::ReportFigures page;
  std::vector<diag::HtmlFigure>* into[] = {&page.regimes, &page.residuals, &page.road_profiles};
  for (std::size_t s = 0; s < sections.size(); ++s)
    for (std::size_t k = 0; k < sections[s].size(); ++k) {
      const Figure& f = sections[s][k];
      files.push_back({(fs::path(dir) / f.file).string(), "--report", svgs[s][k]});
      into[s]->push_back({fs::path(f.file).stem().string(), f.caption, svgs[s][k]});
    }
  files.push_back({(fs::path(dir) / "report.html").string(), "--report", diag::report_page(d, title, page)});
  return files;
}

std::vector<std::string> remove_stale_report_figures(const std::string& dir, const std::vector<OutputFile>& written) {
  std::set<fs::path> kept;
  for (const auto& f : written) kept.insert(fs::path(f.path).lexically_normal());
  static const std::regex figure(R"((energy|cumulative|regimes|residual_(speed|accel|time)|road_profile(_[0-9]+)?)\.svg)");
  std::vector<std::string> removed;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const fs::path p = it->path();
    if (!std::regex_match(p.filename().string(), figure) || kept.count(p.lexically_normal()) || !it->is_regular_file(ec)) continue;
    if (fs::remove(p, ec)) removed.push_back(p.string());
  }
  return removed;
}

std::vector<std::string> write_diagnosis_report(const std::string& dir, const Diagnosis& d, const std::string& title) {
  const auto files = render_diagnosis_report(dir, d, title);
  write_files_atomically(files);
  remove_stale_report_figures(dir, files);
  std::vector<std::string> written;
  for (const auto& f : files) written.push_back(f.path);
  return written;
}

}  // namespace rollsim
