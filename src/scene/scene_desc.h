// The scene description: what a scene file says, after validation and after meshes are loaded
// and transformed into world space. Plain data; Embree never appears here (scene.h owns it),
// so the rasterizer and the tests can use descriptions directly.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/math.h"

namespace wedge::scene {

/// An OBJ material's `map_Kd` image: linear RGB texels (a PNG decoded from sRGB), looked up at
/// the mesh's texture coordinates with bilinear interpolation, repeating (or clamped with the
/// MTL's `-clamp on`) after the MTL's `-s` scale and `-o` offset. The MTL format multiplies it by
/// Kd. Texture coordinates (0, 0) are the image's bottom left corner.
struct TextureMap {
    std::string file;
    Image3f texels;  // row 0 at the top (v = 1)
    Vec2f scale{1.f, 1.f}, offset{0.f, 0.f};
    bool clamp = false;
    Vec3f lookup(Vec2f uv) const;
};

struct Material {
    std::string name;
    Vec3f albedo{0.8f};
    Vec3f emission{0.f};
    /// Procedural texture ("checker" or empty): scene/checker.h.
    std::string texture;
    float textureScale = 1.f;  // checker cells per world unit
    /// An OBJ material's map_Kd (or null), times `albedo`, on meshes with texture coordinates.
    std::shared_ptr<const TextureMap> map;
    bool isEmitter() const { return maxComponent(emission) > 0; }
};

struct CameraDesc {
    Vec3f position{0, 0, 1}, lookAt{0, 0, 0}, up{0, 1, 0};
    float fovY = 45.f;  // degrees, full vertical angle
    int width = 512, height = 512;
    float apertureRadius = 0.f;  // world units; 0 = pinhole
    float focusDistance = 1.f;   // along forward
    /// The shutter, in the unit of time of the objects' `velocity`: an object is where the scene
    /// puts it when the shutter opens and moves by velocity x (close - open) until it closes.
    float shutterOpen = 0.f, shutterClose = 1.f;
    float shutterLength() const { return shutterClose - shutterOpen; }
    /// The camera's own motion, in world units per unit of shutter time, as an object's: it is at
    /// `position` looking at `look_at` when the shutter opens, and both move, position by
    /// velocity and look_at by lookAtVelocity x (close - open), until it closes, with the same
    /// up, lens and focus distance. lookAtVelocity is velocity unless the scene gives it, so
    /// that a moving camera keeps its orientation; another turns it (a pan, a tilt).
    Vec3f velocity{0.f}, lookAtVelocity{0.f};
    /// Its translation over the whole shutter.
    Vec3f displacement() const { return velocity * shutterLength(); }
};

/// An area light emitting `radiance` from the side of normalize(cross(edge1, edge2)): the
/// parallelogram corner + a edge1 + b edge2 (a, b in [0, 1]), or the triangle (corner,
/// corner + edge1, corner + edge2), the parallelogram's half where a + b <= 1; or a sphere of
/// `radius` about `corner` emitting outward (edge1, edge2 unused).
struct AreaLight {
    enum class Shape : uint8_t { Parallelogram, Triangle, Sphere };

    Vec3f corner, edge1, edge2, radiance;
    Shape shape = Shape::Parallelogram;
    float radius = 0;  // a sphere's

