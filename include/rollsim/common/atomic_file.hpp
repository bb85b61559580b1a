// Output files written whole or not at all: checked before any computation, content goes to a temporary
// beside the target, and all of a command's outputs are renamed into place together at the end.
#pragma once

#include <functional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace rollsim {

/// Checks, before any computation, that `path` can be written: it is not a folder, not one of the command's
/// `inputs` (the same file under any name), and its folder exists and is writable (a symlink's target's folder; a
/// device or pipe must be writable itself). Throws InputError naming `option` and the path otherwise.
void check_output_file(const std::string& path, const std::string& option, const std::vector<std::string>& inputs = {});
/// Only the part of it that keeps an input from being overwritten: for files an output names itself (a report's).
void check_not_an_input(const std::string& path, const std::string& option, const std::vector<std::string>& inputs);

/// Checks that no two of a command's outputs (path, option) are one file. Throws InputError naming both.
void check_outputs_distinct(const std::vector<std::pair<std::string, std::string>>& path_and_option);

/// Checks that `dir` is a writable folder, or can be created as one in a writable folder that exists (a probe file is
/// made there and removed, since root passes the permission bits under /proc).
/// Creates nothing that stays. Throws InputError naming `option` and the folder otherwise.
void check_output_dir(const std::string& dir, const std::string& option);

/// One output of a command: where it goes, the option that asked for it (for errors), its whole content.
struct OutputFile {
  std::string path;
  std::string option;
  std::string content;
};

/// Writes every file to a temporary beside its target (creating missing folders; a symlink's target is the
/// target, and a device or pipe is written in place), and only when all were written renames them into place.
/// Any failure removes the temporaries and throws InputError naming the
/// option and path: no output is left half-written, and none is written when another could not be. SIGINT, SIGTERM,
/// SIGHUP and SIGQUIT are held meanwhile; one that arrived removes the temporaries before any rename, and then ends
/// the run (or, where it is caught, throws InputError).
void write_files_atomically(const std::vector<OutputFile>& files);

/// One file, its content produced by `write` on a stream: write_files_atomically of a single output.
/// A throwing `write` leaves no file behind.
void write_file_atomically(const std::string& path, const std::string& option,
                           const std::function<void(std::ostream&)>& write);

}  // namespace rollsim
