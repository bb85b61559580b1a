// Output files written whole or not at all: content goes to a temporary beside the target, then is renamed.
#pragma once

#include <functional>
#include <ostream>
#include <string>

namespace rollsim {

/// Calls `write` with a stream to a temporary file in the target's folder and renames it to `path` only when
/// `write` returned and the stream is good. Throws InputError naming `option` and the path when the folder is
/// not writable; a failed or throwing `write` leaves no file behind.
void write_file_atomically(const std::string& path, const std::string& option,
                           const std::function<void(std::ostream&)>& write);

}  // namespace rollsim
