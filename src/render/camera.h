// Thin-lens camera of the scene format: forward = normalize(look_at - position),
// right = normalize(cross(forward, up)), image x along right, image y downward; a disc aperture
// of radius A and a plane of focus at distance F along forward. With A = 0 it is a pinhole.
//
// A moving camera (CameraDesc::velocity, lookAtVelocity) is this camera at every shutter time t
// in [0, 1], with position + D t and look_at + L t (D, L: the velocities times the shutter's
// length) and the same `up`, field of view, lens and focus distance: a translation moves every
// ray's origin, a moving look_at turns the camera (a pan or a tilt), and a pixel's rays at
// time t are those of the camera at t.
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

    /// Where the camera is and how it is turned at one shutter time.
    struct Pose {
        Vec3f position, forward, right, up;
    };

    /// The ray through film position (px, py) in pixels (0..W, 0..H) and lens point `lens` on the
    /// unit disc, at shutter time `time` in [0, 1].
    Ray generate(float px, float py, Vec2f lens, float time = 0.f) const {
        const Pose pose = poseAt(time);
        float xc = (2.f * px / m_width - 1.f) * m_tanHalfX;
        float yc = (1.f - 2.f * py / m_height) * m_tanHalfY;
        Vec3f dirPinhole = pose.forward + pose.right * xc + pose.up * yc;
        if (m_aperture <= 0) return {pose.position, normalize(dirPinhole)};
        // All rays through film point (xc, yc) meet on the plane of focus.
        Vec3f focus = pose.position + dirPinhole * m_focus;
        Vec3f origin = pose.position + (pose.right * lens.x + pose.up * lens.y) * m_aperture;
        return {origin, normalize(focus - origin)};
    }

    /// generate() for n <= 16 rays at once, into origin[0..n) and direction[0..n): its
    /// arithmetic in its order, lane by lane (the same bits where both are compiled alike, as in
    /// camera.cpp; render_test compares to rounding), as a loop that the compiler vectorises across the rays
    /// where the camera does not turn (a turning camera's pose, `turned`, takes the loop over
    /// generate()).
    void generate(int n, const float* px, const float* py, const Vec2f* lens, const float* time, Vec3f* origin,
                  Vec3f* direction) const;

    /// Image position (pixels) of a world point seen through the lens centre at shutter time t.
    Vec2f project(const Vec3f& p, float time = 0.f) const;
    /// Depth of a world point along forward, from the camera at shutter time t.
    float depth(const Vec3f& p, float time = 0.f) const {
        const Pose pose = poseAt(time);
        return dot(p - pose.position, pose.forward);
    }
    /// The camera at shutter time t (the one pose of a still camera).
    Pose poseAt(float time) const {
        if (!m_moving) return m_pose;
        const Vec3f position = m_pose.position + m_displacement * time;
        if (!m_turning) return {position, m_pose.forward, m_pose.right, m_pose.up};
        return turned(position, m_lookAt + m_lookAtDisplacement * time);
    }
    /// Whether the camera moves (translates or turns) over the shutter.
    bool moving() const { return m_moving; }

    ViewGeometry view() const;
    int width() const { return m_width; }
    int height() const { return m_height; }
    float focalPixels() const { return m_focalPixels; }
    bool hasLens() const { return m_aperture > 0; }

private:
    /// The pose at `position` looking at `lookAt`, with the scene's up.
    Pose turned(const Vec3f& position, const Vec3f& lookAt) const;

    Pose m_pose;  // at the shutter's open
    Vec3f m_lookAt, m_sceneUp;
    Vec3f m_displacement{0.f}, m_lookAtDisplacement{0.f};  // over the whole shutter
    bool m_moving = false, m_turning = false;
    int m_width, m_height;
    float m_tanHalfX, m_tanHalfY, m_focalPixels, m_aperture, m_focus;
};

}  // namespace wedge::render
