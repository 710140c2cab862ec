// parameters.cpp: every render setting as C (mlt.h) and C++ (mlt.hpp) see it. tests/c_hosts.rs
// runs it and compares each line with the declarations in src/render/settings.rs, from which
// tests/parameters.rs generates the checks below.
// Prints "<language> <setting> <value>" for each default, and
// "<language> <setting> message <text>" for the message of an out-of-range value, set in
// the C struct or through the C++ wrapper.
//
// Usage:  parameters

#include <mlt.hpp>

#include <array>
#include <cinttypes>
#include <cstdint>
#include <cstdio>

namespace {

void show(const char *language, const char *name, std::uint32_t v) {
    std::printf("%s %s %" PRIu32 "\n", language, name, v);
}
void show(const char *language, const char *name, std::uint64_t v) {
    std::printf("%s %s %" PRIu64 "\n", language, name, v);
}
void show(const char *language, const char *name, std::int32_t v) {
    std::printf("%s %s %" PRId32 "\n", language, name, v);
}
void show(const char *language, const char *name, bool v) {
    std::printf("%s %s %d\n", language, name, v ? 1 : 0);
}
void show(const char *language, const char *name, mlt::Algorithm v) {
    show(language, name, mlt::detail::c_value(v));
}
void show(const char *language, const char *name, float v) {
    std::printf("%s %s %.9g\n", language, name, double(v));
}
void show(const char *language, const char *name, double v) {
    std::printf("%s %s %.17g\n", language, name, v);
}
void show(const char *language, const char *name, const float (&v)[4]) {
    std::printf("%s %s %.9g %.9g %.9g %.9g\n", language, name, double(v[0]), double(v[1]),
                double(v[2]), double(v[3]));
}
void show(const char *language, const char *name, const std::array<float, 4> &v) {
    std::printf("%s %s %.9g %.9g %.9g %.9g\n", language, name, double(v[0]), double(v[1]),
                double(v[2]), double(v[3]));
}

/// The message of rendering `scene` with `settings` (validation fails before any pixel).
void message(const char *language, const char *name, const MltScene *scene,
             const MltRenderSettings &settings) {
    MltCamera camera;
    mlt_camera_default(&camera);
    const MltStatus status =
        mlt_render(scene, &camera, &settings, nullptr, 0, nullptr, nullptr);
    std::printf("%s %s message %s\n", language, name,
                status == MLT_STATUS_OK ? "(accepted)" : mlt_last_error_message());
}

}  // namespace

