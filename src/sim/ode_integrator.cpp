#include "rollsim/sim/ode_integrator.hpp"

#include <cvodes/cvodes.h>
#include <nvector/nvector_serial.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <string>

#include "rollsim/sim/sundials_compat.hpp"

namespace rollsim {

namespace {

// Lean kernels for the vector operations CVODES calls in every step. Our vectors hold 3 to 20 numbers, and
// CVODES calls some 50 operations per step: the serial kernels' case analysis (which of a, b is 1 or -1, which
// operand aliases which) costs more than the arithmetic. These are the same element-wise formulas, in the
// order that makes aliasing harmless (every element is read before it is written), installed in the serial
// vector's operation table so that every clone CVODES makes inherits them.
double* data(N_Vector v) { return NV_DATA_S(v); }
sunindextype length(N_Vector v) { return NV_LENGTH_S(v); }

// z[i] = f(i) for every element.
template <typename F>
void each(N_Vector z, F&& f) {
  double* zd = data(z);
  for (sunindextype i = 0, n = length(z); i < n; ++i) zd[i] = f(i);
}

void linear_sum(sundials::real a, N_Vector x, sundials::real b, N_Vector y, N_Vector z) {
  const double *xd = data(x), *yd = data(y);
  each(z, [&](sunindextype i) { return a * xd[i] + b * yd[i]; });
}
void scale(sundials::real c, N_Vector x, N_Vector z) {
  const double* xd = data(x);
  each(z, [&](sunindextype i) { return c * xd[i]; });
}
void constant(sundials::real c, N_Vector z) {
  each(z, [&](sunindextype) { return c; });
}
void absolute(N_Vector x, N_Vector z) {
  const double* xd = data(x);
  each(z, [&](sunindextype i) { return std::abs(xd[i]); });
}
void inverse(N_Vector x, N_Vector z) {
  const double* xd = data(x);
  each(z, [&](sunindextype i) { return 1.0 / xd[i]; });
}
void add_constant(N_Vector x, sundials::real b, N_Vector z) {
  const double* xd = data(x);
  each(z, [&](sunindextype i) { return xd[i] + b; });
}
void product(N_Vector x, N_Vector y, N_Vector z) {
  const double *xd = data(x), *yd = data(y);
  each(z, [&](sunindextype i) { return xd[i] * yd[i]; });
}
sundials::real weighted_square_sum(N_Vector x, N_Vector w) {
  const double *xd = data(x), *wd = data(w);
  double sum = 0.0;
  for (sunindextype i = 0, n = length(x); i < n; ++i) sum += (xd[i] * wd[i]) * (xd[i] * wd[i]);
  return sum;
}
sundials::real wrms_norm(N_Vector x, N_Vector w) { return std::sqrt(weighted_square_sum(x, w) / static_cast<double>(length(x))); }
int linear_combination(int nv, sundials::real* c, N_Vector* xs, N_Vector z) {
  each(z, [&](sunindextype i) {
    double sum = 0.0;
    for (int j = 0; j < nv; ++j) sum += c[j] * data(xs[j])[i];
    return sum;
  });
  return 0;
}
int scale_add_multi(int nv, sundials::real* a, N_Vector x, N_Vector* ys, N_Vector* zs) {
  const double* xd = data(x);
  for (int j = 0; j < nv; ++j) {
    const double* yd = data(ys[j]);
    each(zs[j], [&](sunindextype i) { return a[j] * xd[i] + yd[i]; });
  }
  return 0;
}
int scale_vector_array(int nv, sundials::real* c, N_Vector* xs, N_Vector* zs) {
  for (int j = 0; j < nv; ++j) scale(c[j], xs[j], zs[j]);
  return 0;
}

// CVODES' name for a return flag. CVodeGetReturnFlagName would do, but it returns a string it malloc'ed, one
// leak per failure; these are the flags CVode and its setters return.
const char* flag_name(int flag) {
  switch (flag) {
    case CV_TOO_MUCH_WORK: return "CV_TOO_MUCH_WORK";
    case CV_TOO_MUCH_ACC: return "CV_TOO_MUCH_ACC";
    case CV_ERR_FAILURE: return "CV_ERR_FAILURE";
    case CV_CONV_FAILURE: return "CV_CONV_FAILURE";
    case CV_LINIT_FAIL: return "CV_LINIT_FAIL";
    case CV_LSETUP_FAIL: return "CV_LSETUP_FAIL";
    case CV_LSOLVE_FAIL: return "CV_LSOLVE_FAIL";
    case CV_RHSFUNC_FAIL: return "CV_RHSFUNC_FAIL";
    case CV_FIRST_RHSFUNC_ERR: return "CV_FIRST_RHSFUNC_ERR";
    case CV_REPTD_RHSFUNC_ERR: return "CV_REPTD_RHSFUNC_ERR";
    case CV_UNREC_RHSFUNC_ERR: return "CV_UNREC_RHSFUNC_ERR";
    case CV_RTFUNC_FAIL: return "CV_RTFUNC_FAIL";
    case CV_NLS_INIT_FAIL: return "CV_NLS_INIT_FAIL";
    case CV_NLS_SETUP_FAIL: return "CV_NLS_SETUP_FAIL";
    case CV_CONSTR_FAIL: return "CV_CONSTR_FAIL";
    case CV_NLS_FAIL: return "CV_NLS_FAIL";
    case CV_MEM_FAIL: return "CV_MEM_FAIL";
    case CV_MEM_NULL: return "CV_MEM_NULL";
    case CV_ILL_INPUT: return "CV_ILL_INPUT";
    case CV_NO_MALLOC: return "CV_NO_MALLOC";
    case CV_BAD_K: return "CV_BAD_K";
    case CV_BAD_T: return "CV_BAD_T";
    case CV_BAD_DKY: return "CV_BAD_DKY";
    case CV_TOO_CLOSE: return "CV_TOO_CLOSE";
    case CV_VECTOROP_ERR: return "CV_VECTOROP_ERR";
    case CV_QRHSFUNC_FAIL: return "CV_QRHSFUNC_FAIL";
    case CV_FIRST_QRHSFUNC_ERR: return "CV_FIRST_QRHSFUNC_ERR";
    case CV_REPTD_QRHSFUNC_ERR: return "CV_REPTD_QRHSFUNC_ERR";
    case CV_UNREC_QRHSFUNC_ERR: return "CV_UNREC_QRHSFUNC_ERR";
    case CV_NO_QUAD: return "CV_NO_QUAD";
    default: return "CVODES error";
  }
}

N_Vector new_vector(int n, SUNContext ctx) {
  N_Vector v = N_VNew_Serial(n, ctx);
  if (!v) return v;
  N_Vector_Ops ops = v->ops;
  ops->nvlinearsum = linear_sum;
  ops->nvscale = scale;
  ops->nvconst = constant;
  ops->nvabs = absolute;
  ops->nvinv = inverse;
  ops->nvaddconst = add_constant;
  ops->nvprod = product;
  ops->nvwrmsnorm = wrms_norm;
  ops->nvwsqrsumlocal = weighted_square_sum;
  ops->nvlinearcombination = linear_combination;
  ops->nvscaleaddmulti = scale_add_multi;
  ops->nvscalevectorarray = scale_vector_array;
  return v;
}

}  // namespace

struct CvodeIntegrator::Impl {
  SUNContext ctx = nullptr;
  void* mem = nullptr;
  N_Vector y = nullptr;
  N_Vector abstol = nullptr;
  N_Vector q = nullptr;
  N_Vector q_abstol = nullptr;
  N_Vector scratch = nullptr;  // for dense output, allocated once
  SUNNonlinearSolver nls = nullptr;
  OdeSystem* system = nullptr;
  std::string last_error;
  std::string model_error;  // what the model threw inside a callback
  sundials::detail::SinkAndUser error_route{&Impl::on_error, this};

