// Scene module: geometry conventions of the built Embree scene, the occluder-span query, and the
// checks of OBJ and MTL text.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <memory>
#include <random>
#include <tuple>

#include "core/error.h"
#include "io/image_io.h"
#include "scene/checker.h"
#include "scene/light_irradiance.h"
#include "scene/obj_check.h"
#include "scene/scene.h"
#include "scene/scene_loader.h"
#include "test_util.h"

using namespace wedge;
using namespace wedge::scene;

namespace {

SceneDesc oneQuad() {
    SceneDesc d;
    d.materials.push_back({"white", Vec3f(0.5f), Vec3f(0.f), "", 1.f, nullptr});
    TriangleMesh m;
    appendQuad(m, {-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, 0);  // normal +z
    d.meshes.push_back(m);
    d.lights.push_back({{-0.5f, -0.5f, 5}, {1, 0, 0}, {0, -1, 0}, Vec3f(1.f)});
    return d;
}

}  // namespace

TEST(Scene, TriangleNormalIsCounterClockwise) {
    Scene s(oneQuad());
    Hit h;
    ASSERT_TRUE(s.intersect({0, 0, 3}, {0, 0, -1}, 0, kInf, 0, h));
    EXPECT_NEAR(h.t, 3.f, 1e-5f);
    EXPECT_NEAR(h.normal.z, 1.f, 1e-6f);
    ASSERT_TRUE(s.intersect({0, 0, -3}, {0, 0, 1}, 0, kInf, 0, h));
    EXPECT_NEAR(h.normal.z, 1.f, 1e-6f) << "the normal does not depend on the side the ray comes from";
}

TEST(Scene, LightNormalFollowsEdges) {
    AreaLight l{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, Vec3f(1.f)};
    EXPECT_NEAR(l.normal().z, 1.f, 1e-6f);
    EXPECT_NEAR(l.area(), 1.f, 1e-6f);
}

TEST(Scene, TriangleLightSamplesAreUniformOnTheTriangle) {
    // The unit square's cell centres fold onto the triangle: every point inside, their mean the
    // centroid, and each of the triangle's four midpoint sub-triangles takes a quarter of them.
    AreaLight l{{1, 2, 3}, {2, 0, 0.5f}, {0.5f, 0, 1.5f}, Vec3f(1.f), AreaLight::Shape::Triangle};
    EXPECT_NEAR(l.area(), 0.5f * length(cross(l.edge1, l.edge2)), 1e-6f);
    const int n = 64;
    Vec3f mean(0.f);
    int quarter[4] = {};
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            const Vec3f p = l.pointAt((i + 0.5f) / n, (j + 0.5f) / n);
            mean += p / float(n * n);
            // (a, b) with p = corner + a edge1 + b edge2: the edges' coordinates in their plane.
            const Vec3f d = p - l.corner, c = cross(l.edge1, l.edge2);
            const float a = dot(cross(d, l.edge2), c) / dot(c, c), b = dot(cross(l.edge1, d), c) / dot(c, c);
            ASSERT_GE(a, -1e-5f);
            ASSERT_GE(b, -1e-5f);
            ASSERT_LE(a + b, 1 + 1e-5f);
            ++quarter[a > 0.5f ? 1 : b > 0.5f ? 2 : a + b < 0.5f ? 0 : 3];
        }
    EXPECT_LT(length(mean - l.center()), 1e-3f);  // the diagonal cells sit on the hypotenuse: O(1/n)
    for (int q : quarter) EXPECT_NEAR(q, n * n / 4, n / 2) << "a sub-triangle's share";
    Vec3f v[4];
    EXPECT_EQ(l.vertices(v), 3);
    EXPECT_EQ(v[2], l.corner + l.edge2);
}

TEST(Scene, TwoTriangleLightsIrradianceIsTheirParallelograms) {
    // Lambert's formula is additive over the polygon: a parallelogram's two halves as triangle
    // lights give its irradiance, also where the receiver's horizon clips them.
    const AreaLight quad{{-0.5f, 2, -0.3f}, {1.2f, 0, 0.1f}, {0.2f, 0.1f, 0.9f}, Vec3f(3.f, 2.f, 1.f)};
    const Vec3f far = quad.corner + quad.edge1 + quad.edge2;
    const AreaLight t1{quad.corner, quad.edge1, quad.edge2, quad.radiance, AreaLight::Shape::Triangle};
    const AreaLight t2{far, -quad.edge1, -quad.edge2, quad.radiance, AreaLight::Shape::Triangle};
    const Vec3f receivers[][2] = {{{0, 0, 0}, {0, 1, 0}},                            // facing it
                                  {{0.3f, 0.5f, 0.2f}, normalize(Vec3f(1, 0.4f, 0))},  // clipped by the horizon
                                  {{0.2f, 1.5f, 0.3f}, {1, 0, 0}}};                   // under it, cut in two
    for (const auto& r : receivers) {
        const Vec3f whole = unoccludedIrradiance({quad}, r[0], r[1]), halves = unoccludedIrradiance({t1, t2}, r[0], r[1]);
        ASSERT_GT(whole.x, 0.f);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(halves[c], whole[c], 1e-5f * whole[c]);
    }
}

TEST(Scene, CoplanarLightsThatShareACornerAreOneGroup) {
    // A round lamp as a fan of 8 triangles (facing down), as an OBJ tessellates it, is one light
    // for the filters; lights that do not share a corner, face another way, lie in another plane
    // or have another radiance stay apart. Groups are numbered by their first light.
    const Vec3f centre(0.3f, 2.f, -0.2f), radiance(5.f);
    const float r = 0.4f;
    std::vector<AreaLight> lights;
    auto rim = [&](int i) {
        const float a = 2 * kPi * float(i) / 8;
        return Vec3f(r * std::cos(a), 0, r * std::sin(a));
    };
    for (int i = 0; i < 8; ++i) lights.push_back({centre, rim(i), rim(i + 1), radiance, AreaLight::Shape::Triangle});
    const Vec3f edge = centre + rim(0);  // a corner on the lamp's rim
    lights.push_back({edge, {0.3f, 0, 0}, {0, 0, 0.3f}, Vec3f(4.f)});                              // another radiance
    lights.push_back({edge, {0, 0, 0.3f}, {0.3f, 0, 0}, radiance});                              // facing up
    lights.push_back({edge, {0.3f, 0.05f, 0}, {0, 0, 0.3f}, radiance});                          // tilted
    lights.push_back({centre + Vec3f(2, 0, 0), {0.3f, 0, 0}, {0, 0, 0.3f}, radiance});           // apart
    lights.push_back({edge, {0.3f, 0, 0}, {0, 0, 0.3f}, radiance});                              // joins the lamp
    lights.push_back({centre + Vec3f(2.3f, 0, 0.3f), {0.2f, 0, 0}, {0, 0, 0.2f}, radiance});     // joins "apart"
    const std::vector<uint32_t> group = lightGroups(lights);
    const std::vector<uint32_t> expected = {0, 0, 0, 0, 0, 0, 0, 0, 1, 2, 3, 4, 0, 4};
    EXPECT_EQ(group, expected);
    // An emissive box's faces share corners but no plane: six lights.
    std::vector<AreaLight> box;
    for (const auto& f : boxFaces({0, 0, 0}, {1, 1, 1})) box.push_back({f[0], f[1], f[2], radiance});
    const std::vector<uint32_t> six = {0, 1, 2, 3, 4, 5};
    EXPECT_EQ(lightGroups(box), six);
}