int main() {
    // One triangle: validation needs a scene, not what is in it.
    const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const std::uint32_t indices[3] = {0, 1, 2};
    MltMaterial material;
    mlt_material_default(&material);
    MltSceneDesc desc;
    mlt_scene_desc_default(&desc);
    desc.positions = positions;
    desc.positions_len = 9;
    desc.indices = indices;
    desc.indices_len = 3;
    desc.materials = &material;
    desc.materials_len = 1;
    MltScene *scene = nullptr;
    if (mlt_scene_create(&desc, &scene) != MLT_STATUS_OK) {
        std::printf("mlt_scene_create: %s\n", mlt_last_error_message());
        return 1;
    }
    MltRenderSettings c;
    mlt_render_settings_default(&c);
    const mlt::RenderSettings cpp;
    // BEGIN GENERATED checks: tests/parameters.rs writes these lines from src/render/settings.rs
    show("c", "width", c.width);
    show("c++", "width", cpp.width);
    show("c", "height", c.height);
    show("c++", "height", cpp.height);
    show("c", "algorithm", c.algorithm);
    show("c++", "algorithm", cpp.algorithm);
    show("c", "samples_per_pixel", c.samples_per_pixel);
    show("c++", "samples_per_pixel", cpp.samples_per_pixel);
    show("c", "max_depth", c.max_depth);
    show("c++", "max_depth", cpp.max_depth);
    show("c", "threads", c.threads);
    show("c++", "threads", cpp.threads);
    show("c", "seed", c.seed);
    show("c++", "seed", cpp.seed);
    show("c", "time_limit_seconds", c.time_limit_seconds);
    show("c++", "time_limit_seconds", cpp.time_limit_seconds);
    show("c", "mutations_per_pixel", c.mutations_per_pixel);
    show("c++", "mutations_per_pixel", cpp.mutations_per_pixel);
    show("c", "bootstrap_samples", c.bootstrap_samples);
    show("c++", "bootstrap_samples", cpp.bootstrap_samples);
    show("c", "chains", c.chains);
    show("c++", "chains", cpp.chains);
    show("c", "large_step_probability", c.large_step_probability);
    show("c++", "large_step_probability", cpp.large_step_probability);
    show("c", "small_step_sigma", c.small_step_sigma);
    show("c++", "small_step_sigma", cpp.small_step_sigma);
    show("c", "direct_samples_per_mutation", c.direct_samples_per_mutation);
    show("c++", "direct_samples_per_mutation", cpp.direct_samples_per_mutation);
    show("c", "mutation_weights", c.mutation_weights);
    show("c++", "mutation_weights", cpp.mutation_weights);
    show("c", "erpt_chain_length", c.erpt_chain_length);
    show("c++", "erpt_chain_length", cpp.erpt_chain_length);
    show("c", "erpt_deposit_energy", c.erpt_deposit_energy);
    show("c++", "erpt_deposit_energy", cpp.erpt_deposit_energy);
    show("c", "adapt_mutation_weights", c.adapt_mutation_weights);
    show("c++", "adapt_mutation_weights", cpp.adapt_mutation_weights);
    show("c", "perturb_in_sample_space", c.perturb_in_sample_space);
    show("c++", "perturb_in_sample_space", cpp.perturb_in_sample_space);
    show("c", "filter_buffers", c.filter_buffers);
    show("c++", "filter_buffers", cpp.filter_buffers);
    show("c", "filter_strength", c.filter_strength);
    show("c++", "filter_strength", cpp.filter_strength);
    show("c", "filter_radius", c.filter_radius);
    show("c++", "filter_radius", cpp.filter_radius);
    show("c", "normalization_work_fraction", c.normalization_work_fraction);
    show("c++", "normalization_work_fraction", cpp.normalization_work_fraction);
    show("c", "spectral", c.spectral);
    show("c++", "spectral", cpp.spectral);
    show("c", "roulette_start_depth", c.roulette_start_depth);
    show("c++", "roulette_start_depth", cpp.roulette_start_depth);
    show("c", "roulette_max_survival", c.roulette_max_survival);
    show("c++", "roulette_max_survival", cpp.roulette_max_survival);
    {
        mlt::RenderSettings s;
        s.width = 0;
        message("c++", "width", scene, s.to_c());
        MltRenderSettings cs = c;
        cs.width = 0;
        message("c", "width", scene, cs);
    }
    {
        mlt::RenderSettings s;
        s.height = 0;
        message("c++", "height", scene, s.to_c());
        MltRenderSettings cs = c;
        cs.height = 0;
        message("c", "height", scene, cs);
    }
    {
        mlt::RenderSettings s;
        s.samples_per_pixel = 16777217;
        message("c++", "samples_per_pixel", scene, s.to_c());
        MltRenderSettings cs = c;
        cs.samples_per_pixel = 16777217;
        message("c", "samples_per_pixel", scene, cs);
    }
    {
        mlt::RenderSettings s;
        s.max_depth = 1025;
        message("c++", "max_depth", scene, s.to_c());
        MltRenderSettings cs = c;
        cs.max_depth = 1025;
        message("c", "max_depth", scene, cs);
    }
    {
        mlt::RenderSettings s;
        s.threads = 4097;
        message("c++", "threads", scene, s.to_c());
        MltRenderSettings cs = c;
        cs.threads = 4097;
        message("c", "threads", scene, cs);
    }
    {
        mlt::RenderSettings s;
        s.time_limit_seconds = 20000000.0;
        message("c++", "time_limit_seconds", scene, s.to_c());
        MltRenderSettings cs = c;
        cs.time_limit_seconds = 20000000.0;
        message("c", "time_limit_seconds", scene, cs);
    }
    {
        mlt::RenderSettings s;
        s.mutations_per_pixel = 16777217;
        message("c++", "mutations_per_pixel", scene, s.to_c());
        MltRenderSettings cs = c;
        cs.mutations_per_pixel = 16777217;
        message("c", "mutations_per_pixel", scene, cs);
    }
    {
        mlt::RenderSettings s;
        s.bootstrap_samples = 268435457;
        message("c++", "bootstrap_samples", scene, s.to_c());
        MltRenderSettings cs = c;
        cs.bootstrap_samples = 268435457;
        message("c", "bootstrap_samples", scene, cs);
    }
    {
        mlt::RenderSettings s;
        s.chains = 0;
        message("c++", "chains", scene, s.to_c());
        MltRenderSettings cs = c;
        cs.chains = 0;
        message("c", "chains", scene, cs);
    }
    {
        mlt::RenderSettings s;
        s.large_step_probability = 2.0f;
        message("c++", "large_step_probability", scene, s.to_c());
        MltRenderSettings cs = c;
        cs.large_step_probability = 2.0f;
        message("c", "large_step_probability", scene, cs);
    }
    {
        mlt::RenderSettings s;
        s.small_step_sigma = 0.0f;
        message("c++", "small_step_sigma", scene, s.to_c());
        MltRenderSettings cs = c;
        cs.small_step_sigma = 0.0f;
        message("c", "small_step_sigma", scene, cs);
    }
    {
        mlt::RenderSettings s;
        s.mutation_weights = {2e6f, 0.25f, 0.25f, 0.25f};
        message("c++", "mutation_weights", scene, s.to_c());
        MltRenderSettings cs = c;
        const std::array<float, 4> bad{2e6f, 0.25f, 0.25f, 0.25f};
        for (int i = 0; i < 4; ++i) cs.mutation_weights[i] = bad[i];
        message("c", "mutation_weights", scene, cs);
    }
    {
        mlt::RenderSettings s;
        s.erpt_chain_length = 0;
        message("c++", "erpt_chain_length", scene, s.to_c());
        MltRenderSettings cs = c;
        cs.erpt_chain_length = 0;
        message("c", "erpt_chain_length", scene, cs);
    }
    {
        mlt::RenderSettings s;
        s.erpt_deposit_energy = 2e30f;
        message("c++", "erpt_deposit_energy", scene, s.to_c());
        MltRenderSettings cs = c;
        cs.erpt_deposit_energy = 2e30f;
        message("c", "erpt_deposit_energy", scene, cs);
    }
    {
        mlt::RenderSettings s;
        s.filter_buffers = 1;
        message("c++", "filter_buffers", scene, s.to_c());
        MltRenderSettings cs = c;
        cs.filter_buffers = 1;
        message("c", "filter_buffers", scene, cs);
    }
    {
        mlt::RenderSettings s;
        s.filter_strength = 0.0f;
        message("c++", "filter_strength", scene, s.to_c());
        MltRenderSettings cs = c;
        cs.filter_strength = 0.0f;
        message("c", "filter_strength", scene, cs);
    }
    {
        mlt::RenderSettings s;
        s.filter_radius = 0;
        message("c++", "filter_radius", scene, s.to_c());
        MltRenderSettings cs = c;
        cs.filter_radius = 0;
        message("c", "filter_radius", scene, cs);
    }
    {
        mlt::RenderSettings s;
        s.normalization_work_fraction = 1.8f;
        message("c++", "normalization_work_fraction", scene, s.to_c());
        MltRenderSettings cs = c;
        cs.normalization_work_fraction = 1.8f;
        message("c", "normalization_work_fraction", scene, cs);
    }
    {
        mlt::RenderSettings s;
        s.roulette_start_depth = 1025;
        message("c++", "roulette_start_depth", scene, s.to_c());
        MltRenderSettings cs = c;
        cs.roulette_start_depth = 1025;
        message("c", "roulette_start_depth", scene, cs);
    }
    {
        mlt::RenderSettings s;
        s.roulette_max_survival = 0.0f;
        message("c++", "roulette_max_survival", scene, s.to_c());
        MltRenderSettings cs = c;
        cs.roulette_max_survival = 0.0f;
        message("c", "roulette_max_survival", scene, cs);
    }
    // END GENERATED checks
    mlt_scene_release(scene);
    return 0;
}
