// Placeholder until --method atrous lands; replaced by its implementation.
#include "core/error.h"
#include "render/methods.h"

namespace wedge::render {

void renderAtrous(const MethodContext&, RenderResult&) { throw Error("--method atrous", "not available yet"); }

}  // namespace wedge::render