TEST(Scene, GroupedIrradianceIsTheSumOverItsLights) {
    // LightIrradiance sums a group the receiver sees whole over its outline (the shared edges
    // cancel) and clips a group the horizon cuts light by light: either way the irradiance of
    // every light, to float precision. A round lamp of 12 triangles, a 3 x 3 grid of quads, and
    // a lone light, at receivers in front of them, cut by their horizon, and behind them.
    std::vector<AreaLight> lights;
    const Vec3f centre(0.2f, 2.f, 0.1f);
    for (int i = 0; i < 12; ++i) {
        auto rim = [&](int k) { return Vec3f(0.5f * std::cos(kPi * k / 6), 0, 0.5f * std::sin(kPi * k / 6)); };
        lights.push_back({centre, rim(i), rim(i + 1), Vec3f(3.f, 2.f, 1.f), AreaLight::Shape::Triangle});
    }
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            lights.push_back({Vec3f(-1.5f + 0.3f * i, 1.2f + 0.3f * j, -0.8f), {0.3f, 0, 0}, {0, 0.3f, 0}, Vec3f(1.f, 4.f, 2.f)});
    lights.push_back({{1.f, 1.f, 1.f}, {0, 0, -0.4f}, {0, 0.3f, 0}, Vec3f(2.f)});
    const LightIrradiance grouped(lights);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> U(-1.f, 1.f);
    int cut = 0;
    for (int i = 0; i < 400; ++i) {
        const Vec3f x(1.5f * U(rng), 1.f + U(rng), 1.5f * U(rng)), n = normalize(Vec3f(U(rng), U(rng), U(rng)));
        const Vec3f expected = unoccludedIrradiance(lights, x, n), got = grouped(x, n);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], expected[c], 1e-5f * (1.f + expected[c])) << i;
        // Count the receivers whose horizon cuts the lamp (some of its corners below it).
        int below = 0;
        for (int k = 0; k < 12; ++k) below += dot(lights[k].corner + lights[k].edge1 - x, n) < 0;
        cut += below > 0 && below < 12 && dot(x - centre, Vec3f(0, -1, 0)) > 0;
    }
    EXPECT_GT(cut, 20);  // both paths ran
}

TEST(Scene, SphereLightIrradianceMatchesTheConeItFills) {
    // A sphere light's irradiance is L times the integral of max(0, n . w) over the cone of
    // directions it fills; by a fine midpoint rule over the cone (in double), against the closed
    // form where the cone is above the horizon and the clipped polygon where the horizon cuts it,
    // and zero behind the horizon and inside the sphere.
    AreaLight sphere;
    sphere.shape = AreaLight::Shape::Sphere;
    sphere.corner = {0.3f, 1.5f, -0.2f};
    sphere.radius = 0.4f;
    sphere.radiance = Vec3f(2.f);
    auto numeric = [&](const Vec3f& x, const Vec3f& n) {
        const Vec3f w = sphere.corner - x;
        const double d = length(w), sinA = sphere.radius / d, cosA = std::sqrt(1 - sinA * sinA);
        const Vec3f axis = w / float(d);
        const Vec3f a = normalize(cross(axis, std::abs(axis.x) < 0.9f ? Vec3f(1, 0, 0) : Vec3f(0, 1, 0))), b = cross(axis, a);
        const int nt = 400, np = 400;
        double sum = 0;
        for (int i = 0; i < nt; ++i) {
            const double c = 1 - (i + 0.5) / nt * (1 - cosA), sn = std::sqrt(1 - c * c);  // uniform in solid angle
            for (int j = 0; j < np; ++j) {
                const double phi = 2 * M_PI * (j + 0.5) / np;
                const double cn = c * dot(n, axis) + sn * (std::cos(phi) * dot(n, a) + std::sin(phi) * dot(n, b));
                sum += std::max(0.0, cn);
            }
        }
        return 2.0 * sphere.radiance.x * M_PI * (1 - cosA) * sum / (double(nt) * np);
    };
    const Vec3f x0(0.f, 0.f, 0.f);
    const Vec3f toCentre = normalize(sphere.corner - x0);
    const Vec3f side = normalize(cross(toCentre, Vec3f(1, 0, 0)));
    // Normals from facing the sphere to past the horizon: whole, cut, and gone.
    for (float tilt : {0.f, 0.5f, 1.2f, 1.35f, 1.5f, 1.57f, 1.65f, 1.75f, 2.2f}) {
        const Vec3f n = normalize(toCentre * std::cos(tilt) + side * std::sin(tilt));
        const double expected = numeric(x0, n);
        const float got = unoccludedIrradiance({sphere}, x0, n).x;
        EXPECT_NEAR(got, expected, 0.002 * sphere.radiance.x * std::sin(0.4 / length(sphere.corner)) + 0.003 * expected)
            << "tilt " << tilt;
        EXPECT_EQ(LightIrradiance({sphere})(x0, n).x, got);
    }
    EXPECT_EQ(unoccludedIrradiance({sphere}, sphere.corner + Vec3f(0.1f, 0, 0), {0, 1, 0}).x, 0.f) << "inside";
}

TEST(Scene, NearestOccluderIsTheFirstAlongTheSegment) {
    // Three occluders stacked over the origin, one more only over x in [5, 7]: the shadow
    // slopes take the one nearest the receiver, measured from the segment's origin whatever
    // its tNear, and none beyond its end.
    SceneDesc d = oneQuad();
    TriangleMesh m;
    for (float z : {1.f, 1.7f, 2.5f}) appendQuad(m, {-1, -1, z}, {2, 0, 0}, {0, 2, 0}, 0);
    appendQuad(m, {5, -1, 1.2f}, {2, 0, 0}, {0, 2, 0}, 0);
    d.meshes.push_back(m);
    Scene s(std::move(d));
    EXPECT_NEAR(s.nearestOccluder({0, 0, 0.01f}, {0, 0, 1}, 0, 10, 0), 0.99f, 1e-4f);
    EXPECT_NEAR(s.nearestOccluder({0, 0, 0}, {0, 0, 1}, 0.5f, 3.f, 0), 1.f, 1e-4f);
    EXPECT_NEAR(s.nearestOccluder({0, 0, 0}, {0, 0, 1}, 1.2f, 3.f, 0), 1.7f, 1e-4f);  // past the first
    EXPECT_NEAR(s.nearestOccluder({6, 0, 0}, {0, 0, 1}, 0.f, 3.f, 0), 1.2f, 1e-4f);
    EXPECT_TRUE(s.occluded({0, 0, 0.01f}, {0, 0, 1}, 0, 10, 0));
    EXPECT_FALSE(s.occluded({0, 0, 0.01f}, {0, 0, 1}, 0, 0.5f, 0));
    EXPECT_EQ(s.nearestOccluder({0, 0, 0.01f}, {0, 0, 1}, 0, 0.5f, 0), kInf);
    EXPECT_EQ(s.nearestOccluder({3, 0, 0.01f}, {0, 0, 1}, 0, 10, 0), kInf);  // beside them all
}

