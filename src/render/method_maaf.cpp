// Placeholder until --method maaf lands; replaced by its implementation.
#include "core/error.h"
#include "render/methods.h"

namespace wedge::render {

void renderMaaf(const MethodContext&, RenderResult&) { throw Error("--method maaf", "not available yet"); }

}  // namespace wedge::render
