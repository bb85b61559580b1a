// `rollsim diagnose --report DIR`: figures (gnuplot SVG) of a diagnosis and a self-contained HTML page.
#pragma once

#include <string>
#include <vector>

#include "rollsim/common/atomic_file.hpp"
#include "rollsim/diagnose/diagnose.hpp"

namespace rollsim {

/// Files written into DIR, each atomically (temporary + rename): energy.svg (measured against simulated mean
/// power per window), cumulative.svg (cumulative residual over time), residual_speed.svg, residual_accel.svg,
/// residual_time.svg (window residual against each signature variable), each before and after the findings'
/// effects, and report.html embedding the SVGs inline with the text and JSON summaries. Creates DIR if missing.
/// Throws InputError (naming `--report` and DIR) when DIR cannot be created or written, or gnuplot is missing
/// or fails. Returns the paths written.
/// Checks that DIR is a writable folder or can be created, and that gnuplot is there, so that a bad --report
/// fails before a long diagnosis; creates nothing. Throws InputError as write_diagnosis_report does.
void check_report_dir(const std::string& dir);

/// The report's files (paths inside DIR and contents), drawn but not written: the CLI writes them together
/// with its other outputs, so that nothing is written when any of them fails.
std::vector<OutputFile> render_diagnosis_report(const std::string& dir, const Diagnosis& d, const std::string& title);

std::vector<std::string> write_diagnosis_report(const std::string& dir, const Diagnosis& d, const std::string& title);

}  // namespace rollsim
