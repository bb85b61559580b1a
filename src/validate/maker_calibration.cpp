#include "rollsim/validate/maker_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "rollsim/common/csv.hpp"
#include "rollsim/common/statistics.hpp"
#include "rollsim/common/text.hpp"

namespace rollsim::validate {

namespace {

constexpr double kNoCalibration = std::numeric_limits<double>::infinity();

// The group's log factor without `leave_out`'s rows, shrunk towards no correction by n / (n + shrinkage): a make
// seen on two rows moves a prediction less than one seen on forty.
template <class Rows>
double shrunk_median(const Rows& rows, const std::optional<std::string>& leave_out, double shrinkage_rows) {
  if (std::isinf(shrinkage_rows)) return 0.0;
  std::vector<double> e;
  for (const auto& r : rows) {
    if (!leave_out || r.model != *leave_out) e.push_back(r.log_error);
  }
  if (e.empty()) return 0.0;
  const double n = static_cast<double>(e.size());
  return median(e) * n / (n + shrinkage_rows);
}

}  // namespace

MakerCalibration MakerCalibration::fit(const std::vector<CalibrationSample>& fitting) {
  MakerCalibration c;
  for (const auto& s : fitting) {
    if (trim(s.make).empty() || !std::isfinite(s.log_error)) continue;
    c.groups_[{s.fuel, s.cycle, lower_ascii(s.make)}].push_back({lower_ascii(s.model), s.log_error});
  }
  // Each sample scored as a row of its group, looked up once: the candidates below score every sample again.
  struct Scored {
    const std::vector<ModelErrors>* group;
    const ModelErrors* row;
  };
  std::map<EpaFuel, std::vector<Scored>> by_fuel;
  for (const auto& [key, rows] : c.groups_) {
    for (const auto& row : rows) by_fuel[std::get<0>(key)].push_back({&rows, &row});
  }
  for (const auto& entry : by_fuel) {
    const EpaFuel fuel = entry.first;
    const auto& samples = entry.second;  // not a structured binding: clang before 16 cannot capture one in C++20
    auto mean_abs_log_error = [&](double shrinkage_rows) {
      double sum = 0.0;
      for (const Scored& s : samples) sum += std::abs(s.row->log_error - shrunk_median(*s.group, s.row->model, shrinkage_rows));
      return sum / static_cast<double>(samples.size());
    };
    CalibrationChoice choice;
    choice.rows = samples.size();
    choice.shrinkage_rows = kNoCalibration;
    choice.mean_abs_log_error_uncalibrated = mean_abs_log_error(kNoCalibration);
    choice.mean_abs_log_error_calibrated = choice.mean_abs_log_error_uncalibrated;
    // From the most shrinkage to the least, so a tie keeps the smaller correction.
    for (auto k = std::rbegin(kShrinkageCandidates); k != std::rend(kShrinkageCandidates); ++k) {
      const double score = mean_abs_log_error(*k);
      if (score < choice.mean_abs_log_error_calibrated) {
        choice.mean_abs_log_error_calibrated = score;
        choice.shrinkage_rows = *k;
      }
    }
    for (const auto& [key, rows] : c.groups_) {
      if (std::get<0>(key) == fuel) ++choice.groups;
    }
    c.choices_[fuel] = choice;
  }
  return c;
}

double MakerCalibration::factor(EpaFuel fuel, EpaCycle cycle, const std::string& make,
                                const std::optional<std::string>& leave_out_model) const {
  const auto choice = choices_.find(fuel);
  const auto group = groups_.find({fuel, cycle, lower_ascii(make)});
  if (choice == choices_.end() || group == groups_.end() || trim(make).empty()) return 1.0;
  // The physics' log error is ln(predicted / measured); the calibration divides out its expected part.
  const auto leave_out = leave_out_model ? std::optional<std::string>(lower_ascii(*leave_out_model)) : std::nullopt;
  return std::exp(-shrunk_median(group->second, leave_out, choice->second.shrinkage_rows));
}

}  // namespace rollsim::validate
