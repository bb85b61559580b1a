// Fuzzes the vehicle file loader (tyres named in it resolve to the shipped ones).
#include "fuzz_input.hpp"
#include "rollsim/vehicle/vehicle.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return rollsim::fuzz::run_on_file(data, size, ".yaml", [](const std::string& path) {
    const rollsim::Vehicle v = rollsim::load_vehicle_file(path);
    (void)v;
  });
}
