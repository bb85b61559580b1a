// Fuzzes the recording CSV loader with the default column names.
#include "fuzz_input.hpp"
#include "rollsim/recording/recording.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return rollsim::fuzz::run_on_file(data, size, ".csv", [](const std::string& path) {
    const rollsim::Recording r = rollsim::load_recording(path, rollsim::ColumnMapping{});
    (void)r;
  });
}
