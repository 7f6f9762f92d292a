// Multiple axis-aligned filters (Wu et al. 2017) for soft shadows x lens (direct light) and
// indirect x lens, as 6D filters that are products of two flatland 3D filters, one per image
// axis (Sec. 6.1 Fig. 7, Sec. 6.2).
//
// Per pixel and effect, each axis k has N component pairs p (maaf_components.h: eqs. 6-8, 10 and
// the corrected eq. 24), built after the Sec. 6.2 optimisation: the x bandwidth is the smallest of
// the pixel's (1/step), the shadow or indirect wedge's (Omega_y^max / s_min) and the lens
// wedge's (Omega_u^max / s^u_min), and Omega_y^max is tightened to s_min times it.
//
// A sample s at pixel x' with secondary coordinates y_k (light-plane position or bounce
// direction along axis k) and lens coordinates u_k contributes, per axis and component,
//   phi = C_y y + C_u u,  window = exp(-(sigma_y y)^2 / 2) exp(-(sigma_u u)^2 / 2)
// and per pair of components (p on axis 1, q on axis 2) the four products of
// {cos phi_1, sin phi_1} x {cos phi_2, sin phi_2} (eq. 23 on each axis; the product expands
// cos(A1 - phi1) cos(A2 - phi2) of the 6D kernel). Only these (2N-1)^2 accumulations are kept
// per pixel and effect (rgb and the weight alone), never the samples. The image-space filter is
// eq. 21 on axis 1 (image x), then on axis 2 (image y):
//   sum_p c_p mu_p g_p(r) [cos(C_x a) T_cos + sin(C_x a) T_sin],  c_0 = 1, c_p = 2,
// with a = signed world offset (output minus input) along the axis, g_p a unit-integral Gaussian
// of standard deviation 1/sigma_x^p, neighbours rejected across normal (20 degrees) and depth
// discontinuities. The result is the ratio of the filtered rgb and the filtered weight, so a
// constant signal is reproduced exactly.
//
// Sign convention (checked numerically in tests/maaf_test.cpp): all three wedges are of the
// form f(x, y) = g(x + s y) with s > 0 (shadows: x + s y is constant along a ray through an
// occluder; indirect: x + z y; lens: x + s_u u), whose spectrum lies on Omega_y = s Omega_x.
// The paper's eq. 19/22 writes cos(C_x (x - x') + C_y y); evaluated as a convolution at y = 0
// the kernel's argument is -y, so the phase is C_x a - C_y y, which is what is used.
//
// Spatial Gaussians are unit-integral, so that component p peaks at mu_p along Omega_x as eq. 9
// says. Five practical conventions, each measured against a reference (docs/maaf.md):
//  - Weights: eq. 10 weighs component p by a Gaussian over the double wedge, the spectrum of a
//    Gaussian light of std sqrt(area) / 2. Without eq. 20's windows the light and lens samples
//    are drawn from the light's and the aperture's own densities, so the kernel over a sample's
//    (y, u) is sum_p mu_p cos(C_y y + C_u u): a Fourier series that reproduces the sheared light
//    profile only if mu_p is that density's spectrum at (C_y, C_u). By default mu_p is that
//    spectrum: lightSpectrum (sinc x sinc of a parallelogram's edges projected on the axis, a
//    triangle's triangleSpectrum, or the area-weighted sum of its parts' for a group of lights,
//    scene::lightGroups) times discSpectrum (2 J1(w) / w) for the lens;
//    discSpectrum for the cosine-weighted bounce.
//    Checked numerically on a flatland penumbra (unbounded window, tests/filter_test.cpp,
//    MaafWeights): N = 3's bias is 0.030 (eq. 10) vs 0.026 under a square light and 0.109 vs
//    0.037 under a 4:1 strip seen along its length, whose sqrt(area) misstates the extent.
//    Renders: sponza relMSE -17%, conference -3%, cornell -2%. `--maaf-weights eq10` restores eq. 10.
//  - Fourier widths: the paper's Gaussians have the box half-widths of eq. 8 as standard
//    deviation, which attenuates the wedge's edge by e^-1/2 and over-blurs; the spatial Fourier
//    std is sqrt(6) times the half-width, the factor AAF's kernel exp(-3 r^2 Omega^2) implies.
//  - Windows: eq. 20 weighs light and lens samples by Gaussians of std 1/sigma_y, 1/sigma_u;
//    for the uniform parallelogram lights and disc apertures here that re-shapes the light and
//    the bokeh (biased); by default samples are weighted by cos/sin only (eq. 20 without g;
//    the Monte Carlo density is the light's own profile). `apertureWindows` restores them.
//  - Components that fit: the central component is K = 2N-1 times wider in space than AAF's
//    filter; a window of R pixels resolves it only where K <= Omega_x R step / 3, so fewer
//    components are used where the wedge's bandwidth is low (soft shadows: the axis-aligned
//    filter, N = 1); truncated wide components are biased next to silhouettes.
//  - Symmetric support: an outer component's modulated kernel uses a neighbour only if its
//    mirror is usable too, so a one-sided window (a shadow next to its occluder) does not turn
//    the modulation into a DC offset.
//
// Focal plane (NOTES: the known failure): where the defocus slope changes sign within the
// detection window the wedge degenerates to a box; those pixels use the central component only
// (N = 1, the axis-aligned filter) and get adaptive samples at the AAF rates.
#pragma once


