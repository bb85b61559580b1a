// Vehicle energy simulation over a speed trace: forward (driver + CVODE) and kinematic replay, one power flow.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/powertrain/powertrain.hpp"
#include "rollsim/effects/effect.hpp"
#include "rollsim/sim/ode_integrator.hpp"
#include "rollsim/vehicle/road_load.hpp"
#include "rollsim/vehicle/vehicle.hpp"
#include "rollsim/common/units.hpp"

namespace rollsim {

/// The run-time model of a car: what the simulator needs, assembled once from a Vehicle description.
struct VehicleModel {
  std::string name;
  std::string road_load_description;
  std::string rolling_term;        ///< road_load->rolling_term(), as the energy table names it
  double mass_kg = 0.0;             ///< test mass (grade and inertia)
  double rotating_mass_kg = 0.0;    ///< equivalent mass of rotating parts (inertia only)
  double wheel_radius_m = 0.0;      ///< effective rolling radius of the driven wheels
  std::shared_ptr<const RoadLoadModel> road_load;
  RoadLoadCoeffs flat_road_load;   ///< road_load->at_grade(0), prepared once: most traces are flat
  std::shared_ptr<const Powertrain> powertrain;
  std::vector<std::shared_ptr<const Effect>> effects;

  double inertial_mass_kg() const { return mass_kg + rotating_mass_kg; }
  static VehicleModel assemble(const Vehicle& vehicle);
  /// `base` with the tyre-dependent parts (road load, driven wheel radius) made again for `vehicle`'s tyres; the
  /// powertrain and effects, which do not depend on the tyres, are shared with `base`. For sweeps and comparisons
  /// that change only the tyres: the same model as assemble(vehicle) at a fraction of its cost.
  static VehicleModel with_tyres_of(const VehicleModel& base, const Vehicle& vehicle);
};

struct SimulationOptions {
  double relative_tolerance = 1e-5;
  /// Absolute tolerance of the energy quadratures in each interval between restarts, as a fraction of the
  /// energy the trace moves in that interval (kinetic swing + road-load work + auxiliaries). Sets how closely
  /// the energy balance closes: 1e-4 closes it to 0.003 % or better on every shipped cycle (README, "Energy
  /// balance"), 1e-5 to 0.0016 % in 30 % more steps.
  double quadrature_energy_fraction = 1e-4;
  /// Driver PI gains on the speed error. The feed-forward from the trace does the tracking (0.002 km/h on
  /// NEDC); the PI only recovers from limits, so it is gentle: a 2 s time constant. Higher gains track no
  /// better and cap Adams' fixed-point step at ~1/kp (kp 2: 1760 steps on NEDC, kp 0.5: 800).
  double driver_kp_per_s = 0.5;        ///< proportional gain [1/s]
  double driver_ki_per_s2 = 0.1;       ///< integral gain [1/s^2]
  bool record_trace = false;           ///< one row per cycle sample
  /// Replay with a trace: each ramp's end at its own acceleration too (TracePoint::end_*), one more evaluation per
  /// ramp; otherwise the ends are the point values. The diagnosis asks for them once it reads a channel as instants.
  bool record_segment_ends = false;
  /// A shortfall is reported where the car falls behind the trace by more than this (the regulation's
  /// speed tolerance is 2 km/h).
  double shortfall_threshold_mps = units::kmh_to_mps(2.0);
};

/// Energies over a run [J]. At the wheel hubs: traction + unmet demand = rolling + aero + grade + other +
/// friction brake + regen + wheel loss + kinetic change. Electric: battery terminal = traction - regen + gearbox + motor + aux.
/// Combustion: fuel = engine loss + traction + gearbox + clutch + aux.
struct EnergyBreakdown {
  double traction_j = 0.0;
  double rolling_j = 0.0;
  double aero_j = 0.0;
  double grade_j = 0.0;           ///< signed: net potential energy gained
  double other_resistance_j = 0.0;  ///< effects' forces (wind, ...)
  double friction_brake_j = 0.0;
  double regen_wheel_j = 0.0;
  double kinetic_change_j = 0.0;
  double wheel_loss_j = 0.0;      ///< effects' wheel losses (tyre slip)
  /// Replay only: wheel work the trace demanded beyond the powertrain's limits (the car could not have followed;
  /// such intervals are also reported as shortfalls). Zero in forward simulation, where the car falls behind.
  double unmet_demand_j = 0.0;
  double gearbox_loss_j = 0.0;
  double motor_loss_j = 0.0;
  double battery_loss_j = 0.0;
  double aux_j = 0.0;
  double battery_terminal_j = 0.0;  ///< signed: + discharged
  double fuel_j = 0.0;
  double engine_loss_j = 0.0;
  double clutch_loss_j = 0.0;

