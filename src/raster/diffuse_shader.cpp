// Unshadowed diffuse shading: Lambert's polygon irradiance for each parallelogram light, clipped
// to the receiver's hemisphere, times the filtered albedo (see diffuse_shader.h).
#include "raster/diffuse_shader.h"

#include "raster/checker_texture.h"

namespace wedge::raster {

float polygonIrradiance(const scene::ParallelogramLight& light, const Vec3f& p, const Vec3f& n) {
    if (dot(p - light.corner, light.normal()) <= 0) return 0.f;  // behind the emitting side
    Vec3f in[4] = {light.corner - p, light.corner + light.edge1 - p, light.corner + light.edge1 + light.edge2 - p,
                   light.corner + light.edge2 - p};
    // Sutherland-Hodgman against the receiver's tangent plane dot(n, r) >= 0.
    Vec3f out[8];
    int count = 0;
    for (int k = 0; k < 4; ++k) {
        const Vec3f& a = in[k];
        const Vec3f& b = in[(k + 1) % 4];
        float da = dot(n, a), db = dot(n, b);
        if (da >= 0) out[count++] = a;
        if ((da >= 0) != (db >= 0)) out[count++] = a + (b - a) * (da / (da - db));
    }
    if (count < 3) return 0.f;
    float sum = 0;
    for (int k = 0; k < count; ++k) {
        Vec3f a = normalize(out[k]), b = normalize(out[(k + 1) % count]);
        Vec3f c = cross(a, b);
        float len = length(c);
        if (len < 1e-12f) continue;
        sum += std::atan2(len, dot(a, b)) * dot(c, n) / len;
    }
    return 0.5f * std::abs(sum);
}

Vec3f shadeSurface(const RasterScene& scene, const RasterTriangle& tri, const Vec3f& bary, float tau,
                   const Vec3f& footA, const Vec3f& footB) {
    const scene::Material& m = scene.materials[tri.material];
    if (m.isEmitter()) return m.emission;
    Vec3f pRest = tri.pointRest(bary);
    Vec3f p = pRest + tri.motionWorld * tau;
    Vec3f n = normalize(tri.nWorld[0] * bary.x + tri.nWorld[1] * bary.y + tri.nWorld[2] * bary.z);
    // Two-sided: shade the side the camera sees.
    if (dot(tri.faceNormalWorld, scene.camera.position() - p) < 0) n = -n;
    Vec3f albedo = texturedAlbedo(m, pRest, tri.faceNormalWorld, footA, footB);
    Vec3f irradiance(0.f);
    for (const auto& l : scene.lights) irradiance += l.radiance * polygonIrradiance(l, p, n);
    return albedo * irradiance * kInvPi;
}

}  // namespace wedge::raster
