// Order statistics of samples (medians of errors, fitted constants and effect sizes).
#pragma once

#include <vector>

namespace rollsim {

/// The middle value, or the mean of the two middle values for an even count; NaN for no values.
double median(std::vector<double> values);

}  // namespace rollsim
