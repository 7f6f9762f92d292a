#include "core/buffers.h"

namespace wedge {

FrameBuffers::FrameBuffers(int w, int h)
    : width(w), height(h), color(w, h), emission(w, h), direct(w, h), indirect(w, h), albedo(w, h), normal(w, h),
      position(w, h), offSurface(w, h), depth(w, h), spp(w, h), object(w, h), coverage(w, h), variance(w, h),
      directUnoccluded(w, h), visibility(w, h), unoccluded(w, h), d1(w, h), sMax(w, h), sMin(w, h),
      occluded(w, h), zMin(w, h), zMax(w, h), suMin(w, h), suMax(w, h), footprint(w, h) {}

void FrameBuffers::forEachPlane(const std::function<void(const std::string&, int, const float*)>& fn) const {
    auto v3 = [&](const char* n, const Image3f& img) { fn(n, 3, &img[0].x); };
    auto v1 = [&](const char* n, const Image1f& img) { fn(n, 1, img.data()); };
    v3("emission", emission);
    v3("direct", direct);
    v3("indirect", indirect);
    v3("albedo", albedo);
    v3("normal", normal);
    v3("position", position);
    v3("offsurface", offSurface);
    v1("depth", depth);
    v1("spp", spp);
    v1("object", object);
    v1("coverage", coverage);
    v1("variance", variance);
    v3("direct_unoccluded", directUnoccluded);
    v1("visibility", visibility);
    v1("unoccluded", unoccluded);
    v1("slope.d1", d1);
    v1("slope.s1", sMax);
    v1("slope.s2", sMin);
    v1("slope.occluded", occluded);
    v1("slope.zmin", zMin);
    v1("slope.zmax", zMax);
    v1("slope.sumin", suMin);
    v1("slope.sumax", suMax);
    v1("footprint", footprint);
}

}  // namespace wedge