  double wheel_residual_j() const;       ///< traction minus all its uses; ~0 when the balance closes
  double powertrain_residual_j() const;  ///< source energy (battery terminals + fuel) minus all its uses
};

struct Shortfall {
  double start_s = 0.0;
  double end_s = 0.0;
  double max_deficit_mps = 0.0;  ///< largest (trace - actual) speed in the interval
  double at_s = 0.0;             ///< when it was largest
};

/// Whether a run kept to its trace, in one value that the front ends carry and compare: false where the car fell
/// behind (forward) or the powertrain could not deliver the trace (replay, which cannot fall behind: deficit 0).
struct TraceFollowing {
  bool followed = true;
  double max_deficit_mps = 0.0;  ///< largest speed deficit behind the trace over every shortfall
};

/// Where an electric car's usable battery ran empty (its state of charge reached 0).
struct BatteryDepletion {
  double time_s = 0.0;
  double distance_m = 0.0;
};

struct TracePoint {
  double time_s, target_speed_mps, speed_mps, accel_mps2, grade;
  double rolling_force_n, aero_force_n, grade_force_n, wheel_force_n;
  double traction_power_w, battery_power_w, battery_current_a, fuel_rate_m3_per_s;
  double battery_loss_w;  ///< inside the cells (I^2 R and effects'); a state of charge sees terminal + this
  /// Means over the segment from this sample to the next, as the run integrates them (replay: the segment's
  /// quadrature / its length; forward and the last sample: the point values). A channel summed as mean x dt over
  /// the trace adds up to the run's energy totals; the point values, a left-end rule, do not.
  double segment_battery_power_w, segment_battery_loss_w, segment_fuel_rate_m3_per_s;
  /// Point values at the segment's end, at the segment's own acceleration (replay; forward and the last sample: the
  /// point values). Over a ramp the trace's acceleration jumps at each sample, so an instant read a fraction f into
  /// a segment lies between this sample's point value and these, not between two samples' point values.
  double end_battery_power_w, end_battery_loss_w, end_fuel_rate_m3_per_s;
  double rrc;  ///< rolling force / total normal load
  double machine_speed_radps;  ///< engine or motor speed (0 with the engine off)
  double gear_ratio;           ///< the powertrain's engaged gear ratio (0: none, or a powertrain without gears)
  double soc;  ///< state of charge, fraction (electric)
  /// Running totals from the start to this sample, as the run integrates them: their last values are the run's
  /// totals, and differences give any interval's exactly (point powers summed over a trace do not, at kinks).
  double battery_terminal_energy_j;  ///< drawn at the battery's terminals (regeneration negative)
  double fuel_volume_m3;
  int gear;
};

/// What a run took from a battery, when the powertrain has one.
struct BatteryFigures {
  double usable_j = 0.0;     ///< usable capacity
  double initial_soc = 1.0;  ///< fraction of usable capacity
  double final_soc = 1.0;
  /// The highest state of charge of the run (read at the integrator's steps or the replay's segment ends). Above 1
  /// the run booked regeneration a full battery could not take (no charge limit is modelled); the report warns.
  double max_soc = 1.0;
};

/// What a run burned, when the powertrain has a fuel converter.
struct FuelFigures {
  double volume_m3 = 0.0;
  double co2_kg = 0.0;
};

struct SimulationResult {
  std::string vehicle;
  std::string road_load;
  std::string rolling_term = "rolling resistance (tyres)";  ///< what the rolling energy holds (RoadLoadModel)
  std::string cycle;
  std::string mode;  ///< "forward" or "replay"
  double duration_s = 0.0;
  double distance_m = 0.0;
  double trace_distance_m = 0.0;  ///< what the trace asks to drive (a forward car that falls behind covers less)
  EnergyBreakdown energy;
  std::optional<BatteryFigures> battery;  ///< set when the powertrain has a battery
  std::optional<FuelFigures> fuel;        ///< set when it burns fuel
  /// Where the usable battery ran empty, if it did. The run still drives the whole trace (its energies are the
  /// trace's) and battery->final_soc goes below 0, but a real car would have stopped here: reports must say so,
  /// never print a negative state of charge as a result.
  std::optional<BatteryDepletion> battery_empty;
  double max_speed_error_mps = 0.0;
  double max_speed_error_time_s = 0.0;
  OdeStats solver;
  std::vector<Shortfall> shortfalls;
  std::vector<TracePoint> trace;

  /// Per-distance figures exist only for a run that drove its trace: a standstill-only trace has none, and neither has
  /// a car that covered less than kMinShareOfTraceDriven of it (a motor of 0.25 N m: 10^8 kWh/10 km over millimetres,
  /// a figure of no drive), nor a trace that covers under kMinTraceDistance_m (1.4 um read 6,003,380 kWh/10 km: the
  /// standing auxiliaries over a distance of no drive; session 22's outside testing). They are NaN then.
  bool moved() const {
    return distance_m > 0.0 && trace_distance_m >= kMinTraceDistance_m && distance_m >= kMinShareOfTraceDriven * trace_distance_m;
  }
  static constexpr double kMinShareOfTraceDriven = 0.1;
  static constexpr double kMinTraceDistance_m = 1.0;
  /// Energy taken from the sources [J]: battery terminals plus fuel (lower heating value).
  double source_energy_j() const;
  /// Battery-terminal energy per distance in kWh/10 km (the platform study's unit).
  double aec_kwh_per_10km() const;
  double fuel_l_per_100km() const;
  double co2_g_per_km() const;
  /// Distance on the usable battery at this consumption [km] (battery chemical energy, incl. its loss); NaN when
  /// the run did not move or ended with more charge than it began.
  double range_km() const;
  /// The shortfalls summed up: followed when there are none, and the largest deficit among them.
  TraceFollowing trace_following() const;
};

/// Forward simulation: a driver (cycle feed-forward + PI) follows the trace; CVODES integrates speed,
/// distance, the driver's integral and effects' states, with every energy accumulator as a quadrature,
/// stopping at each kink of the trace and each gear shift (a located root). Throws SolverError if it fails.
SimulationResult simulate_forward(const VehicleModel& model, const DriveCycle& cycle, const SimulationOptions& opt = {});

/// Kinematic replay: the car follows the trace exactly; the same power flow is integrated per segment
/// (Gauss-Legendre, 2 points; one for constant speed), with no driver and no ODE solver.
SimulationResult simulate_replay(const VehicleModel& model, const DriveCycle& cycle, const SimulationOptions& opt = {});

}  // namespace rollsim
