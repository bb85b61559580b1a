// Order statistics of samples (medians of errors, fitted constants and effect sizes), and the quantile a fitted
// constant's interval needs.
#pragma once

#include <vector>

namespace rollsim {

/// The middle value, or the mean of the two middle values for an even count; NaN for no values.
double median(std::vector<double> values);

/// The median of successive differences (a time channel's typical sample interval); NaN for fewer than two values.
double median_step(const std::vector<double>& values);

/// The two-sided 95 % quantile of Student's t with `dof` degrees of freedom (12.706 for 1, 4.303 for 2, 2.228 for
/// 10, towards 1.960): the half-width, in standard errors, of a 95 % interval whose scatter was estimated from `dof`
/// residuals. From the exact distribution function for whole dof (Abramowitz and Stegun 26.7.3-4), by bisection.
double student_t_95(int dof);

}  // namespace rollsim
