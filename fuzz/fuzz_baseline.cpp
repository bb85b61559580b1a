// Fuzzes the energy-regression baseline loader (reading only; running its cases is not the loader's job).
#include "fuzz_input.hpp"
#include "rollsim/selection/regress.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return rollsim::fuzz::run_on_file(data, size, ".yaml", [](const std::string& path) {
    const rollsim::selection::Baseline b = rollsim::selection::load_baseline(path);
    (void)b;
  });
}
