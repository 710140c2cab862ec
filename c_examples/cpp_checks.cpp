// cpp_checks.cpp: a test program for include/mlt.hpp (tests/c_hosts.rs runs it as C++17
// and C++20). It checks what the C++ layer adds to the C interface: the defaults of its
// structs against the library's, errors as mlt::Error with the right status and message,
// the progress callback (a lambda that cancels, one that throws: the render is cancelled
// and the exception reaches the caller), the spans, the scene handle's ownership, and a
// render split into jobs (mlt::Bytes owning what mlt gives).
// Prints one "ok: ..." line per check and "all checks passed" at the end; exits with 1 on
// the first failure.
//
// Usage:  cpp_checks
//
// Build (from the crate root, after `cargo build --release`):
//   c++ -std=c++17 -Wall -Wextra -I include c_examples/cpp_checks.cpp
//       target/release/libmlt.a -lpthread -ldl -lm -o cpp_checks      (one line)

#include <mlt.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>
#if defined(__cpp_lib_span)
#  include <span>
#endif

namespace {

[[noreturn]] void fail(const std::string &what, int line) {
    std::cerr << "cpp_checks.cpp:" << line << ": FAILED: " << what << "\n";
    std::exit(1);
}

#define CHECK(condition)                                                                      \
    do {                                                                                      \
        if (!(condition)) fail(#condition, __LINE__);                                         \
    } while (false)

void ok(const std::string &what) { std::cout << "ok: " << what << "\n"; }

bool contains(const std::string &text, const std::string &part) {
    return text.find(part) != std::string::npos;
}

// Runs `f`, which must throw mlt::Error with `status` and a message containing `part`.
template <class F>
mlt::Error expectError(F &&f, mlt::Status status, const std::string &part, int line) {
    try {
        f();
    } catch (const mlt::Error &e) {
        if (e.status() != status)
            fail(std::string("status is \"") + mlt::status_string(e.status()) + "\", expected \"" +
                     mlt::status_string(status) + "\" (" + e.what() + ")",
                 line);
        if (!contains(e.message(), part))
            fail("message \"" + std::string(e.message()) + "\" lacks \"" + part + "\"", line);
        if (!contains(e.what(), mlt::status_string(status)) || !contains(e.what(), e.message()))
            fail(std::string("what() is \"") + e.what() + "\"", line);
        return e;
    }
    fail("no mlt::Error was thrown", line);
}

// A 2 x 2 ground square at y = 0 with a 2 x 2 checker texture, under a constant sky, a sun
// and a point light: every kind of light and a texture go through the C++ structs. Not
// copyable: the texture points into `texels`.
struct Ground {
    std::vector<float> positions{-1, 0, -1, -1, 0, 1, 1, 0, 1, 1, 0, -1};
    std::vector<std::uint32_t> indices{0, 1, 2, 0, 2, 3};
    std::vector<float> texcoords{0, 0, 0, 1, 1, 1, 1, 0};
    std::array<std::uint8_t, 2 * 2 * 3> texels{64, 64, 64, 255, 255, 255, 255, 255, 255, 64, 64, 64};
    std::vector<mlt::Texture> textures{mlt::Texture::u8(2, 2, 3, texels)};
    std::vector<mlt::Material> materials;
    std::vector<mlt::PunctualLight> lights{mlt::PunctualLight::point({0, 1, 0}, {0.1f, 0.1f, 0.1f})};

    Ground() {
        mlt::Material ground = mlt::Material::diffuse({0.5f, 0.5f, 0.5f});
        ground.base_color_texture.texture = 0;
        materials.push_back(ground);
        textures[0].filter = mlt::TextureFilter::Nearest;
    }
    Ground(const Ground &) = delete;
    Ground &operator=(const Ground &) = delete;

    mlt::SceneDesc desc() const {
        mlt::SceneDesc desc;
        desc.positions = positions;
        desc.indices = indices;
        desc.texcoords = texcoords;
        desc.materials = materials;
        desc.textures = textures;
        desc.environment = mlt::Environment::constant({1.0f, 1.0f, 1.0f});
        mlt::Sun sun;
        sun.irradiance = {0.5f, 0.5f, 0.5f};
        desc.sun = sun;
        desc.punctual_lights = lights;
        return desc;
    }
};

// Straight down at the ground, which fills the image.
mlt::Camera topCamera() {
    mlt::Camera camera;
    camera.eye = {0, 2, 0};
    camera.target = {0, 0, 0};
    camera.up = {0, 0, 1};
    camera.fov_y_deg = 40;
    return camera;
}

mlt::RenderSettings quickSettings() {
    mlt::RenderSettings settings;
    settings.algorithm = mlt::Algorithm::Path;
    settings.width = 16;
    settings.height = 16;
    settings.samples_per_pixel = 4;
    settings.threads = 2;
    return settings;
}

// A render that goes on until its time limit, long enough for many progress calls.
mlt::RenderSettings longSettings() {
    mlt::RenderSettings settings = quickSettings();
    settings.samples_per_pixel = 0;
    settings.time_limit_seconds = 60.0;
    return settings;
}

bool allFiniteAndNonNegative(const std::vector<float> &rgb) {
    for (const float v : rgb)
        if (!std::isfinite(v) || v < 0.0f) return false;
    return true;
}

double secondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

struct StopRequested : std::runtime_error {
    int call;
    explicit StopRequested(int c) : std::runtime_error("stop requested"), call(c) {}
};

// ---------------------------------------------------------------------------------------

void defaultsAreTheLibrarys() {
    static_assert(std::is_aggregate_v<mlt::RenderSettings>, "designated initializers work");
#define SAME(a, b, field) CHECK((a).field == (b).field)
    {
        // Each setting's default against the C struct's is checked by parameters.cpp (made
        // from the declarations); here the wrapper's whole.
        const mlt::RenderSettings mine, lib = mlt::RenderSettings::library_defaults();
        SAME(mine, lib, algorithm);
        SAME(mine, lib, mutation_weights);
        // And the round trip through the C struct keeps every field.
        const mlt::RenderSettings back = mlt::RenderSettings::from_c(mine.to_c());
        SAME(mine, back, mutation_weights);
        SAME(mine, back, algorithm);
        SAME(mine, back, normalization_work_fraction);
        CHECK(mine.to_c().struct_size == sizeof(MltRenderSettings));
    }
    ok("mlt::RenderSettings{} is mlt_render_settings_default");
    {
        const mlt::Camera mine, lib = mlt::Camera::library_defaults();
        SAME(mine, lib, eye);
        SAME(mine, lib, target);
        SAME(mine, lib, up);
        SAME(mine, lib, fov_y_deg);
        SAME(mine, lib, lens_radius);
        SAME(mine, lib, focus_distance);
    }
    ok("mlt::Camera{} is mlt_camera_default");
    {
        // Each parameter's default against the C struct's is checked by parameters.cpp (made
        // from the declarations); here the wrapper's whole, and a texture slot's transform.
        const mlt::Material mine, lib = mlt::Material::library_defaults();
        SAME(mine, lib, kind);
        SAME(mine, lib, color);
        SAME(mine.normal_texture, lib.normal_texture, texture);
        SAME(mine.normal_texture, lib.normal_texture, offset);
        SAME(mine.normal_texture, lib.normal_texture, rotation);
        SAME(mine.normal_texture, lib.normal_texture, scale);
        // And the round trip through the C struct keeps every field.
        mlt::Material textured = mlt::Material::metallic_roughness({0.5f, 0.25f, 1.0f}, 1.0f, 0.5f);
        textured.emission_texture.texture = 3;
        textured.emission_texture.rotation = 0.5f;
        const mlt::Material back = mlt::Material::from_c(textured.to_c());
        SAME(textured, back, kind);
        SAME(textured, back, color);
        SAME(textured, back, roughness);
        SAME(textured.emission_texture, back.emission_texture, texture);
        SAME(textured.emission_texture, back.emission_texture, rotation);
        CHECK(mine.to_c().struct_size == sizeof(MltMaterial));
    }
    ok("mlt::Material{} is mlt_material_default");
    {
        const mlt::Texture mine, lib = mlt::Texture::library_defaults();
        SAME(mine, lib, width);
        SAME(mine, lib, height);
        SAME(mine, lib, channels);
        SAME(mine, lib, texel_type);
        SAME(mine, lib, texels);
        SAME(mine, lib, encoding);
        SAME(mine, lib, wrap_u);
        SAME(mine, lib, wrap_v);
        SAME(mine, lib, filter);
    }
    {
        const mlt::Sun mine, lib = mlt::Sun::library_defaults();
        SAME(mine, lib, direction);
        SAME(mine, lib, angular_radius_degrees);
        SAME(mine, lib, irradiance);
    }
    {
        const mlt::PunctualLight mine, lib = mlt::PunctualLight::library_defaults();
        SAME(mine, lib, kind);
        SAME(mine, lib, position);
        SAME(mine, lib, direction);
        SAME(mine, lib, intensity);
        SAME(mine, lib, inner_cone_degrees);
        SAME(mine, lib, outer_cone_degrees);
    }
    {
        MltEnvironment lib;
        CHECK(mlt_environment_default(&lib) == MLT_STATUS_OK);
        const mlt::Environment mine;
        CHECK(mine.rotation_degrees == lib.rotation_degrees && mine.scale == lib.scale);
    }
#undef SAME
    ok("mlt::Texture, Sun, PunctualLight and Environment defaults are the library's");
    CHECK(mlt::version() == mlt::header_version);
    ok(std::string("header and library are version ") + mlt::version_string());
}

void errorsCarryStatusAndMessage() {
    const Ground ground;
    const mlt::Scene scene(ground.desc());

    // A bad setting: the library's message names the field and its value.
    mlt::RenderSettings bad = quickSettings();
    bad.width = 0;
    const mlt::Error e = expectError([&] { mlt::render_image(scene, topCamera(), bad); },
                                     mlt::Status::InvalidArgument, "settings.width is 0",
                                     __LINE__);
    CHECK(contains(e.what(), "mlt_render: invalid argument: settings.width is 0"));
    // An mlt::Error is a std::runtime_error, and its copies keep the status and message.
    const mlt::Error copy = e;
    CHECK(copy.status() == mlt::Status::InvalidArgument && std::string(copy.message()) == e.message());
    static_assert(std::is_base_of_v<std::runtime_error, mlt::Error>, "");
    static_assert(std::is_nothrow_copy_constructible_v<mlt::Error>, "");
    ok(std::string("a bad setting throws mlt::Error: ") + e.what());

    // render_image allocates only for an image size mlt accepts: this one is reported, not
    // attempted.
    bad = quickSettings();
    bad.width = 4000000000u;
    bad.height = 4000000000u;
    expectError([&] { mlt::render_image(scene, topCamera(), bad); },
                mlt::Status::InvalidArgument, "settings.width is 4000000000", __LINE__);

    bad = quickSettings();
    bad.samples_per_pixel = 0; // and no time limit: the render would never end
    expectError([&] { mlt::render_image(scene, topCamera(), bad); },
                mlt::Status::InvalidArgument, "settings.samples_per_pixel is 0", __LINE__);
    mlt::Camera badCamera = topCamera();
    badCamera.target = badCamera.eye;
    expectError([&] { mlt::render_image(scene, badCamera, quickSettings()); },
                mlt::Status::InvalidArgument, "", __LINE__);
    ok("a huge image, a bad camera and a render without an end throw InvalidArgument");

    // An output span too small for the image.
    std::vector<float> small(10);
    expectError([&] { mlt::render(scene, topCamera(), quickSettings(), small); },
                mlt::Status::InvalidArgument, "out_len is 10", __LINE__);
    ok("a short output span throws InvalidArgument");

    // A scene whose triangle names a vertex that does not exist.
    Ground badIndex;
    badIndex.indices[4] = 7;
    expectError([&] { mlt::Scene s(badIndex.desc()); }, mlt::Status::InvalidArgument,
                "desc.indices[4]", __LINE__);
    Ground badMaterial;
    badMaterial.materials[0].roughness = 2.0f;
    expectError([&] { mlt::Scene s(badMaterial.desc()); }, mlt::Status::InvalidArgument,
                "roughness", __LINE__);
    ok("a bad scene description throws InvalidArgument naming the field");

    // Checks of the C++ layer itself.
    const std::vector<std::uint8_t> texels(5);
    expectError([&] { mlt::Texture::u8(2, 2, 3, texels); }, mlt::Status::InvalidArgument,
                "need 12", __LINE__);
    std::vector<mlt::Hit> hits(1);
    const std::vector<mlt::Ray> rays{mlt::ray({0, 1, 0}, {0, -1, 0}), mlt::ray({0, 1, 0}, {0, 1, 0})};
    expectError([&] { scene.intersect(rays, hits); }, mlt::Status::InvalidArgument,
                "hits holds 1 results for 2 rays", __LINE__);
    std::vector<mlt::Ray> badRays = rays;
    badRays[1].direction[0] = badRays[1].direction[1] = badRays[1].direction[2] = 0.0f;
    expectError([&] { scene.occluded(badRays); }, mlt::Status::InvalidArgument, "rays[1]",
                __LINE__);
    ok("size checks of the C++ layer, and a bad ray, throw InvalidArgument");

    // A backend this build lacks.
    mlt::SceneDesc embree = ground.desc();
    embree.backend = mlt::Backend::Embree;
    if (mlt::backend_supported(mlt::Backend::Embree)) {
        CHECK(mlt::Scene(embree).info().backend == mlt::Backend::Embree);
        ok("the Embree backend is built in and creates scenes");
    } else {
        expectError([&] { mlt::Scene s(embree); }, mlt::Status::Unsupported, "", __LINE__);
        ok("the Embree backend is not built in: Unsupported");
    }

    // An empty handle.
    mlt::Scene empty;
    CHECK(!empty);
    expectError([&] { empty.info(); }, mlt::Status::InvalidArgument, "scene", __LINE__);
    ok("an empty mlt::Scene throws InvalidArgument when used");
}

void callbacks() {
    const Ground ground;
    const mlt::Scene scene(ground.desc());
    const mlt::Camera camera = topCamera();

    // A lambda returning void only watches: the render completes, 1.0 last.
    {
        int calls = 0;
        float last = -1.0f;
        const mlt::Image image = mlt::render_image(scene, camera, quickSettings(),
                                                   [&](const mlt::Progress &p) {
                                                       ++calls;
                                                       last = p.fraction;
                                                   });
        CHECK(image.result.completed() && image.result.status == mlt::Status::Ok);
        CHECK(image.result.message.empty());
        CHECK(calls >= 1 && last == 1.0f);
        CHECK(allFiniteAndNonNegative(image.rgb));
        ok("a void lambda sees the render to 1.0 (progress calls: " + std::to_string(calls) + ")");
    }

    // A lambda returning false cancels: a valid image, status Cancelled, no exception.
    {
        int calls = 0;
        const auto start = std::chrono::steady_clock::now();
        const mlt::Image image =
            mlt::render_image(scene, camera, longSettings(), [&](const mlt::Progress &) {
                return ++calls < 3;
            });
        const double seconds = secondsSince(start);
        CHECK(image.result.status == mlt::Status::Cancelled && !image.result.completed());
        CHECK(contains(image.result.message, "cancelled"));
        CHECK(calls >= 3);
        CHECK(seconds < 30.0);
        CHECK(image.result.stats.samples >= 16u * 16u); // every pixel has a sample
        CHECK(allFiniteAndNonNegative(image.rgb));
        ok("a lambda returning false cancels the render (" + image.result.message + ")");
    }

    // A lambda that throws: the library sees a cancel, the exception reaches the caller,
    // and the lambda is not called again.
    {
        int calls = 0;
        const auto start = std::chrono::steady_clock::now();
        std::vector<float> rgb(16 * 16 * 3);
        try {
            mlt::render(scene, camera, longSettings(), rgb, [&](const mlt::Progress &) {
                if (++calls == 3) throw StopRequested(calls);
                return true;
            });
            fail("the lambda's exception did not reach the caller", __LINE__);
        } catch (const StopRequested &stop) {
            CHECK(stop.call == 3);
        }
        const double seconds = secondsSince(start);
        CHECK(calls == 3);
        CHECK(seconds < 30.0);
        CHECK(allFiniteAndNonNegative(rgb)); // the library still finished its image
        ok("a lambda's exception cancels the render and is rethrown after it (" +
           std::to_string(seconds) + " s)");
    }

    // An exception from the last call (1.0) of a completed render is rethrown too.
    {
        try {
            mlt::render_image(scene, camera, quickSettings(), [](const mlt::Progress &p) {
                if (p.fraction == 1.0f) throw std::logic_error("at the end");
            });
            fail("the exception from the last progress call was lost", __LINE__);
        } catch (const std::logic_error &e) {
            CHECK(std::string(e.what()) == "at the end");
        }
        ok("an exception from the final progress call is rethrown");
    }

    // std::function and a mutable lambda passed by value work as well.
    {
        int calls = 0;
        const std::function<bool(const mlt::Progress &)> f = [&](const mlt::Progress &) {
            ++calls;
            return true;
        };
        CHECK(mlt::render_image(scene, camera, quickSettings(), f).result.completed());
        CHECK(calls >= 1);
        int own = 0;
        CHECK(mlt::render_image(scene, camera, quickSettings(),
                                [own](const mlt::Progress &) mutable { return ++own > 0; })
                  .result.completed());
        ok("std::function and mutable lambdas are progress callbacks");
    }

    // A time limit stops a render too, with a valid image.
    {
        mlt::RenderSettings settings = longSettings();
        settings.time_limit_seconds = 0.2;
        const mlt::Image image = mlt::render_image(scene, camera, settings);
        CHECK(image.result.status == mlt::Status::TimeLimitReached);
        CHECK(contains(image.result.message, "time limit"));
        CHECK(allFiniteAndNonNegative(image.rgb));
        ok("a time limit returns TimeLimitReached with a valid image");
    }
}

// Texture coordinate set 1 (glTF's TEXCOORD_1): a slot whose TextureRef::texcoord is 1 reads
// SceneDesc::texcoords1 (its MLT_TEXCOORD1_* bit of MltMaterial.texcoord1_slots in C). Set 1
// mirrors u here, so the checker's dark and white quarters swap places in the image.
void textureCoordinateSets() {
    mlt::Material material;
    material.normal_texture.texture = 0;
    material.normal_texture.texcoord = 1;
    const MltMaterial c = material.to_c();
    CHECK(c.texcoord1_slots == MLT_TEXCOORD1_NORMAL);
    CHECK(mlt::Material::from_c(c).normal_texture.texcoord == 1);
    CHECK(mlt::Material::from_c(c).base_color_texture.texcoord == 0);
    material.base_color_texture.texcoord = 2;
    expectError([&] { material.to_c(); }, mlt::Status::InvalidArgument,
                "material.base_color_texture.texcoord is 2", __LINE__);

    Ground ground;
    ground.materials[0].base_color_texture.texcoord = 1;
    expectError([&] { mlt::Scene s(ground.desc()); }, mlt::Status::InvalidArgument,
                "desc.materials[0].base_color_texture uses texture coordinate set 1 but "
                "desc.texcoords1 is empty",
                __LINE__);
    const std::vector<float> mirrored{1, 0, 1, 1, 0, 1, 0, 0};
    // The mean of the image's quarter whose top-left pixel is (x0, y0), 2 pixels in.
    auto quarter = [](const mlt::Image &image, std::uint32_t x0, std::uint32_t y0) {
        double sum = 0.0;
        for (std::uint32_t y = y0 + 2; y < y0 + 6; ++y)
            for (std::uint32_t x = x0 + 2; x < x0 + 6; ++x)
                for (const float v : image.pixel(x, y)) sum += v;
        return sum / (4 * 4 * 3);
    };
    double contrast[2] = {0.0, 0.0};
    for (std::uint32_t set = 0; set < 2; ++set) {
        ground.materials[0].base_color_texture.texcoord = set;
        mlt::SceneDesc desc = ground.desc();
        desc.texcoords1 = mirrored;
        const mlt::Image image = mlt::render_image(mlt::Scene(desc), topCamera(), quickSettings());
        contrast[set] = quarter(image, 0, 0) / quarter(image, 8, 0);
    }
    // One set's top-left quarter is dark where the other's is white (sRGB 64 against 255).
    CHECK((contrast[0] < 0.5 && contrast[1] > 2.0) || (contrast[0] > 2.0 && contrast[1] < 0.5));
    ok("TextureRef::texcoord 1 reads SceneDesc::texcoords1; texcoord1_slots round-trips; "
       "set 1 without texcoords1, and set 2, throw");
}

void spansAndImages() {
    const Ground ground;
    const mlt::Scene scene(ground.desc());
    const mlt::Camera camera = topCamera();
    const mlt::RenderSettings settings = quickSettings();

    // Equal seeds and settings give bitwise equal images, whatever the output's type.
    const mlt::Image reference = mlt::render_image(scene, camera, settings);
    CHECK(reference.width == 16 && reference.height == 16 && reference.rgb.size() == 16 * 16 * 3);
    std::vector<float> vec(16 * 16 * 3);
    CHECK(mlt::render(scene, camera, settings, vec).completed());
    CHECK(vec == reference.rgb);
    std::array<float, 16 * 16 * 3> arr{};
    CHECK(mlt::render(scene, camera, settings, arr).completed());
    CHECK(std::vector<float>(arr.begin(), arr.end()) == reference.rgb);
    std::vector<float> bigger(16 * 16 * 3 + 5, -1.0f);
    CHECK(mlt::render(scene, camera, settings, mlt::Span<float>(bigger.data(), bigger.size()))
              .completed());
    CHECK(std::vector<float>(bigger.begin(), bigger.begin() + 16 * 16 * 3) == reference.rgb);
    CHECK(bigger.back() == -1.0f); // past the image: untouched
    const mlt::Span<const float> pixel = reference.pixel(3, 5);
    CHECK(pixel.size() == 3 && pixel.data() == reference.rgb.data() + (5 * 16 + 3) * 3);
    ok("render into std::vector, std::array and mlt::Span gives render_image's image");

    // Span conversions: non-const to const, containers, C arrays.
    float carray[4] = {1, 2, 3, 4};
    const mlt::Span<float> s(carray);
    const mlt::Span<const float> cs = s;
    CHECK(cs.size() == 4 && cs[3] == 4.0f && cs.data() == carray);
    static_assert(!std::is_convertible_v<mlt::Span<const float>, mlt::Span<float>>, "");
    static_assert(!std::is_convertible_v<const std::vector<float> &, mlt::Span<float>>, "");
    static_assert(!std::is_convertible_v<std::vector<float> &&, mlt::Span<float>>, "");
    static_assert(std::is_convertible_v<std::vector<float> &&, mlt::Span<const float>>, "");
    static_assert(!std::is_convertible_v<std::vector<double> &, mlt::Span<float>>, "");
    ok("mlt::Span converts from containers and C arrays, keeping const");

#if defined(__cpp_lib_span)
    // C++20: std::span in, std::span out.
    std::vector<float> storage(16 * 16 * 3);
    const std::span<float> out(storage);
    CHECK(mlt::render(scene, camera, settings, out).completed());
    CHECK(storage == reference.rgb);
    const std::span<const float> back = mlt::Span<const float>(reference.rgb);
    CHECK(back.data() == reference.rgb.data() && back.size() == reference.rgb.size());
    const std::span<float> fromTemporary = mlt::Span<float>(storage);
    CHECK(fromTemporary.size() == storage.size());
    ok("C++20: render into a std::span, and mlt::Span converts to std::span");
#else
    ok("C++17: mlt::Span without std::span");
#endif
}

void sceneOwnership() {
    const Ground ground;
    mlt::Scene a(ground.desc());
    CHECK(a && a.info().triangle_count == 2);
    const MltScene *raw = a.get();
    mlt::Scene b = std::move(a);
    CHECK(!a && b && b.get() == raw); // NOLINT(bugprone-use-after-move): checking it
    mlt::Scene c(ground.desc());
    c = std::move(b); // releases c's own scene
    CHECK(!b && c.get() == raw);
    MltScene *released = c.release();
    CHECK(!c && released == raw);
    mlt::Scene adopted = mlt::Scene::adopt(released);
    CHECK(adopted.info().triangle_count == 2);
    static_assert(std::is_nothrow_move_constructible_v<mlt::Scene>, "");
    {
        // Copies share the scene: it outlives the Scene it was copied from.
        mlt::Scene copy = adopted;
        CHECK(copy.get() == adopted.get());
        mlt::Scene other(ground.desc());
        other = copy;
        CHECK(other.get() == adopted.get());
        mlt::Scene last = std::move(copy);
        other = mlt::Scene();
        CHECK(last.info().triangle_count == 2);
    }
    CHECK(adopted.info().triangle_count == 2);

    const mlt::SceneInfo info = adopted.info();
    CHECK(info.emitter_count == 0 && info.degenerate_triangle_count == 0);
    CHECK(info.bounds_min == (mlt::Vec3{-1, 0, -1}) && info.bounds_max == (mlt::Vec3{1, 0, 1}));
    CHECK(info.backend == mlt::Backend::Bvh);

    // Ray queries through the C++ spans.
    const std::vector<mlt::Ray> rays{mlt::ray({0.5f, 1, 0.5f}, {0, -1, 0}),
                                     mlt::ray({0.5f, 1, 0.5f}, {0, 1, 0}),
                                     mlt::segment({0.5f, 1, 0.5f}, {0.5f, 0, 0.5f}, 0.0f, 0.5f)};
    const std::vector<mlt::Hit> hits = adopted.intersect(rays);
    CHECK(mlt::is_hit(hits[0]) && std::fabs(hits[0].t - 1.0f) < 1e-5f && !mlt::is_hit(hits[1]));
    CHECK(hits[1].triangle_id == mlt::invalid_id && std::isinf(hits[1].t));
    const std::vector<bool> blocked = adopted.occluded(rays);
    CHECK(blocked[0] && !blocked[1] && !blocked[2]);
    std::array<std::uint8_t, 3> flags{};
    adopted.occluded(rays, flags);
    CHECK(flags[0] == 1 && flags[1] == 0 && flags[2] == 0);
    ok("mlt::Scene moves, copies (sharing), releases and adopts its handle; ray queries answer");
}

void splitRenders() {
    const Ground ground;
    const mlt::Scene scene(ground.desc());
    const mlt::Camera camera = topCamera();
    const mlt::RenderSettings settings = quickSettings();
    const mlt::Image whole = mlt::render_image(scene, camera, settings);

    // Plan, three jobs (their bytes kept in mlt::Bytes or copied into vectors, as a host
    // receiving them from other machines has them), merged in another order.
    const mlt::Bytes plan = mlt::render_plan(scene, camera, settings);
    CHECK(!plan.empty() && plan.size() == plan.to_vector().size());
    std::vector<mlt::Bytes> owned;
    std::vector<std::vector<std::uint8_t>> copied;
    for (std::uint32_t job = 0; job < 3; ++job) {
        mlt::JobResult result = mlt::render_job(scene, plan, job, 3, job % 2);
        CHECK(result.result.completed() && result.result.stats.samples > 0);
        copied.push_back(result.partial.to_vector());
        owned.push_back(std::move(result.partial));
        CHECK(result.partial.empty()); // NOLINT(bugprone-use-after-move): checking it
    }
    std::vector<float> merged(whole.rgb.size());
    std::reverse(owned.begin(), owned.end());
    const mlt::RenderResult result = mlt::render_merge(plan, owned, merged);
    CHECK(result.completed() && result.stats.samples == whole.result.stats.samples);
    CHECK(merged == whole.rgb);
    std::vector<float> fromCopies(whole.rgb.size());
    const std::vector<mlt::Span<const std::uint8_t>> spans{copied[1], copied[2], copied[0]};
    CHECK(mlt::render_merge(plan.to_vector(), spans, fromCopies).completed());
    CHECK(fromCopies == whole.rgb);
    // Two partial results combined into one, merged with the third.
    const std::vector<mlt::Span<const std::uint8_t>> firstTwo{copied[1], copied[0]};
    const mlt::Bytes pair = mlt::render_combine(plan, firstTwo);
    CHECK(!pair.empty());
    std::vector<float> fromPair(whole.rgb.size());
    const std::vector<mlt::Span<const std::uint8_t>> pairAndLast{copied[2], pair};
    CHECK(mlt::render_merge(plan, pairAndLast, fromPair).completed());
    CHECK(fromPair == whole.rgb);
    expectError([&] { mlt::render_combine(plan, std::vector<mlt::Span<const std::uint8_t>>{pair, copied[0]}); },
                mlt::Status::InvalidArgument, "job 0 of 3 is given twice", __LINE__);
    ok("mlt::render_plan, render_job, render_combine and render_merge: 3 jobs merge into "
       "render's image");

    // Bad input throws, and a progress lambda cancels a job, which still gives its part.
    copied[1][copied[1].size() / 2] ^= 1;
    expectError([&] { mlt::render_merge(plan, copied, merged); },
                mlt::Status::InvalidArgument, "partials[1]", __LINE__);
    expectError([&] { mlt::render_merge(plan, std::vector<mlt::Bytes>(), merged); },
                mlt::Status::InvalidArgument, "partial_count is 0", __LINE__);
    expectError([&] { mlt::render_job(scene, plan, 3, 3); }, mlt::Status::InvalidArgument,
                "job 3 does not exist", __LINE__);
    const mlt::Bytes long_plan = mlt::render_plan(scene, camera, longSettings());
    const mlt::JobResult cancelled =
        mlt::render_job(scene, long_plan, 0, 2, 1, [](const mlt::Progress &) { return false; });
    CHECK(cancelled.result.status == mlt::Status::Cancelled && !cancelled.partial.empty());
    CHECK(contains(cancelled.result.message, "job 0 of 2"));
    static_assert(std::is_nothrow_move_constructible_v<mlt::Bytes>, "");
    static_assert(!std::is_copy_constructible_v<mlt::Bytes>, "");
    mlt::Bytes moved = mlt::render_plan(scene, camera, settings);
    MltBytes raw = moved.release();
    CHECK(moved.empty() && raw.data != nullptr);
    const mlt::Bytes adopted = mlt::Bytes::adopt(raw);
    CHECK(adopted.size() == plan.size());
    ok("split renders throw on bad input; a cancelled job gives its partial result; mlt::Bytes owns its bytes");
}

} // namespace

int main() try {
    defaultsAreTheLibrarys();
    errorsCarryStatusAndMessage();
    callbacks();
    textureCoordinateSets();
    spansAndImages();
    sceneOwnership();
    splitRenders();
    std::cout << "all checks passed (C++" << (__cplusplus / 100) % 100 << ")\n";
    return 0;
} catch (const std::exception &e) {
    std::cerr << "unexpected exception: " << e.what() << "\n";
    return 1;
}
