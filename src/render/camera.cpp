#include "render/camera.h"

namespace wedge::render {

Camera::Camera(const scene::CameraDesc& d)
    : m_position(d.position), m_width(d.width), m_height(d.height), m_aperture(d.apertureRadius), m_focus(d.focusDistance) {
    m_forward = normalize(d.lookAt - d.position);
    m_right = normalize(cross(m_forward, d.up));
    m_up = cross(m_right, m_forward);
    m_tanHalfY = std::tan(0.5f * d.fovY * kPi / 180.f);
    m_tanHalfX = m_tanHalfY * float(d.width) / float(d.height);
    m_focalPixels = 0.5f * float(d.height) / m_tanHalfY;
    m_displacement = d.displacement();
    m_moving = m_displacement != Vec3f(0.f);
}

Vec2f Camera::project(const Vec3f& p, float time) const {
    Vec3f v = p - positionAt(time);
    float z = dot(v, m_forward);
    float xc = dot(v, m_right) / z, yc = dot(v, m_up) / z;
    return {(xc / m_tanHalfX + 1.f) * 0.5f * m_width, (1.f - yc / m_tanHalfY) * 0.5f * m_height};
}

ViewGeometry Camera::view() const {
    ViewGeometry v;
    v.width = m_width;
    v.height = m_height;
    // A moving camera's at mid-shutter: the filters take a pixel's view direction from it and the
    // pixel's mean hit point, which its samples at every shutter time make (filter_frames.cpp).
    v.cameraPosition = positionAt(0.5f);
    v.forward = m_forward;
    v.right = m_right;
    v.up = m_up;
    v.focalPixels = m_focalPixels;
    v.apertureRadius = m_aperture;
    v.focusDistance = m_focus;
    return v;
}

}  // namespace wedge::render
