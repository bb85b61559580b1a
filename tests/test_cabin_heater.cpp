// Cabin conditioning (issue 10): aux_load's decay from the trip's start, the winter-heater truth, and the diagnosis
// naming a heater's decay with its profiled time constant while steady and duty-cycled loads get none.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "rollsim/common/error.hpp"
#include "rollsim/diagnose/diagnose.hpp"
#include "rollsim/discovery/generate.hpp"
#include "rollsim/discovery/truths.hpp"
#include "rollsim/effects/catalogue.hpp"
#include "rollsim/vehicle/vehicle_file.hpp"

namespace rollsim {
namespace {

Vehicle ev() { return load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml"); }

double aux_power_w(const std::shared_ptr<const Effect>& e, double t_s) {
  EffectInputs in;
  in.time_s = t_s;
  return e->extra_electric_power_w(in, nullptr);
}

TEST(CabinHeater, DecayingAuxLoadFallsFromPowerToItsSettledShare) {
  const Vehicle v = ev();
  const auto e = make_effect("aux_load", {{"power_w", 3000.0}, {"decay_s", 600.0}, {"decaying_share", 0.6}}, effect_context(v));
  EXPECT_NEAR(aux_power_w(e, 0.0), 3000.0, 1e-9);                                  // P0 + P1 at the start
  EXPECT_NEAR(aux_power_w(e, 600.0), 3000.0 * (0.4 + 0.6 * std::exp(-1.0)), 1e-9);  // one time constant in
  EXPECT_NEAR(aux_power_w(e, 36000.0), 1200.0, 1e-6);                              // P0 once settled
  // Without a decay (the default) it stays the constant load it was.
  const auto c = make_effect("aux_load", {{"power_w", 3000.0}}, effect_context(v));
  EXPECT_DOUBLE_EQ(aux_power_w(c, 0.0), aux_power_w(c, 5000.0));
  EXPECT_THROW(make_effect("aux_load", {{"power_w", 1000.0}, {"decaying_share", 1.5}}, effect_context(v)), InputError);
  EXPECT_THROW(make_effect("aux_load", {{"power_w", 1000.0}, {"decay_s", -60.0}}, effect_context(v)), InputError);
}

SyntheticCase heater_case(double max_w, unsigned seed) {
  SyntheticCase c;
  c.effects = {{"winter_heater", max_w}};
  c.seed = seed;
  return c;
}

TEST(CabinHeater, WinterHeaterTruthRunsAtItsMaximumThenSettlesOnItsHoldingPower) {
  // Independent of the catalogue: the truth's extra battery power over the same trip without it, noise-free.
  const Vehicle v = ev();
  SyntheticCase base = heater_case(3000.0, 21), with = heater_case(3000.0, 21);
  base.effects.clear();
  for (SyntheticCase* c : {&base, &with}) c->noise_w = 0.0, c->quantum_w = 0.0, c->lag_s = 0.0, c->scale_jitter = 0.0, c->rrc_level_jitter = 0.0;
  const auto p0 = *generate_case(v, base).battery_power_w, p1 = *generate_case(v, with).battery_power_w;
  std::mt19937 truth_rng(21u * 7919u + 13u);  // the generator's truth stream: the cabin it drew
  const WinterCabin cab = winter_cabin(3000.0, truth_rng);
  const double hold_w = cab.ua_w_per_k * cab.setpoint_excess_k;
  EXPECT_NEAR(p1[30] - p0[30], 3000.0 + cab.blower_w, 1.0);  // half a minute in: the air is cold, full power
  const double late = p1[p1.size() - 10] - p0[p0.size() - 10];  // an hour in: the interior is warm
  EXPECT_NEAR(late, hold_w + cab.blower_w, 0.1 * hold_w);
  EXPECT_GT(hold_w, 0.25 * 3000.0 - 1.0);
  EXPECT_LT(hold_w, 0.50 * 3000.0 + 1.0);
}

double fitted_or(const Finding& f, const std::string& key, double fallback) {
  const auto it = f.fitted.find(key);
  return it == f.fitted.end() ? fallback : it->second;
}

TEST(CabinHeater, WinterHeaterIsNamedAuxLoadDecayingWithItsInteriorTimeConstant) {
  // After the plateau the air is held at its set point, so the heater's excess over its holding power decays as the
  // interior warms, with time constant C_int / h: the profiled decay_s should find it (within its grid's spacing).
  const Vehicle v = ev();
  for (unsigned seed : {3u, 4u}) {
    const SyntheticCase c = real_logger(heater_case(2000.0, seed));
    const Diagnosis d = diagnose(v, {generate_case(v, c)});
    ASSERT_FALSE(d.findings.empty()) << seed;
    const Finding& f = d.findings.front();
    EXPECT_EQ(f.effect, "aux_load") << seed;
    std::mt19937 truth_rng(seed * 7919u + 13u);
    const WinterCabin cab = winter_cabin(2000.0, truth_rng);
    const double tau_s = cab.interior_j_per_k / cab.interior_w_per_k;
    const double decay_s = fitted_or(f, "decay_s", -1.0);
    ASSERT_GT(decay_s, 0.0) << seed << ": no decay found";
    EXPECT_GT(decay_s, tau_s / 2.0) << seed;
    EXPECT_LT(decay_s, tau_s * 2.0) << seed;
    bool profiled = false;
    for (const auto& p : f.parameters)
      if (p.name == "decay_s") profiled = p.profiled && p.ci_low <= decay_s && decay_s <= p.ci_high && p.ci_high > p.ci_low;
    EXPECT_TRUE(profiled) << seed;
    // The start's power: maximum plus blower, roughly (the exponential misses the plateau's flat top).
    EXPECT_NEAR(f.parameters.front().value, 2000.0 + cab.blower_w, 600.0) << seed;
  }
}

TEST(CabinHeater, DutyCycledCompressorIsNotGivenADecay) {
  // A compressor cycling all trip long is a load, but not one falling from the start: no decay_s.
  // (The row names 86-97 % of 100 seeds; the rest are missed, `unexplained`: counted here only where named.)
  const Vehicle v = ev();
  int named = 0;
  for (unsigned seed = 5; seed < 13; ++seed) {
    SyntheticCase c = real_logger(SyntheticCase{});
    c.effects = {{"ac_duty_cycle", 1000.0}};
    c.seed = seed;
    const Diagnosis d = diagnose(v, {generate_case(v, c)});
    ASSERT_FALSE(d.findings.empty()) << seed;
    if (d.findings.front().effect != "aux_load") continue;
    ++named;
    EXPECT_LT(fitted_or(d.findings.front(), "decay_s", -1.0), 0.0) << seed;
  }
  EXPECT_GE(named, 5);
}

}  // namespace
}  // namespace rollsim
