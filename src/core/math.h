// Small vector math for the renderer and the filters: 3-vectors of float, an orthonormal frame,
// and the constants and helpers that every module needs. Deliberately tiny (pbrt's util/ in
// spirit); anything heavier belongs to a library.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace wedge {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kInvPi = 0.31830988618379067154f;
constexpr float kInf = 1e30f;

struct Vec2f {
    float x = 0, y = 0;
};

struct Vec3f {
    float x = 0, y = 0, z = 0;

    constexpr Vec3f() = default;
    constexpr Vec3f(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}
    constexpr explicit Vec3f(float s) : x(s), y(s), z(s) {}

    constexpr float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }

    constexpr Vec3f operator+(const Vec3f& b) const { return {x + b.x, y + b.y, z + b.z}; }
    constexpr Vec3f operator-(const Vec3f& b) const { return {x - b.x, y - b.y, z - b.z}; }
    constexpr Vec3f operator*(const Vec3f& b) const { return {x * b.x, y * b.y, z * b.z}; }
    constexpr Vec3f operator/(const Vec3f& b) const { return {x / b.x, y / b.y, z / b.z}; }
    constexpr Vec3f operator*(float s) const { return {x * s, y * s, z * s}; }
    constexpr Vec3f operator/(float s) const { return {x / s, y / s, z / s}; }
    constexpr Vec3f operator-() const { return {-x, -y, -z}; }
    Vec3f& operator+=(const Vec3f& b) { x += b.x; y += b.y; z += b.z; return *this; }
    Vec3f& operator-=(const Vec3f& b) { x -= b.x; y -= b.y; z -= b.z; return *this; }
    Vec3f& operator*=(float s) { x *= s; y *= s; z *= s; return *this; }
    Vec3f& operator*=(const Vec3f& b) { x *= b.x; y *= b.y; z *= b.z; return *this; }
    constexpr bool operator==(const Vec3f& b) const = default;
};

constexpr Vec3f operator*(float s, const Vec3f& v) { return v * s; }
constexpr float dot(const Vec3f& a, const Vec3f& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr Vec3f cross(const Vec3f& a, const Vec3f& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float length(const Vec3f& v) { return std::sqrt(dot(v, v)); }
constexpr float lengthSquared(const Vec3f& v) { return dot(v, v); }
/// (Selects per component, not a branch between two Vec3f: a loop over it then vectorises,
/// render/camera.cpp's camera rays. The same values.)
inline Vec3f normalize(const Vec3f& v) {
    const float l = length(v);
    const bool ok = l > 0;
    return {ok ? v.x / l : 0.f, ok ? v.y / l : 0.f, ok ? v.z / l : 0.f};
}
inline Vec3f vmin(const Vec3f& a, const Vec3f& b) { return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)}; }
inline Vec3f vmax(const Vec3f& a, const Vec3f& b) { return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)}; }
inline Vec2f vmin(const Vec2f& a, const Vec2f& b) { return {std::min(a.x, b.x), std::min(a.y, b.y)}; }
inline Vec2f vmax(const Vec2f& a, const Vec2f& b) { return {std::max(a.x, b.x), std::max(a.y, b.y)}; }
inline float maxComponent(const Vec3f& v) { return std::max(v.x, std::max(v.y, v.z)); }
inline float luminance(const Vec3f& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
inline bool isFinite(const Vec3f& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

template <class T>
constexpr T sqr(T v) { return v * v; }

/// Orthonormal frame around a unit normal (Duff et al. 2017, "Building an orthonormal basis, revisited").
struct Frame {
    Vec3f s, t, n;

    Frame() = default;
    explicit Frame(const Vec3f& nUnit) : n(nUnit) {
        float sign = std::copysign(1.f, n.z);
        float a = -1.f / (sign + n.z);
        float b = n.x * n.y * a;
        s = {1.f + sign * n.x * n.x * a, sign * b, -sign * n.x};
        t = {b, sign + n.y * n.y * a, -n.y};
    }
    Frame(const Vec3f& s_, const Vec3f& t_, const Vec3f& n_) : s(s_), t(t_), n(n_) {}

    Vec3f toWorld(const Vec3f& v) const { return s * v.x + t * v.y + n * v.z; }
    Vec3f toLocal(const Vec3f& v) const { return {dot(v, s), dot(v, t), dot(v, n)}; }
};

/// Rotation of v about a unit axis by an angle in radians (Rodrigues).
inline Vec3f rotate(const Vec3f& v, const Vec3f& axisUnit, float radians) {
    float c = std::cos(radians), s = std::sin(radians);
    return v * c + cross(axisUnit, v) * s + axisUnit * (dot(axisUnit, v) * (1.f - c));
}

/// Uniform point on the unit disc from a point in [0,1)^2 (Shirley-Chiu concentric map:
/// it keeps the stratification of the input).
inline Vec2f concentricDisc(float u1, float u2) {
    const float a = 2.f * u1 - 1.f, b = 2.f * u2 - 1.f;
    // Shirley-Chiu: r = a at angle (pi/4)(b/a), or r = b at pi/2 - (pi/4)(a/b). cos and sin of
    // theta in [-pi/4, pi/4] by their Taylor series to x^10 (truncation below 2e-9, float
    // rounding above it; std::cos / std::sin cost the layered reconstruction 12% of its time).
    // Selects, not branches, so that the layered reconstruction's SIMD loop over its rays
    // vectorises (the centre, a = b = 0, divides 0 by 0 in a lane whose result is not taken).
    const bool wide = std::abs(a) > std::abs(b);
    const float r = wide ? a : b;
    const float th = (kPi / 4) * ((wide ? b : a) / (wide ? a : b)), t2 = th * th;
    const float s = th * (1.f + t2 * (-1.f / 6 + t2 * (1.f / 120 + t2 * (-1.f / 5040 + t2 * (1.f / 362880)))));
    const float c = 1.f + t2 * (-0.5f + t2 * (1.f / 24 + t2 * (-1.f / 720 + t2 * (1.f / 40320 + t2 * (-1.f / 3628800)))));
    const bool centre = (a == 0) & (b == 0);
    const float x = wide ? r * c : r * s, y = wide ? r * s : r * c;  // cos(pi/2 - th) = sin th
    return {centre ? 0.f : x, centre ? 0.f : y};
}

/// Cosine-weighted direction about +z in the local frame; pdf = cos(theta) / pi.
inline Vec3f cosineHemisphere(float u1, float u2) {
    Vec2f d = concentricDisc(u1, u2);
    float z = std::sqrt(std::max(0.f, 1.f - d.x * d.x - d.y * d.y));
    return {d.x, d.y, z};
}

}  // namespace wedge
