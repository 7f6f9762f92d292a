// Placeholder until --method aaf lands; replaced by its implementation.
#include "core/error.h"
#include "render/methods.h"

namespace wedge::render {

void renderAaf(const MethodContext&, RenderResult&) { throw Error("--method aaf", "not available yet"); }

}  // namespace wedge::render