TEST(Scene, StreamQueriesAreTheSingleRayQueries) {
    // The sampler traces several pixels' rays as one Embree stream; whatever a stream's length
    // and whichever rays share it, every ray must get what it gets alone (bit for bit: the same
    // seed gives the same image on any number of threads or ranks).
    SceneDesc d = oneQuad();
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1.f, 1.f);
    TriangleMesh m;  // 400 small quads at random heights and tilts over the floor
    for (int i = 0; i < 400; ++i)
        appendQuad(m, {2 * u(rng), 2 * u(rng), 1.5f + u(rng)}, {0.3f, 0.1f * u(rng), 0.1f * u(rng)},
                   {0.1f * u(rng), 0.3f, 0.1f * u(rng)}, 0);
    d.meshes.push_back(m);
    Scene s(std::move(d));
    std::vector<RaySegment> rays;
    for (int i = 0; i < 700; ++i) {
        const Vec3f org{2 * u(rng), 2 * u(rng), 0.01f}, dir = normalize(Vec3f{u(rng), u(rng), 0.5f + 0.5f * std::abs(u(rng))});
        rays.push_back({org, dir, i % 3 == 0 ? 10.f : 3.f * std::abs(u(rng)), 0.f});
    }
    const size_t n = rays.size();
    std::vector<Hit> hits(n);
    std::vector<char> found(n), occ(n);
    std::vector<float> nearest(n);
    int hitCount = 0;
    for (size_t i = 0; i < n; ++i) {
        found[i] = s.intersect(rays[i].org, rays[i].dir, 0.f, rays[i].tFar, 0.f, hits[i]);
        occ[i] = s.occluded(rays[i].org, rays[i].dir, 0.f, rays[i].tFar, 0.f);
        nearest[i] = s.nearestOccluder(rays[i].org, rays[i].dir, 0.f, rays[i].tFar, 0.f);
        hitCount += found[i];
        // The same closest hit as intersect's, without its hit record.
        EXPECT_EQ(nearest[i], found[i] ? hits[i].t : kInf) << i;
        EXPECT_EQ(nearest[i] < kInf, bool(occ[i])) << i;
    }
    ASSERT_GT(hitCount, 100);
    ASSERT_LT(hitCount, 650);
    for (size_t chunk : {size_t(1), size_t(13), size_t(256), n}) {
        std::vector<Hit> h(n);
        bool f[700], o[700];
        std::vector<float> t(n);
        for (size_t b = 0; b < n; b += chunk) {
            const size_t c = std::min(chunk, n - b);
            s.intersect(rays.data() + b, c, h.data() + b, f + b);
            s.occluded(rays.data() + b, c, o + b);
            s.nearestOccluders(rays.data() + b, c, t.data() + b);
        }
        for (size_t i = 0; i < n; ++i) {
            ASSERT_EQ(f[i], bool(found[i])) << "chunk " << chunk << " ray " << i;
            EXPECT_EQ(o[i], bool(occ[i])) << "chunk " << chunk << " ray " << i;
            EXPECT_EQ(t[i], nearest[i]) << "chunk " << chunk << " ray " << i;
            if (!f[i]) continue;
            EXPECT_EQ(0, std::memcmp(&h[i].position, &hits[i].position, sizeof(Vec3f))) << "chunk " << chunk << " ray " << i;
            EXPECT_EQ(0, std::memcmp(&h[i].normal, &hits[i].normal, sizeof(Vec3f)));
            EXPECT_EQ(h[i].t, hits[i].t);
            EXPECT_EQ(h[i].object, hits[i].object);
        }
    }
}

TEST(Scene, SphereNormalPointsOutward) {
    SceneDesc d = oneQuad();
    d.spheres.push_back({{0, 0, 10}, 1.f, 0, Vec3f(0.f)});
    Scene s(std::move(d));
    Hit h;
    ASSERT_TRUE(s.intersect({0, 0, 20}, {0, 0, -1}, 0, kInf, 0, h));
    EXPECT_NEAR(h.t, 9.f, 1e-4f);
    EXPECT_NEAR(h.normal.z, 1.f, 1e-4f);
}

TEST(Scene, MotionBlurMovesGeometryOverTheShutter) {
    SceneDesc d;
    d.materials.push_back({"white", Vec3f(0.5f), Vec3f(0.f), "", 1.f, nullptr});
    d.lights.push_back({{-0.5f, -0.5f, 5}, {1, 0, 0}, {0, -1, 0}, Vec3f(1.f)});
    TriangleMesh m;
    appendQuad(m, {-0.5f, -0.5f, 0}, {1, 0, 0}, {0, 1, 0}, 0);
    m.velocity = {2, 0, 0};
    d.meshes.push_back(m);
    Scene s(std::move(d));
    Hit h;
    EXPECT_TRUE(s.intersect({0, 0, 1}, {0, 0, -1}, 0, kInf, 0.f, h));
    EXPECT_FALSE(s.intersect({0, 0, 1}, {0, 0, -1}, 0, kInf, 0.5f, h));   // quad now spans x in [0.5, 1.5]
    EXPECT_TRUE(s.intersect({1, 0, 1}, {0, 0, -1}, 0, kInf, 0.5f, h));
}

TEST(Scene, AMovingMeshBesideAStillOneIsFoundByEveryQuery) {
    // A moving mesh is an instance of its own scene (Scene::Scene): its hits must carry its own
    // material, object and motion through the single ray, the 16-wide packet and the stream,
    // beside a still mesh with other ones, and find it where it is at the ray's time.
    SceneDesc d;
    d.materials.push_back({"a", Vec3f(0.25f), Vec3f(0.f), "", 1.f, nullptr});
    d.materials.push_back({"b", Vec3f(0.75f), Vec3f(0.f), "", 1.f, nullptr});
    d.lights.push_back({{-0.5f, -0.5f, 5}, {1, 0, 0}, {0, -1, 0}, Vec3f(1.f)});
    TriangleMesh still, moving;
    appendQuad(still, {-3.f, -0.5f, -1.f}, {2, 0, 0}, {0, 1, 0}, 0);  // x in [-3, -1], z = -1
    appendQuad(moving, {-0.5f, -0.5f, 0.f}, {1, 0, 0}, {0, 1, 0}, 1);  // x in [-0.5, 0.5] at shutter open, z = 0
    moving.velocity = {2, 0, 0};
    d.meshes.push_back(still);
    d.meshes.push_back(moving);
    Scene s(std::move(d));
    // (x, time, expected material or -1 for a miss)
    const struct { float x, time; int material; } cases[] = {
        {0.f, 0.f, 1}, {0.f, 0.5f, -1}, {1.f, 0.5f, 1}, {2.2f, 1.f, 1}, {-2.f, 0.f, 0}, {-2.f, 1.f, 0}, {-0.8f, 0.f, -1}};
    RayPacket packet;
    std::vector<RaySegment> stream;
    for (int i = 0; i < int(std::size(cases)); ++i) {
        packet.set(i, {cases[i].x, 0, 5}, {0, 0, -1}, kInf, cases[i].time);
        stream.push_back({{cases[i].x, 0, 5}, {0, 0, -1}, kInf, cases[i].time});
    }
    Hit packetHits[RayPacket::kSize];
    bool packetFound[RayPacket::kSize];
    s.intersect(packet, packetHits, packetFound);
    std::vector<Hit> streamHits(stream.size());
    std::unique_ptr<bool[]> streamFound(new bool[stream.size()]);
    s.intersect(stream.data(), stream.size(), streamHits.data(), streamFound.get());
    for (int i = 0; i < int(std::size(cases)); ++i) {
        SCOPED_TRACE(i);
        Hit one;
        const bool found = s.intersect({cases[i].x, 0, 5}, {0, 0, -1}, 0, kInf, cases[i].time, one);
        ASSERT_EQ(found, cases[i].material >= 0);
        ASSERT_EQ(packetFound[i], found);
        ASSERT_EQ(streamFound[i], found);
        if (!found) continue;
        for (const Hit* h : {&one, &packetHits[i], &streamHits[i]}) {
            EXPECT_EQ(int(h->material), cases[i].material);
            EXPECT_EQ(h->albedo, Vec3f(cases[i].material == 1 ? 0.75f : 0.25f));
            EXPECT_NEAR(h->t, cases[i].material == 1 ? 5.f : 6.f, 1e-5f);
            EXPECT_NEAR(h->normal.z, 1.f, 1e-6f);
            EXPECT_EQ(h->motion ? h->motion->displacement : Vec3f(0.f), cases[i].material == 1 ? Vec3f(2, 0, 0) : Vec3f(0.f));
        }
        EXPECT_EQ(one.object, cases[i].material == 1 ? 1u : 0u) << "each mesh its own object";
        ASSERT_LT(one.object, s.objectMoves().size());
        EXPECT_EQ(s.objectMoves()[one.object], cases[i].material == 1) << "which objects move (MAAF's central-only rule)";
    }
    EXPECT_EQ(s.objectMoves().size(), 2u);
}

TEST(Scene, ObjectMovesNamesTheMovingSpheresByTheirHitsObject) {
    // Spheres follow the meshes in the object ids (Hit::object); objectMoves() says which move.
    SceneDesc d;
    d.materials.push_back({"a", Vec3f(0.5f), Vec3f(0.f), "", 1.f, nullptr});
    d.lights.push_back({{-0.5f, -0.5f, 5}, {1, 0, 0}, {0, -1, 0}, Vec3f(1.f)});
    TriangleMesh floor;
    appendQuad(floor, {-3.f, -3.f, -2.f}, {6, 0, 0}, {0, 6, 0}, 0);
    d.meshes.push_back(floor);
    d.spheres.push_back({{-1.f, 0.f, 0.f}, 0.5f, 0, Vec3f(0.f)});
    d.spheres.push_back({{1.f, 0.f, 0.f}, 0.5f, 0, Vec3f(0.f, 1.f, 0.f)});
    Scene s(std::move(d));
    ASSERT_EQ(s.objectMoves(), (std::vector<uint8_t>{0, 0, 1}));
    for (const auto& [x, object] : {std::pair{-1.f, 1u}, std::pair{1.f, 2u}, std::pair{0.f, 0u}}) {
        Hit h;
        ASSERT_TRUE(s.intersect({x, 0, 5}, {0, 0, -1}, 0, kInf, 0.f, h));
        EXPECT_EQ(h.object, object);
    }
}

