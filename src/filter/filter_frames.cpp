#include "filter/filter_frames.h"

#include "core/parallel.h"

namespace wedge::filter {

int dominantLight(const ViewGeometry& view) {
    int best = 0;
    for (size_t i = 1; i < view.lights.size(); ++i)
        if (view.lights[i].power > view.lights[best].power) best = int(i);
    return best;
}

namespace {

/// Orthonormal pair from two step vectors (keeps the first direction), with their lengths.
AxisFrame makeFrame(const Vec3f& s1, const Vec3f& s2, const Vec3f& fallback1, const Vec3f& planeNormal) {
    AxisFrame f;
    float l1 = length(s1);
    Vec3f a1 = l1 > 0 ? s1 / l1 : fallback1;
    Vec3f t2 = s2 - a1 * dot(a1, s2);
    float l2 = length(t2);
    Vec3f a2 = l2 > 1e-12f ? t2 / l2 : normalize(cross(planeNormal, a1));
    if (dot(a2, s2) < 0) a2 = -a2;
    f.axis[0] = a1;
    f.axis[1] = a2;
    f.step[0] = std::max(l1, 1e-12f);
    f.step[1] = std::max(std::abs(dot(a2, s2)), 1e-12f);
    return f;
}

}  // namespace

namespace {

/// World steps s1, s2 of one pixel step along image x and y in pixel p's tangent plane; false
/// where the pixel has no surface.
bool tangentSteps(const FrameBuffers& fb, const ViewGeometry& view, size_t p, Vec3f& s1, Vec3f& s2) {
    const Vec3f n = fb.normal[p];
    const float depth = fb.depth[p];
    if (fb.object[p] < 0 || depth <= 0) return false;
    // dP/dx for a pinhole ray D = forward + ... (D . forward = 1) hitting the tangent plane:
    // dP = (depth / f) (e - D (n . e) / (n . D)), e = right or down.
    const Vec3f down = -view.up;
    Vec3f P = fb.position[p];
    Vec3f D = (P - view.cameraPosition) / depth;
    float nD = dot(n, D);
    float lenD = length(D);
    if (std::abs(nD) < 0.1f * lenD) nD = std::copysign(0.1f * lenD, nD == 0 ? 1.f : nD);  // grazing: cap the stretch
    float scale = depth / view.focalPixels;
    s1 = (view.right - D * (dot(n, view.right) / nD)) * scale;
    s2 = (down - D * (dot(n, down) / nD)) * scale;
    return true;
}

}  // namespace

float indirectStepBound(const FrameBuffers& fb, const ViewGeometry& view, size_t p) {
    const Vec3f n = fb.normal[p];
    const float depth = fb.depth[p];
    if (fb.object[p] < 0 || depth <= 0) return 1.f;
    // |s_k| = scale |e - D (n . e) / (n . D)| <= scale (1 + |D| |n| / |n . D|) for a unit e
    // (the camera's right and down), with n . D capped as tangentSteps caps it; a 1% margin for
    // the rounding of either.
    const Vec3f D = (fb.position[p] - view.cameraPosition) / depth;
    const float lenD = length(D);
    const float nD = std::max(std::abs(dot(n, D)), 0.1f * lenD);
    return 1.01f * (depth / view.focalPixels) * (1.f + lenD * length(n) / std::max(nD, 1e-30f));
}

AxisFrame indirectFrame(const FrameBuffers& fb, const ViewGeometry& view, size_t p) {
    Vec3f s1, s2;
    if (!tangentSteps(fb, view, p, s1, s2)) return {{view.right, -view.up}, {1, 1}};
    return makeFrame(s1, s2, view.right, fb.normal[p]);
}

namespace {

/// Pixel p's direct frame from its tangent steps: the steps projected on the light's plane (a
/// sphere light's: the one facing this receiver).
AxisFrame directFrameFromSteps(const FrameBuffers& fb, const ViewGeometry& view, int light, size_t p, const Vec3f& s1,
                               const Vec3f& s2) {
    Vec3f lp = view.lights.empty() ? Vec3f(0, 1, 0) : view.lights[light].normal;
    Vec3f lx = view.lights.empty() ? Vec3f(1, 0, 0) : view.lights[light].axisA;
    if (!view.lights.empty() && view.lights[light].sphere) {
        lp = normalize(view.lights[light].center - fb.position[p]);
        lx = normalize(cross(lp, std::abs(lp.x) < 0.9f ? Vec3f(1, 0, 0) : Vec3f(0, 1, 0)));
    }
    Vec3f p1 = s1 - lp * dot(lp, s1), p2 = s2 - lp * dot(lp, s2);
    return makeFrame(p1, p2, lx, lp);
}

}  // namespace

AxisFrame directFrame(const FrameBuffers& fb, const ViewGeometry& view, size_t p) {
    Vec3f s1, s2;
    if (!tangentSteps(fb, view, p, s1, s2)) return {{view.right, -view.up}, {1, 1}};
    return directFrameFromSteps(fb, view, dominantLight(view), p, s1, s2);
}

FilterFrames computeFrames(const FrameBuffers& fb, const ViewGeometry& view, bool withDirect, const Image<uint8_t>* where) {
    FilterFrames ff;
    if (withDirect) ff.direct = Image<AxisFrame>(fb.width, fb.height);
    ff.indirect = Image<AxisFrame>(fb.width, fb.height);
    ff.light = dominantLight(view);
    const Vec3f down = -view.up;
    parallelRows(fb.height, [&](int y) {
        for (int x = 0; x < fb.width; ++x) {
            size_t p = size_t(y) * fb.width + x;
            if (where && !(*where)[p]) continue;
            Vec3f s1, s2;
            if (!tangentSteps(fb, view, p, s1, s2)) {
                if (withDirect) ff.direct[p] = {{view.right, down}, {1, 1}};
                ff.indirect[p] = {{view.right, down}, {1, 1}};
                continue;
            }
            ff.indirect[p] = makeFrame(s1, s2, view.right, fb.normal[p]);
            if (withDirect) ff.direct[p] = directFrameFromSteps(fb, view, ff.light, p, s1, s2);
        }
    });
    return ff;
}

}  // namespace wedge::filter