#include <cstddef>
#include <functional>
#include <string>
#include <type_traits>
#include <vector>

#include "core/buffers.h"
#include "filter/filter_frames.h"
#include "filter/maaf_components.h"
#include "filter/wedge_field.h"

namespace wedge::filter {

constexpr int kMaafMaxPairs = 4;  // 7 components
constexpr int kMaafMaxWindowRadius = 128;  // pixels (MaafOptions::maxRadius)

/// Trivially constructible (value-initialise with {} for zeros), so that the per-pixel images
/// of parameters are first written where they are computed.
struct MaafAxis {
    int pairs;  // components in use on this axis (1 = central only)
    float cx[kMaafMaxPairs], sx[kMaafMaxPairs], weight[kMaafMaxPairs];  // weight = c_p mu_p
    float cy[kMaafMaxPairs], sy[kMaafMaxPairs];
    float cu[kMaafMaxPairs], su[kMaafMaxPairs];
};
struct MaafPixel {
    MaafAxis axis[2];
};

enum class MaafWeights {
    Sampling,  // the spectra of the light's, the lens's and the bounce's sampling densities (default)
    Eq10,      // eq. 10's Gaussian over the double wedge (a Gaussian light)
    Unit,      // every component weighs 1
};

/// "sampling", "eq10" or "unit"; throws Error naming `flag` otherwise.
MaafWeights parseMaafWeights(const std::string& name, const std::string& flag);

/// E[cos(w y)] for y the projection onto the unit `axis` of a point uniform on `light`, taken
/// from its centroid: the spectrum the direct components' weights follow (Weights, above).
double lightSpectrum(double w, const ViewGeometry::Light& light, const Vec3f& axis);

/// mu_p of component c under `weights`; samplingSpectrum() gives the spectrum of the densities
/// the samples are drawn from at the component's centre (called only for MaafWeights::Sampling).
template <class SamplingSpectrum>
double componentWeight(const MaafComponent& c, MaafWeights weights, SamplingSpectrum&& samplingSpectrum) {
    switch (weights) {
    case MaafWeights::Eq10: return c.mu;
    case MaafWeights::Unit: return 1.0;
    case MaafWeights::Sampling: break;
    }
    return samplingSpectrum();
}

struct MaafOptions {
    int pairs = 3;               // N: 2N-1 components per axis (--maaf-components 5)
    float mu = 2.f;              // Omega_y^max = mu / sigma_light (as AAF)
    float lensOmega = 6.f;       // Omega_u^max, lens = Gaussian of a third of its radius
    float indirectOmega = 2.8f;  // Omega_h^max of a Lambertian receiver
    int maxRadius = 10;          // pixels
    float normalCos = kSameSurfaceCos;
    float planeDistance = 2.f;   // pixel sizes off the tangent plane
    float zMinPixels = 10.f;  // clamp of the bounce distance z_min, in pixel sizes (NOTES: scene-scale constant)
    float bandwidthRatio = 3.f;  // reject neighbours whose central width differs by more than this factor
    bool focalFallback = true;
    // Practical conventions (measured, see the file comment and docs/maaf.md):
    float spatialScale = 2.449490f;  // Fourier std of the spatial Gaussians = sqrt(6) x the half-width (AAF's kernel)
    float pixelBandwidth = 2.449490f;  // Omega_x never exceeds this / (world size of a pixel)
    bool apertureWindows = false;    // eq. 20's Gaussian windows over the light and the lens
    MaafWeights weights = MaafWeights::Sampling;  // mu_p
    bool fitComponents = true;       // use only as many components as the window resolves:
    /// the fit keeps the central component's 3 sigma (its actual width, spatialScale included)
    /// within this share of the window (maxRadius). 1 / sqrt(6) (4.1 px of the 10-px window) is
    /// the rule as first written, which left spatialScale out; the whole window (1) measured worse
    /// (docs/maaf.md, "The fit rule").
    float fitShare = 0.40824829f;
    // Outer components in the direct light's (shadow x lens) filter as well as the indirect
    // light's; without them the direct filter is the central, axis-aligned one everywhere.
    bool shadowComponents = true;
    // Shadow components only where the shadow slopes on the pixel's surface along its row and
    // column, maxRadius pixels each way, span at most this factor (max / min); 0: everywhere (the
    // paper's pipeline). The outer components reproduce one occluder's sheared profile; where the
    // filter's reach holds occluders at other slopes (grids-shadows' two layers of bars, the
    // bunny's contact shadow) they measured as bias (docs/maaf.md, "The direct light's effective
    // centre").
    float shadowSpan = 0.f;
    // Whether the direct light is filtered by MAAF at all. Without (AAF's pipeline, which filters
    // it with AAF's filter when it has no outer components) its effect is central-only everywhere
    // and carries no widths: nothing reads them (computing them took 0.005-0.011 s of a
    // 512x512 cornell render on two threads, and 5 MB of fresh memory).
    bool directEffect = true;
    // Indirect outer components only where the nearest bounce hit is at least this share of the
    // clamp zMinPixels (in pixel sizes) away; 0 admits every pixel (the paper's pipeline). Closer
    // hits (a corner, a contact) vary faster than the clamped wedge says, and there the outer
    // components measured as bias (issue 28; docs/maaf.md, "Outer components near contacts").
    float outerMinBounce = 0.f;
    // By object id (FrameBuffers::object): 1 where the object moves over the shutter
    // (scene::Scene::objectMoves); a pixel whose primary surface moves uses the central component
    // only. MAAF's analysis (Sec. 4-5) has no time axis: a moving surface's samples are its points
    // at different times, and outer components placed by its still wedge measured as bias (the
    // held-out docs/moving-blinds.json, the moving slats: MAAF 0.000219 against AAF's 0.000205
    // relMSE, 0.000205 with this rule; docs/maaf.md, "Moving surfaces").
    std::vector<uint8_t> movingObjects;
    bool symmetricOuter = true;      // outer components only where a neighbour's mirror is accepted too
    bool mirrorSurfaceCuts = true;   // as AafOptions::mirrorSurfaceCuts, for every component
};

/// The most pairs N whose central component (K = 2N - 1, Fourier std spatialScale Omega_x / K
/// along an axis of `step` world units per pixel) keeps its 3 sigma within o.fitShare x
/// o.maxRadius pixels;
/// at least 1. (The pairs used are also at most o.pairs.)
int maafFitPairs(double omegaX, double step, const MaafOptions& o);

/// One effect's components for every pixel, computed on demand: a MaafPixel is 232 bytes, and
/// storing one per pixel and effect cost a 720x720 render 240 MB of freshly zeroed pages (7% of
/// its CPU time, `perf record`), more than computing them three times. Kept per pixel: what the
/// neighbours of a pixel, the accumulator's layout and the filter of a central-only axis need
/// (the central width, weight and component count of each axis, 20 bytes).
class MaafEffect {
public:
    /// Writes pixel p's components along axis k.
    using Compute = std::function<void(size_t p, int k, MaafAxis& out)>;
    /// With `region`, the stored widths only where it is non-zero; elsewhere pairs() is 1 and
    /// centralSx() 0 (a caller that reads only the region, and has no outer components outside it).
    MaafEffect(int width, int height, Compute compute, const Image<uint8_t>* region = nullptr);
    /// Central-only everywhere, with no widths: an effect MAAF does not filter (AAF's pipeline
    /// filters it with AAF's filter). Stores nothing; pairs() is 1 and axis() the bare centre.
    MaafEffect(int width, int height) : m_width(width), m_height(height) {}
    /// Stored parameters (tests, tiny images); `params` must outlive this.
    explicit MaafEffect(const Image<MaafPixel>& params);

