// Thin-lens camera of the scene format: forward = normalize(look_at - position),
// right = normalize(cross(forward, up)), image x along right, image y downward; a disc aperture
// of radius A and a plane of focus at distance F along forward. With A = 0 it is a pinhole. A
// moving camera (CameraDesc::velocity) translates by D = velocity x shutter length over the
// shutter: at shutter time t in [0, 1] every ray leaves from D t further, with the same direction.
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
    /// unit disc, at shutter time `time` in [0, 1].
    Ray generate(float px, float py, Vec2f lens, float time = 0.f) const {
        float xc = (2.f * px / m_width - 1.f) * m_tanHalfX;
        float yc = (1.f - 2.f * py / m_height) * m_tanHalfY;
        Vec3f dirPinhole = m_forward + m_right * xc + m_up * yc;
        const Vec3f position = positionAt(time);
        if (m_aperture <= 0) return {position, normalize(dirPinhole)};
        // All rays through film point (xc, yc) meet on the plane of focus.
        Vec3f focus = position + dirPinhole * m_focus;
        Vec3f origin = position + (m_right * lens.x + m_up * lens.y) * m_aperture;
        return {origin, normalize(focus - origin)};
    }

    /// Image position (pixels) of a world point seen through the lens centre at shutter time t.
    Vec2f project(const Vec3f& p, float time = 0.f) const;
    /// Depth of a world point along forward, from the camera at shutter time t.
    float depth(const Vec3f& p, float time = 0.f) const { return dot(p - positionAt(time), m_forward); }
    /// The lens centre at shutter time t.
    Vec3f positionAt(float time) const { return m_moving ? m_position + m_displacement * time : m_position; }
    /// Whether the camera translates over the shutter.
    bool moving() const { return m_moving; }

    ViewGeometry view() const;
    int width() const { return m_width; }
    int height() const { return m_height; }
    float focalPixels() const { return m_focalPixels; }
    bool hasLens() const { return m_aperture > 0; }

private:
    Vec3f m_position, m_forward, m_right, m_up;
    Vec3f m_displacement{0.f};  // over the whole shutter
    bool m_moving = false;
    int m_width, m_height;
    float m_tanHalfX, m_tanHalfY, m_focalPixels, m_aperture, m_focus;
};

}  // namespace wedge::render
