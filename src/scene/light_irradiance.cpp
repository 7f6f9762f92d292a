#include "scene/light_irradiance.h"

#include <algorithm>
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

/// An edge's term of Lambert's sum, theta n . unit(a x b), for the edge from a to b (seen from
/// the receiver).
double edgeTerm(const D3& a, const D3& b, const D3& n) {
    D3 c = crossd(a, b);
    double cl = std::sqrt(dotd(c, c));
    return cl > 0 ? std::atan2(cl, dotd(a, b)) * dotd(n, c) / cl : 0.0;
}

/// Lambert: E / L = (1/2) |sum_i theta_i n . unit(v_i x v_{i+1})| for a polygon above the horizon.
double polygonFormFactor(const D3* v, int count, const D3& n) {
    double sum = 0;
    for (int i = 0; i < count; ++i) sum += edgeTerm(v[i], v[(i + 1) % count], n);
    return 0.5 * std::abs(sum);
}

/// The form factor of one light at x (normal n), clipped to the upper hemisphere n . v >= 0.
double lightFormFactor(const AreaLight& l, const D3& x, const D3& n) {
    Vec3f corners[4];
    const int count = l.vertices(corners);
    D3 poly[4];
    for (int i = 0; i < count; ++i) poly[i] = toD(corners[i]) - x;
    // Sutherland-Hodgman against one plane: one vertex more at most.
    D3 clipped[5];
    int kept = 0;
    for (int i = 0; i < count; ++i) {
        const D3& a = poly[i];
        const D3& b = poly[(i + 1) % count];
        double da = dotd(n, a), db = dotd(n, b);
        if (da >= 0) clipped[kept++] = a;
        if ((da >= 0) != (db >= 0)) clipped[kept++] = a + (b - a) * (da / (da - db));
    }
    return kept < 3 ? 0.0 : polygonFormFactor(clipped, kept, n);
}

}  // namespace

Vec3f unoccludedIrradiance(const std::vector<AreaLight>& lights, const Vec3f& xf, const Vec3f& nf) {
    Vec3f total(0.f);
    const D3 x = toD(xf), n = toD(nf);
    for (const auto& l : lights) {
        if (dot(xf - l.corner, l.normal()) <= 0) continue;  // behind the emitting side
        total += l.radiance * float(lightFormFactor(l, x, n));
    }
    return total;
}

LightIrradiance::LightIrradiance(const std::vector<AreaLight>& lights) {
    const std::vector<uint32_t> group = lightGroups(lights);
    for (size_t i = 0; i < lights.size(); ++i) {
        if (group[i] == m_groups.size()) m_groups.push_back({lights[i].corner, lights[i].normal(), lights[i].radiance, {}, {}, {}});
        m_groups[group[i]].lights.push_back(lights[i]);
    }
    for (Group& g : m_groups) {
        // Every light's edges, then those walked both ways removed (the corners lightGroups
        // found shared are equal up to its tolerance; a shared edge's two walks are matched
        // within it).
        std::vector<Vec3f> from, to;
        float size = 0;
        for (const AreaLight& l : g.lights) {
            Vec3f v[4];
            const int count = l.vertices(v);
            for (int k = 0; k < count; ++k) {
                from.push_back(v[k]);
                to.push_back(v[(k + 1) % count]);
            }
            size = std::max({size, length(l.edge1), length(l.edge2)});
        }
        const float tol = 1e-4f * size;
        std::vector<bool> gone(from.size(), false);
        for (size_t a = 0; a < from.size(); ++a)
            for (size_t b = a + 1; b < from.size() && !gone[a]; ++b)
                if (!gone[b] && length(from[a] - to[b]) <= tol && length(to[a] - from[b]) <= tol) gone[a] = gone[b] = true;
        for (size_t a = 0; a < from.size(); ++a)
            if (!gone[a]) {
                g.from.push_back(from[a]);
                g.to.push_back(to[a]);
            }
    }
}

Vec3f LightIrradiance::operator()(const Vec3f& xf, const Vec3f& nf) const {
    Vec3f total(0.f);
    const D3 x = toD(xf), n = toD(nf);
    for (const Group& g : m_groups) {
        if (dot(xf - g.point, g.normal) <= 0) continue;  // behind the emitting side
        // The lights lie in the convex hull of the outline's corners: above the horizon if they are.
        bool above = true;
        for (const Vec3f& v : g.from) above = above && dotd(n, toD(v) - x) >= 0;
        double formFactor = 0;
        if (above && g.lights.size() > 1) {
            double sum = 0;
            for (size_t e = 0; e < g.from.size(); ++e) sum += edgeTerm(toD(g.from[e]) - x, toD(g.to[e]) - x, n);
            formFactor = 0.5 * std::abs(sum);
        } else {
            for (const AreaLight& l : g.lights) formFactor += lightFormFactor(l, x, n);
        }
        total += g.radiance * float(formFactor);
    }
    return total;
}

}  // namespace wedge::scene
