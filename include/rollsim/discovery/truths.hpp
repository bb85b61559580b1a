// Concealed truths of the discovery benchmark that real loggers and roads vary: hills, cycling and cabin loads,
// an RRC rising over the trip, and the logger's sub-sample lag; each on its own code, never a catalogue module.
#pragma once

#include <memory>
#include <random>
#include <vector>

#include "rollsim/effects/effect.hpp"

namespace rollsim {

/// Rolling hills along the distance: h(s) = sum_k a_k sin(2 pi s / L_k + phi_k), zero mean.
struct RollingHills {
  std::vector<double> amplitude_m, wavelength_m, phase_rad;
  double elevation_m(double distance_m) const;
  double grade(double distance_m) const;  ///< dh/ds, rise over run
};

/// Three components with wavelengths log-uniform in 0.5-3 km and amplitudes proportional to the wavelength (each
/// component as steep as the others, as on a self-similar road), scaled so that sqrt(sum a_k^2) = amplitude_m (the
/// amplitude of one sinusoid of the same RMS). Where the components' summed peak grade would exceed
/// `max_grade`, every wavelength is stretched by the same factor (a road that steep would not be built).
RollingHills rolling_hills(double amplitude_m, std::mt19937& rng, double max_grade = 0.08);

/// An A/C compressor's on/off schedule: a trip-long duty (0.3-0.7) and period (2-6 min), each cycle's period
/// jittered +-25 % as a thermostat's would be, starting at a random phase of the first cycle.
struct DutyCycle {
  std::vector<double> on_from_s, on_until_s;  ///< the on intervals, in time order
  double on_power_w = 0.0;
  double power_w(double time_s) const;
  double mean_power_w(double duration_s) const;  ///< time average over [0, duration_s]
};
DutyCycle compressor_cycles(double on_power_w, double duration_s, std::mt19937& rng);

/// Truth effects (extra electrical power, or a factor on the tyres' rolling resistance).
std::shared_ptr<const Effect> duty_cycled_ac_truth(DutyCycle schedule);
/// Cabin conditioning of an electric car: `initial_w` from the start, constant (decay_s = 0) or falling to
/// floor x initial_w with time constant decay_s (a cabin reaching its set temperature).
std::shared_ptr<const Effect> cabin_load_truth(double initial_w, double decay_s, double floor);
/// RRC rising over the trip (rain, a road surface turning rough, a slow puncture): factor 1 + rise (t / T)^p.
std::shared_ptr<const Effect> rising_rrc_truth(double rise, double duration_s, double power);

/// A channel as a logger with a lag behind the truth records it: x(t - lag_s), linearly interpolated between the
/// samples (a lag need not be a whole number of samples); held at the first value before the start.
std::vector<double> delayed(const std::vector<double>& time_s, const std::vector<double>& x, double lag_s);

}  // namespace rollsim