  ~Impl() {
    if (mem) CVodeFree(&mem);
    if (nls) SUNNonlinSolFree(nls);
    for (N_Vector v : {y, abstol, q, q_abstol, scratch}) {
      if (v) N_VDestroy(v);
    }
    if (ctx) SUNContext_Free(&ctx);
  }

  // No exception may cross CVODES' C frames: a model that throws (a battery asked for more than it can give)
  // ends the integration with an unrecoverable flag, and its message becomes the SolverError's cause.
  template <typename F>
  static int guarded(void* user, F&& f) {
    auto* self = static_cast<Impl*>(user);
    try {
      return f(*self);
    } catch (const std::exception& e) {
      self->model_error = e.what();
      return -1;
    }
  }
  static int rhs(sundials::real t, N_Vector y, N_Vector ydot, void* user) {
    return guarded(user, [&](Impl& s) { return s.system->rhs(t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot)); });
  }
  static int quad_rhs(sundials::real t, N_Vector y, N_Vector qdot, void* user) {
    return guarded(user, [&](Impl& s) {
      return s.system->quadrature_rhs(t, N_VGetArrayPointer(y), N_VGetArrayPointer(qdot));
    });
  }
  static int roots(sundials::real t, N_Vector y, sundials::real* g, void* user) {
    return guarded(user, [&](Impl& s) {
      s.system->roots(t, N_VGetArrayPointer(y), g);
      return 0;
    });
  }
  // CVODES reports through this instead of printing; the message becomes part of the SolverError.
  static void on_error(const char* function, const char* msg, void* user) {
    static_cast<Impl*>(user)->last_error = std::string(function ? function : "CVODES") + ": " + (msg ? msg : "");
  }

