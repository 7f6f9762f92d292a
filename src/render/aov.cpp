#include "render/aov.h"

#include <filesystem>

#include "io/image_io.h"

namespace wedge::render {

void writeAov(const std::string& dir, const std::string& name, const Image1f& plane, float lo, float hi) {
    if (hi <= lo) {
        lo = kInf;
        hi = -kInf;
        for (size_t i = 0; i < plane.size(); ++i)
            if (std::isfinite(plane[i]) && std::abs(plane[i]) < 1e29f) {
                lo = std::min(lo, plane[i]);
                hi = std::max(hi, plane[i]);
            }
        if (!(hi > lo)) { lo = 0; hi = 1; }
    }
    io::writePngHeat((std::filesystem::path(dir) / (name + ".png")).string(), plane, lo, hi);
}

void writeWedgeAovs(const std::string& dir, const std::string& prefix, const FrameBuffers& fb,
                    const filter::WedgeField& wedges) {
    Image1f s2(fb.width, fb.height);
    for (size_t i = 0; i < s2.size(); ++i) s2[i] = wedges.s2[i] < kInf ? wedges.s2[i] : 0.f;
    writeAov(dir, prefix + "_spp", fb.spp);
    writeAov(dir, prefix + "_s1", wedges.s1);
    writeAov(dir, prefix + "_s2", s2);
    writeAov(dir, prefix + "_defocus_min", wedges.suMin);
    writeAov(dir, prefix + "_defocus_max", wedges.suMax);
    writeAov(dir, prefix + "_defocus_b", fb.defocus);  // the defocus filter's circle of confusion
    writeAov(dir, prefix + "_coverage", fb.coverage, 0.f, 1.f);  // the primary surface's share
    Image1f rest(fb.width, fb.height);
    for (size_t i = 0; i < rest.size(); ++i) {
        rest[i] = fb.object[i] < 0 ? 0.f : 1.f - fb.coverage[i];
        for (const auto& o : fb.other) rest[i] -= o.coverage[i];
    }
    writeAov(dir, prefix + "_rest_share", rest, 0.f, 1.f);  // samples on no kept surface (further surfaces, misses)
    io::writePng((std::filesystem::path(dir) / (prefix + "_unfiltered.png")).string(), fb.color);
}

}  // namespace wedge::render
