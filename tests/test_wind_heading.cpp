// Wind with heading: the direction of travel from GPS, the wind_heading module's headwind w cos(theta - psi), and a
// steady wind named with its bearing on a winding route (issue 10).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "rollsim/common/units.hpp"
#include "rollsim/diagnose/diagnose.hpp"
#include "rollsim/discovery/generate.hpp"
#include "rollsim/effects/catalogue.hpp"
#include "rollsim/vehicle/vehicle_file.hpp"

namespace rollsim {
namespace {

Vehicle ev() { return load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml"); }

TEST(WindHeading, HeadingFromGpsIsTheBearingOfTheTrack) {
  // 100 points 5 m apart going east at 48 degN, then 100 going north: headings pi/2 then 0.
  const double m_per_deg_lat = 6371000.0 * units::deg_to_rad(1.0);
  const double m_per_deg_lon = m_per_deg_lat * std::cos(units::deg_to_rad(48.0));
  std::vector<double> lat, lon;
  for (int i = 0; i < 100; ++i) lat.push_back(48.0), lon.push_back(11.0 + 5.0 * i / m_per_deg_lon);
  for (int i = 1; i <= 100; ++i) lat.push_back(48.0 + 5.0 * i / m_per_deg_lat), lon.push_back(lon[99]);
  const std::vector<double> h = heading_from_gps(lat, lon, 20.0);
  ASSERT_EQ(h.size(), lat.size());
  EXPECT_NEAR(h[10], units::kPi / 2.0, 1e-6);
  EXPECT_NEAR(h[150], 0.0, 1e-6);
  EXPECT_TRUE(heading_from_gps(std::vector<double>(5, 48.0), std::vector<double>(5, 11.0)).empty());  // never moved
}

TEST(WindHeading, HeadwindIsTheWindsComponentAgainstTheHeading) {
  const Vehicle v = ev();
  const EffectContext ctx = effect_context(v);
  const double k = 0.5 * ctx.rho_cda_kg_per_m, speed = 20.0, w = 4.0;
  auto force = [&](double from_deg, double heading_deg, bool known) {
    const auto e = make_effect("wind_heading", {{"wind_speed_mps", w}, {"wind_from_deg", from_deg}}, ctx);
    EffectInputs in;
    in.speed_mps = speed;
    in.heading_rad = units::deg_to_rad(heading_deg);
    in.heading_known = known;
    return e->extra_resistance_n(in, nullptr);
  };
  EXPECT_NEAR(force(0.0, 0.0, true), k * ((speed + w) * (speed + w) - speed * speed), 1e-9);   // from ahead
  EXPECT_NEAR(force(180.0, 0.0, true), k * ((speed - w) * (speed - w) - speed * speed), 1e-9);  // from behind
  EXPECT_NEAR(force(90.0, 0.0, true), 0.0, 1e-9);                                              // across
  const double u = w * std::cos(units::deg_to_rad(60.0 - 10.0));
  EXPECT_NEAR(force(60.0, 10.0, true), k * ((speed + u) * (speed + u) - speed * speed), 1e-9);
  EXPECT_EQ(force(0.0, 0.0, false), 0.0);  // no heading: no direction to blow against
}

TEST(WindHeading, SteadyWindOnAWindingRouteIsNamedWithItsBearing) {
  // Over 20 seeds, since a 95 % interval judged on one seed says little either way. Every seed must name the wind
  // and its bearing; the interval must be closed, narrower than the half circle and hold the truth as a 95 % interval
  // does: 17 or more of 20 (a true 95 % interval falls below that about one time in 60). Measured: 20 of these 20, 29 of
  // seeds 1-30; with the bearing's signatures mixed from the north and east replays it was 16 of 20.
  const Vehicle v = ev();
  int covered = 0;
  constexpr unsigned kSeeds = 20;
  for (unsigned seed = 1; seed <= kSeeds; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    SyntheticCase c;
    c.gps = true;
    c.effects = {{"wind_steady_gps", 4.0}};
    c.wind_from_deg = 250.0;
    c.seed = seed;
    const Diagnosis d = diagnose(v, {generate_case(v, c)});
    ASSERT_FALSE(d.findings.empty());
    const Finding& f = d.findings.front();
    ASSERT_EQ(f.effect, "wind_heading");
    const double from = f.fitted.at("wind_from_deg");
    EXPECT_LE(std::min(std::abs(from - 250.0), 360.0 - std::abs(from - 250.0)), 45.0) << from;
    EXPECT_NEAR(f.fitted.at("wind_speed_mps"), 4.0, 1.5);
    EXPECT_NE(f.description.find("from"), std::string::npos);
    EXPECT_NE(f.description.find("95 % profile interval"), std::string::npos) << f.description;
    const auto p = std::find_if(f.parameters.begin(), f.parameters.end(), [](const auto& e) { return e.name == "wind_from_deg"; });
    ASSERT_NE(p, f.parameters.end());
    EXPECT_TRUE(p->profiled);
    EXPECT_FALSE(p->ci_low_open || p->ci_high_open) << p->ci_low << " " << p->ci_high;
    EXPECT_LT(p->ci_high - p->ci_low, 90.0) << p->ci_low << " " << p->ci_high;
    EXPECT_LE(p->ci_low, p->value);
    EXPECT_GE(p->ci_high, p->value);
    const double truth = p->value + std::remainder(250.0 - p->value, 360.0);  // the truth on the interval's turn
    covered += truth >= p->ci_low && truth <= p->ci_high;
  }
  EXPECT_GE(covered, 17) << "of " << kSeeds;
}

TEST(WindHeading, GustyWindOnAWindingRouteIsNamedWithItsMeanBearing) {
  // Without a heading a mean headwind is nearly the calibration's RRC level and aero C (k u^2 + 2 k u v), and the
  // gusts leave a residual no steady shape explains (wind_gusty: 33 % named at 5 m/s); with the route's heading the
  // wind's mean is what varies with the bends, and the gusts are noise about it.
  const Vehicle v = ev();
  for (const auto& [seed, from_deg] : {std::pair{11u, 40.0}, std::pair{12u, 200.0}}) {
    SyntheticCase c;
    c.gps = true;
    c.effects = {{"wind_gusty_gps", 4.0}};
    c.wind_from_deg = from_deg;
    c.seed = seed;
    const Diagnosis d = diagnose(v, {generate_case(v, c)});
    ASSERT_FALSE(d.findings.empty()) << "seed " << seed;
    const Finding& f = d.findings.front();
    ASSERT_EQ(f.effect, "wind_heading") << "seed " << seed;
    const double from = f.fitted.at("wind_from_deg");
    EXPECT_LE(std::min(std::abs(from - from_deg), 360.0 - std::abs(from - from_deg)), 45.0) << "seed " << seed << ": " << from;
  }
}

TEST(WindHeading, GustyWindsBearingIntervalHoldsTheTruthAsA95PercentIntervalDoes) {
  // Gusts leave residuals that grow where the route runs along the wind, which a likelihood ratio with one variance
  // for every window reads as more certainty than there is: its 95 % interval held the mean bearing on 63 of the 95
  // seeds of 100 that named a 6 m/s gusty wind (diagnose-bench), and on 31 of these 40, all named. Widened to the
  // bearing's jackknife variance it holds it on 88 of 95 there, 37 of 40 here. A true 95 % interval falls below 85 %
  // of 40 about one time in 300; the bearings are spread round the compass.
  const Vehicle v = ev();
  int named = 0, held = 0;
  for (unsigned seed = 1; seed <= 40; ++seed) {
    SyntheticCase c;
    c.gps = true;
    c.effects = {{"wind_gusty_gps", 6.0}};
    c.wind_from_deg = std::fmod(17.0 + 53.0 * seed, 360.0);
    c.seed = seed;
    const Diagnosis d = diagnose(v, {generate_case(v, c)});
    if (d.findings.empty() || d.findings.front().effect != "wind_heading") continue;
    const auto& ps = d.findings.front().parameters;
    const auto p = std::find_if(ps.begin(), ps.end(), [](const auto& e) { return e.name == "wind_from_deg"; });
    ASSERT_NE(p, ps.end());
    ++named;
    const double truth = p->value + std::remainder(*c.wind_from_deg - p->value, 360.0);
    held += truth >= p->ci_low && truth <= p->ci_high;
  }
  EXPECT_GE(named, 34);
  EXPECT_GE(held * 100, named * 85) << held << " of " << named << " named";
}

TEST(WindHeading, WithoutGpsTheDiagnosisSaysTheHeadingIsUnknown) {
  const Vehicle v = ev();
  SyntheticCase c;
  c.seed = 2;
  const Diagnosis d = diagnose(v, {generate_case(v, c)});
  bool said = false;
  for (const auto& n : d.notes) said = said || n.find("the route's heading is unknown") != std::string::npos;
  EXPECT_TRUE(said);
}

}  // namespace
}  // namespace rollsim
