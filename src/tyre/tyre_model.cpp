#include "rollsim/tyre/tyre_model.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "rollsim/common/error.hpp"
#include "rollsim/tyre/hysteresis_model.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/common/format.hpp"

namespace rollsim {
namespace {

// Geometry of the loaded patch, shared by the reference sum and the prepared tyre.
struct Patch {
  double stiffness_n_per_m;
  double deflection_m;
  double loaded_radius_m;
  double half_angle_rad;
};

Patch loaded_patch(const TyreState& tyre, double load_n) {
  Patch p{};
  p.stiffness_n_per_m = vertical_stiffness_n_per_m(tyre);
  p.deflection_m = load_n / p.stiffness_n_per_m;
  p.loaded_radius_m = tyre.geometry.outer_radius_m - p.deflection_m;
  p.half_angle_rad = std::acos(p.loaded_radius_m / tyre.geometry.outer_radius_m);
  return p;
}

// Sums over the n + 1 elements of |x_i| (Coulomb lever arms) and |sin theta_i| |x_i| (viscous lever arms per
// unit rim speed w R). With sign(zdot_i) = -sign(theta_i), every element's moment F_i x_i is non-negative, so
// M = (Cc/n) S0 + (Cv/n) V S1 exactly as the element-by-element sum, and F = N (the damping forces cancel
// pairwise by symmetry).
struct LeverSums {
  double coulomb_m = 0.0;
  double viscous_m = 0.0;
};

LeverSums lever_sums(const Patch& p, int n) {
  LeverSums s;
  for (int i = 0; i <= n; ++i) {
    // From the element's index, so the centre element (n even, i = n / 2) is at exactly 0: as -theta_max + i dtheta
    // it came out as +-5e-17 in ~1 % of operating points, its sign was +-1 and a Coulomb force Cc / n appeared there
    // (RRC jumps of up to 3.6e-4 relative between neighbouring loads; --explain's elasticities off by 0.2; session 20).
    const double theta = (2.0 * i / n - 1.0) * p.half_angle_rad;
    const double x_abs = std::abs(p.loaded_radius_m * std::tan(theta));
    const double sin_abs = std::abs(std::sin(theta));
    if (sin_abs > 0.0) s.coulomb_m += x_abs;  // sign(0) = 0: the centre element carries no force
    s.viscous_m += sin_abs * x_abs;
  }
  return s;
}

// Figures in messages: four significant digits say what is wrong without false precision.
std::string v(double x) { return std::abs(x) >= 1e3 && std::abs(x) < 1e12 ? fixed(x, 0) : significant(x, 4); }

}  // namespace

double vertical_stiffness_n_per_m(const TyreState& tyre) {
  const double p_bar = tyre.pressure_pa / 1.0e5;
  const double w_mm = tyre.geometry.section_width_m * 1.0e3;
  const double d_mm = 2.0 * tyre.geometry.outer_radius_m * 1.0e3;
  const auto& c = tyre.constants;
  // Rhyne's fit is in kgf/mm with 0.7 W as contact width; the spec converts with 1e4 (not 9806.65).
  return 1.0e4 * (c.stiffness_pressure_coeff * p_bar * std::sqrt(0.7 * w_mm * d_mm) + c.stiffness_offset_kgf_per_mm);
}

TyreState with_geometry(const TyreState& tyre, const TyreGeometry& geometry) {
  TyreState t = tyre;
  if (t.model == TyreModelKind::Hysteresis) t.hysteresis.reference_deflection_m = hysteresis_reference_deflection_m(tyre);
  t.geometry = geometry;
  return t;
}

void check_operating_point(const TyreState& tyre, double load_n, double speed_mps) {
  const auto& g = tyre.geometry;
  if (!(g.outer_radius_m > 0.0) || !std::isfinite(g.outer_radius_m))
    throw ModelDomainError("outer radius " + v(g.outer_radius_m) + " m: must be > 0");
  if (!(g.section_width_m > 0.0) || !std::isfinite(g.section_width_m))
    throw ModelDomainError("section width " + v(g.section_width_m) + " m: must be > 0");
  if (!(g.rim_radius_m >= 0.0) || !(g.rim_radius_m < g.outer_radius_m))
    throw ModelDomainError("rim radius " + v(g.rim_radius_m) + " m: must be >= 0 and below the outer radius " +
                           v(g.outer_radius_m) + " m");
  if (!(tyre.pressure_pa > 0.0) || !std::isfinite(tyre.pressure_pa))
    throw ModelDomainError("inflation pressure " + v(tyre.pressure_pa / 1e5) + " bar: must be > 0");
  if (!(load_n > 0.0) || !std::isfinite(load_n)) throw ModelDomainError("normal load " + v(load_n) + " N: must be > 0");
  if (!(speed_mps >= 0.0) || !std::isfinite(speed_mps))
    throw ModelDomainError("speed " + v(units::mps_to_kmh(speed_mps)) + " km/h: must be >= 0");
  const auto& c = tyre.constants;
  if (c.elements < 2 || c.elements % 2 != 0)
    throw ModelDomainError("element count " + std::to_string(c.elements) + ": must be an even number >= 2");
  if (!(c.viscous_damping_ns_per_m >= 0.0) || !(c.coulomb_damping_n >= 0.0) || !(c.rotational_drag_kg_per_m2 >= 0.0))
    throw ModelDomainError("damping and drag constants must be >= 0");
  if (tyre.model == TyreModelKind::Hysteresis) check_hysteresis_constants(tyre.hysteresis);
  const double kz = vertical_stiffness_n_per_m(tyre);
  if (!(kz > 0.0) || !std::isfinite(kz)) throw ModelDomainError("vertical stiffness " + v(kz) + " N/m: must be > 0");
  const double deflection_m = load_n / kz;
  // Without a rim the sidewall is unknown, and the outer radius alone let a tyre deflect to its axle (299.8 of
  // 300 mm at an RRC of 5.5e-5, session 20). A third of the outer radius is beyond any passenger or light-truck
  // sidewall (aspect ratio 80 on a 13" rim: 0.38 R) and far beyond a working deflection (a tenth of it).
  const bool rim_known = g.rim_radius_m > 0.0;
  const double limit_m = rim_known ? g.outer_radius_m - g.rim_radius_m : g.outer_radius_m / 3.0;
  if (!(deflection_m < limit_m)) {
    throw ModelDomainError("load " + v(load_n) + " N deflects the tyre by " + v(deflection_m * 1e3) + " mm, which " +
                           (rim_known ? "reaches the rim (sidewall height "
                                      : "is over a third of the outer radius, beyond any tyre's sidewall (no rim given; ") +
                           v(limit_m * 1e3) + " mm at stiffness " + v(kz) + " N/m); the model has no solution: " +
                           "load must be below " + fixed(kz * limit_m, 2) + " N at this pressure");
  }
}

namespace {

// Past kMaxRrc it is the constants that extrapolate: name them, so the user sees which to mend.
void check_rrc_level(double rrc, const TyreState& tyre, double load_n, const std::string& what) {
  if (rrc <= kMaxRrc) return;
  std::string constants;
  if (tyre.model == TyreModelKind::Hysteresis) {
    constants = "exponents (deflection " + v(tyre.hysteresis.deflection_exponent) + ", load " +
                v(tyre.hysteresis.load_exponent) + ")";
  } else {
    const auto& c = tyre.constants;
    constants = "damping constants (coulomb_damping_n " + v(c.coulomb_damping_n) + ", viscous_damping_ns_per_m " +
                v(c.viscous_damping_ns_per_m) + ", rotational_drag_kg_per_m2 " + v(c.rotational_drag_kg_per_m2) + ")";
  }
  // The sentence ended at "outside any tyre's" (session 20), and said nothing of the load, which is as often the cause.
  throw ModelDomainError(what + " " + v(rrc) + " at " + v(load_n) + " N and " + v(units::pa_to_bar(tyre.pressure_pa)) +
                         " bar is beyond " + v(kMaxRrc) + " (no pneumatic tyre loses that much): the model extrapolates "
                         "here; its " + constants + " describe a tyre at its working loads, a few kN, and either the load " +
                         "is far below that or the constants are outside any tyre's range");
}

// The loaded-patch figures both models report.
RollingResistance patch_result(const Patch& p, double outer_radius_m) {
  RollingResistance out;
  out.stiffness_n_per_m = p.stiffness_n_per_m;
  out.deflection_m = p.deflection_m;
  out.loaded_radius_m = p.loaded_radius_m;
  out.half_angle_rad = p.half_angle_rad;
  out.contact_length_m = 2.0 * outer_radius_m * std::sin(p.half_angle_rad);
  return out;
}

RollingResistance evaluate_hysteresis(const TyreState& tyre, double load_n, double speed_mps) {
  const Patch p = loaded_patch(tyre, load_n);
  const SpeedPolynomial k = hysteresis_polynomial(tyre, load_n);
  const double r = tyre.geometry.outer_radius_m;
  RollingResistance out = patch_result(p, r);
  if (speed_mps > 0.0) {  // standstill: no rolling loss, as in the thesis model
    out.rrc_coulomb = k.k0;
    out.rrc_viscous = k.k1_s_per_m * speed_mps;
    out.rrc_rotational_drag = k.k2_s2_per_m2 * speed_mps * speed_mps;
  }
  out.rrc = out.rrc_coulomb + out.rrc_viscous + out.rrc_rotational_drag;
  check_rrc_level(std::max(out.rrc, k.k0), tyre, load_n, "RRC at " + v(units::mps_to_kmh(speed_mps)) + " km/h");
  out.offset_e_m = out.rrc * r;
  out.rr_force_n = out.rrc * load_n;
  out.rr_power_w = out.rr_force_n * speed_mps;
  return out;
}

}  // namespace

RollingResistance evaluate_rolling_resistance(const TyreState& tyre, double load_n, double speed_mps) {
  check_operating_point(tyre, load_n, speed_mps);
  if (tyre.model == TyreModelKind::Hysteresis) return evaluate_hysteresis(tyre, load_n, speed_mps);
  const Patch p = loaded_patch(tyre, load_n);
  const auto& c = tyre.constants;
  const double r = tyre.geometry.outer_radius_m;
  const int n = c.elements;
  const double cv = c.viscous_damping_ns_per_m / n;
  const double cc = c.coulomb_damping_n / n;
  const double w = speed_mps / r;

  // The element sum exactly as the spec writes it, keeping the three moment parts apart.
  double m_coulomb = 0.0, m_viscous = 0.0, f_sum = 0.0;
  for (int i = 0; i <= n; ++i) {
    const double theta = (2.0 * i / n - 1.0) * p.half_angle_rad;  // the centre exactly 0, as in lever_sums
    const double zdot = -w * r * std::sin(theta);
    const double sgn = (zdot > 0.0) - (zdot < 0.0);
    const double f_visc = -cv * zdot;
    const double f_coul = -cc * sgn;
    const double x = p.loaded_radius_m * std::tan(theta);
    m_viscous += f_visc * x;
    m_coulomb += f_coul * x;
    f_sum += f_visc + f_coul;
  }
  const double m_drag = speed_mps * speed_mps * (2.0 * std::numbers::pi * r * tyre.geometry.section_width_m) *
                        c.rotational_drag_kg_per_m2;
  const double f_total = f_sum + load_n;

  RollingResistance out = patch_result(p, r);
  out.offset_e_m = (m_coulomb + m_viscous + m_drag) / f_total;
  out.rrc = out.offset_e_m / r;
  out.rrc_coulomb = m_coulomb / f_total / r;
  out.rrc_viscous = m_viscous / f_total / r;
  out.rrc_rotational_drag = m_drag / f_total / r;
  out.rr_force_n = out.rrc * load_n;
  out.rr_power_w = out.rr_force_n * speed_mps;
  check_rrc_level(out.rrc, tyre, load_n, "RRC at " + v(units::mps_to_kmh(speed_mps)) + " km/h");
  return out;
}

TyreAtLoad TyreAtLoad::prepare(const TyreState& tyre, double load_n) {
  check_operating_point(tyre, load_n, 0.0);
  if (tyre.model == TyreModelKind::Hysteresis) {
    const SpeedPolynomial k = hysteresis_polynomial(tyre, load_n);
    check_rrc_level(k.k0, tyre, load_n, "RRC level (as the speed goes to 0)");
    TyreAtLoad t;
    t.k0_ = k.k0;
    t.k1_s_per_m_ = k.k1_s_per_m;
    t.k2_s2_per_m2_ = k.k2_s2_per_m2;
    t.load_n_ = load_n;
    return t;
  }
  const Patch p = loaded_patch(tyre, load_n);
  const auto& c = tyre.constants;
  const double r = tyre.geometry.outer_radius_m;
  const LeverSums s = lever_sums(p, c.elements);
  const double per_nr = 1.0 / (load_n * r);
  TyreAtLoad t;
  t.k0_ = c.coulomb_damping_n / c.elements * s.coulomb_m * per_nr;
  t.k1_s_per_m_ = c.viscous_damping_ns_per_m / c.elements * s.viscous_m * per_nr;
  t.k2_s2_per_m2_ = 2.0 * std::numbers::pi * r * tyre.geometry.section_width_m * c.rotational_drag_kg_per_m2 * per_nr;
  check_rrc_level(t.k0_, tyre, load_n, "RRC level (as the speed goes to 0)");
  t.load_n_ = load_n;
  return t;
}

}  // namespace rollsim
