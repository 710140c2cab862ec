// cornell.cpp: using mlt from C++ through include/mlt.hpp.
//
// mlt.hpp wraps the C interface (include/mlt.h) in C++17: errors are exceptions carrying
// the status and the library's message, mlt::Scene releases its handle in its destructor,
// settings and materials are structs whose defaults are the library's, arrays are spans
// (std::vector converts), and the progress callback is a lambda. This example builds the
// Cornell box from quads, asks the scene a few ray queries, renders it and writes a PFM
// file.
//
// Usage:  cornell [out.pfm] [width height mutations-per-pixel]   (defaults: cornell.pfm 256 256 32)
//
// Build (from the crate root, after `cargo build --release`):
//   c++ -std=c++17 -Wall -Wextra -I include c_examples/cornell.cpp
//       target/release/libmlt.a -lpthread -ldl -lm -o cornell      (one line)

#include <mlt.hpp>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <fstream>
#include <initializer_list>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

// Geometry in std::vectors; scene() points an mlt::SceneDesc at them.
struct Mesh {
    std::vector<float> positions;
    std::vector<std::uint32_t> indices;
    std::vector<std::uint32_t> materialIds;
    std::vector<mlt::Material> materials;

    std::uint32_t addMaterial(const mlt::Material &m) {
        materials.push_back(m);
        return static_cast<std::uint32_t>(materials.size() - 1);
    }

    // A planar quad with corners in counter-clockwise order seen from its front side, as
    // the triangles (a, b, c) and (a, c, d).
    void addQuad(std::uint32_t material, mlt::Vec3 a, mlt::Vec3 b, mlt::Vec3 c, mlt::Vec3 d) {
        const auto first = static_cast<std::uint32_t>(positions.size() / 3);
        for (const mlt::Vec3 &p : {a, b, c, d}) positions.insert(positions.end(), p.begin(), p.end());
        indices.insert(indices.end(), {first, first + 1, first + 2, first, first + 2, first + 3});
        materialIds.insert(materialIds.end(), {material, material});
    }

    // mlt copies the arrays: the mesh may go away once the scene exists.
    mlt::Scene scene() const {
        mlt::SceneDesc desc;
        desc.positions = positions;
        desc.indices = indices;
        desc.material_ids = materialIds;
        desc.materials = materials;
        return mlt::Scene(desc);
    }
};

// The Cornell box (tests/scenes/cornell-box.obj), millimetres, y up. Walls face into the
// room, blocks outward, and the light faces down: emitters shine from their front only.
Mesh cornellBox() {
    Mesh mesh;
    const std::uint32_t white = mesh.addMaterial(mlt::Material::diffuse({0.725f, 0.71f, 0.68f}));
    const std::uint32_t red = mesh.addMaterial(mlt::Material::diffuse({0.63f, 0.065f, 0.05f}));
    const std::uint32_t green = mesh.addMaterial(mlt::Material::diffuse({0.14f, 0.45f, 0.091f}));
    const std::uint32_t light = mesh.addMaterial(mlt::Material::emitter({17.0f, 12.0f, 4.0f}));

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

// PFM: header, then little-endian float RGB rows from the bottom of the image up.
void writePfm(const std::string &path, const mlt::Image &image) {
    std::ofstream file(path, std::ios::binary);
    file << "PF\n" << image.width << ' ' << image.height << "\n-1.0\n";
    for (std::uint32_t row = image.height; row-- > 0;) {
        for (std::uint32_t x = 0; x < image.width; ++x) {
            for (const float value : image.pixel(x, row)) {
                std::uint32_t bits;
                std::memcpy(&bits, &value, 4);
                const char bytes[4] = {char(bits & 0xff), char((bits >> 8) & 0xff),
                                       char((bits >> 16) & 0xff), char((bits >> 24) & 0xff)};
                file.write(bytes, 4);
            }
        }
    }
    if (!file.flush()) throw std::runtime_error("could not write " + path);
}

} // namespace

