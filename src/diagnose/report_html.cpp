// The diagnosis report's HTML page, written for a reader: the answer first, then the evidence, the raw text last.
#include "report_html.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "rollsim/common/format.hpp"
#include "rollsim/common/text.hpp"
#include "rollsim/diagnose/report.hpp"

namespace rollsim::diag {
namespace {

constexpr const char* kStyle =
    "*{box-sizing:border-box}"
    "body{font:16px/1.5 system-ui,-apple-system,'Segoe UI',sans-serif;margin:0;padding:0 12px 2em;color:#1c1c1c;background:#fff;"
    "overflow-wrap:anywhere}"
    "main{max-width:980px;margin:auto}"
    "h1{font-size:1.45em;margin:.8em 0 .3em}h2{font-size:1.2em;margin:1.6em 0 .4em;border-bottom:1px solid #ddd}"
    ".headline{font-size:1.1em;padding:10px 14px;border-left:6px solid #777;background:#f5f5f5;margin:.6em 0 1em}"
    ".v-missing_physics{border-color:#b03a2e}.v-confounded{border-color:#c27c0e}.v-nothing_missing{border-color:#1e8449}"
    ".scroll{overflow-x:auto;max-width:100%;-webkit-overflow-scrolling:touch}"
    "table{border-collapse:collapse;font-size:.9em;margin:.3em 0}"
    "th,td{border-bottom:1px solid #ddd;padding:5px 8px;text-align:left;vertical-align:top;overflow-wrap:normal}"
    "th{background:#f0f0f0;min-width:6em}td.num{text-align:right;white-space:nowrap}"
    "td.params{min-width:13em}td.wide{min-width:14em}"
    "figure{margin:1em 0}figure .scroll svg{display:block;width:100%;min-width:480px;height:auto}"
    "figcaption{font-size:.9em;color:#444}"
    "details{margin:1em 0}summary{cursor:pointer;font-weight:600}"
    "pre{overflow-x:auto;background:#f4f4f4;padding:8px;font-size:.8em;overflow-wrap:normal}"
    "dt{font-weight:600}dd{margin:0 0 .6em 1em}";

// Decimals showing about three significant digits of `scale` (at most six). Fixed-point, unlike `significant`: a
// value and its interval's ends share the decimals of the largest, and no reader meets "2.58e+03 W".
int decimals_for(double scale) {
  if (!(std::abs(scale) > 0.0) || !std::isfinite(scale)) return 0;
  return std::clamp(2 - static_cast<int>(std::floor(std::log10(std::abs(scale)))), 0, 6);
}

std::string num3(double v) { return fixed(v, decimals_for(v)); }

std::string unit_suffix(const std::string& unit) { return unit.empty() || unit == "1" ? "" : " " + unit; }

// "value [low, high] unit", the ends marked open where a profile reached its grid's end; "(fixed)" when not fitted.
std::string parameter_text(const ParameterEstimate& p) {
  const int dec = decimals_for(std::max({std::abs(p.value), std::abs(p.ci_low), std::abs(p.ci_high)}));
  std::string s = p.name + " = " + fixed(p.value, dec);
  if (p.ci_low == p.value && p.ci_high == p.value) return s + unit_suffix(p.unit) + " (fixed)";
  s += " [" + std::string(p.ci_low_open ? "< " : "") + fixed(p.ci_low, dec) + ", " + (p.ci_high_open ? "> " : "") +
       fixed(p.ci_high, dec) + "]" + unit_suffix(p.unit);
  return s;
}

bool is_fitted(const Finding& f) { return !std::isnan(f.energy_share_pct); }

// What a finding that fits nothing is: a catalogue shape fitted with the impossible sign, or the residual left
// above the noise floor.
std::string unfitted_words(const Finding& f) {
  return f.wrong_sign ? "a catalogue shape with the impossible sign, so not that effect"
                      : "the residual left above the recording's noise floor";
}

std::string kj(double j) { return num3(j / 1e3); }

std::string verdict_words(const std::string& verdict) {
  if (verdict == "missing_physics") return "Missing physics";
  if (verdict == "confounded") return "Confounded";
  if (verdict == "nothing_missing") return "Nothing missing";
  return verdict;
}

void findings_table(std::ostream& os, const Diagnosis& d) {
  os << "<h2 id=\"findings\">Findings</h2>\n";
  if (d.findings.empty()) {
    os << "<p>No catalogue effect passed the test (Delta BIC threshold, and a better held-out fit).</p>\n";
    return;
  }
  os << "<div class=\"scroll\"><table>\n<thead><tr><th>Effect</th><th>Parameters (95 % interval)</th>"
        "<th>Share of measured energy</th><th>Held-out error per window [kJ]<br>before &rarr; after</th>"
        "<th>Held-out trip energy error [%]<br>before &rarr; after</th><th>&Delta;BIC</th><th>Confounded with</th>"
        "<th>Experiment that separates them</th></tr></thead>\n<tbody>\n";
  for (const auto& f : d.findings) {
    os << "<tr><td>" << html_escape(f.effect) << "</td><td class=\"params\">";
    for (std::size_t k = 0; k < f.parameters.size(); ++k) os << (k ? "<br>" : "") << html_escape(parameter_text(f.parameters[k]));
    os << "</td>";
    // A road profile is scored on held-out windows but is no single effect's energy: its share is a dash.
    if (f.heldout_scored)
      os << "<td class=\"num\">" << (is_fitted(f) ? fixed(f.energy_share_pct, 2) + " %" : std::string("&mdash;"))
         << "</td><td class=\"num\">" << kj(f.heldout_rmse_before_j)
         << " &rarr; " << kj(f.heldout_rmse_after_j) << "</td><td class=\"num\">" << fixed(f.heldout_energy_error_pct_before, 2)
         << " &rarr; " << fixed(f.heldout_energy_error_pct_after, 2) << "</td><td class=\"num\">" << fixed(f.delta_bic, 1) << "</td>";
    else
      os << "<td colspan=\"4\">not a fitted effect: " << html_escape(unfitted_words(f)) << "</td>";
    os << "<td>";
    for (std::size_t k = 0; k < f.confounded_with.size(); ++k) os << (k ? "<br>" : "") << html_escape(f.confounded_with[k]);
    os << (f.confounded_with.empty() ? "none" : "") << "</td><td class=\"wide\">";
    for (std::size_t k = 0; k < f.separating_tests.size(); ++k) os << (k ? "<br>" : "") << html_escape(f.separating_tests[k]);
    os << (f.separating_tests.empty() ? "&mdash;" : "") << "</td></tr>\n";
  }
  os << "</tbody></table></div>\n<dl>\n";
  for (const auto& f : d.findings)
    if (!f.description.empty()) os << "<dt>" << html_escape(f.effect) << "</dt><dd>" << html_escape(f.description) << "</dd>\n";
  os << "</dl>\n";
}

void calibration_table(std::ostream& os, const Diagnosis& d) {
  auto row = [&](const std::string& what, const std::string& value) {
    os << "<tr><th scope=\"row\">" << html_escape(what) << "</th><td class=\"num\">" << html_escape(value) << "</td></tr>\n";
  };
  os << "<h2 id=\"calibration\">Calibration and noise</h2>\n<div class=\"scroll\"><table>\n";
  row("measured channel", d.channel);
  row("energy windows (effective)", std::to_string(d.windows) + " (" + fixed(d.effective_windows, 1) + ") of " + fixed(d.window_s, 0) + " s");
  row("channel lag, 95 %", lag_text(d));
  if (d.channel != "soc")
    row("channel sampling (residual as means / as instants)",
        (d.channel_sampling == "instantaneous" ? "at each sample's instant" : "mean over each interval") + std::string(" (") +
            fixed(d.channel_sampling_sse_ratio, 3) + ")");
  row("uncalibrated trip energy error [%]", fixed(d.raw_trip_energy_error_pct, 2));
  row("channel scale (prior box)", fixed(d.channel_scale, 3) + " (" + fixed(d.channel_scale_prior_low, 3) + " to " +
                                       fixed(d.channel_scale_prior_high, 3) + ")");
  row("RRC level change [%]", fixed(100.0 * d.rrc_level_change, 2));
  row("aero C change [%]", fixed(100.0 * d.drag_change, 2));
  row("noise floor per noise window [kJ]", kj(d.noise_floor_j));
  row("residual / noise floor (variance), before → after findings", fixed(d.residual_to_noise_ratio, 2) + " → " +
                                                                            fixed(d.final_residual_to_noise_ratio, 2));
  row("held-out error per window, calibrated [kJ]", kj(d.heldout_rmse_calibrated_j));
  row("held-out trip energy error, calibrated [%]", fixed(d.heldout_energy_error_pct_calibrated, 2));
  os << "</table></div>\n";
  if (!d.notes.empty()) {
    os << "<ul>\n";
    for (const auto& n : d.notes) os << "<li>" << html_escape(n) << "</li>\n";
    os << "</ul>\n";
  }
}

void limits_table(std::ostream& os, const Diagnosis& d) {
  os << "<h2 id=\"limits\">Detection limits</h2>\n";
  if (d.detection_limits.empty()) {
    os << "<p>Every catalogue effect that could be tested was found or tested; no limits to state.</p>\n";
    return;
  }
  os << "<p>For each catalogue effect not found: the smallest size of its catalogue shape this data would have shown "
        "(an estimate, not a bound: real shapes differ, and the discovery benchmark needs 1-3 times these; a smaller one "
        "may still be found).</p>\n"
        "<div class=\"scroll\"><table>\n<thead><tr><th>Effect</th><th>Parameter</th><th>Smallest detectable</th><th>Unit</th>"
        "<th>Within its physical bounds</th></tr></thead>\n<tbody>\n";
  for (const auto& l : d.detection_limits)
    os << "<tr><td>" << html_escape(l.effect) << "</td><td>" << html_escape(l.parameter) << "</td><td class=\"num\">"
       << num3(l.smallest_detectable) << "</td><td>" << html_escape(l.unit == "1" ? "" : l.unit) << "</td><td>"
       << (l.within_bounds ? "yes" : "no: not detectable on this data") << "</td></tr>\n";
  os << "</tbody></table></div>\n";
}

// gnuplot's SVG inline: without its XML prolog (not allowed in HTML), titled with the caption, and its ids (the
// same in every gnuplot SVG: gpPt0, gnuplot_canvas) prefixed so that each figure's references stay its own.
std::string inline_svg(const HtmlFigure& f) {
  const auto at = f.svg.find("<svg");
  std::string s = at == std::string::npos ? f.svg : f.svg.substr(at);
  const std::string p = f.id + "-";
  for (const std::string key : {"id='", "id=\"", "href='#", "href=\"#", "url(#"})
    for (auto k = s.find(key); k != std::string::npos; k = s.find(key, k + key.size() + p.size())) s.insert(k + key.size(), p);
  if (const auto t = s.find("<title>Gnuplot</title>"); t != std::string::npos)
    s.replace(t, 22, "<title>" + html_escape(f.caption) + "</title>");
  return s.insert(4, " role=\"img\"");
}

void figures(std::ostream& os, const std::vector<HtmlFigure>& figs) {
  for (const auto& f : figs)
    os << "<figure id=\"fig-" << html_escape(f.id) << "\"><div class=\"scroll\">" << inline_svg(f) << "</div>\n<figcaption>"
       << html_escape(f.caption) << "</figcaption></figure>\n";
}

// A description up to its first "; " or ". " outside brackets: the part a headline can carry.
std::string first_clause(const std::string& text) {
  int depth = 0;
  for (std::size_t i = 0; i + 1 < text.size(); ++i) {
    depth += text[i] == '(' || text[i] == '[' ? 1 : text[i] == ')' || text[i] == ']' ? -1 : 0;
    if (depth == 0 && (text[i] == ';' || text[i] == '.') && text[i + 1] == ' ') return text.substr(0, i);
  }
  return text;
}

// "tyre_warmup (cold_excess = 0.21 [0.15, 0.27])": the effect with its leading parameter.
std::string finding_words(const Finding& f) {
  if (f.parameters.empty()) return f.effect;
  return f.effect + " (" + parameter_text(f.parameters.front()) + ")";
}

// How the held-out fit changes from the calibrated model to the model with every fitted finding.
std::string heldout_change(const Diagnosis& d) {
  const Finding* last = nullptr;
  int fitted = 0;
  for (const auto& f : d.findings)
    if (is_fitted(f)) last = &f, ++fitted;
  if (!last)
    return "no effect was fitted, so the held-out error stays at " + kj(d.heldout_rmse_calibrated_j) +
           " kJ per window (trip energy error " + fixed(d.heldout_energy_error_pct_calibrated, 2) + " %).";
  const double before = d.heldout_rmse_calibrated_j, after = last->heldout_rmse_after_j;
  const double change_pct = before > 0.0 ? 100.0 * (before - after) / before : 0.0;
  return std::string(fitted == 1 ? "With it" : "With the " + std::to_string(fitted) + " fitted effects") +
         ", the held-out error per window " + (after <= before ? "falls" : "rises") + " from " + kj(before) + " to " + kj(after) +
         " kJ (" + fixed(std::abs(change_pct), 0) + " % " + (after <= before ? "lower" : "higher") +
         ") and the held-out trip energy error goes from " + fixed(d.heldout_energy_error_pct_calibrated, 2) + " % to " +
         fixed(last->heldout_energy_error_pct_after, 2) + " %.";
}

}  // namespace

std::string html_escape(const std::string& text) {
  std::string o;
  o.reserve(text.size());
  for (const char c : valid_utf8(text)) {  // the page declares UTF-8
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      case '\'': o += "&#39;"; break;
      default: o += c;
    }
  }
  return o;
}

