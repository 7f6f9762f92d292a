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

/// The form factor of a convex polygon (vertices relative to the receiver) clipped to the upper
/// hemisphere n . v >= 0 (Sutherland-Hodgman against one plane: one vertex more at most).
template <int kMax>
double clippedFormFactor(const D3* poly, int count, const D3& n) {
    D3 clipped[kMax + 1];
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

/// Sides of the polygon that stands in for a sphere light's silhouette where the horizon cuts it.
constexpr int kSphereSides = 64;

/// A sphere light's form factor at x (normal n). From outside, the sphere fills the cone of
/// half-angle alpha (sin alpha = r / d) about the direction c to its centre, as does the disc
/// its tangent points span: pi sin^2 alpha cos theta of irradiance per radiance (theta between
/// n and c) while the cone is wholly above the horizon (theta <= 90 degrees - alpha). Where the
/// horizon cuts the cone, that disc, as a regular polygon of the same area, clipped (Lambert).
double sphereFormFactor(const AreaLight& l, const D3& x, const D3& n) {
    const D3 w = toD(l.corner) - x;
    const double d2 = dotd(w, w), r2 = double(l.radius) * l.radius;
    if (d2 <= r2) return 0.0;  // inside the sphere: its outside faces away
    const double d = std::sqrt(d2), sin2 = r2 / d2, cosAlpha = std::sqrt(1.0 - sin2);
    const D3 axis = w * (1.0 / d);
    const double cosTheta = dotd(n, axis), sinAlpha = std::sqrt(sin2);
    // theta <= 90 - alpha  <=>  cos theta >= sin alpha
    if (cosTheta >= sinAlpha) return M_PI * sin2 * cosTheta;
    if (cosTheta <= -sinAlpha) return 0.0;
    // The tangent circle: centre at (d - r^2 / d) along the axis, radius r cos alpha; a polygon
    // of kSphereSides with the circle's area.
    const double rho = std::sqrt(r2) * cosAlpha *
                       std::sqrt(2.0 * M_PI / (kSphereSides * std::sin(2.0 * M_PI / kSphereSides)));
    const D3 centre = axis * (d - r2 / d);
    D3 u = std::abs(axis.x) < 0.9 ? D3{1, 0, 0} : D3{0, 1, 0};
    u = crossd(axis, u);
    u = u * (1.0 / std::sqrt(dotd(u, u)));
    const D3 v = crossd(axis, u);
    D3 poly[kSphereSides];
    for (int i = 0; i < kSphereSides; ++i) {
        const double a = 2.0 * M_PI * i / kSphereSides;
        poly[i] = centre + u * (rho * std::cos(a)) + v * (rho * std::sin(a));
    }
    return clippedFormFactor<kSphereSides>(poly, kSphereSides, n);
}

/// The form factor of one light at x (normal n), clipped to the upper hemisphere n . v >= 0.
double lightFormFactor(const AreaLight& l, const D3& x, const D3& n) {
    if (l.sphere()) return sphereFormFactor(l, x, n);
    Vec3f corners[4];
    const int count = l.vertices(corners);
    D3 poly[4];
    for (int i = 0; i < count; ++i) poly[i] = toD(corners[i]) - x;
    return clippedFormFactor<4>(poly, count, n);
}

}  // namespace

Vec3f unoccludedIrradiance(const std::vector<AreaLight>& lights, const Vec3f& xf, const Vec3f& nf) {
    Vec3f total(0.f);
    const D3 x = toD(xf), n = toD(nf);
    for (const auto& l : lights) {
        if (!l.sphere() && dot(xf - l.corner, l.normal()) <= 0) continue;  // behind the emitting side
        total += l.radiance * float(lightFormFactor(l, x, n));
    }
    return total;
}

LightIrradiance::LightIrradiance(const std::vector<AreaLight>& lights, const std::vector<uint32_t>& group) {
    for (size_t i = 0; i < lights.size(); ++i) {
        if (group[i] == m_groups.size()) {
            const Vec3f normal = lights[i].sphere() ? Vec3f(0.f) : lights[i].normal();
            m_groups.push_back({lights[i].corner, normal, lights[i].radiance, {}, {}, {}});
        }
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
        if (g.normal != Vec3f(0.f) && dot(xf - g.point, g.normal) <= 0) continue;  // behind the emitting side (a sphere: none)
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
