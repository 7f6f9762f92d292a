#include "render/camera.h"

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