int main(int argc, char **argv) try {
    if (argc != 1 && argc != 2 && argc != 5) {
        std::cerr << "usage: " << argv[0] << " [out.pfm] [width height mutations-per-pixel]\n";
        return 2;
    }
    const std::string outPath = argc > 1 ? argv[1] : "cornell.pfm";

    const mlt::Scene scene = cornellBox().scene();
    const mlt::SceneInfo info = scene.info();
    std::cout << "scene: " << info.triangle_count << " triangles, " << info.emitter_count
              << " lights\n";

    // Ray queries. Triangle ids are the host's: triangle i is indices[3i..3i+3), so the
    // back wall (the third quad) is triangles 4 and 5.
    const mlt::Vec3 eye{278, 273, -800};
    const std::vector<mlt::Ray> rays = {
        mlt::segment(eye, {150, 450, 559.2f}), // at the back wall, above both blocks
        mlt::segment(eye, {278, 273, -900}),   // away from the box: a miss
    };
    const std::vector<mlt::Hit> hits = scene.intersect(rays);
    for (std::size_t i = 0; i < hits.size(); ++i) {
        if (!mlt::is_hit(hits[i]))
            std::cout << "ray " << i << ": miss\n";
        else
            std::cout << "ray " << i << ": triangle " << hits[i].triangle_id << " at t = "
                      << hits[i].t << " (u = " << hits[i].u << ", v = " << hits[i].v << ")\n";
    }
    if (!(hits[0].triangle_id == 4 || hits[0].triangle_id == 5) || mlt::is_hit(hits[1])) {
        std::cerr << "unexpected ray query result\n";
        return 1;
    }
    std::cout << "ray 0 hits the back wall\n";

    // Shadow rays towards the centre of the light, stopping just short of it.
    const mlt::Vec3 lightCentre{278, 548.7f, 279.5f};
    const std::vector<mlt::Ray> shadowRays = {
        mlt::segment({278, 0.5f, 279.6f}, lightCentre, 0.0f, 0.999f), // open floor: lit
        mlt::segment({185, 0.5f, 169}, lightCentre, 0.0f, 0.999f),    // under the short block
    };
    const std::vector<bool> blocked = scene.occluded(shadowRays);
    std::cout << "floor point 0 is " << (blocked[0] ? "in shadow" : "lit") << ", floor point 1 is "
              << (blocked[1] ? "in shadow" : "lit") << "\n";
    if (blocked[0] || !blocked[1]) {
        std::cerr << "unexpected occlusion result\n";
        return 1;
    }

    // Render with the default algorithm (multiplexed Metropolis light transport); its
    // quality knob is mutations per pixel. mlt::Camera{} is the Cornell box's camera.
    mlt::RenderSettings settings;
    if (argc == 5) {
        settings.width = static_cast<std::uint32_t>(std::strtoul(argv[2], nullptr, 10));
        settings.height = static_cast<std::uint32_t>(std::strtoul(argv[3], nullptr, 10));
        settings.mutations_per_pixel = static_cast<std::uint32_t>(std::strtoul(argv[4], nullptr, 10));
    }
    int lastPercent = -1;
    const mlt::Image image =
        mlt::render_image(scene, mlt::Camera{}, settings, [&](const mlt::Progress &progress) {
            const int percent = static_cast<int>(progress.fraction * 100.0f);
            if (percent != lastPercent) std::cerr << "\rrendering: " << percent << "%" << std::flush;
            lastPercent = percent;
        });
    std::cerr << "\n";
    if (!image.result.completed()) {
        std::cerr << "the render stopped early: " << image.result.message << "\n";
        return 1;
    }
    const mlt::RenderStats &stats = image.result.stats;
    std::cout << "rendered " << stats.samples << " samples and " << stats.mutations
              << " mutations, " << stats.rays << " rays in " << stats.seconds << " s on "
              << stats.threads << " threads\n";
    writePfm(outPath, image);
    std::cout << "wrote " << outPath << "\n";
    return 0;
} catch (const mlt::Error &e) {
    std::cerr << "mlt error (status " << static_cast<int>(e.status()) << "): " << e.what() << "\n";
    return 1;
} catch (const std::exception &e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
}
