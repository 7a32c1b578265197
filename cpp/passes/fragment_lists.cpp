#include "passes/fragment_lists.h"

#include "render/pass_registry.h"

namespace ssr {

SSR_REGISTER_PASS(FragmentListsPass());

}  // namespace ssr