  // The state components with the largest weighted local error estimates (CVodeGetErrWeights times
  // CVodeGetEstLocalErrors, as Cantera's CVodesIntegrator reports them): which part of the model the failing
  // step could not resolve. Empty when CVODES has no step to report on.
  std::string largest_local_errors() const {
    if (!mem || !y) return "";
    const sunindextype n = NV_LENGTH_S(y);
    N_Vector w = N_VClone(y), e = N_VClone(y);
    std::string out;
    if (w && e && CVodeGetErrWeights(mem, w) == CV_SUCCESS && CVodeGetEstLocalErrors(mem, e) == CV_SUCCESS) {
      std::vector<double> weighted(static_cast<std::size_t>(n));
      for (sunindextype i = 0; i < n; ++i) weighted[static_cast<std::size_t>(i)] = std::abs(NV_Ith_S(w, i) * NV_Ith_S(e, i));
      std::vector<std::size_t> order(weighted.size());
      std::iota(order.begin(), order.end(), std::size_t{0});
      std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return weighted[a] > weighted[b]; });
      for (std::size_t k = 0; k < std::min<std::size_t>(3, order.size()); ++k) {
        if (!(weighted[order[k]] > 0.0)) break;
        char v[32];
        std::snprintf(v, sizeof v, "%.3g", weighted[order[k]]);
        out += (k ? ", " : "") + system->state_name(static_cast<int>(order[k])) + " " + v;
      }
    }
    if (w) N_VDestroy(w);
    if (e) N_VDestroy(e);
    return out.empty() ? "" : "; largest weighted local errors: " + out;
  }

  void check(int flag, const char* call, double t) const {
    if (flag < 0) {
      char when[32];
      std::snprintf(when, sizeof when, "%.3f", t);
      const std::string cause = !model_error.empty() ? model_error : last_error;
      const bool stepping = flag == CV_TOO_MUCH_WORK || flag == CV_TOO_MUCH_ACC || flag == CV_ERR_FAILURE ||
                            flag == CV_CONV_FAILURE || flag == CV_NLS_FAIL;
      throw SolverError(t, std::string(call) + " failed at t = " + when + " s: " + flag_name(flag) +
                               (cause.empty() ? "" : " (" + cause + ")") + (stepping ? largest_local_errors() : ""));
    }
  }
};

