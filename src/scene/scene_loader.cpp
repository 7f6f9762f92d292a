#include "scene/scene_loader.h"

#include <tbb/parallel_invoke.h>
#include <tiny_obj_loader.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <map>
#include <optional>
#include <unordered_map>

#include "core/error.h"
#include "core/image.h"
#include "io/image_io.h"
#include "io/json_reader.h"
#include "io/text_file.h"
#include "scene/obj_check.h"

#ifndef WEDGE_SCENES_DIR
#define WEDGE_SCENES_DIR "scenes"
#endif

namespace fs = std::filesystem;

namespace wedge::scene {

using io::JsonNode;

namespace {

constexpr float kDegToRad = kPi / 180.f;
/// Crease angle for smoothing the normals of OBJ meshes without `vn`: a box's 90-degree edges
/// stay sharp, a scan's facets blend.
constexpr float kCreaseDegrees = 60.f;

Vec3f readScale(JsonNode node) {
    if (node.isArray()) {
        Vec3f s = node.vec3();
        if (s.x <= 0 || s.y <= 0 || s.z <= 0) node.fail("expected positive scale factors");
        return s;
    }
    return Vec3f(node.positive());
}

/// "a, b, c and 2 more": the first few items for a warning.
std::string fewOf(const std::vector<std::string>& items) {
    std::string s;
    for (size_t i = 0; i < items.size() && i < 3; ++i) s += (i ? ", " : "") + items[i];
    if (items.size() > 3) s += " and " + std::to_string(items.size() - 3) + " more";
    return s;
}


/// Accepts a 4-vertex face as a parallelogram light if v2 = v0 + e1 + e2 up to rounding.
bool asParallelogram(const Vec3f v[4], AreaLight& light) {
    Vec3f e1 = v[1] - v[0], e2 = v[3] - v[0];
    float scale = std::max(length(e1), length(e2));
    if (scale <= 0 || length(cross(e1, e2)) <= 1e-8f * scale * scale) return false;
    if (length(v[0] + e1 + e2 - v[2]) > 1e-3f * scale) return false;
    light.corner = v[0];
    light.edge1 = e1;
    light.edge2 = e2;
    return true;
}

struct Transform {
    Vec3f scale{1.f}, translate{0.f}, axis{0, 1, 0};
    float radians = 0;
    Vec3f apply(const Vec3f& p) const {
        Vec3f q = p * scale;
        if (radians != 0) q = rotate(q, axis, radians);
        return q + translate;
    }
    /// Normals transform by the inverse transpose: 1/scale, then the rotation.
    Vec3f applyNormal(const Vec3f& n) const {
        Vec3f q = n / scale;
        if (radians != 0) q = rotate(q, axis, radians);
        return normalize(q);
    }
};

/// The largest scene coordinate (checkExtent) and shutter time wedge accepts.
constexpr float kMaxCoordinate = 1e15f, kMaxShutterTime = 1e6f;
/// The largest radiance component of a light or an emissive material. Sample values are summed
/// and squared in single precision (a pixel's luminance variance, which à-trous's edge-stopping
/// and the mixed pixels' top-ups read), and a single sample near a light can be a thousand times
/// its radiance: at 1e20 à-trous's image was NaN everywhere (MC, AAF and MAAF still finite).
constexpr float kMaxRadiance = 1e15f;
/// The most a turning object turns over the shutter, in degrees (ten turns).
constexpr double kMaxTurnDegrees = 3600;

class SceneParser {
public:
    SceneParser(std::string file, std::string baseDir) : m_file(std::move(file)), m_baseDir(std::move(baseDir)) {}

