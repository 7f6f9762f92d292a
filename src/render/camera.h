// Thin-lens camera of the scene format: forward = normalize(look_at - position),
// right = normalize(cross(forward, up)), image x along right, image y downward; a disc aperture
// of radius A and a plane of focus at distance F along forward. With A = 0 it is a pinhole.
#pragma once

#include "core/buffers.h"
#include "scene/scene_desc.h"

namespace wedge::render {

struct Ray {
    Vec3f origin, direction;  // direction is unit length
};

class Camera {
public:
    explicit Camera(const scene::CameraDesc& desc);

    /// The ray through film position (px, py) in pixels (0..W, 0..H) and lens point `lens` on the
    /// unit disc.
    Ray generate(float px, float py, Vec2f lens) const {
        float xc = (2.f * px / m_width - 1.f) * m_tanHalfX;
        float yc = (1.f - 2.f * py / m_height) * m_tanHalfY;
        Vec3f dirPinhole = m_forward + m_right * xc + m_up * yc;
        if (m_aperture <= 0) return {m_position, normalize(dirPinhole)};
        // All rays through film point (xc, yc) meet on the plane of focus.
        Vec3f focus = m_position + dirPinhole * m_focus;
        Vec3f origin = m_position + (m_right * lens.x + m_up * lens.y) * m_aperture;
        return {origin, normalize(focus - origin)};
    }

    /// Image position (pixels) of a world point seen through the lens centre.
    Vec2f project(const Vec3f& p) const;
    /// Depth of a world point along forward.
    float depth(const Vec3f& p) const { return dot(p - m_position, m_forward); }

    ViewGeometry view() const;
    int width() const { return m_width; }
    int height() const { return m_height; }
    float focalPixels() const { return m_focalPixels; }
    bool hasLens() const { return m_aperture > 0; }

private:
    Vec3f m_position, m_forward, m_right, m_up;
    int m_width, m_height;
    float m_tanHalfX, m_tanHalfY, m_focalPixels, m_aperture, m_focus;
};

}  // namespace wedge::render
