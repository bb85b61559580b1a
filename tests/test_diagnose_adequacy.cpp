// The diagnosis against the recording's own noise floor, within physical priors and signs: recordings whose truths
// are written here (simulator hooks driven by this file's own models, not the catalogue's modules).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>

#include "rollsim/common/error.hpp"
#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/diagnose/diagnose.hpp"
#include "rollsim/sim/simulation.hpp"

namespace rollsim {
namespace {

Vehicle ev() { return load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml"); }

constexpr double kG = 9.80665, kTwoPi = 6.283185307179586;

// Rolling hills along distance: h(s) = 25 sin(2 pi s / 2.4 km) + 10 sin(2 pi s / 0.9 km + 1), grade dh/ds.
class Hills final : public Effect {
 public:
  explicit Hills(double mass_kg) : m_(mass_kg) {}
  std::string id() const override { return "test_hills"; }
  double extra_resistance_n(const EffectInputs& in, const double*) const override {
    if (in.speed_mps <= 0.0) return 0.0;
    const double s = in.distance_m;
    const double g = 25.0 * kTwoPi / 2400.0 * std::cos(kTwoPi * s / 2400.0) + 10.0 * kTwoPi / 900.0 * std::cos(kTwoPi * s / 900.0 + 1.0);
    return m_ * kG * g / std::sqrt(1.0 + g * g);
  }

 private:
  double m_;
};

// A compressor cycling every `period_s`, on for `on_s` of it at `on_w`, standing or driving (default: every 4
// minutes, on half of the time at 3 kW, 1.5 kW mean).
class Compressor final : public Effect {
 public:
  explicit Compressor(double on_w = 3000.0, double on_s = 120.0, double period_s = 240.0)
      : on_w_(on_w), on_s_(on_s), period_s_(period_s) {}
  std::string id() const override { return "test_compressor"; }
  double extra_electric_power_w(const EffectInputs& in, const double*) const override {
    return std::fmod(in.time_s, period_s_) < on_s_ ? on_w_ : 0.0;
  }

 private:
  double on_w_, on_s_, period_s_;
};

// RRC rising linearly over the trip to +40 % at its end (a tyre losing pressure): the opposite of a warm-up.
class RisingRrc final : public Effect {
 public:
  explicit RisingRrc(double duration_s) : d_(duration_s) {}
  std::string id() const override { return "test_rising_rrc"; }
  double rolling_resistance_factor(const EffectInputs& in, const double*) const override { return 1.0 + 0.4 * in.time_s / d_; }

 private:
  double d_;
};

// WLTC twice at 10 Hz; the truth replayed there; the recording at `hz`, its power the truth's `lag_s` earlier (the
// 10 Hz trace read at a shifted sample: no interpolation shared with the diagnosis), times `scale`, plus white noise.
// `instantaneous`: a logger that reads the power at the sample's instant instead of integrating over its interval.
// `smooth`: the truth's speed a Catmull-Rom cubic through the cycle's points (a car's speed has no corners; the
// logged samples are the same), so its acceleration is continuous, not held per second.
Recording recording(const Vehicle& v, std::shared_ptr<const Effect> truth, double hz, double lag_s, double scale, unsigned seed,
                    bool instantaneous = false, bool smooth = false, const std::string& cycle = "wltc", int repeats = 2) {
  const DriveCycle one = load_cycle(cycle);
  DriveCycle c;
  c.name = cycle + " x" + std::to_string(repeats) + " at 10 Hz";
  const double period = one.time_s.back() - one.time_s.front() + 1.0;
  const std::size_t n = one.time_s.size();
  for (int rep = 0; rep < repeats; ++rep)
    for (std::size_t i = 0; i + 1 < n; ++i)
      for (int k = 0; k < 10; ++k) {
        const double f = k / 10.0;
        c.time_s.push_back(rep * period + one.time_s[i] + f * (one.time_s[i + 1] - one.time_s[i]));
        const double v0 = one.speed_mps[i > 0 ? i - 1 : i], v1 = one.speed_mps[i], v2 = one.speed_mps[i + 1],
                     v3 = one.speed_mps[i + 2 < n ? i + 2 : i + 1];
        const double cubic = 0.5 * (2.0 * v1 + (v2 - v0) * f + (2.0 * v0 - 5.0 * v1 + 4.0 * v2 - v3) * f * f +
                                    (3.0 * v1 - v0 - 3.0 * v2 + v3) * f * f * f);
        c.speed_mps.push_back(smooth ? std::max(0.0, cubic) : (1.0 - f) * v1 + f * v2);
        c.grade.push_back(0.0);
      }
  VehicleModel m = VehicleModel::assemble(v);
  if (truth) m.effects.push_back(truth);
  SimulationOptions so;
  so.record_trace = true;
  const SimulationResult r = simulate_replay(m, c, so);
  Recording rec;
  rec.source = "test recording";
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 300.0);
  std::vector<double> p;
  const auto step = static_cast<std::size_t>(std::lround(10.0 / hz));
  const auto shift = static_cast<std::size_t>(std::lround(lag_s * 10.0));
  // An integrating logger: each sample holds the mean power over its interval (the truth's 0.1 s segments).
  for (std::size_t i = shift; i + step < r.trace.size(); i += step) {
    rec.time_s.push_back(c.time_s[i]);
    rec.speed_mps.push_back(c.speed_mps[i]);
    double mean_w = 0.0;
    for (std::size_t k = 0; k < step; ++k) mean_w += r.trace[i - shift + k].segment_battery_power_w / static_cast<double>(step);
    p.push_back(scale * (instantaneous ? r.trace[i - shift].battery_power_w : mean_w) + noise(rng));
  }
  rec.battery_power_w = p;
  return rec;
}

Diagnosis run(const Vehicle& v, const Recording& r, double window_s) {
  DiagnoseOptions o;
  o.window_s = window_s;
  return diagnose(v, {r}, o);
}

bool named(const Diagnosis& d, const std::string& effect) {
  return std::any_of(d.findings.begin(), d.findings.end(), [&](const Finding& f) { return f.effect == effect; });
}

TEST(DiagnoseAdequacy, NullIsNothingMissingAt10And30And60sWindows) {
  const Vehicle v = ev();
  const Recording r = recording(v, nullptr, 1.0, 0.0, 1.0, 3);
  for (double w : {10.0, 30.0, 60.0}) {
    const Diagnosis d = run(v, r, w);
    EXPECT_EQ(d.verdict, "nothing_missing") << w << " s\n" << diagnosis_text(d);
    EXPECT_LT(d.residual_to_noise_ratio, 2.0) << w;  // noise alone sits at its floor
  }
}

TEST(DiagnoseAdequacy, WithheldRollingHillsAreMissingPhysicsAt10And30And60sWindows) {
  const Vehicle v = ev();
  const Recording r = recording(v, std::make_shared<Hills>(v.body.test_mass_kg), 1.0, 0.0, 1.0, 4);
  for (double w : {10.0, 30.0, 60.0}) {
    const Diagnosis d = run(v, r, w);
    EXPECT_NE(d.verdict, "nothing_missing") << w << " s\n" << diagnosis_text(d);
    EXPECT_GT(d.residual_to_noise_ratio, 2.0) << w;
    EXPECT_FALSE(d.findings.empty());
  }
}

// The same hills with a constant electrical load drawn beside them, standing or driving.
class HillsAndLoad final : public Effect {
 public:
  HillsAndLoad(double mass_kg, double load_w) : hills_(mass_kg), load_w_(load_w) {}
  std::string id() const override { return "test_hills_and_load"; }
  double extra_resistance_n(const EffectInputs& in, const double* s) const override { return hills_.extra_resistance_n(in, s); }
  double extra_electric_power_w(const EffectInputs&, const double*) const override { return load_w_; }

