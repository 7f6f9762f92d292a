// Scene module: geometry conventions of the built Embree scene and the occluder-span query.
#include <gtest/gtest.h>

#include "scene/scene.h"

using namespace wedge;
using namespace wedge::scene;

namespace {

SceneDesc oneQuad() {
    SceneDesc d;
    d.materials.push_back({"white", Vec3f(0.5f), Vec3f(0.f), "", 1.f});
    TriangleMesh m;
    appendQuad(m, {-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, 0);  // normal +z
    d.meshes.push_back(m);
    d.lights.push_back({{-0.5f, -0.5f, 5}, {1, 0, 0}, {0, -1, 0}, Vec3f(1.f)});
    return d;
}

void expectSpan(const OccluderSpan& span, float tNear, float tFar) {
    ASSERT_TRUE(span.occluded);
    EXPECT_NEAR(span.tNear, tNear, 1e-4f);
    EXPECT_NEAR(span.tFar, tFar, 1e-4f);
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
    ParallelogramLight l{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, Vec3f(1.f)};
    EXPECT_NEAR(l.normal().z, 1.f, 1e-6f);
    EXPECT_NEAR(l.area(), 1.f, 1e-6f);
}

TEST(Scene, OccluderSpanFindsNearestAndFarthest) {
    SceneDesc d = oneQuad();
    TriangleMesh m;
    appendQuad(m, {-1, -1, 1}, {2, 0, 0}, {0, 2, 0}, 0);
    appendQuad(m, {-1, -1, 2.5f}, {2, 0, 0}, {0, 2, 0}, 0);
    d.meshes.push_back(m);
    Scene s(std::move(d));
    expectSpan(s.occluders({0, 0, 0.01f}, {0, 0, 1}, 0, 10, 0), 0.99f, 2.49f);
    EXPECT_TRUE(s.occluded({0, 0, 0.01f}, {0, 0, 1}, 0, 10, 0));
    EXPECT_FALSE(s.occluded({0, 0, 0.01f}, {0, 0, 1}, 0, 0.5f, 0));
    EXPECT_FALSE(s.occluders({0, 0, 0.01f}, {0, 0, 1}, 0, 0.5f, 0).occluded);
}

TEST(Scene, OccluderSpanOfManyAndOfOneOccluder) {
    // The span is found by two closest-hit queries (from each end): the middle occluder must not
    // matter, and a single occluder gives tNear == tFar. Offsetting the segment's start shifts both.
    SceneDesc d = oneQuad();
    TriangleMesh m;
    for (float z : {1.f, 1.7f, 2.5f}) appendQuad(m, {-1, -1, z}, {2, 0, 0}, {0, 2, 0}, 0);
    appendQuad(m, {5, -1, 1.2f}, {2, 0, 0}, {0, 2, 0}, 0);  // only under x in [5, 7]
    d.meshes.push_back(m);
    Scene s(std::move(d));
    expectSpan(s.occluders({0, 0, 0}, {0, 0, 1}, 0.5f, 3.f, 0), 1.f, 2.5f);
    expectSpan(s.occluders({6, 0, 0}, {0, 0, 1}, 0.f, 3.f, 0), 1.2f, 1.2f);
    // A segment ending between the occluders sees only those before its end.
    expectSpan(s.occluders({0, 0, 0}, {0, 0, 1}, 0.f, 2.f, 0), 1.f, 1.7f);
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
    d.materials.push_back({"white", Vec3f(0.5f), Vec3f(0.f), "", 1.f});
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

TEST(Scene, CornerNormalsAreInterpolatedWithEmbreeBarycentrics) {
    SceneDesc d;
    d.materials.push_back({"white", Vec3f(0.5f), Vec3f(0.f), "", 1.f});
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
