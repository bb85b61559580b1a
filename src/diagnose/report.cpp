// Diagnosis report: per-window data to gnuplot (SVG), and one HTML page with the SVGs inline.
#include "rollsim/common/units.hpp"
#include "rollsim/diagnose/report.hpp"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "rollsim/common/atomic_file.hpp"
#include "rollsim/common/error.hpp"
#include "rollsim/report/gnuplot.hpp"

namespace rollsim {
namespace {

namespace fs = std::filesystem;




std::string html_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '<') o += "&lt;";
    else if (c == '>') o += "&gt;";
    else if (c == '&') o += "&amp;";
    else o += c;
  }
  return o;
}

std::string read_all(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

struct Figure {
  std::string file, caption, script;
};

}  // namespace

void check_report_dir(const std::string& dir) {
  check_output_dir(dir, "--report");
  if (report::find_gnuplot().empty())
    throw InputError("--report '" + dir + "'", "gnuplot is not installed or not on PATH (Debian: apt-get install gnuplot-nox); "
                                               "the text and --json output do not need it");
}

std::vector<OutputFile> render_diagnosis_report(const std::string& dir, const Diagnosis& d, const std::string& title) {
  const std::string where = "--report '" + dir + "'";
  check_report_dir(dir);
  std::error_code ec;
  const std::string gnuplot = report::find_gnuplot();
  if (d.series.empty()) throw InputError(where, "the diagnosis has no windows to draw");

  const fs::path work = fs::temp_directory_path() / ("rollsim_report_" + std::to_string(getpid()) + "_" +
                                                     std::to_string(reinterpret_cast<std::uintptr_t>(&d)));
  fs::create_directories(work);
  // Columns: 1 time on a concatenated axis [min], 2 measured, 3 simulated, 4 calibrated, 5 fitted mean power [W],
  // 6 cumulative residual before [kJ], 7 after [kJ], 8 mean speed [km/h], 9 mean positive accel [m/s^2],
  // 10 time since the start of its recording [min], 11 residual power before [W], 12 after [W].
  {
    std::ofstream data(work / "windows.dat");
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
  using report::gnuplot_string;
  const std::string dat = gnuplot_string((work / "windows.dat").string());
  const std::string after = gnuplot_string(d.findings.empty() ? "after (no findings: same as before)" : "after the findings' effects");
  // Window residuals before and after, as points against one signature variable (a column of windows.dat).
  auto residual_against = [&](const std::string& file, const std::string& what, const std::string& xlabel, int column) {
    std::ostringstream script;
    script << "set xlabel " << gnuplot_string(xlabel) << "\nset ylabel 'residual mean power [W]'\nplot " << dat << " u " << column
           << ":11 w p pt 7 ps 0.6 t 'before', " << dat << " u " << column << ":12 w p pt 6 ps 0.6 t " << after
           << ", 0 w l lc 'black' notitle\n";
    return Figure{file, "Window residual against " + what, script.str()};
  };
  std::vector<Figure> figs{
      {"energy.svg", "Measured against simulated mean power per window (" + d.channel + " channel)",
       "set xlabel 'time, recordings one after another [min]'\nset ylabel 'mean power per window [W]'\nplot " + dat +
           " u 1:2 w lp pt 7 ps 0.5 lw 2 t 'measured', " + dat + " u 1:3 w l lw 1 dt 2 t 'simulated (nominal)', " + dat +
           " u 1:4 w l lw 2 t 'calibrated', " + dat + " u 1:5 w l lw 2 t " + after + "\n"},
      {"cumulative.svg", "Cumulative residual (measured minus model) over time",
       "set xlabel 'time, recordings one after another [min]'\nset ylabel 'cumulative residual energy [kJ]'\nplot " + dat +
           " u 1:6 w l lw 2 t 'before (calibrated)', " + dat + " u 1:7 w l lw 2 t " + after + "\n"},
      residual_against("residual_speed.svg", "mean speed", "mean speed in the window [km/h]", 8),
      residual_against("residual_accel.svg", "mean positive acceleration", "mean of max(0, a) in the window [m/s^2]", 9),
      residual_against("residual_time.svg", "time since the start of its recording", "time since the start of the recording [min]", 10),
  };
  std::vector<std::string> svgs;
  for (const auto& f : figs) {
    const fs::path out = work / f.file;
    {
      std::ofstream gp(work / "plot.gp");
      gp << report::gnuplot_terminal("svg size 800,450 dynamic font 'Sans,11'") << "set output " << gnuplot_string(out.string()) << "\n"
         << "set title " << gnuplot_string(f.caption) << "\nset grid\nset key outside bottom center horizontal\n" << f.script;
    }
    if (const std::string err = report::run_gnuplot_script(gnuplot, (work / "plot.gp").string()); !err.empty()) {
      fs::remove_all(work, ec);
      throw InputError(where, "gnuplot failed on " + f.file + ": " + err);
    }
    svgs.push_back(read_all(out));
  }
  fs::remove_all(work, ec);

  std::vector<OutputFile> files;
  for (std::size_t k = 0; k < figs.size(); ++k) files.push_back({(fs::path(dir) / figs[k].file).string(), "--report", svgs[k]});
  std::ostringstream os;
  os << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>" << html_escape(title)
     << "</title>\n<style>body{font-family:sans-serif;max-width:900px;margin:auto}pre{background:#f4f4f4;padding:8px;"
        "overflow-x:auto}figure{margin:1em 0}</style></head><body>\n<h1>"
     << html_escape(title) << "</h1>\n<h2>Verdict: " << html_escape(d.verdict) << "</h2>\n<pre>" << html_escape(diagnosis_text(d))
     << "</pre>\n";
  for (std::size_t k = 0; k < figs.size(); ++k) {
    // Inline SVG: drop the XML prolog and doctype, which are not allowed inside HTML.
    const std::string& s = svgs[k];
    const auto at = s.find("<svg");
    os << "<figure>\n" << (at == std::string::npos ? s : s.substr(at)) << "\n<figcaption>" << html_escape(figs[k].caption)
       << "</figcaption></figure>\n";
  }
  os << "<h2>JSON</h2>\n<pre>" << html_escape(diagnosis_json(d)) << "</pre>\n</body></html>\n";
  files.push_back({(fs::path(dir) / "report.html").string(), "--report", os.str()});
  return files;
}

std::vector<std::string> write_diagnosis_report(const std::string& dir, const Diagnosis& d, const std::string& title) {
  const auto files = render_diagnosis_report(dir, d, title);
  write_files_atomically(files);
  std::vector<std::string> written;
  for (const auto& f : files) written.push_back(f.path);
  return written;
}

}  // namespace rollsim
