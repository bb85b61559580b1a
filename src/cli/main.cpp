// rollsim command-line entry point: parses the subcommand and hands over to the library.
#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <optional>
#include <set>
#include <string>

#include "commands.hpp"
#include "rollsim/common/distribute.hpp"
#include "rollsim/common/error.hpp"

namespace {

// Under mpirun every rank runs a distributed command (distributes_over_ranks) on the same input; only rank 0 prints. Errors that every rank
// meets alike (bad input, a failed case: agreed collectively) are printed once, by rank 0; any other error may be
// one rank's alone, so that rank names itself.
// A message quotes what the user gave (a key, a column header, a value); a control character in it is shown as
// \xNN, not sent to the terminal (an escape sequence in a CSV header recoloured or cleared it; session 21).
std::string printable(const std::string& text) {
  std::string out;
  for (const char ch : text) {
    const auto u = static_cast<unsigned char>(ch);
    if ((u < 0x20 && ch != '\n' && ch != '\t') || u == 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02X", u);
      out += hex;
    } else {
      out += ch;
    }
  }
  return out;
}

int report(const rollsim::ProcessGroup& group, const std::exception& e, bool same_on_every_rank, int code) {
  if (group.is_root()) std::cerr << "error: " << printable(e.what()) << "\n";
  else if (!same_on_every_rank) std::fprintf(stderr, "error (rank %d): %s\n", group.rank(), printable(e.what()).c_str());
  return code;
}

// CLI11 2.1 takes the next word as an option's value even when it is another option ("--label --output x.yaml"
// read "--output" as the label and then blamed x.yaml): an option's own command's option names are refused as values,
// and so is an empty value.
void refuse_option_names_as_values(CLI::App& app) {
  std::set<std::string> names;
  for (const CLI::Option* opt : app.get_options())
    for (const std::string& n : opt->get_lnames()) names.insert("--" + n);
  for (CLI::Option* opt : app.get_options()) {
    if (opt->get_type_size_max() == 0) continue;  // a flag takes no value
    opt->check(CLI::Validator(
        [names](std::string& value) {
          // An empty value was taken as the option not given: `--trace ""` wrote nothing and exited 0 (session 21).
          if (value.empty()) return std::string("needs a value here, and an empty one is none");
          return names.count(value) ? "needs a value here, and '" + value + "' is an option, not a value" : std::string();
        },
        "", "not an option name"));
  }
  for (CLI::App* sub : app.get_subcommands({})) refuse_option_names_as_values(*sub);
}

// An option whose value may be left out (`compare --catalogue [DIR]`) reads an empty value as none: `--catalogue ""`
// compared the shipped catalogue (session 22's notes), and CLI11 hands both over alike. An empty word or `--x=` after
// an option is refused before parsing, as the validator above refuses it for options that need a value.
std::string empty_option_value(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("--", 0) != 0 || a == "--") continue;
    if (a.find('=') == a.size() - 1) return a.substr(0, a.size() - 1);  // `--x=`, not `--x=a=`
    if (i + 1 < argc && argv[i + 1][0] == '\0') return a;
  }
  return "";
}

// The commands that split their cases over MPI ranks (README, "Running on a cluster"). Every other command is one
// computation: under mpirun it ran on every rank, each writing the same files (and a report's clean-up racing the
// other rank's figures: session 23's notes), so it runs on rank 0 alone.
bool distributes_over_ranks(int argc, char** argv) {
  if (argc < 2) return false;
  const std::string command = argv[1];
  if (command == "sweep" || command == "compare" || command == "validate" || command == "diagnose-bench") return true;
  if (command != "diagnose") return false;
  for (int i = 2; i < argc; ++i)
    if (std::string(argv[i]) == "--fleet" || std::string(argv[i]).rfind("--fleet=", 0) == 0) return true;
  return false;
}

