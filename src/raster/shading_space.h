// Shading space: where a visibility sample of a triangle is shaded. A sample maps to its
// triangle's canonical pose (lens centre, shutter centre; Vaidyanathan et al. 2012, eq. 4, done
// exactly through the sample's surface barycentrics as in Ragan-Kelley et al. 2011) and from
// there to a shading grid. Decoupled sampling (DS) uses the pixel grid. Adaptive anisotropic
// shading (AAS) bounds the spectrum of A' * S' * R over the primitive (Sec. 3.2: minimum circle of
// confusion, minimum screen speed, span of motion directions), takes the oriented box of
// eqs. 8-9 and samples at its Nyquist spacing on a grid rotated to the motion (Sec. 3.3), through
// the mapping M_g of Sec. 3.4. Shading points are clamped into the triangle (Sec. 3.4, closest
// point after Ericson 2005).
#pragma once

#include <cstdint>

#include "raster/raster_geometry.h"

namespace wedge::raster {

/// The spectral cutoffs of the analysis (cycles per unit of their domain). Neither the disc
/// aperture nor the box shutter is band-limited (Fig. 3); each cutoff is where the spectrum's
/// magnitude stays below about 13% of its peak from then on, so the two blurs are cut alike.
struct FrequencyCutoffs {
    /// Omega_A^max of the unit-disc aperture, spectrum 2 J1(2 pi rho) / (2 pi rho): 0.61 is its first
    /// zero, after which the side lobes peak at 0.13 (84% of the energy inside).
    float lens = 0.61f;
    /// Omega_S^max of the box shutter over the normalised shutter, spectrum sinc(Omega): 2 is its
    /// second zero, after which the side lobes peak at 0.13 (the first side lobe, 0.22 at 1.43,
    /// would otherwise alias visibly on textures; 95% of the energy inside).
    float shutter = 2.0f;
    /// Omega_R^max of the pixel reconstruction: 0.5 cycles per pixel, so that an unblurred
    /// primitive gets the pixel grid of DS (spacing 1 / (2 Omega_R) = 1 pixel).
    float pixel = 0.5f;
};

/// The per-primitive quantities of Sec. 3.2 and the box of eqs. 8-9.
struct AasBounds {
    float phiMin = 0;     // pixels; minimum |circle of confusion| over the shutter (0: straddles focus)
    float speedMin = 0;   // pixels per shutter; ||mu_min|| over the velocity hull
    float halfSpan = 0;   // radians; half the span theta-hat of motion directions
    Vec2f eMu{1, 0};      // unit, screen; centre of the direction span
    float omegaLens = kInf;     // Omega_A'^max = Omega_A / phi_min
    float omegaShutter = kInf;  // Omega_S'^max = Omega_S / ||mu_min||  (eq. 7)
    float r = 0.5f;             // min(Omega_A'^max, Omega_R^max)
    float dMu = 1, dPerp = 1;   // cycles per pixel; box extents along e_mu and e_perp (eqs. 8, 9)
    bool anisotropic = false;   // false: the square box 2r x 2r, kept axis-aligned
};

AasBounds aasBounds(const RasterTriangle& tri, const RasterCamera& camera, const FrequencyCutoffs& cutoffs);

/// The linear map M from canonical screen pixels to shading-grid units (the grid is the integer
/// lattice there) and its inverse, whose columns are the grid steps in pixels.
struct ShadingGrid {
    float m[2][2] = {{1, 0}, {0, 1}};
    float inv[2][2] = {{1, 0}, {0, 1}};

    static ShadingGrid pixel() { return {}; }
    /// M = M_g of Sec. 3.4: rotate screen vectors into (e_mu, e_perp), then scale by (d_mu, d_perp),
    /// so a grid cell spans 1/d_mu x 1/d_perp pixels. Spacings are capped at kMaxSpacing pixels.
    static ShadingGrid fromBounds(const AasBounds& b);

    Vec2f origin{0, 0};  // grid units; subtracted after M

    Vec2f toGrid(Vec2f s) const {
        return {m[0][0] * s.x + m[0][1] * s.y - origin.x, m[1][0] * s.x + m[1][1] * s.y - origin.y};
    }
    /// Moves the lattice so that the triangle's grid-space bounding box starts on a quad corner.
    void alignTo(const RasterTriangle& tri);
    Vec2f stepA() const { return {inv[0][0], inv[1][0]}; }  // pixels per grid unit along grid x
    Vec2f stepB() const { return {inv[0][1], inv[1][1]}; }  // pixels per grid unit along grid y
};

constexpr float kMaxSpacing = 256.f;  // pixels

/// A shading-grid cell of one primitive: the memoization cache key.
struct CellKey {
    uint32_t prim = 0;
    int32_t x = 0, y = 0;
    bool operator==(const CellKey&) const = default;
};
struct CellKeyHash {
    size_t operator()(const CellKey& k) const {
        uint64_t h = uint64_t(k.prim) * 0x9e3779b97f4a7c15ULL;
        h ^= (uint64_t(uint32_t(k.x)) + 0x632be59bd9b4e019ULL + (h << 6) + (h >> 2)) * 0xff51afd7ed558ccdULL;
        h ^= (uint64_t(uint32_t(k.y)) + 0x85ebca6b27d4eb4fULL + (h << 6) + (h >> 2)) * 0xc4ceb9fe1a85ec53ULL;
        return size_t(h ^ (h >> 29));
    }
};

inline int32_t floorToInt(float v) {
    float f = std::floor(v);
    return int32_t(std::clamp(f, -1e9f, 1e9f));
}
inline int32_t floorDiv2(int32_t v) { return v >= 0 ? v / 2 : -((-v + 1) / 2); }

/// Barycentrics of the point of triangle (a, b, c) closest to p (Ericson 2005, Sec. 5.1.5),
/// robust to degenerate triangles.
Vec3f closestPointBarycentrics(Vec2f p, Vec2f a, Vec2f b, Vec2f c);

/// Where and over which footprint a cell is shaded.
struct ShadingPoint {
    Vec3f bary;      // surface barycentrics
    Vec2f screen;    // canonical screen position, pixels
    Vec2f stepA, stepB;  // the shading grid's steps in canonical pixels (texture footprint)
};

/// The shading point of cell (cx, cy): the cell centre, clamped into the triangle in grid space.
ShadingPoint cellShadingPoint(const RasterTriangle& tri, const ShadingGrid& grid, int32_t cx, int32_t cy);

/// World-space footprint (two vectors) of the screen steps a and b at pinhole screen position s
/// on the triangle's plane at shutter time tau: the Jacobian of the pinhole ray / plane
/// intersection. Zero (a point sample) where the plane is seen edge-on.
void worldFootprint(const RasterTriangle& tri, const RasterCamera& camera, float tau, Vec2f s, Vec2f a, Vec2f b,
                    Vec3f& footA, Vec3f& footB);

}  // namespace wedge::raster