    int width() const { return m_width; }
    int height() const { return m_height; }
    MaafAxis axis(size_t p, int k) const {
        MaafAxis a{};
        if (m_compute) m_compute(p, k, a);
        else a.pairs = 1;
        return a;
    }
    MaafPixel pixel(size_t p) const { return MaafPixel{{axis(p, 0), axis(p, 1)}}; }
    /// sx[0] of pixel p along axis k (the central component's spatial bandwidth).
    float centralSx(size_t p, int k) const { return m_central.empty() ? 0.f : m_central[p].sx[k]; }
    int pairs(size_t p, int k) const { return m_central.empty() ? 1 : m_central[p].pairs[k]; }
    /// What the image-space filter reads of pixel p's axis k: the stored central width and
    /// weight where the axis uses the central component only (most pixels), else axis(p, k).
    MaafAxis filterAxis(size_t p, int k) const {
        if (m_central.empty() || m_central[p].pairs[k] > 1) return axis(p, k);
        MaafAxis a{};
        a.pairs = 1;
        a.sx[0] = m_central[p].sx[k];
        a.weight[0] = m_central[p].weight[k];
        return a;
    }

private:
    struct Central {
        float sx[2], weight[2];
        uint8_t pairs[2];
    };
    int m_width, m_height;
    Compute m_compute;
    LargeVector<Central> m_central;
};

struct MaafParams {
    MaafEffect direct, indirect;
    Image1f fallback;  // 1 where the pixel uses the central component only (focal plane, a moving surface)
};

/// Components for every pixel, effect and axis. The result refers to fb, wedges, frames, view
/// and shadowAgree, which must outlive it (MaafEffect computes a pixel's axes again when they
/// are asked for). With `region`, both effects' stored widths only there (MaafEffect), whose
/// frames are then all `frames` needs. `shadowAgree` (shadowSlopesAgree; null: everywhere):
/// where the direct effect may have outer components.
MaafParams maafParams(const FrameBuffers& fb, const WedgeField& wedges, const FilterFrames& frames,
                      const ViewGeometry& view, const MaafOptions& options, const Image<uint8_t>* region = nullptr,
                      const Image<uint8_t>* shadowAgree = nullptr);

/// The light whose spectrum weighs the direct light's outer components: the only one the
/// filters see (a lamp of many coplanar triangles is one, scene::lightGroups), if it is planar
/// (a sphere's samples have no one plane to take y in: its direct filter is central, as with
/// several); null otherwise.
const ViewGeometry::Light* singlePlanarLight(const ViewGeometry& view);

/// 1 where the shadow slopes of pixel p and of the pixels on its surface along its row and
/// column, within o.maxRadius, span at most o.shadowSpan (MaafOptions::shadowSpan); 0 where p
/// has no shadow wedge.
Image<uint8_t> shadowSlopesAgree(const FrameBuffers& fb, const WedgeField& wedges, const MaafOptions& options);

/// 1 where maafParams' direct effect has outer components on either axis, decided pixel by
/// pixel with the pixel's own direct frame (filter::directFrame), without the frames image or
/// the effect (as maafIndirectOuter for the indirect light).
Image<uint8_t> maafDirectOuter(const FrameBuffers& fb, const WedgeField& wedges, const ViewGeometry& view,
                               const MaafOptions& options, const Image<uint8_t>* shadowAgree);

/// 1 where maafParams' indirect effect has outer components on either axis (pairs() > 1),
/// decided from the pixel's wedge and its frame's steps alone, without the components, the
/// frames image or the effect: where MAAF's sparse pipeline computes them (render/method_maaf.cpp).
Image<uint8_t> maafIndirectOuter(const FrameBuffers& fb, const WedgeField& wedges, const ViewGeometry& view,
                                 const MaafOptions& options);

/// 1 within `radius` pixels along both image axes (a (2 radius + 1)^2 box) of a non-zero pixel of `mask`.
Image<uint8_t> dilateBox(const Image<uint8_t>& mask, int radius);

/// Per-pixel accumulations of eq. 23 for one effect, (2N-1)^2 bands x (values..., weight).
/// Indirect light accumulates rgb with weight 1; direct light accumulates the visibility with
/// the unoccluded luminance as weight, so that the filtered ratio is the visibility (multiplied
/// afterwards by the closed-form unoccluded irradiance). Each pixel stores only the bands its
/// own components use ((2 N_1 - 1) x (2 N_2 - 1)), so memory and work follow the wedge.
class MaafAccumulator {
public:
    /// With `region`, storage only for the pixels where it is non-zero (the others have no bands
    /// and must not be read: a filter whose `only` pixels' windows lie within the region).
    MaafAccumulator(const MaafEffect& params, int pairs, int values, const Image<uint8_t>* region = nullptr);
    /// Upper bound of the memory for every pixel using all components (for the memory check).
    static size_t bytes(int width, int height, int pairs, int values) {
        return size_t(width) * height * size_t(sqr(2 * pairs - 1)) * size_t(values + 1) * sizeof(float);
    }
    size_t allocatedBytes() const { return m_data.size() * sizeof(float) + m_offset.size() * sizeof(size_t); }

