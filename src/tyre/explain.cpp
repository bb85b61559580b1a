#include "rollsim/tyre/explain.hpp"

#include <cmath>
#include <cstdio>
#include <functional>

#include "rollsim/common/error.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/common/format.hpp"

namespace rollsim {
namespace {

constexpr double kNoEffect = 0.005;  // |elasticity| below this reads as "no effect" in the text

std::string f2(double x) {
  const std::string s = fixed(x, 2);
  return s[0] == '-' ? s : "+" + s;
}
std::string pct(double share) { return fixed(100.0 * share, 0) + " %"; }

// Central difference of ln(output) against ln(parameter): symmetric, so first-order errors cancel.
struct Responses {
  double rrc, power, deflection, contact;
};
Responses log_slopes(const std::function<RollingResistance(double)>& at_scale, double h) {
  const RollingResistance up = at_scale(1.0 + h);
  const RollingResistance dn = at_scale(1.0 - h);
  const double dlnx = std::log1p(h) - std::log1p(-h);
  auto e = [&](double a, double b) { return (std::log(a) - std::log(b)) / dlnx; };
  return {e(up.rrc, dn.rrc), e(up.rr_power_w, dn.rr_power_w), e(up.deflection_m, dn.deflection_m),
          e(up.contact_length_m, dn.contact_length_m)};
}

std::string diameter_text(const ParameterElasticity& p) {
  if (p.rrc_elasticity < -kNoEffect) {
    return "A larger tyre rolls easier: RRC = e/R, and the damping offset e grows with the patch length, which grows "
           "only like sqrt(R dz); Rhyne's stiffness also rises with sqrt(D), so the deflection changes by " +
           f2(p.deflection_elasticity) + " and the contact length by " + f2(p.contact_length_elasticity) +
           " per % of diameter, less than R itself. The rotational-drag part of RRC does not depend on R.";
  }
  if (p.rrc_elasticity > kNoEffect) {
    return "RRC rises with diameter here, against the usual trend: the patch lengthens (" +
           f2(p.contact_length_elasticity) + " per %) faster than R at this load and pressure.";
  }
  return "Diameter has almost no effect here: the patch lengthens about as fast as R grows.";
}

std::string width_text(const ParameterElasticity& p, double drag_share) {
  const std::string stiff = "a wider tyre is stiffer (Kz grows with sqrt(0.7 W D) in the pressure term), so it deflects "
                            "less (" + f2(p.deflection_elasticity) + " per %) and its patch is shorter (" +
                            f2(p.contact_length_elasticity) + " per %), shrinking the damping offset";
  const std::string drag = "the rotational-drag part (" + pct(drag_share) + " of RRC here) grows in proportion to width";
  std::string s;
  if (p.rrc_elasticity < -kNoEffect) {
    s = "Wider lowers RRC slightly: " + stiff + "; " + drag + " but is outweighed.";
  } else if (p.rrc_elasticity > kNoEffect) {
    s = "Wider raises RRC here: " + drag + " and outweighs the stiffness effect (" + stiff + ").";
  } else {
    s = "Width has almost no effect here: " + stiff + ", while " + drag + "; the two cancel.";
  }
  return s + " The model has no width dependence of the damping itself (a known gap), so the effect is weak.";
}

std::string pressure_text(const ParameterElasticity& p) {
  if (p.rrc_elasticity < -kNoEffect) {
    return "Higher pressure lowers RRC: the tyre is stiffer, deflects less (" + f2(p.deflection_elasticity) +
           " per %) and its contact patch is shorter (" + f2(p.contact_length_elasticity) +
           " per %), so the asymmetric damping forces act on shorter lever arms and the offset e falls. "
           "(Pressure is taken as independent of deflection and temperature.)";
  }
  return "Pressure has little effect here: the stiffness is dominated by Rhyne's pressure-independent offset term.";
}

std::string load_text(const ParameterElasticity& p) {
  std::string s;
  if (p.rrc_elasticity < -kNoEffect) {
    s = "In the model more load lowers RRC: the tyre deflects in proportion (" + f2(p.deflection_elasticity) +
        " per %) but the patch lengthens only like sqrt(dz) (" + f2(p.contact_length_elasticity) +
        " per %), so the damping moment grows less than the load it is divided by. ";
  } else {
    s = "In the model RRC does not fall with load here: ";
  }
  s += "Force and power still rise with load (power " + f2(p.power_elasticity) +
       " per %). Measurements disagree on RRC: the thesis' model gives -6.5 % for 80 -> 90 % of maximum load where "
       "measured RRC rises about +3 %; the lumped damping constants do not scale with load, and temperature and "
       "material behaviour are missing. Treat the model's load trend of RRC with caution.";
  return s;
}

std::string speed_text(const ParameterElasticity& p, const RollingResistance& r) {
  // V dRRC/dV = viscous + 2 drag (Coulomb is speed independent for V > 0): split the elasticity by source.
  const double visc = r.rrc_viscous / r.rrc;
  const double drag = 2.0 * r.rrc_rotational_drag / r.rrc;
  std::string s = "RRC rises with speed: the Coulomb part (" + pct(r.rrc_coulomb / r.rrc) +
                  " of RRC) does not depend on speed, the viscous damping part grows linearly (contributes " +
                  f2(visc) + " to the elasticity) and rotational aerodynamic drag with V^2 (contributes " +
                  f2(drag) + "). ";
  s += drag > visc ? "Most of the rise comes from rotational drag here."
                   : "Most of the rise comes from viscous damping here; rotational drag takes over at higher speed.";
  char buf[96];
  std::snprintf(buf, sizeof buf, " Power = F_RR V, so its elasticity is 1 + (%.3f) = %.3f.", p.rrc_elasticity,
                1.0 + p.rrc_elasticity);
  s += buf;
  return s;
}

}  // namespace

std::string elasticity_sign(double elasticity) {
  if (elasticity > kNoEffect) return "+";
  if (elasticity < -kNoEffect) return "-";
  return "0";
}

TyreExplanation explain_tyre(const TyreState& tyre, double load_n, double speed_mps, double relative_step) {
  if (!(speed_mps > 0.0)) {
    throw ModelDomainError("speed " + format_value(units::mps_to_kmh(speed_mps)) +
                           " km/h: explaining needs a speed > 0 (at standstill RRC is 0 and has no elasticity)");
  }
  TyreExplanation out;
  out.at_point = evaluate_rolling_resistance(tyre, load_n, speed_mps);
  out.load_n = load_n;
  out.speed_mps = speed_mps;
  const double h = relative_step;

  auto add = [&](TyreParameter which, const char* name, const char* key, double value,
                 const std::function<RollingResistance(double)>& at_scale) {
    ParameterElasticity p;
    p.parameter = which;
    p.name = name;
    p.key = key;
    p.value_si = value;
    Responses e;
    try {
      e = log_slopes(at_scale, h);
    } catch (const ModelDomainError& err) {
      // The point itself was evaluated above; a step of the difference left the domain. Said as such: the message
      // described the stepped tyre as if it were the user's (session 20).
      throw ModelDomainError("the elasticity to " + std::string(name) + " steps it by +-" + format_value(100.0 * h) +
                             " %, and the stepped point leaves the model's domain (the point itself is inside it; move " +
                             "it away from the edge): " + err.what());
    }
    p.rrc_elasticity = e.rrc;
    p.power_elasticity = e.power;
    p.deflection_elasticity = e.deflection;
    p.contact_length_elasticity = e.contact;
    out.parameters.push_back(p);
  };

  // Diameter is scaled with the rim kept: a bigger tyre on the same rim has a taller sidewall.
  add(TyreParameter::OuterDiameter, "outer diameter", "outer_diameter", 2.0 * tyre.geometry.outer_radius_m,
      [&](double s) {
        TyreGeometry g = tyre.geometry;
        g.outer_radius_m *= s;
        return evaluate_rolling_resistance(with_geometry(tyre, g), load_n, speed_mps);
      });
  add(TyreParameter::SectionWidth, "section width", "section_width", tyre.geometry.section_width_m, [&](double s) {
    TyreGeometry g = tyre.geometry;
    g.section_width_m *= s;
    return evaluate_rolling_resistance(with_geometry(tyre, g), load_n, speed_mps);
  });
  add(TyreParameter::Pressure, "inflation pressure", "pressure", tyre.pressure_pa, [&](double s) {
    TyreState t = tyre;
    t.pressure_pa *= s;
    return evaluate_rolling_resistance(t, load_n, speed_mps);
  });
  add(TyreParameter::Load, "normal load", "load", load_n,
      [&](double s) { return evaluate_rolling_resistance(tyre, load_n * s, speed_mps); });
  add(TyreParameter::Speed, "speed", "speed", speed_mps,
      [&](double s) { return evaluate_rolling_resistance(tyre, load_n, speed_mps * s); });

  const double drag_share = out.at_point.rrc_rotational_drag / out.at_point.rrc;
  for (auto& p : out.parameters) {
    switch (p.parameter) {
      case TyreParameter::OuterDiameter: p.mechanism = diameter_text(p); break;
      case TyreParameter::SectionWidth: p.mechanism = width_text(p, drag_share); break;
      case TyreParameter::Pressure: p.mechanism = pressure_text(p); break;
      case TyreParameter::Load: p.mechanism = load_text(p); break;
      case TyreParameter::Speed: p.mechanism = speed_text(p, out.at_point); break;
    }
  }
  return out;
}

}  // namespace rollsim
