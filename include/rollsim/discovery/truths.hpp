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
/// A winter heater (an electric car's PTC heater and its blower) warming a car soaked at ambient: two nodes, the
/// cabin air (C_air, losing UA (T_air - T_amb) through glass and ventilation) and the interior it heats (seats, trim:
/// C_int, exchanging h (T_air - T_int)). The heater holds the air at its set point, drawing
/// min(P_max, UA dT_set + (P_max / band) (dT_set - dT_air)): full power while the air is cold, then falling as the
/// interior warms, to UA dT_set. The catalogue's shape is a plain exponential decay from the start.
struct WinterCabin {
  double max_power_w = 3000.0;
  double setpoint_excess_k = 21.0;  ///< set point above the ambient
  double ua_w_per_k = 50.0;
  double air_j_per_k = 20000.0;
  double interior_w_per_k = 80.0;
  double interior_j_per_k = 100000.0;
  double band_k = 2.0;  ///< proportional band
  double blower_w = 150.0;
};
/// Per seed: ambient -10 to +5 degC (set point 21 degC), a settled power of 25-50 % of the maximum, an interior that
/// with the cabin at ambient would take 60-100 % of the rest, interior time constant C_int / h of 10-30 min, air
/// 15-30 kJ/K, blower 100-200 W.
WinterCabin winter_cabin(double max_power_w, std::mt19937& rng);
std::shared_ptr<const Effect> winter_heater_truth(const WinterCabin& cabin);
/// An electric car's cabin conditioning on a trip at one ambient, steady (the trip's mean): a PTC heater (COP 1)
/// replacing the cabin's loss UA (T_heat - T_amb) below the driver's heating threshold, an A/C removing
/// UA (T_amb - T_cool) plus the sun through the glass above the cooling one at a COP falling as the ambient rises,
/// and a blower whenever either runs. Not the catalogue's law: the blower steps on at the thresholds, the sun is a
/// load at any hot ambient, the COP bends the cooling branch, and the thresholds move from trip to trip.
struct CabinClimate {
  double ua_w_per_k = 50.0;  ///< the cabin's heat loss per K (glass, body, ventilation): the row's size
  double heat_below_c = 18.0, cool_above_c = 24.0;
  double solar_w = 200.0, blower_w = 150.0;
  double cop_at_25c = 3.0, cop_per_k = 0.05;  ///< COP = cop_at_25c - cop_per_k (T - 25 degC), at least 1.5
  double power_w(double ambient_c) const;     ///< the electrical power at that ambient
};
/// One trip's climate control (each trip its own draw: the driver's thresholds 17-19 and 23-25 degC, sun 100-400 W,
/// blower 100-200 W, COP 2.5-3.5 at 25 degC falling 0.05 per K).
CabinClimate cabin_climate(double ua_w_per_k, std::mt19937& rng);
std::shared_ptr<const Effect> hvac_cabin_truth(const CabinClimate& c, double ambient_c);

/// RRC rising over the trip (rain, a road surface turning rough, a slow puncture): factor 1 + rise (t / T)^p.
std::shared_ptr<const Effect> rising_rrc_truth(double rise, double duration_s, double power);

/// A petrol engine's warm-up as two thermal nodes above ambient, oil and block (with its coolant), for the fuel
/// channel: the fuel power's losses (fuel minus positive traction power) heat the block (30 %) and the oil (10 %,
/// the friction), the two exchange 80 W/K; the block loses 20 W/K below its thermostat (85 K above ambient) and
/// a radiator's 800 W/K above it, the sump 6 W/K; switched off (a soak) nothing heats, the radiator's fan is off
/// and the block loses 12 W/K to still air. Friction follows oil viscosity, ~ exp(b (T_ref - T_oil)), b = 0.035 /K,
/// T_ref = 70 K, so the fuel power is multiplied by 1 + k (exp(b (T_ref - T_oil)) - 1) / (exp(b T_ref) - 1): exactly
/// 1 + k at ambient, 1 once the oil is warm; the extra fuel's losses heat the engine too.
struct EngineThermalTruth {
  double cold_excess = 0.0;      ///< k: the fuel power's excess of an engine at ambient
  double oil_j_per_k = 10000.0;  ///< oil and the parts it wets
  double block_j_per_k = 50000.0;
  bool hot_start = false;        ///< both nodes at their warm running temperature at the start
};
/// Draws an engine whose friction warm-up (the oil reaching its warm viscosity on a UDDS) takes about 3-10 minutes:
/// oil 5-12 kJ/K (log-uniform), block 4-6 times the oil.
EngineThermalTruth cold_start_engine(double cold_excess, std::mt19937& rng);
/// The truth's fuel power per sample from the cold-free simulated fuel power `fuel_w` and positive traction power
/// `traction_w` (per sample, held over the segment that starts there), with the engine off where `engine_off`
/// says (segment flags, as DriveCycle::engine_off).
std::vector<double> engine_thermal_fuel_power_w(const std::vector<double>& time_s, const std::vector<double>& fuel_w,
                                                const std::vector<double>& traction_w, const std::vector<bool>& engine_off,
                                                const EngineThermalTruth& e);

/// A winding route: the heading along the distance, psi(s) = psi0 + sum_k a_k sin(2 pi s / L_k + phi_k), three
/// bends of 1-4 km (log-uniform) whose amplitudes sum to 1.2-1.8 rad, so the road turns through +-70-100 degrees.
struct WindingRoute {
  double heading0_rad = 0.0;
  std::vector<double> amplitude_rad, wavelength_m, phase_rad;
  double heading_rad(double distance_m) const;  ///< clockwise from north
};
WindingRoute winding_route(std::mt19937& rng);
/// A steady wind of `speed_mps` from the bearing `from_deg` on that route: headwind w cos(theta - psi(s)), the aero
/// force 0.5 rho CdA ((v + u)|v + u| - v^2) while moving.
std::shared_ptr<const Effect> steady_wind_truth(double speed_mps, double from_deg, WindingRoute route, double rho_cda_kg_per_m);
/// The same wind with along-wind Ornstein-Uhlenbeck gusts about its mean (sd 1.5 m/s, 15 s), drawn from `rng`.
std::shared_ptr<const Effect> gusty_wind_truth(double mean_speed_mps, double from_deg, WindingRoute route,
                                               double rho_cda_kg_per_m, double duration_s, std::mt19937& rng);
/// Latitude and longitude [deg] of the points at these distances along the route from (lat0, lon0), integrated on a
/// local flat earth in 1 m steps.
void route_gps(const WindingRoute& route, const std::vector<double>& distance_m, double lat0_deg, double lon0_deg,
               std::vector<double>& latitude_deg, std::vector<double>& longitude_deg);

/// A channel as a logger with a lag behind the truth records it: x(t - lag_s), linearly interpolated between the
/// samples (a lag need not be a whole number of samples); held at the first value before the start.
std::vector<double> delayed(const std::vector<double>& time_s, const std::vector<double>& x, double lag_s);

}  // namespace rollsim
