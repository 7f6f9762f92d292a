#include "filter/maaf.h"

#include <cmath>

#include <memory>

#include "core/error.h"
#include "core/parallel.h"
#include "filter/maaf_components.h"

namespace wedge::filter {

namespace {

constexpr float kInvSqrt2Pi = 0.39894228f;

struct AxisInputs {
    bool yWedge = false;
    double omegaY = 1, sMin = 1, sMax = 1;  // secondary (light or bounce) wedge
    bool lens = false;
    double suMin = 0, suMax = 0;            // lens wedge, world units per lens unit (signed)
    double omegaU = 6;
    double step = 1;                        // world size of a pixel along the axis
    bool fallback = false;                  // the central component only (focal plane; several lights)
    // The density y is sampled from: `light` seen along `axis` (the samples' y are their
    // coordinates from its centroid), or, without a light, the unit disc of a cosine-weighted
    // bounce.
    const ViewGeometry::Light* light = nullptr;
    Vec3f axis{0.f};
};

}  // namespace

MaafWeights parseMaafWeights(const std::string& name, const std::string& flag) {
    if (name == "sampling") return MaafWeights::Sampling;
    if (name == "eq10") return MaafWeights::Eq10;
    if (name == "unit") return MaafWeights::Unit;
    throw Error(flag, "expected sampling, eq10 or unit, got '" + name + "'");
}

/// A part's characteristic function about the light's centroid is its own times e^{iwd}, d its
/// centre's offset; a parallelogram's own is real.
double lightSpectrum(double w, const ViewGeometry::Light& light, const Vec3f& axis) {
    if (w == 0) return 1;  // the central component's (a density integrates to one)
    double sum = 0;
    for (const auto& part : light.parts) {
        const double x0 = dot(part.corner - light.center, axis), e1 = dot(part.edge1, axis), e2 = dot(part.edge2, axis);
        sum += part.share * (part.triangle ? triangleSpectrumAt(w, x0, x0 + e1, x0 + e2)
                                           : std::cos(w * (x0 + 0.5 * (e1 + e2))) * parallelogramSpectrum(w, e1, e2));
    }
    return sum;
}

namespace {

/// The spectrum of the densities a pixel's samples are drawn from at component c's centre: the
/// light's (or the bounce's) along y, times the lens's along u (maaf.h, "Weights").
double samplingSpectrum(const MaafComponent& c, const AxisInputs& in) {
    double mu = in.light ? lightSpectrum(c.cy, *in.light, in.axis) : discSpectrum(c.cy);
    return in.lens ? mu * discSpectrum(c.cu) : mu;
}

}  // namespace

int maafFitPairs(double omegaX, double step, const MaafOptions& o) {
    const double fitRadius = double(o.fitShare) * o.maxRadius;
    const int kFit = int(std::floor(o.spatialScale * omegaX * fitRadius * step / 3.0 + 1e-6));
    return std::max(1, (kFit + 1) / 2);
}

namespace {

/// What an axis's components follow from its inputs (buildAxis): the lens wedge with its sign
/// folded into u, the x bandwidth and the number of pairs the window fits.
struct AxisFit {
    double suLo = 0, suHi = 0, uSign = 1;
    bool straddle = false;
    double omegaX = 0;
    int pairs = 1;
};

AxisFit fitAxis(const AxisInputs& in, const MaafOptions& o) {
    AxisFit f;
    // Lens wedge, with the sign folded into u (eq. 24 assumes 0 < s^u_min <= s^u_max).
    f.suLo = in.suMin;
    f.suHi = in.suMax;
    if (in.lens && f.suHi < 0) {
        f.suLo = -in.suMax;
        f.suHi = -in.suMin;
        f.uSign = -1;
    }
    f.straddle = in.lens && f.suLo < 0;
    if (f.straddle) {  // the focal plane crosses the pixel's lens samples: a box in (Omega_x, Omega_u)
        f.suHi = std::max(std::abs(f.suLo), std::abs(f.suHi));
        f.suLo = 0;
    }
    // Sec. 6.2: the x bandwidth is the smallest of the pixel's and the two wedges'.
    f.omegaX = o.pixelBandwidth / in.step;
    f.omegaX = std::min(f.omegaX, in.omegaY / in.sMin);
    if (in.lens && f.suLo > 0) f.omegaX = std::min(f.omegaX, in.omegaU / f.suLo);
    f.pairs = (in.fallback || f.straddle) ? 1 : o.pairs;
    // The window resolves Fourier widths down to about 3 / (R step): use only as many components
    // as keep the central one's 3 sigma within R = fitShare maxRadius pixels. Its Fourier std is
    // spatialScale Omega_x / K (maafComponents: sx = (Om / s_min) / K = Omega_x / K), so
    // 3 K / (spatialScale Omega_x step) <= R, K <= spatialScale Omega_x R step / 3.
    if (o.fitComponents) f.pairs = std::min(f.pairs, maafFitPairs(f.omegaX, in.step, o));
    return f;
}

/// The components an axis uses (1 where the signal has no wedge: no occluder, no bounce hit).
int axisPairs(const AxisInputs& in, const MaafOptions& o) { return in.yWedge ? fitAxis(in, o).pairs : 1; }

MaafAxis buildAxis(const AxisInputs& in, const MaafOptions& o) {
    const int maxRadius = o.maxRadius;
    MaafAxis ax{};
    const float sxFloor = float(1.0 / (maxRadius * in.step));  // primal std of maxRadius pixels
    if (!in.yWedge) {
        // No wedge (no occluder, no bounce hit): the signal is smooth; the widest filter.
        ax.pairs = 1;
        ax.sx[0] = sxFloor;
        ax.weight[0] = 1;
        return ax;
    }
    const AxisFit fit = fitAxis(in, o);
    const double suLo = fit.suLo, suHi = fit.suHi, uSign = fit.uSign, omegaX = fit.omegaX;
    const int n = fit.pairs;
    // Omega_y tightened to s_min times the x bandwidth (Sec. 6.2).
    WedgeShape w;
    w.omegaYMax = std::min(in.omegaY, in.sMin * omegaX);
    w.sMin = in.sMin;
    w.sMax = std::max(in.sMax, in.sMin);
    w.lens = in.lens;
    w.suMin = suLo;
    w.suMax = suHi;
    w.omegaUMax = in.omegaU;
    MaafComponent comps[kMaafMaxPairs];
    maafComponents(n, w, comps);
    ax.pairs = n;
    for (int p = 0; p < n; ++p) {
        const MaafComponent& c = comps[p];
        ax.cx[p] = float(c.cx);
        ax.sx[p] = std::max(float(c.sx) * o.spatialScale, sxFloor);
        ax.weight[p] = float((p == 0 ? 1.0 : 2.0) * componentWeight(c, o.weights, [&] { return samplingSpectrum(c, in); }));
        ax.cy[p] = float(c.cy);
        ax.cu[p] = in.lens ? float(uSign * c.cu) : 0.f;
        ax.sy[p] = o.apertureWindows ? float(c.sy) : 0.f;  // 0: no window
        ax.su[p] = o.apertureWindows && in.lens ? float(c.su) : 0.f;
    }
    return ax;
}

}  // namespace

MaafEffect::MaafEffect(int width, int height, Compute compute, const Image<uint8_t>* region)
    : m_width(width), m_height(height), m_compute(std::move(compute)), m_central(size_t(width) * height) {
    parallelRows(height, [&](int y) {
        for (int x = 0; x < width; ++x) {
            size_t p = size_t(y) * width + x;
            if (region && !(*region)[p]) {
                m_central[p] = Central{{0.f, 0.f}, {0.f, 0.f}, {1, 1}};
                continue;
            }
            for (int k = 0; k < 2; ++k) {
                MaafAxis a;
                m_compute(p, k, a);
                m_central[p].sx[k] = a.sx[0];
                m_central[p].weight[k] = a.weight[0];
                m_central[p].pairs[k] = uint8_t(a.pairs);
            }
        }
    });
}

MaafEffect::MaafEffect(const Image<MaafPixel>& params)
    : MaafEffect(params.width(), params.height(), [&params](size_t p, int k, MaafAxis& out) { out = params[p].axis[k]; }) {}

namespace {

/// Whether pixel p uses the central component only (MaafParams::fallback): at the focal plane,
/// or where its primary surface moves over the shutter (MaafOptions::movingObjects).
bool centralOnly(const FrameBuffers& fb, const WedgeField& wf, bool lens, const MaafOptions& o, size_t p) {
    if (fb.object[p] < 0) return false;
    const size_t object = size_t(fb.object[p]);
    if (object < o.movingObjects.size() && o.movingObjects[object]) return true;
    return o.focalFallback && lens && (wf.focalStraddle[p] > 0 || (wf.suMin[p] < 0 && wf.suMax[p] > 0));
}

/// Whether pixel p (footprint d) has no indirect outer components for its nearest bounce hit:
/// a pixel that sees surfaces within a few pixel sizes (a corner, a contact) has light that
/// varies faster than its clamped wedge says, and outer components placed by that wedge
/// measured as bias (MaafOptions::outerMinBounce).
bool nearBounce(const WedgeField& wf, const MaafOptions& o, size_t p, float d) {
    return wf.zMin[p] < o.outerMinBounce * o.zMinPixels * d;
}

/// The indirect light's inputs of pixel p's axis k: the bounce wedge in the tangent plane (z
/// clamped to zMinPixels pixel sizes); the bounce is a cosine-weighted direction. `footprint`
/// and `fallback` are the pixel's (as the prefilter saw them); false where it has no surface.
bool indirectInputs(const WedgeField& wf, const AxisFrame& frame, float object, float footprint, bool fallback,
                    bool lens, size_t p, int k, const MaafOptions& o, AxisInputs& in) {
    if (object < 0) return false;
    in.lens = lens;
    in.omegaU = o.lensOmega;
    in.fallback = fallback;
    float d = std::max(footprint, 1e-12f);
    in.step = frame.step[k];
    in.yWedge = wf.zMin[p] < kInf;
    in.omegaY = o.indirectOmega;
    in.sMin = std::max(wf.zMin[p], o.zMinPixels * d);
    if (nearBounce(wf, o, p, d)) in.fallback = true;
    in.sMax = std::max(wf.zMax[p], float(in.sMin));
    in.suMin = wf.suMin[p] * in.step;
    in.suMax = wf.suMax[p] * in.step;
    return true;
}

/// The direct light's inputs of pixel p's axis k: the shadow wedge in the light plane.
/// The outer components reproduce the sheared profile of one light (their weights are its
/// spectrum, their y its coordinates): with several lights (groups), whose samples share a
/// pixel's accumulations, the direct filter is the central component (axis-aligned). Measured
/// on a floor, a box and a plank under a large and a small parallelogram (16 spp, 384x384,
/// against 512-spp MC): the outer components gave relMSE 0.00495, worse than MC's 0.00278.
/// False where it has no surface.
bool directInputs(const WedgeField& wf, const AxisFrame& frame, float object, bool fallback, bool lens,
                  const ViewGeometry::Light* single, const Image<uint8_t>* agree, size_t p, int k, const MaafOptions& o,
                  AxisInputs& in) {
    if (object < 0) return false;
    in.lens = lens;
    in.omegaU = o.lensOmega;
    in.fallback = fallback || !single || !o.shadowComponents || (agree && !(*agree)[p]);
    in.step = frame.step[k];
    in.yWedge = wf.s2[p] < kInf;
    in.omegaY = o.mu / wf.lightSigma[p];  // the light whose shadow this is (wedge_field.h)
    in.sMin = std::max(wf.s2[p], 1e-4f);
    in.sMax = std::max(wf.s1[p], wf.s2[p]);
    in.suMin = wf.suMin[p] * in.step;
    in.suMax = wf.suMax[p] * in.step;
    in.light = single;  // with several lights the weights are unused (central only)
    in.axis = frame.axis[k];
    return true;
}

}  // namespace

const ViewGeometry::Light* singlePlanarLight(const ViewGeometry& view) {
    return view.lights.size() == 1 && !view.lights.front().sphere ? &view.lights.front() : nullptr;
}

Image<uint8_t> shadowSlopesAgree(const FrameBuffers& fb, const WedgeField& wf, const MaafOptions& o) {
    const int W = fb.width, H = fb.height;
    Image<uint8_t> agree(W, H);
    parallelRows(H, [&](int y) {
        for (int x = 0; x < W; ++x) {
            const size_t p = size_t(y) * W + x;
            if (!(wf.s2[p] < kInf)) continue;
            float lo = wf.s2[p], hi = std::max(wf.s1[p], wf.s2[p]);
            auto visit = [&](int qx, int qy) {
                if (qx < 0 || qy < 0 || qx >= W || qy >= H) return;
                const size_t q = size_t(qy) * W + qx;
                if (!(wf.s2[q] < kInf) || !sameSurface(fb, p, q, o.normalCos)) return;
                lo = std::min(lo, wf.s2[q]);
                hi = std::max(hi, std::max(wf.s1[q], wf.s2[q]));
            };
            for (int d = -o.maxRadius; d <= o.maxRadius; ++d) {
                visit(x + d, y);
                visit(x, y + d);
            }
            agree[p] = hi <= o.shadowSpan * std::max(lo, 1e-4f);
        }
    });
    return agree;
}

Image<uint8_t> maafDirectOuter(const FrameBuffers& fb, const WedgeField& wf, const ViewGeometry& view, const MaafOptions& o,
                               const Image<uint8_t>* agree) {
    const int W = fb.width, H = fb.height;
    const bool lens = view.apertureRadius > 0;
    const ViewGeometry::Light* single = singlePlanarLight(view);
    Image<uint8_t> outer(W, H);
    if (o.pairs < 2 || !o.shadowComponents || !o.directEffect || !single) return outer;
    parallelRows(H, [&](int y) {
        for (int x = 0; x < W; ++x) {
            const size_t p = size_t(y) * W + x;
            // What needs no frame first: no surface, no shadow wedge, the focal plane, slopes
            // that disagree (directInputs would make it central).
            if (fb.object[p] < 0 || !(wf.s2[p] < kInf) || (agree && !(*agree)[p])) continue;
            const bool fallback = centralOnly(fb, wf, lens, o, p);
            if (fallback) continue;
            const AxisFrame frame = directFrame(fb, view, p);
            for (int k = 0; k < 2 && !outer[p]; ++k) {
                AxisInputs in;
                if (directInputs(wf, frame, fb.object[p], fallback, lens, single, agree, p, k, o, in))
                    outer[p] = axisPairs(in, o) > 1;
            }
        }
    });
    return outer;
}

Image<uint8_t> maafIndirectOuter(const FrameBuffers& fb, const WedgeField& wf, const ViewGeometry& view, const MaafOptions& o) {
    const int W = fb.width, H = fb.height;
    const bool lens = view.apertureRadius > 0;
    Image<uint8_t> outer(W, H);
    if (o.pairs < 2) return outer;
    parallelRows(H, [&](int y) {
        for (int x = 0; x < W; ++x) {
            const size_t p = size_t(y) * W + x;
            // What needs no frame first: no surface, no bounce hit, the focal plane, a near hit.
            if (fb.object[p] < 0 || !(wf.zMin[p] < kInf)) continue;
            const bool fallback = centralOnly(fb, wf, lens, o, p);
            const float d = std::max(fb.footprint[p], 1e-12f);
            if (fallback || nearBounce(wf, o, p, d)) continue;
            // K >= 3 needs spatialScale Omega_x R step / 3 >= 3 (maafFitPairs) with Omega_x at most
            // indirectOmega / s_min (fitAxis): a step of at least 9 s_min / (spatialScale
            // indirectOmega R), which most pixels' steps are far from (a 0.1% margin).
            const double sMin = std::max(wf.zMin[p], o.zMinPixels * d);
            const double fitRadius = double(o.fitShare) * o.maxRadius;
            if (o.fitComponents &&
                indirectStepBound(fb, view, p) < 0.999 * 9.0 * sMin / (o.spatialScale * o.indirectOmega * fitRadius))
                continue;
            const AxisFrame frame = indirectFrame(fb, view, p);
            for (int k = 0; k < 2 && !outer[p]; ++k) {
                AxisInputs in;
                if (indirectInputs(wf, frame, fb.object[p], fb.footprint[p], fallback, lens, p, k, o, in))
                    outer[p] = axisPairs(in, o) > 1;
            }
        }
    });
    return outer;
}

Image<uint8_t> dilateBox(const Image<uint8_t>& mask, int radius) {
    const int W = mask.width(), H = mask.height();
    // Running counts over [x - radius, x + radius] along each row, then along each column.
    Image<uint8_t> rows(W, H), out(W, H);
    parallelRows(H, [&](int y) {
        const uint8_t* m = &mask[size_t(y) * W];
        int count = 0;
        for (int x = 0; x < std::min(W, radius); ++x) count += m[x] != 0;
        for (int x = 0; x < W; ++x) {
            if (x + radius < W) count += m[x + radius] != 0;
            rows[size_t(y) * W + x] = count > 0;
            if (x - radius >= 0) count -= m[x - radius] != 0;
        }
    });
    parallelRows(W, [&](int x) {  // (over columns)
        int count = 0;
        for (int y = 0; y < std::min(H, radius); ++y) count += rows(x, y);
        for (int y = 0; y < H; ++y) {
            if (y + radius < H) count += rows(x, y + radius);
            out(x, y) = count > 0;
            if (y - radius >= 0) count -= rows(x, y - radius);
        }
    });
    return out;
}

MaafParams maafParams(const FrameBuffers& fb, const WedgeField& wf, const FilterFrames& frames, const ViewGeometry& view,
                      const MaafOptions& o, const Image<uint8_t>* region, const Image<uint8_t>* shadowAgree) {
    const int W = fb.width, H = fb.height;
    const ViewGeometry::Light* single = singlePlanarLight(view);
    const bool lens = view.apertureRadius > 0;
    Image1f fallback(W, H);
    parallelRows(H, [&](int y) {
        for (int x = 0; x < W; ++x) {
            size_t p = size_t(y) * W + x;
            fallback[p] = centralOnly(fb, wf, lens, o, p) ? 1.f : 0.f;
        }
    });
    // The planes the components read that the renderer rewrites after adaptive sampling are
    // copied, so that a pixel's components stay those its accumulations were laid out for.
    struct Snapshot {
        Image1f object, footprint, fallback;
    };
    auto snap = std::make_shared<Snapshot>(Snapshot{fb.object, fb.footprint, fallback});
    // Direct: the shadow wedge in the light plane (directInputs).
    auto direct = [&, snap, lens, single, shadowAgree, o](size_t p, int k, MaafAxis& out) {
        AxisInputs in;
        if (!directInputs(wf, frames.direct[p], snap->object[p], snap->fallback[p] > 0, lens, single, shadowAgree, p, k, o,
                          in)) {
            out = MaafAxis{};
            out.pairs = 1;
            return;
        }
        out = buildAxis(in, o);
    };
    // Indirect: the bounce wedge (indirectInputs).
    auto indirect = [&, snap, lens, o](size_t p, int k, MaafAxis& out) {
        AxisInputs in;
        if (!indirectInputs(wf, frames.indirect[p], snap->object[p], snap->footprint[p], snap->fallback[p] > 0, lens, p, k,
                            o, in)) {
            out = MaafAxis{};
            out.pairs = 1;
            return;
        }
        out = buildAxis(in, o);
    };
    return MaafParams{o.directEffect ? MaafEffect(W, H, direct, region) : MaafEffect(W, H), MaafEffect(W, H, indirect, region),
                      std::move(fallback)};
}

namespace {

uint16_t toUnorm16(float v) { return uint16_t(std::clamp(v, 0.f, 1.f) * 65535.f + 0.5f); }
float fromUnorm16(uint16_t v) { return float(v) * (1.f / 65535.f); }

/// Octahedral map of a unit vector to [0, 1]^2 (Cigolle et al. 2014) and back.
Vec2f octEncode(const Vec3f& v) {
    float l1 = std::abs(v.x) + std::abs(v.y) + std::abs(v.z);
    if (l1 <= 0) return {0.5f, 0.5f};
    float x = v.x / l1, y = v.y / l1;
    if (v.z < 0) {
        float ox = (1.f - std::abs(y)) * (x >= 0 ? 1.f : -1.f);
        float oy = (1.f - std::abs(x)) * (y >= 0 ? 1.f : -1.f);
        x = ox;
        y = oy;
    }
    return {0.5f * x + 0.5f, 0.5f * y + 0.5f};
}
Vec3f octDecode(float u, float v) {
    float x = 2.f * u - 1.f, y = 2.f * v - 1.f, z = 1.f - std::abs(x) - std::abs(y);
    if (z < 0) {
        float ox = (1.f - std::abs(y)) * (x >= 0 ? 1.f : -1.f);
        float oy = (1.f - std::abs(x)) * (y >= 0 ? 1.f : -1.f);
        x = ox;
        y = oy;
    }
    return normalize(Vec3f(x, y, z));
}

}  // namespace

MaafSample MaafSample::pack(const SampleRecord& r, const ViewGeometry& view, int slot) {
    MaafSample m;
    m.indirect[0] = r.indirect.x;
    m.indirect[1] = r.indirect.y;
    m.indirect[2] = r.indirect.z;
    const ViewGeometry::Light& l = view.lights[r.light];
    Vec3f rel = r.lightPoint - l.center;
    m.lightA = dot(rel, l.axisA);
    m.lightB = dot(rel, l.axisB);
    m.unoccluded = r.unoccluded;
    m.lens[0] = toUnorm16(0.5f * r.lens.x + 0.5f);
    m.lens[1] = toUnorm16(0.5f * r.lens.y + 0.5f);
    bool bounced = lengthSquared(r.bounceDir) > 0;
    Vec2f o = bounced ? octEncode(r.bounceDir) : Vec2f{0.5f, 0.5f};
    m.bounce[0] = toUnorm16(o.x);
    m.bounce[1] = toUnorm16(o.y);
    m.light = uint8_t(r.light);
    m.visible = uint8_t((luminance(r.direct) > 0 ? 1 : 0) | (bounced ? 2 : 0));
    m.slot = int8_t(slot);
    m.pad = 0;
    return m;
}

Vec2f lightIrradianceCentre(const ViewGeometry::Light& l, const Vec3f& p, const Vec3f& n) {
    if (l.sphere || l.parts.empty()) return {0.f, 0.f};
    constexpr int kGrid = 8;
    double sum = 0, sumA = 0, sumB = 0;
    for (const ViewGeometry::Light::Part& part : l.parts) {
        const Vec3f ln = normalize(cross(part.edge1, part.edge2));
        for (int i = 0; i < kGrid; ++i)
            for (int j = 0; j < kGrid; ++j) {
                float a = (float(i) + 0.5f) / kGrid, b = (float(j) + 0.5f) / kGrid;
                if (part.triangle) {  // the square onto the triangle, uniform in area
                    const float r = std::sqrt(a);
                    a = 1.f - r;
                    b = b * r;
                }
                const Vec3f q = part.corner + part.edge1 * a + part.edge2 * b;
                const Vec3f d = q - p;
                const float r2 = lengthSquared(d);
                if (!(r2 > 0.f)) continue;
                const float inv = 1.f / std::sqrt(r2);
                const float w = std::max(0.f, dot(n, d) * inv) * std::abs(dot(ln, d) * inv) / r2 * part.share;
                const Vec3f rel = q - l.center;
                sum += w;
                sumA += w * dot(rel, l.axisA);
                sumB += w * dot(rel, l.axisB);
            }
    }
    if (!(sum > 0)) return {0.f, 0.f};
    return {float(sumA / sum), float(sumB / sum)};
}

void MaafSample::coordinates(const ViewGeometry& view, const AxisFrame& direct, const AxisFrame& indirect,
                             float yDirect[2], float yIndirect[2], float u[2], Vec2f lightCentre) const {
    const ViewGeometry::Light& l = view.lights[light];
    const Vec3f bounceDir =
        (visible & 2) ? octDecode(fromUnorm16(bounce[0]), fromUnorm16(bounce[1])) : Vec3f(0.f);
    const float a = lightA - lightCentre.x, b = lightB - lightCentre.y;
    for (int k = 0; k < 2; ++k) {
        yDirect[k] = a * dot(l.axisA, direct.axis[k]) + b * dot(l.axisB, direct.axis[k]);
        yIndirect[k] = dot(bounceDir, indirect.axis[k]);
    }
    u[0] = 2.f * fromUnorm16(lens[0]) - 1.f;
    u[1] = -(2.f * fromUnorm16(lens[1]) - 1.f);  // lens y is along camera up; axis 2 is image down
}

MaafAccumulator::MaafAccumulator(const MaafEffect& params, int pairs, int values, const Image<uint8_t>* region)
    : m_width(params.width()), m_height(params.height()), m_pairs(pairs), m_values(values),
      m_channels(values + 1) {
    const size_t n = size_t(params.width()) * params.height();
    m_bands1.resize(n);
    m_bands2.resize(n);
    m_offset.resize(n + 1);
    // Each row's bands and offsets from its own start, the rows' starts, then the offsets, in
    // parallel (the serial pass was part of the 0.006-0.028 s the layout took at 512x512,
    // docs/maaf.md, "Sparse components").
    const int W = m_width, H = m_height;
    std::vector<size_t> rowStart(size_t(H) + 1, 0);
    parallelRows(H, [&](int y) {
        size_t total = 0;
        for (int x = 0; x < W; ++x) {
            const size_t p = size_t(y) * W + x;
            if (region && !(*region)[p]) {  // no storage
                m_bands1[p] = m_bands2[p] = 0;
                m_offset[p] = total;
                continue;
            }
            m_bands1[p] = uint8_t(2 * std::min(params.pairs(p, 0), pairs) - 1);
            m_bands2[p] = uint8_t(2 * std::min(params.pairs(p, 1), pairs) - 1);
            m_offset[p] = total;
            total += size_t(m_bands1[p]) * m_bands2[p] * size_t(m_channels);
        }
        rowStart[size_t(y) + 1] = total;
    });
    for (int y = 0; y < H; ++y) rowStart[size_t(y) + 1] += rowStart[size_t(y)];
    parallelRows(H, [&](int y) {
        for (int x = 0; x < W; ++x) m_offset[size_t(y) * W + x] += rowStart[size_t(y)];
    });
    const size_t total = rowStart[size_t(H)];
    m_offset[n] = total;
    m_data.resize(total);
    parallelRows(m_height, [&](int y) {
        size_t a = m_offset[size_t(y) * m_width], b = m_offset[size_t(y + 1) * m_width];
        std::fill(m_data.begin() + a, m_data.begin() + b, 0.f);
    });
}

void MaafAccumulator::add(size_t pixel, const float* value, float weight, const float y[2], const float u[2],
                          const MaafPixel& params) {
    if (weight == 0.f) return;
    float A[2][2 * kMaafMaxPairs - 1] = {};
    int used[2] = {1, 1};  // bands with a non-zero factor on each axis
    for (int k = 0; k < 2; ++k) {
        const MaafAxis& ax = params.axis[k];
        const int n = std::min(ax.pairs, m_pairs);
        used[k] = 2 * n - 1;
        for (int p = 0; p < n; ++p) {
            // Eq. 23: phase C_y y + C_u u; optional windows over the light (bounce) and the lens.
            float wy = ax.sy[p] * y[k], wu = ax.su[p] * u[k];
            float win = (wy == 0.f && wu == 0.f) ? 1.f : std::exp(-0.5f * (wy * wy + wu * wu));
            if (p == 0) {
                A[k][0] = win;
            } else {
                float s, c;
                sincosf(ax.cy[p] * y[k] + ax.cu[p] * u[k], &s, &c);
                A[k][2 * p - 1] = win * c;
                A[k][2 * p] = win * s;
            }
        }
    }
    float* d = &m_data[m_offset[pixel]];
    const int C = m_channels, V = m_values, b2 = m_bands2[pixel];
    for (int i = 0; i < used[0]; ++i) {
        if (A[0][i] == 0.f) continue;
        for (int j = 0; j < used[1]; ++j) {
            float t = A[0][i] * A[1][j] * weight;
            float* e = d + C * (i * b2 + j);
            for (int c = 0; c < V; ++c) e[c] += value[c] * t;
            e[V] += t;
        }
    }
}

void MaafAccumulator::setCentral(size_t pixel, const float* meanValueTimesWeight, float meanWeight) {
    float* d = &m_data[m_offset[pixel]];
    for (int c = 0; c < m_values; ++c) d[c] = meanValueTimesWeight[c];
    d[m_values] = meanWeight;
}

void MaafAccumulator::scale(size_t pixel, float s) {
    for (size_t i = m_offset[pixel]; i < m_offset[pixel + 1]; ++i) m_data[i] *= s;
}

namespace {

/// Radius in pixels of the window along an axis: three standard deviations of the central
/// component, at most maxRadius.
int windowRadius(const MaafAxis& ax, float step, int maxRadius) {
    float stdPx = 1.f / (ax.sx[0] * step);
    return std::clamp(int(std::ceil(3.f * stdPx)), 1, maxRadius);
}

/// Neighbour test shared by both passes; on acceptance gives the signed offset a (output minus
/// input, along `axis` of the output pixel's frame) and the in-plane distance r.
enum class Neighbour { Accepted, OtherSurface, Rejected };
inline Neighbour neighbour(const FrameBuffers& fb, const MaafEffect& params, const AxisFrame& f, size_t p, size_t q, int axis,
                    const MaafOptions& o, float& a, float& r) {
    a = r = 0;
    if (q == p) return Neighbour::Accepted;
    const Vec3f dP = fb.position[p] - fb.position[q];
    if (!sameSurface(fb, p, q, o.normalCos) || !onTangentPlane(fb, p, dP, o.planeDistance)) return Neighbour::OtherSurface;
    float wp = params.centralSx(p, axis), wq = params.centralSx(q, axis);
    if (wp > o.bandwidthRatio * wq || wq > o.bandwidthRatio * wp) return Neighbour::Rejected;
    float a0 = dot(dP, f.axis[0]), a1 = dot(dP, f.axis[1]);
    a = axis == 0 ? a0 : a1;
    r = std::sqrt(a0 * a0 + a1 * a1);
    return Neighbour::Accepted;
}

/// The neighbours of pixel (x, y) along image axis `axis` within the pixel's window:
/// ok[k + radius] where neighbour() accepts the pixel at offset k, with its a and r. With
/// MaafOptions::mirrorSurfaceCuts (and a pixel that saw one surface), a neighbour whose mirror
/// image is another surface is left out too, so that the window stays symmetric (filter/aaf.h).
struct Window {
    static constexpr int kMaxRadius = kMaafMaxWindowRadius;
    int radius;
    bool ok[2 * kMaxRadius + 1];
    float a[2 * kMaxRadius + 1], r[2 * kMaxRadius + 1];

