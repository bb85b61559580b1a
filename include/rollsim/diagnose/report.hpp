// `rollsim diagnose --report DIR`: figures (gnuplot SVG) of a diagnosis and a self-contained HTML page.
#pragma once

#include <string>
#include <vector>

#include "rollsim/common/atomic_file.hpp"
#include "rollsim/diagnose/diagnose.hpp"

namespace rollsim {

/// Checks that DIR is a writable folder or can be created, and that gnuplot is there, so that a bad --report
/// fails before a long diagnosis; creates nothing. Throws InputError as write_diagnosis_report does.
void check_report_dir(const std::string& dir);

/// The report's files (paths inside DIR and contents), drawn but not written: the CLI writes them together
/// with its other outputs, so that nothing is written when any of them fails.
std::vector<OutputFile> render_diagnosis_report(const std::string& dir, const Diagnosis& d, const std::string& title);

/// Removes from DIR the figures an earlier report left there that `written` does not hold again (a road_profile.svg
/// stayed beside a report that had none: session 23's outside testing). Only the report's own figure names are
/// touched (energy.svg, cumulative.svg, regimes.svg, residual_*.svg, road_profile*.svg); returns the paths removed.
std::vector<std::string> remove_stale_report_figures(const std::string& dir, const std::vector<OutputFile>& written);

/// One sentence for a reader: the verdict, the main finding with its leading parameter and share of the measured
/// energy (and what it is confounded with), and how the held-out error per window changes with the fitted effects.
std::string diagnosis_headline(const Diagnosis& d);

/// Writes into DIR, each file atomically (temporary + rename): regimes.svg (mean residual power per driving regime
/// with its 95 % interval), energy.svg (measured against simulated mean power per window), cumulative.svg
/// (cumulative residual over time), residual_speed.svg, residual_accel.svg, residual_time.svg (window residual
/// against each signature variable, before and after the findings' effects), road_profile.svg for each finding
/// carrying a recovered road profile, and report.html: a self-contained page (headline, findings table, the
/// figures inline, detection limits, calibration, the raw text and JSON folded away). Creates DIR if missing.
/// Throws InputError (naming `--report` and DIR) when DIR cannot be created or written, or gnuplot is missing
/// or fails. Returns the paths written.
std::vector<std::string> write_diagnosis_report(const std::string& dir, const Diagnosis& d, const std::string& title);

}  // namespace rollsim
