// The contract between sampling and filtering. Filters never see rays, scenes or Embree: they
// get FrameBuffers (equal-sized named per-pixel planes), ViewGeometry (camera and light frames,
// as plain numbers), and, where a filter needs them, the individual SampleRecords of a pixel.
// Given the same buffers a filter produces the same image.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/image.h"

namespace wedge {

/// One path sample of the MAAF paper (Sec. 6.2): primary lens ray, one light sample with a shadow
/// ray, one cosine-weighted bounce lit by its own light sample. World space. 64 bytes.
struct SampleRecord {
    Vec3f direct;      // demodulated direct light (irradiance/pi, visibility included), rgb
    Vec3f indirect;    // demodulated one-bounce indirect radiance, rgb
    Vec3f lightPoint;  // the sampled point on the light
    Vec3f bounceDir;   // unit bounce direction; zero when no bounce was traced
    Vec2f lens;        // lens position on the unit disc (x along camera right, y along camera up)
    uint32_t light = 0;    // the ViewGeometry light (a group of scene lights) the light sample is on
    float unoccluded = 0;  // luminance of the direct sample without visibility (its weight in visibility filters)
};
static_assert(sizeof(SampleRecord) == 64);

/// Camera and light frames the filters use to turn samples into filter coordinates.
struct ViewGeometry {
    int width = 0, height = 0;
    Vec3f cameraPosition, forward, right, up;  // up = image "up" (image y grows along -up)
    float focalPixels = 1;     // focal length in pixels: (H/2) / tan(fov_y/2)
    float apertureRadius = 0;  // world
    float focusDistance = 1;   // world, along forward
    /// A light as the filters see it: one scene light, or a group of them that is one planar
    /// light (scene::lightGroups), over whose outline the samples are uniform.
    struct Light {
        /// A scene light of the group: the parallelogram or triangle (corner, corner + edge1,
        /// corner + edge2), in world space, and its share of the group's area.
        struct Part {
            Vec3f corner, edge1, edge2;
            bool triangle = false;
            float share = 1;
        };
        Vec3f center, normal, axisA, axisB;  // center: the centroid; axisA/B: orthonormal in the light plane
        std::vector<Part> parts;
        float sigma = 1;                     // Gaussian model of the light: sqrt(area)/2
        float power = 0;                     // luminance of radiance x area
        /// A sphere light: no plane and no parts; its plane as the filters see it is the one
        /// facing each receiver (filter_frames.cpp), and MAAF's direct filter is central.
        bool sphere = false;
    };
    std::vector<Light> lights;

