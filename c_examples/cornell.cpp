// cornell.cpp: using mlt from C++ with small RAII wrappers.
//
// mlt's interface is plain C (include/mlt.h). This example shows how little it takes to
// make it comfortable in C++: an exception type carrying the status and message, a
// move-only Scene class that releases its handle in the destructor, and std::vector
// instead of pointer + length pairs. It builds the Cornell box from quads, renders it to a
// PFM file, and asks the scene a few ray queries (mlt_intersect / mlt_occluded).
//
// Usage:  cornell [out.pfm] [width height mutations-per-pixel]   (defaults: cornell.pfm 256 256 32)
//
// Build (from the crate root, after `cargo build --release`):
//   c++ -std=c++17 -Wall -Wextra -I include c_examples/cornell.cpp
//       target/release/libmlt.a -lpthread -ldl -lm -o cornell      (one line)

#include <mlt.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <iostream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace mltxx {

// ---------------------------------------------------------------------------------------
// Errors: every failing mlt call becomes an exception with its status and message.
// ---------------------------------------------------------------------------------------

class Error : public std::runtime_error {
public:
    Error(MltStatus status, const std::string &what)
        : std::runtime_error(what + ": " + mlt_status_string(status) + ": " +
                             mlt_last_error_message()),
          status_(status) {}
    MltStatus status() const { return status_; }

private:
    MltStatus status_;
};

// Throws unless `status` is MLT_STATUS_OK. Read the message right away: it is the calling
// thread's and the next mlt call replaces it.
inline void check(MltStatus status, const char *what) {
    if (status != MLT_STATUS_OK) throw Error(status, what);
}

// The C initializers, as value-returning functions.
inline MltMaterial defaultMaterial() {
    MltMaterial m;
    check(mlt_material_default(&m), "mlt_material_default");
    return m;
}
inline MltCamera defaultCamera() {
    MltCamera c;
    check(mlt_camera_default(&c), "mlt_camera_default");
    return c;
}
inline MltRenderSettings defaultSettings() {
    MltRenderSettings s;
    check(mlt_render_settings_default(&s), "mlt_render_settings_default");
    return s;
}
// Structs mlt fills in are initialized too: struct_size says which fields this header has.
inline MltRenderStats emptyStats() {
    MltRenderStats s;
    check(mlt_render_stats_default(&s), "mlt_render_stats_default");
    return s;
}

struct Vec3 {
    float x, y, z;
};

// ---------------------------------------------------------------------------------------
// Geometry in std::vectors, turned into an MltSceneDesc on demand.
// ---------------------------------------------------------------------------------------

struct Mesh {
    std::vector<float> positions;
    std::vector<std::uint32_t> indices;
    std::vector<std::uint32_t> materialIds;
    std::vector<MltMaterial> materials;

    std::uint32_t addMaterial(const MltMaterial &m) {
        materials.push_back(m);
        return static_cast<std::uint32_t>(materials.size() - 1);
    }

    // A planar quad with corners in counter-clockwise order seen from its front side, as
    // the triangles (a, b, c) and (a, c, d).
    void addQuad(std::uint32_t material, Vec3 a, Vec3 b, Vec3 c, Vec3 d) {
        const auto first = static_cast<std::uint32_t>(positions.size() / 3);
        for (const Vec3 &p : {a, b, c, d}) positions.insert(positions.end(), {p.x, p.y, p.z});
        indices.insert(indices.end(), {first, first + 1, first + 2, first, first + 2, first + 3});
        materialIds.insert(materialIds.end(), {material, material});
    }

    // The description points into this mesh: keep the mesh alive until mlt_scene_create
    // returns (mlt copies everything it needs).
    MltSceneDesc desc() const {
        MltSceneDesc d;
        check(mlt_scene_desc_default(&d), "mlt_scene_desc_default");
        d.positions = positions.data();
        d.positions_len = positions.size();
        d.indices = indices.data();
        d.indices_len = indices.size();
        d.material_ids = materialIds.data();
        d.material_ids_len = materialIds.size();
        d.materials = materials.data();
        d.materials_len = materials.size();
        return d;
    }
};

