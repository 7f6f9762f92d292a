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
double polygonFormFactor(const std::vector<D3>& v, const D3& n) {
    double sum = 0;
    for (size_t i = 0; i < v.size(); ++i) {
        const D3& a = v[i];
        const D3& b = v[(i + 1) % v.size()];
        D3 c = crossd(a, b);
        double cl = std::sqrt(dotd(c, c));
        if (cl <= 0) continue;
        double theta = std::atan2(cl, dotd(a, b));
        sum += theta * dotd(n, c) / cl;
    }
    return 0.5 * std::abs(sum);
}

}  // namespace

Vec3f unoccludedIrradiance(const std::vector<ParallelogramLight>& lights, const Vec3f& xf, const Vec3f& nf) {
    Vec3f total(0.f);
    const D3 x = toD(xf), n = toD(nf);
    for (const auto& l : lights) {
        if (dot(xf - l.corner, l.normal()) <= 0) continue;  // behind the emitting side
        D3 c = toD(l.corner) - x, e1 = toD(l.edge1), e2 = toD(l.edge2);
        std::vector<D3> poly = {c, c + e1, c + e1 + e2, c + e2};
        // Clip to the upper hemisphere n . v >= 0 (Sutherland-Hodgman against one plane).
        std::vector<D3> clipped;
        for (size_t i = 0; i < poly.size(); ++i) {
            const D3& a = poly[i];
            const D3& b = poly[(i + 1) % poly.size()];
            double da = dotd(n, a), db = dotd(n, b);
            if (da >= 0) clipped.push_back(a);
            if ((da >= 0) != (db >= 0)) clipped.push_back(a + (b - a) * (da / (da - db)));
        }
        if (clipped.size() < 3) continue;
        total += l.radiance * float(polygonFormFactor(clipped, n));
    }
    return total;
}

}  // namespace wedge::scene
