#include "render/path_sampler.h"

namespace wedge::render {

PathSampler::PathSampler(const scene::Scene& scene, const Camera& camera, bool indirect, uint32_t seed)
    : m_scene(scene), m_camera(camera), m_indirect(indirect), m_seed(seed) {
    m_epsilon = 1e-5f * scene.extent();
    float total = 0;
    for (const auto& l : scene.desc().lights) {
        total += std::max(1e-12f, luminance(l.radiance) * l.area());
        m_lightCdf.push_back(total);
    }
    for (float& c : m_lightCdf) c /= total;
}

ViewGeometry PathSampler::view() const {
    ViewGeometry v = m_camera.view();
    for (const auto& l : m_scene.desc().lights) {
        ViewGeometry::Light g;
        g.center = l.center();
        g.normal = l.normal();
        g.axisA = normalize(l.edge1);
        g.axisB = normalize(cross(g.normal, g.axisA));
        g.sigma = l.sigma();
        g.power = luminance(l.radiance) * l.area();
        v.lights.push_back(g);
    }
    return v;
}

PathSampler::LightSample PathSampler::sampleLight(const Vec3f& p, const Vec3f& n, Vec2f u, float choice) const {
    const auto& lights = m_scene.desc().lights;
    uint32_t li = 0;
    while (li + 1 < lights.size() && choice >= m_lightCdf[li]) ++li;
    float pChoice = m_lightCdf[li] - (li > 0 ? m_lightCdf[li - 1] : 0.f);
    const scene::ParallelogramLight& light = lights[li];
    LightSample s;
    s.light = li;
    s.point = light.pointAt(u.x, u.y);
    Vec3f w = s.point - p;
    s.distance = length(w);
    s.toLight = w / s.distance;
    float cosX = dot(n, s.toLight);
    float cosY = -dot(light.normal(), s.toLight);  // emits only from the front side
    if (cosX <= 0 || cosY <= 0 || s.distance <= 0) {
        s.irradiance = Vec3f(0.f);
    } else {
        // Uniform area sampling: pdf = 1 / (area * pChoice).
        s.irradiance = light.radiance * (cosX * cosY / (s.distance * s.distance) * light.area() / pChoice);
    }
    return s;
}

TracedSample PathSampler::trace(int x, int y, uint32_t index, bool span) const {
    PixelSampler rng(m_seed, uint32_t(y) * uint32_t(m_camera.width()) + uint32_t(x));
    TracedSample out;
    Vec2f pix = rng.get2D(index, kPixel);
    Vec2f lensU = rng.get2D(index, kLens);
    Vec2f choice = rng.get2D(index, kChoice);
    float time = choice.y;
    Vec2f lens = m_camera.hasLens() ? concentricDisc(lensU.x, lensU.y) : Vec2f{0, 0};
    out.record.lens = lens;

    Ray ray = m_camera.generate(float(x) + pix.x, float(y) + pix.y, lens);
    scene::Hit hit;
    ++out.rays;
    if (!m_scene.intersect(ray.origin, ray.direction, 0.f, kInf, time, hit)) return out;

    const scene::Material& mat = m_scene.material(hit.material);
    bool front = dot(hit.normal, ray.direction) < 0;
    Vec3f n = front ? hit.normal : -hit.normal;  // two-sided shading
    out.hit = true;
    out.albedo = mat.albedo;
    out.normal = n;
    out.position = hit.position;
    out.depth = m_camera.depth(hit.position);
    out.object = hit.object;
    if (front) out.emission = mat.emission;  // emitters shine from their front side

    // Direct light at the primary hit.
    const auto& lights = m_scene.desc().lights;
    LightSample ls = sampleLight(hit.position, n, rng.get2D(index, kLight), choice.x);
    out.record.light = ls.light;
    out.record.lightPoint = ls.point;
    if (maxComponent(ls.irradiance) > 0) {
        out.record.unoccluded = luminance(ls.irradiance) * kInvPi;
        Vec3f org = offset(hit.position, n);
        Vec3f toPoint = ls.point - org;
        float dist = length(toPoint);
        Vec3f dir = toPoint / dist;
        float tMax = dist * (1.f - 1e-4f);
        out.shadowTested = true;
        out.d1 = length(lights[ls.light].center() - hit.position);
        ++out.rays;
        if (span) {
            scene::OccluderSpan s = m_scene.occluders(org, dir, 0.f, tMax, time);
            out.occluded = s.occluded;
            out.tNear = s.tNear;
            out.tFar = s.tFar;
        } else {
            out.occluded = m_scene.occluded(org, dir, 0.f, tMax, time);
        }
        if (!out.occluded) out.record.direct = ls.irradiance * kInvPi;
    }

    // One diffuse bounce, lit by its own light sample.
    if (m_indirect && maxComponent(mat.albedo) > 0) {
        Vec2f ub = rng.get2D(index, kBounce);
        Frame frame(n);
        Vec3f dir = frame.toWorld(cosineHemisphere(ub.x, ub.y));
        out.record.bounceDir = dir;
        scene::Hit h2;
        ++out.rays;
        if (m_scene.intersect(offset(hit.position, n), dir, 0.f, kInf, time, h2)) {
            out.bounceHit = true;
            out.bounceDistance = h2.t;
            const scene::Material& m2 = m_scene.material(h2.material);
            Vec3f n2 = dot(h2.normal, dir) < 0 ? h2.normal : -h2.normal;
            if (maxComponent(m2.albedo) > 0) {
                LightSample l2 = sampleLight(h2.position, n2, rng.get2D(index, kBounceLight), choice.x);
                if (maxComponent(l2.irradiance) > 0) {
                    Vec3f org2 = offset(h2.position, n2);
                    Vec3f toPoint = l2.point - org2;
                    float dist = length(toPoint);
                    ++out.rays;
                    if (!m_scene.occluded(org2, toPoint / dist, 0.f, dist * (1.f - 1e-4f), time))
                        // Cosine-weighted bounce: (albedo/pi) L cos / (cos/pi) = albedo L, so the
                        // demodulated indirect is the incident radiance L = albedo2 E2 / pi.
                        out.record.indirect = m2.albedo * l2.irradiance * kInvPi;
                }
            }
        }
    }
    return out;
}

}  // namespace wedge::render