struct Image {
    std::uint32_t width = 0, height = 0;
    std::vector<float> rgb; // width * height * 3, rows top to bottom

    // PFM: header, then little-endian float RGB rows from the bottom of the image up.
    void writePfm(const std::string &path) const {
        std::ofstream file(path, std::ios::binary);
        file << "PF\n" << width << ' ' << height << "\n-1.0\n";
        for (std::uint32_t row = height; row-- > 0;) {
            for (std::size_t i = 0; i < std::size_t(width) * 3; ++i) {
                std::uint32_t bits;
                std::memcpy(&bits, &rgb[(std::size_t(row) * width * 3) + i], 4);
                const char bytes[4] = {char(bits & 0xff), char((bits >> 8) & 0xff),
                                       char((bits >> 16) & 0xff), char((bits >> 24) & 0xff)};
                file.write(bytes, 4);
            }
        }
        if (!file.flush()) throw std::runtime_error("could not write " + path);
    }
};

// ---------------------------------------------------------------------------------------
// The scene handle: owns an MltScene*, released exactly once. Movable, not copyable.
// ---------------------------------------------------------------------------------------

class Scene {
public:
    explicit Scene(const MltSceneDesc &desc) {
        check(mlt_scene_create(&desc, &handle_), "mlt_scene_create");
    }
    ~Scene() { mlt_scene_release(handle_); } // NULL (a moved-from Scene) is fine
    Scene(Scene &&other) noexcept : handle_(std::exchange(other.handle_, nullptr)) {}
    Scene &operator=(Scene &&other) noexcept {
        if (this != &other) {
            mlt_scene_release(handle_);
            handle_ = std::exchange(other.handle_, nullptr);
        }
        return *this;
    }
    Scene(const Scene &) = delete;
    Scene &operator=(const Scene &) = delete;

    MltSceneInfo info() const {
        MltSceneInfo info;
        check(mlt_scene_info_default(&info), "mlt_scene_info_default");
        check(mlt_scene_get_info(handle_, &info), "mlt_scene_get_info");
        return info;
    }

    // Renders; `progress` gets the fraction done and returns false to cancel. Any status
    // but OK throws (CANCELLED and TIME_LIMIT_REACHED included, for simplicity).
    Image render(const MltCamera &camera, const MltRenderSettings &settings,
                 std::function<bool(float)> progress = {}, MltRenderStats *stats = nullptr) const {
        Image image;
        image.width = settings.width;
        image.height = settings.height;
        image.rgb.resize(std::size_t(settings.width) * settings.height * 3);
        check(mlt_render_ex(handle_, &camera, &settings, image.rgb.data(), image.rgb.size(),
                            progress ? &Scene::forwardProgress : nullptr, &progress, stats),
              "mlt_render");
        return image;
    }

    std::vector<MltHit> intersect(const std::vector<MltRay> &rays) const {
        std::vector<MltHit> hits(rays.size());
        check(mlt_intersect(handle_, rays.data(), rays.size(), hits.data()), "mlt_intersect");
        return hits;
    }

    std::vector<bool> occluded(const std::vector<MltRay> &rays) const {
        std::vector<std::uint8_t> flags(rays.size());
        check(mlt_occluded(handle_, rays.data(), rays.size(), flags.data()), "mlt_occluded");
        return std::vector<bool>(flags.begin(), flags.end());
    }

    const MltScene *get() const { return handle_; }

private:
    // The C callback. An exception must never unwind through mlt's C frames: catch it here
    // and cancel the render instead.
    static bool forwardProgress(float fraction, void *userData) {
        try {
            return (*static_cast<std::function<bool(float)> *>(userData))(fraction);
        } catch (...) {
            return false;
        }
    }

    MltScene *handle_ = nullptr;
};

