// Unit conversions used only at input and output boundaries; everything inside rollsim is SI.
#pragma once

#include <cmath>

namespace rollsim::units {

inline constexpr double kStandardGravity_mps2 = 9.80665;
inline constexpr double kPaPerBar = 1.0e5;
inline constexpr double kMpsPerKmh = 1.0 / 3.6;
inline constexpr double kMPerMm = 1.0e-3;
inline constexpr double kMPerInch = 0.0254;
inline constexpr double kJPerKwh = 3.6e6;
inline constexpr double kMPerKm = 1000.0;
inline constexpr double kM3PerLitre = 1.0e-3;
inline constexpr double kWPerHp = 745.69987158;  ///< mechanical horsepower (550 ft lbf/s)
inline constexpr double kKelvinOffset = 273.15;
inline constexpr double kMPerMile = 1609.344;
inline constexpr double kSPerHour = 3600.0;
inline constexpr double kM3PerCm3 = 1.0e-6;
inline constexpr double kMpsPerMph = kMPerMile / kSPerHour;
inline constexpr double kNPerLbf = 4.4482216152605;

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kRadpsPerRpm = 2.0 * kPi / 60.0;  ///< engine and motor speeds are given in rpm in files
inline constexpr double kEarthRadius_m = 6371000.0;  ///< mean radius, for local flat-earth projections of GPS
constexpr double deg_to_rad(double angle_deg) { return angle_deg * kPi / 180.0; }
/// A bearing taken to [0, 360) deg.
inline double wrap_deg(double angle_deg) { return std::fmod(std::fmod(angle_deg, 360.0) + 360.0, 360.0); }
constexpr double rad_to_deg(double angle_rad) { return angle_rad * 180.0 / kPi; }
constexpr double kmh_to_mps(double speed_kmh) { return speed_kmh * kMpsPerKmh; }
constexpr double mps_to_kmh(double speed_mps) { return speed_mps / kMpsPerKmh; }
constexpr double bar_to_pa(double pressure_bar) { return pressure_bar * kPaPerBar; }
constexpr double pa_to_bar(double pressure_pa) { return pressure_pa / kPaPerBar; }
constexpr double j_to_kwh(double energy_j) { return energy_j / kJPerKwh; }
constexpr double kwh_to_j(double energy_kwh) { return energy_kwh * kJPerKwh; }

}  // namespace rollsim::units
