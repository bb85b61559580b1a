// libFuzzer harness support: each input goes to a temporary file that a loader reads like a user's file.
// A loader may reject an input only with InputError or ModelDomainError; any other exception escapes and
// libFuzzer reports it as a crash, as it does for ASan and UBSan findings.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "rollsim/common/error.hpp"

namespace rollsim::fuzz {

/// Writes the input to /tmp/rollsim_fuzz_<pid><extension> and calls `load(path)`; expected rejections are
/// swallowed. One file per process, overwritten per input.
template <class Load>
int run_on_file(const std::uint8_t* data, std::size_t size, const std::string& extension, Load&& load) {
  static const std::string path =
      (std::filesystem::temp_directory_path() / ("rollsim_fuzz_" + std::to_string(::getpid()) + extension)).string();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    load(path);
  } catch (const InputError&) {
  } catch (const ModelDomainError&) {
  }
  return 0;
}

}  // namespace rollsim::fuzz
