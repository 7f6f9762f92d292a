#include "scene/light_irradiance.h"

#include <cmath>

namespace wedge::scene {

namespace {

struct D3 {
    double x, y, z;
    D3 operator-(const D3& b) const { return {x - b.x, y - b.y, z - b.z}; }
    D3 operator+(const D3& b) const { return {x + b.x, y + b.y, z + b.z}; }
    D3 operator*(double s) const { return {x * s, y * s, z * s}; }
};
double dotd(const D3& a, const D3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
D3 crossd(const D3& a, const D3& b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
D3 toD(const Vec3f& v) { return {v.x, v.y, v.z}; }

/// Lambert: E / L = (1/2) |sum_i theta_i n . unit(v_i x v_{i+1})| for a polygon above the horizon.
double polygonFormFactor(const D3* v, int count, const D3& n) {
    double sum = 0;
    for (int i = 0; i < count; ++i) {
        const D3& a = v[i];
        const D3& b = v[(i + 1) % count];
        D3 c = crossd(a, b);
        double cl = std::sqrt(dotd(c, c));
        if (cl <= 0) continue;
        double theta = std::atan2(cl, dotd(a, b));
        sum += theta * dotd(n, c) / cl;
    }
    return 0.5 * std::abs(sum);
}

}  // namespace

Vec3f unoccludedIrradiance(const std::vector<AreaLight>& lights, const Vec3f& xf, const Vec3f& nf) {
    Vec3f total(0.f);
    const D3 x = toD(xf), n = toD(nf);
    for (const auto& l : lights) {
        if (dot(xf - l.corner, l.normal()) <= 0) continue;  // behind the emitting side
        Vec3f corners[4];
        const int count = l.vertices(corners);
        D3 poly[4];
        for (int i = 0; i < count; ++i) poly[i] = toD(corners[i]) - x;
        // Clip to the upper hemisphere n . v >= 0 (Sutherland-Hodgman against one plane): one
        // vertex more at most.
        D3 clipped[5];
        int kept = 0;
        for (int i = 0; i < count; ++i) {
            const D3& a = poly[i];
            const D3& b = poly[(i + 1) % count];
            double da = dotd(n, a), db = dotd(n, b);
            if (da >= 0) clipped[kept++] = a;
            if ((da >= 0) != (db >= 0)) clipped[kept++] = a + (b - a) * (da / (da - db));
        }
        if (kept < 3) continue;
        total += l.radiance * float(polygonFormFactor(clipped, kept, n));
    }
    return total;
}

}  // namespace wedge::scene
