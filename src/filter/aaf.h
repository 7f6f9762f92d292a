// Axis-aligned filtering (AAF) of soft shadows, indirect light and defocus together, following
// Mehta et al. 2012 (soft shadows; aaf-wang-2013-report.md ch. 3 and the authors' constants in
// NOTES.md), Mehta et al. 2013 (diffuse indirect; report ch. 4) and the reconstructed MYRD14
// rules for combining them with depth of field (NOTES.md).
//
// Bandwidths (world units^-1, along the receiver; d = world size of a pixel):
//   shadow   Omega_s = min(mu / (sigma s2), 1 / (d (1 + s2)))      (NOTES, AAF 2012 code; mu = 2)
//   indirect Omega_i = Omega_h^max / z_min, Omega_h^max = 2.8        (report eq. 4.4 / NOTES)
//   defocus  Omega_u = Omega_u^max / (min |s_u| d), Omega_u^max = 2/sigma_u, sigma_u = 1/3 (lens = Gaussian of A/3)
//   combined Omega_x = min(1/d, Omega_s or Omega_i, Omega_u)         (NOTES: the widest of the widths)
// Kernel exp(-3 r^2 Omega_x^2), cut at r Omega_x > 1, separable along the image axes
// (report eq. 3.7), r in world space within the light plane (direct) or the tangent plane; a
// window cut by another surface on one side is cut on the other too (AafOptions::mirrorSurfaceCuts).
// Sampling rates: direct per NOTES (AAF 2012 code), indirect per report eq. 4.6, both with the
// combined Omega_x; a lens rate of the same form as the shadow rate.
#pragma once


#include "core/buffers.h"
#include "filter/filter_frames.h"
#include "filter/wedge_field.h"

namespace wedge::filter {

struct AafOptions {
    float mu = 2.f;              // bandwidth factor of the light (NOTES)
    float lensOmega = 6.f;       // 2 / sigma_u with the lens a Gaussian of sigma_u = 1/3 aperture radii
    float indirectOmega = 2.8f;  // Omega_h^max for Lambertian receivers
    int maxRadius = 10;          // pixels (NOTES: separable, radius 10 px)
    float normalCos = kSameSurfaceCos;  // reject neighbours whose normals differ by 20 degrees or more
    float bandwidthRatio = 3.f;  // reject neighbours whose bandwidth differs by more than this factor
    float planeDistance = 2.f;   // reject neighbours farther than this many pixel sizes off the tangent plane
    // A neighbour cut off by another surface (another object, a normal 20 degrees off, off the
    // tangent plane) also removes its mirror image from the window, so that the window stays
    // symmetric about the pixel: a one-sided window averages the surface's gradient towards the
    // silhouette (a contact shadow, indirect light darkening into a corner) into bias. Pixels
    // whose samples saw several surfaces keep one-sided windows: they need their primary surface's
    // neighbours. Measured (512x512, relMSE against 1024-spp references): grids -16%, bunny -3%,
    // sponza -1%, conference -1%, cornell and cornell-sphere +0.5%.
    bool mirrorSurfaceCuts = true;
    float zMinPixels = 10.f;  // clamp of the bounce distance z_min, in pixel sizes (NOTES: scene-scale constant)
};

/// AAF's slope prefilter: a pixel keeps its own slopes and those without take them from a
/// 10-px window (NOTES, AAF 2012 code).
inline WedgeOptions aafWedgeOptions() {
    WedgeOptions wo;
    wo.radius = 5;
    wo.fillOnly = true;
    return wo;
}

/// Per-pixel AAF parameters.
struct AafParams {
    Image1f omegaDirect, omegaIndirect;  // combined bandwidths, world^-1 (0: unbounded)
    Image1f sppDirect, sppIndirect, sppLens;  // required samples per pixel by each rate
};

/// Combined bandwidths and sampling rates for every pixel.
AafParams aafParams(const FrameBuffers& fb, const WedgeField& wedges, const ViewGeometry& view, const AafOptions& o);

/// Separable spatially varying Gaussian (report eq. 3.7) of `signal` with per-pixel bandwidth
/// `omega`, neighbour rejection as in AafOptions, distances measured in the frames' planes.
/// With `weight`, each pixel counts in proportion to it (sum w q s / sum w q): the visibility
/// is filtered weighted by the unoccluded light each pixel's samples saw.
Image3f aafFilter(const Image3f& signal, const Image1f& omega, const FrameBuffers& fb, const Image<AxisFrame>& frames,
                  const AafOptions& o, const Image1f* weight = nullptr);

/// Filter width in pixels for a bandwidth (the debug "beta" map): 1 / (Omega * step), capped.
float aafRadiusPixels(float omega, float step, int maxRadius);

}  // namespace wedge::filter
