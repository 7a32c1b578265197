// The registration of the linear tracer (trace_linear.h): the trace of every ray, and the variance-guided
// second trace over the rays adaptive_rays left out (Settings.variance_rays).
#include "passes/trace_linear.h"

#include "render/pass_registry.h"

namespace ssr {

SSR_REGISTER_PASS(TraceLinearPass(false));
SSR_REGISTER_PASS(TraceLinearPass(true));

}  // namespace ssr
