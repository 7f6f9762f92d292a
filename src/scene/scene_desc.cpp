#include "scene/scene_desc.h"

#include <algorithm>
#include <cmath>

namespace wedge::scene {

Vec3f TextureMap::lookup(Vec2f uv) const {
    const int w = texels.width(), h = texels.height();
    float u = uv.x * scale.x + offset.x, v = uv.y * scale.y + offset.y;
    if (!std::isfinite(u)) u = 0.f;  // vt and -s are finite, but their product may overflow
    if (!std::isfinite(v)) v = 0.f;
    if (clamp) {
        u = std::clamp(u, 0.f, 1.f);
        v = std::clamp(v, 0.f, 1.f);
    }
    // Texel centres at (i + 0.5) / w; v runs up the image, rows down it. In double: u x w
    // overflows float for u near its largest values.
    const double fx = double(u) * w - 0.5, fy = (1.0 - double(v)) * h - 0.5;
    const double x0f = std::floor(fx), y0f = std::floor(fy);
    const float tx = float(fx - x0f), ty = float(fy - y0f);
    auto index = [&](double i, int n) {
        if (clamp) return int(std::clamp(i, 0.0, double(n - 1)));
        const double m = std::fmod(i, double(n));  // repeat, negative coordinates too
        return std::clamp(int(m < 0 ? m + n : m), 0, n - 1);
    };
    const int x0 = index(x0f, w), x1 = index(x0f + 1, w), y0 = index(y0f, h), y1 = index(y0f + 1, h);
    return (texels(x0, y0) * (1 - tx) + texels(x1, y0) * tx) * (1 - ty) + (texels(x0, y1) * (1 - tx) + texels(x1, y1) * tx) * ty;
}

bool SceneDesc::hasMotion() const {
    if (camera.velocity != Vec3f(0.f) || camera.lookAtVelocity != Vec3f(0.f)) return true;  // everything moves on the screen
    for (auto& m : meshes)
        if (m.moves()) return true;
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
    if (!mesh.cornerNormals.empty()) mesh.cornerNormals.insert(mesh.cornerNormals.end(), 6, normalize(cross(e1, e2)));
}

void appendTriangle(TriangleMesh& mesh, const Vec3f& corner, const Vec3f& e1, const Vec3f& e2, uint32_t material) {
    uint32_t base = uint32_t(mesh.positions.size());
    mesh.positions.insert(mesh.positions.end(), {corner, corner + e1, corner + e2});
    mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 2});
    mesh.materialIds.push_back(material);
    mesh.shapeIds.push_back(0);
    if (!mesh.cornerNormals.empty()) mesh.cornerNormals.insert(mesh.cornerNormals.end(), 3, normalize(cross(e1, e2)));
}

void smoothCornerNormals(TriangleMesh& mesh, float creaseDegrees) {
    const size_t triangles = mesh.triangleCount();
    if (mesh.cornerNormals.empty()) mesh.cornerNormals.assign(3 * triangles, Vec3f(0.f));
    // A mesh whose file gives every corner a normal (sponza, conference) needs no adjacency.
    if (std::none_of(mesh.cornerNormals.begin(), mesh.cornerNormals.end(), [](const Vec3f& n) { return n == Vec3f(0.f); }))
        return;
    // Area-weighted face normals (the cross product's length is twice the area).
    std::vector<Vec3f> face(triangles);
    for (size_t t = 0; t < triangles; ++t) {
        const Vec3f &a = mesh.positions[mesh.indices[3 * t]], &b = mesh.positions[mesh.indices[3 * t + 1]],
                    &c = mesh.positions[mesh.indices[3 * t + 2]];
        face[t] = cross(b - a, c - a);
    }
    // Triangles around each vertex (compressed adjacency).
    const size_t vertices = mesh.positions.size();
    std::vector<uint32_t> start(vertices + 1, 0), around(3 * triangles);
    for (uint32_t v : mesh.indices) ++start[v + 1];
    for (size_t v = 0; v < vertices; ++v) start[v + 1] += start[v];
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (size_t i = 0; i < mesh.indices.size(); ++i) around[fill[mesh.indices[i]]++] = uint32_t(i / 3);
    const float cosCrease = std::cos(creaseDegrees * kPi / 180.f);
    for (size_t i = 0; i < 3 * triangles; ++i) {
        if (mesh.cornerNormals[i] != Vec3f(0.f)) continue;
        const size_t t = i / 3;
        const float area = length(face[t]);
        if (area <= 0) {  // degenerate: never hit by a ray, any unit vector will do
            mesh.cornerNormals[i] = Vec3f(0, 0, 1);
            continue;
        }
        const Vec3f own = face[t] / area;
        Vec3f sum(0.f);
        const uint32_t v = mesh.indices[i];
        for (uint32_t k = start[v]; k < start[v + 1]; ++k) {
            const Vec3f& f = face[around[k]];
            const float len = length(f);
            if (len > 0 && dot(f, own) >= cosCrease * len) sum += f;
        }
        mesh.cornerNormals[i] = normalize(sum);  // includes the own face, so never zero
    }
}

