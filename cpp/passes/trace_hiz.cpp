// The registration of the Hi-Z tracer (trace_hiz.h): the trace of every ray, and the variance-guided
// second trace over the rays adaptive_rays left out (Settings.variance_rays).
#include "passes/trace_hiz.h"

#include "render/pass_registry.h"

namespace ssr {

SSR_REGISTER_PASS(TraceHizPass(false));
SSR_REGISTER_PASS(TraceHizPass(true));

}  // namespace ssr