TEST(Scene, ATurningMeshIsWhereItsRotationPutsIt) {
    // A 2 x 2 quad in the plane z = 0 (front +z) turning about the y axis through its centre
    // (`angular_velocity`, the pivot at its box's centre) by 90 degrees, and another by 360,
    // over the shutter. At time t the quad's plane has the normal n = (sin a, 0, cos a), a = the
    // angle turned, so a ray from (0.5, 0, 5) down -z meets it at z = -0.5 tan a (within the
    // quad while a < 60 degrees, or near a half turn): its distance, its normal (turned with
    // the quad: Embree gives an instance's Ng in the instanced scene's space) and the point of
    // the quad at shutter open it hit (RigidMotion::atOpen: on z = 0 at x = 0.5 / cos a). The
    // full turn's half (180 degrees) is past a slerp's shorter way between two time steps, which
    // would have left the quad unturned: the steps are at most a quarter turn apart.
    for (float degrees : {90.f, 360.f}) {
        SceneDesc d;
        d.materials.push_back({"white", Vec3f(0.5f), Vec3f(0.f), "", 1.f, nullptr});
        d.lights.push_back({{-0.5f, 5, -0.5f}, {1, 0, 0}, {0, 0, 1}, Vec3f(1.f)});
        TriangleMesh m;
        appendQuad(m, {-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, 0);
        m.turnAxis = {0, 1, 0};
        m.turnDegrees = degrees;
        m.pivot = {0, 0, 0};
        d.meshes.push_back(m);
        ASSERT_TRUE(d.hasMotion());
        Scene s(std::move(d));
        for (float t : {0.f, 0.1f, 0.25f, 0.5f}) {
            const double a = double(degrees) * t * kPi / 180.0;
            if (std::abs(std::tan(a)) > 1.5) continue;  // the ray misses the quad's edge-on passage
            SCOPED_TRACE(std::to_string(degrees) + " degrees at t = " + std::to_string(t));
            Hit h;
            ASSERT_TRUE(s.intersect({0.5f, 0, 5}, {0, 0, -1}, 0, kInf, t, h));
            EXPECT_NEAR(h.t, 5.0 + 0.5 * std::tan(a), 1e-4);
            EXPECT_NEAR(h.normal.x, std::sin(a), 1e-4);
            EXPECT_NEAR(h.normal.z, std::cos(a), 1e-4);
            EXPECT_NEAR(h.shadingNormal.x, std::sin(a), 1e-4);
            ASSERT_NE(h.motion, nullptr);
            const Vec3f open = h.motion->atOpen(h.position, t);
            EXPECT_NEAR(open.z, 0.f, 1e-4f);
            EXPECT_NEAR(open.x, 0.5 / std::abs(std::cos(a)) * (std::cos(a) > 0 ? 1 : -1), 1e-4);
            const Vec3f back = h.motion->at(open, t);
            EXPECT_NEAR(length(back - h.position), 0.f, 1e-4f) << "at() undoes atOpen()";
        }
    }
}

TEST(Scene, TheCheckerMovesWithItsObject) {
    // A checkered quad moving 1.5 along x over the shutter [0, 2]: the point of the quad a ray
    // hits at time tau (normalised) sits 1.5 tau further right, and shows the same cell.
    SceneDesc d;
    d.materials.push_back({"c", Vec3f(0.5f), Vec3f(0.f), "checker", 1.f, nullptr});  // cells 1 wide
    d.lights.push_back({{-0.5f, -0.5f, 5}, {1, 0, 0}, {0, -1, 0}, Vec3f(1.f)});
    d.camera.shutterOpen = 0.f;
    d.camera.shutterClose = 2.f;
    TriangleMesh m;
    appendQuad(m, {-4, -4, 0}, {8, 0, 0}, {0, 8, 0}, 0);  // normal +z: textured in (x, y)
    m.velocity = {0.75f, 0, 0};                           // 1.5 over the shutter
    d.meshes.push_back(m);
    Scene s(std::move(d));
    auto albedoAt = [&](float x, float y, float tau) {
        Hit h;
        EXPECT_TRUE(s.intersect({x, y, 1}, {0, 0, -1}, 0, kInf, tau, h));
        return h.albedo;
    };
    const Vec3f light(0.5f), dark(0.5f * kCheckerDark);
    EXPECT_EQ(albedoAt(0.25f, 0.25f, 0.f), light);  // cell [0, 1) x [0, 1)
    EXPECT_EQ(albedoAt(1.25f, 0.25f, 0.f), dark);   // cell [1, 2) x [0, 1)
    EXPECT_EQ(albedoAt(0.25f + 0.75f, 0.25f, 0.5f), light) << "the same point of the quad, moved 0.75";
    EXPECT_EQ(albedoAt(1.25f + 1.5f, 0.25f, 1.f), dark);
    EXPECT_EQ(albedoAt(1.25f, 0.25f, 0.5f), light) << "a fixed point of space sees the quad slide under it";
}

TEST(Scene, TheCheckerTurnsWithItsObject) {
    // The same checkered quad turning 90 degrees about the view axis through the origin (and
    // moving 1 along y) over the shutter: the point a ray meets at time t is the quad's point
    // at shutter open turned by 90 t degrees and moved by t, and shows that point's cell.
    SceneDesc d;
    d.materials.push_back({"c", Vec3f(0.5f), Vec3f(0.f), "checker", 1.f, nullptr});
    d.lights.push_back({{-0.5f, -0.5f, 5}, {1, 0, 0}, {0, -1, 0}, Vec3f(1.f)});
    TriangleMesh m;
    appendQuad(m, {-4, -4, 0}, {8, 0, 0}, {0, 8, 0}, 0);
    m.velocity = {0, 1, 0};
    m.turnAxis = {0, 0, 1};
    m.turnDegrees = 90.f;
    m.pivot = {0, 0, 0};
    d.meshes.push_back(m);
    Scene s(std::move(d));
    auto albedoAt = [&](Vec2f p, float t) {
        Hit h;
        EXPECT_TRUE(s.intersect({p.x, p.y, 1}, {0, 0, -1}, 0, kInf, t, h));
        return h.albedo;
    };
    int dark = 0, checked = 0;
    for (float t : {0.25f, 0.5f, 0.8f})
        for (int i = 0; i < 13; ++i)
            for (int j = 0; j < 13; ++j) {
                const float x = -1.85f + 0.3f * float(i), y = -1.85f + 0.3f * float(j);  // 0.05 or more from a cell's edge
                const float a = 0.5f * kPi * t;  // where the quad's point (x, y) is at time t
                const Vec2f moved{x * std::cos(a) - y * std::sin(a), x * std::sin(a) + y * std::cos(a) + t};
                const Vec3f open = albedoAt({x, y}, 0.f);
                EXPECT_EQ(albedoAt(moved, t), open) << "(" << x << ", " << y << ") at t = " << t;
                dark += open.x < 0.4f;
                ++checked;
            }
    EXPECT_GT(dark, checked / 4) << "both cells are among the points";
    EXPECT_LT(dark, 3 * checked / 4);
}

TEST(Scene, CornerNormalsAreInterpolatedWithEmbreeBarycentrics) {
    SceneDesc d;
    d.materials.push_back({"white", Vec3f(0.5f), Vec3f(0.f), "", 1.f, nullptr});
    TriangleMesh m;
    m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};  // geometric normal +z
    m.indices = {0, 1, 2};
    m.materialIds = {0};
    m.shapeIds = {0};
    m.cornerNormals = {normalize(Vec3f(-1, 0, 1)), normalize(Vec3f(1, 0, 1)), normalize(Vec3f(0, 1, 1))};
    const std::vector<Vec3f> corners = m.cornerNormals;
    d.meshes.push_back(m);
    Scene s(std::move(d));
    Hit h;
    // Point 0.2 p0 + 0.5 p1 + 0.3 p2.
    ASSERT_TRUE(s.intersect({0.5f, 0.3f, 2}, {0, 0, -1}, 0, kInf, 0, h));
    Vec3f expected = normalize(corners[0] * 0.2f + corners[1] * 0.5f + corners[2] * 0.3f);
    EXPECT_NEAR(h.shadingNormal.x, expected.x, 1e-5f);
    EXPECT_NEAR(h.shadingNormal.y, expected.y, 1e-5f);
    EXPECT_NEAR(h.shadingNormal.z, expected.z, 1e-5f);
    EXPECT_NEAR(h.normal.z, 1.f, 1e-6f) << "the geometric normal stays the facet's";
    // Flat meshes (quads, boxes) shade with the geometric normal.
    Scene flat(oneQuad());
    ASSERT_TRUE(flat.intersect({0.3f, 0.1f, 3}, {0, 0, -1}, 0, kInf, 0, h));
    EXPECT_NEAR(h.shadingNormal.z, 1.f, 1e-6f);
}

