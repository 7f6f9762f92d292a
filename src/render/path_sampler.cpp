#include "render/path_sampler.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <memory>

#include "core/light_field.h"

namespace wedge::render {

namespace {

/// The shading normal on the geometric normal's side (vn may be authored either way round).
Vec3f facing(const Vec3f& shading, const Vec3f& geometric) { return dot(shading, geometric) < 0 ? -shading : shading; }

/// samplePlanarLights' arithmetic once each sample's light is chosen (li[k]; with kOne, the
/// scene's only light, whose data the loop then reads once instead of gathering it).
template <bool kOne>
void kernelPlanarLights(int n, const int* __restrict li, const float* __restrict cdf, const Vec3f* __restrict corner,
                        const Vec3f* __restrict edge1, const Vec3f* __restrict edge2, const Vec3f* __restrict normal,
                        const Vec3f* __restrict radiance, const float* __restrict area,
                        const int* __restrict triangle, const Vec3f* __restrict p, const Vec3f* __restrict nrm,
                        const Vec2f* __restrict u, PathSampler::LightSample* __restrict out) {
    for (int k = 0; k < n; ++k) {
        const int i = kOne ? 0 : li[k];
        const float pChoice = cdf[i + 1] - cdf[i];  // sampleLight's
        const bool fold = triangle[i] && u[k].x + u[k].y > 1.f;  // AreaLight::pointAt
        const float a = fold ? 1.f - u[k].x : u[k].x, b = fold ? 1.f - u[k].y : u[k].y;
        const Vec3f point = corner[i] + edge1[i] * a + edge2[i] * b;
        const Vec3f w = point - p[k];
        const float distance = length(w);
        const Vec3f toLight = w / distance;
        const float cosX = dot(nrm[k], toLight);
        const float cosY = -dot(normal[i], toLight);
        const bool dark = cosX <= 0 || cosY <= 0 || distance <= 0;
        const float e = cosX * cosY / (distance * distance) * area[i] / pChoice;
        const Vec3f r = radiance[i];
        // Member by member: a Vec3f's copy is one statement the vectoriser does not split.
        PathSampler::LightSample& s = out[k];
        s.point.x = point.x, s.point.y = point.y, s.point.z = point.z;
        s.toLight.x = toLight.x, s.toLight.y = toLight.y, s.toLight.z = toLight.z;
        s.distance = distance;
        s.light = uint32_t(i);
        s.irradiance.x = dark ? 0.f : r.x * e, s.irradiance.y = dark ? 0.f : r.y * e, s.irradiance.z = dark ? 0.f : r.z * e;
    }
}

/// For lanes l < n: the cosine-weighted bounce direction about the shading normal and its dot
/// product with the geometric normal (<= 0: into the facet), as a loop across the lanes that the
/// compiler vectorises (lanes without a hit take their dummy normals and are skipped after).
void bounceDirections(int n, const Vec3f* __restrict normal, const Vec3f* __restrict geometric,
                      const Vec2f* __restrict u, Vec3f* __restrict dir, float* __restrict intoFacet) {
    for (int l = 0; l < n; ++l) {
        const Vec3f d = Frame(normal[l]).toWorld(cosineHemisphere(u[l].x, u[l].y));
        dir[l].x = d.x, dir[l].y = d.y, dir[l].z = d.z;  // (member by member: see kernelPlanarLights)
        intoFacet[l] = dot(d, geometric[l]);
    }
}

/// The per-light data sampleLight reads, as tables by light index (PathSampler::sampleLights).
struct PlanarLights {
    int count;
    const float* cdf;  // cdf[i + 1]: the cumulative share of lights 0..i; cdf[0] = 0
    const Vec3f *corner, *edge1, *edge2, *normal, *radiance;
    const float* area;
    const int* triangle;  // 1 for a triangle (int: a gather of bytes does not vectorise)
};

/// PathSampler::sampleLight's arithmetic, in its order, for samples k < n on planar lights, as
/// loops across the samples that the compiler vectorises (the per-light data gathered by index):
/// the same samples to the bit. (The pointers are __restrict parameters, so that the gathers
/// need no run-time check against the stores.)
void samplePlanarLights(const PlanarLights& lights, int n, const Vec3f* __restrict p, const Vec3f* __restrict nrm,
                        const Vec2f* __restrict u, const float* __restrict choice,
                        PathSampler::LightSample* __restrict out) {
    assert(n <= PathSampler::kLightBatch);
    int li[PathSampler::kLightBatch];  // (signed: the gathers' indices)
    const int count = lights.count;
    const float* __restrict cdf = lights.cdf;
    for (int k = 0; k < n; ++k) li[k] = 0;
    if (count > 1) {
        // upper_bound as the count of cumulative shares <= choice, found bit by bit from the
        // highest (the same index for a sorted table), then the last light for rounding's sake.
        for (int step = int(std::bit_floor(uint32_t(count))); step > 0; step >>= 1)
            for (int k = 0; k < n; ++k) {
                const int j = li[k] + step;
                const float share = cdf[std::min(j, count)];
                li[k] = (j <= count) & (share <= choice[k]) ? j : li[k];
            }
        for (int k = 0; k < n; ++k) li[k] = std::min(li[k], count - 1);
    }
    if (count == 1)
        kernelPlanarLights<true>(n, li, cdf, lights.corner, lights.edge1, lights.edge2, lights.normal, lights.radiance,
                                 lights.area, lights.triangle, p, nrm, u, out);
    else
        kernelPlanarLights<false>(n, li, cdf, lights.corner, lights.edge1, lights.edge2, lights.normal,
                                  lights.radiance, lights.area, lights.triangle, p, nrm, u, out);
}

}  // namespace

PathSampler::PathSampler(const scene::Scene& scene, const Camera& camera, bool indirect, uint32_t seed)
    : m_scene(scene), m_camera(camera), m_indirect(indirect), m_seed(seed),
      m_group(scene::lightGroups(scene.desc().lights)), m_irradiance(scene.desc().lights, m_group) {
    m_epsilon = 1e-5f * scene.extent();
    m_needChoice = scene.desc().lights.size() > 1 || scene.desc().hasMotion();
    float total = 0;
    m_lightCdf.push_back(0.f);
    for (const auto& l : scene.desc().lights) {
        total += std::max(1e-12f, luminance(l.radiance) * l.area());
        m_lightCdf.push_back(total);
        m_lightNormal.push_back(l.sphere() ? Vec3f(0.f) : l.normal());
        m_lightArea.push_back(l.area());
        m_lightCorner.push_back(l.corner);
        m_lightEdge1.push_back(l.edge1);
        m_lightEdge2.push_back(l.edge2);
        m_lightRadiance.push_back(l.radiance);
        m_lightTriangle.push_back(l.triangle() ? 1 : 0);
        m_anySphere = m_anySphere || l.sphere();
    }
    for (float& c : m_lightCdf) c /= total;
    // The lights the filters see (scene::lightGroups) and their centroids.
    const auto& lights = scene.desc().lights;
    for (size_t i = 0; i < lights.size(); ++i) {
        if (m_group[i] == m_groupCenter.size()) {
            m_groupCenter.push_back(Vec3f(0.f));
            m_groupArea.push_back(0.f);
        }
        m_groupCenter[m_group[i]] += lights[i].center() * lights[i].area();
        m_groupArea[m_group[i]] += lights[i].area();
    }
    std::vector<int> parts(m_groupArea.size(), 0);
    for (uint32_t g : m_group) ++parts[g];
    for (size_t g = 0; g < m_groupArea.size(); ++g) m_groupCenter[g] = m_groupCenter[g] / m_groupArea[g];
    for (size_t i = 0; i < lights.size(); ++i)  // a light on its own: its centre to the last bit
        if (parts[m_group[i]] == 1) m_groupCenter[m_group[i]] = lights[i].center();
}

ViewGeometry PathSampler::view() const {
    ViewGeometry v = m_camera.view();
    const auto& lights = m_scene.desc().lights;
    v.lights.resize(m_groupCenter.size());
    for (size_t i = 0; i < lights.size(); ++i) {
        const scene::AreaLight& l = lights[i];
        ViewGeometry::Light& g = v.lights[m_group[i]];
        g.power += luminance(l.radiance) * l.area();
        if (l.sphere()) {
            // Seen from anywhere a disc of its radius, facing the viewer: the Gaussian is that
            // disc's; no plane, no parts (scene::lightGroups keeps a sphere on its own).
            g.sphere = true;
            g.normal = Vec3f(0, 1, 0);
            g.axisA = Vec3f(1, 0, 0);
            g.axisB = Vec3f(0, 0, 1);
            g.sigma = 0.5f * std::sqrt(kPi * l.radius * l.radius);
            continue;
        }
        if (g.parts.empty()) {  // the group's frame: its first light's
            g.normal = l.normal();
            g.axisA = normalize(l.edge1);
            g.axisB = normalize(cross(g.normal, g.axisA));
        }
        g.parts.push_back({l.corner, l.edge1, l.edge2, l.triangle(), l.area() / m_groupArea[m_group[i]]});
    }
    for (size_t k = 0; k < v.lights.size(); ++k) {
        ViewGeometry::Light& g = v.lights[k];
        g.center = m_groupCenter[k];
        // The Gaussian the analysis treats the light as (NOTES: sqrt(area) / 2), of the whole group.
        if (!g.sphere) g.sigma = 0.5f * std::sqrt(m_groupArea[k]);
    }
    return v;
}

PathSampler::LightSample PathSampler::sampleLight(const Vec3f& p, const Vec3f& n, Vec2f u, float choice) const {
    const auto& lights = m_scene.desc().lights;
    // The first light whose cumulative share exceeds `choice` (the last one for rounding's sake).
    const uint32_t li = uint32_t(std::min<size_t>(
        std::upper_bound(m_lightCdf.begin() + 1, m_lightCdf.end(), choice) - m_lightCdf.begin() - 1, lights.size() - 1));
    const float pChoice = m_lightCdf[li + 1] - m_lightCdf[li];  // (the first light's: its share - 0, to the bit)
    const scene::AreaLight& light = lights[li];
    LightSample s;
    s.light = li;
    if (light.sphere()) return sampleSphere(light, li, p, n, u, pChoice);
    s.point = light.pointAt(u.x, u.y);
    Vec3f w = s.point - p;
    s.distance = length(w);
    s.toLight = w / s.distance;
    float cosX = dot(n, s.toLight);
    float cosY = -dot(m_lightNormal[li], s.toLight);  // emits only from the front side
    if (cosX <= 0 || cosY <= 0 || s.distance <= 0) {
        s.irradiance = Vec3f(0.f);
    } else {
        // Uniform area sampling: pdf = 1 / (area * pChoice).
        s.irradiance = light.radiance * (cosX * cosY / (s.distance * s.distance) * m_lightArea[li] / pChoice);
    }
    return s;
}

void PathSampler::sampleLights(int n, const Vec3f* p, const Vec3f* nrm, const Vec2f* u, const float* choice,
                               LightSample* out) const {
    if (m_anySphere) {
        for (int k = 0; k < n; ++k) out[k] = sampleLight(p[k], nrm[k], u[k], choice[k]);
        return;
    }
    const PlanarLights lights{int(m_lightCdf.size()) - 1, m_lightCdf.data(), m_lightCorner.data(), m_lightEdge1.data(),
                              m_lightEdge2.data(), m_lightNormal.data(), m_lightRadiance.data(), m_lightArea.data(),
                              m_lightTriangle.data()};
    samplePlanarLights(lights, n, p, nrm, u, choice, out);
}

PathSampler::LightSample PathSampler::sampleSphere(const scene::AreaLight& light, uint32_t index, const Vec3f& p,
                                                   const Vec3f& n, Vec2f u, float pChoice) const {
    // Uniform in the cone of directions the sphere fills seen from p (half-angle alpha, sin alpha
    // = r / d), to the nearer of the two points where a direction meets it: pdf 1 / (2 pi (1 -
    // cos alpha)) per solid angle. From inside (or on) the sphere nothing: its outside faces away.
    LightSample s;
    s.light = index;
    s.irradiance = Vec3f(0.f);
    const Vec3f w = light.corner - p;
    const float d2 = dot(w, w), r2 = light.radius * light.radius;
    if (d2 <= r2) {
        s.point = light.corner;
        s.toLight = Vec3f(0, 1, 0);
        s.distance = 0;
        return s;
    }
    const float d = std::sqrt(d2), sin2 = r2 / d2;
    const float oneMinusCos = sin2 / (1.f + std::sqrt(1.f - sin2));  // 1 - cos alpha without cancellation
    const float cosT = 1.f - u.x * oneMinusCos, sinT = std::sqrt(std::max(0.f, 1.f - cosT * cosT));
    const float phi = 2.f * kPi * u.y;
    const Vec3f axis = w / d;
    const Vec3f a = normalize(cross(axis, std::abs(axis.x) < 0.9f ? Vec3f(1, 0, 0) : Vec3f(0, 1, 0))), b = cross(axis, a);
    s.toLight = normalize(axis * cosT + a * (sinT * std::cos(phi)) + b * (sinT * std::sin(phi)));
    // The nearer intersection: t = d cos - sqrt(r^2 - d^2 sin^2), clamped at the silhouette.
    const float along = dot(w, s.toLight);
    s.distance = std::max(0.f, along - std::sqrt(std::max(0.f, r2 - (d2 - along * along))));
    s.point = p + s.toLight * s.distance;
    const float cosX = dot(n, s.toLight);
    if (cosX > 0 && s.distance > 0)
        s.irradiance = light.radiance * (cosX * 2.f * kPi * oneMinusCos / pChoice);  // L cos / (pdf pChoice)
    return s;
}

TracedSample PathSampler::trace(int x, int y, uint32_t index, bool slopes) const {
    TracedSample out;
    traceBatch(x, y, index, 1, slopes, &out);
    return out;
}

void PathSampler::setPrimaryHit(TracedSample& o, const scene::Hit& hit, const Vec3f& geometric, float time) const {
    o.hit = true;
    o.albedo = hit.albedo;
    o.normal = facing(hit.shadingNormal, geometric);
    o.position = hit.position;
    o.depth = m_camera.depth(hit.position, time);
    o.object = hit.object;
}

PathSampler::ShutterPath PathSampler::shutterPath(const scene::Hit& hit, float time) const {
    const scene::RigidMotion* m = hit.motion;
    const Vec3f atOpen = m ? m->atOpen(hit.position, time) : hit.position;
    const Vec3f atClose = m ? m->atClose(hit.position, time) : hit.position;
    return {atOpen, atClose, m_camera.project(atOpen, 0.f), m_camera.project(atClose, 1.f)};
}

void PathSampler::cameraRays(const PixelSampler& rng, int x, int y, uint32_t first, int n, scene::RayPacket& primary,
                             Vec2f* lens, float* choice, float* time, Vec2f* uLight, Vec2f* film) const {
    constexpr int K = scene::RayPacket::kSize;
    Vec2f uPix[K], uLens[K], uChoice[K];
    // Pixel and lens positions as one 4D Sobol point, so a defocused edge (a discontinuity in
    // (x, y, u, v) together) is stratified jointly; the pixel positions are those of a pinhole.
    if (m_camera.hasLens()) rng.get4DBatch(first, uint32_t(n), kPixel, uPix, uLens);
    else rng.get2DBatch(first, uint32_t(n), kPixel, uPix);
    // The light choice and the shutter time as Sobol dimensions 2-3 of the light sample's point
    // (dimensions 0-1, `uLight`, are exactly get2D(kLight) either way):
    // the samples that choose one light are then stratified over it too, and a moving
    // occluder's shadow (a function of time and light point together) is stratified jointly.
    // Against an independent pair (MC at 16 spp, relMSE, three seeds): a square lamp of 4
    // triangles -19%, a 4 x 4 grid of quads -7%, a 12-triangle disc -5%, that disc and a
    // triangle light -5% (docs/lamps); docs/motion.json -20%.
    Vec2f scratch[K];
    if (m_needChoice) {
        rng.get4DBatch(first, uint32_t(n), kLight, uLight ? uLight : scratch, uChoice);
    } else {
        if (uLight) rng.get2DBatch(first, uint32_t(n), kLight, uLight);
        std::fill(uChoice, uChoice + n, Vec2f{0, 0});
    }
    // Loops the compiler vectorises across the samples (Camera::generate's batch too).
    float px[K], py[K];
    for (int k = 0; k < n; ++k) {
        choice[k] = uChoice[k].x;
        time[k] = uChoice[k].y;
        px[k] = float(x) + uPix[k].x;
        py[k] = float(y) + uPix[k].y;
    }
    if (m_camera.hasLens())
        for (int k = 0; k < n; ++k) lens[k] = concentricDisc(uLens[k].x, uLens[k].y);
    else
        std::fill(lens, lens + n, Vec2f{0, 0});
    if (film) std::copy(uPix, uPix + n, film);
    m_camera.generate(n, px, py, lens, time, primary.org, primary.dir);
    for (int k = 0; k < n; ++k) {
        primary.valid[k] = -1;
        primary.tFar[k] = kInf;
        primary.time[k] = time[k];
    }
}

/// A wave of samples traced together (PathSampler::traceMany): up to kLanes samples of
/// several pixels, 16 at a time through the camera (one pixel's batch: a coherent packet), and
/// then each of the other three kinds of ray (shadow, bounce, the bounce's shadow) as one
/// Embree stream. Kept per thread and reused.
struct PathSampler::Wave {
    static constexpr int kLanes = kLightBatch;
    TracedSample* out[kLanes];
    float time[kLanes], choice[kLanes];
    Vec3f normal[kLanes], geometric[kLanes];  // shading and geometric normals, on the side the ray came from
    Vec2f uLight[kLanes], uBounce[kLanes], uBounceLight[kLanes];
    LightSample ls[kLanes];
    scene::Hit hit[kLanes];
    bool found[kLanes];
    // The bounce rays (a stream), the lane of each, their hits and light samples.
    scene::RaySegment bounce[kLanes];
    uint16_t bounceLane[kLanes];
    scene::Hit h2[kLanes];
    bool found2[kLanes];
    // A stream of shadow rays and the lane (or the bounce hit's light sample, atSample) each belongs to.
    scene::RaySegment rays[kLanes];
    uint16_t lane[kLanes];
    bool occluded[kLanes];
    float tOccluder[kLanes];
    // Where a batch of light samples is taken (PathSampler::sampleLights): the points, their
    // normals, numbers and light choices; for the bounces' hits, which bounce each is, its facet's
    // normal and the sample taken there.
    Vec3f at[kLanes], atNormal[kLanes], atFacet[kLanes];
    Vec2f atU[kLanes];
    float atChoice[kLanes];
    uint16_t atBounce[kLanes];
    LightSample atSample[kLanes];
    // Each lane's bounce direction and its dot product with the facet's normal (bounceDirections).
    Vec3f bounceDir[kLanes];
    float intoFacet[kLanes];
    int nRays = 0;
    /// Queues the shadow ray of lane (or light sample) l from `org` to just short of `lightPoint`.
    void pushShadow(int l, const Vec3f& org, const Vec3f& lightPoint, float t) {
        const Vec3f toPoint = lightPoint - org;
        const float dist = length(toPoint);
        rays[nRays] = {org, toPoint / dist, dist * (1.f - 1e-4f), t};
        lane[nRays++] = uint16_t(l);
    }
};

void PathSampler::traceBatch(int x, int y, uint32_t first, uint32_t count, bool slopes, TracedSample* outs) const {
    const SampleRun run{x, y, first, count, outs};
    traceMany(&run, 1, slopes);
}

void PathSampler::traceRuns(std::vector<SampleRun>& runs, std::vector<TracedSample>& buffer, bool slopes) const {
    size_t total = 0;
    for (const SampleRun& run : runs) total += run.count;
    if (buffer.size() < total) buffer.resize(total);
    size_t offset = 0;
    for (SampleRun& run : runs) {
        run.out = buffer.data() + offset;
        offset += run.count;
    }
    traceMany(runs.data(), runs.size(), slopes);
}

void PathSampler::traceMany(const SampleRun* runs, size_t nRuns, bool slopes) const {
    constexpr int K = scene::RayPacket::kSize;
    thread_local std::unique_ptr<Wave> scratch;
    if (!scratch) scratch = std::make_unique<Wave>();
    Wave& w = *scratch;
    size_t r = 0;
    uint32_t done = 0;  // samples of runs[r] already traced
    uint64_t bad = 0, lit = 0;
    while (r < nRuns) {
        // Camera rays and primary hits, one pixel's batch of up to 16 at a time, and each hit's
        // light sample, until the wave is full.
        int lanes = 0;
        w.nRays = 0;
        while (r < nRuns && lanes + K <= Wave::kLanes) {
            const SampleRun& run = runs[r];
            if (done >= run.count) {
                ++r;
                done = 0;
                continue;
            }
            const int n = int(std::min<uint32_t>(K, run.count - done));
            const uint32_t first = run.first + done;
            TracedSample* out = run.out + done;
            done += uint32_t(n);
            const int l0 = lanes;
            lanes += n;

            // The batch's random numbers, pair by pair (vectorised across samples). Dimensions
            // that do not matter are not drawn (the others do not depend on it).
            const PixelSampler rng(m_seed, uint32_t(run.y) * uint32_t(m_camera.width()) + uint32_t(run.x), m_independent);
            if (m_indirect) {
                rng.get2DBatch(first, uint32_t(n), kBounce, w.uBounce + l0);
                rng.get2DBatch(first, uint32_t(n), kBounceLight, w.uBounceLight + l0);
            }

            // Primary rays through the lens.
            scene::RayPacket primary;
            Vec2f lens[K], film[K];
            cameraRays(rng, run.x, run.y, first, n, primary, lens, w.choice + l0, w.time + l0, w.uLight + l0, film);
            for (int k = 0; k < n; ++k) {
                w.out[l0 + k] = out + k;
                std::construct_at(out + k);  // in place: a temporary assigned stalled on store forwarding (7% of traceMany)
                out[k].record.lens = lens[k];
                out[k].film = film[k];
                out[k].time = w.time[l0 + k];
                out[k].rays = 1;
            }
            if (m_log) m_log->add(scene::RayLog::kPrimary, primary);
            m_scene.intersect(primary, w.hit + l0, w.found + l0);

            // Direct light at the primary hits: one light sample each, its shadow ray queued.
            for (int k = 0; k < n; ++k) {
                const int l = l0 + k;
                if (!w.found[l]) continue;
                const scene::Hit& hit = w.hit[l];
                const scene::Material& mat = m_scene.material(hit.material);
                const bool front = dot(hit.normal, primary.dir[k]) < 0;
                w.geometric[l] = front ? hit.normal : -hit.normal;  // two-sided shading
                TracedSample& o = out[k];
                setPrimaryHit(o, hit, w.geometric[l], w.time[l]);
                w.normal[l] = o.normal;
                if (hit.motion || m_camera.moving()) {
                    // The hit point's path over the shutter (shutterPath).
                    const scene::RigidMotion* m = hit.motion;
                    const ShutterPath path = shutterPath(hit, w.time[l]);
                    const float t = w.time[l];
                    const Vec3f &atOpen = path.atOpen, &atClose = path.atClose;
                    const Vec2f open = path.open, close = path.close;
                    o.motion = {close.x - open.x, close.y - open.y};
                    // Where it is at mid-shutter, off the chord's line: the sagitta of an arc,
                    // r (1 - cos(a / 2)) for a turn of a in the image plane. (Along the line a
                    // sample the stage misplaces stays in its own streak, whose blur hides it:
                    // counted too, the uneven pace of a point turning in depth, the filters lost
                    // the layers on docs/bunny-turn.json, +20% relMSE; the pace of an object
                    // moving in depth is the stage's alongChord.)
                    const Vec3f atMid = m ? m->at(atOpen, 0.5f) : hit.position;
                    const Vec2f mid = m_camera.project(atMid, 0.5f);
                    const float ox = mid.x - 0.5f * (open.x + close.x), oy = mid.y - 0.5f * (open.y + close.y);
                    const float chord = std::sqrt(o.motion.x * o.motion.x + o.motion.y * o.motion.y);
                    o.bend = chord > 1e-3f ? std::abs(ox * o.motion.y - oy * o.motion.x) / chord : std::sqrt(ox * ox + oy * oy);
                    // The sagitta for the layers' curved trajectories (TracedSample::sag), where
                    // the object turns by at most half a turn, and in depth by at most
                    // kCurvedTurnInDepth.
                    if (m && m->turns() && std::abs(m->radians) <= kPi) {
                        const Vec3f view = normalize(atMid - m_camera.poseAt(0.5f).position);
                        if (std::abs(m->radians) * length(cross(m->axis, view)) <= kCurvedTurnInDepth) o.sag = {ox, oy};
                    }
                    if (o.bend > LightFieldSamples::kBentPath) {
                        // The normal at the open and at the close (Embree's is the hit's time's),
                        // against the direction to the camera then.
                        const Vec3f n0 = m ? m->turn(w.geometric[l], -t) : w.geometric[l];
                        const Vec3f n1 = m ? m->turn(n0, 1.f) : n0;
                        const Vec3f v0 = normalize(m_camera.poseAt(0.f).position - atOpen);
                        const Vec3f v1 = normalize(m_camera.poseAt(1.f).position - atClose);
                        o.faceTurn = std::abs(dot(n1, v1) - dot(n0, v0));
                    }
                }
                if (front) o.emission = mat.emission;  // emitters shine from their front side
                w.at[l] = hit.position;
            }
            // The batch's light samples together (lanes without a hit take a dummy and are skipped).
            for (int k = 0; k < n; ++k)
                if (!w.found[l0 + k])
                    w.at[l0 + k] = Vec3f(0.f), w.normal[l0 + k] = w.geometric[l0 + k] = Vec3f(0.f, 0.f, 1.f);
            sampleLights(n, w.at + l0, w.normal + l0, w.uLight + l0, w.choice + l0, w.ls + l0);
            for (int k = 0; k < n; ++k) {
                const int l = l0 + k;
                if (!w.found[l]) continue;
                const scene::Hit& hit = w.hit[l];
                TracedSample& o = out[k];
                const LightSample& ls = w.ls[l];
                o.record.light = m_group[ls.light];
                o.record.lightPoint = ls.point;
                if (maxComponent(ls.irradiance) <= 0) continue;
                ++lit;
                o.record.unoccluded = luminance(ls.irradiance) * kInvPi;
                o.shadowTested = true;
                o.d1 = length(m_groupCenter[o.record.light] - hit.position);
                if (dot(ls.toLight, w.geometric[l]) <= 0) {
                    // Above the shading normal's horizon, below the facet's: the surface shadows
                    // itself (no occluder to take a slope from).
                    o.occluded = o.selfShadowed = true;
                    continue;
                }
                w.pushShadow(l, offset(hit.position, w.geometric[l]), ls.point, w.time[l]);
                ++o.rays;
            }
        }
        if (lanes == 0) break;

        // The wave's shadow rays as one stream.
        if (m_log) m_log->add(scene::RayLog::kShadow, w.rays, size_t(w.nRays));
        if (slopes) {
            m_scene.nearestOccluders(w.rays, size_t(w.nRays), w.tOccluder);
            for (int j = 0; j < w.nRays; ++j) {
                TracedSample& o = *w.out[w.lane[j]];
                o.tOccluder = w.tOccluder[j];
                o.occluded = o.tOccluder < kInf;
            }
        } else {
            m_scene.occluded(w.rays, size_t(w.nRays), w.occluded);
            for (int j = 0; j < w.nRays; ++j) w.out[w.lane[j]]->occluded = w.occluded[j];
        }
        for (int j = 0; j < w.nRays; ++j) {
            TracedSample& o = *w.out[w.lane[j]];
            if (!o.occluded) o.record.direct = w.ls[w.lane[j]].irradiance * kInvPi;
        }
        if (m_indirect) {
            // One cosine-weighted bounce per sample, the wave's as one stream (incoherent rays:
            // as fast as one by one in Embree, bench/embree_ceiling.cpp, and their hits' data is
            // then fetched together), each hit lit by its own light sample.
            int nBounce = 0;
            bounceDirections(lanes, w.normal, w.geometric, w.uBounce, w.bounceDir, w.intoFacet);
            for (int l = 0; l < lanes; ++l) {
                if (!w.found[l] || maxComponent(w.hit[l].albedo) <= 0) continue;
                const Vec3f dir = w.bounceDir[l];
                if (w.intoFacet[l] <= 0) continue;  // into the facet: no light comes that way
                w.out[l]->record.bounceDir = dir;
                ++w.out[l]->rays;
                w.bounce[nBounce] = {offset(w.hit[l].position, w.geometric[l]), dir, kInf, w.time[l]};
                w.bounceLane[nBounce++] = uint16_t(l);
            }
            if (m_log) m_log->add(scene::RayLog::kBounce, w.bounce, size_t(nBounce));
            m_scene.intersect(w.bounce, size_t(nBounce), w.h2, w.found2);
            w.nRays = 0;
            int nLit = 0;  // the bounces whose hit takes a light sample
            for (int j = 0; j < nBounce; ++j) {
                if (!w.found2[j]) continue;
                const int l = w.bounceLane[j];
                const scene::Hit& h2 = w.h2[j];
                TracedSample& o = *w.out[l];
                o.bounceHit = true;
                o.bounceDistance = h2.t;
                if (maxComponent(h2.albedo) <= 0) continue;
                const Vec3f g2 = w.atFacet[nLit] = dot(h2.normal, w.bounce[j].dir) < 0 ? h2.normal : -h2.normal;
                w.at[nLit] = h2.position;
                w.atNormal[nLit] = facing(h2.shadingNormal, g2);
                w.atU[nLit] = w.uBounceLight[l];
                w.atChoice[nLit] = w.choice[l];
                w.atBounce[nLit++] = uint16_t(j);
            }
            sampleLights(nLit, w.at, w.atNormal, w.atU, w.atChoice, w.atSample);
            for (int i = 0; i < nLit; ++i) {
                const int l = w.bounceLane[w.atBounce[i]];
                const LightSample& l2 = w.atSample[i];
                if (maxComponent(l2.irradiance) <= 0 || dot(l2.toLight, w.atFacet[i]) <= 0) continue;
                ++lit;
                w.pushShadow(i, offset(w.at[i], w.atFacet[i]), l2.point, w.time[l]);
                ++w.out[l]->rays;
            }
            if (m_log) m_log->add(scene::RayLog::kBounceShadow, w.rays, size_t(w.nRays));
            m_scene.occluded(w.rays, size_t(w.nRays), w.occluded);
            for (int r = 0; r < w.nRays; ++r) {
                if (w.occluded[r]) continue;
                const int i = w.lane[r];  // the light sample
                const int j = w.atBounce[i];  // the bounce
                // Cosine-weighted bounce: (albedo/pi) L cos / (cos/pi) = albedo L, so the
                // demodulated indirect is the incident radiance L = albedo2 E2 / pi.
                w.out[w.bounceLane[j]]->record.indirect = w.h2[j].albedo * w.atSample[i].irradiance * kInvPi;
            }
        }
        for (int l = 0; l < lanes; ++l) {
            const TracedSample& o = *w.out[l];
            bad += !(isFinite(o.emission) && isFinite(o.record.direct) && isFinite(o.record.indirect) &&
                     std::isfinite(o.record.unoccluded));
        }
    }
    if (bad > 0) m_nonFinite.fetch_add(bad, std::memory_order_relaxed);
    if (lit > 0) m_lit.fetch_add(lit, std::memory_order_relaxed);
}

Vec3f PathSampler::meanEmission(int x, int y, uint32_t count, const LightFieldSamples* lf, Vec3f* wide) const {
    constexpr int K = scene::RayPacket::kSize;
    const PixelSampler rng(m_seed, uint32_t(y) * uint32_t(m_camera.width()) + uint32_t(x), m_independent);
    Vec3f sum(0.f), wideSum(0.f);
    for (uint32_t first = 0; first < count; first += K) {
        const int n = int(std::min<uint32_t>(K, count - first));
        scene::RayPacket primary;
        Vec2f lens[K];
        float choice[K], time[K];
        cameraRays(rng, x, y, first, n, primary, lens, choice, time, nullptr);
        scene::Hit hit[K];
        bool found[K] = {};
        m_scene.intersect(primary, hit, found);
        for (int k = 0; k < n; ++k)
            if (found[k] && dot(hit[k].normal, primary.dir[k]) < 0) {  // emitters shine from their front
                const Vec3f& e = m_scene.material(hit[k].material).emission;
                sum += e;
                if (wide && maxComponent(e) > 0.f) {
                    // Its depth and screen motion as traceMany takes a path sample's.
                    Vec2f motion{0.f, 0.f};
                    if (hit[k].motion || m_camera.moving()) {
                        const ShutterPath path = shutterPath(hit[k], time[k]);
                        motion = {path.close.x - path.open.x, path.close.y - path.open.y};
                    }
                    if (lf->wideBlur(m_camera.depth(hit[k].position, time[k]), motion, hit[k].object)) wideSum += e;
                }
            }
    }
    if (wide) *wide = count > 0 ? wideSum / float(count) : wideSum;
    return count > 0 ? sum / float(count) : sum;
}

uint64_t PathSampler::primaryHits(int x, int y, uint32_t first, uint32_t count, TracedSample* out) const {
    constexpr int K = scene::RayPacket::kSize;
    const PixelSampler rng(m_seed, uint32_t(y) * uint32_t(m_camera.width()) + uint32_t(x), m_independent);
    for (uint32_t done = 0; done < count; done += K) {
        const int n = int(std::min<uint32_t>(K, count - done));
        scene::RayPacket primary;
        Vec2f lens[K];
        float choice[K], time[K];
        cameraRays(rng, x, y, first + done, n, primary, lens, choice, time, nullptr);
        scene::Hit hit[K];
        bool found[K] = {};
        m_scene.intersect(primary, hit, found);
        for (int k = 0; k < n; ++k) {
            TracedSample& o = out[done + k];
            o = TracedSample();
            o.rays = 1;
            if (!found[k]) continue;
            // As traceMany takes them, so that a texture sample finds the slot of its surface.
            setPrimaryHit(o, hit[k], dot(hit[k].normal, primary.dir[k]) < 0 ? hit[k].normal : -hit[k].normal, time[k]);
        }
    }
    return count;
}

}  // namespace wedge::render