// A ray from `from` towards `to`: t = 1 at `to`, so t in (0, 1) means "between them".
inline MltRay segment(Vec3 from, Vec3 to, float tmin = 0.0f, float tmax = INFINITY) {
    MltRay r;
    r.origin[0] = from.x; r.origin[1] = from.y; r.origin[2] = from.z;
    r.direction[0] = to.x - from.x; r.direction[1] = to.y - from.y; r.direction[2] = to.z - from.z;
    r.tmin = tmin;
    r.tmax = tmax;
    return r;
}

} // namespace mltxx

// The Cornell box (tests/scenes/cornell-box.obj), millimetres, y up. Walls face into the
// room, blocks outward, and the light faces down: emitters shine from their front only.
static mltxx::Mesh cornellBox() {
    using mltxx::Vec3;
    mltxx::Mesh mesh;
    auto diffuse = [&](float r, float g, float b) {
        MltMaterial m = mltxx::defaultMaterial();
        m.kind = MLT_MATERIAL_DIFFUSE;
        m.color[0] = r; m.color[1] = g; m.color[2] = b;
        return mesh.addMaterial(m);
    };
    const std::uint32_t white = diffuse(0.725f, 0.71f, 0.68f);
    const std::uint32_t red = diffuse(0.63f, 0.065f, 0.05f);
    const std::uint32_t green = diffuse(0.14f, 0.45f, 0.091f);
    MltMaterial lightMaterial = mltxx::defaultMaterial();
    lightMaterial.color[0] = lightMaterial.color[1] = lightMaterial.color[2] = 0.0f;
    lightMaterial.emission[0] = 17.0f; lightMaterial.emission[1] = 12.0f; lightMaterial.emission[2] = 4.0f;
    const std::uint32_t light = mesh.addMaterial(lightMaterial);

    mesh.addQuad(white, {552.8f, 0, 0}, {0, 0, 0}, {0, 0, 559.2f}, {549.6f, 0, 559.2f});   // floor
    mesh.addQuad(white, {556, 548.8f, 0}, {556, 548.8f, 559.2f}, {0, 548.8f, 559.2f}, {0, 548.8f, 0}); // ceiling
    mesh.addQuad(white, {549.6f, 0, 559.2f}, {0, 0, 559.2f}, {0, 548.8f, 559.2f}, {556, 548.8f, 559.2f}); // back
    mesh.addQuad(green, {0, 0, 559.2f}, {0, 0, 0}, {0, 548.8f, 0}, {0, 548.8f, 559.2f});    // right
    mesh.addQuad(red, {552.8f, 0, 0}, {549.6f, 0, 559.2f}, {556, 548.8f, 559.2f}, {556, 548.8f, 0}); // left

    mesh.addQuad(white, {130, 165, 65}, {82, 165, 225}, {240, 165, 272}, {290, 165, 114}); // short block
    mesh.addQuad(white, {290, 0, 114}, {290, 165, 114}, {240, 165, 272}, {240, 0, 272});
    mesh.addQuad(white, {130, 0, 65}, {130, 165, 65}, {290, 165, 114}, {290, 0, 114});
    mesh.addQuad(white, {82, 0, 225}, {82, 165, 225}, {130, 165, 65}, {130, 0, 65});
    mesh.addQuad(white, {240, 0, 272}, {240, 165, 272}, {82, 165, 225}, {82, 0, 225});

    mesh.addQuad(white, {423, 330, 247}, {265, 330, 296}, {314, 330, 456}, {472, 330, 406}); // tall block
    mesh.addQuad(white, {423, 0, 247}, {423, 330, 247}, {472, 330, 406}, {472, 0, 406});
    mesh.addQuad(white, {472, 0, 406}, {472, 330, 406}, {314, 330, 456}, {314, 0, 456});
    mesh.addQuad(white, {314, 0, 456}, {314, 330, 456}, {265, 330, 296}, {265, 0, 296});
    mesh.addQuad(white, {265, 0, 296}, {265, 330, 296}, {423, 330, 247}, {423, 0, 247});

    mesh.addQuad(light, {343, 548.7f, 227}, {343, 548.7f, 332}, {213, 548.7f, 332}, {213, 548.7f, 227});
    return mesh;
}

