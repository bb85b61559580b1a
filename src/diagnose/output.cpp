// Diagnosis output: the JSON and text reports, and the vehicle file with the fitted effects.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "pipeline.hpp"
#include "rollsim/common/json.hpp"
#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/common/error.hpp"

namespace rollsim {

namespace diag {

std::string num(double v) { return significant(v, 6); }

}  // namespace diag

using diag::num;

std::string diagnosis_json(const Diagnosis& d) {
  // JSON has no NaN or infinity: a figure a degenerate recording leaves undefined is null.
  const auto jnum = [](double v) { return std::isfinite(v) ? num(v) : std::string("null"); };
  std::ostringstream os;
  os << "{\n  \"verdict\": \"" << d.verdict << "\",\n  \"channel\": \"" << d.channel << "\",\n";
  os << "  \"windows\": " << d.windows << ",\n  \"effective_windows\": " << jnum(d.effective_windows) << ",\n";
  os << "  \"calibration\": {\"channel_scale\": " << jnum(d.channel_scale) << ", \"rrc_level_change\": " << jnum(d.rrc_level_change)
     << ", \"drag_change\": " << jnum(d.drag_change) << ", \"channel_scale_prior\": {\"low\": " << jnum(d.channel_scale_prior_low)
     << ", \"high\": " << jnum(d.channel_scale_prior_high) << "}, \"channel_scale_free\": " << jnum(d.channel_scale_free) << ", \"rrc_level_change_free\": " << jnum(d.rrc_level_change_free)
     << ", \"drag_change_free\": " << jnum(d.drag_change_free) << ", \"delta_bic_leaving_prior\": " << jnum(d.calibration_delta_bic_leaving_prior)
     << ", \"outside_prior\": " << (d.calibration_outside_prior ? "true" : "false") << ", \"beyond_prior\": [";
  for (std::size_t i = 0; i < d.calibration_beyond_prior.size(); ++i) os << (i ? ", " : "") << json_string(d.calibration_beyond_prior[i]);
  os << "]"
     << ", \"scale_absorbed_energy_pct\": " << jnum(d.scale_absorbed_energy_pct) << ", \"with_findings\": {\"channel_scale\": "
     << jnum(d.channel_scale_with_findings) << ", \"rrc_level_change\": " << jnum(d.rrc_level_change_with_findings)
     << ", \"drag_change\": " << jnum(d.drag_change_with_findings) << "}},\n";
  os << "  \"adequacy\": {\"noise_floor_j\": " << jnum(d.noise_floor_j) << ", \"residual_to_noise_ratio\": "
     << jnum(d.residual_to_noise_ratio) << ", \"z\": " << jnum(d.residual_to_noise_z) << ", \"scale_s\": " << jnum(d.adequacy_scale_s)
     << ", \"after_findings_ratio\": " << jnum(d.final_residual_to_noise_ratio) << ", \"after_findings_z\": "
     << jnum(d.final_residual_to_noise_z) << "},\n";
  os << "  \"lag_samples\": " << d.lag_samples << ",\n";
  os << "  \"lag_s\": {\"value\": " << jnum(d.lag_s) << ", \"ci_low\": " << jnum(d.lag_ci_low_s) << ", \"ci_high\": " << jnum(d.lag_ci_high_s)
     << ", \"estimated\": " << (d.lag_estimated ? "true" : "false") << "},\n";
  os << "  \"engine_starts\": [";
  for (std::size_t i = 0; i < d.engine_starts.size(); ++i) {
    const auto& e = d.engine_starts[i];
    os << (i ? ", " : "") << "{\"recording\": " << json_string(e.recording) << ", \"start\": " << json_string(to_string(e.start))
       << ", \"inferred\": " << (e.inferred ? "true" : "false") << ", \"early_excess\": " << jnum(e.early_excess)
       << ", \"early_excess_ci\": [" << jnum(e.early_excess_ci_low) << ", " << jnum(e.early_excess_ci_high) << "]";
    if (e.idle_inferred)
      os << ", \"idle_excess\": " << jnum(e.idle_excess) << ", \"idle_excess_ci\": [" << jnum(e.idle_excess_ci_low) << ", "
         << jnum(e.idle_excess_ci_high) << "]";
    os << "}";
  }
  os << "],\n";
  os << "  \"channel_sampling\": {\"chosen\": \"" << d.channel_sampling << "\", \"interval_over_instant_sse\": "
     << jnum(d.channel_sampling_sse_ratio) << "},\n";
  os << "  \"window_s\": " << jnum(d.window_s) << ",\n  \"notes\": [";
  for (std::size_t i = 0; i < d.notes.size(); ++i) os << (i ? ", " : "") << json_string(d.notes[i]);
  os << "],\n";
  os << "  \"raw_trip_energy_error_pct\": " << jnum(d.raw_trip_energy_error_pct) << ",\n";
  os << "  \"heldout_rmse_calibrated\": " << jnum(d.heldout_rmse_calibrated_j) << ",\n";
  os << "  \"heldout_energy_error_pct_calibrated\": " << jnum(d.heldout_energy_error_pct_calibrated) << ",\n";
  os << "  \"findings\": [";
  for (std::size_t i = 0; i < d.findings.size(); ++i) {
    const auto& f = d.findings[i];
    // A finding that fitted nothing has no held-out figures: null, not the zeros its fields start at.
    const auto scored = [&f, &jnum](double x) { return f.heldout_scored ? jnum(x) : std::string("null"); };
    os << (i ? "," : "") << "\n    {\"effect\": \"" << f.effect << "\", ";
    if (!f.description.empty()) os << "\"description\": " << json_string(f.description) << ", ";
    os << "\"parameters\": {";
    for (std::size_t k = 0; k < f.parameters.size(); ++k) {
      const auto& p = f.parameters[k];
      os << (k ? ", " : "") << "\"" << p.name << "\": {\"value\": " << jnum(p.value) << ", \"ci_low\": " << jnum(p.ci_low)
         << ", \"ci_high\": " << jnum(p.ci_high) << ", \"unit\": \"" << p.unit << "\"";
      if (p.profiled)
        os << ", \"interval\": \"profile\", \"ci_low_open\": " << (p.ci_low_open ? "true" : "false")
           << ", \"ci_high_open\": " << (p.ci_high_open ? "true" : "false");
      os << "}";
    }
    os << "}, \"confounded_with\": [";
    for (std::size_t k = 0; k < f.confounded_with.size(); ++k) os << (k ? ", " : "") << "\"" << f.confounded_with[k] << "\"";
    os << "], \"separating_tests\": [";
    for (std::size_t k = 0; k < f.separating_tests.size(); ++k)
      os << (k ? ", " : "") << json_string(f.separating_tests[k]);
    os << "], \"delta_bic\": " << jnum(f.delta_bic)
       << ", \"energy_share_pct\": " << jnum(f.energy_share_pct)
       << ", \"heldout_rmse_before\": " << scored(f.heldout_rmse_before_j)
       << ", \"heldout_rmse_after\": " << scored(f.heldout_rmse_after_j)
       << ", \"heldout_energy_error_pct_before\": " << scored(f.heldout_energy_error_pct_before)
       << ", \"heldout_energy_error_pct_after\": " << scored(f.heldout_energy_error_pct_after)
       << ", \"heldout_lag1_autocorrelation_before\": " << scored(f.heldout_lag1_autocorrelation_before)
       << ", \"heldout_lag1_autocorrelation_after\": " << scored(f.heldout_lag1_autocorrelation_after);
    if (f.road_profile) {
      auto array = [&os, &jnum](const char* key, const std::vector<double>& v) {
        os << "\"" << key << "\": [";
        for (std::size_t k = 0; k < v.size(); ++k) os << (k ? ", " : "") << jnum(v[k]);
        os << "]";
      };
      os << ", \"road_profile\": {";
      array("distance_m", f.road_profile->distance_m);
      os << ", ";
      array("elevation_m", f.road_profile->elevation_m);
      os << ", ";
      array("elevation_ci_low_m", f.road_profile->elevation_ci_low_m);
      os << ", ";
      array("elevation_ci_high_m", f.road_profile->elevation_ci_high_m);
      os << "}";
    }
    os << "}";
  }
  os << (d.findings.empty() ? "" : "\n  ") << "],\n  \"located\": [";
  for (std::size_t i = 0; i < d.located.size(); ++i) {
    const auto& l = d.located[i];
    os << (i ? "," : "") << "\n    {\"regime\": \"" << l.regime << "\", \"samples\": " << l.samples << ", \"mean_residual_w\": "
       << jnum(l.mean_w) << ", \"ci_low_w\": " << jnum(l.ci_low_w) << ", \"ci_high_w\": " << jnum(l.ci_high_w) << "}";
  }
  os << (d.located.empty() ? "" : "\n  ") << "],\n  \"detection_limits\": [";
  for (std::size_t i = 0; i < d.detection_limits.size(); ++i) {
    const auto& l = d.detection_limits[i];
    os << (i ? "," : "") << "\n    {\"effect\": \"" << l.effect << "\", \"parameter\": \"" << l.parameter
       << "\", \"smallest_detectable\": " << jnum(l.smallest_detectable) << ", \"unit\": \"" << l.unit
       << "\", \"within_bounds\": " << (l.within_bounds ? "true" : "false") << "}";
  }
  os << (d.detection_limits.empty() ? "" : "\n  ") << "]\n}\n";
  return os.str();
}

std::string lag_text(const Diagnosis& d) {
  if (!d.lag_estimated) return "not estimated (a state of charge integrates the power: a lag of seconds does not show in it)";
  return fixed(d.lag_s, 2) + " s [" + fixed(d.lag_ci_low_s, 2) + ", " + fixed(d.lag_ci_high_s, 2) + "] (interpolated channel" +
         (d.lag_ci_low_s <= 0.0 ? "; 0 is the search's lower end: a channel that leads the speed, its clock ahead, reads 0 too" : "") + ")";
}

std::string diagnosis_text(const Diagnosis& d) {
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(3);
  os << "channel " << d.channel << ", " << d.windows << " windows (effective " << d.effective_windows
     << ", lag-1 autocorrelation " << d.lag1_autocorrelation << ")\n";
  for (const auto& note : d.notes) os << note << "\n";
  os << "channel lag: " << lag_text(d) << "\n";
  if (d.channel != "soc")
    os << "channel sampling: " << (d.channel_sampling == "instantaneous" ? "read at each sample's instant" : "mean over each sample's interval")
       << " (squared residual as interval means over as instants: " << d.channel_sampling_sse_ratio
       << "; the instant is chosen above 1.05)\n";
  os << "uncalibrated trip energy error: " << d.raw_trip_energy_error_pct << " %\n";
  os << "calibration" << (d.findings.empty() ? "" : " before the findings") << ": channel scale " << d.channel_scale
     << " (prior [" << d.channel_scale_prior_low << ", " << d.channel_scale_prior_high << "]), RRC level "
     << 100 * d.rrc_level_change << " %, aero C " << 100 * d.drag_change << " %";
  if (std::isfinite(d.channel_scale_with_findings))
    os << "; beside them: channel scale " << d.channel_scale_with_findings << ", RRC level " << 100 * d.rrc_level_change_with_findings
       << " %, aero C " << 100 * d.drag_change_with_findings << " %";
  os << "\n";
  if (d.calibration_outside_prior) {
    os << "  outside its prior (";
    if (!d.calibration_beyond_prior.empty()) os << "beyond the box: ";
    for (std::size_t i = 0; i < d.calibration_beyond_prior.size(); ++i) os << (i ? ", " : "") << d.calibration_beyond_prior[i];
    os << (d.calibration_beyond_prior.empty() ? "" : "; ") << "Delta BIC " << d.calibration_delta_bic_leaving_prior << "): the data alone wanted scale "
       << d.channel_scale_free << ", RRC level " << 100 * d.rrc_level_change_free << " %, aero C " << 100 * d.drag_change_free
       << " %; held in the prior, it leaves " << d.scale_absorbed_energy_pct << " % of the measured energy for the effects\n";
  }
  os << "noise floor: " << d.noise_floor_j / 1e3 << " kJ per noise window; calibrated residual " << d.residual_to_noise_ratio
     << " x the floor (z " << d.residual_to_noise_z << ", " << d.adequacy_scale_s << " s blocks), after the findings "
     << d.final_residual_to_noise_ratio << " x (z " << d.final_residual_to_noise_z << ")\n";
  os << "held-out, calibrated: RMSE " << d.heldout_rmse_calibrated_j / 1e3 << " kJ per window, trip energy error "
     << d.heldout_energy_error_pct_calibrated << " %\n";
  os << "verdict: " << d.verdict << "\n";
  for (const auto& f : d.findings) {
    os << "  " << f.effect << " (delta BIC " << f.delta_bic << ")";
    if (!f.confounded_with.empty()) {
      os << " confounded with";
      for (const auto& c : f.confounded_with) os << " " << c;
    }
    os << "\n";
    if (!f.description.empty()) os << "    " << f.description << "\n";
    for (const auto& t : f.separating_tests) os << "    to separate from " << t << "\n";
    for (const auto& p : f.parameters) {
      os << "    " << p.name << " = " << p.value;
      if (p.profiled)
        os << " [" << (p.ci_low_open ? "< " : "") << p.ci_low << ", " << (p.ci_high_open ? "> " : "") << p.ci_high
           << "] " << p.unit << " (profile likelihood, 95 %" << (p.ci_low_open || p.ci_high_open ? "; open at the grid's end" : "")
           << ")\n";
      else if (p.ci_low == p.value && p.ci_high == p.value)
        os << " " << p.unit << " (fixed)\n";
      else
        os << " [" << p.ci_low << ", " << p.ci_high << "] " << p.unit << "\n";
    }
    if (f.road_profile && !f.road_profile->distance_m.empty()) {
      const auto& p = *f.road_profile;
      const auto [lo, hi] = std::minmax_element(p.elevation_m.begin(), p.elevation_m.end());
      os << "    elevation profile: " << p.distance_m.size() << " knots over " << p.distance_m.back() / 1e3 << " km, "
         << *lo << " to " << *hi << " m from the start's (with its 95 % band in --json, road_profile)\n";
    }
    if (!std::isnan(f.energy_share_pct)) os << "    " << f.energy_share_pct << " % of the measured energy (in-sample)\n";
    if (f.heldout_scored)
      os << "    held-out RMSE " << f.heldout_rmse_before_j / 1e3 << " -> " << f.heldout_rmse_after_j / 1e3
       << " kJ/window, trip energy error " << f.heldout_energy_error_pct_before << " -> " << f.heldout_energy_error_pct_after
       << " %, residual lag-1 autocorrelation " << f.heldout_lag1_autocorrelation_before << " -> "
       << f.heldout_lag1_autocorrelation_after << " (0: white)\n";
  }
  if (!d.detection_limits.empty()) {
    // Not "a lower bound": an aux_load of 400 W was found on the Argonne UDDS beside a limit of 1162 W (session 24's
    // outside testing); the limit rests on the estimated noise floor and the catalogue's exact shape.
    os << "not found; smallest size of each effect's catalogue shape this data would have shown (an estimate, not a\n"
       << "bound: real shapes differ, and the discovery benchmark needs 1-3 times these; a smaller one may still be found):\n";
    for (const auto& l : d.detection_limits) {
      // Four significant digits: at the text's three decimals a limit of 0.00048 read "0.000", as if any size were
      // detectable (session 21).
      char limit[32];
      std::snprintf(limit, sizeof limit, "%.4g", l.smallest_detectable);
      os << "  " << l.effect << ": " << l.parameter << " " << limit << " " << l.unit
         << (l.within_bounds ? "" : " (beyond its physical bounds: not detectable here)") << "\n";
    }
  }
  os << "located (measured - calibrated model, mean power, 95 %):\n";
  os.precision(0);
  for (const auto& l : d.located)
    // A state of charge gives energy per window, so it is located by window (session 20: "samples" there).
    os << "  " << l.regime << ": " << l.mean_w << " W [" << l.ci_low_w << ", " << l.ci_high_w << "] (" << l.samples
       << (d.channel == "soc" ? " windows)\n" : " samples)\n");
  return os.str();
}

void check_no_effects_block(const YamlMap& vehicle_file, const std::string& vehicle_path) {
  if (vehicle_file.has("effects"))
    throw InputError(vehicle_path, "already has an effects: block; remove it to write a fitted one (--write-vehicle)");
}

std::string fitted_vehicle_yaml(const std::string& vehicle_path, const Diagnosis& d) {
  std::ifstream in(vehicle_path);
  if (!in) throw InputError(vehicle_path, "cannot read");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  // Only files without an effects block are rewritten: merging two blocks would silently drop one. Asked of the
  // YAML, not of the text, so that "effects :" or "\"effects\":" is one too.
  check_no_effects_block(YamlMap::load_text(text, vehicle_path), vehicle_path);
  std::vector<std::pair<std::string, EffectParameters>> eff;
  std::string not_written;
  for (const auto& f : d.findings) {
    // unexplained: described, not a module; road_profile: its knots are the diagnosis' output, not parameters. Each
    // is named, so a file with nothing under its heading does not read as "nothing found" (session 20).
    if (f.effect == "road_profile") not_written += "# found, not written: road_profile (a property of the route, not the car)\n";
    else if (f.effect == "unexplained") not_written += "# found, not written: unexplained (a signature no catalogue effect fits)\n";
    else eff.emplace_back(f.effect, f.fitted);
  }
  if (!text.empty() && text.back() != '\n') text += '\n';
  text += "# effects fitted by rollsim diagnose (verdict: " + d.verdict + ")\n" + not_written;
  if (eff.empty()) return text;
  return text + effects_yaml(eff);
}

}  // namespace rollsim
