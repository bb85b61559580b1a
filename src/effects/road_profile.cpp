// The road-profile effect: grade from an elevation profile along distance.
#include "rollsim/effects/road_profile.hpp"

#include <algorithm>
#include <cmath>

#include "rollsim/common/units.hpp"

namespace rollsim {

double ElevationProfile::grade_at(double s) const {
  if (distance_m.size() < 2 || s < distance_m.front() || s >= distance_m.back()) return 0.0;
  const auto k = static_cast<std::size_t>(std::upper_bound(distance_m.begin(), distance_m.end(), s) - distance_m.begin()) - 1;
  return (elevation_m[k + 1] - elevation_m[k]) / (distance_m[k + 1] - distance_m[k]);
}

RoadProfile::RoadProfile(const RoadProfileParams& p, const EffectContext& c) : scale_(p.profile_scale), mass_kg_(c.mass_kg) {}

RoadProfile::RoadProfile(ElevationProfile profile, double scale, double mass_kg)
    : profile_(std::move(profile)), scale_(scale), mass_kg_(mass_kg) {}

double RoadProfile::extra_resistance_n(const EffectInputs& in, const double*) const {
  if (std::max(in.speed_mps, 0.0) <= 0.0) return 0.0;  // standing still: the brakes hold the car
  const double g = scale_ * profile_.grade_at(in.distance_m);
  return mass_kg_ * units::kStandardGravity_mps2 * std::sin(std::atan(g));
}

}  // namespace rollsim