    bool triangle() const { return shape == Shape::Triangle; }
    bool sphere() const { return shape == Shape::Sphere; }
    /// The emitting side's normal (a planar light's; a sphere's differs from point to point).
    Vec3f normal() const { return normalize(cross(edge1, edge2)); }
    float area() const {
        if (sphere()) return 4.f * kPi * radius * radius;
        return (triangle() ? 0.5f : 1.f) * length(cross(edge1, edge2));
    }
    /// The centroid.
    Vec3f center() const {
        if (sphere()) return corner;
        return corner + (edge1 + edge2) * (triangle() ? 1.f / 3.f : 0.5f);
    }
    /// Uniform on a planar light for (u, v) uniform on the unit square: a triangle folds the
    /// square's half beyond its hypotenuse (u + v > 1) onto its own, which keeps the density
    /// uniform and the square's stratification. (A sphere is sampled from the receiver, in the
    /// cone it fills: render::PathSampler.)
    Vec3f pointAt(float u, float v) const {
        if (triangle() && u + v > 1.f) {
            u = 1.f - u;
            v = 1.f - v;
        }
        return corner + edge1 * u + edge2 * v;
    }
    /// The outline, counter-clockwise seen from the emitting side: 3 or 4 vertices (a sphere: 0);
    /// returns the count.
    int vertices(Vec3f out[4]) const {
        if (sphere()) return 0;
        out[0] = corner;
        out[1] = corner + edge1;
        if (triangle()) {
            out[2] = corner + edge2;
            return 3;
        }
        out[2] = corner + edge1 + edge2;
        out[3] = corner + edge2;
        return 4;
    }
};

/// The lights the filters treat as one light: lights that lie in one plane, face the same way,
/// have the same radiance and share a corner (transitively) are one group, such as a lamp an OBJ
/// tessellates into triangles. Their samples are then uniform over the group's outline (the
/// light is chosen by power), so the filters' analysis of one planar light holds for the group.
/// Returns each light's group, the groups numbered in the order their first light appears.
std::vector<uint32_t> lightGroups(const std::vector<AreaLight>& lights);

/// At most this many lights in a scene: MAAF's sample records keep a light's index in a byte,
/// and every pixel sums the closed-form irradiance of every light.
constexpr size_t kMaxLights = 256;

/// An object's rigid motion over the shutter, t its normalised time (0 at open, 1 at close): the
/// point p0 of the object at shutter open is at pivot + displacement t + R(radians t) (p0 -
/// pivot), R the rotation about `axis` (unit) through the pivot. A translation alone has
/// radians 0 (the pivot is then unused).
struct RigidMotion {
    Vec3f displacement{0.f};  // over the whole shutter
    Vec3f pivot{0.f}, axis{0, 1, 0};
    float radians = 0;  // turned over the whole shutter
    bool turns() const { return radians != 0; }
    bool moves() const { return turns() || displacement != Vec3f(0.f); }
    /// Where the object's point p0 at shutter open is at time t.
    Vec3f at(const Vec3f& p0, float t) const {
        return turns() ? pivot + displacement * t + rotate(p0 - pivot, axis, radians * t) : p0 + displacement * t;
    }
    /// The object's point at shutter open that is at p at time t.
    Vec3f atOpen(const Vec3f& p, float t) const {
        return turns() ? pivot + rotate(p - displacement * t - pivot, axis, -radians * t) : p - displacement * t;
    }
    /// Where the point that is at p at time t is at shutter close: at(atOpen(p, t), 1), or for a
    /// translation p + displacement (1 - t) (the same to float rounding; so written, a
    /// translation's samples keep the screen motion they had before objects could turn).
    Vec3f atClose(const Vec3f& p, float t) const { return turns() ? at(atOpen(p, t), 1.f) : p + displacement * (1.f - t); }
    /// A direction of the object at shutter open (a normal) as it is turned at time t.
    Vec3f turn(const Vec3f& v, float t) const { return turns() ? rotate(v, axis, radians * t) : v; }
};

/// Triangles in world space at shutter open; `velocity` (world units per unit of shutter time)
/// moves the whole mesh by velocity x CameraDesc::shutterLength() over the shutter, and
/// `turnDegrees` (degrees per unit of shutter time) turns it about `turnAxis` through `pivot`.
struct TriangleMesh {
    std::string name;
    std::vector<Vec3f> positions;
    std::vector<uint32_t> indices;      // 3 per triangle
    std::vector<uint32_t> materialIds;  // 1 per triangle
    std::vector<uint32_t> shapeIds;     // 1 per triangle: the OBJ group / shape (surfaces the filters keep apart)
    /// Shading normals, 3 per triangle (one per corner, unit length), or empty for flat shading
    /// (quads, boxes). OBJ meshes always have them: the file's `vn`, else smoothed face normals.
    std::vector<Vec3f> cornerNormals;
    /// Texture coordinates, 3 per triangle (an OBJ's `vt`; (0, 0) at corners without one), or
    /// empty.
    std::vector<Vec2f> cornerUVs;
    Vec3f velocity{0.f};
    Vec3f turnAxis{0, 1, 0}, pivot{0.f};  // turnAxis: unit length
    float turnDegrees = 0;
    size_t triangleCount() const { return indices.size() / 3; }
    bool moves() const { return velocity != Vec3f(0.f) || turnDegrees != 0; }
    /// Its motion over a shutter of the given length.
    RigidMotion motion(float shutterLength) const {
        return {velocity * shutterLength, pivot, turnAxis, turnDegrees * shutterLength * (kPi / 180.f)};
    }
};

struct Sphere {
    Vec3f center;
    float radius = 1.f;
    uint32_t material = 0;
    Vec3f velocity{0.f};
};

struct RenderSettings {
    int spp = 16;
    uint32_t seed = 0;
    bool indirect = true;
};

struct SceneDesc {
    std::string file;  // the scene file, for messages
    CameraDesc camera;
    std::vector<Material> materials;
    std::vector<AreaLight> lights;
    std::vector<TriangleMesh> meshes;
    std::vector<Sphere> spheres;
    RenderSettings render;
    std::vector<std::string> warnings;  // what was read but is not rendered (the CLI prints them)

    size_t triangleCount() const {
        size_t n = 0;
        for (auto& m : meshes) n += m.triangleCount();
        return n;
    }
    /// Whether anything moves over the shutter: an object or the camera.
    bool hasMotion() const;
};

/// Appends the two triangles of a parallelogram (corner, corner+e1, corner+e1+e2, corner+e2),
/// wound so that their normal is cross(e1, e2).
void appendQuad(TriangleMesh& mesh, const Vec3f& corner, const Vec3f& e1, const Vec3f& e2, uint32_t material);
/// Fills the corner normals of `mesh` that are zero with the area-weighted mean of the face
/// normals around that corner's vertex, taking only faces within `creaseDegrees` of the
/// corner's own face, so that a scanned surface shades smoothly and a box keeps its edges.
/// Allocates cornerNormals (zeros) first if it is empty.
void smoothCornerNormals(TriangleMesh& mesh, float creaseDegrees);
/// Appends the triangle (corner, corner+e1, corner+e2), wound so that its normal is cross(e1, e2).
void appendTriangle(TriangleMesh& mesh, const Vec3f& corner, const Vec3f& e1, const Vec3f& e2, uint32_t material);
/// The six faces of an axis-aligned box as (corner, e1, e2), cross(e1, e2) pointing outward.
std::array<std::array<Vec3f, 3>, 6> boxFaces(const Vec3f& lo, const Vec3f& hi);
/// Appends the 12 outward-facing triangles of an axis-aligned box.
void appendBox(TriangleMesh& mesh, const Vec3f& lo, const Vec3f& hi, uint32_t material);

}  // namespace wedge::scene
