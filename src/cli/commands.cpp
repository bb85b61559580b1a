#include "commands.hpp"

namespace rollsim::cli {

void register_commands(CLI::App& app) {
  (void)app;
}

}  // namespace rollsim::cli
