// Fuzzes the drive-cycle CSV loader.
#include "fuzz_input.hpp"
#include "rollsim/cycle/drive_cycle.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return rollsim::fuzz::run_on_file(data, size, ".csv", [](const std::string& path) {
    const rollsim::DriveCycle c = rollsim::load_cycle(path, "--cycle");
    (void)c;
  });
}