CvodeIntegrator::CvodeIntegrator(OdeSystem& system, double t0, const std::vector<double>& y0,
                                 const std::vector<double>& q0, const OdeTolerances& tol)
    : impl_(std::make_unique<Impl>()), t_(t0), y_(y0), q_(q0) {
  auto& s = *impl_;
  s.system = &system;
  const int n = system.size();
  const int nq = system.num_quadratures();
  s.check(sundials::create_context(&s.ctx), "SUNContext_Create", t0);
  s.y = new_vector(n, s.ctx);
  s.abstol = new_vector(n, s.ctx);
  s.scratch = new_vector(n, s.ctx);
  for (int i = 0; i < n; ++i) {
    NV_Ith_S(s.y, i) = y0.at(i);
    NV_Ith_S(s.abstol, i) = tol.absolute.at(i);
  }
  s.mem = CVodeCreate(CV_ADAMS, s.ctx);
  if (!s.mem) throw SolverError(t0, "CVodeCreate failed");
  s.check(sundials::set_error_handler(s.ctx, s.mem, &s.error_route), "setting the error handler", t0);
  s.check(CVodeInit(s.mem, &Impl::rhs, t0, s.y), "CVodeInit", t0);
  s.check(CVodeSVtolerances(s.mem, tol.relative, s.abstol), "CVodeSVtolerances", t0);
  s.check(CVodeSetUserData(s.mem, &s), "CVodeSetUserData", t0);
  s.check(CVodeSetMaxNumSteps(s.mem, 100000), "CVodeSetMaxNumSteps", t0);
  s.nls = SUNNonlinSol_FixedPoint(s.y, 0, s.ctx);
  s.check(CVodeSetNonlinearSolver(s.mem, s.nls), "CVodeSetNonlinearSolver", t0);
  if (nq > 0) {
    s.q = new_vector(nq, s.ctx);
    s.q_abstol = new_vector(nq, s.ctx);
    q_offset_ = q0;
    for (int i = 0; i < nq; ++i) {
      NV_Ith_S(s.q, i) = 0.0;
      NV_Ith_S(s.q_abstol, i) = tol.quadrature_absolute.at(i);
    }
    s.check(CVodeQuadInit(s.mem, &Impl::quad_rhs, s.q), "CVodeQuadInit", t0);
    quadrature_relative_ = tol.quadrature_relative;
    s.check(CVodeQuadSVtolerances(s.mem, tol.quadrature_relative, s.q_abstol), "CVodeQuadSVtolerances", t0);
    s.check(CVodeSetQuadErrCon(s.mem, SUNTRUE), "CVodeSetQuadErrCon", t0);
  }
  if (system.num_roots() > 0) {
    s.check(CVodeRootInit(s.mem, system.num_roots(), &Impl::roots), "CVodeRootInit", t0);
    s.check(CVodeSetNoInactiveRootWarn(s.mem), "CVodeSetNoInactiveRootWarn", t0);
    root_flags_.assign(system.num_roots(), 0);
  }
}

CvodeIntegrator::~CvodeIntegrator() = default;

bool CvodeIntegrator::step(double t_stop) {
  auto& s = *impl_;
  // CVODES may already stand at the stop time; setting the same stop again would be rejected, so it is set
  // once per stop (and again after a restart, which clears it).
  if (t_stop != stop_time_) {
    s.check(CVodeSetStopTime(s.mem, t_stop), "CVodeSetStopTime", t_);
    stop_time_ = t_stop;
  }
  sundials::real t_reached = t_;
  const int flag = CVode(s.mem, t_stop, s.y, &t_reached, CV_ONE_STEP);
  // CVODES' fixed-point solver can take a failed callback for a failed iteration and return without a step;
  // a model error is final whatever CVODES made of it.
  if (!s.model_error.empty()) {
    char when[32];
    std::snprintf(when, sizeof when, "%.3f", t_reached);
    throw SolverError(t_reached, std::string("the model failed in the step after t = ") + when + " s: " + s.model_error);
  }
  s.check(flag, "CVode", t_reached);
  if (!(t_reached > t_)) {
    if (++stalls_ > 100) throw SolverError(t_, "CVODES made no progress past t = " + std::to_string(t_) + " s");
  } else {
    stalls_ = 0;
  }
  t_ = t_reached;
  const double* data = N_VGetArrayPointer(s.y);
  y_.assign(data, data + y_.size());
  q_current_ = false;
  if (flag == CV_ROOT_RETURN) {
    s.check(CVodeGetRootInfo(s.mem, root_flags_.data()), "CVodeGetRootInfo", t_);
    return true;
  }
  return false;
}