    /// Adds one sample: `value` (m_values floats) with weight `weight` (the filter returns the
    /// weighted mean of the values), secondary coordinates y[2] and lens coordinates u[2] (per
    /// axis). `params` must be the pixel's own. Not synchronised: one thread per pixel.
    void add(size_t pixel, const float* value, float weight, const float y[2], const float u[2], const MaafPixel& params);
    /// Divides a pixel's accumulations by its sample count (per-pixel means).
    void scale(size_t pixel, float s);
    /// Sets the mean of a pixel that uses the central component only on both axes, without
    /// windows: eq. 23 is then the plain mean of value x weight and of weight.
    void setCentral(size_t pixel, const float* meanValueTimesWeight, float meanWeight);
    const float* pixel(size_t p) const { return &m_data[m_offset[p]]; }
    int bands(size_t p, int axis) const { return axis == 0 ? m_bands1[p] : m_bands2[p]; }

    /// Eq. 21 on image x then image y: the filtered values divided by the filtered weight (one
    /// value channel is replicated to rgb). Pixels without a surface or weight keep `fallback`,
    /// and so do those outside `only` where it is given (non-zero: filter this pixel): the first
    /// pass then runs only where the second reads it.
    Image3f filter(const MaafEffect& params, const FrameBuffers& fb, const Image<AxisFrame>& frames,
                   const Image3f& fallback, const MaafOptions& options, const Image<uint8_t>* only = nullptr) const;

private:
    int m_width, m_height, m_pairs, m_values, m_channels;
    LargeVector<uint8_t> m_bands1, m_bands2;
    LargeVector<size_t> m_offset;
    LargeVector<float> m_data;
};

/// Where a receiver's unoccluded irradiance from light `l` is centred on the light: the mean
/// light point weighted by cos(receiver) cos(light) / r^2, relative to the light's centre along
/// its axes A and B (8 x 8 midpoints over each part, uniform in area). The direct light's
/// accumulation is a ratio, the visibility weighted by each sample's unoccluded light over the
/// unoccluded light (eq. 23 with value V and weight L), so the light profile its components
/// reconstruct is the light's density times that weight, not the light's uniform density that
/// the weights mu_p and the phases C_y y take it to be. A light seen obliquely is brighter on its
/// near side, and that profile's centroid lies off the light's centre: measured from the centre,
/// every outer component's phase C_y y carries C_y y0 = s C_x y0, a shift of the reconstructed
/// shadow by s y0 away from the light (the central component has no phase and does not move).
/// Measured on a plank's 5.6-px penumbra under a 0.8-wide light 2.5 to the side (docs/maaf.md,
/// "The direct light's effective centre"): the outer components' shadow 0.18 px off, this
/// centroid predicting 0.24 px. A flatland penumbra under a uniform, unweighted light
/// (analysis/penumbra.h) has no such shift, which is one reason the renders disagreed with it.
Vec2f lightIrradianceCentre(const ViewGeometry::Light& l, const Vec3f& p, const Vec3f& n);

/// A sample as MAAF's accumulation reads it: 36 bytes instead of the 64 of a SampleRecord. The
/// samples of pixels with outer components are kept in this form until the pixel is accumulated
/// (render/method_maaf.cpp: the initial ones of every pixel, or those pixels' traced again).
/// The filter never sees samples; only the accumulations reach it. Trivially constructible, so
/// that allocating the records touches no memory: the sampling threads first-touch their own
/// pages.
struct MaafSample {
    float indirect[3];     // demodulated one-bounce radiance
    float lightA, lightB;  // light point relative to the light's centre, along its axes A and B
    float unoccluded;      // the direct sample's luminance without visibility (0: light behind)
    uint16_t lens[2];      // lens position, unorm16 of (l + 1) / 2
    uint16_t bounce[2];    // bounce direction, octahedral, unorm16
    uint8_t light, visible;  // light: the ViewGeometry light (a group of scene lights)
    int8_t slot;           // the pixel's surface slot (PixelStats) the sample went to, -1: none
    uint8_t pad;

    static MaafSample pack(const SampleRecord& r, const ViewGeometry& view, int slot);
    /// What the accumulation needs: the light point relative to the light's centre along the
    /// direct frame's axes, the bounce direction along the indirect frame's, and the lens
    /// position along both (lens y is along camera up, axis 2 is image down, hence its sign).
    /// `lightCentre`: the origin of the light's coordinates, relative to its centre along axes A
    /// and B (lightIrradianceCentre: where the receiver's unoccluded light is centred).
    void coordinates(const ViewGeometry& view, const AxisFrame& direct, const AxisFrame& indirect, float yDirect[2],
                     float yIndirect[2], float u[2], Vec2f lightCentre = {0.f, 0.f}) const;
    float visibility() const { return (visible & 1) ? 1.f : 0.f; }
};
static_assert(sizeof(MaafSample) == 36 && std::is_trivially_default_constructible_v<MaafSample>);

}  // namespace wedge::filter