 private:
  Hills hills_;
  double load_w_;
};

TEST(DiagnoseAdequacy, DetectionLimitsBehindWithheldHillsAreTheirProfilesResiduals) {
  // The detection limits were taken before the road profile, from the hills' own residual: on session 27's outside
  // tester's SUV behind 25 m hills, aux_load 6.5-10 kW and wind 167-262 m/s. Here (this file's hills and a 400 W
  // load) aux_load read 5662 W before, now 357 W. Searching
  // the catalogue again behind the profile was tried and dropped: it named rr_speed 0.17 here, which is not in the
  // truth.
  const Vehicle v = ev();
  const Diagnosis d = run(v, recording(v, std::make_shared<HillsAndLoad>(v.body.test_mass_kg, 400.0), 1.0, 0.0, 1.0, 4), 60.0);
  ASSERT_FALSE(d.findings.empty()) << diagnosis_text(d);
  EXPECT_EQ(d.findings.front().effect, "road_profile") << diagnosis_text(d);
  EXPECT_FALSE(named(d, "rr_speed")) << diagnosis_text(d);
  bool aux_limit = false;
  for (const auto& l : d.detection_limits)
    if (l.effect == "aux_load") {
      aux_limit = true;
      EXPECT_LT(l.smallest_detectable, 1000.0) << diagnosis_text(d);
    }
  EXPECT_TRUE(aux_limit) << diagnosis_text(d);
}

// The recording's elevation column: `hills` (the Hills truth's profile, else a level road at 150 m) along the
// recording's own distance, plus white GPS noise of `sd_m` per reading (this file's generator, not rollsim's).
void record_elevation(Recording& r, bool hills, double sd_m, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sd_m);
  std::vector<double> h;
  double s = 0.0;
  for (std::size_t i = 0; i < r.time_s.size(); ++i) {
    if (i > 0) s += 0.5 * (r.speed_mps[i] + r.speed_mps[i - 1]) * (r.time_s[i] - r.time_s[i - 1]);
    const double road = hills ? 25.0 * std::sin(kTwoPi * s / 2400.0) + 10.0 * std::sin(kTwoPi * s / 900.0 + 1.0) : 0.0;
    h.push_back(150.0 + road + noise(rng));
  }
  r.elevation_m = h;
}

TEST(DiagnoseAdequacy, NoiseInARecordedElevationIsNotReadAsPhysics) {
  // 1.5 m of white GPS noise per reading on a level road is 0.8 % of grade rms after the 300 m filter, correlated
  // over 300 m: about 2 kW at 30 km/h, far above the short windows' floor. Read as physics it was an unexplained
  // finding in the uphill and downhill regimes on 4 of 4 such nulls (session 25's outside testing); the grade's
  // errors now count in the floor the residual is judged against.
  const Vehicle v = ev();
  for (unsigned seed : {21u, 22u, 23u}) {
    Recording r = recording(v, nullptr, 1.0, 0.0, 1.0, seed);
    record_elevation(r, false, 1.5, 100 + seed);
    const Diagnosis d = run(v, r, 60.0);
    EXPECT_EQ(d.verdict, "nothing_missing") << seed << "\n" << diagnosis_text(d);
    const std::string text = diagnosis_text(d);
    EXPECT_NE(text.find("carried into the noise floor"), std::string::npos) << text;
  }
  // Recorded without noise, the hills are known physics. Each sample's grade was read at the sample and held over
  // its segment, half a segment behind the road; this null read 7.1 x its floor, missing_physics (session 26).
  Recording exact = recording(v, std::make_shared<Hills>(v.body.test_mass_kg), 1.0, 0.0, 1.0, 27);
  record_elevation(exact, true, 1e-9, 127);
  const Diagnosis e = run(v, exact, 60.0);
  EXPECT_EQ(e.verdict, "nothing_missing") << diagnosis_text(e);
  // The same hills recorded through the same noise are known physics, not missing (this one read 2.5 x the floor,
  // missing_physics, before; the level nulls above passed then too, their logger's 300 W noise being the larger).
  Recording hilly = recording(v, std::make_shared<Hills>(v.body.test_mass_kg), 1.0, 0.0, 1.0, 24);
  record_elevation(hilly, true, 1.5, 124);
  const Diagnosis d = run(v, hilly, 60.0);
  EXPECT_EQ(d.verdict, "nothing_missing") << diagnosis_text(d);
}

TEST(DiagnoseAdequacy, WhatIsMissingIsStillFoundBehindANoisyElevation) {
  // The floor the grade's noise adds is what that noise can do, not a licence: hills withheld from a noisy level
  // elevation are still missing physics, and a compressor's load is still named.
  const Vehicle v = ev();
  Recording hills = recording(v, std::make_shared<Hills>(v.body.test_mass_kg), 1.0, 0.0, 1.0, 25);
  record_elevation(hills, false, 1.5, 125);
  const Diagnosis h = run(v, hills, 60.0);
  EXPECT_NE(h.verdict, "nothing_missing") << diagnosis_text(h);
  // The catalogue cannot name a recorded elevation's own errors; the finding points at them.
  EXPECT_NE(diagnosis_text(h).find("the grade comes from the recorded elevation"), std::string::npos) << diagnosis_text(h);
  Recording aux = recording(v, std::make_shared<Compressor>(), 1.0, 0.0, 1.0, 26);
  record_elevation(aux, false, 1.5, 126);
  const Diagnosis a = run(v, aux, 60.0);
  ASSERT_FALSE(a.findings.empty()) << diagnosis_text(a);
  EXPECT_EQ(a.findings.front().effect, "aux_load") << diagnosis_text(a);
}

// A payload: its inertia and its rolling resistance at a fixed RRC of 0.008 (this file's model, not the catalogue's).
class Payload final : public Effect {
 public:
  explicit Payload(double kg) : kg_(kg) {}
  std::string id() const override { return "test_payload"; }
  double extra_resistance_n(const EffectInputs& in, const double*) const override {
    return kg_ * (in.accel_mps2 + (in.speed_mps > 0.0 ? kG * 0.008 : 0.0));
  }

