// rollsim command-line entry point: parses the subcommand and hands over to the library.
#include <CLI/CLI.hpp>

#include <iostream>

#include "commands.hpp"
#include "rollsim/common/error.hpp"

int main(int argc, char** argv) {
  CLI::App app{"rollsim: tyre rolling resistance and vehicle energy simulation"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "rollsim 0.1.0");
  rollsim::cli::register_commands(app);
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