std::string report_page(const Diagnosis& d, const std::string& title, const ReportFigures& figs) {
  std::ostringstream os;
  os << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n"
        "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>"
     << html_escape(title) << "</title>\n<style>" << kStyle << "</style></head>\n<body><main>\n<h1>" << html_escape(title)
     << "</h1>\n<p class=\"headline v-" << html_escape(d.verdict) << "\" id=\"headline\">" << html_escape(diagnosis_headline(d))
     << "</p>\n";
  findings_table(os, d);
  os << "<h2 id=\"regimes\">Where the model misses</h2>\n";
  if (figs.regimes.empty()) os << "<p>No driving regime had enough samples to locate the residual.</p>\n";
  figures(os, figs.regimes);
  if (!figs.road_profiles.empty()) {
    os << "<h2 id=\"road\">Recovered road profile</h2>\n";
    figures(os, figs.road_profiles);
  }
  os << "<h2 id=\"residuals\">Residuals</h2>\n";
  figures(os, figs.residuals);
  limits_table(os, d);
  calibration_table(os, d);
  os << "<details id=\"raw\"><summary>Raw text and JSON output</summary>\n<pre>" << html_escape(diagnosis_text(d)) << "</pre>\n<pre>"
     << html_escape(diagnosis_json(d)) << "</pre>\n</details>\n</main></body></html>\n";
  return os.str();
}

}  // namespace rollsim::diag

namespace rollsim {

std::string diagnosis_headline(const Diagnosis& d) {
  using namespace diag;
  const std::string verdict = verdict_words(d.verdict) + ": ";
  const std::string noise = fixed(d.final_residual_to_noise_ratio, 1) + " x the recording's noise floor";
  if (d.findings.empty())
    return verdict + "the calibrated model leaves a residual of " + noise + " and no catalogue effect improves the held-out fit; " +
           heldout_change(d);
  const Finding& f = d.findings.front();
  if (!is_fitted(f))
    return verdict + (f.description.empty() ? "the residual is " + noise : first_clause(f.description)) + "; " + heldout_change(d);
  std::string s = verdict + "the main finding is " + finding_words(f) + ", " + fixed(f.energy_share_pct, 1) +
                  " % of the measured energy";
  if (!f.confounded_with.empty()) {
    s += ", which this data cannot tell from ";
    for (std::size_t k = 0; k < f.confounded_with.size(); ++k) s += (k ? " or " : "") + f.confounded_with[k];
  }
  return s + ". " + heldout_change(d);
}

}  // namespace rollsim
