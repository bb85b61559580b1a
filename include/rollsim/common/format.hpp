// Numbers as text: the forms every report, table and error message uses.
#pragma once

#include <string>

namespace rollsim {

/// The shortest text that reads back as the same double ("0.1", "1e+308"), for input values quoted in errors
/// and for machine-read output (CSV, JSON); "NaN", "inf", "-inf" for non-finite values.
std::string format_value(double value);

/// Fixed-point text of `value` with `decimals` digits after the point, for tables ("NaN"/"inf" for non-finite values).
std::string fixed(double value, int decimals);

/// The fewest decimals, from `least` up to `most`, at which fixed() tells `a` and `b` apart: a message comparing two
/// figures must not print them equal ("load 3999 N > 3999 N capacity": session 23's outside testing).
int decimals_apart(double a, double b, int least, int most);

/// `value` to `digits` significant digits ("%g" style: 0.000123, 1.23e+06), for figures whose magnitude varies
/// (fitted parameters, message values); "NaN"/"inf" for non-finite values.
std::string significant(double value, int digits);

}  // namespace rollsim
