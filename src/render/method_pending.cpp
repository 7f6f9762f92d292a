#include "core/error.h"
#include "render/methods.h"
namespace wedge::render {
void renderAaf(const MethodContext&, RenderResult&) { throw Error("--method aaf", "not available yet"); }
void renderMaaf(const MethodContext&, RenderResult&) { throw Error("--method maaf", "not available yet"); }
void renderAtrous(const MethodContext&, RenderResult&) { throw Error("--method atrous", "not available yet"); }
}
