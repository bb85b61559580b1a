// Elasticities of the tyre model: signs, analytic limits, and consistency with the thesis' published changes.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "rollsim/common/error.hpp"
#include "rollsim/tyre/explain.hpp"
#include "rollsim/tyre/tyre_model.hpp"

using namespace rollsim;

namespace {

// 175/70 R14 at 2.1 bar (the thesis' example), without relying on the tyre-file code.
TyreState example_tyre() {
  TyreState t;
  t.geometry.outer_radius_m = 0.0254 * 7 + 0.175 * 0.70;
  t.geometry.section_width_m = 0.175;
  t.geometry.rim_radius_m = 0.0254 * 7;
  t.pressure_pa = 2.1e5;
  return t;
}
constexpr double kLoadN = 0.8 * 500 * 9.81;
constexpr double kSpeedMps = 80 / 3.6;

const ParameterElasticity& find(const TyreExplanation& x, TyreParameter p) {
  for (const auto& e : x.parameters)
    if (e.parameter == p) return e;
  throw std::logic_error("parameter missing");
}

}  // namespace

TEST(Explain, SignsAtTheThesisOperatingPoint) {
  const auto x = explain_tyre(example_tyre(), kLoadN, kSpeedMps);
  ASSERT_EQ(x.parameters.size(), 5u);
  EXPECT_LT(find(x, TyreParameter::OuterDiameter).rrc_elasticity, 0.0);
  EXPECT_LT(find(x, TyreParameter::Pressure).rrc_elasticity, 0.0);
  EXPECT_GT(find(x, TyreParameter::Speed).rrc_elasticity, 0.0);
  EXPECT_LT(find(x, TyreParameter::Load).rrc_elasticity, 0.0);   // the model's (wrong) load trend
  EXPECT_GT(find(x, TyreParameter::Load).power_elasticity, 0.0);  // but the force still rises with load
  EXPECT_EQ(elasticity_sign(find(x, TyreParameter::OuterDiameter).rrc_elasticity), "-");
  EXPECT_EQ(elasticity_sign(find(x, TyreParameter::Speed).rrc_elasticity), "+");
  for (const auto& p : x.parameters) EXPECT_FALSE(p.mechanism.empty()) << p.name;
}

// Published finite changes (docs/tyre-model.md) turned into mean elasticities, ln(1 + change) / ln(x1 / x0):
// diameter 60 -> 65 cm -4.84 % -> -0.62; pressure 2.1 -> 1.8 bar +5.6 % -> -0.35 and 2.1 -> 2.9 -11.3 % -> -0.37;
// load 80 -> 90 % -6.5 % -> -0.57. The local elasticity at the base point lies near these.
TEST(Explain, ElasticitiesAgreeWithThePublishedFiniteChanges) {
  const auto x = explain_tyre(example_tyre(), kLoadN, kSpeedMps);
  EXPECT_NEAR(find(x, TyreParameter::OuterDiameter).rrc_elasticity, std::log(1 - 0.0484) / std::log(65.0 / 60), 0.05);
  EXPECT_NEAR(find(x, TyreParameter::Pressure).rrc_elasticity, std::log(1 + 0.056) / std::log(1.8 / 2.1), 0.03);
  EXPECT_NEAR(find(x, TyreParameter::Pressure).rrc_elasticity, std::log(1 - 0.113) / std::log(2.9 / 2.1), 0.03);
  EXPECT_NEAR(find(x, TyreParameter::Load).rrc_elasticity, std::log(1 - 0.065) / std::log(0.9 / 0.8), 0.03);
}

// P = RRC N V: for speed and load the power elasticity is exactly 1 + the RRC elasticity; for geometry and
// pressure (N and V fixed) they are equal. Both are computed separately by central differences.
TEST(Explain, PowerElasticityIsOnePlusRrcElasticityForSpeedAndLoad) {
  for (const double v_kmh : {20.0, 80.0, 150.0}) {
    const auto x = explain_tyre(example_tyre(), kLoadN, v_kmh / 3.6);
    for (const auto& p : x.parameters) {
      const bool scales_power = p.parameter == TyreParameter::Speed || p.parameter == TyreParameter::Load;
      EXPECT_NEAR(p.power_elasticity, (scales_power ? 1.0 : 0.0) + p.rrc_elasticity, 1e-6) << p.name << " " << v_kmh;
    }
  }
}

// With only one damping/drag mechanism switched on, RRC's speed dependence is a pure power law of V:
// Coulomb V^0, viscous V^1, rotational drag V^2. And the drag part of RRC, V^2 2 pi R W Cd / (N R), is
// proportional to W and independent of R.
TEST(Explain, SpeedElasticityMatchesEachMechanismsPowerLaw) {
  auto only = [](double cc, double cv, double cd) {
    TyreState t = example_tyre();
    t.constants.coulomb_damping_n = cc;
    t.constants.viscous_damping_ns_per_m = cv;
    t.constants.rotational_drag_kg_per_m2 = cd;
    return explain_tyre(t, kLoadN, kSpeedMps);
  };
  EXPECT_NEAR(find(only(180, 0, 0), TyreParameter::Speed).rrc_elasticity, 0.0, 1e-6);
  EXPECT_EQ(elasticity_sign(find(only(180, 0, 0), TyreParameter::Speed).rrc_elasticity), "0");
  EXPECT_NEAR(find(only(0, 0.5, 0), TyreParameter::Speed).rrc_elasticity, 1.0, 1e-6);
  const auto drag = only(0, 0, 1.0 / 280);
  EXPECT_NEAR(find(drag, TyreParameter::Speed).rrc_elasticity, 2.0, 1e-6);
  EXPECT_NEAR(find(drag, TyreParameter::SectionWidth).rrc_elasticity, 1.0, 1e-6);
  EXPECT_NEAR(find(drag, TyreParameter::OuterDiameter).rrc_elasticity, 0.0, 1e-6);
  EXPECT_NEAR(find(drag, TyreParameter::Load).rrc_elasticity, -1.0, 1e-6);
}

TEST(Explain, MechanismTextFollowsTheComputedSign) {
  // At high speed on a wide tyre the drag part (proportional to W) can outweigh the stiffness effect of width.
  TyreState t = example_tyre();
  t.constants.rotational_drag_kg_per_m2 = 0.05;
  const auto x = explain_tyre(t, kLoadN, 200 / 3.6);
  const auto& w = find(x, TyreParameter::SectionWidth);
  ASSERT_GT(w.rrc_elasticity, 0.0);
  EXPECT_NE(w.mechanism.find("raises"), std::string::npos) << w.mechanism;
  const auto base = explain_tyre(example_tyre(), kLoadN, kSpeedMps);
  EXPECT_NE(find(base, TyreParameter::SectionWidth).mechanism.find("lowers"), std::string::npos);
  // The load mechanism always states where the model disagrees with measurements.
  EXPECT_NE(find(base, TyreParameter::Load).mechanism.find("+3 %"), std::string::npos);
}

TEST(Explain, NeedsARollingTyreInsideTheDomain) {
  EXPECT_THROW(explain_tyre(example_tyre(), kLoadN, 0.0), ModelDomainError);
  EXPECT_THROW(explain_tyre(example_tyre(), 1e6, kSpeedMps), ModelDomainError);
}
