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

}  // namespace wedge::render
