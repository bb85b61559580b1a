// Judging tyre models on measured J2452 surfaces: one-point and full fits, baselines, leave-one-tyre-out.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "rollsim/tyre/j2452.hpp"
#include "rollsim/tyre/tyre_model.hpp"

namespace rollsim {

/// How a surface's RR force scales, read from the surface: log-slopes across the grid at the reference point.
struct SurfaceScaling {
  double pressure_exponent = 0.0;  ///< d ln F / d ln P, 180 -> 300 kPa at 4000 N, 80 km/h
  double load_exponent = 0.0;      ///< d ln F / d ln Z, 3 -> 6 kN at 210 kPa, 80 km/h
  double speed_rise = 0.0;         ///< F(115 km/h) / F(15 km/h) - 1 at 210 kPa, 4000 N
};

/// An operating point of a measurement plan.
struct OperatingPoint {
  double pressure_pa = 0.0;
  double load_n = 0.0;
  double speed_mps = 0.0;
};

/// What a user measures on a tyre besides the one label-like point (210 kPa, 4000 N, 80 km/h): extra points,
/// each read off the held-out tyre's surface. The fit frees what the points determine (identifiable_params), as
/// `rollsim tyre fit --point ... --point ...` does, and keeps the leave-one-tyre-out shared constants for the rest.
struct MeasurementPlan {
  std::string name;  ///< e.g. "+15 km/h, +300 kPa"
  std::vector<OperatingPoint> extra;
  std::vector<HysteresisParam> fitted;  ///< what the fit frees for these points with the reference point
};

/// The plans judged: every single extra point at an edge of the grid (15 or 115 km/h, 180 or 300 kPa, 3 or 6 kN),
/// every pair of one extra speed and one extra pressure, both speeds, and both speeds with either pressure.
std::vector<MeasurementPlan> j2452_measurement_plans();

/// The mix of seen shapes nearest a target shape, level free: the weights (>= 0, summing to 1) of the rows of
/// `shapes` whose weighted sum, shifted by a constant, is closest to `target` in RMS over the columns.
struct NearestMix {
  Eigen::VectorXd weights;
  double log_rms = 0.0;  ///< RMS of the log ratio at the optimum: no mix at any level comes nearer
  double rms = 0.0;      ///< RMS relative error of that mix at its best level
};
NearestMix nearest_mix(const Eigen::MatrixXd& shapes, const Eigen::VectorXd& target);

struct TyreEvaluation {
  std::string name;
  bool flagged = false;            ///< the set's values were read with a correction (J2452Set::flagged)
  double reference_rrc = 0.0;      ///< the measured (flat-road) RRC at the one point [-]
  // RMS (and largest) relative RRC error over the grid [-], every model scaled to the tyre at one point
  // (210 kPa, 4000 N, 80 km/h) except the full fit.
  double one_point_rms = 0.0;      ///< hysteresis model, shared constants fitted without this tyre
  double one_point_max = 0.0;
  double full_fit_rms = 0.0;       ///< hysteresis model, all six constants fitted to this tyre's grid
  double thesis_rms = 0.0;         ///< thesis model with its constants, scaled
  double constant_rms = 0.0;       ///< a constant RRC
  double median_shape_rms = 0.0;   ///< median J2452 exponents and speed terms of the other tyres, scaled
  std::vector<double> plan_rms;    ///< hysteresis model fitted to each measurement plan's points (J2452Evaluation::plans)
  SurfaceScaling measured, one_point, full_fit, thesis;
  /// The bound of every predictor confined to the shapes of the tyres it saw (the others, or the training sets):
  /// their mix nearest this tyre's own log-RRC shape over the grid, chosen in hindsight with its grid in hand. A
  /// prediction from one point that stays among the shapes seen cannot come nearer this tyre than this.
  NearestMix seen_shapes;
  HysteresisConstants shared;      ///< the shared constants it was judged with, fitted without this tyre
};

/// What any model that gives every tyre one common shape (scaled at the one point) could reach at best, chosen
/// in hindsight with all tyres seen: the centre of the smallest ball holding every tyre's log-RRC shape over
/// the grid. Its radius bounds the worst tyre from below for every such model, in RMS of the log ratio.
struct CommonShapeBound {
  double worst_log_rms = 0.0;      ///< the ball's radius: no common shape has a smaller worst-tyre log RMS
  std::vector<double> rms;         ///< RMS relative RRC error of the centre shape, per tyre (the tyres' order)
};

struct J2452Evaluation {
  std::vector<TyreEvaluation> tyres;
  HysteresisConstants shared_all;  ///< shared constants fitted on every set (the shipped defaults)
  bool leave_one_out = true;       ///< false: every tyre judged with shared_all, fitted on other tyres
  std::vector<MeasurementPlan> plans;
  CommonShapeBound common_shape;
};

/// The minimiser of w'Qw + c'w over the simplex (w >= 0, sum w = 1), Q symmetric positive semi-definite.
Eigen::VectorXd minimise_on_simplex(const Eigen::MatrixXd& q, const Eigen::VectorXd& c);

/// The smallest enclosing ball of `shapes` (rows), in RMS over the columns: its centre and radius. Frank-Wolfe on
/// the dual over the simplex of the rows' weights, which needs only their Gram matrix.
struct EnclosingBall {
  Eigen::VectorXd centre;
  double radius = 0.0;
};
EnclosingBall smallest_enclosing_ball(const Eigen::MatrixXd& shapes);

/// The model tyre of a set: geometry from its size designation, thesis constants, pressure 210 kPa.
TyreState j2452_tyre(const J2452Set& set);

/// Shared constants (all but rrc_ref) minimising the one-point-fit error over `training` on the grid: each
/// training tyre's level is set from its own reference point, as a user would with one label point.
HysteresisConstants fit_shared_constants(const std::vector<J2452Set>& training, double drum_radius_m);

/// Leave-one-tyre-out evaluation of every set, with the baselines and the all-sets shared constants.
J2452Evaluation evaluate_j2452(const std::vector<J2452Set>& sets, double drum_radius_m);

/// The same judgement of `test` tyres with the shared constants (and the median J2452 shape) fitted once on
/// `training`: tyres the model never saw. `shared_all` is the training fit; the common-shape bound is the test
/// tyres'. A test tyre that is also a training one (same_j2452_tyre) throws InputError naming both sources.
J2452Evaluation evaluate_j2452_held_out(const std::vector<J2452Set>& training, const std::vector<J2452Set>& test,
                                        double drum_radius_m, const std::string& training_source = "the fitting sets",
                                        const std::string& test_source = "the held-out sets");

/// Each tyre's RMS error under plan `k` (ev.plans[k]), in the tyres' order.
std::vector<double> plan_rms_column(const J2452Evaluation& ev, std::size_t k);

/// The evaluation as JSON lines, the command's tables in files' units (percent): one "tyre" object per tyre (its
/// errors and the exponents measured and modelled), one "plan" per measurement plan (median, worst and each tyre's
/// RMS by name), the "common_shape" bound, and one "shared" object per set of shared constants (`fitted_without`
/// a tyre's name, or "" for the fit on every training set).
void write_j2452_evaluation_json(std::ostream& out, const J2452Evaluation& ev);

}  // namespace rollsim
