// Fuzzes the EPA Test Car List reader and, on short lists, the whole validation (classification, cars from rows,
// replays, the fit), as `rollsim validate --epa-test-car-list FILE` runs them.
#include "fuzz_input.hpp"
#include "rollsim/validate/epa_car.hpp"
#include "rollsim/validate/epa_test_car.hpp"
#include "rollsim/validate/validate.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return rollsim::fuzz::run_on_file(data, size, ".csv", [](const std::string& path) {
    const auto rows = rollsim::validate::read_epa_test_car_list(path);
    if (rows.size() <= 4) {
      (void)rollsim::validate::validate_epa_list(rows, 1);  // a few replays each: kept to short lists for speed
      return;
    }
    for (const auto& row : rows) {  // longer lists: every row's checks and car, without replays
      std::string detail;
      if (rollsim::validate::check_car_fields(row, detail) == rollsim::validate::SkipReason::none) {
        (void)rollsim::validate::car_from_row(row, rollsim::validate::EpaDefaults{});
      }
    }
  });
}
