// Fuzzes the measured-tyre readers (a J2452 coefficient CSV, a measured-points CSV) and the fits they feed.
#include <algorithm>

#include "fuzz_input.hpp"
#include "rollsim/tyre/j2452.hpp"
#include "rollsim/tyre/j2452_evaluation.hpp"
#include "rollsim/tyre/tyre_fit.hpp"

namespace {

// A file of J2452 sets: each (up to three) sampled on the grid and fitted from its reference point, as
// --evaluate-j2452 and --j2452 do.
void fit_sets(const std::string& path) {
  const auto sets = rollsim::load_j2452_csv(path);
  for (std::size_t i = 0; i < std::min<std::size_t>(sets.size(), 3); ++i) {
    rollsim::TyreState start = rollsim::j2452_tyre(sets[i]);
    start.model = rollsim::TyreModelKind::Hysteresis;
    rollsim::FitRequest request;
    request.points = rollsim::sample_j2452(sets[i], rollsim::j2452_grid(), rollsim::kJ2452DrumRadius_m, sets[i].name);
    (void)rollsim::fit_hysteresis(start, request);
  }
}

// A file of measured points fitted on a 205/55 R16 (at most 200 points, to keep each input fast).
void fit_points(const std::string& path) {
  auto points = rollsim::load_measured_rrc_csv(path);
  if (points.size() > 200) points.resize(200);
  rollsim::TyreState start;
  start.geometry = {0.3172, 0.205, 0.2032};
  start.pressure_pa = 2.1e5;
  start.model = rollsim::TyreModelKind::Hysteresis;
  rollsim::FitRequest request;
  request.points = points;
  (void)rollsim::fit_hysteresis(start, request);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  rollsim::fuzz::run_on_file(data, size, ".csv", fit_sets);
  return rollsim::fuzz::run_on_file(data, size, ".csv", fit_points);
}