    SceneDesc parse(const nlohmann::json& doc) {
        JsonNode root(doc, m_file, "");
        if (!root.isObject()) root.fail("expected a JSON object at the top level");
        m_desc.file = m_file;
        if (auto v = root.optional("version"))
            if (v->integer() != 1) v->fail("unsupported scene version (expected 1)");
        parseCamera(root["camera"]);
        if (auto mats = root.optional("materials")) parseMaterials(*mats);
        if (auto lights = root.optional("lights")) parseLights(*lights);
        parseObjects(root["objects"]);
        if (auto r = root.optional("render")) parseRender(*r);
        root.finish();
        if (m_desc.lights.empty())
            throw Error(m_file + ": lights", "the scene has no light (add a parallelogram, triangle or sphere light, or an emissive surface)");
        if (m_desc.meshes.empty() && m_desc.spheres.empty()) throw Error(m_file + ": objects", "the scene has no geometry");
        return std::move(m_desc);
    }

private:
    void parseCamera(JsonNode c) {
        CameraDesc& cam = m_desc.camera;
        cam.position = c["position"].vec3();
        cam.lookAt = c["look_at"].vec3();
        checkExtent(c["position"], {cam.position});
        checkExtent(c["look_at"], {cam.lookAt});
        cam.up = c["up"].vec3();
        Vec3f forward = cam.lookAt - cam.position;
        if (length(forward) <= 0) c["look_at"].fail("must differ from camera.position");
        if (length(cross(normalize(forward), cam.up)) < 1e-6f) c["up"].fail("must not be parallel to the view direction");
        JsonNode fov = c["fov_y"];
        cam.fovY = fov.positive();
        if (cam.fovY >= 180.f) fov.fail("expected an angle in degrees below 180");
        JsonNode res = c["resolution"];
        if (res.size() != 2) res.fail("expected [width, height]");
        for (int i = 0; i < 2; ++i) {
            JsonNode r = res[size_t(i)];
            int v = r.integer();
            if (v <= 0) r.fail("expected a positive resolution");
            if (v > kMaxImageSide) r.fail("resolution above " + std::to_string(kMaxImageSide) + " is not supported");
            (i == 0 ? cam.width : cam.height) = v;
        }
        if (auto a = c.optional("aperture_radius")) cam.apertureRadius = a->nonNegative();
        cam.focusDistance = length(forward);
        if (auto f = c.optional("focus_distance")) cam.focusDistance = f->positive();
        if (auto s = c.optional("shutter")) {
            if (s->size() != 2) s->fail("expected [open, close]");
            cam.shutterOpen = (*s)[0].number();
            cam.shutterClose = (*s)[1].number();
            if (!(cam.shutterClose > cam.shutterOpen)) s->fail("expected close > open");
            if (std::max(std::abs(cam.shutterOpen), std::abs(cam.shutterClose)) > kMaxShutterTime)
                s->fail("expected times within +-1e6");
        }
        if (auto v = c.optional("velocity")) {  // (after the shutter, whose length it is scaled by)
            cam.velocity = v->vec3();
            checkExtent(*v, {cam.position}, cam.velocity);
        }
        const std::optional<JsonNode> lookAtVelocity = c.optional("look_at_velocity");
        // Unless given, look_at moves with the camera, which keeps its orientation.
        cam.lookAtVelocity = lookAtVelocity ? lookAtVelocity->vec3() : cam.velocity;
        {
            const JsonNode where = lookAtVelocity ? *lookAtVelocity : c["look_at"];
            checkExtent(where, {cam.lookAt}, cam.lookAtVelocity);
            // The view direction a + b t over the shutter (t in [0, 1]) must not vanish or turn
            // parallel to up: its part across up, a linear function of t, is nearest zero at t*.
            const Vec3f up = normalize(cam.up), a = forward, b = (cam.lookAtVelocity - cam.velocity) * cam.shutterLength();
            const Vec3f aAcross = a - up * dot(a, up), bAcross = b - up * dot(b, up);
            const float bb = dot(bAcross, bAcross);
            const float t = bb > 0 ? std::clamp(-dot(aAcross, bAcross) / bb, 0.f, 1.f) : 0.f;
            if (!(length(aAcross + bAcross * t) >= 1e-6f * (length(a) + length(b))))
                where.fail("the view direction (look_at - position) turns " +
                           std::string(length(a + b * t) > 0 ? "parallel to camera.up" : "to nothing") + " during the shutter");
        }
        c.finish();
    }

    void parseMaterials(JsonNode mats) {
        if (!mats.isObject()) mats.fail("expected an object mapping names to materials");
        for (const std::string& name : mats.keys()) {
            JsonNode m = mats[name];
            Material mat;
            mat.name = name;
            mat.albedo = m["albedo"].color();
            if (maxComponent(mat.albedo) > 1.f) m["albedo"].fail("albedo components must lie in [0, 1]");
            if (auto e = m.optional("emission")) mat.emission = radiance(*e);
            if (auto t = m.optional("texture")) {
                mat.texture = t->string();
                if (mat.texture != "checker") t->fail("unknown texture '" + mat.texture + "' (expected \"checker\")");
            }
            if (auto ts = m.optional("texture_scale")) mat.textureScale = ts->positive();
            m.finish();
            m_materialIndex[name] = uint32_t(m_desc.materials.size());
            m_desc.materials.push_back(mat);
        }
    }

    void parseLights(JsonNode lights) {
        for (size_t i = 0; i < lights.size(); ++i) {
            JsonNode l = lights[i];
            std::string type = l["type"].string();
            AreaLight light;
            if (type == "triangle") light.shape = AreaLight::Shape::Triangle;
            else if (type == "sphere") light.shape = AreaLight::Shape::Sphere;
            else if (type != "parallelogram")
                l["type"].fail("unknown light type '" + type + "' (expected \"parallelogram\", \"triangle\" or \"sphere\")");
            if (light.sphere()) {
                light.corner = l["center"].vec3();
                light.radius = l["radius"].positive();
                light.radiance = radiance(l["radiance"]);
                checkExtent(l, {light.corner - Vec3f(light.radius), light.corner + Vec3f(light.radius)});
            } else {
                light.corner = l["corner"].vec3();
                light.edge1 = l["edge1"].vec3();
                light.edge2 = l["edge2"].vec3();
                light.radiance = radiance(l["radiance"]);
                if (light.area() <= 0) l["edge2"].fail("edge1 and edge2 span no area");
                Vec3f corners[4];
                checkExtent(l, std::vector<Vec3f>(corners, corners + light.vertices(corners)));
            }
            if (m_desc.lights.size() == kMaxLights)
                l.fail("more than " + std::to_string(kMaxLights) + " lights (MAAF keeps a light's index in a byte)");
            l.finish();
            m_desc.lights.push_back(light);
            // The light is visible to the camera as an emitter of its own (albedo 0).
            Material mat;
            mat.name = "light" + std::to_string(i);
            mat.albedo = Vec3f(0.f);
            mat.emission = light.radiance;
            uint32_t id = uint32_t(m_desc.materials.size());
            m_desc.materials.push_back(mat);
            if (light.sphere()) {
                m_desc.spheres.push_back({light.corner, light.radius, id, Vec3f(0.f)});
                continue;
            }
            TriangleMesh mesh;
            mesh.name = mat.name;
            if (light.triangle()) appendTriangle(mesh, light.corner, light.edge1, light.edge2, id);
            else appendQuad(mesh, light.corner, light.edge1, light.edge2, id);
            m_desc.meshes.push_back(std::move(mesh));
        }
    }

