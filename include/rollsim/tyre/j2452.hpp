// SAE J2452 rolling-resistance coefficient sets: reading them, their drum-to-flat correction, sampling them.
#pragma once

#include <string>
#include <vector>

#include "rollsim/tyre/tyre_fit.hpp"

namespace rollsim {

/// F_drum [N] = P[kPa]^alpha Z[N]^beta (a + b V[km/h] + c V[km/h]^2), SAE J2452's force law on a test drum.
struct J2452Set {
  std::string name;        ///< e.g. "P205/60R15 LO"
  std::string size;        ///< designation, e.g. "P205/60R15"
  double alpha = 0.0, beta = 0.0, a = 0.0, b = 0.0, c = 0.0;
  double rolling_radius_m = 0.0;  ///< the tyre's radius for the drum-to-flat correction
  bool flagged = false;           ///< the file's value_flagged: a value read with a correction its source note gives
};

/// The drum radius of the shipped Michelin sets (data/tyres/SOURCES.md) [m].
inline constexpr double kJ2452DrumRadius_m = 0.85;
/// ISO 28580's drum radius [m]: results on another drum are corrected to a 2.0 m diameter, and the EU label
/// (Regulation (EU) 2020/740, through UN R117 Annex 6) gives that value.
inline constexpr double kIso28580DrumRadius_m = 1.0;
/// A drum radius a user gave [m], if in (0.1, 10) m; otherwise InputError(where, ...) naming it and the range.
double checked_drum_radius_m(double radius_m, const std::string& where);

/// Flat-road over drum force, sqrt(r_drum / (r_drum + r_tyre)) (SAE J2452 Eq. 22 as quoted by the ADVISOR
/// files, data/tyres/SOURCES.md; ISO 28580 uses the same relation). A curved drum deflects the tyre more than
/// a flat road at the same load, so the drum reads high.
double drum_to_flat_factor(double drum_radius_m, double tyre_radius_m);

/// Flat-road RRC of the set at a point (SI in, kPa and km/h inside the law).
double j2452_flat_rrc(const J2452Set& set, double pressure_pa, double load_n, double speed_mps, double drum_radius_m);

/// One tyre given twice: the same name (size and class) or the same five coefficients.
bool same_j2452_tyre(const J2452Set& a, const J2452Set& b);

/// Parses "ALPHA,BETA,A,B,C" (--j2452); throws InputError(where, ...) naming the field.
J2452Set parse_j2452_text(const std::string& text, const std::string& where);

/// Reads sets from a CSV with columns size, rr_class, alpha, beta, a, b, c, wh_radius_m and optionally
/// value_flagged (yes/no) (as shipped in shared/data/tyres and tyres/measured); throws InputError naming file,
/// line and column.
std::vector<J2452Set> load_j2452_csv(const std::string& path);

/// The evaluation grid of the issue: 180-300 kPa (5) x 3-6 kN (5) x 15-115 km/h (6), 150 points.
struct OperatingGrid {
  std::vector<double> pressures_pa, loads_n, speeds_mps;
};
OperatingGrid j2452_grid();

/// The set's flat-road RRC at every grid point, as fit points named `where`.
std::vector<RrcPoint> sample_j2452(const J2452Set& set, const OperatingGrid& grid, double drum_radius_m,
                                   const std::string& where);

}  // namespace rollsim
