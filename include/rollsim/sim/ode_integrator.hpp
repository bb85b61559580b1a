// A thin RAII driver of SUNDIALS CVODES for small systems: tolerances, stop times, roots, quadratures, errors.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace rollsim {

/// An ODE system y' = f(t, y), with quadratures q' = fq(t, y) (integrals that feed nothing back, such as
/// energy accumulators) and switching functions g(t, y) whose zero crossings the integrator locates.
/// The integrator knows nothing else about what the state means.
class OdeSystem {
 public:
  virtual ~OdeSystem() = default;
  virtual int size() const = 0;
  /// Returns 0 on success, > 0 for a recoverable error (CVODES retries a smaller step), < 0 to abort.
  virtual int rhs(double t, const double* y, double* ydot) = 0;
  virtual int num_quadratures() const { return 0; }
  virtual int quadrature_rhs(double /*t*/, const double* /*y*/, double* /*qdot*/) { return 0; }
  virtual int num_roots() const { return 0; }
  /// A readable name of state component i, for solver-failure messages.
  virtual std::string state_name(int i) const { return "y[" + std::to_string(i) + "]"; }
  virtual void roots(double /*t*/, const double* /*y*/, double* /*g*/) {}
};

/// Thrown when CVODES fails; carries the time and CVODES' own reason so no number from a failed step is used.
class SolverError : public std::runtime_error {
 public:
  SolverError(double t, const std::string& what) : std::runtime_error(what), time_s(t) {}
  double time_s;
};

struct OdeTolerances {
  double relative = 1e-6;
  std::vector<double> absolute;             ///< one per state component
  double quadrature_relative = 1e-6;        ///< applies to each interval's integral (they restart at restarts)
  std::vector<double> quadrature_absolute;  ///< one per quadrature; they take part in error control
};

struct OdeStats {
  long steps = 0;
  long rhs_evals = 0;
  long quadrature_evals = 0;
  long error_test_failures = 0;
  long nonlinear_failures = 0;
  long root_evals = 0;
  long restarts = 0;  ///< re-initialisations at discontinuities
};

/// Adams-Moulton with fixed-point iteration: the systems here are small and non-stiff, and fixed point needs no
/// Jacobian. Quadratures are integrated by the same method outside the nonlinear iteration (CVODES).
class CvodeIntegrator {
 public:
  CvodeIntegrator(OdeSystem& system, double t0, const std::vector<double>& y0, const std::vector<double>& q0,
                  const OdeTolerances& tol);
  ~CvodeIntegrator();
  CvodeIntegrator(const CvodeIntegrator&) = delete;
  CvodeIntegrator& operator=(const CvodeIntegrator&) = delete;

  /// Takes one internal step towards `t_stop` (a discontinuity) without passing it. Returns true when the step
  /// found a root (then time() is the root's time and root_flags() says which). Points inside the step are
  /// read with state_at(): dense output, so reporting at fixed times costs no extra solver calls.
  bool step(double t_stop);
  /// The state at t within the last step, by CVODES' interpolating polynomial.
  std::vector<double> state_at(double t) const;
  /// The quadratures at time(), fetched from CVODES on demand.
  const std::vector<double>& quadratures();
  /// The quadratures at t within the last step, interpolated like state_at().
  std::vector<double> quadratures_at(double t) const;
  /// Restarts the method at a discontinuity with state `y` (quadratures carry on): no step straddles it.
  void restart(double t, const std::vector<double>& y);
  /// New absolute tolerances for the quadratures (one each), from the next step on: the integral restarts at
  /// each restart, so a caller can fit them to the energy scale of the interval ahead.
  void set_quadrature_absolute_tolerances(const std::vector<double>& absolute);

  double time() const { return t_; }
  const std::vector<double>& state() const { return y_; }
  const std::vector<int>& root_flags() const { return root_flags_; }
  OdeStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  double t_ = 0.0;
  std::vector<double> y_;
  std::vector<double> q_;
  std::vector<double> q_offset_;  // quadrature sums up to the last restart
  bool q_current_ = true;          // q_ holds the quadratures at t_
  std::vector<int> root_flags_;
  long restarts_ = 0;
  int stalls_ = 0;  // successive calls that returned without advancing
  double stop_time_ = -1e300;
  double quadrature_relative_ = 0.0;
  OdeStats before_restarts_;  // CVodeReInit zeroes the counters; earlier runs are kept here
};

}  // namespace rollsim
