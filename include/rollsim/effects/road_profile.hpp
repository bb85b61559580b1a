// Road profile: an elevation along distance (linear between knots) whose grade force m g sin(theta(s)) the model lacked.
#pragma once

#include <vector>

#include "rollsim/effects/catalogue.hpp"

namespace rollsim {

/// Knots of an elevation profile along the distance driven, ascending in distance.
struct ElevationProfile {
  std::vector<double> distance_m, elevation_m;
  /// Grade (rise over run) at distance s: the slope of the segment holding s; 0 outside the profile.
  double grade_at(double distance_m) const;
};

struct RoadProfileParams {
  double profile_scale, knot_spacing_m;
};

/// Grade force of an elevation profile, m g sin(atan(scale x dh/ds)), while moving (standing, the brakes hold the
/// car). Built from the registry (a vehicle file) it has no knots and is flat: the profile comes from a diagnosis.
class RoadProfile final : public Effect {
 public:
  RoadProfile(const RoadProfileParams& p, const EffectContext& c);
  RoadProfile(ElevationProfile profile, double scale, double mass_kg);
  std::string id() const override { return "road_profile"; }
  double extra_resistance_n(const EffectInputs& in, const double*) const override;

 private:
  ElevationProfile profile_;
  double scale_ = 0.0, mass_kg_ = 0.0;
};

}  // namespace rollsim
