// rollsim command-line entry point: parses the subcommand and hands over to the library.
#include <CLI/CLI.hpp>

#include <iostream>
#include <string>

#include "commands.hpp"
#include "rollsim/common/error.hpp"

int main(int argc, char** argv) {
  CLI::App app{"rollsim: tyre rolling resistance and vehicle energy simulation"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "rollsim 0.1.0");
  rollsim::cli::register_commands(app);
  // CLI11 answers an unknown first word with "A subcommand is required"; name it and the known ones instead.
  if (argc > 1 && argv[1][0] != '-') {
    std::string known;
    bool found = false;
    for (const CLI::App* sub : app.get_subcommands({})) {
      found = found || sub->check_name(argv[1]);
      known += (known.empty() ? "" : ", ") + sub->get_name();
    }
    if (!found) {
      std::cerr << "error: unknown command '" << argv[1] << "'; the commands are " << known << "\n";
      return 2;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const rollsim::InputError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const rollsim::ModelDomainError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
