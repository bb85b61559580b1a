#include "rollsim/tyre/hysteresis_model.hpp"

#include <cmath>
#include <numbers>
#include <string>

#include "rollsim/common/error.hpp"

namespace rollsim {

double hysteresis_reference_deflection_m(const TyreState& tyre) {
  const HysteresisConstants& c = tyre.hysteresis;
  if (c.reference_deflection_m > 0.0) return c.reference_deflection_m;
  TyreState at_ref = tyre;
  at_ref.pressure_pa = c.reference_pressure_pa;
  return c.reference_load_n / vertical_stiffness_n_per_m(at_ref);
}

SpeedPolynomial hysteresis_polynomial(const TyreState& tyre, double load_n) {
  const HysteresisConstants& c = tyre.hysteresis;
  const double deflection_m = load_n / vertical_stiffness_n_per_m(tyre);
  const double deflection_ref_m = hysteresis_reference_deflection_m(tyre);
  const double load_ratio = load_n / c.reference_load_n;
  const double hysteresis = c.rrc_ref * std::pow(deflection_m / deflection_ref_m, c.deflection_exponent) *
                            std::pow(load_ratio, c.load_exponent);
  // f = V / (2 pi R): one deformation cycle of each tread element per wheel turn.
  const double hz_per_mps = 1.0 / (2.0 * std::numbers::pi * tyre.geometry.outer_radius_m);
  SpeedPolynomial p;
  p.k0 = hysteresis;
  p.k1_s_per_m = hysteresis * c.frequency_slope_per_hz * hz_per_mps;
  p.k2_s2_per_m2 = c.speed_loss_rrc_per_hz2 * std::pow(load_ratio, c.speed_loss_load_exponent) * hz_per_mps * hz_per_mps;
  return p;
}

void check_hysteresis_constants(const HysteresisConstants& c) {
  auto fail = [](const std::string& name, double v, const std::string& allowed) {
    throw ModelDomainError("hysteresis constant " + name + " = " + format_value(v) + ": " + allowed);
  };
  if (!(c.reference_pressure_pa > 0.0) || !std::isfinite(c.reference_pressure_pa))
    fail("reference pressure [Pa]", c.reference_pressure_pa, "must be > 0");
  if (!(c.reference_load_n > 0.0) || !std::isfinite(c.reference_load_n))
    fail("reference load [N]", c.reference_load_n, "must be > 0");
  if (!(c.reference_deflection_m >= 0.0) || !std::isfinite(c.reference_deflection_m))
    fail("reference deflection [m]", c.reference_deflection_m, "must be >= 0 (0: the tyre's own)");
  if (!(c.rrc_ref > 0.0 && c.rrc_ref <= kMaxRrc)) fail("rrc_ref", c.rrc_ref, "must be in (0, 0.1]");
  // Loss grows with deflection (strain amplitude): a negative exponent would have RRC rise with pressure.
  if (!(c.deflection_exponent >= 0.0 && c.deflection_exponent <= 5.0))
    fail("deflection_exponent", c.deflection_exponent, "must be in [0, 5]");
  for (const auto& [name, v] : {std::pair{"load_exponent", c.load_exponent},
                                std::pair{"speed_loss_load_exponent", c.speed_loss_load_exponent}}) {
    if (!(std::abs(v) <= 5.0)) fail(name, v, "must be in [-5, 5]");
  }
  // RRC must stay positive at every speed: a falling loss modulus or a negative speed loss would let it
  // reach zero at some speed, which no tyre does.
  if (!(c.frequency_slope_per_hz >= 0.0 && c.frequency_slope_per_hz <= 1.0))
    fail("frequency_slope_per_hz", c.frequency_slope_per_hz, "must be in [0, 1]");
  if (!(c.speed_loss_rrc_per_hz2 >= 0.0 && c.speed_loss_rrc_per_hz2 <= 1e-3))
    fail("speed_loss_rrc_per_hz2", c.speed_loss_rrc_per_hz2, "must be in [0, 0.001]");
}

}  // namespace rollsim