TEST(Scene, SmoothNormalsBlendShallowFoldsAndKeepCreases) {
    // Two triangles sharing the edge (0,0,0)-(0,1,0), folded by `fold` degrees about it.
    auto tent = [](float fold) {
        TriangleMesh m;
        float a = fold * kPi / 180.f;
        m.positions = {{0, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {std::cos(a), 0, std::sin(a)}};
        m.indices = {0, 1, 2, 0, 3, 1};  // left face normal +z; right face (-sin, 0, cos) of `fold`
        m.materialIds = {0, 0};
        m.shapeIds = {0, 0};
        smoothCornerNormals(m, 60.f);
        return m;
    };
    const TriangleMesh shallow = tent(30.f);
    ASSERT_EQ(shallow.cornerNormals.size(), 6u);
    // Both faces have the same area, so a shared corner's normal bisects the fold.
    Vec3f bisector = normalize(Vec3f(0, 0, 1) + Vec3f(-std::sin(30.f * kPi / 180.f), 0, std::cos(30.f * kPi / 180.f)));
    for (int i : {0, 1, 3, 5}) {  // corners at the shared vertices 0 and 1
        EXPECT_NEAR(dot(shallow.cornerNormals[i], bisector), 1.f, 1e-5f) << "corner " << i;
    }
    EXPECT_NEAR(shallow.cornerNormals[2].z, 1.f, 1e-6f) << "a vertex of one face keeps that face's normal";
    const TriangleMesh crease = tent(90.f);  // a box edge
    for (int i : {0, 1, 2}) EXPECT_NEAR(crease.cornerNormals[i].z, 1.f, 1e-6f) << "corner " << i;
    for (int i : {3, 4, 5}) EXPECT_NEAR(crease.cornerNormals[i].x, -1.f, 1e-6f) << "corner " << i;
}

// OBJ and MTL text checks (obj_check.h): tinyobjloader reads what is not a number as 0.

namespace {

using test::errorOf;

std::string objError(const std::string& obj) {
    return errorOf([&] { checkObjText(obj, "s.json: objects[0].file", "m.obj"); });
}

std::string mtlError(const std::string& mtl) {
    return errorOf([&] { checkMtlText(mtl, "s.json: objects[0].file", "m.mtl"); });
}

/// What loadObj makes of an OBJ file on its own (its MTL's materials).
struct LoadedObj {
    std::vector<Material> materials;
    TriangleMesh mesh;
    std::vector<AreaLight> promoted;
    std::vector<std::string> warnings;
};
LoadedObj loadObjFile(const std::string& path, const std::string& where = "w") {
    LoadedObj o;
    loadObj(path, where, -1, o.materials, o.mesh, o.promoted, o.warnings);
    return o;
}

}  // namespace

TEST(ObjCheck, AcceptsWhatTheObjFormatAllows) {
    const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    EXPECT_EQ(objError(tri + "f 1 2 3\n"), "");
    EXPECT_EQ(objError("# comment\r\nv +1 .5 1e-3 1\r\nv 1 0 0 0.2 0.3 0.4\r\nv\t0 1 0\r\n  f 1 2 3\r\n"), "")
        << "CRLF, a leading '+', w, vertex colours, tabs and indentation";
    EXPECT_EQ(objError(tri + "vt 0 0\nvt 1\nvn 0 0 1\nf 1/1/1 2/2/1 3//1\nf -3 -2 -1\nf 1/1 2/2 3/2 1/1\n"), "")
        << "every corner form; negative indices count back";
    EXPECT_EQ(objError(tri + "g box\nusemtl a\ns off\nl 1 2\no thing\n"), "") << "statements wedge ignores";
    EXPECT_EQ(objError("v 0 0 0 # a\nv 1 0 0 #b\nv 0 1 0\nf 1 2 3\n"), "") << "comments after the numbers";
}

TEST(ObjCheck, NamesTheLineOfEveryMalformedNumber) {
    // Each of these rendered without a word before: tinyobjloader read the bad token as 0.
    const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    EXPECT_EQ(objError("v nan 0 0\n"),
              "s.json: objects[0].file: 'm.obj' line 1: `v` expects 3 to 7 numbers (x y z [w] [r g b]), and 'nan' is not a finite number within +-3.4e38");
    EXPECT_NE(objError("v 0 0 inf\n").find("'inf' is not a finite number within +-3.4e38"), std::string::npos);
    EXPECT_NE(objError("v 0.5.5 0 0\n").find("'0.5.5' is not a finite number within +-3.4e38"), std::string::npos);
    EXPECT_NE(objError("v 1,5 0 0\n").find("'1,5' is not a finite number within +-3.4e38"), std::string::npos);
    EXPECT_NE(objError("v 1 0 5#b\n").find("'5#b' is not a finite number"), std::string::npos) << "tinyobjloader reads 0";
    EXPECT_NE(objError("v 1e999 0 0\n").find("'1e999' is not a finite number within +-3.4e38"), std::string::npos);
    EXPECT_NE(objError("v 1e39 0 0\n").find("'1e39' is not a finite number within +-3.4e38"), std::string::npos)
        << "finite as a double, infinite as the float the mesh keeps";
    EXPECT_EQ(objError("v 3e38 0 0\nv 1 0 0\nv 0 1 0\n"), "");
    EXPECT_NE(objError("v 0 0\n").find("line 1: `v` expects 3 to 7 numbers (x y z [w] [r g b]), got 2 values"), std::string::npos);
    EXPECT_NE(objError(tri + "vn 0 0 nan\n").find("line 4: `vn` expects 3 numbers (x y z), and 'nan'"), std::string::npos);
    EXPECT_NE(objError(tri + "vn 0 1\n").find("line 4: `vn` expects 3 numbers (x y z), got 2 values"), std::string::npos);
}

TEST(ObjCheck, NamesTheLineOfEveryMalformedFace) {
    const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    EXPECT_EQ(objError(tri + "f 1 2 x\n"), "s.json: objects[0].file: 'm.obj' line 4: face corner 'x' is not a non-zero integer index");
    EXPECT_NE(objError(tri + "f 1 2 0\n").find("line 4: face corner '0' is not a non-zero integer index"), std::string::npos);
    EXPECT_NE(objError(tri + "f 1 2 3/x\n").find("face corner '3/x': 'x' is not a non-zero integer index"), std::string::npos);
    EXPECT_NE(objError(tri + "f 1 2 3/1/2/4\n").find("face corner '3/1/2/4' is not v, v/t, v//n or v/t/n"), std::string::npos);
    EXPECT_NE(objError(tri + "f 1 2 3/\n").find("is not v, v/t, v//n or v/t/n"), std::string::npos);
    EXPECT_NE(objError(tri + "f 1 2 3 # c\n").find("face corner '#' is not a non-zero integer index"), std::string::npos)
        << "tinyobjloader rejects a comment after a face";
    EXPECT_NE(objError(tri + "f 1 2\n").find("line 4: a face needs at least 3 corners, got 2"), std::string::npos);
    // An index names an element of the file; a negative one counts back from the last one
    // defined above the face. (tinyobjloader resolves positive indices after reading the file,
    // so a face may name a vertex defined below it.)
    EXPECT_EQ(objError(tri + "f 1 2 4\nv 0 0 1\n"), "");
    EXPECT_EQ(objError(tri + "f 1 2 7\nf 1 2 5\nv 0 0 1\n"),
              "s.json: objects[0].file: 'm.obj' line 4: face corner '7' refers to vertex 7, but the file has 4 `v` lines");
    EXPECT_NE(objError(tri + "f 1 2 -4\nv 0 0 1\n").find("line 4: face corner '-4' refers to vertex -4, but 3 `v` lines precede it"),
              std::string::npos);
    EXPECT_NE(objError(tri + "vn 0 0 1\nf 1//1 2//1 3//2\n").find("line 5: face corner '3//2' refers to normal 2, but the file has 1 `vn` line"),
              std::string::npos);
}

TEST(ObjCheck, LinesThatAreNoStatementAreNamed) {
    // tinyobjloader skips them; a mistyped `v` or `f` loses geometry without a word.
    const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    EXPECT_EQ(checkObjText(tri + "vp 0.5\ncstype bspline\ng a\no b\ns 1\nusemtl m\nl 1 2\np 1\n", "w", "m.obj"), "");
    EXPECT_EQ(checkObjText("v 0 0 0\nv1 0 0\n/v 1 0 0\n" + tri, "w", "m.obj"),
              "'m.obj' line 2: 'v1' is not an OBJ statement (nor are the first words of 1 more lines); skipped");
    EXPECT_EQ(checkObjText(tri + "3 -2 -1\n", "w", "m.obj"), "'m.obj' line 5: '3' is not an OBJ statement; skipped");
}

TEST(ObjCheck, MtlColoursAreOneOrThreeFiniteNumbers) {
    auto materials = checkMtlText("# c\r\nnewmtl a b\r\nKd 0.5\r\nKe 1 2 3\r\nnewmtl c\nKd 0.1 0.2 0.3\nKe 4\nNs x\nmap_Kd t.png\n", "w", "m.mtl");
    ASSERT_EQ(materials.size(), 2u) << "statements wedge does not render (Ns, map_Kd) are not checked";
    EXPECT_EQ(materials[0].name, "a b");
    EXPECT_TRUE(materials[0].greyKd);
    EXPECT_FALSE(materials[0].greyKe);
    EXPECT_FALSE(materials[1].greyKd);
    EXPECT_TRUE(materials[1].greyKe);
    EXPECT_FALSE(checkMtlText("newmtl a\nKd 0.5\nKd 0.1 0.2 0.3\n", "w", "m.mtl")[0].greyKd) << "the last Kd counts";
    EXPECT_EQ(mtlError("newmtl a # b\nKd 0.5 0.5 0.5 # grey\n"), "");

    EXPECT_EQ(mtlError("newmtl a\nKd 0.5 x 0.2\n"),
              "s.json: objects[0].file: 'm.mtl' line 2: `Kd` expects r g b (or one number for grey), and 'x' is not a finite number within +-3.4e38");
    EXPECT_NE(mtlError("newmtl a\nKd 0.5 0.5\n").find("line 2: `Kd` expects r g b (or one number for grey), got 2 values"),
              std::string::npos);
    EXPECT_NE(mtlError("newmtl a\nKd 1e999 0 0\n").find("'1e999' is not a finite number"), std::string::npos);
    EXPECT_NE(mtlError("newmtl a\nKe nan 0 0\n").find("'nan' is not a finite number within +-3.4e38"), std::string::npos);
    EXPECT_NE(mtlError("newmtl a\nKd\n").find("got 0 values"), std::string::npos);
    EXPECT_NE(mtlError("newmtl a\nKd spectral a.rfl\n").find("line 2: `Kd spectral` colours are not supported; give r g b"),
              std::string::npos);
}

TEST(ObjCheck, MtlFilesAreFoundAsTinyobjloaderFindsThem) {
    std::string dir = test::tempDir();
    test::writeFile(dir + "/a.mtl", "newmtl a\n");
    test::writeFile(dir + "/b c.mtl", "newmtl b\n");
    // Per statement the first name that exists; a name read before is not read again.
    EXPECT_EQ(mtlFilesOf("mtllib missing.mtl a.mtl other.mtl\nmtllib a.mtl\nmtllib b\\ c.mtl\n", dir),
              (std::vector<std::string>{dir + "/a.mtl", dir + "/b c.mtl"}));
    EXPECT_TRUE(mtlFilesOf("mtllib missing.mtl\n", dir).empty());
}

TEST(ObjCheck, AGreyMtlColourLoadsAsGrey) {
    // The MTL format reads `Kd 0.5` as 0.5 0.5 0.5; tinyobjloader reads (0.5, 0, 0).
    std::string dir = test::tempDir();
    test::writeFile(dir + "/q.obj", "mtllib q.mtl\nv -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nusemtl g\nf 1 4 3\nusemtl c\nf 1 3 2\n");
    test::writeFile(dir + "/q.mtl", "newmtl g\nKd 0.5\nKe 2\nnewmtl c\nKd 0.1 0.2 0.3\n");
    const std::vector<Material> materials = loadObjFile(dir + "/q.obj").materials;
    ASSERT_EQ(materials.size(), 2u);
    EXPECT_EQ(materials[0].albedo, Vec3f(0.5f));
    EXPECT_EQ(materials[0].emission, Vec3f(2.f));
    EXPECT_EQ(materials[1].albedo, Vec3f(0.1f, 0.2f, 0.3f));
    EXPECT_EQ(materials[1].emission, Vec3f(0.f));
}

TEST(ObjCheck, ShippedMeshesPass) {
    int mtls = 0;
    for (const char* obj : {"cornell/CornellBox-Original.obj", "cornell/CornellBox-Glossy.obj", "conference/conference.obj",
                            "sponza/sponza.obj", "bunny/stanford-bunny.obj"}) {
        const std::string path = scenesDirectory() + "/" + obj, text = test::readFile(path);
        ASSERT_FALSE(text.empty()) << path;
        EXPECT_NO_THROW(checkObjText(text, "test", path)) << path;
        for (const std::string& mtl : mtlFilesOf(text, std::filesystem::path(path).parent_path().string())) {
            EXPECT_NO_THROW(checkMtlText(test::readFile(mtl), "test", mtl)) << mtl;
            ++mtls;
        }
    }
    EXPECT_EQ(mtls, 4) << "the two Cornell boxes', conference's and sponza's";
}

TEST(SceneFile, EmittersBecomeLightsOrAreNamed) {
    // The scene's lights, and emissive quads, boxes, spheres and OBJ meshes that do not move,
    // are lights; moving emitters are seen but light nothing, which used to pass silently, and
    // so are emitters past kMaxLights.
    auto warningsOf = [](const std::string& objects, const std::string& dir = ".") {
        const std::string json = R"({
          "camera": {"position": [0, 1, 3], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_y": 40, "resolution": [8, 8]},
          "materials": {"white": {"albedo": [0.8, 0.8, 0.8]}, "glow": {"albedo": [0, 0, 0], "emission": [4, 4, 4]}},
          "lights": [{"type": "parallelogram", "corner": [-0.5, 2, -0.5], "edge1": [1, 0, 0], "edge2": [0, 0, 1], "radiance": [5, 5, 5]}],
          "objects": [)" + objects + R"(]})";
        SceneDesc d = parseScene(json, "s.json", dir);
        std::string all;
        for (const std::string& w : d.warnings) all += w + "\n";
        return std::make_pair(all, d.lights.size());
    };
    auto [quad, quadLights] = warningsOf(R"({"type": "quad", "corner": [0, 1, 0], "edge1": [1, 0, 0], "edge2": [0, 0, 1], "material": "glow"})");
    EXPECT_EQ(quad, "");
    EXPECT_EQ(quadLights, 2u) << "a still emissive quad is a light";
    auto [box, boxLights] = warningsOf(R"({"type": "box", "min": [0, 0, 0], "max": [1, 1, 1], "material": "glow"})");
    EXPECT_EQ(box, "");
    EXPECT_EQ(boxLights, 7u) << "a box's six faces are lights";
    auto [sphere, sphereLights] = warningsOf(R"({"type": "sphere", "center": [0, 0, 0], "radius": 0.5, "material": "glow"})");
    EXPECT_EQ(sphere, "");
    EXPECT_EQ(sphereLights, 2u) << "a still emissive sphere is a light";
    auto [movingSphere, movingSphereLights] = warningsOf(
        R"({"type": "sphere", "center": [0, 0, 0], "radius": 0.5, "material": "glow", "velocity": [1, 0, 0]})");
    EXPECT_EQ(movingSphere,
              "s.json: objects[0]: the 1 emissive face(s) of this sphere are only seen and light nothing: moving emitters are not lights\n");
    EXPECT_EQ(movingSphereLights, 1u);
    auto [moving, movingLights] = warningsOf(
        R"({"type": "box", "min": [0, 0, 0], "max": [1, 1, 1], "material": "glow", "velocity": [1, 0, 0]})");
    EXPECT_EQ(moving, "s.json: objects[0]: the 6 emissive face(s) of this box are only seen and light nothing: moving emitters are not lights\n");
    EXPECT_EQ(movingLights, 1u);

    std::string dir = test::tempDir();
    test::writeFile(dir + "/lamp.obj", "mtllib lamp.mtl\nv 0 2 0\nv 1 2 0\nv 0 2 1\nv 1 2 1\nusemtl lamp\nf 1 2 3\nf 1 3 4 2\n");
    test::writeFile(dir + "/lamp.mtl", "newmtl lamp\nKd 0 0 0\nKe 9 9 9\n");
    auto [obj, objLights] = warningsOf(R"({"type": "mesh", "file": "lamp.obj"})", dir);
    EXPECT_EQ(obj, "");
    EXPECT_EQ(objLights, 3u) << "the parallelogram face and the triangle are lights";
    auto [movingObj, movingObjLights] = warningsOf(R"({"type": "mesh", "file": "lamp.obj", "velocity": [0, 1, 0]})", dir);
    EXPECT_EQ(movingObj, "s.json: objects[0]: the 2 emissive face(s) of 'lamp.obj' are only seen and light nothing: moving emitters are not lights\n");
    EXPECT_EQ(movingObjLights, 1u);

    // kMaxLights: 300 separate emissive triangles would make 301 lights; none of them is one.
    std::string many = "mtllib lamp.mtl\nusemtl lamp\n";
    for (int i = 0; i < 300; ++i) {
        const std::string x = std::to_string(i * 0.01), x2 = std::to_string(i * 0.01 + 0.005);
        many += "v " + x + " 1 0\nv " + x + " 1 0.005\nv " + x2 + " 1 0\nf -3 -2 -1\n";
    }
    test::writeFile(dir + "/many.obj", many);
    auto [tooMany, tooManyLights] = warningsOf(R"({"type": "mesh", "file": "many.obj"})", dir);
    EXPECT_EQ(tooMany, "s.json: objects[0]: the 300 emissive face(s) of 'many.obj' are only seen and light nothing: the scene "
                       "has 1 lights before them and takes 256 at most\n");
    EXPECT_EQ(tooManyLights, 1u);
    std::string lights;
    for (size_t i = 0; i <= kMaxLights; ++i)
        lights += std::string(i ? ", " : "") +
                  R"({"type": "triangle", "corner": [0, 2, 0], "edge1": [0, 0, 1], "edge2": [1, 0, 0], "radiance": [1, 1, 1]})";
    EXPECT_EQ(test::errorOf([&] {
                  parseScene(R"({"camera": {"position": [0, 1, 3], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_y": 40, "resolution": [8, 8]},
                                 "lights": [)" + lights + R"(], "materials": {"w": {"albedo": [1, 1, 1]}},
                                 "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "w"}]})",
                             "s.json", ".");
              }),
              "s.json: lights[256]: more than 256 lights (MAAF keeps a light's index in a byte)");
}

