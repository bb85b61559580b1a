// What differs between SUNDIALS 6 and 7 for the CVODES driver: the real type, the context's constructor, errors.
#pragma once

#include <cvodes/cvodes.h>
#include <sundials/sundials_config.h>
#include <sundials/sundials_context.h>
#include <sundials/sundials_types.h>

// SUNDIALS 6 (Debian 12 ships 6.4.1, which the project builds and tests against) and 7 (written from the 7.x
// headers and release notes; built and tested against 7.5.0 from source by hand, see the README). 7 removed `realtype` (use `sunrealtype`, present since 6.0), takes a
// SUNComm instead of a void* in SUNContext_Create, and moved error handlers from each integrator
// (CVodeSetErrHandlerFn) to the context (SUNContext_PushErrHandler), with a new handler signature.
#if SUNDIALS_VERSION_MAJOR >= 7
#include <sundials/sundials_errors.h>
#include <sundials/sundials_logger.h>
#endif

namespace rollsim::sundials {

using real = sunrealtype;

/// Creates a serial context; returns SUNDIALS' flag (0 on success).
inline int create_context(SUNContext* ctx) {
#if SUNDIALS_VERSION_MAJOR >= 7
  // 7 sends warnings (a step below round-off) to the context's logger, which prints them on stdout, where they
  // would corrupt a --json or CSV output; 6 sent them to the error handler, which keeps them. An empty name leaves
  // the logger's stdout in place, so the warnings go to the null device.
  int flag = SUNContext_Create(SUN_COMM_NULL, ctx);
  SUNLogger logger = nullptr;
  if (flag == 0) flag = SUNContext_GetLogger(*ctx, &logger);
  if (flag == 0) flag = SUNLogger_SetWarningFilename(logger, "/dev/null");
  return flag;
#else
  return SUNContext_Create(nullptr, ctx);
#endif
}

/// What an error handler is told, in either version: the function that failed and its message.
using ErrorSink = void (*)(const char* function, const char* message, void* user);

namespace detail {
struct SinkAndUser {
  ErrorSink sink;
  void* user;
};
#if SUNDIALS_VERSION_MAJOR >= 7
inline void forward_error(int /*line*/, const char* function, const char* /*file*/, const char* message,
                          SUNErrCode /*code*/, void* data, SUNContext /*ctx*/) {
  const auto* s = static_cast<const SinkAndUser*>(data);
  s->sink(function, message, s->user);
}
#else
inline void forward_error(int /*code*/, const char* /*module*/, const char* function, char* message, void* data) {
  const auto* s = static_cast<const SinkAndUser*>(data);
  s->sink(function, message, s->user);
}
#endif
}  // namespace detail

/// Routes CVODES' error messages to `route->sink` instead of stderr. `route` must outlive the integrator. SUNDIALS 7
/// attaches handlers to the context (its default one, which prints, is removed first); 6 to the CVODES memory.
inline int set_error_handler(SUNContext ctx, void* cvode_mem, detail::SinkAndUser* route) {
#if SUNDIALS_VERSION_MAJOR >= 7
  (void)cvode_mem;
  const int flag = SUNContext_ClearErrHandlers(ctx);
  return flag != 0 ? flag : SUNContext_PushErrHandler(ctx, &detail::forward_error, route);
#else
  (void)ctx;
  return CVodeSetErrHandlerFn(cvode_mem, &detail::forward_error, route);
#endif
}

}  // namespace rollsim::sundials