    Window(const FrameBuffers& fb, const MaafEffect& params, const MaafAxis& own, const AxisFrame& f, int x, int y,
           int axis, const MaafOptions& o) {
        radius = std::min(windowRadius(own, f.step[axis], o.maxRadius), kMaxRadius);
        const size_t p = size_t(y) * fb.width + x;
        bool cut[2 * kMaxRadius + 1];
        for (int k = -radius; k <= radius; ++k) {
            int xx = axis == 0 ? x + k : x, yy = axis == 0 ? y : y + k;
            Neighbour n = Neighbour::Rejected;  // outside the image
            if (xx >= 0 && xx < fb.width && yy >= 0 && yy < fb.height)
                n = neighbour(fb, params, f, p, size_t(yy) * fb.width + xx, axis, o, a[k + radius], r[k + radius]);
            ok[k + radius] = n == Neighbour::Accepted;
            cut[k + radius] = n == Neighbour::OtherSurface;
        }
        if (o.mirrorSurfaceCuts && fb.coverage[p] >= kFullCoverage)
            for (int k = -radius; k <= radius; ++k) ok[k + radius] = ok[k + radius] && !cut[radius - k];
    }
};

}  // namespace

Image3f MaafAccumulator::filter(const MaafEffect& params, const FrameBuffers& fb, const Image<AxisFrame>& frames,
                                const Image3f& fallback, const MaafOptions& o, const Image<uint8_t>* only) const {
    const int W = m_width, H = m_height, C = m_channels, V = m_values;
    // With `only`, pass 1 runs where pass 2 reads it: within the widest window along image y of
    // a pixel to filter (a running count down each column).
    LargeVector<uint8_t> needed;
    if (only) {
        const int reachY = std::min(o.maxRadius, kMaafMaxWindowRadius);
        needed.resize(size_t(W) * H);
        parallelRows(W, [&](int x) {  // (over columns)
            int count = 0;  // pixels to filter in rows [y - reachY, y + reachY]
            for (int y = 0; y < std::min(H, reachY); ++y) count += (*only)(x, y) != 0;
            for (int y = 0; y < H; ++y) {
                if (y + reachY < H) count += (*only)(x, y + reachY) != 0;
                needed[size_t(y) * W + x] = count > 0;
                if (y - reachY >= 0) count -= (*only)(x, y - reachY) != 0;
            }
        });
    }
    // Pass 1's output at a pixel: the axis-2 bands its row neighbours accumulated, at most as many
    // as the most any pixel within the widest window has (1 in most of an image), plus the
    // central-only band. A fixed (2N-1) + 1 bands per pixel would be 38 MB at 512x512, mostly zeros.
    const int reach = std::min(o.maxRadius, kMaafMaxWindowRadius);
    // Where pass 1 does not run (outside `needed`), no bands and no storage.
    LargeVector<uint8_t> interBands(size_t(W) * H);
    parallelRows(H, [&](int y) {
        for (int x = 0; x < W; ++x) {
            if (only && !needed[size_t(y) * W + x]) {
                interBands[size_t(y) * W + x] = 0;
                continue;
            }
            uint8_t b = 1;
            for (int xx = std::max(0, x - reach); xx <= std::min(W - 1, x + reach); ++xx)
                b = std::max(b, m_bands2[size_t(y) * W + xx]);
            interBands[size_t(y) * W + x] = b;
        }
    });
    LargeVector<size_t> interOffset(size_t(W) * H + 1);
    interOffset[0] = 0;
    for (size_t p = 0; p < size_t(W) * H; ++p)
        interOffset[p + 1] = interOffset[p] + (interBands[p] > 0 ? size_t(interBands[p] + 1) * C : 0);
    LargeVector<float> inter(interOffset.back());  // default-initialised: zeroed by the rows in parallel
    parallelRows(H, [&](int y) {
        std::fill(inter.begin() + interOffset[size_t(y) * W], inter.begin() + interOffset[size_t(y + 1) * W], 0.f);
    });

    // Pass 1 along image x: sum over the components p of axis 1 (eq. 21).
    parallelRows(H, [&](int y) {
        for (int x = 0; x < W; ++x) {
            size_t p = size_t(y) * W + x;
            if (fb.object[p] < 0 || (only && !needed[p])) continue;
            const MaafAxis ax = params.filterAxis(p, 0);
            const AxisFrame& f = frames[p];
            float* out = &inter[interOffset[p]];
            const int B = interBands[p];  // the central-only band follows the B bands
            const Window win(fb, params, ax, f, x, y, 0, o);
            const int radius = win.radius;
            for (int k = -radius; k <= radius; ++k) {
                if (!win.ok[k + radius]) continue;
                size_t q = size_t(y) * W + x + k;
                float a = win.a[k + radius], r = win.r[k + radius];
                const float* T = pixel(q);
                const int bq2 = m_bands2[q];  // the neighbour's own bands: its storage's layout
                // Outer components (of either axis) only where the mirror neighbour is accepted
                // and has them too: a one-sided window (an occluder's silhouette next to its
                // shadow, the border between pixels with and without outer components) would
                // turn their modulation into bias (issue 28: a ramp across a K = 1 / K = 5
                // border moved by 0.16%, filter_test KernelStaysSymmetricAcrossABorderOfComponents).
                int pairs = std::min<int>(ax.pairs, (m_bands1[q] + 1) / 2), bands2 = bq2;
                if (o.symmetricOuter) {
                    const size_t m = size_t(y) * W + x - k;
                    const bool mirror = win.ok[radius - k];
                    pairs = mirror ? std::min<int>(pairs, (m_bands1[m] + 1) / 2) : 1;
                    bands2 = mirror ? std::min<int>(bq2, m_bands2[m]) : 1;
                }
                for (int c = 0; c < pairs; ++c) {
                    float sr = ax.sx[c] * r;
                    float g = ax.weight[c] * ax.sx[c] * kInvSqrt2Pi * std::exp(-0.5f * sr * sr);
                    if (c == 0) {
                        for (int j = 0; j < bands2 * C; ++j) out[j] += g * T[j];
                        for (int j = 0; j < C; ++j) out[B * C + j] += g * T[j];
                    } else {
                        float sn, cs;
                        sincosf(ax.cx[c] * a, &sn, &cs);
                        float gc = g * cs, gs = g * sn;
                        const float* Tc = T + (2 * c - 1) * bq2 * C;
                        const float* Ts = T + (2 * c) * bq2 * C;
                        for (int j = 0; j < bands2 * C; ++j) out[j] += gc * Tc[j] + gs * Ts[j];
                    }
                }
            }
        }
    });

    // Pass 2 along image y: sum over the components q of axis 2, then the ratio.
    Image3f result(W, H);
    parallelRows(H, [&](int y) {
        for (int x = 0; x < W; ++x) {
            size_t p = size_t(y) * W + x;
            if (fb.object[p] < 0 || (only && !(*only)[p])) {
                result[p] = fallback[p];
                continue;
            }
            const MaafAxis ax = params.filterAxis(p, 1);
            const AxisFrame& f = frames[p];
            float h[4] = {0, 0, 0, 0}, h0[4] = {0, 0, 0, 0};  // values..., weight (C <= 4)
            const Window win(fb, params, ax, f, x, y, 1, o);
            const int radius = win.radius;
            for (int k = -radius; k <= radius; ++k) {
                if (!win.ok[k + radius]) continue;
                size_t q = size_t(y + k) * W + x;
                float a = win.a[k + radius], r = win.r[k + radius];
                const float* I = &inter[interOffset[q]];
                const int B = interBands[q];  // bands beyond B are zero
                // As in pass 1: components the mirror row has too.
                int bands = B;
                int pairs = ax.pairs;
                if (o.symmetricOuter) {
                    const bool mirror = win.ok[radius - k];
                    pairs = mirror ? pairs : 1;
                    if (mirror) bands = std::min<int>(B, interBands[size_t(y - k) * W + x]);
                }
                for (int c = 0; c < pairs && 2 * c < bands; ++c) {
                    float sr = ax.sx[c] * r;
                    float g = ax.weight[c] * ax.sx[c] * kInvSqrt2Pi * std::exp(-0.5f * sr * sr);
                    if (c == 0) {
                        for (int j = 0; j < C; ++j) {
                            h[j] += g * I[j];
                            h0[j] += g * I[B * C + j];
                        }
                    } else {
                        float gc = g * std::cos(ax.cx[c] * a), gs = g * std::sin(ax.cx[c] * a);
                        for (int j = 0; j < C; ++j) h[j] += gc * I[(2 * c - 1) * C + j] + gs * I[(2 * c) * C + j];
                    }
                }
            }
            // The outer components redistribute energy; if they cancel most of the central
            // weight (a thin, oddly shaped neighbourhood), the central filter alone is safer.
            constexpr float thr = 0.25f;
            const float* r = (h[V] > thr * h0[V] && h[V] > 0) ? h : (h0[V] > 0 ? h0 : nullptr);
            if (!r) result[p] = fallback[p];
            else if (V == 1) result[p] = Vec3f(r[0] / r[V]);
            else result[p] = Vec3f(r[0], r[1], r[2]) / r[V];
        }
    });
    return result;
}

}  // namespace wedge::filter
