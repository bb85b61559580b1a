// Explains the tyre model at one operating point: elasticities of RRC and RR power and the mechanism behind each.
#pragma once

#include <string>
#include <vector>

#include "rollsim/tyre/tyre_model.hpp"

namespace rollsim {

enum class TyreParameter { OuterDiameter, SectionWidth, Pressure, Load, Speed };

/// How the model's answer responds to one parameter: elasticities are % change of the output per % change of
/// the parameter (d ln y / d ln x), by central differences of the model itself.
struct ParameterElasticity {
  TyreParameter parameter = TyreParameter::OuterDiameter;
  std::string name;             ///< "outer diameter", ...
  std::string key;              ///< "outer_diameter", ... (for JSON keys)
  double value_si = 0.0;        ///< the parameter's value at the operating point (m, m, Pa, N, m/s)
  double rrc_elasticity = 0.0;
  double power_elasticity = 0.0;
  double deflection_elasticity = 0.0;
  double contact_length_elasticity = 0.0;
  std::string mechanism;        ///< why, in this model; chosen by the computed sign and magnitude
};

struct TyreExplanation {
  RollingResistance at_point;   ///< the model's result at the operating point
  double load_n = 0.0;
  double speed_mps = 0.0;
  std::vector<ParameterElasticity> parameters;  ///< diameter, width, pressure, load, speed, in that order
};

/// Elasticities at (tyre, load, speed). `relative_step` is the central-difference step (x (1 +- h)).
/// Needs speed > 0 (at standstill RRC is 0 and elasticities are undefined); throws ModelDomainError otherwise
/// or when a perturbed state has no solution.
TyreExplanation explain_tyre(const TyreState& tyre, double load_n, double speed_mps, double relative_step = 1e-3);

/// "-" / "+" / "0" for an elasticity (|e| < 0.005 counts as no effect).
std::string elasticity_sign(double elasticity);

}  // namespace rollsim
