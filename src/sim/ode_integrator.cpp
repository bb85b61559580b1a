#include "rollsim/sim/ode_integrator.hpp"

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <limits>
#include <string>

namespace rollsim {

struct CvodeIntegrator::Impl {
  SUNContext ctx = nullptr;
  void* mem = nullptr;
  N_Vector y = nullptr;
  N_Vector abstol = nullptr;
  SUNNonlinearSolver nls = nullptr;
  OdeSystem* system = nullptr;
  std::string last_error;

  ~Impl() {
    if (mem) CVodeFree(&mem);
    if (nls) SUNNonlinSolFree(nls);
    if (y) N_VDestroy(y);
    if (abstol) N_VDestroy(abstol);
    if (ctx) SUNContext_Free(&ctx);
  }

  static int rhs(realtype t, N_Vector y, N_Vector ydot, void* user) {
    auto* self = static_cast<Impl*>(user);
    return self->system->rhs(t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot));
  }
  static int roots(realtype t, N_Vector y, realtype* g, void* user) {
    static_cast<Impl*>(user)->system->roots(t, N_VGetArrayPointer(y), g);
    return 0;
  }
  // CVODE reports through this instead of printing; the message becomes part of the SolverError.
  static void on_error(int, const char*, const char* function, char* msg, void* user) {
    static_cast<Impl*>(user)->last_error = std::string(function) + ": " + msg;
  }

  void check(int flag, const char* call, double t) const {
    if (flag < 0) {
      throw SolverError(t, std::string(call) + " failed at t = " + std::to_string(t) + " s: " +
                               CVodeGetReturnFlagName(flag) + (last_error.empty() ? "" : " (" + last_error + ")"));
    }
  }
};

CvodeIntegrator::CvodeIntegrator(OdeSystem& system, double t0, const std::vector<double>& y0,
                                 const OdeTolerances& tol)
    : impl_(std::make_unique<Impl>()), t_(t0), y_(y0) {
  auto& s = *impl_;
  s.system = &system;
  const int n = system.size();
  s.check(SUNContext_Create(nullptr, &s.ctx), "SUNContext_Create", t0);
  s.y = N_VNew_Serial(n, s.ctx);
  s.abstol = N_VNew_Serial(n, s.ctx);
  for (int i = 0; i < n; ++i) {
    NV_Ith_S(s.y, i) = y0[i];
    NV_Ith_S(s.abstol, i) = tol.absolute.at(i);
  }
  s.mem = CVodeCreate(CV_ADAMS, s.ctx);
  if (!s.mem) throw SolverError(t0, "CVodeCreate failed");
  s.check(CVodeSetErrHandlerFn(s.mem, &Impl::on_error, &s), "CVodeSetErrHandlerFn", t0);
  s.check(CVodeInit(s.mem, &Impl::rhs, t0, s.y), "CVodeInit", t0);
  s.check(CVodeSVtolerances(s.mem, tol.relative, s.abstol), "CVodeSVtolerances", t0);
  s.check(CVodeSetUserData(s.mem, &s), "CVodeSetUserData", t0);
  s.check(CVodeSetMaxNumSteps(s.mem, 100000), "CVodeSetMaxNumSteps", t0);
  // Newton with a dense difference-quotient Jacobian: the driver's PI loop makes the system mildly stiff, and
  // BDF then steps over whole trace segments where Adams would be held to fractions of a second.
  s.nls = SUNNonlinSol_FixedPoint(s.y, 0, s.ctx);
  s.check(CVodeSetNonlinearSolver(s.mem, s.nls), "CVodeSetNonlinearSolver", t0);
  if (system.num_roots() > 0) {
    s.check(CVodeRootInit(s.mem, system.num_roots(), &Impl::roots), "CVodeRootInit", t0);
    s.check(CVodeSetNoInactiveRootWarn(s.mem), "CVodeSetNoInactiveRootWarn", t0);
    root_flags_.assign(system.num_roots(), 0);
  }
}

CvodeIntegrator::~CvodeIntegrator() = default;

bool CvodeIntegrator::advance(double t_out, double t_stop) {
  auto& s = *impl_;
  // CVODE may already stand at the stop time, having stepped there while answering an earlier, nearer t_out;
  // setting the same stop again would be rejected, so it is set once per stop.
  if (t_stop != stop_time_) {
    s.check(CVodeSetStopTime(s.mem, t_stop), "CVodeSetStopTime", t_);
    stop_time_ = t_stop;
  }
  realtype t_reached = t_;
  const int flag = CVode(s.mem, t_out, s.y, &t_reached, CV_NORMAL);
  s.check(flag, "CVode", t_reached);
  t_ = t_reached;
  const double* data = N_VGetArrayPointer(s.y);
  y_.assign(data, data + y_.size());
  if (flag == CV_ROOT_RETURN) {
    s.check(CVodeGetRootInfo(s.mem, root_flags_.data()), "CVodeGetRootInfo", t_);
    return true;
  }
  return false;
}

void CvodeIntegrator::restart(double t, const std::vector<double>& y) {
  auto& s = *impl_;
  const OdeStats so_far = stats();
  before_restarts_ = so_far;
  for (std::size_t i = 0; i < y.size(); ++i) NV_Ith_S(s.y, i) = y[i];
  s.check(CVodeReInit(s.mem, t, s.y), "CVodeReInit", t);
  stop_time_ = std::numeric_limits<double>::quiet_NaN();
  t_ = t;
  y_ = y;
  ++restarts_;
}

OdeStats CvodeIntegrator::stats() const {
  OdeStats st;
  auto* mem = impl_->mem;
  CVodeGetNumSteps(mem, &st.steps);
  CVodeGetNumRhsEvals(mem, &st.rhs_evals);
  CVodeGetNumErrTestFails(mem, &st.error_test_failures);
  CVodeGetNumNonlinSolvConvFails(mem, &st.nonlinear_failures);
  if (!root_flags_.empty()) CVodeGetNumGEvals(mem, &st.root_evals);
  st.steps += before_restarts_.steps;
  st.rhs_evals += before_restarts_.rhs_evals;
  st.error_test_failures += before_restarts_.error_test_failures;
  st.nonlinear_failures += before_restarts_.nonlinear_failures;
  st.root_evals += before_restarts_.root_evals;
  st.restarts = restarts_;
  return st;
}

}  // namespace rollsim