 private:
  double kg_;
};

TEST(DiagnoseAdequacy, AMassFoundBesideAPinnedScaleHasAnIntervalThatLetsTheScaleMove) {
  // 250 kg more, logged 4.8 % high: the data hold the scale at its +5 % bound beside the finding. The fit's
  // covariance held that scale fixed, and its symmetric interval had missed the truth on session 25's outside
  // tester's recording (214 [197, 231] kg for 250; now [196, 270]). The interval is now the mass's profile with the
  // scale refitted within its box: a scale that can only fall lets the mass only rise, so it widens upward alone
  // (this one read [237.5, 250.1] before, now [237.4, 282.1]).
  const Vehicle v = ev();
  const Diagnosis d = run(v, recording(v, std::make_shared<Payload>(250.0), 1.0, 0.0, 1.048, 41), 60.0);
  ASSERT_FALSE(d.findings.empty()) << diagnosis_text(d);
  const Finding& f = d.findings.front();
  ASSERT_EQ(f.effect, "mass") << diagnosis_text(d);
  EXPECT_NEAR(d.channel_scale_with_findings, 1.05, 1e-9) << diagnosis_text(d);
  const ParameterEstimate& mass = f.parameters.front();
  EXPECT_LE(mass.ci_low, 250.0) << diagnosis_text(d);
  EXPECT_GE(mass.ci_high, 250.0) << diagnosis_text(d);
  EXPECT_GT(mass.ci_high - mass.value, 3.0 * (mass.value - mass.ci_low)) << diagnosis_text(d);
}

TEST(DiagnoseAdequacy, AFindingAScaleBeyondItsBoxWouldCarryIsConfoundedWithTheScale) {
  // Logged 8 % high with nothing else wrong, against a +5 % box: what the box leaves is sometimes named (session
  // 28's outside tester: a 40-80 kg mass on 6 of its nulls at scales 1.06-1.08, nothing saying the scale would do).
  // Each named effect now carries the channel scale as its alternative, with the scale that would carry it.
  const Vehicle v = ev();
  int named = 0;
  for (unsigned seed = 1; seed <= 3; ++seed) {
    const Diagnosis d = run(v, recording(v, nullptr, 1.0, 0.0, 1.08, seed), 60.0);
    // The scale's own share is said where the RRC level and C took it (the total read "absorbed -0.0 %").
    EXPECT_NE(diagnosis_text(d).find("its scale alone"), std::string::npos) << diagnosis_text(d);
    for (const Finding& f : d.findings) {
      if (f.effect == "unexplained") continue;
      ++named;
      EXPECT_NE(std::find(f.confounded_with.begin(), f.confounded_with.end(), "channel_scale"), f.confounded_with.end())
          << diagnosis_text(d);
      EXPECT_EQ(d.verdict, "confounded") << diagnosis_text(d);
    }
  }
  EXPECT_GE(named, 1) << "no seed named an effect: the test shows nothing";
  // A payload whose shape a scale cannot take keeps its own name, beside a pinned scale.
  const Diagnosis d = run(v, recording(v, std::make_shared<Payload>(250.0), 1.0, 0.0, 1.048, 41), 60.0);
  ASSERT_FALSE(d.findings.empty()) << diagnosis_text(d);
  const auto& with = d.findings.front().confounded_with;
  EXPECT_EQ(std::find(with.begin(), with.end(), "channel_scale"), with.end()) << diagnosis_text(d);
}

// Tyres rolling 14 % harder all trip (under-inflated): a constant RRC factor.
class HarderRolling final : public Effect {
 public:
  std::string id() const override { return "test_harder_rolling"; }
  double rolling_resistance_factor(const EffectInputs&, const double*) const override { return 1.14; }
};

TEST(DiagnoseAdequacy, AShapeWithTheImpossibleSignThatAScaleBeyondItsBoxWouldCarryIsConfoundedWithTheScale) {
  // Logged 7 % low against a -5 % box, the tyres rolling 14 % harder (session 28's outside tester, own EV: a mass
  // shape with the impossible sign, -218 kg, named `unexplained` while the scale swung from 0.95 to 1.05 beside it,
  // with nothing saying the scale the data wanted, 0.933, would do as well).
  const Vehicle v = ev();
  int wrong_sign = 0;
  for (unsigned seed = 1; seed <= 4; ++seed) {
    const Diagnosis d = run(v, recording(v, std::make_shared<HarderRolling>(), 1.0, 0.0, 0.927, seed, false, false, "us06", 3), 60.0);
    for (const Finding& f : d.findings) {
      if (!f.wrong_sign) continue;
      ++wrong_sign;
      EXPECT_NE(std::find(f.confounded_with.begin(), f.confounded_with.end(), "channel_scale"), f.confounded_with.end())
          << diagnosis_text(d);
    }
  }
  EXPECT_GE(wrong_sign, 1) << "no seed fitted a shape with the impossible sign: the test shows nothing";
}

// A drag area larger than the file's by `share` (written here: 0.5 rho CdA v^2 at 1.2 kg/m^3 and the ev file's CdA, 0.31 x 2.30 m^2).
class LargerDragArea final : public Effect {
 public:
  explicit LargerDragArea(double share) : share_(share) {}
  std::string id() const override { return "test_larger_cda"; }
  double extra_resistance_n(const EffectInputs& in, const double*) const override {
    return share_ * 0.5 * 1.2 * 0.31 * 2.30 * in.speed_mps * in.speed_mps;
  }