TEST(SceneFile, EmissiveTrianglesAreLightsAndPairsThatMakeAParallelogramOne) {
    // A triangulating exporter splits a rectangular light along one diagonal or the other; the
    // two triangles become one parallelogram light again, facing as they do. Triangles that make
    // no parallelogram are triangle lights.
    std::string dir = test::tempDir();
    test::writeFile(dir + "/lamp.mtl", "newmtl lamp\nKd 0 0 0\nKe 9 9 9\n");
    const std::string corners = "mtllib lamp.mtl\nv 0 2 0\nv 0 2 1\nv 2 2 1\nv 2 2 0\nusemtl lamp\n";  // wound to face +y
    for (const char* faces : {"f 1 2 3\nf 1 3 4\n", "f 1 2 4\nf 2 3 4\n", "f 3 4 1\nf 2 3 1\n"}) {
        test::writeFile(dir + "/lamp.obj", corners + faces);
        LoadedObj o = loadObjFile(dir + "/lamp.obj");
        ASSERT_EQ(o.promoted.size(), 1u) << faces;
        EXPECT_TRUE(o.warnings.empty()) << o.warnings[0];
        const AreaLight& l = o.promoted[0];
        EXPECT_FALSE(l.triangle());
        EXPECT_NEAR(l.area(), 2.f, 1e-6f) << faces;
        EXPECT_NEAR(l.normal().y, 1.f, 1e-6f) << faces;  // as each triangle faces
        EXPECT_EQ(l.radiance, Vec3f(9.f));
    }
    // Not a parallelogram (a kite: areas 1 and 3.5), or a third triangle over two that pair:
    // triangle lights, facing as their faces do.
    for (auto [faces, lights, triangleArea] : {std::tuple{"v 1 2 -3\nf 1 2 3\nf 1 3 5\n", 2u, 4.5f},
                                               std::tuple{"f 1 2 3\nf 3 4 1\nf 1 2 4\n", 2u, 1.f}}) {
        test::writeFile(dir + "/lamp.obj", corners + faces);
        LoadedObj o = loadObjFile(dir + "/lamp.obj");
        EXPECT_TRUE(o.warnings.empty()) << o.warnings[0];
        ASSERT_EQ(o.promoted.size(), lights) << faces;
        float area = 0;
        for (const AreaLight& l : o.promoted)
            if (l.triangle()) {
                area += l.area();
                EXPECT_NEAR(std::abs(l.normal().y), 1.f, 1e-6f);
            }
        EXPECT_NEAR(area, triangleArea, 1e-5f) << faces;
    }
}