std::vector<uint32_t> lightGroups(const std::vector<AreaLight>& lights) {
    const size_t n = lights.size();
    std::vector<uint32_t> parent(n);
    for (size_t i = 0; i < n; ++i) parent[i] = uint32_t(i);
    auto root = [&](uint32_t i) {
        while (parent[i] != i) i = parent[i] = parent[parent[i]];
        return i;
    };
    std::vector<std::array<Vec3f, 4>> corners(n);
    std::vector<int> count(n);
    std::vector<float> size(n);  // the longest edge: the scale of the tolerances
    for (size_t i = 0; i < n; ++i) {
        count[i] = lights[i].vertices(corners[i].data());
        size[i] = std::max(length(lights[i].edge1), length(lights[i].edge2));
    }
    // Float noise from an OBJ's transform leaves shared corners and a common plane equal only to
    // about 1e-6 of the light's size; 1e-4 of it (and 0.1 degrees between the normals) is far
    // from any two lights a scene means to keep apart.
    constexpr float kCosParallel = 0.9999985f;  // cos(0.1 degrees)
    for (size_t i = 0; i < n; ++i)
        for (size_t j = i + 1; j < n; ++j) {
            const AreaLight &a = lights[i], &b = lights[j];
            if (a.sphere() || b.sphere()) continue;
            if (!(a.radiance == b.radiance) || dot(a.normal(), b.normal()) < kCosParallel) continue;
            const float tol = 1e-4f * std::max(size[i], size[j]);
            if (std::abs(dot(a.normal(), b.center() - a.center())) > tol) continue;
            bool touch = false;
            for (int u = 0; u < count[i] && !touch; ++u)
                for (int v = 0; v < count[j] && !touch; ++v) touch = length(corners[i][u] - corners[j][v]) <= tol;
            if (touch) parent[root(uint32_t(j))] = root(uint32_t(i));
        }
    // Number the groups by their first light.
    std::vector<uint32_t> group(n), number(n, UINT32_MAX);
    uint32_t next = 0;
    for (size_t i = 0; i < n; ++i) {
        uint32_t r = root(uint32_t(i));
        if (number[r] == UINT32_MAX) number[r] = next++;
        group[i] = number[r];
    }
    return group;
}

std::array<std::array<Vec3f, 3>, 6> boxFaces(const Vec3f& lo, const Vec3f& hi) {
    const Vec3f d = hi - lo;
    const Vec3f ex(d.x, 0, 0), ey(0, d.y, 0), ez(0, 0, d.z);
    return {{{lo, ey, ex},         // z = lo (normal -z)
             {lo + ez, ex, ey},    // z = hi (+z)
             {lo, ez, ey},         // x = lo (-x)
             {lo + ex, ey, ez},    // x = hi (+x)
             {lo, ex, ez},         // y = lo (-y)
             {lo + ey, ez, ex}}};  // y = hi (+y)
}

void appendBox(TriangleMesh& mesh, const Vec3f& lo, const Vec3f& hi, uint32_t material) {
    for (const auto& f : boxFaces(lo, hi)) appendQuad(mesh, f[0], f[1], f[2], material);
}

}  // namespace wedge::scene
