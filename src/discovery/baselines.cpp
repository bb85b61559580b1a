// Discovery benchmark's baseline: sparse regression (SINDy-style STLSQ) on window integrals of speed terms.
#include "rollsim/discovery/baselines.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>

#include "rollsim/common/error.hpp"
#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/diagnose/diagnose.hpp"
#include "rollsim/sim/simulation.hpp"

namespace rollsim {

namespace {

constexpr int kTerms = 7;  // sim, 1, v, v^2, v^3, a, a v

// Window integrals of the library terms and the measured channel's window energies, on one recording.
struct SparseDesign {
  Eigen::MatrixXd x;
  Eigen::VectorXd y;
};

SparseDesign sparse_design(const Vehicle& vehicle, const Recording& rec, double window_s) {
  // Nominal model on the recorded speed: the regression explains the measured window energy by the simulated one
  // plus library terms, as a SINDy user without the physics catalogue would.
  const DriveCycle c = cycle_of_recording(rec);
  SimulationOptions so;
  so.record_trace = true;
  const SimulationResult sim = simulate_replay(VehicleModel::assemble(vehicle), c, so);
  // The channel in the simulation's energy domain: battery power, fuel chemical power, or SOC x capacity.
  double fuel_j_per_m3 = 0.0, capacity_j = 0.0;
  if (const FuelParams* f = vehicle.fuel()) fuel_j_per_m3 = f->energy_j_per_m3();
  if (const BatteryParams* b = vehicle.battery()) capacity_j = b->usable_capacity_j;
  const bool soc = !rec.battery_power_w && !rec.fuel_rate_m3ps && rec.soc_fraction;
  std::vector<double> meas(rec.time_s.size(), 0.0);
  if (rec.battery_power_w) meas = *rec.battery_power_w;
  else if (rec.fuel_rate_m3ps)
    for (std::size_t i = 0; i < meas.size(); ++i) meas[i] = (*rec.fuel_rate_m3ps)[i] * fuel_j_per_m3;
  std::vector<std::array<double, kTerms>> rows;
  std::vector<double> y;
  std::array<double, kTerms> acc{};
  double yw = 0.0, w0 = rec.time_s.front();
  for (std::size_t i = 0; i + 1 < rec.time_s.size() && i < sim.trace.size(); ++i) {
    const double dt = rec.time_s[i + 1] - rec.time_s[i], v = rec.speed_mps[i];
    const double a = (rec.speed_mps[i + 1] - v) / dt;
    const double sim_w = fuel_j_per_m3 > 0.0 ? sim.trace[i].segment_fuel_rate_m3_per_s * fuel_j_per_m3 : sim.trace[i].segment_battery_power_w;
    const std::array<double, kTerms> phi{sim_w, 1.0, v, v * v, v * v * v, a, a * v};
    for (int k = 0; k < kTerms; ++k) acc[k] += phi[k] * dt;
    // SOC is a state: a window's energy is its drop times the capacity, not an integral of samples.
    yw += soc ? ((*rec.soc_fraction)[i] - (*rec.soc_fraction)[i + 1]) * capacity_j : meas[i] * dt;
    if (rec.time_s[i + 1] - w0 >= window_s) {  // the diagnosis' windows
      rows.push_back(acc);
      y.push_back(yw);
      acc = {};
      yw = 0.0;
      w0 = rec.time_s[i + 1];
    }
  }
  const auto n = static_cast<Eigen::Index>(y.size());
  SparseDesign d;
  d.x.resize(n, kTerms);
  d.y.resize(n);
  for (Eigen::Index r = 0; r < n; ++r) {
    d.y[r] = y[static_cast<std::size_t>(r)];
    for (int k = 0; k < kTerms; ++k) d.x(r, k) = rows[static_cast<std::size_t>(r)][k];
  }
  return d;
}

struct SparseFit {
  std::vector<bool> on;
  Eigen::VectorXd coef;
  double rss = 0.0;
};

// Sequential thresholded least squares (Brunton et al. 2016) on unit-norm columns: a term whose contribution
// |c_k| ||x_k|| is below `lambda` ||y|| is dropped and the rest refitted, until the set stops changing. The
// simulated energy (column 0) is always kept.
SparseFit stlsq(const SparseDesign& d, double lambda) {
  const Eigen::Index n = d.y.size();
  SparseFit f;
  f.on.assign(kTerms, true);
  f.coef = Eigen::VectorXd::Zero(kTerms);
  for (int iter = 0; iter < 20; ++iter) {
    std::vector<int> idx;
    for (int k = 0; k < kTerms; ++k)
      if (f.on[k]) idx.push_back(k);
    Eigen::MatrixXd xs(n, static_cast<Eigen::Index>(idx.size()));
    for (std::size_t j = 0; j < idx.size(); ++j) xs.col(static_cast<Eigen::Index>(j)) = d.x.col(idx[j]);
    const Eigen::VectorXd c = xs.colPivHouseholderQr().solve(d.y);
    f.coef.setZero();
    for (std::size_t j = 0; j < idx.size(); ++j) f.coef[idx[j]] = c[static_cast<Eigen::Index>(j)];
    f.rss = (d.y - xs * c).squaredNorm();
    bool changed = false;
    for (int k = 1; k < kTerms; ++k) {
      if (f.on[k] && std::abs(f.coef[k]) * d.x.col(k).norm() < lambda * d.y.norm()) {
        f.on[k] = false;
        changed = true;
      }
    }
    if (!changed) break;
  }
  return f;
}

// Mapping of terms to catalogue signatures (power terms): 1 -> aux_load (constant power); v^2 -> wind (the
// 2 rho CdA u v force); a -> regen_limit (the only catalogue effect that acts on the sign of a: braking losses);
// a v -> mass or rotational_inertia (inertial power, the two cannot be told apart from it). v and v^3 are the
// RRC level and CdA, calibration quantities, so never discoveries. Time-dependent effects (warm-ups), F^2 v
// (slip) and trip-level terms (ambient) have no term: the library cannot name them.
std::vector<std::string> sparse_names(const SparseDesign& d, const SparseFit& f) {
  const char* map[kTerms] = {nullptr, "aux_load", nullptr, "wind", nullptr, "regen_limit", "mass|rotational_inertia"};
  std::vector<std::pair<double, std::string>> found;
  for (int k = 1; k < kTerms; ++k)
    if (f.on[k] && map[k]) found.push_back({std::abs(f.coef[k]) * d.x.col(k).norm(), map[k]});
  std::sort(found.begin(), found.end(), [](const auto& p, const auto& q) { return p.first > q.first; });
  std::vector<std::string> out;
  for (const auto& x : found) out.push_back(x.second);
  return out;
}

}  // namespace

const std::vector<double>& sparse_thresholds() {
  static const std::vector<double> kThresholds{0.003, 0.01, 0.03, 0.1};
  return kThresholds;
}

std::vector<std::string> sparse_regression_discovery(const Vehicle& vehicle, const Recording& rec, double window_s,
                                                     double threshold) {
  if (!(threshold > 0.0)) throw InputError("sparse regression threshold", "must be positive");
  const SparseDesign d = sparse_design(vehicle, rec, window_s);
  return sparse_names(d, stlsq(d, threshold));
}

SparseSweep sparse_regression_sweep(const Vehicle& vehicle, const Recording& rec, double window_s) {
  const SparseDesign d = sparse_design(vehicle, rec, window_s);
  SparseSweep out;
  for (double t : sparse_thresholds()) out.by_threshold.push_back(sparse_names(d, stlsq(d, t)));
  // The threshold chosen by BIC along the STLSQ path (a log grid 0.001-0.3, 13 values): each threshold gives a
  // support; the support with the least n ln(RSS / n) + k ln n wins (ties: the sparser, i.e. larger threshold).
  const double n = static_cast<double>(d.y.size());
  double best = 1e300;
  for (int i = 0; i <= 12; ++i) {
    const double t = 0.001 * std::pow(300.0, i / 12.0);
    const SparseFit f = stlsq(d, t);
    const double k = static_cast<double>(std::count(f.on.begin(), f.on.end(), true));
    const double bic = n * std::log(std::max(1e-300, f.rss / n)) + k * std::log(n);
    if (bic <= best) {
      best = bic;
      out.bic_threshold = t;
      out.bic = sparse_names(d, f);
    }
  }
  return out;
}

}  // namespace rollsim