// Most commands' output is stdout: a write that failed there (a full disk, a closed stream) left a table or CSV cut
// off mid-row with exit 0 (session 21's outside testing: `sweep > /dev/full`). Flushed and checked before exiting.
int checked_stdout(const rollsim::ProcessGroup& group, int code) {
  if (!group.is_root()) return code;  // its stdout is switched off
  std::cout.flush();
  const bool failed = std::cout.fail() | (std::fflush(stdout) != 0) | (std::ferror(stdout) != 0);
  if (!failed) return code;
  const int err = errno;
  std::cerr << "error: writing to standard output failed" << (err ? std::string(": ") + std::strerror(err) : "")
            << "; what was written there is incomplete\n";
  return code == 0 ? 2 : code;
}

// `--json` is a flag that prints on stdout in every command but diagnose, where it names a file: a file name after
// it elsewhere was refused as "The following argument was not expected" (session 26's outside testing).
std::string json_file_hint(int argc, char** argv, const std::string& parse_error) {
  if (argc < 2 || std::string(argv[1]) == "diagnose") return "";
  for (int i = 2; i + 1 < argc; ++i) {
    if (std::string(argv[i]) != "--json" || parse_error.find(argv[i + 1]) == std::string::npos) continue;
    return std::string("--json ") + argv[i + 1] + ": `rollsim " + argv[1] + " --json` takes no file: it prints JSON on stdout "
           "(redirect it: --json > " + argv[i + 1] + "); `rollsim diagnose --json FILE` is the one that writes a file";
  }
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  std::optional<rollsim::ProcessGroup> started;
  try {
    started.emplace(argc, argv);
  } catch (const rollsim::InputError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  const rollsim::ProcessGroup& group = *started;
  if (!group.is_root() && !distributes_over_ranks(argc, argv)) return 0;
  if (!group.is_root()) {
    std::cout.rdbuf(nullptr);
    std::cerr.rdbuf(nullptr);
  }
  CLI::App app{"rollsim: tyre rolling resistance and vehicle energy simulation"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "rollsim 0.1.0");
  // The parser's errors read like every other: one line after "error: " (CLI11's own read "--pressure-bar: At Most 1
  // required but received 2" with no prefix; session 27's outside tester).
  app.failure_message([](const CLI::App*, const CLI::Error& e) {
    return "error: " + std::string(e.what()) + "\nRun with --help for more information.\n";
  });
  rollsim::cli::register_commands(app, group);
  refuse_option_names_as_values(app);
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
  if (const std::string opt = empty_option_value(argc, argv); !opt.empty()) {
    std::cerr << "error: " << opt << ": needs a value here, and an empty one is none\n";
    return 2;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::RuntimeError& e) {
    // A command's own verdict (regress: 1 when a figure drifted), not a parse error.
    return checked_stdout(group, e.get_exit_code());
  } catch (const CLI::ParseError& e) {
    // --help and --version answer with exit 0; every other parse error is bad input, exit 2 like the rest (CLI11's
    // own codes, 105-109, would tell a script nothing more).
    // The help and version text go to stdout too, and a failed write there is said (it exited 0: session 22).
    if (const std::string hint = json_file_hint(argc, argv, e.what()); !hint.empty()) {
      std::cerr << "error: " << hint << "\n";
      return 2;
    }
    const int code = app.exit(e);
    return code == 0 ? checked_stdout(group, 0) : 2;
  } catch (const rollsim::InputError& e) {
    return report(group, e, true, 2);
  } catch (const rollsim::ModelDomainError& e) {
    return report(group, e, true, 2);
  } catch (const rollsim::CaseFailure& e) {
    // Bad input met inside a case (a fleet manifest's file or column) is bad input like any other: its own message,
    // which names the file and line, and exit 2. A case that failed to compute keeps its case number, and exit 1.
    if (e.bad_input()) return report(group, std::runtime_error(e.reason()), true, 2);
    return report(group, e, true, 1);
  } catch (const std::exception& e) {
    return report(group, e, group.size() == 1, 1);
  }
  return checked_stdout(group, 0);
}
