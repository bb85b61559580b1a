#include "commands.hpp"

namespace rollsim::cli {

void register_commands(CLI::App& app) {
  register_tyre_command(app);
}

}  // namespace rollsim::cli
