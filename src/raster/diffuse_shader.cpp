// Unshadowed diffuse shading: the lights' closed-form irradiance (scene/light_irradiance.h) times
// the filtered albedo (see diffuse_shader.h).
#include "raster/diffuse_shader.h"

#include "raster/checker_texture.h"

namespace wedge::raster {

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
    return albedo * scene.irradiance(p, n) * kInvPi;
}

}  // namespace wedge::raster