    uint32_t material(JsonNode node) {
        std::string name = node.string();
        auto it = m_materialIndex.find(name);
        if (it == m_materialIndex.end()) node.fail("unknown material '" + name + "'");
        return it->second;
    }

    void parseObjects(JsonNode objects) {
        if (objects.size() == 0) objects.fail("expected at least one object");
        for (size_t i = 0; i < objects.size(); ++i) {
            JsonNode o = objects[i];
            std::string type = o["type"].string();
            TriangleMesh mesh;
            mesh.name = type + "[" + std::to_string(i) + "]";
            if (auto v = o.optional("velocity")) mesh.velocity = v->vec3();
            // A turn over the shutter: [axis_x, axis_y, axis_z, degrees per unit of shutter time],
            // about `pivot` (by default the centre of the object's box at shutter open).
            const std::optional<JsonNode> turn = o.optional("angular_velocity");
            if (turn) {
                if (turn->size() != 4) turn->fail("expected [axis_x, axis_y, axis_z, degrees per unit of shutter time]");
                const Vec3f axis((*turn)[0].number(), (*turn)[1].number(), (*turn)[2].number());
                if (!(length(axis) > 0)) turn->fail("the axis must be non-zero");
                mesh.turnAxis = normalize(axis);
                mesh.turnDegrees = (*turn)[3].number();
                if (type == "sphere") turn->fail("a sphere does not turn (meshes, quads and boxes do)");
                // Embree takes at most 129 time steps, a quarter turn apart here (Scene::Scene),
                // and the layers follow a sample's chord: ten turns a shutter is already a blur.
                const double turned = std::abs(double(mesh.turnDegrees) * m_desc.camera.shutterLength());
                if (!(turned <= kMaxTurnDegrees))
                    turn->fail("turns " + std::to_string(int64_t(std::min(turned, 1e18))) + " degrees over the shutter; wedge takes at most " +
                               std::to_string(int(kMaxTurnDegrees)));
            }
            const std::optional<JsonNode> pivot = o.optional("pivot");
            if (pivot && !turn) pivot->fail("a pivot needs an angular_velocity to turn about it");
            if (type == "mesh") {
                parseMesh(o, mesh);
            } else if (type == "quad") {
                Vec3f corner = o["corner"].vec3(), e1 = o["edge1"].vec3(), e2 = o["edge2"].vec3();
                if (length(cross(e1, e2)) <= 0) o["edge2"].fail("edge1 and edge2 span no area");
                uint32_t mat = material(o["material"]);
                appendQuad(mesh, corner, e1, e2, mat);
                promoteIfEmissive(o, mat, {{corner, e1, e2, m_desc.materials[mat].emission}}, mesh.moves(), "this quad");
            } else if (type == "box") {
                Vec3f lo = o["min"].vec3(), hi = o["max"].vec3();
                if (!(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z)) o["max"].fail("expected max > min in every axis");
                const uint32_t mat = material(o["material"]);
                appendBox(mesh, lo, hi, mat);
                std::vector<AreaLight> faces;
                for (const auto& f : boxFaces(lo, hi)) faces.push_back({f[0], f[1], f[2], m_desc.materials[mat].emission});
                promoteIfEmissive(o, mat, faces, mesh.moves(), "this box");
            } else if (type == "sphere") {
                Sphere s;
                s.center = o["center"].vec3();
                s.radius = o["radius"].positive();
                s.material = material(o["material"]);
                s.velocity = mesh.velocity;
                checkExtent(o, {s.center - Vec3f(s.radius), s.center + Vec3f(s.radius)}, s.velocity);
                AreaLight light;
                light.shape = AreaLight::Shape::Sphere;
                light.corner = s.center;
                light.radius = s.radius;
                light.radiance = m_desc.materials[s.material].emission;
                promoteIfEmissive(o, s.material, {light}, s.velocity != Vec3f(0.f), "this sphere");
                o.finish();
                m_desc.spheres.push_back(s);
                continue;
            } else {
                o["type"].fail("unknown object type '" + type + "' (expected mesh, quad, box or sphere)");
            }
            checkExtent(o, mesh.positions, mesh.velocity);
            if (turn) {
                if (pivot) {
                    mesh.pivot = pivot->vec3();
                } else {
                    Vec3f lo(kInf), hi(-kInf);
                    for (const Vec3f& p : mesh.positions) lo = vmin(lo, p), hi = vmax(hi, p);
                    mesh.pivot = (lo + hi) * 0.5f;
                }
                // Every point stays within its distance to the pivot, which moves by velocity.
                float r = 0;
                for (const Vec3f& p : mesh.positions) r = std::max(r, length(p - mesh.pivot));
                checkExtent(pivot ? *pivot : *turn, {mesh.pivot - Vec3f(r), mesh.pivot + Vec3f(r)}, mesh.velocity);
            }
            o.finish();
            m_desc.meshes.push_back(std::move(mesh));
        }
    }

