// Fuzzes the tyre file loader and the model at the loaded tyre's rated load.
#include "fuzz_input.hpp"
#include "rollsim/tyre/tyre_model.hpp"
#include "rollsim/tyre/tyre_spec.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return rollsim::fuzz::run_on_file(data, size, ".yaml", [](const std::string& path) {
    const rollsim::TyreSpec spec = rollsim::load_tyre_file(path);
    const double load_n = spec.max_load_n > 0.0 ? 0.8 * spec.max_load_n : 4000.0;
    const double speed_mps = 22.0;
    rollsim::check_operating_point(spec.state, load_n, speed_mps);
    (void)rollsim::evaluate_rolling_resistance(spec.state, load_n, speed_mps);
  });
}