TEST(SceneFile, ObjDiffuseMapsTextureTheAlbedo) {
    // A quad with texture coordinates and a 2x2 PNG map_Kd: a hit's albedo is Kd times the
    // bilinear texel at its (u, v), (0, 0) at the image's bottom left, repeating.
    std::string dir = test::tempDir();
    Image3f img(2, 2);
    img(0, 0) = Vec3f(1, 0, 0);  // top left
    img(1, 0) = Vec3f(0, 1, 0);
    img(0, 1) = Vec3f(0, 0, 1);  // bottom left
    img(1, 1) = Vec3f(1, 1, 1);
    io::writePng(dir + "/t.png", img);
    test::writeFile(dir + "/q.obj", "mtllib q.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                    "usemtl m\nf 1/1 2/2 3/3 4/4\n");
    test::writeFile(dir + "/q.mtl", "newmtl m\nKd 0.5 0.5 0.5\nmap_Kd t.png\n");
    SceneDesc d;
    std::vector<AreaLight> promoted;
    loadObj(dir + "/q.obj", "s.json: objects[0].file", -1, d.materials, d.meshes.emplace_back(), promoted, d.warnings);
    ASSERT_EQ(d.materials.size(), 1u);
    ASSERT_TRUE(d.materials[0].map);
    EXPECT_TRUE(d.warnings.empty()) << d.warnings[0];
    const TextureMap& map = *d.materials[0].map;
    d.lights.push_back({{0, 0, 5}, {1, 0, 0}, {0, 1, 0}, Vec3f(1.f)});
    Scene s(std::move(d));
    auto albedoAt = [&](float x, float y) {
        Hit h;
        EXPECT_TRUE(s.intersect({x, y, 1}, {0, 0, -1}, 0, kInf, 0, h));
        return h.albedo;
    };
    auto near = [](const Vec3f& a, const Vec3f& b) { return length(a - b) < 1e-5f; };
    // Texel centres at u, v = 0.25 and 0.75: exactly the texels, times Kd.
    EXPECT_TRUE(near(albedoAt(0.25f, 0.75f), map.texels(0, 0) * 0.5f));
    EXPECT_TRUE(near(albedoAt(0.75f, 0.75f), map.texels(1, 0) * 0.5f));
    EXPECT_TRUE(near(albedoAt(0.25f, 0.25f), map.texels(0, 1) * 0.5f));
    EXPECT_TRUE(near(map.texels(0, 1), Vec3f(0, 0, 1))) << "the PNG keeps pure colours";
    // Between two texel centres: their mean. At the quad's edge (u = 0): the texel and its
    // repeated neighbour (u = -0.25 is texel 1).
    EXPECT_TRUE(near(albedoAt(0.5f, 0.75f), (map.texels(0, 0) + map.texels(1, 0)) * 0.25f));
    EXPECT_TRUE(near(map.lookup({0.f, 0.75f}), (map.texels(0, 0) + map.texels(1, 0)) * 0.5f));
    EXPECT_TRUE(near(map.lookup({1.25f, 0.75f}), map.texels(0, 0))) << "repeats";
    EXPECT_TRUE(near(map.lookup({-0.75f, -0.25f}), map.texels(0, 0))) << "repeats below zero";
    for (float big : {3e38f, -3e38f, 1e30f}) {
        const Vec3f c = map.lookup({big, big * 4});  // overflows to infinity: a texel all the same
        EXPECT_TRUE(isFinite(c) && c.x >= 0 && c.x <= 1) << big;
    }
}

TEST(SceneFile, DiffuseMapsWedgeCannotReadAreNamed) {
    std::string dir = test::tempDir();
    test::writeFile(dir + "/q.obj", "mtllib q.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nusemtl a\nf 1 2 3\nusemtl b\nf 1 3 2\n");
    test::writeFile(dir + "/q.mtl", "newmtl a\nKd 0.5 0.5 0.5\nmap_Kd wood.tga\nnewmtl b\nKd 0.5 0.5 0.5\nmap_Kd gone.png\n");
    LoadedObj o = loadObjFile(dir + "/q.obj");
    ASSERT_EQ(o.warnings.size(), 1u);
    EXPECT_NE(o.warnings[0].find("the diffuse maps of 'a' (map_Kd 'wood.tga': wedge reads PNG and JPEG textures), 'b' (map_Kd '" + dir +
                                 "/gone.png' does not exist) are not rendered"),
              std::string::npos)
        << o.warnings[0];
    EXPECT_FALSE(o.materials[0].map);

    // A PNG map on a file without texture coordinates.
    Image3f img(1, 1, Vec3f(0.5f));
    io::writePng(dir + "/t.png", img);
    test::writeFile(dir + "/q.mtl", "newmtl a\nKd 0.5 0.5 0.5\nmap_Kd t.png\nnewmtl b\nKd 0.5 0.5 0.5\n");
    o = loadObjFile(dir + "/q.obj");
    ASSERT_EQ(o.warnings.size(), 1u);
    EXPECT_NE(o.warnings[0].find("the map_Kd of 'q.obj:a' is not rendered: the file has no texture coordinates (vt)"), std::string::npos)
        << o.warnings[0];

    // Options: -s with three numbers scales (u, v); with two, tinyobjloader takes the file name
    // for the third and loses it, which is an error rather than an untextured material.
    test::writeFile(dir + "/uv.obj", "mtllib uv.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nusemtl a\nf 1/1 2/1 3/1\n");
    test::writeFile(dir + "/uv.mtl", "newmtl a\nKd 0.5 0.5 0.5\nmap_Kd -s 4 2 1 -o 0.5 0 0 t.png\n");
    o = loadObjFile(dir + "/uv.obj");
    ASSERT_TRUE(o.materials[0].map);
    EXPECT_EQ(o.materials[0].map->scale.x, 4.f);
    EXPECT_EQ(o.materials[0].map->scale.y, 2.f);
    EXPECT_EQ(o.materials[0].map->offset.x, 0.5f);
    test::writeFile(dir + "/uv.mtl", "newmtl a\nKd 0.5 0.5 0.5\nmap_Kd -s 4 4 t.png\n");
    EXPECT_NE(errorOf([&] { loadObjFile(dir + "/uv.obj"); }).find("material 'a': tinyobjloader reads 'map_Kd -s 4 4 t.png' as the file ''"),
              std::string::npos);
    // A file name with a space is the rest of the line, for tinyobjloader too.
    io::writePng(dir + "/my t.png", img);
    test::writeFile(dir + "/uv.mtl", "newmtl a\nKd 0.5 0.5 0.5\nmap_Kd -clamp on my t.png \n");
    o = loadObjFile(dir + "/uv.obj");
    ASSERT_TRUE(o.materials[0].map);
    EXPECT_EQ(o.materials[0].map->file, dir + "/my t.png");
    EXPECT_TRUE(o.materials[0].map->clamp);

    // A file that is not a PNG: an error naming the material.
    test::writeFile(dir + "/t.png", "not a png");
    EXPECT_NE(errorOf([&] { loadObjFile(dir + "/q.obj"); }).find("w: '" + dir + "/q.obj': material 'a': map_Kd: " + dir + "/t.png"),
              std::string::npos);
    // A JPEG map (.jpg or .jpeg, any case) is read as a JPEG, sRGB to linear; a damaged one is
    // an error too.
    test::writeJpeg(dir + "/t.jpeg", 8, 8, 1, std::vector<unsigned char>(64, 188), 90);
    test::writeFile(dir + "/q.mtl", "newmtl a\nKd 0.5 0.5 0.5\nmap_Kd t.jpeg\nnewmtl b\nKd 0.5 0.5 0.5\n");
    o = loadObjFile(dir + "/q.obj");
    ASSERT_TRUE(o.materials[0].map);
    EXPECT_NEAR(o.materials[0].map->texels(3, 3).y, 0.503f, 0.01f);  // sRGB 188 / 255
    test::writeFile(dir + "/t.JPG", "not a jpeg");
    test::writeFile(dir + "/q.mtl", "newmtl a\nKd 0.5 0.5 0.5\nmap_Kd t.JPG\nnewmtl b\nKd 0.5 0.5 0.5\n");
    EXPECT_NE(errorOf([&] { loadObjFile(dir + "/q.obj"); }).find("material 'a': map_Kd: " + dir + "/t.JPG: corrupt JPEG file"),
              std::string::npos)
        << errorOf([&] { loadObjFile(dir + "/q.obj"); });
}

// Every scene file the docs measure on (docs/*.json, docs/lamps/*.json) loads without a warning
// (but a moving emitter's),
// has something to see and a light: a docs table whose scene no longer parses is a table
// nobody can reproduce.
TEST(Scene, EveryDocsSceneLoads) {
    namespace fs = std::filesystem;
    int n = 0;
    for (const char* dir : {"docs", "docs/lamps"}) {
        for (const auto& e : fs::directory_iterator(fs::path(test::sourceDir()) / dir)) {
            if (e.path().extension() != ".json") continue;
            SCOPED_TRACE(e.path().string());
            scene::SceneDesc d;
            ASSERT_NO_THROW(d = scene::loadScene(e.path().string()));
            // (But that a moving emitter lights nothing: docs/bokeh.json and docs/streaks.json have them on purpose.)
            for (const std::string& w : d.warnings) EXPECT_NE(w.find("moving emitters are not lights"), std::string::npos) << w;
            EXPECT_GT(d.triangleCount() + d.spheres.size(), 0u);
            EXPECT_FALSE(d.lights.empty());
            ++n;
        }
    }
    EXPECT_GE(n, 18);
}
