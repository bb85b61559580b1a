// The tyre rolling-resistance models: the thesis' (Redrouthu & Das 2014: Rhyne stiffness, n-element damping,
// drag) and a measured-data hysteresis model, selected per tyre.
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

/// Which rolling-resistance law a tyre follows. Thesis is the default, so tyre files without a choice keep
/// reproducing the thesis' reference values and trends.
enum class TyreModelKind { Thesis, Hysteresis };

/// Constants of the hysteresis model (docs in tyres/README.md, evidence in README.md). With f = V / (2 pi R)
/// the wheel's rotation frequency (each piece of rubber is deformed once per turn), dz = N / Kz the Rhyne
/// deflection and the subscript ref the reference point:
///   RRC = rrc_ref (dz / dz_ref)^n_d (N / N_ref)^n_z (1 + s_f f) + c_w f^2 (N / N_ref)^n_w.
/// The first term is the compound's hysteresis loss (level, its scaling with deflection and load, and the rise
/// of the loss modulus with deformation frequency); the second a speed-squared loss that does not scale with
/// the compound's level (tread inertia and air pumping). Defaults other than the level are shared constants
/// fitted to all nine Michelin J2452 sets (`rollsim tyre fit --evaluate-j2452`); rrc_ref is per tyre.
struct HysteresisConstants {
  double reference_pressure_pa = 2.1e5;  ///< P_ref, where dz_ref is taken (ISO 28580 standard load: 210 kPa)
  double reference_load_n = 4000.0;      ///< N_ref
  double rrc_ref = 0.010;                ///< hysteresis RRC at the reference point as f -> 0
  double deflection_exponent = 0.54166;   ///< n_d: loss per unit load grows with deflection
  double load_exponent = -0.58678;        ///< n_z: load dependence at fixed deflection
  double frequency_slope_per_hz = 0.017138;   ///< s_f: relative rise of the loss modulus per Hz
  double speed_loss_rrc_per_hz2 = 4.2285e-6;  ///< c_w: speed-squared loss [RRC / Hz^2]
  double speed_loss_load_exponent = 0.086928;  ///< n_w
  /// dz_ref [m] held fixed by a what-if on the tyre's size (with_geometry); 0: the tyre's own deflection at
  /// P_ref and N_ref, which is what a tyre file and a fit use.
  double reference_deflection_m = 0.0;
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
  TyreModelKind model = TyreModelKind::Thesis;
  TyreModelConstants constants;      ///< thesis constants; Rhyne's stiffness is used by both models
  HysteresisConstants hysteresis;    ///< used when model == Hysteresis
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
  // The three parts of rrc by speed dependence. Thesis: Coulomb damping, viscous damping, rotational drag.
  // Hysteresis model: hysteresis at f -> 0, its rise with frequency, the speed-squared loss.
  double rrc_coulomb = 0.0;        ///< speed-independent part (for V > 0)
  double rrc_viscous = 0.0;        ///< part linear in V
  double rrc_rotational_drag = 0.0;  ///< part quadratic in V
  double rr_force_n = 0.0;         ///< rrc * N
  double rr_power_w = 0.0;         ///< rr_force_n * V
};

/// The largest RRC either model may give (100 kg/t, ten times a production tyre's). A file's constants can
/// extrapolate past it (a damping or an exponent far from any tyre's); beyond it they, not a tyre, speak, so an
/// evaluation or a prepared tyre there is a ModelDomainError naming them.
inline constexpr double kMaxRrc = 0.1;

/// Vertical stiffness of the constant-belt model [N/m].
double vertical_stiffness_n_per_m(const TyreState& tyre);

/// The tyre resized to `geometry`, for a what-if on its size (sweeps, sensitivities). A hysteresis tyre keeps the
/// reference deflection of the size it was measured at: its loss follows (dz / dz_ref)^n_d, and re-deriving dz_ref
/// from the new size would cancel the size's effect on the deflection (a wider tyre would lose exactly as much).
TyreState with_geometry(const TyreState& tyre, const TyreGeometry& geometry);

/// Checks that `tyre` and the operating point are in the model's domain; throws ModelDomainError saying
/// which quantity is out and what is allowed (deflection reaching the rim, non-positive pressure, ...).
void check_operating_point(const TyreState& tyre, double load_n, double speed_mps);

/// Rolling resistance under the tyre's own model (state.model). Thesis: the reference computation, the
/// n-element sum of docs/tyre-model.md step by step, O(n); use TyreAtLoad in simulations. Hysteresis: the
/// closed form of HysteresisConstants. Throws ModelDomainError outside the model's domain.
RollingResistance evaluate_rolling_resistance(const TyreState& tyre, double load_n, double speed_mps);

/// A tyre prepared at a fixed load: RRC(V) = k0 + k1 V + k2 V^2 for V > 0, and 0 at V = 0. This is exactly
/// the thesis' n-element sum (the Coulomb sum does not depend on wheel speed, the viscous one is linear in it,
/// the drag term quadratic) and the hysteresis model's form at fixed load. Preparing costs one O(n) pass for
/// the thesis model; each evaluation is a few flops.
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
