#include "render/camera.h"

#include <type_traits>

namespace wedge::render {

Camera::Camera(const scene::CameraDesc& d)
    : m_lookAt(d.lookAt), m_sceneUp(d.up), m_width(d.width), m_height(d.height), m_aperture(d.apertureRadius),
      m_focus(d.focusDistance) {
    m_pose = turned(d.position, d.lookAt);
    m_tanHalfY = std::tan(0.5f * d.fovY * kPi / 180.f);
    m_tanHalfX = m_tanHalfY * float(d.width) / float(d.height);
    m_focalPixels = 0.5f * float(d.height) / m_tanHalfY;
    m_displacement = d.displacement();
    m_lookAtDisplacement = d.lookAtVelocity * d.shutterLength();
    m_turning = m_lookAtDisplacement != m_displacement;  // (look_at moving with the camera: a translation)
    m_moving = m_turning || m_displacement != Vec3f(0.f);
}

Camera::Pose Camera::turned(const Vec3f& position, const Vec3f& lookAt) const {
    Pose p;
    p.position = position;
    p.forward = normalize(lookAt - position);
    p.right = normalize(cross(p.forward, m_sceneUp));
    p.up = cross(p.right, p.forward);
    return p;
}

void Camera::generate(int n, const float* px, const float* py, const Vec2f* lens, const float* time, Vec3f* origin,
                      Vec3f* direction) const {
    if (m_turning) {
        for (int k = 0; k < n; ++k) {
            const Ray ray = generate(px[k], py[k], lens[k], time[k]);
            origin[k] = ray.origin;
            direction[k] = ray.direction;
        }
        return;
    }
    // generate()'s arithmetic, in its order, on the pose of a camera that at most translates.
    const Vec3f p0 = m_pose.position, d = m_displacement, f = m_pose.forward, r = m_pose.right, u = m_pose.up;
    const float w = float(m_width), h = float(m_height), tx = m_tanHalfX, ty = m_tanHalfY;
    const float aperture = m_aperture, focusDistance = m_focus;
    auto rays = [&](auto moving, auto lensed) {
        for (int k = 0; k < n; ++k) {
            const float xc = (2.f * px[k] / w - 1.f) * tx;
            const float yc = (1.f - 2.f * py[k] / h) * ty;
            const Vec3f position = moving ? p0 + d * time[k] : p0;
            const Vec3f dirPinhole = f + r * xc + u * yc;
            Vec3f o = position, dir;
            if constexpr (!decltype(lensed)::value) {
                dir = normalize(dirPinhole);
            } else {
                const Vec3f focus = position + dirPinhole * focusDistance;
                o = position + (r * lens[k].x + u * lens[k].y) * aperture;
                dir = normalize(focus - o);
            }
            // Member by member: a Vec3f's copy is one statement the vectoriser does not split.
            origin[k].x = o.x, origin[k].y = o.y, origin[k].z = o.z;
            direction[k].x = dir.x, direction[k].y = dir.y, direction[k].z = dir.z;
        }
    };
    using Yes = std::true_type;
    using No = std::false_type;
    if (m_moving) aperture > 0 ? rays(Yes{}, Yes{}) : rays(Yes{}, No{});
    else aperture > 0 ? rays(No{}, Yes{}) : rays(No{}, No{});
}

Vec2f Camera::project(const Vec3f& p, float time) const {
    const Pose pose = poseAt(time);
    Vec3f v = p - pose.position;
    float z = dot(v, pose.forward);
    float xc = dot(v, pose.right) / z, yc = dot(v, pose.up) / z;
    return {(xc / m_tanHalfX + 1.f) * 0.5f * m_width, (1.f - yc / m_tanHalfY) * 0.5f * m_height};
}

ViewGeometry Camera::view() const {
    // A moving camera's at mid-shutter: the filters take a pixel's view direction from it and the
    // pixel's mean hit point, which its samples at every shutter time make (filter_frames.cpp).
    const Pose pose = poseAt(0.5f);
    ViewGeometry v;
    v.width = m_width;
    v.height = m_height;
    v.cameraPosition = pose.position;
    v.forward = pose.forward;
    v.right = pose.right;
    v.up = pose.up;
    v.focalPixels = m_focalPixels;
    v.apertureRadius = m_aperture;
    v.focusDistance = m_focus;
    return v;
}

}  // namespace wedge::render
