// parameters.cpp: every render setting and material parameter as C (mlt.h) and C++ (mlt.hpp)
// see it. tests/c_hosts.rs runs it and compares each line with the declarations in
// src/render/settings.rs and src/scene/material.rs, from which tests/parameters.rs generates
// the checks below.
// Prints "<language> <name> <value>" for each default (a material's name is
// "material.<parameter>"), and "<language> <name> message <text>" for the message of an
// out-of-range value, set in the C struct or through the C++ wrapper.
//
// Usage:  parameters

#include <mlt.hpp>

#include <array>
#include <cinttypes>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <type_traits>

// BEGIN GENERATED constants: tests/parameters.rs writes these lines from the declarations
static_assert(MLT_ALGORITHM_PATH == 0 && MLT_ALGORITHM_BDPT == 1 && MLT_ALGORITHM_PSSMLT == 2 && MLT_ALGORITHM_MMLT == 3 && MLT_ALGORITHM_PSSMLT_BDPT == 4 && MLT_ALGORITHM_PATH_SPACE_MLT == 5 && MLT_ALGORITHM_ERPT == 6, "MLT_ALGORITHM_* are 0, 1, ... in the declared order");
static_assert(MLT_MATERIAL_DIFFUSE == 0 && MLT_MATERIAL_MIRROR == 1 && MLT_MATERIAL_DIELECTRIC == 2 && MLT_MATERIAL_METALLIC_ROUGHNESS == 3, "MLT_MATERIAL_* are 0, 1, ... in the declared order");
static_assert(MLT_ALPHA_OPAQUE == 0 && MLT_ALPHA_MASK == 1 && MLT_ALPHA_BLEND == 2, "MLT_ALPHA_* are 0, 1, ... in the declared order");
// END GENERATED constants

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
template <class E, class = std::enable_if_t<std::is_enum<E>::value>>
void show(const char *language, const char *name, E v) {
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
void show(const char *language, const char *name, const float (&v)[3]) {
    std::printf("%s %s %.9g %.9g %.9g\n", language, name, double(v[0]), double(v[1]),
                double(v[2]));
}
void show(const char *language, const char *name, const std::array<float, 3> &v) {
    std::printf("%s %s %.9g %.9g %.9g\n", language, name, double(v[0]), double(v[1]),
                double(v[2]));
}
/// A texture slot: its texture's index (-1: none).
void show(const char *language, const char *name, const MltTextureRef &v) {
    show(language, name, v.texture);
}
void show(const char *language, const char *name, const mlt::TextureRef &v) {
    show(language, name, v.texture);
}

/// One triangle: validation needs a scene, not what is in it.
const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
const std::uint32_t indices[3] = {0, 1, 2};

/// The status of creating the one-triangle scene with `material`; `scene` receives it.
MltStatus create_scene(const MltMaterial &material, MltScene **scene) {
    MltSceneDesc desc;
    mlt_scene_desc_default(&desc);
    desc.positions = positions;
    desc.positions_len = 9;
    desc.indices = indices;
    desc.indices_len = 3;
    desc.materials = &material;
    desc.materials_len = 1;
    return mlt_scene_create(&desc, scene);
}

/// The one-triangle scene every settings check renders.
MltScene *scene = nullptr;

void print_message(const char *language, const char *name, MltStatus status) {
    std::printf("%s %s message %s\n", language, name,
                status == MLT_STATUS_OK ? "(accepted)" : mlt_last_error_message());
}

/// The message of rendering the scene with `settings` (validation fails before any pixel).
void message(const char *language, const char *name, const MltRenderSettings &settings) {
    MltCamera camera;
    mlt_camera_default(&camera);
    print_message(language, name,
                  mlt_render(scene, &camera, &settings, nullptr, 0, nullptr, nullptr));
}

/// The message of creating a scene with `material`.
void message(const char *language, const char *name, const MltMaterial &material) {
    MltScene *created = nullptr;
    const MltStatus status = create_scene(material, &created);
    mlt_scene_release(created);
    print_message(language, name, status);
}

void check_settings() {
    MltRenderSettings c;
    mlt_render_settings_default(&c);
    const mlt::RenderSettings cpp;
    // BEGIN GENERATED settings checks: tests/parameters.rs writes these lines from src/render/settings.rs
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
    show("c", "full_resolution_textures", c.full_resolution_textures);
    show("c++", "full_resolution_textures", cpp.full_resolution_textures);
    {
        mlt::RenderSettings s;
        s.width = 0;
        message("c++", "width", s.to_c());
        MltRenderSettings cs = c;
        cs.width = 0;
        message("c", "width", cs);
    }
    {
        mlt::RenderSettings s;
        s.height = 0;
        message("c++", "height", s.to_c());
        MltRenderSettings cs = c;
        cs.height = 0;
        message("c", "height", cs);
    }
    {
        mlt::RenderSettings s;
        s.samples_per_pixel = 16777217;
        message("c++", "samples_per_pixel", s.to_c());
        MltRenderSettings cs = c;
        cs.samples_per_pixel = 16777217;
        message("c", "samples_per_pixel", cs);
    }
    {
        mlt::RenderSettings s;
        s.max_depth = 1025;
        message("c++", "max_depth", s.to_c());
        MltRenderSettings cs = c;
        cs.max_depth = 1025;
        message("c", "max_depth", cs);
    }
    {
        mlt::RenderSettings s;
        s.threads = 4097;
        message("c++", "threads", s.to_c());
        MltRenderSettings cs = c;
        cs.threads = 4097;
        message("c", "threads", cs);
    }
    {
        mlt::RenderSettings s;
        s.time_limit_seconds = 20000000.0;
        message("c++", "time_limit_seconds", s.to_c());
        MltRenderSettings cs = c;
        cs.time_limit_seconds = 20000000.0;
        message("c", "time_limit_seconds", cs);
    }
    {
        mlt::RenderSettings s;
        s.mutations_per_pixel = 16777217;
        message("c++", "mutations_per_pixel", s.to_c());
        MltRenderSettings cs = c;
        cs.mutations_per_pixel = 16777217;
        message("c", "mutations_per_pixel", cs);
    }
    {
        mlt::RenderSettings s;
        s.bootstrap_samples = 268435457;
        message("c++", "bootstrap_samples", s.to_c());
        MltRenderSettings cs = c;
        cs.bootstrap_samples = 268435457;
        message("c", "bootstrap_samples", cs);
    }
    {
        mlt::RenderSettings s;
        s.chains = 0;
        message("c++", "chains", s.to_c());
        MltRenderSettings cs = c;
        cs.chains = 0;
        message("c", "chains", cs);
    }
    {
        mlt::RenderSettings s;
        s.large_step_probability = 2.0f;
        message("c++", "large_step_probability", s.to_c());
        MltRenderSettings cs = c;
        cs.large_step_probability = 2.0f;
        message("c", "large_step_probability", cs);
    }
    {
        mlt::RenderSettings s;
        s.small_step_sigma = 0.0f;
        message("c++", "small_step_sigma", s.to_c());
        MltRenderSettings cs = c;
        cs.small_step_sigma = 0.0f;
        message("c", "small_step_sigma", cs);
    }
    {
        mlt::RenderSettings s;
        s.mutation_weights = {2e6f, 0.25f, 0.25f, 0.25f};
        message("c++", "mutation_weights", s.to_c());
        MltRenderSettings cs = c;
        const std::array<float, 4> bad{2e6f, 0.25f, 0.25f, 0.25f};
        for (std::size_t i = 0; i < bad.size(); ++i) cs.mutation_weights[i] = bad[i];
        message("c", "mutation_weights", cs);
    }
    {
        mlt::RenderSettings s;
        s.erpt_chain_length = 0;
        message("c++", "erpt_chain_length", s.to_c());
        MltRenderSettings cs = c;
        cs.erpt_chain_length = 0;
        message("c", "erpt_chain_length", cs);
    }
    {
        mlt::RenderSettings s;
        s.erpt_deposit_energy = 2e30f;
        message("c++", "erpt_deposit_energy", s.to_c());
        MltRenderSettings cs = c;
        cs.erpt_deposit_energy = 2e30f;
        message("c", "erpt_deposit_energy", cs);
    }
    {
        mlt::RenderSettings s;
        s.filter_buffers = 1;
        message("c++", "filter_buffers", s.to_c());
        MltRenderSettings cs = c;
        cs.filter_buffers = 1;
        message("c", "filter_buffers", cs);
    }
    {
        mlt::RenderSettings s;
        s.filter_strength = 0.0f;
        message("c++", "filter_strength", s.to_c());
        MltRenderSettings cs = c;
        cs.filter_strength = 0.0f;
        message("c", "filter_strength", cs);
    }
    {
        mlt::RenderSettings s;
        s.filter_radius = 0;
        message("c++", "filter_radius", s.to_c());
        MltRenderSettings cs = c;
        cs.filter_radius = 0;
        message("c", "filter_radius", cs);
    }
    {
        mlt::RenderSettings s;
        s.normalization_work_fraction = 1.8f;
        message("c++", "normalization_work_fraction", s.to_c());
        MltRenderSettings cs = c;
        cs.normalization_work_fraction = 1.8f;
        message("c", "normalization_work_fraction", cs);
    }
    {
        mlt::RenderSettings s;
        s.roulette_start_depth = 1025;
        message("c++", "roulette_start_depth", s.to_c());
        MltRenderSettings cs = c;
        cs.roulette_start_depth = 1025;
        message("c", "roulette_start_depth", cs);
    }
    {
        mlt::RenderSettings s;
        s.roulette_max_survival = 0.0f;
        message("c++", "roulette_max_survival", s.to_c());
        MltRenderSettings cs = c;
        cs.roulette_max_survival = 0.0f;
        message("c", "roulette_max_survival", cs);
    }
    // END GENERATED settings checks
}

void check_materials() {
    MltMaterial c;
    mlt_material_default(&c);
    const mlt::Material cpp;
    // BEGIN GENERATED material checks: tests/parameters.rs writes these lines from src/scene/material.rs
    show("c", "material.kind", c.kind);
    show("c++", "material.kind", cpp.kind);
    show("c", "material.color", c.color);
    show("c++", "material.color", cpp.color);
    show("c", "material.emission", c.emission);
    show("c++", "material.emission", cpp.emission);
    show("c", "material.ior", c.ior);
    show("c++", "material.ior", cpp.ior);
    show("c", "material.metallic", c.metallic);
    show("c++", "material.metallic", cpp.metallic);
    show("c", "material.roughness", c.roughness);
    show("c++", "material.roughness", cpp.roughness);
    show("c", "material.transmission", c.transmission);
    show("c++", "material.transmission", cpp.transmission);
    show("c", "material.alpha", c.alpha);
    show("c++", "material.alpha", cpp.alpha);
    show("c", "material.alpha_mode", c.alpha_mode);
    show("c++", "material.alpha_mode", cpp.alpha_mode);
    show("c", "material.alpha_cutoff", c.alpha_cutoff);
    show("c++", "material.alpha_cutoff", cpp.alpha_cutoff);
    show("c", "material.base_color_texture", c.base_color_texture);
    show("c++", "material.base_color_texture", cpp.base_color_texture);
    show("c", "material.metallic_roughness_texture", c.metallic_roughness_texture);
    show("c++", "material.metallic_roughness_texture", cpp.metallic_roughness_texture);
    show("c", "material.normal_texture", c.normal_texture);
    show("c++", "material.normal_texture", cpp.normal_texture);
    show("c", "material.emission_texture", c.emission_texture);
    show("c++", "material.emission_texture", cpp.emission_texture);
    show("c", "material.normal_scale", c.normal_scale);
    show("c++", "material.normal_scale", cpp.normal_scale);
    show("c", "material.energy_compensation", c.energy_compensation);
    show("c++", "material.energy_compensation", cpp.energy_compensation);
    show("c", "material.abbe_number", c.abbe_number);
    show("c++", "material.abbe_number", cpp.abbe_number);
    show("c", "material.transmission_texture", c.transmission_texture);
    show("c++", "material.transmission_texture", cpp.transmission_texture);
    show("c", "material.clearcoat", c.clearcoat);
    show("c++", "material.clearcoat", cpp.clearcoat);
    show("c", "material.clearcoat_roughness", c.clearcoat_roughness);
    show("c++", "material.clearcoat_roughness", cpp.clearcoat_roughness);
    show("c", "material.clearcoat_texture", c.clearcoat_texture);
    show("c++", "material.clearcoat_texture", cpp.clearcoat_texture);
    show("c", "material.clearcoat_roughness_texture", c.clearcoat_roughness_texture);
    show("c++", "material.clearcoat_roughness_texture", cpp.clearcoat_roughness_texture);
    show("c", "material.clearcoat_normal_texture", c.clearcoat_normal_texture);
    show("c++", "material.clearcoat_normal_texture", cpp.clearcoat_normal_texture);
    show("c", "material.clearcoat_normal_scale", c.clearcoat_normal_scale);
    show("c++", "material.clearcoat_normal_scale", cpp.clearcoat_normal_scale);
    show("c", "material.thickness", c.thickness);
    show("c++", "material.thickness", cpp.thickness);
    show("c", "material.attenuation_color", c.attenuation_color);
    show("c++", "material.attenuation_color", cpp.attenuation_color);
    show("c", "material.attenuation_distance", c.attenuation_distance);
    show("c++", "material.attenuation_distance", cpp.attenuation_distance);
    show("c", "material.specular", c.specular);
    show("c++", "material.specular", cpp.specular);
    show("c", "material.specular_color", c.specular_color);
    show("c++", "material.specular_color", cpp.specular_color);
    show("c", "material.specular_texture", c.specular_texture);
    show("c++", "material.specular_texture", cpp.specular_texture);
    show("c", "material.specular_color_texture", c.specular_color_texture);
    show("c++", "material.specular_color_texture", cpp.specular_color_texture);
    show("c", "material.sheen_color", c.sheen_color);
    show("c++", "material.sheen_color", cpp.sheen_color);
    show("c", "material.sheen_roughness", c.sheen_roughness);
    show("c++", "material.sheen_roughness", cpp.sheen_roughness);
    show("c", "material.sheen_color_texture", c.sheen_color_texture);
    show("c++", "material.sheen_color_texture", cpp.sheen_color_texture);
    show("c", "material.sheen_roughness_texture", c.sheen_roughness_texture);
    show("c++", "material.sheen_roughness_texture", cpp.sheen_roughness_texture);
    show("c", "material.anisotropy", c.anisotropy);
    show("c++", "material.anisotropy", cpp.anisotropy);
    show("c", "material.anisotropy_rotation", c.anisotropy_rotation);
    show("c++", "material.anisotropy_rotation", cpp.anisotropy_rotation);
    show("c", "material.anisotropy_texture", c.anisotropy_texture);
    show("c++", "material.anisotropy_texture", cpp.anisotropy_texture);
    show("c", "material.iridescence", c.iridescence);
    show("c++", "material.iridescence", cpp.iridescence);
    show("c", "material.iridescence_texture", c.iridescence_texture);
    show("c++", "material.iridescence_texture", cpp.iridescence_texture);
    show("c", "material.iridescence_ior", c.iridescence_ior);
    show("c++", "material.iridescence_ior", cpp.iridescence_ior);
    show("c", "material.iridescence_thickness_minimum", c.iridescence_thickness_minimum);
    show("c++", "material.iridescence_thickness_minimum", cpp.iridescence_thickness_minimum);
    show("c", "material.iridescence_thickness_maximum", c.iridescence_thickness_maximum);
    show("c++", "material.iridescence_thickness_maximum", cpp.iridescence_thickness_maximum);
    show("c", "material.iridescence_thickness_texture", c.iridescence_thickness_texture);
    show("c++", "material.iridescence_thickness_texture", cpp.iridescence_thickness_texture);
    {
        mlt::Material s;
        s.color = {2.0f, 0.8f, 0.8f};
        message("c++", "material.color", s.to_c());
        MltMaterial cs = c;
        const std::array<float, 3> bad{2.0f, 0.8f, 0.8f};
        for (std::size_t i = 0; i < bad.size(); ++i) cs.color[i] = bad[i];
        message("c", "material.color", cs);
    }
    {
        mlt::Material s;
        s.emission = {-1.0f, 0.0f, 0.0f};
        message("c++", "material.emission", s.to_c());
        MltMaterial cs = c;
        const std::array<float, 3> bad{-1.0f, 0.0f, 0.0f};
        for (std::size_t i = 0; i < bad.size(); ++i) cs.emission[i] = bad[i];
        message("c", "material.emission", cs);
    }
    {
        mlt::Material s;
        s.metallic = 2.0f;
        message("c++", "material.metallic", s.to_c());
        MltMaterial cs = c;
        cs.metallic = 2.0f;
        message("c", "material.metallic", cs);
    }
    {
        mlt::Material s;
        s.roughness = 2.0f;
        message("c++", "material.roughness", s.to_c());
        MltMaterial cs = c;
        cs.roughness = 2.0f;
        message("c", "material.roughness", cs);
    }
    {
        mlt::Material s;
        s.transmission = 2.0f;
        message("c++", "material.transmission", s.to_c());
        MltMaterial cs = c;
        cs.transmission = 2.0f;
        message("c", "material.transmission", cs);
    }
    {
        mlt::Material s;
        s.alpha = 2.0f;
        message("c++", "material.alpha", s.to_c());
        MltMaterial cs = c;
        cs.alpha = 2.0f;
        message("c", "material.alpha", cs);
    }
    {
        mlt::Material s;
        s.alpha_cutoff = -1.0f;
        message("c++", "material.alpha_cutoff", s.to_c());
        MltMaterial cs = c;
        cs.alpha_cutoff = -1.0f;
        message("c", "material.alpha_cutoff", cs);
    }
    {
        mlt::Material s;
        s.abbe_number = -1.0f;
        message("c++", "material.abbe_number", s.to_c());
        MltMaterial cs = c;
        cs.abbe_number = -1.0f;
        message("c", "material.abbe_number", cs);
    }
    {
        mlt::Material s;
        s.clearcoat = 2.0f;
        message("c++", "material.clearcoat", s.to_c());
        MltMaterial cs = c;
        cs.clearcoat = 2.0f;
        message("c", "material.clearcoat", cs);
    }
    {
        mlt::Material s;
        s.clearcoat_roughness = 2.0f;
        message("c++", "material.clearcoat_roughness", s.to_c());
        MltMaterial cs = c;
        cs.clearcoat_roughness = 2.0f;
        message("c", "material.clearcoat_roughness", cs);
    }
    {
        mlt::Material s;
        s.thickness = -1.0f;
        message("c++", "material.thickness", s.to_c());
        MltMaterial cs = c;
        cs.thickness = -1.0f;
        message("c", "material.thickness", cs);
    }
    {
        mlt::Material s;
        s.attenuation_color = {2.0f, 1.0f, 1.0f};
        message("c++", "material.attenuation_color", s.to_c());
        MltMaterial cs = c;
        const std::array<float, 3> bad{2.0f, 1.0f, 1.0f};
        for (std::size_t i = 0; i < bad.size(); ++i) cs.attenuation_color[i] = bad[i];
        message("c", "material.attenuation_color", cs);
    }
    {
        mlt::Material s;
        s.attenuation_distance = 0.0f;
        message("c++", "material.attenuation_distance", s.to_c());
        MltMaterial cs = c;
        cs.attenuation_distance = 0.0f;
        message("c", "material.attenuation_distance", cs);
    }
    {
        mlt::Material s;
        s.specular = 2.0f;
        message("c++", "material.specular", s.to_c());
        MltMaterial cs = c;
        cs.specular = 2.0f;
        message("c", "material.specular", cs);
    }
    {
        mlt::Material s;
        s.specular_color = {-1.0f, 1.0f, 1.0f};
        message("c++", "material.specular_color", s.to_c());
        MltMaterial cs = c;
        const std::array<float, 3> bad{-1.0f, 1.0f, 1.0f};
        for (std::size_t i = 0; i < bad.size(); ++i) cs.specular_color[i] = bad[i];
        message("c", "material.specular_color", cs);
    }
    {
        mlt::Material s;
        s.sheen_color = {2.0f, 0.0f, 0.0f};
        message("c++", "material.sheen_color", s.to_c());
        MltMaterial cs = c;
        const std::array<float, 3> bad{2.0f, 0.0f, 0.0f};
        for (std::size_t i = 0; i < bad.size(); ++i) cs.sheen_color[i] = bad[i];
        message("c", "material.sheen_color", cs);
    }
    {
        mlt::Material s;
        s.sheen_roughness = 2.0f;
        message("c++", "material.sheen_roughness", s.to_c());
        MltMaterial cs = c;
        cs.sheen_roughness = 2.0f;
        message("c", "material.sheen_roughness", cs);
    }
    {
        mlt::Material s;
        s.anisotropy = 2.0f;
        message("c++", "material.anisotropy", s.to_c());
        MltMaterial cs = c;
        cs.anisotropy = 2.0f;
        message("c", "material.anisotropy", cs);
    }
    {
        mlt::Material s;
        s.iridescence = 2.0f;
        message("c++", "material.iridescence", s.to_c());
        MltMaterial cs = c;
        cs.iridescence = 2.0f;
        message("c", "material.iridescence", cs);
    }
    {
        mlt::Material s;
        s.iridescence_ior = 0.0f;
        message("c++", "material.iridescence_ior", s.to_c());
        MltMaterial cs = c;
        cs.iridescence_ior = 0.0f;
        message("c", "material.iridescence_ior", cs);
    }
    {
        mlt::Material s;
        s.iridescence_thickness_minimum = -1.0f;
        message("c++", "material.iridescence_thickness_minimum", s.to_c());
        MltMaterial cs = c;
        cs.iridescence_thickness_minimum = -1.0f;
        message("c", "material.iridescence_thickness_minimum", cs);
    }
    {
        mlt::Material s;
        s.iridescence_thickness_maximum = -1.0f;
        message("c++", "material.iridescence_thickness_maximum", s.to_c());
        MltMaterial cs = c;
        cs.iridescence_thickness_maximum = -1.0f;
        message("c", "material.iridescence_thickness_maximum", cs);
    }
    // END GENERATED material checks
}

}  // namespace

int main() {
    MltMaterial material;
    mlt_material_default(&material);
    if (create_scene(material, &scene) != MLT_STATUS_OK) {
        std::printf("mlt_scene_create: %s\n", mlt_last_error_message());
        return 1;
    }
    check_settings();
    check_materials();
    mlt_scene_release(scene);
    return 0;
}
