#include "scene/scene_desc.h"

namespace wedge::scene {

bool SceneDesc::hasMotion() const {
    for (auto& m : meshes)
        if (m.velocity != Vec3f(0.f)) return true;
    for (auto& s : spheres)
        if (s.velocity != Vec3f(0.f)) return true;
    return false;
}

void appendQuad(TriangleMesh& mesh, const Vec3f& corner, const Vec3f& e1, const Vec3f& e2, uint32_t material) {
    uint32_t base = uint32_t(mesh.positions.size());
    mesh.positions.insert(mesh.positions.end(), {corner, corner + e1, corner + e1 + e2, corner + e2});
    mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    mesh.materialIds.insert(mesh.materialIds.end(), {material, material});
    mesh.shapeIds.insert(mesh.shapeIds.end(), {0, 0});
}

void appendBox(TriangleMesh& mesh, const Vec3f& lo, const Vec3f& hi, uint32_t material) {
    Vec3f d = hi - lo;
    Vec3f ex(d.x, 0, 0), ey(0, d.y, 0), ez(0, 0, d.z);
    // Each face as corner + two edges whose cross product points outward.
    appendQuad(mesh, lo, ey, ex, material);              // z = lo (normal -z)
    appendQuad(mesh, lo + ez, ex, ey, material);         // z = hi (+z)
    appendQuad(mesh, lo, ez, ey, material);              // x = lo (-x)
    appendQuad(mesh, lo + ex, ey, ez, material);         // x = hi (+x)
    appendQuad(mesh, lo, ex, ez, material);              // y = lo (-y)
    appendQuad(mesh, lo + ey, ez, ex, material);         // y = hi (+y)
}

}  // namespace wedge::scene