std::vector<double> CvodeIntegrator::state_at(double t) const {
  auto& s = *impl_;
  s.check(CVodeGetDky(s.mem, t, 0, s.scratch), "CVodeGetDky", t);
  const double* d = N_VGetArrayPointer(s.scratch);
  return std::vector<double>(d, d + y_.size());
}

std::vector<double> CvodeIntegrator::quadratures_at(double t) const {
  auto& s = *impl_;
  std::vector<double> q(q_offset_);
  if (!s.q) return q;
  N_Vector out = N_VClone(s.q);
  const int flag = CVodeGetQuadDky(s.mem, t, 0, out);
  for (std::size_t i = 0; i < q.size(); ++i) q[i] += NV_Ith_S(out, i);
  N_VDestroy(out);
  s.check(flag, "CVodeGetQuadDky", t);
  return q;
}

const std::vector<double>& CvodeIntegrator::quadratures() {
  auto& s = *impl_;
  if (s.q && !q_current_) {
    // CVodeGetQuadDky at the last reached time: after a root return that is the root, not the internal tn.
    s.check(CVodeGetQuadDky(s.mem, t_, 0, s.q), "CVodeGetQuadDky", t_);
    const double* qd = N_VGetArrayPointer(s.q);
    for (std::size_t i = 0; i < q_.size(); ++i) q_[i] = q_offset_[i] + qd[i];
  }
  q_current_ = true;
  return q_;
}

void CvodeIntegrator::restart(double t, const std::vector<double>& y) {
  auto& s = *impl_;
  before_restarts_ = stats();
  quadratures();  // the sums up to t, before the method forgets its history
  for (std::size_t i = 0; i < y.size(); ++i) NV_Ith_S(s.y, i) = y[i];
  s.check(CVodeReInit(s.mem, t, s.y), "CVodeReInit", t);
  if (s.q) {
    // Quadratures restart from zero and their running sums are kept here: CVODES' relative tolerance then
    // bounds each interval's integral, not the ever-growing total (whose step errors would add up).
    q_offset_ = q_;
    N_VConst(0.0, s.q);
    q_current_ = true;
    s.check(CVodeQuadReInit(s.mem, s.q), "CVodeQuadReInit", t);
  }
  stop_time_ = std::numeric_limits<double>::quiet_NaN();
  t_ = t;
  y_ = y;
  ++restarts_;
}

void CvodeIntegrator::set_quadrature_absolute_tolerances(const std::vector<double>& absolute) {
  auto& s = *impl_;
  if (!s.q) return;
  for (std::size_t i = 0; i < absolute.size(); ++i) NV_Ith_S(s.q_abstol, i) = absolute[i];
  s.check(CVodeQuadSVtolerances(s.mem, quadrature_relative_, s.q_abstol), "CVodeQuadSVtolerances", t_);
}

OdeStats CvodeIntegrator::stats() const {
  OdeStats st;
  auto* mem = impl_->mem;
  CVodeGetNumSteps(mem, &st.steps);
  CVodeGetNumRhsEvals(mem, &st.rhs_evals);
  CVodeGetNumErrTestFails(mem, &st.error_test_failures);
  CVodeGetNumNonlinSolvConvFails(mem, &st.nonlinear_failures);
  if (!root_flags_.empty()) CVodeGetNumGEvals(mem, &st.root_evals);
  if (impl_->q) CVodeGetQuadNumRhsEvals(mem, &st.quadrature_evals);
  st.steps += before_restarts_.steps;
  st.rhs_evals += before_restarts_.rhs_evals;
  st.quadrature_evals += before_restarts_.quadrature_evals;
  st.error_test_failures += before_restarts_.error_test_failures;
  st.nonlinear_failures += before_restarts_.nonlinear_failures;
  st.root_evals += before_restarts_.root_evals;
  st.restarts = restarts_;
  return st;
}

}  // namespace rollsim