 private:
  double share_;
};

TEST(DiagnoseAdequacy, ASpeedSquaredFindingBesideAnAeroCBeyondItsBoxIsConfoundedWithTheDrag) {
  // A CdA 50 % above the file's is beyond the aero C's +-20 % box; what the box leaves has the v^2 shape of an RRC
  // rising with speed, and was named rr_speed alone (session 28's outside tester: 20 of 20 at +20 % of energy).
  // Only the prior tells them apart, so a v^2 finding says that the drag is its other reading.
  const Vehicle v = ev();
  int named = 0;
  for (unsigned seed = 1; seed <= 2; ++seed) {
    const Diagnosis d = run(v, recording(v, std::make_shared<LargerDragArea>(0.5), 1.0, 0.0, 1.0, seed), 60.0);
    for (const Finding& f : d.findings) {
      if (f.effect != "rr_speed" && f.effect != "wind") continue;
      ++named;
      EXPECT_NE(std::find(f.confounded_with.begin(), f.confounded_with.end(), "drag"), f.confounded_with.end())
          << diagnosis_text(d);
    }
  }
  EXPECT_GE(named, 1) << "no seed named a speed-squared effect: the test shows nothing";
}

TEST(DiagnoseAdequacy, DutyCycledCompressorIsAnAuxLoadNotAScale) {
  // 1.5 kW mean on a battery-power channel: the scale may not take it (a few per cent), the standing residual
  // names it, and its fitted size is the compressor's mean.
  const Vehicle v = ev();
  const Diagnosis d = run(v, recording(v, std::make_shared<Compressor>(), 1.0, 0.0, 1.0, 5), 60.0);
  ASSERT_FALSE(d.findings.empty()) << diagnosis_text(d);
  EXPECT_EQ(d.findings.front().effect, "aux_load") << diagnosis_text(d);
  EXPECT_NEAR(d.findings.front().parameters.front().value, 1500.0, 300.0) << diagnosis_text(d);
  EXPECT_LE(d.channel_scale, 1.05 + 1e-9);
  // The calibration beside the finding is the truth's (scale 1, RRC and C unchanged), and nothing says that no
  // catalogue effect explains what the finding explains (session 24's outside testing: said beside aux_load 302 W).
  EXPECT_NEAR(d.channel_scale_with_findings, 1.0, 0.02) << diagnosis_text(d);
  EXPECT_NEAR(d.rrc_level_change_with_findings, 0.0, 0.05) << diagnosis_text(d);
  const std::string text = diagnosis_text(d);
  EXPECT_EQ(text.find("No catalogue effect alone explains"), std::string::npos) << text;
  EXPECT_NE(text.find("; beside them: channel scale"), std::string::npos) << text;
}

TEST(DiagnoseAdequacy, ALargeSwitchingLoadIsNamedByItsStandstillsSwitching) {
  // 2 kW on for 2 minutes in 5 (800 W mean). Its own on-and-off swing is the residual's variance, which the fit's
  // test of a constant load is judged against, and the standing residual's mean is uncertain by as much (standstills
  // catch it on or off): on session 27's outside tester's heavy SUV it was named in 1 of 6 recordings, the rest
  // 'unexplained' with mass suggested, where a 500 W one was named 2 of 2. What tells it is that the standing
  // residual switches: standstill means at about 0 or 2 kW, far beyond the noise within each standstill.
  const Vehicle v = ev();
  for (unsigned seed : {5u, 6u}) {
    const Diagnosis d = run(v, recording(v, std::make_shared<Compressor>(2000.0, 120.0, 300.0), 1.0, 0.0, 1.0, seed), 60.0);
    ASSERT_TRUE(named(d, "aux_load")) << diagnosis_text(d);
    const ParameterEstimate& p = d.findings.front().parameters.front();
    EXPECT_LE(p.ci_low, 800.0) << diagnosis_text(d);
    EXPECT_GE(p.ci_high, 800.0) << diagnosis_text(d);
    // Its swing is left, above the floor; beside the fitted mean it nets out, and is said to (it read "net -0 kJ").
    ASSERT_TRUE(named(d, "unexplained")) << diagnosis_text(d);
    for (const auto& f : d.findings)
      if (f.effect == "unexplained") EXPECT_NE(f.description.find("that nets out"), std::string::npos) << diagnosis_text(d);
  }
}

// A day's air density, off the reference by `delta` (the barometer moves it 1-3 % and is not recorded): the aero
// force times 1 + delta.
class AirDensity final : public Effect {
 public:
  AirDensity(double rho_cda_kg_per_m, double delta) : k_(0.5 * rho_cda_kg_per_m * delta) {}
  std::string id() const override { return "test_air_density"; }
  double extra_resistance_n(const EffectInputs& in, const double*) const override { return k_ * in.speed_mps * in.speed_mps; }

