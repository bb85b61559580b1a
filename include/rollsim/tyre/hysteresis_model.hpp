// The hysteresis rolling-resistance model for measured tyres: its speed polynomial at a fixed load.
#pragma once

#include "rollsim/tyre/tyre_model.hpp"

namespace rollsim {

/// RRC(V) = k0 + k1 V + k2 V^2 of the hysteresis model at one load and the tyre's pressure (V in m/s, V > 0).
struct SpeedPolynomial {
  double k0 = 0.0;            ///< hysteresis part as f -> 0 [-]
  double k1_s_per_m = 0.0;    ///< its rise with deformation frequency [1/(m/s)]
  double k2_s2_per_m2 = 0.0;  ///< speed-squared loss [1/(m/s)^2]
};

/// dz_ref: the pinned reference deflection, or the tyre's own at P_ref and N_ref.
double hysteresis_reference_deflection_m(const TyreState& tyre);

/// The hysteresis model's polynomial (HysteresisConstants). Assumes check_operating_point passed.
SpeedPolynomial hysteresis_polynomial(const TyreState& tyre, double load_n);

/// Checks the hysteresis constants (positive level and reference point, finite exponents, RRC > 0 at all
/// speeds); throws ModelDomainError naming the constant and what is allowed.
void check_hysteresis_constants(const HysteresisConstants& c);

}  // namespace rollsim
