// Debug maps (--aov DIR): single-channel planes as colour-ramp PNGs, in the spirit of the
// figures of aaf-soft-shadow-project-report.md (spp, filter width), plus the unfiltered image.
#pragma once

#include <string>

#include "core/image.h"

namespace wedge::render {

/// Writes `dir/name.png` mapping [lo, hi] (hi <= lo: the plane's own finite range) to a ramp.
void writeAov(const std::string& dir, const std::string& name, const Image1f& plane, float lo = 0, float hi = 0);

}  // namespace wedge::render
