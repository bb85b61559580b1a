// The physical tyre rolling-resistance model (Redrouthu & Das 2014): Rhyne stiffness, n-element damping, drag.
#pragma once

#include <string>

namespace rollsim {

/// The model's five tuning constants (docs/tyre-model.md) and its discretisation. Defaults are the thesis'.
struct TyreModelConstants {
  /// Total viscous damping of the contact patch [N s/m]; each of the n elements gets Cv / n. Sets the
  /// first-order rise of RRC with speed.
  double viscous_damping_ns_per_m = 0.5;
  /// Total Coulomb (friction) damping [N]; each element gets Cc / n. Sets the RRC level at low speed.
  double coulomb_damping_n = 180.0;
  /// Rotational aerodynamic drag constant Cd [kg/m^2]: moment = V^2 * (2 pi R W) * Cd. Sets the
  /// high-speed curvature.
  double rotational_drag_kg_per_m2 = 1.0 / 280.0;
  /// Rhyne's pressure coefficient a in Kz = 1e4 (a P[bar] sqrt(0.7 W[mm] D[mm]) + b) [kgf/mm per bar per mm].
  double stiffness_pressure_coeff = 0.0274;
  /// Rhyne's offset b in the same formula [kgf/mm].
  double stiffness_offset_kgf_per_mm = 3.38;
  /// Number of element intervals n; n + 1 elements span the patch, both edges included.
  int elements = 500;
};

/// Undeformed tyre geometry.
struct TyreGeometry {
  double outer_radius_m = 0.0;   ///< R, unloaded outer radius
  double section_width_m = 0.0;  ///< W, nominal section width
  /// Rim radius; a deflection reaching it has no solution. 0 when unknown: then only R bounds the deflection.
  double rim_radius_m = 0.0;
};

/// One tyre and its inflation: what the model needs besides load and speed.
struct TyreState {
  TyreGeometry geometry;
  double pressure_pa = 0.0;
  TyreModelConstants constants;
};

/// Everything the model computes at one operating point. Force/power are per tyre.
struct RollingResistance {
  double stiffness_n_per_m = 0.0;  ///< Kz, vertical stiffness
  double deflection_m = 0.0;       ///< dz = N / Kz
  double loaded_radius_m = 0.0;    ///< a = R - dz, radius at the patch centre
  double half_angle_rad = 0.0;     ///< theta_max = acos(a / R)
  double contact_length_m = 0.0;   ///< 2 R sin(theta_max)
  double offset_e_m = 0.0;         ///< forward shift of the normal-pressure centre, e = M / F
  double rrc = 0.0;                ///< rolling-resistance coefficient e / R
  double rrc_coulomb = 0.0;        ///< part of rrc from Coulomb damping (speed independent for V > 0)
  double rrc_viscous = 0.0;        ///< part of rrc from viscous damping (linear in V)
  double rrc_rotational_drag = 0.0;  ///< part of rrc from rotational aerodynamic drag (quadratic in V)
  double rr_force_n = 0.0;         ///< rrc * N
  double rr_power_w = 0.0;         ///< rr_force_n * V
};

/// Vertical stiffness of the constant-belt model [N/m].
double vertical_stiffness_n_per_m(const TyreState& tyre);

/// Checks that `tyre` and the operating point are in the model's domain; throws ModelDomainError saying
/// which quantity is out and what is allowed (deflection reaching the rim, non-positive pressure, ...).
void check_operating_point(const TyreState& tyre, double load_n, double speed_mps);

/// The reference computation: the n-element sum of docs/tyre-model.md, step by step. Slow (O(n)); use
/// TyreAtLoad in simulations. Throws ModelDomainError outside the model's domain.
RollingResistance evaluate_rolling_resistance(const TyreState& tyre, double load_n, double speed_mps);

/// A tyre prepared at a fixed load: RRC(V) = k0 + k1 V + k2 V^2 for V > 0, and 0 at V = 0, exactly the
/// n-element sum (the Coulomb sum does not depend on wheel speed, the viscous one is linear in it, and the
/// drag term quadratic). Preparing costs one O(n) pass; each evaluation is a few flops.
class TyreAtLoad {
 public:
  TyreAtLoad() = default;
  /// Throws ModelDomainError outside the model's domain.
  static TyreAtLoad prepare(const TyreState& tyre, double load_n);

  double rrc(double speed_mps) const {
    const double v = speed_mps < 0.0 ? -speed_mps : speed_mps;
    return v > 0.0 ? k0_ + v * (k1_s_per_m_ + v * k2_s2_per_m2_) : 0.0;
  }
  double rr_force_n(double speed_mps) const { return rrc(speed_mps) * load_n_; }
  double load_n() const { return load_n_; }
  double k0() const { return k0_; }                    ///< Coulomb part of RRC [-]
  double k1_s_per_m() const { return k1_s_per_m_; }    ///< viscous slope [1/(m/s)]
  double k2_s2_per_m2() const { return k2_s2_per_m2_; }  ///< drag curvature [1/(m/s)^2]

 private:
  double k0_ = 0.0;
  double k1_s_per_m_ = 0.0;
  double k2_s2_per_m2_ = 0.0;
  double load_n_ = 0.0;
};

}  // namespace rollsim