    /// World size of one pixel at depth z along forward.
    float pixelFootprint(float depth) const { return depth / focalPixels; }
    /// Defocus slope of a hit at depth z (NOTES, MYRD14): pixels per unit lens coordinate.
    float defocusSlope(float depth) const { return defocusSlopeAt(1.f / std::max(depth, 1e-6f), 1.f / focusDistance); }
    /// The same from 1 / max(z, 1e-6) and 1 / focusDistance, for a caller that has the one
    /// already and keeps the other out of its loop (the same value).
    float defocusSlopeAt(float inverseDepth, float inverseFocus) const {
        return apertureRadius * focalPixels * (inverseDepth - inverseFocus);
    }
};

/// cos 20 degrees: two normals closer than this are one surface, for the pixel's surface slots
/// (render/pixel_stats.h) and for every filter's neighbour test.
constexpr float kSameSurfaceCos = 0.9396926f;
/// A pixel whose primary surface covers at least this fraction of its samples saw one surface
/// only (FrameBuffers::coverage); below it, a mixed pixel.
constexpr float kFullCoverage = 0.999f;

/// Per-pixel planes. A pixel's samples are split by surface (object, normal within 20 degrees,
/// tangent plane): the G-buffer planes (albedo, normal, position, depth, object) and the
/// demodulated light (direct, indirect) describe the samples on the pixel's primary surface (the
/// one most of its samples hit), `coverage` is their fraction; `other[k]` describe the further
/// surfaces the pixel sees (a silhouette, a defocused edge, the tubes of a defocused chair), `rest`
/// is the Monte Carlo colour of all other samples. For the Monte Carlo estimate
///   color = emission + coverage albedo (direct + indirect) + sum_k other[k].coverage other[k].albedo
///           (other[k].direct + other[k].indirect) + rest
/// holds exactly. Filters filter the primary surface; composeFiltered() gives the other surfaces
/// the filtered light of a neighbour whose primary surface they are.
struct FrameBuffers {
    /// Surfaces besides the primary one that a pixel keeps apart; samples on any further surface
    /// go to `rest`, unfiltered. Measured, 1 -> 2 (512x512, relMSE against 1024-spp references):
    /// aaf conference 0.000665 -> 0.000642, sponza 0.000828 -> 0.000804; maaf 0.000799 ->
    /// 0.000779, 0.001057 -> 0.001031; cornell, grids, bunny, cornell-sphere within 1%. The
    /// defocused chairs of conference (tubes whose facets are separate surfaces) and sponza's
    /// columns are where pixels see three or more. Cost: MAAF's peak at 720x720 on conference
    /// 769 -> 906 MB (a third PixelStats slot and these planes), time unchanged.
    static constexpr int kOtherSurfaces = 2;
    int width = 0, height = 0;
    Image3f color, emission, direct, indirect, albedo, normal, position, rest;
    Image1f depth, spp, object, coverage, variance;  // variance: of the pixel mean's luminance (demodulated light)
    // Direct light factored as in AAF (report eq. 3.2): direct = directUnoccluded * visibility.
    Image3f directUnoccluded;  // closed-form unoccluded irradiance / pi of all lights at the primary surface
    Image1f visibility;        // sum of luminance(direct_s) / sum of unoccluded_s over the primary samples
    Image1f unoccluded;        // mean unoccluded_s over the primary samples (the visibility's weight)
    // The further surfaces a pixel sees, by slot order (coverage 0 where there is none).
    struct OtherSurface {
        Image3f albedo, normal, position, direct, indirect;  // as the primary surface's planes
        Image1f object, coverage;
    };
    std::array<OtherSurface, kOtherSurfaces> other;
    // Slope statistics of the initial samples (AAF/MAAF prefilter input).
    Image1f d1;            // mean distance receiver -> light centre over occluded shadow rays
    Image1f sMax, sMin;    // shadow slopes s1 = max d1/d2min - 1, s2 = min d1/d2max - 1; 0/inf when unoccluded
    Image1f occluded;      // fraction of shadow rays that hit an occluder
    Image1f lightSigma;    // the smallest Gaussian model (sigma) among the lights of the occluded
                           // shadow rays: the size of the light that casts the pixel's shadow; inf where none
    Image1f zMin, zMax;    // bounce distances
    Image1f bounced;       // fraction of the initial samples whose bounce ray hit a surface
    Image1f suMin, suMax;  // defocus slopes, pixels per unit lens coordinate
    Image1f defocus;       // smallest |defocus slope| over all of the pixel's initial samples, every
                           // surface and misses (0 where they straddle the focal plane)
    Image1f footprint;     // world size of one pixel at the hit

    FrameBuffers() = default;
    FrameBuffers(int w, int h);

    /// Primary-surface light only, other surfaces and rest as sampled (Monte Carlo).
    Vec3f compose(size_t p, const Vec3f& directPrimary, const Vec3f& indirectPrimary) const {
        Vec3f c = emission[p] + albedo[p] * (directPrimary + indirectPrimary) * coverage[p] + rest[p];
        for (const OtherSurface& o : other) c += o.albedo[p] * (o.direct[p] + o.indirect[p]) * o.coverage[p];
        return c;
    }
    /// The final image from filtered primary-surface light: each of a pixel's other surfaces takes
    /// the filtered direct and indirect light of the nearest pixel (within 2) whose primary
    /// surface it is (its own samples' light where there is none).
    Image3f composeFiltered(const Image3f& direct, const Image3f& indirect) const;
    /// The filtered demodulated light of each surface a pixel keeps, as composeFiltered uses it:
    /// [0] the primary surface's, direct + indirect; [1 + k] other[k]'s, the filtered light of
    /// the nearest pixel (within 2) whose primary surface it is, or its own samples' light.
    std::array<Image3f, 1 + kOtherSurfaces> surfaceLight(const Image3f& direct, const Image3f& indirect) const;

    /// Every plane with its EXR channel names ("direct.R", "normal.X", "depth", ...).
    void forEachPlane(const std::function<void(const std::string& name, int channels, const float* data)>& fn) const;
};

}  // namespace wedge