 private:
  double k_;
};

TEST(DiagnoseAdequacy, TripsOnDaysOfDifferentAirAreNotAnUnexplainedShape) {
  // Trips of one car over different cycles on days whose air density differs by 1-1.5 %, pooled: each trip's own aero level is weather,
  // not physics the model lacks. Session 27's outside tester's pooled nulls read "a force proportional to speed
  // squared decaying from the start of the trip" on 5 of 30 sets, beside a residual at 0.8-1.0 x the floor.
  const Vehicle v = ev();
  const double rho_cda = v.body.air_density_kg_per_m3 * v.body.drag_coefficient * v.body.frontal_area_m2;
  const char* cycle[] = {"hwfet", "udds", "hwfet", "wltc", "udds", "hwfet"};
  int false_findings = 0;
  for (unsigned set = 0; set < 8; ++set) {
    std::mt19937 rng(700 + set);
    std::uniform_real_distribution<double> day(-0.015, 0.015);
    std::vector<Recording> trips;
    for (unsigned k = 0; k < 6; ++k) {
      trips.push_back(recording(v, std::make_shared<AirDensity>(rho_cda, day(rng)), 1.0, 0.0, 1.0, 60 + 10 * set + k, false,
                                false, cycle[(k + set) % 6], 1 + static_cast<int>((k + set) % 2)));
      trips.back().source = "trip " + std::to_string(k);
    }
    const Diagnosis d = diagnose(v, trips, DiagnoseOptions{});
    if (named(d, "unexplained")) ++false_findings, ADD_FAILURE() << "set " << set << "\n" << diagnosis_text(d);
  }
  EXPECT_EQ(false_findings, 0);
}

TEST(DiagnoseAdequacy, AResidualHeldByOneTripNamesIt) {
  // One trip of five with a 300 W load of its own (a fleet's odd one out): pooled, the residual was "unexplained ...
  // most in regime 'braking'" and named no trip (session 27's outside tester). It now names the trip that holds it.
  const Vehicle v = ev();
  std::vector<Recording> trips;
  const char* cycle[] = {"udds", "hwfet", "wltc", "udds", "hwfet"};
  for (unsigned k = 0; k < 5; ++k) {
    trips.push_back(recording(v, k == 2 ? std::make_shared<Compressor>(300.0, 1.0, 1.0) : nullptr, 1.0, 0.0, 1.0, 80 + k,
                              false, false, cycle[k], 1));
    trips.back().source = "trip" + std::to_string(k) + ".csv";
  }
  const Diagnosis d = diagnose(v, trips, DiagnoseOptions{});
  ASSERT_TRUE(named(d, "unexplained")) << diagnosis_text(d);
  for (const auto& f : d.findings)
    if (f.effect == "unexplained") EXPECT_NE(f.description.find("% of it in trip2.csv"), std::string::npos) << diagnosis_text(d);
}

TEST(DiagnoseAdequacy, RisingRrcIsNeverCalledTyreWarmupNorANegativeEffect) {
  const Vehicle v = ev();
  const Recording r = recording(v, std::make_shared<RisingRrc>(2 * 1800.0), 1.0, 0.0, 1.0, 6);
  const Diagnosis d = run(v, r, 60.0);
  EXPECT_NE(d.verdict, "nothing_missing") << diagnosis_text(d);
  EXPECT_FALSE(named(d, "tyre_warmup")) << diagnosis_text(d);
  for (const auto& f : d.findings) {
    if (f.effect == "unexplained") continue;
    EXPECT_GE(f.parameters.front().value, 0.0) << f.effect;  // no catalogue effect with an impossible sign
  }
}

TEST(DiagnoseAdequacy, ScaleOutsideItsPriorIsReportedNotApplied) {
  // A terminal-power channel reading 30 % high with nothing else wrong: the scale is held at its +5 % bound, the
  // data's wish (1.3) is reported, and the verdict is never nothing_missing.
  const Vehicle v = ev();
  const Diagnosis d = run(v, recording(v, nullptr, 1.0, 0.0, 1.3, 7), 60.0);
  EXPECT_NEAR(d.channel_scale_prior_high, 1.05, 1e-12);
  EXPECT_LE(d.channel_scale, 1.05 + 1e-9);
  EXPECT_NEAR(d.channel_scale_free, 1.3, 0.05) << diagnosis_text(d);
  EXPECT_TRUE(d.calibration_outside_prior);
  // What is beyond its box is named: the scale (outside testing found the key called a channel scale out of its
  // box where the RRC level was).
  ASSERT_FALSE(d.calibration_beyond_prior.empty());
  EXPECT_EQ(d.calibration_beyond_prior.front(), "channel_scale") << diagnosis_text(d);
  EXPECT_NE(diagnosis_json(d).find("\"beyond_prior\": [\"channel_scale\""), std::string::npos) << diagnosis_json(d);
  EXPECT_NE(d.verdict, "nothing_missing") << diagnosis_text(d);
  EXPECT_NE(diagnosis_json(d).find("\"channel_scale_prior\""), std::string::npos);
}

TEST(DiagnoseAdequacy, ScalePinnedJustBeyondItsBoxIsNotedNotMissingPhysics) {
  // 5.7 % high against the +5 % box, where the boxed model still meets the trip's energy held out (the RRC level
  // takes the rest): the pin is said in a note, and no missing physics is claimed. Session 28's outside tester had
  // 5 nulls (true scales 1.045-1.05) called missing_physics with an `unexplained` at Delta BIC 0 beside a residual
  // of 0.3 x the noise floor. The Twizy trip below, where the pinned model misses by 10 %, still is.
  const Vehicle v = ev();
  const Diagnosis d = run(v, recording(v, nullptr, 1.0, 0.0, 1.057, 7), 60.0);
  EXPECT_GT(d.channel_scale_free, 1.05) << diagnosis_text(d);
  EXPECT_LT(d.channel_scale_free, 1.06) << diagnosis_text(d);
  EXPECT_LT(std::abs(d.heldout_energy_error_pct_calibrated), 1.0) << diagnosis_text(d);
  EXPECT_FALSE(d.calibration_outside_prior);
  EXPECT_EQ(d.verdict, "nothing_missing") << diagnosis_text(d);
  EXPECT_NE(diagnosis_text(d).find("calibration at its prior's bound"), std::string::npos) << diagnosis_text(d);
  // Nor does the note beside nothing_missing say what the model lacks (it did: "a drive efficiency or consumer the
  // model lacks", session 28's outside tester).
  EXPECT_EQ(diagnosis_text(d).find("the model lacks"), std::string::npos) << diagnosis_text(d);
}

TEST(DiagnoseAdequacy, TwizyTripUnderPredictedBehindAPinnedScaleIsNotNothingMissing) {
  // The real trip that read nothing_missing at a SOC scale pinned at 1.10 (wanted 1.107), 17.6 % under-predicted.
  const std::string path = std::string(ROLLSIM_SHARED_DIR) + "/data/recordings/rsk_renault_twizy/T1_06_30_2021_2.csv";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared recordings not present";
  const Vehicle v = load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/twizy.yaml");
  const Diagnosis d = diagnose(v, {load_recording(path, preset_mapping("rsk_twizy"))});
  EXPECT_NE(d.verdict, "nothing_missing") << diagnosis_text(d);
}

TEST(DiagnoseAdequacy, SubSampleLagIsEstimatedWithItsInterval) {
  // 1 Hz logger lagging 0.6 s: between whole samples; the interval holds the truth and excludes both neighbours.
  const Vehicle v = ev();
  const Diagnosis d = run(v, recording(v, nullptr, 1.0, 0.6, 1.0, 8), 60.0);
  EXPECT_NEAR(d.lag_s, 0.6, 0.1) << diagnosis_text(d);
  EXPECT_LE(d.lag_ci_low_s, 0.6);
  EXPECT_GE(d.lag_ci_high_s, 0.6);
  EXPECT_GT(d.lag_ci_low_s, 0.0);
  EXPECT_LT(d.lag_ci_high_s, 1.0);
  EXPECT_EQ(d.verdict, "nothing_missing") << diagnosis_text(d);
  // Where the model misses is read at the whole lag too: rounded to a sample, a null lagging 0.4 s read
  // 'accelerating -601 W [-817, -385]' (session 25's outside testing); this one read +766 W, now +249 W (what is
  // left is the power's rise within a second, which a mix of two seconds' means does not hold).
  for (const auto& l : d.located) EXPECT_LT(std::abs(l.mean_w), 400.0) << l.regime << "\n" << diagnosis_text(d);
}

TEST(DiagnoseAdequacy, AnInstantaneousLoggerIsReadAsOne) {
  // The replay's power is each interval's mean; a 1 Hz logger that reads the power at the interval's start differs
  // from it by half a second of speed change in every ramp, which no lag removes: read as interval means, this
  // null was missing_physics with two unexplained findings. (At 10 Hz the two readings differ too little to choose.)
  const Vehicle v = ev();
  const Diagnosis d = run(v, recording(v, nullptr, 1.0, 0.0, 1.0, 8, true), 60.0);
  EXPECT_EQ(d.channel_sampling, "instantaneous") << diagnosis_text(d);
  EXPECT_GT(d.channel_sampling_sse_ratio, 1.05);
  EXPECT_NEAR(d.lag_s, 0.0, 0.1) << diagnosis_text(d);
  EXPECT_EQ(d.verdict, "nothing_missing") << diagnosis_text(d);
  // And an integrating logger is read as the interval means it holds.
  EXPECT_EQ(run(v, recording(v, nullptr, 1.0, 0.0, 1.0, 8), 60.0).channel_sampling, "interval_mean");
}

TEST(DiagnoseAdequacy, ASmoothlyDrivenCarLoggedEitherWayThroughAScaleErrorIsNothingMissing) {
  // A real car's acceleration has no corners. Its instants then sit close to interval means half a sample later, so
  // either reading may fit (the replay holds each second's acceleration); what must hold is the verdict, through a
  // 3 % scale error and a fractional lag, whichever the logger is.
  const Vehicle v = ev();
  const double lag_s = 0.4;  // fractional; lag 0 as well doubled the test's 15 s under the sanitizers
  for (bool instantaneous : {true, false}) {
    const Diagnosis d = run(v, recording(v, nullptr, 1.0, lag_s, 1.03, 9, instantaneous, true), 60.0);
    EXPECT_EQ(d.verdict, "nothing_missing") << (instantaneous ? "instants\n" : "means\n") << diagnosis_text(d);
    EXPECT_NEAR(d.channel_scale, 1.03, 0.01) << diagnosis_text(d);
  }
}

TEST(DiagnoseAdequacy, TheSamplingIsReadAlikeThroughAChannelScaleError) {
  // A logger 3 % off in scale adds the same misfit to both readings and had hidden the instant's better fit: a 1 Hz
  // instantaneous logger 3 % high was read as interval means and its ramps' residual named (session 23's outside
  // testing). The choice is made with each reading's own best scale.
  // One scale each way per reading (both readings at both scales was 17 s under the sanitizers).
  const Vehicle v = ev();
  const Diagnosis point = run(v, recording(v, nullptr, 1.0, 0.0, 0.97, 8, true), 60.0);
  EXPECT_EQ(point.channel_sampling, "instantaneous") << diagnosis_text(point);
  EXPECT_EQ(point.verdict, "nothing_missing") << diagnosis_text(point);
  const Diagnosis mean = run(v, recording(v, nullptr, 1.0, 0.0, 1.03, 8), 60.0);
  EXPECT_EQ(mean.channel_sampling, "interval_mean") << diagnosis_text(mean);
  EXPECT_EQ(mean.verdict, "nothing_missing") << diagnosis_text(mean);
}

TEST(DiagnoseAdequacy, CalibrationPriorsAreReadFromTheVehicleFileStrictly) {
  const auto dir = std::filesystem::temp_directory_path() / ("rollsim_priors_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string good = (dir / "good.yaml").string(), bad = (dir / "bad.yaml").string(), typo = (dir / "typo.yaml").string();
  std::ofstream(good) << "calibration_priors:\n  soc_scale_bound: 0.2\n  rrc_level_sd: 0.05\n";
  std::ofstream(bad) << "calibration_priors:\n  soc_scale_bound: 0.9\n";
  std::ofstream(typo) << "calibration_priors:\n  soc_scale: 0.2\n";
  YamlMap g = YamlMap::load_file(good);
  const CalibrationPriors p = calibration_priors_from_yaml(g);
  EXPECT_DOUBLE_EQ(p.soc_scale_bound, 0.2);
  EXPECT_DOUBLE_EQ(p.rrc_level_sd, 0.05);
  EXPECT_DOUBLE_EQ(p.terminal_scale_bound, CalibrationPriors{}.terminal_scale_bound);
  EXPECT_DOUBLE_EQ(p.scale_bound(ChannelKind::soc), 0.2);
  YamlMap b = YamlMap::load_file(bad);
  try {
    calibration_priors_from_yaml(b);
    ADD_FAILURE() << "0.9 accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("soc_scale_bound"), std::string::npos) << e.what();
  }
  YamlMap t = YamlMap::load_file(typo);
  EXPECT_THROW(calibration_priors_from_yaml(t), InputError);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace rollsim