int main(int argc, char **argv) try {
    using mltxx::Vec3;
    if (argc != 1 && argc != 2 && argc != 5) {
        std::cerr << "usage: " << argv[0] << " [out.pfm] [width height mutations-per-pixel]\n";
        return 2;
    }
    const std::string outPath = argc > 1 ? argv[1] : "cornell.pfm";

    // The mesh may go away once the scene exists: mlt keeps its own copy.
    mltxx::Scene scene(cornellBox().desc());
    const MltSceneInfo info = scene.info();
    std::cout << "scene: " << info.triangle_count << " triangles, " << info.emitter_count
              << " lights\n";

    // Ray queries. Triangle ids are the host's: triangle i is indices[3i..3i+3), so the
    // back wall (the third quad) is triangles 4 and 5.
    const Vec3 eye{278, 273, -800};
    const std::vector<MltRay> rays = {
        mltxx::segment(eye, {150, 450, 559.2f}), // at the back wall, above both blocks
        mltxx::segment(eye, {278, 273, -900}),   // away from the box: a miss
    };
    const std::vector<MltHit> hits = scene.intersect(rays);
    for (std::size_t i = 0; i < hits.size(); ++i) {
        if (hits[i].triangle_id == MLT_INVALID_ID)
            std::cout << "ray " << i << ": miss\n";
        else
            std::cout << "ray " << i << ": triangle " << hits[i].triangle_id << " at t = "
                      << hits[i].t << " (u = " << hits[i].u << ", v = " << hits[i].v << ")\n";
    }
    if (!(hits[0].triangle_id == 4 || hits[0].triangle_id == 5) || hits[1].triangle_id != MLT_INVALID_ID) {
        std::cerr << "unexpected ray query result\n";
        return 1;
    }
    std::cout << "ray 0 hits the back wall\n";

    // Shadow rays towards the centre of the light, stopping just short of it.
    const Vec3 lightCentre{278, 548.7f, 279.5f};
    const std::vector<MltRay> shadowRays = {
        mltxx::segment({278, 0.5f, 279.6f}, lightCentre, 0.0f, 0.999f), // open floor: lit
        mltxx::segment({185, 0.5f, 169}, lightCentre, 0.0f, 0.999f),    // under the short block
    };
    const std::vector<bool> blocked = scene.occluded(shadowRays);
    std::cout << "floor point 0 is " << (blocked[0] ? "in shadow" : "lit") << ", floor point 1 is "
              << (blocked[1] ? "in shadow" : "lit") << "\n";
    if (blocked[0] || !blocked[1]) {
        std::cerr << "unexpected occlusion result\n";
        return 1;
    }

    // Render.
    // Render with the default algorithm (Metropolis light transport); its quality knob is
    // mutations per pixel.
    MltRenderSettings settings = mltxx::defaultSettings();
    if (argc == 5) {
        settings.width = static_cast<std::uint32_t>(std::strtoul(argv[2], nullptr, 10));
        settings.height = static_cast<std::uint32_t>(std::strtoul(argv[3], nullptr, 10));
        settings.mutations_per_pixel = static_cast<std::uint32_t>(std::strtoul(argv[4], nullptr, 10));
    }
    int lastPercent = -1;
    MltRenderStats stats = mltxx::emptyStats();
    const mltxx::Image image = scene.render(
        mltxx::defaultCamera(), settings,
        [&](float fraction) {
            const int percent = static_cast<int>(fraction * 100.0f);
            if (percent != lastPercent) std::cerr << "\rrendering: " << percent << "%" << std::flush;
            lastPercent = percent;
            return true;
        },
        &stats);
    std::cerr << "\n";
    std::cout << "rendered " << stats.samples << " mutations, " << stats.rays << " rays in "
              << stats.seconds << " s on " << stats.threads << " threads\n";
    image.writePfm(outPath);
    std::cout << "wrote " << outPath << "\n";
    return 0;
} catch (const mltxx::Error &e) {
    std::cerr << "mlt error (status " << int(e.status()) << "): " << e.what() << "\n";
    return 1;
} catch (const std::exception &e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
}