    void parseMesh(JsonNode& o, TriangleMesh& mesh) {
        JsonNode fileNode = o["file"];
        std::string rel = fileNode.string();
        fs::path p = fs::path(rel).is_absolute() ? fs::path(rel) : fs::path(m_baseDir) / rel;
        int overrideMaterial = -1;
        if (auto m = o.optional("material")) overrideMaterial = int(material(*m));
        Transform xf;
        if (auto s = o.optional("scale")) xf.scale = readScale(*s);
        if (auto t = o.optional("translate")) xf.translate = t->vec3();
        if (auto r = o.optional("rotate")) {
            if (r->size() != 4) r->fail("expected [axis_x, axis_y, axis_z, degrees]");
            Vec3f axis((*r)[0].number(), (*r)[1].number(), (*r)[2].number());
            if (length(axis) <= 0) r->fail("rotation axis must be non-zero");
            xf.axis = normalize(axis);
            xf.radians = (*r)[3].number() * kDegToRad;
        }
        std::vector<AreaLight> promoted;
        loadObj(p.string(), fileNode.where(), overrideMaterial, m_desc.materials, mesh, promoted, m_desc.warnings);
        for (auto& v : mesh.positions) v = xf.apply(v);
        for (auto& n : mesh.cornerNormals) n = xf.applyNormal(n);
        for (auto& l : promoted) {
            Vec3f c0 = xf.apply(l.corner);
            l.edge1 = xf.apply(l.corner + l.edge1) - c0;
            l.edge2 = xf.apply(l.corner + l.edge2) - c0;
            l.corner = c0;
        }
        addLights(o, promoted, mesh.moves(), "'" + fileNode.string() + "'");
    }

    /// Light comes from the scene's lights and from the emitters that do not move: quads, boxes'
    /// faces and OBJ faces become lights. Spheres are seen (their emission is in the image where
    /// the camera sees them) but light nothing. Say so.

    /// Adds an object's emissive faces (those of `owner`) as lights: all of them, or none where
    /// the object moves or they would take the scene past kMaxLights.
    void addLights(const JsonNode& o, const std::vector<AreaLight>& faces, bool moving, const std::string& owner) {
        if (faces.empty()) return;
        std::string why;
        if (moving) why = "moving emitters are not lights";
        else if (m_desc.lights.size() + faces.size() > kMaxLights)
            why = "the scene has " + std::to_string(m_desc.lights.size()) + " lights before them and takes " +
                  std::to_string(kMaxLights) + " at most";
        if (why.empty()) m_desc.lights.insert(m_desc.lights.end(), faces.begin(), faces.end());
        else
            m_desc.warnings.push_back(o.where() + ": the " + std::to_string(faces.size()) + " emissive face(s) of " + owner +
                                      " are only seen and light nothing: " + why);
    }

    /// `faces` of material `mat` as lights, if it emits.
    void promoteIfEmissive(const JsonNode& o, uint32_t mat, const std::vector<AreaLight>& faces, bool moving,
                           const std::string& owner) {
        if (m_desc.materials[mat].isEmitter()) addLights(o, faces, moving, owner);
    }

    /// A colour of emitted radiance: non-negative, at most kMaxRadiance.
    static Vec3f radiance(const JsonNode& node) {
        const Vec3f v = node.color();
        if (maxComponent(v) > kMaxRadiance) {
            char c[96];
            std::snprintf(c, sizeof c, "(%g, %g, %g)", v.x, v.y, v.z);
            node.fail(std::string("radiance ") + c + " above 1e15, the most wedge renders");
        }
        return v;
    }

    /// Every point, at the shutter's open and close (moved by velocity x (close - open)), within
    /// +-kMaxCoordinate. Beyond about 1.8e18
    /// Embree rejects a ray's origin and direction (an assertion that aborts the process, as a
    /// sphere of radius 1e20 did), and squared distances overflow float near 1.8e19.
    void checkExtent(const JsonNode& node, const std::vector<Vec3f>& points, const Vec3f& velocity = Vec3f(0.f)) const {
        const CameraDesc& cam = m_desc.camera;
        for (const Vec3f& p : points)
            for (float t : {0.f, cam.shutterLength()}) {
                const Vec3f q = p + velocity * t;
                if (!(std::max({std::abs(q.x), std::abs(q.y), std::abs(q.z)}) <= kMaxCoordinate)) {
                    char v[96];
                    std::snprintf(v, sizeof v, "(%g, %g, %g)", q.x, q.y, q.z);
                    node.fail(std::string("reaches ") + v + (velocity == Vec3f(0.f) ? "" : " over the shutter") +
                              "; wedge renders coordinates within +-1e15");
                }
            }
    }

    void parseRender(JsonNode r) {
        if (auto s = r.optional("spp")) {
            int spp = s->integer();
            if (spp <= 0) s->fail("expected a positive number of samples");
            m_desc.render.spp = spp;
        }
        if (auto s = r.optional("seed")) {
            long long v = s->integer();
            if (v < 0) s->fail("expected a non-negative seed");
            m_desc.render.seed = uint32_t(v);
        }
        if (auto s = r.optional("indirect")) m_desc.render.indirect = s->boolean();
        r.finish();
    }

