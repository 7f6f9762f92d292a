// Per-pixel axes of the image-space filters. The 4D/6D filters are products of two flatland
// filters (MAAF Sec. 6.1, Fig. 7), one per image axis; each needs the world direction that an
// image-axis step moves along and the world length of one pixel step:
//  - direct light: the step projected into the plane of the light (AAF measures receiver
//    distances "with the component along the light normal removed"), so that the receiver
//    coordinate x_k and the light coordinate y_k lie along the same world direction and the
//    occluder relation x + s y = const holds (s = d1/d2 - 1);
//  - indirect light: the step in the receiver's tangent plane, with bounce directions measured
//    along the same axes (y_k = omega . t_k), so that x + z y = const for a reflector at z.
// The lens coordinates of each axis are u_1 = lens.x (camera right), u_2 = -lens.y (image down).
#pragma once

#include "core/buffers.h"

namespace wedge::filter {

struct AxisFrame {
    Vec3f axis[2];  // unit world directions of image +x and +y steps (orthonormalised)
    float step[2];  // world length of one pixel step along each axis
};

struct FilterFrames {
    Image<AxisFrame> direct, indirect;
    int light = 0;  // the light whose plane the direct frames use
};

/// withDirect = false leaves `direct` empty (a caller that filters only the indirect light
/// with these frames: MAAF in AAF's pipeline). With `where`, only the pixels where it is
/// non-zero get their frames (the others keep the image's default: a caller that reads only
/// those, MAAF's sparse components).
FilterFrames computeFrames(const FrameBuffers& fb, const ViewGeometry& view, bool withDirect = true,
                           const Image<uint8_t>* where = nullptr);

/// Pixel p's indirect frame, as computeFrames gives it, computed alone.
AxisFrame indirectFrame(const FrameBuffers& fb, const ViewGeometry& view, size_t p);
/// Pixel p's direct frame, as computeFrames gives it, computed alone.
AxisFrame directFrame(const FrameBuffers& fb, const ViewGeometry& view, size_t p);
/// At least both steps of pixel p's indirect frame, for less work than the frame (a quick
/// rejection of pixels whose steps are too short for something).
float indirectStepBound(const FrameBuffers& fb, const ViewGeometry& view, size_t p);

/// The light the direct-light filters take their plane and bandwidth from: the most powerful.
int dominantLight(const ViewGeometry& view);

}  // namespace wedge::filter
