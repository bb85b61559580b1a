// Names read from files compared without regard to case (column names, cycle names, makes and models).
#pragma once

#include <string>

namespace rollsim {

/// `text` with its ASCII letters lower-cased; other bytes (UTF-8 included) unchanged.
std::string lower_ascii(std::string text);

}  // namespace rollsim
