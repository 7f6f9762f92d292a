// Debug maps (--aov DIR): single-channel planes as colour-ramp PNGs, in the spirit of the
// figures of aaf-soft-shadow-project-report.md (spp, filter width), plus the unfiltered image.
#pragma once

#include <string>

#include "core/buffers.h"
#include "filter/wedge_field.h"

namespace wedge::render {

/// Writes `dir/name.png` mapping [lo, hi] (hi <= lo: the plane's own finite range) to a ramp.
void writeAov(const std::string& dir, const std::string& name, const Image1f& plane, float lo = 0, float hi = 0);

/// The maps AAF and MAAF share, named `prefix_...`: spp, the slopes s1 and s2 (0 where no
/// occluder), the defocus slopes, and the unfiltered image.
void writeWedgeAovs(const std::string& dir, const std::string& prefix, const FrameBuffers& fb,
                    const filter::WedgeField& wedges);

}  // namespace wedge::render
