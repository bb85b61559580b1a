// A thin RAII driver of SUNDIALS CVODE for small systems: tolerances, stop times, roots, restarts, errors.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace rollsim {

/// An ODE system y' = f(t, y) with optional switching functions g(t, y) whose zero crossings CVODE locates.
/// The integrator knows nothing else about what the state means.
class OdeSystem {
 public:
  virtual ~OdeSystem() = default;
  virtual int size() const = 0;
  /// Returns 0 on success, > 0 for a recoverable error (CVODE retries a smaller step), < 0 to abort.
  virtual int rhs(double t, const double* y, double* ydot) = 0;
  virtual int num_roots() const { return 0; }
  virtual void roots(double /*t*/, const double* /*y*/, double* /*g*/) {}
};

/// Thrown when CVODE fails; carries the time and CVODE's own reason so no number from a failed step is used.
class SolverError : public std::runtime_error {
 public:
  SolverError(double t, const std::string& what) : std::runtime_error(what), time_s(t) {}
  double time_s;
};

struct OdeTolerances {
  double relative = 1e-6;
  std::vector<double> absolute;  ///< one per state component
};

struct OdeStats {
  long steps = 0;
  long rhs_evals = 0;
  long error_test_failures = 0;
  long nonlinear_failures = 0;
  long root_evals = 0;
  long restarts = 0;  ///< re-initialisations at discontinuities
};

/// BDF with Newton iteration and a dense difference-quotient Jacobian, for small, mildly stiff systems.
class CvodeIntegrator {
 public:
  CvodeIntegrator(OdeSystem& system, double t0, const std::vector<double>& y0, const OdeTolerances& tol);
  ~CvodeIntegrator();
  CvodeIntegrator(const CvodeIntegrator&) = delete;
  CvodeIntegrator& operator=(const CvodeIntegrator&) = delete;

  /// Integrates towards `t_out` without stepping past `t_stop` (a discontinuity). Returns true when a root was
  /// found first (then time() is the root's time and root_flags() says which); false when t_out was reached.
  bool advance(double t_out, double t_stop);
  /// Restarts the method at a discontinuity: the history is dropped so no step straddles it.
  void restart(double t, const std::vector<double>& y);

  double time() const { return t_; }
  const std::vector<double>& state() const { return y_; }
  const std::vector<int>& root_flags() const { return root_flags_; }
  OdeStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  double t_ = 0.0;
  std::vector<double> y_;
  std::vector<int> root_flags_;
  long restarts_ = 0;
  double stop_time_ = -1e300;
  OdeStats before_restarts_;  // CVodeReInit zeroes CVODE's counters; earlier runs are kept here
};

}  // namespace rollsim
