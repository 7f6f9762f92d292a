// The thin-lens camera of the scene format seen by the rasterizer: world -> camera space
// (x along right, y along up, z along forward), pinhole projection to pixels, and the thin-lens
// shear. A point at depth Z seen from lens position (lu, lv) on the unit disc lands at
// (x0 + phi(Z) lu, y0 - phi(Z) lv), with (x0, y0) its pinhole image and
// phi(Z) = A f (1/F - 1/Z) the signed circle-of-confusion radius in pixels (the phi of
// Vaidyanathan et al. 2012, eq. 4 and Fig. 2b). The ray tracer's render/camera.h uses the same
// conventions; this file repeats the math so that the raster module needs no Embree.
#pragma once

#include "core/math.h"
#include "scene/scene_desc.h"

namespace wedge::raster {

class RasterCamera {
public:
    explicit RasterCamera(const scene::CameraDesc& d)
        : m_position(d.position), m_width(d.width), m_height(d.height), m_aperture(d.apertureRadius),
          m_focus(d.focusDistance) {
        m_forward = normalize(d.lookAt - d.position);
        m_right = normalize(cross(m_forward, d.up));
        m_up = cross(m_right, m_forward);
        float tanHalfY = std::tan(0.5f * d.fovY * kPi / 180.f);
        m_focalPixels = 0.5f * float(d.height) / tanHalfY;
    }

    Vec3f toCamera(const Vec3f& pWorld) const {
        Vec3f v = pWorld - m_position;
        return {dot(v, m_right), dot(v, m_up), dot(v, m_forward)};
    }
    Vec3f directionToCamera(const Vec3f& dirWorld) const {
        return {dot(dirWorld, m_right), dot(dirWorld, m_up), dot(dirWorld, m_forward)};
    }
    Vec3f directionToWorld(const Vec3f& dirCamera) const {
        return m_right * dirCamera.x + m_up * dirCamera.y + m_forward * dirCamera.z;
    }

    /// Pinhole image (pixels, y down) of a camera-space point with z > 0.
    Vec2f project(const Vec3f& pCamera) const {
        return {0.5f * m_width + m_focalPixels * pCamera.x / pCamera.z,
                0.5f * m_height - m_focalPixels * pCamera.y / pCamera.z};
    }
    /// Signed circle of confusion phi(Z), pixels per unit lens coordinate (0 for a pinhole).
    float circleOfConfusion(float depth) const { return m_aperture * m_focalPixels * (1.f / m_focus - 1.f / depth); }

    /// Camera-space ray of film position (px, py) and lens point (lu, lv) on the unit disc. The
    /// direction is not normalised: its z is F, so a hit at parameter t has depth t F.
    void ray(float px, float py, float lu, float lv, Vec3f& origin, Vec3f& dir) const {
        float xc = (px - 0.5f * m_width) / m_focalPixels, yc = (0.5f * m_height - py) / m_focalPixels;
        origin = {m_aperture * lu, m_aperture * lv, 0.f};
        dir = {m_focus * xc - origin.x, m_focus * yc - origin.y, m_focus};
    }

    /// Camera-space direction of the pinhole ray through film position (px, py), with z = 1.
    Vec3f pinholeDirection(float px, float py) const {
        return {(px - 0.5f * m_width) / m_focalPixels, (0.5f * m_height - py) / m_focalPixels, 1.f};
    }

    const Vec3f& position() const { return m_position; }
    int width() const { return m_width; }
    int height() const { return m_height; }
    float focalPixels() const { return m_focalPixels; }
    float apertureRadius() const { return m_aperture; }
    float focusDistance() const { return m_focus; }

private:
    Vec3f m_position, m_forward, m_right, m_up;
    int m_width, m_height;
    float m_aperture;  // world units
    float m_focus;     // world units along forward
    float m_focalPixels = 1;
};

}  // namespace wedge::raster
