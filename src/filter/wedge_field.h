// Per-pixel double-wedge parameters for the a-priori filters (AAF and MAAF share them): the
// slope bounds of the soft-shadow wedge (s1 = max d1/d2min - 1, s2 = min d1/d2max - 1), of the
// indirect wedge (z_min, z_max of the bounce hits) and of the defocus wedge (s_u, pixels per
// unit lens coordinate), prefiltered over an image window.
//
// The prefilter takes the max of the upper and the min of the lower bounds over neighbours on
// the same surface (same object, normals within 20 degrees). That is robust where few of a
// pixel's 16 samples saw an occluder (NOTES: MAAF reimplementation, 5x5 window) and it fills
// pixels whose samples saw none from their neighbours (NOTES: AAF 2012 code, 10 px window).
// With several lights, the light whose shadow a pixel is in sets its wedge's light size, the
// smallest among those its occluded shadow rays (or its neighbours') aimed at: the visibility of
// an unoccluded light is constant and adds no bandwidth.
#pragma once

#include "core/buffers.h"

namespace wedge::filter {

struct WedgeField {
    Image1f s1, s2;        // shadow slope bounds; s2 = +inf where no occluder was seen in the window
    Image1f lightSigma;    // the size (Gaussian sigma) of the smallest light whose shadow the window
                           // saw, taken with s1 and s2; +inf where s2 is
    Image1f zMin, zMax;    // bounce distances; +inf where no bounce hit
    Image1f suMin, suMax;  // defocus slopes (pixels per unit lens coordinate)
    Image1f focalStraddle; // 1 where defocus slopes within `focalRadius` take both signs (focal plane)
};

struct WedgeOptions {
    int radius = 2;          // window half-size for the slope prefilter
    bool fillOnly = false;   // true: keep a pixel's own slopes when it has them (AAF), only fill empty ones
    // Otherwise (max / min over the window, MAAF) a pixel keeps its own shadow slopes when at
    // least this fraction of its shadow rays hit an occluder: many occluder spans give a
    // trustworthy slope range, a few (a penumbra's edge, a contact shadow) do not. > 1: never.
    float ownShadowOccluded = 2.f;
    // Likewise a pixel keeps its own bounce distances when, on average over the window's pixels
    // on its surface, at least this fraction of the initial samples' bounce rays hit a surface
    // (a well-sampled hemisphere). > 1: never (the window's min / max).
    float ownBounceHit = 2.f;
    int fillRadius = 0;      // > radius: pixels still without a wedge take it from this wider window
    int focalRadius = 10;    // window half-size of the focal-plane (sign change) detection
    float normalCos = kSameSurfaceCos;  // cos 20 degrees
};

WedgeField prefilterWedges(const FrameBuffers& fb, const WedgeOptions& options);

/// True when neighbour q may share filter information with pixel p (same object, normals
/// within the threshold, both hit a surface).
inline bool sameSurface(const FrameBuffers& fb, size_t p, size_t q, float normalCos) {
    if (fb.object[p] < 0 || fb.object[q] != fb.object[p]) return false;
    return dot(fb.normal[p], fb.normal[q]) >= normalCos;
}

/// True when a hit at `offset` from p's (either way round: q - p or p - q) lies within
/// `planeDistance` pixel footprints of p's tangent plane (a box face in front of a parallel wall
/// of the same object is off it). For filters that need the offset anyway.
inline bool onTangentPlane(const FrameBuffers& fb, size_t p, const Vec3f& offset, float planeDistance) {
    return std::abs(dot(offset, fb.normal[p])) <= planeDistance * fb.footprint[p];
}
/// The same for pixel q's hit.
inline bool onTangentPlane(const FrameBuffers& fb, size_t p, size_t q, float planeDistance) {
    return onTangentPlane(fb, p, fb.position[q] - fb.position[p], planeDistance);
}

}  // namespace wedge::filter