    std::string m_file, m_baseDir;
    SceneDesc m_desc;
    std::map<std::string, uint32_t> m_materialIndex;
};

/// tinyobjloader's parse of `path`, with the text checks of obj_check.h run beside it: a
/// malformed number reads as 0 and a grey MTL colour as red in tinyobjloader, so the check's
/// error, if any, is the one reported (whichever finished first; on sponza the check takes
/// 0.12 s, the parse about 0.6 s). `mtlColours`: the MTL materials' grey colours, in order.
void parseObjChecked(const std::string& path, const std::string& where, tinyobj::ObjReader& reader,
                     std::vector<MtlColours>& mtlColours, std::vector<std::string>& warnings) {
    tinyobj::ObjReaderConfig config;
    config.triangulate = false;  // keep quads, so that emissive parallelograms can become lights
    config.vertex_color = false;
    config.mtl_search_path = fs::path(path).parent_path().string();
    std::exception_ptr checkError;
    std::string objWarning;
    bool parsed = false;
    tbb::parallel_invoke(
        [&] {
            try {
                const std::string objText = io::readTextFile(path);
                if (std::string w = checkObjText(objText, where, path); !w.empty()) objWarning = where + ": " + w;
                for (const std::string& mtl : mtlFilesOf(objText, config.mtl_search_path)) {
                    std::vector<MtlColours> c = checkMtlText(io::readTextFile(mtl), where, mtl);
                    mtlColours.insert(mtlColours.end(), c.begin(), c.end());
                }
            } catch (...) {
                checkError = std::current_exception();
            }
        },
        [&] { parsed = reader.ParseFromFile(path, config); });
    if (checkError) std::rethrow_exception(checkError);
    if (!objWarning.empty()) warnings.push_back(objWarning);
    if (!parsed) throw Error(where, "cannot read OBJ '" + path + "': " + reader.Error());
}

/// The material's map_Kd as a TextureMap (PNG and JPEG files; the OBJ's directory is the search
/// path), or null with the reason appended to `notRendered` ("'wood' (map_Kd 'wood.tga': wedge
/// reads PNG and JPEG textures)").
/// Maps shared by several materials are read once (`cache`).
std::shared_ptr<const TextureMap> diffuseMap(const std::string& objPath, const std::string& where, const tinyobj::material_t& m,
                                             std::map<std::string, std::shared_ptr<const TextureMap>>& cache,
                                             std::vector<std::string>& notRendered) {
    std::string name = m.diffuse_texname;
    std::replace(name.begin(), name.end(), '\\', '/');  // exported on Windows
    const fs::path file = fs::path(objPath).parent_path() / name;
    std::string ext = file.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    const bool jpeg = ext == ".jpg" || ext == ".jpeg";
    if (ext != ".png" && !jpeg) {
        notRendered.push_back("'" + m.name + "' (map_Kd '" + name + "': wedge reads PNG and JPEG textures)");
        return nullptr;
    }
    if (const std::string why = io::notARegularFile(file.string()); !why.empty()) {
        notRendered.push_back("'" + m.name + "' (map_Kd '" + file.string() +
                              (why == "no such file" ? "' does not exist)" : "': " + why + ")"));
        return nullptr;
    }
    const tinyobj::texture_option_t& o = m.diffuse_texopt;
    const std::string key = file.string() + (o.clamp ? "|clamp" : "") + "|" + std::to_string(o.scale[0]) + "," +
                            std::to_string(o.scale[1]) + "|" + std::to_string(o.origin_offset[0]) + "," + std::to_string(o.origin_offset[1]);
    if (auto it = cache.find(key); it != cache.end()) return it->second;
    auto map = std::make_shared<TextureMap>();
    map->file = file.string();
    try {
        map->texels = jpeg ? io::readJpeg(map->file) : io::readPng(map->file);  // sRGB decoded to linear
    } catch (const Error& e) {
        throw Error(where, "'" + objPath + "': material '" + m.name + "': map_Kd: " + e.what());
    }
    map->scale = {o.scale[0], o.scale[1]};
    map->offset = {o.origin_offset[0], o.origin_offset[1]};
    map->clamp = o.clamp;
    if (!(std::isfinite(map->scale.x) && std::isfinite(map->scale.y) && std::isfinite(map->offset.x) && std::isfinite(map->offset.y)))
        throw Error(where, "'" + objPath + "': material '" + m.name + "': map_Kd's -s and -o must be finite");
    cache[key] = map;
    return map;
}

/// Appends the MTL's materials to the scene's list (named "file.obj:name"); returns the scene
/// index of each. What wedge does not render (specular terms, transparency, texture maps other
/// than a PNG or JPEG map_Kd) is named in one warning per file.
std::vector<uint32_t> appendMtlMaterials(const std::string& path, const std::string& where, const tinyobj::ObjReader& reader,
                                         const std::vector<MtlColours>& mtlColours, std::vector<Material>& materials,
                                         std::vector<std::string>& warnings) {
    std::vector<uint32_t> mtlToScene;
    const std::string prefix = fs::path(path).filename().string() + ":";
    std::vector<std::string> specular, textured, maps, transparent;
    std::map<std::string, std::shared_ptr<const TextureMap>> cache;
    const auto& mtlMaterials = reader.GetMaterials();
    for (size_t mi = 0; mi < mtlMaterials.size(); ++mi) {
        const tinyobj::material_t& m = mtlMaterials[mi];
        if (std::max({m.specular[0], m.specular[1], m.specular[2]}) > 0) specular.push_back(m.name);
        if (!m.bump_texname.empty() || !m.alpha_texname.empty() || !m.normal_texname.empty()) textured.push_back(m.name);
        if (m.dissolve < 1.f) transparent.push_back(m.name);  // d < 1, or Tr > 0
        Material mat;
        mat.name = prefix + m.name;
        mat.albedo = Vec3f(m.diffuse[0], m.diffuse[1], m.diffuse[2]);
        mat.emission = Vec3f(m.emission[0], m.emission[1], m.emission[2]);
        // "Kd 0.5" is grey in the MTL format; tinyobjloader reads it as (0.5, 0, 0).
        if (mtlColours.size() == mtlMaterials.size() && mtlColours[mi].name == m.name) {
            if (mtlColours[mi].greyKd) mat.albedo = Vec3f(mat.albedo.x);
            if (mtlColours[mi].greyKe) mat.emission = Vec3f(mat.emission.x);
            const std::string& statement = mtlColours[mi].mapKd;  // options, then the file name
            const std::string& file = m.diffuse_texname;
            const bool endsWithFile = !file.empty() && statement.size() >= file.size() &&
                                      statement.compare(statement.size() - file.size(), file.size(), file) == 0;
            if (!statement.empty() && !endsWithFile)
                throw Error(where, "'" + path + "': material '" + m.name + "': tinyobjloader reads 'map_Kd " + statement +
                                       "' as the file '" + file +
                                       "' (its -s, -o and -t options take three numbers each: write -s 4 4 1)");
        }
        // The MTL's colours obey the scene file's rules for "albedo" and "emission": a negative
        // or non-finite albedo would make negative or NaN light, and an albedo above 1 creates
        // energy (the scene file refuses both).
        auto bad = [&](const char* key, const Vec3f& c, const char* rule) {
            char v[96];
            std::snprintf(v, sizeof v, "%g %g %g", c.x, c.y, c.z);
            throw Error(where, "'" + path + "': material '" + m.name + "' (its MTL): " + key + " " + rule + ", got " + v);
        };
        if (!isFinite(mat.albedo) || std::min({mat.albedo.x, mat.albedo.y, mat.albedo.z}) < 0 || maxComponent(mat.albedo) > 1.f)
            bad("Kd", mat.albedo, "components must lie in [0, 1]");
        if (!isFinite(mat.emission) || std::min({mat.emission.x, mat.emission.y, mat.emission.z}) < 0 ||
            maxComponent(mat.emission) > kMaxRadiance)
            bad("Ke", mat.emission, "components must lie in [0, 1e15]");
        if (!m.diffuse_texname.empty()) mat.map = diffuseMap(path, where, m, cache, maps);
        mtlToScene.push_back(uint32_t(materials.size()));
        materials.push_back(mat);
    }
    // Valid input that wedge does not render: say so once per file, naming a few materials.
    std::string unused;
    if (!specular.empty()) unused += "the specular terms (Ks) of " + nameList(specular);
    if (!textured.empty())
        unused += std::string(unused.empty() ? "" : "; ") + "the bump, alpha and normal maps of " + nameList(textured);
    if (!transparent.empty())
        unused += std::string(unused.empty() ? "" : "; ") + "the transparency (d < 1) of " + nameList(transparent);
    if (!maps.empty())  // already quoted, with the reason
        unused += std::string(unused.empty() ? "" : "; ") + "the diffuse maps of " + fewOf(maps);
    if (!unused.empty())
        warnings.push_back(where + ": '" + path + "': " + unused +
                            " are not rendered (surfaces are Lambertian with the MTL's Kd and PNG or JPEG map_Kd)");
    return mtlToScene;
}

}  // namespace

void loadObj(const std::string& path, const std::string& where, int overrideMaterial, std::vector<Material>& materials,
             TriangleMesh& mesh, std::vector<AreaLight>& promoted, std::vector<std::string>& warnings) {
    if (const std::string why = io::notARegularFile(path); !why.empty())
        throw Error(where, "mesh file '" + path + (why == "no such file" ? "' does not exist" : "': " + why));
    tinyobj::ObjReader reader;
    std::vector<MtlColours> mtlColours;
    parseObjChecked(path, where, reader, mtlColours, warnings);
    const auto& attrib = reader.GetAttrib();
    const auto& shapes = reader.GetShapes();
    size_t faceCount = 0;
    for (auto& s : shapes) faceCount += s.mesh.num_face_vertices.size();
    if (attrib.vertices.empty() || faceCount == 0)
        throw Error(where, "'" + path + "' contains no faces (is it a Wavefront OBJ file?)");

    // Materials from the MTL, appended to the scene's list unless overridden.
    const std::vector<uint32_t> mtlToScene =
        overrideMaterial < 0 ? appendMtlMaterials(path, where, reader, mtlColours, materials, warnings) : std::vector<uint32_t>{};

    size_t vertexCount = attrib.vertices.size() / 3, normalCount = attrib.normals.size() / 3;
    mesh.positions.reserve(mesh.positions.size() + vertexCount);
    uint32_t base = uint32_t(mesh.positions.size());
    for (size_t i = 0; i < vertexCount; ++i)
        mesh.positions.emplace_back(attrib.vertices[3 * i], attrib.vertices[3 * i + 1], attrib.vertices[3 * i + 2]);
    for (auto& v : mesh.positions)
        if (!isFinite(v)) throw Error(where, "'" + path + "' has a non-finite vertex coordinate");

    struct EmissiveTriangle {
        uint32_t v[3];
        uint32_t material;
    };
    std::vector<EmissiveTriangle> emissiveTriangles;  // to be paired into parallelograms below
    std::vector<uint32_t> idx;  // one face's vertices, normals and texture coordinates, reused
    std::vector<Vec3f> vn;      // the file's normals; zero: to be smoothed
    std::vector<Vec2f> vt;      // the file's texture coordinates; (0, 0) where a corner has none
    const size_t texcoordCount = attrib.texcoords.size() / 2;
    const bool uvs = texcoordCount > 0;
    if (uvs) mesh.cornerUVs.resize(mesh.indices.size());
    for (size_t shapeIndex = 0; shapeIndex < shapes.size(); ++shapeIndex) {
        const auto& shape = shapes[shapeIndex];
        size_t offset = 0;
        for (size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f) {
            int n = shape.mesh.num_face_vertices[f];
            int mtl = shape.mesh.material_ids.empty() ? -1 : shape.mesh.material_ids[f];
            uint32_t matId;
            if (overrideMaterial >= 0) {
                matId = uint32_t(overrideMaterial);
            } else if (mtl >= 0 && size_t(mtl) < mtlToScene.size()) {
                matId = mtlToScene[mtl];
            } else {
                // tinyobjloader's warnings say why: an MTL not found, a `usemtl` it does not define.
                std::string why = reader.Warning();
                while (!why.empty() && (why.back() == '\n' || why.back() == ' ')) why.pop_back();
                for (char& c : why)
                    if (c == '\n') c = ';';
                throw Error(where, "'" + path + "': shape '" + shape.name + "' has faces without a material" +
                                       (why.empty() ? std::string() : " (tinyobjloader: " + why + ")") +
                                       "; give the object a \"material\"");
            }
            idx.assign(n, 0);
            vn.assign(n, Vec3f(0.f));
            vt.assign(n, Vec2f{});
            for (int k = 0; k < n; ++k) {
                int vi = shape.mesh.indices[offset + k].vertex_index;
                if (vi < 0 || size_t(vi) >= vertexCount)
                    throw Error(where, "'" + path + "': face refers to a missing vertex");
                idx[k] = base + uint32_t(vi);
                int ni = shape.mesh.indices[offset + k].normal_index;
                if (ni >= 0) {
                    if (size_t(ni) >= normalCount)
                        throw Error(where, "'" + path + "': face refers to a missing normal (vn " + std::to_string(ni + 1) + ")");
                    Vec3f nrm(attrib.normals[3 * ni], attrib.normals[3 * ni + 1], attrib.normals[3 * ni + 2]);
                    if (!isFinite(nrm)) throw Error(where, "'" + path + "' has a non-finite normal (vn " + std::to_string(ni + 1) + ")");
                    if (length(nrm) > 0) vn[k] = normalize(nrm);  // a zero vn is smoothed like a missing one
                }
                const int ti = shape.mesh.indices[offset + k].texcoord_index;
                if (ti >= 0 && size_t(ti) < texcoordCount) vt[k] = {attrib.texcoords[2 * ti], attrib.texcoords[2 * ti + 1]};
            }
            offset += n;
            if (n < 3) continue;
            if (materials[matId].isEmitter()) {
                Vec3f v[4];
                AreaLight light;
                if (n == 4) for (int k = 0; k < 4; ++k) v[k] = mesh.positions[idx[k]];
                if (n == 4 && asParallelogram(v, light)) {
                    light.radiance = materials[matId].emission;
                    promoted.push_back(light);
                } else {
                    for (int k = 1; k + 1 < n; ++k) emissiveTriangles.push_back({{idx[0], idx[k], idx[k + 1]}, matId});
                }
            }
            for (int k = 1; k + 1 < n; ++k) {  // fan triangulation (OBJ faces are convex)
                mesh.indices.insert(mesh.indices.end(), {idx[0], idx[k], idx[k + 1]});
                mesh.cornerNormals.insert(mesh.cornerNormals.end(), {vn[0], vn[k], vn[k + 1]});
                if (uvs) mesh.cornerUVs.insert(mesh.cornerUVs.end(), {vt[0], vt[k], vt[k + 1]});
                mesh.materialIds.push_back(matId);
                mesh.shapeIds.push_back(uint32_t(shapeIndex));
            }
        }
    }
    if (mesh.indices.empty()) throw Error(where, "'" + path + "' contains no triangles");
    if (!uvs) {
        std::vector<std::string> mapped;
        for (uint32_t id : mesh.materialIds)
            if (materials[id].map && std::find(mapped.begin(), mapped.end(), materials[id].name) == mapped.end())
                mapped.push_back(materials[id].name);
        if (!mapped.empty())
            warnings.push_back(where + ": '" + path + "': the map_Kd of " + nameList(mapped) +
                               " is not rendered: the file has no texture coordinates (vt)");
    }
    // An exporter that triangulates splits a rectangular light into two triangles along a
    // diagonal: pair such triangles back into parallelogram lights (one light where there would
    // be two, sampled as one). The rest are triangle lights.
    std::vector<bool> paired(emissiveTriangles.size(), false);
    // A triangle's candidates are those sharing an edge with it, found by edge instead of by
    // comparing every pair (an emissive mesh of 69K triangles would take 2.4e9 comparisons).
    auto edgeKey = [](uint32_t i, uint32_t j) { return i < j ? uint64_t(i) << 32 | j : uint64_t(j) << 32 | i; };
    std::unordered_map<uint64_t, std::vector<size_t>> byEdge;
    for (size_t a = 0; a < emissiveTriangles.size(); ++a)
        for (int k = 0; k < 3; ++k) byEdge[edgeKey(emissiveTriangles[a].v[k], emissiveTriangles[a].v[(k + 1) % 3])].push_back(a);
    std::vector<size_t> candidates;
    for (size_t a = 0; a < emissiveTriangles.size(); ++a) {
        if (paired[a]) continue;
        const EmissiveTriangle& t = emissiveTriangles[a];
        candidates.clear();
        for (int k = 0; k < 3; ++k)
            for (size_t b : byEdge[edgeKey(t.v[k], t.v[(k + 1) % 3])])
                if (b > a) candidates.push_back(b);
        std::sort(candidates.begin(), candidates.end());  // the file's order decides, as for every pair
        candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
        for (size_t i = 0; i < candidates.size() && !paired[a]; ++i) {
            const size_t b = candidates[i];
            const EmissiveTriangle& u = emissiveTriangles[b];
            if (paired[b] || u.material != t.material) continue;
            // t's corner k off the shared diagonal, u's vertex d off it: the quad is
            // (t[k+1], t[k+2], ... ) ordered so that the diagonal joins its corners 0 and 2.
            for (int k = 0; k < 3 && !paired[a]; ++k) {
                const uint32_t s1 = t.v[(k + 2) % 3], off = t.v[k], s2 = t.v[(k + 1) % 3];
                int shared = 0, d = -1;
                for (uint32_t w : u.v) {
                    if (w == s1 || w == s2) ++shared;
                    else if (w != off) d = int(w);
                }
                if (shared != 2 || d < 0) continue;
                const Vec3f q[4] = {mesh.positions[s1], mesh.positions[off], mesh.positions[s2], mesh.positions[uint32_t(d)]};
                AreaLight light;
                if (asParallelogram(q, light)) {
                    light.radiance = materials[t.material].emission;
                    promoted.push_back(light);
                    paired[a] = paired[b] = true;
                }
            }
        }
        if (!paired[a]) {
            const Vec3f p0 = mesh.positions[t.v[0]];
            AreaLight light{p0, mesh.positions[t.v[1]] - p0, mesh.positions[t.v[2]] - p0, materials[t.material].emission,
                            AreaLight::Shape::Triangle};
            if (light.area() > 0) promoted.push_back(light);  // a degenerate face emits nothing
        }
    }
    // Corners without a `vn` (a scanned mesh has none) shade smoothly across edges under
    // kCreaseDegrees: per-triangle normals of a fine scan differ by tens of degrees between
    // neighbours, which would split every pixel's samples into several surfaces (pixel_stats.h)
    // and shade the tessellation instead of the surface.
    smoothCornerNormals(mesh, kCreaseDegrees);
}

SceneDesc parseScene(const std::string& jsonText, const std::string& file, const std::string& baseDir) {
    return SceneParser(file, baseDir).parse(io::JsonNode::parseText(jsonText, file));
}

std::string scenesDirectory() {
    if (const char* env = std::getenv("WEDGE_SCENES"); env && *env) return env;
    return WEDGE_SCENES_DIR;
}

std::string nameList(const std::vector<std::string>& names) {
    std::vector<std::string> quoted;
    for (const std::string& n : names) quoted.push_back("'" + n + "'");
    return fewOf(quoted);
}

std::vector<BuiltinScene> builtinScenes() {
    fs::path index = fs::path(scenesDirectory()) / "index.json";
    nlohmann::json doc = JsonNode::parseFile(index.string());
    JsonNode root(doc, index.string(), "");
    JsonNode list = root["scenes"];
    std::vector<BuiltinScene> out;
    for (size_t i = 0; i < list.size(); ++i) {
        JsonNode s = list[i];
        BuiltinScene b;
        b.name = s["name"].string();
        b.file = (fs::path(scenesDirectory()) / s["file"].string()).string();
        b.description = s["description"].string();
        if (auto a = s.optional("attribution")) b.attribution = a->string();
        s.finish();
        out.push_back(b);
    }
    root.finish();
    return out;
}

SceneDesc loadScene(const std::string& pathOrName) {
    std::string file = pathOrName;
    std::error_code ec;
    if (!fs::exists(file, ec) && file.find('/') == std::string::npos && fs::path(file).extension().empty()) {
        bool found = false;
        std::string names;
        for (const auto& b : builtinScenes()) {
            names += (names.empty() ? "" : ", ") + b.name;
            if (b.name == pathOrName) { file = b.file; found = true; }
        }
        if (!found) throw Error(pathOrName, "no such scene file or built-in scene (built-ins: " + names + ")");
    }
    nlohmann::json doc = JsonNode::parseFile(file);
    std::string baseDir = fs::path(file).parent_path().string();
    if (baseDir.empty()) baseDir = ".";
    return SceneParser(file, baseDir).parse(doc);
}

}  // namespace wedge::scene
