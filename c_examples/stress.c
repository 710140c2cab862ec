/*
 * stress.c: a host that misuses and overuses mlt, for runs under AddressSanitizer,
 * UndefinedBehaviorSanitizer and valgrind (tests/c_sanitizers.rs). It checks every status
 * it gets and exits non-zero on any surprise. Four phases:
 *   1. many scenes: random geometry, materials (textures, dispersion), environment, sun
 *      and lamps, each rendered with a random algorithm and tiny budget, some cancelled by
 *      the progress callback at a random call or stopped by a time limit, then released;
 *   2. concurrent renders and ray queries on one scene from several host threads, each
 *      holding its own reference (mlt_scene_retain), with the creator's reference released
 *      while they run; renders with equal settings must give equal images;
 *   3. a scene released by its only owner while renders on other threads are running:
 *      they finish normally, and afterwards the stale pointer is refused;
 *   4. every entry point with bad input: NULLs, unknown struct sizes, non-finite floats,
 *      out-of-range enums and indices, short buffers, released and foreign handles.
 *
 * Usage:  stress [seed] [scenes]   (defaults: 1 and 24)
 */

/* POSIX barriers (pthread_barrier_t) are not in strict C11 without this. */
#define _POSIX_C_SOURCE 200809L

#include <mlt.h>

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static atomic_int failures;

#define EXPECT(condition, ...)                                                           \
    do {                                                                                 \
        if (!(condition)) {                                                              \
            fprintf(stderr, "stress.c:%d: ", __LINE__);                                  \
            fprintf(stderr, __VA_ARGS__);                                                \
            fprintf(stderr, " [%s]\n", mlt_last_error_message());                        \
            atomic_fetch_add(&failures, 1);                                              \
        }                                                                                \
    } while (0)

#define EXPECT_OK(call) EXPECT((call) == MLT_STATUS_OK, "%s failed", #call)

/* A refusal must be INVALID_ARGUMENT with a message naming what was wrong. */
#define EXPECT_INVALID(call, needle)                                                     \
    do {                                                                                 \
        MltStatus status_ = (call);                                                      \
        EXPECT(status_ == MLT_STATUS_INVALID_ARGUMENT &&                                 \
                   strstr(mlt_last_error_message(), (needle)) != NULL,                   \
               "%s gave %d, not INVALID_ARGUMENT mentioning \"%s\"", #call, (int)status_, \
               (needle));                                                                \
    } while (0)

/* splitmix64: a small, good generator, one per thread. */
typedef struct Rng { uint64_t state; } Rng;

static uint64_t next_u64(Rng *rng) {
    uint64_t z = (rng->state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}
static uint32_t below(Rng *rng, uint32_t n) { return (uint32_t)(next_u64(rng) % n); }
static float uniform(Rng *rng) { return (float)(next_u64(rng) >> 40) / 16777216.0f; }

/* ------------------------------------------------------------------------------------- */
/* Random scenes: a bumpy floor of quads under a ceiling lamp, in arrays the host owns.   */
/* ------------------------------------------------------------------------------------- */

enum { MAX_GRID = 8, MAX_QUADS = MAX_GRID * MAX_GRID + 1, MAX_MATERIALS = 5 };

typedef struct HostScene {
    float positions[MAX_QUADS * 4 * 3];
    float texcoords[MAX_QUADS * 4 * 2];
    uint32_t indices[MAX_QUADS * 6];
    uint32_t material_ids[MAX_QUADS * 2];
    MltMaterial materials[MAX_MATERIALS];
    uint8_t texels[4 * 4 * 4];
    MltTexture texture;
    float environment_pixels[8 * 4 * 3];
    MltEnvironment environment;
    MltSun sun;
    MltPunctualLight lamp;
    MltSceneDesc desc;
    uint32_t triangles;
} HostScene;

static void add_quad(HostScene *s, uint32_t quad, const float corners[12], uint32_t material) {
    uint32_t a = quad * 4, k;
    static const float uv[8] = {0, 0, 1, 0, 1, 1, 0, 1};
    memcpy(s->positions + a * 3, corners, 12 * sizeof(float));
    memcpy(s->texcoords + a * 2, uv, sizeof uv);
    for (k = 0; k < 3; ++k) s->indices[quad * 6 + k] = a + k;
    s->indices[quad * 6 + 3] = a;
    s->indices[quad * 6 + 4] = a + 2;
    s->indices[quad * 6 + 5] = a + 3;
    s->material_ids[quad * 2] = s->material_ids[quad * 2 + 1] = material;
}

/* Fills `s` with a random scene; `s->desc` points into it. */
static void random_scene(HostScene *s, Rng *rng) {
    uint32_t grid = 1 + below(rng, MAX_GRID), i, j, m;
    float height[MAX_GRID + 1][MAX_GRID + 1];
    memset(s, 0, sizeof *s);
    for (i = 0; i <= grid; ++i)
        for (j = 0; j <= grid; ++j) height[i][j] = 0.2f * uniform(rng);
    for (i = 0; i < grid; ++i)
        for (j = 0; j < grid; ++j) {
            float x0 = -1 + 2.0f * (float)i / (float)grid, x1 = -1 + 2.0f * (float)(i + 1) / (float)grid;
            float z0 = -1 + 2.0f * (float)j / (float)grid, z1 = -1 + 2.0f * (float)(j + 1) / (float)grid;
            const float corners[12] = {x0, height[i][j],     z0, x0, height[i][j + 1], z1,
                                       x1, height[i + 1][j + 1], z1, x1, height[i + 1][j], z0};
            add_quad(s, i * grid + j, corners, below(rng, MAX_MATERIALS - 1));
        }
    {
        /* The lamp faces down. */
        const float lamp[12] = {-0.3f, 1.5f, -0.3f, 0.3f, 1.5f, -0.3f, 0.3f, 1.5f, 0.3f, -0.3f, 1.5f, 0.3f};
        add_quad(s, grid * grid, lamp, MAX_MATERIALS - 1);
    }
    s->triangles = (grid * grid + 1) * 2;

    for (i = 0; i < sizeof s->texels; ++i) s->texels[i] = (uint8_t)below(rng, 256);
    EXPECT_OK(mlt_texture_default(&s->texture));
    s->texture.width = s->texture.height = 4;
    s->texture.channels = 4;
    s->texture.texel_type = MLT_TEXEL_U8;
    s->texture.texels = s->texels;
    s->texture.filter = below(rng, 2) ? MLT_FILTER_BILINEAR : MLT_FILTER_NEAREST;

    for (m = 0; m < MAX_MATERIALS; ++m) {
        MltMaterial *material = &s->materials[m];
        EXPECT_OK(mlt_material_default(material));
        material->kind = (int32_t)below(rng, 4);
        for (i = 0; i < 3; ++i) material->color[i] = 0.2f + 0.7f * uniform(rng);
        material->roughness = uniform(rng);
        material->metallic = uniform(rng);
        if (material->kind == MLT_MATERIAL_DIELECTRIC) {
            material->ior = 1.2f + uniform(rng);
            if (below(rng, 2)) material->abbe_number = 20.0f + 40.0f * uniform(rng);
        }
        if (material->kind == MLT_MATERIAL_METALLIC_ROUGHNESS && below(rng, 2))
            material->base_color_texture.texture = 0;
    }
    s->materials[MAX_MATERIALS - 1].kind = MLT_MATERIAL_DIFFUSE;
    for (i = 0; i < 3; ++i) s->materials[MAX_MATERIALS - 1].emission[i] = 1.0f + 9.0f * uniform(rng);

    EXPECT_OK(mlt_scene_desc_default(&s->desc));
    s->desc.positions = s->positions;
    s->desc.positions_len = (size_t)s->triangles * 2 * 3;
    s->desc.indices = s->indices;
    s->desc.indices_len = (size_t)s->triangles * 3;
    s->desc.material_ids = s->material_ids;
    s->desc.material_ids_len = s->triangles;
    s->desc.materials = s->materials;
    s->desc.materials_len = MAX_MATERIALS;
    s->desc.texcoords = s->texcoords;
    s->desc.texcoords_len = (size_t)s->triangles * 2 * 2;
    s->desc.textures = &s->texture;
    s->desc.textures_len = 1;
    if (below(rng, 3) == 0) {
        for (i = 0; i < 8 * 4 * 3; ++i) s->environment_pixels[i] = uniform(rng);
        EXPECT_OK(mlt_environment_default(&s->environment));
        s->environment.pixels = s->environment_pixels;
        s->environment.width = 8;
        s->environment.height = 4;
        s->desc.environment = &s->environment;
    }
    if (below(rng, 3) == 0) {
        EXPECT_OK(mlt_sun_default(&s->sun));
        s->sun.direction[0] = uniform(rng) - 0.5f;
        s->sun.direction[1] = 1.0f;
        s->desc.sun = &s->sun;
    }
    if (below(rng, 3) == 0) {
        EXPECT_OK(mlt_punctual_light_default(&s->lamp));
        s->lamp.kind = (int32_t)below(rng, 3);
        s->lamp.position[1] = 1.0f;
        s->lamp.direction[1] = -1.0f;
        s->lamp.intensity[0] = s->lamp.intensity[1] = s->lamp.intensity[2] = 2.0f;
        s->desc.punctual_lights = &s->lamp;
        s->desc.punctual_lights_len = 1;
    }
}

static MltCamera looking_down(void) {
    MltCamera camera;
    EXPECT_OK(mlt_camera_default(&camera));
    camera.eye[0] = 0.0f;    camera.eye[1] = 1.2f;    camera.eye[2] = -2.5f;
    camera.target[0] = 0.0f; camera.target[1] = 0.1f; camera.target[2] = 0.0f;
    camera.up[0] = 0.0f;     camera.up[1] = 1.0f;     camera.up[2] = 0.0f;
    camera.fov_y_deg = 50.0f;
    return camera;
}

/* Random settings with budgets small enough for valgrind: at most 16 x 16 pixels, a few
 * samples or mutations per pixel, a small bootstrap. */
static MltRenderSettings random_settings(Rng *rng) {
    MltRenderSettings settings;
    EXPECT_OK(mlt_render_settings_default(&settings));
    settings.width = 4 + below(rng, 13);
    settings.height = 4 + below(rng, 13);
    settings.algorithm = (int32_t)below(rng, 7);
    settings.samples_per_pixel = 1 + below(rng, 4);
    settings.mutations_per_pixel = 1 + below(rng, 4);
    settings.bootstrap_samples = 256 + below(rng, 768);
    settings.chains = 4 + below(rng, 12);
    settings.max_depth = 1 + below(rng, 6);
    settings.threads = below(rng, 3);
    settings.seed = next_u64(rng);
    settings.spectral = below(rng, 3) == 0;
    /* The filter is for the Metropolis and ERPT images only. */
    if (settings.algorithm >= MLT_ALGORITHM_PSSMLT && below(rng, 3) == 0)
        settings.filter_buffers = 2 + below(rng, 3);
    settings.adapt_mutation_weights = below(rng, 4) == 0;
    settings.perturb_in_sample_space = below(rng, 4) == 0;
    settings.erpt_chain_length = 1 + below(rng, 8);
    return settings;
}

/* Cancels at the progress call numbered `cancel_at` (0: the first); never if negative. */
typedef struct Canceller { int calls, cancel_at; } Canceller;

static bool cancel_at_call(float fraction, void *user_data) {
    Canceller *c = (Canceller *)user_data;
    (void)fraction;
    return c->cancel_at < 0 || c->calls++ < c->cancel_at;
}

static int image_is_finite(const float *rgb, size_t len) {
    size_t i;
    for (i = 0; i < len; ++i)
        if (!isfinite(rgb[i])) return 0;
    return 1;
}

/* ------------------------------------------------------------------------------------- */
/* Phase 1: many scenes.                                                                  */
/* ------------------------------------------------------------------------------------- */

static void many_scenes(Rng *rng, int count) {
    static HostScene host;
    float rgb[16 * 16 * 3];
    int round;
    for (round = 0; round < count; ++round) {
        MltScene *scene = NULL;
        MltSceneInfo info;
        MltRenderSettings settings = random_settings(rng);
        MltCamera camera = looking_down();
        MltRenderStats stats;
        Canceller canceller = {0, -1};
        MltStatus status;
        size_t len = (size_t)settings.width * settings.height * 3;
        random_scene(&host, rng);
        if (mlt_scene_create(&host.desc, &scene) != MLT_STATUS_OK) {
            EXPECT(0, "round %d: mlt_scene_create refused a valid scene", round);
            continue;
        }
        EXPECT_OK(mlt_scene_info_default(&info));
        EXPECT_OK(mlt_scene_get_info(scene, &info));
        EXPECT(info.triangle_count == host.triangles, "round %d: %llu triangles, not %u", round,
               (unsigned long long)info.triangle_count, (unsigned)host.triangles);
        switch (below(rng, 4)) {
        case 0: canceller.cancel_at = (int)below(rng, 3); break;
        case 1: settings.time_limit_seconds = 0.001 * (1 + below(rng, 20)); break;
        default: break;
        }
        /* Cancels and time limits need a render long enough to be interrupted. */
        if (canceller.cancel_at >= 0 || settings.time_limit_seconds > 0) {
            settings.samples_per_pixel *= 64;
            settings.mutations_per_pixel *= 64;
        }
        EXPECT_OK(mlt_render_stats_default(&stats));
        status = mlt_render_ex(scene, &camera, &settings, rgb, len, cancel_at_call, &canceller,
                               &stats);
        EXPECT(status == MLT_STATUS_OK ||
                   (status == MLT_STATUS_CANCELLED && canceller.cancel_at >= 0) ||
                   (status == MLT_STATUS_TIME_LIMIT_REACHED && settings.time_limit_seconds > 0),
               "round %d: algorithm %d gave status %d", round, (int)settings.algorithm, (int)status);
        if (status == MLT_STATUS_OK || status == MLT_STATUS_CANCELLED ||
            status == MLT_STATUS_TIME_LIMIT_REACHED)
            EXPECT(image_is_finite(rgb, len), "round %d: non-finite pixels", round);
        mlt_scene_release(scene);
    }
}

/* ------------------------------------------------------------------------------------- */
/* Phase 2: several host threads on one scene.                                            */
/* ------------------------------------------------------------------------------------- */

enum { HOST_THREADS = 4 };

typedef struct Worker {
    MltScene *scene;
    pthread_barrier_t *started;
    uint64_t seed;
} Worker;

static void *render_and_query(void *argument) {
    Worker *w = (Worker *)argument;
    Rng rng = {w->seed};
    MltCamera camera = looking_down();
    float first[16 * 16 * 3], second[16 * 16 * 3];
    MltRay rays[64];
    MltHit hits[64];
    uint8_t occluded[64];
    int i, r;
    /* This thread's own reference, taken before the creator lets go of its one. */
    EXPECT_OK(mlt_scene_retain(w->scene));
    pthread_barrier_wait(w->started);
    for (r = 0; r < 3; ++r) {
        MltRenderSettings settings = random_settings(&rng);
        size_t len = (size_t)settings.width * settings.height * 3;
        settings.threads = below(&rng, 2); /* the shared pool, or a pool of its own */
        EXPECT_OK(mlt_render(w->scene, &camera, &settings, first, len, NULL, NULL));
        EXPECT_OK(mlt_render(w->scene, &camera, &settings, second, len, NULL, NULL));
        EXPECT(memcmp(first, second, len * sizeof(float)) == 0,
               "algorithm %d: two renders with one seed differ", (int)settings.algorithm);
        for (i = 0; i < 64; ++i) {
            MltRay *ray = &rays[i];
            ray->origin[0] = 2 * uniform(&rng) - 1;
            ray->origin[1] = 2.0f;
            ray->origin[2] = 2 * uniform(&rng) - 1;
            ray->direction[0] = 0.2f * (uniform(&rng) - 0.5f);
            ray->direction[1] = -1.0f;
            ray->direction[2] = 0.2f * (uniform(&rng) - 0.5f);
            ray->tmin = 0.0f;
            ray->tmax = INFINITY;
        }
        EXPECT_OK(mlt_intersect(w->scene, rays, 64, hits));
        EXPECT_OK(mlt_occluded(w->scene, rays, 64, occluded));
        for (i = 0; i < 64; ++i)
            EXPECT((hits[i].triangle_id != MLT_INVALID_ID) == (occluded[i] != 0),
                   "ray %d: intersect and occluded disagree", i);
    }
    mlt_scene_release(w->scene);
    return NULL;
}

static void shared_scene(Rng *rng) {
    static HostScene host;
    MltScene *scene = NULL;
    pthread_t threads[HOST_THREADS];
    Worker workers[HOST_THREADS];
    pthread_barrier_t started;
    int t;
    random_scene(&host, rng);
    EXPECT_OK(mlt_scene_create(&host.desc, &scene));
    pthread_barrier_init(&started, NULL, HOST_THREADS + 1);
    for (t = 0; t < HOST_THREADS; ++t) {
        workers[t].scene = scene;
        workers[t].started = &started;
        workers[t].seed = next_u64(rng);
        EXPECT(pthread_create(&threads[t], NULL, render_and_query, &workers[t]) == 0,
               "pthread_create");
    }
    pthread_barrier_wait(&started);
    mlt_scene_release(scene); /* the workers' references keep it alive */
    for (t = 0; t < HOST_THREADS; ++t) pthread_join(threads[t], NULL);
    pthread_barrier_destroy(&started);
}

/* ------------------------------------------------------------------------------------- */
/* Phase 3: the only reference released under running renders.                            */
/* ------------------------------------------------------------------------------------- */

typedef struct Doomed {
    const MltScene *scene;
    pthread_barrier_t *started;
    int waited;
    MltStatus status;
    float rgb[16 * 16 * 3];
} Doomed;

/* The first progress call (the render's workers are tracing) lets the release happen. */
static bool release_now(float fraction, void *user_data) {
    Doomed *d = (Doomed *)user_data;
    (void)fraction;
    if (!d->waited) {
        d->waited = 1;
        pthread_barrier_wait(d->started);
    }
    return true;
}

static void *render_doomed(void *argument) {
    Doomed *d = (Doomed *)argument;
    MltCamera camera = looking_down();
    MltRenderSettings settings;
    EXPECT_OK(mlt_render_settings_default(&settings));
    settings.width = settings.height = 16;
    settings.algorithm = MLT_ALGORITHM_BDPT;
    settings.samples_per_pixel = 256; /* long enough to be running at the first call */
    settings.threads = 1;
    d->status = mlt_render(d->scene, &camera, &settings, d->rgb, sizeof d->rgb / sizeof(float),
                           release_now, d);
    /* Signals even if the render ended before its first progress call. */
    if (!d->waited) {
        d->waited = 1;
        pthread_barrier_wait(d->started);
    }
    return NULL;
}

static void release_under_renders(Rng *rng) {
    static HostScene host;
    static Doomed doomed[2];
    MltScene *scene = NULL;
    pthread_t threads[2];
    pthread_barrier_t started;
    MltSceneInfo info;
    int t;
    random_scene(&host, rng);
    EXPECT_OK(mlt_scene_create(&host.desc, &scene));
    pthread_barrier_init(&started, NULL, 3);
    for (t = 0; t < 2; ++t) {
        doomed[t].scene = scene;
        doomed[t].started = &started;
        doomed[t].waited = 0;
        EXPECT(pthread_create(&threads[t], NULL, render_doomed, &doomed[t]) == 0, "pthread_create");
    }
    pthread_barrier_wait(&started);
    mlt_scene_release(scene);
    for (t = 0; t < 2; ++t) {
        pthread_join(threads[t], NULL);
        EXPECT(doomed[t].status == MLT_STATUS_OK, "render %d under a release gave %d", t,
               (int)doomed[t].status);
        EXPECT(image_is_finite(doomed[t].rgb, 16 * 16 * 3), "render %d: non-finite pixels", t);
    }
    pthread_barrier_destroy(&started);
    EXPECT_OK(mlt_scene_info_default(&info));
    EXPECT_INVALID(mlt_scene_get_info(scene, &info), "not a live scene");
}

/* ------------------------------------------------------------------------------------- */
/* Phase 4: bad input to every entry point.                                               */
/* ------------------------------------------------------------------------------------- */

static void bad_input(Rng *rng) {
    static HostScene host;
    MltScene *scene = NULL, *released = NULL, *untouched = NULL;
    MltSceneDesc desc;
    MltMaterial material;
    MltCamera camera = looking_down();
    MltRenderSettings settings;
    MltRenderStats stats;
    MltSceneInfo info;
    MltRay ray = {{0, 2, 0}, 0.0f, {0, -1, 0}, INFINITY};
    MltHit hit;
    uint8_t flag;
    float rgb[8 * 8 * 3];
    uint64_t foreign = 0;

    random_scene(&host, rng);
    EXPECT_OK(mlt_scene_create(&host.desc, &scene));
    EXPECT_OK(mlt_scene_create(&host.desc, &released));
    mlt_scene_release(released);

    /* Initializers. */
    EXPECT_INVALID(mlt_material_init(NULL, sizeof(MltMaterial)), "NULL");
    EXPECT_INVALID(mlt_material_init(&material, 3), "struct_size");
    EXPECT_INVALID(mlt_render_settings_init(&settings, sizeof settings + 4096), "struct_size");
    EXPECT_INVALID(mlt_camera_init(&camera, 0), "struct_size");
    camera = looking_down();

    /* Scene descriptions. */
    EXPECT_INVALID(mlt_scene_create(NULL, &untouched), "desc");
    EXPECT_INVALID(mlt_scene_create(&host.desc, NULL), "out");
    desc = host.desc;
    desc.positions = NULL;
    EXPECT_INVALID(mlt_scene_create(&desc, &untouched), "positions");
    desc = host.desc;
    desc.indices_len = 2;
    EXPECT_INVALID(mlt_scene_create(&desc, &untouched), "indices");
    desc = host.desc;
    desc.struct_size = 7;
    EXPECT_INVALID(mlt_scene_create(&desc, &untouched), "struct_size");
    host.indices[4] = 100000;
    EXPECT_INVALID(mlt_scene_create(&host.desc, &untouched), "indices");
    host.indices[4] = host.indices[3];
    host.positions[1] = NAN;
    EXPECT_INVALID(mlt_scene_create(&host.desc, &untouched), "positions");
    host.positions[1] = INFINITY;
    EXPECT_INVALID(mlt_scene_create(&host.desc, &untouched), "positions");
    host.positions[1] = 0.0f;
    host.material_ids[0] = MAX_MATERIALS;
    EXPECT_INVALID(mlt_scene_create(&host.desc, &untouched), "material");
    host.material_ids[0] = 0;
    host.materials[0].kind = 99;
    EXPECT_INVALID(mlt_scene_create(&host.desc, &untouched), "kind");
    host.materials[0].kind = MLT_MATERIAL_DIFFUSE;
    host.materials[0].roughness = NAN;
    EXPECT_INVALID(mlt_scene_create(&host.desc, &untouched), "roughness");
    host.materials[0].roughness = 0.5f;
    host.materials[1].emission[2] = -1.0f;
    EXPECT_INVALID(mlt_scene_create(&host.desc, &untouched), "emission");
    host.materials[1].emission[2] = 0.0f;
    host.texture.width = 1u << 20;
    EXPECT_INVALID(mlt_scene_create(&host.desc, &untouched), "texture");
    host.texture.width = 4;
    host.texture.texel_type = 7;
    EXPECT_INVALID(mlt_scene_create(&host.desc, &untouched), "texel_type");
    host.texture.texel_type = MLT_TEXEL_U8;
    desc = host.desc;
    desc.backend = 42;
    EXPECT_INVALID(mlt_scene_create(&desc, &untouched), "backend");
    EXPECT(untouched == NULL, "a refused mlt_scene_create wrote *out");

    /* Renders. */
    EXPECT_OK(mlt_render_settings_default(&settings));
    settings.width = settings.height = 8;
    settings.algorithm = MLT_ALGORITHM_PATH;
    settings.samples_per_pixel = 1;
    EXPECT_OK(mlt_render(scene, &camera, &settings, rgb, 8 * 8 * 3, NULL, NULL));
    EXPECT_INVALID(mlt_render(NULL, &camera, &settings, rgb, 8 * 8 * 3, NULL, NULL), "scene");
    EXPECT_INVALID(mlt_render(scene, NULL, &settings, rgb, 8 * 8 * 3, NULL, NULL), "camera");
    EXPECT_INVALID(mlt_render(scene, &camera, NULL, rgb, 8 * 8 * 3, NULL, NULL), "settings");
    EXPECT_INVALID(mlt_render(scene, &camera, &settings, NULL, 8 * 8 * 3, NULL, NULL), "rgb_out");
    EXPECT_INVALID(mlt_render(scene, &camera, &settings, rgb, 8 * 8 * 3 - 1, NULL, NULL), "out_len");
    EXPECT_INVALID(mlt_render(released, &camera, &settings, rgb, 8 * 8 * 3, NULL, NULL),
                   "not a live scene");
    EXPECT_INVALID(mlt_render((const MltScene *)(void *)&foreign, &camera, &settings, rgb,
                              8 * 8 * 3, NULL, NULL),
                   "not a live scene");
    EXPECT(foreign == 0, "mlt wrote through a foreign scene pointer");
    settings.algorithm = 7;
    EXPECT_INVALID(mlt_render(scene, &camera, &settings, rgb, 8 * 8 * 3, NULL, NULL), "algorithm");
    settings.algorithm = -1;
    EXPECT_INVALID(mlt_render(scene, &camera, &settings, rgb, 8 * 8 * 3, NULL, NULL), "algorithm");
    settings.algorithm = MLT_ALGORITHM_PATH;
    settings.width = 0;
    EXPECT_INVALID(mlt_render(scene, &camera, &settings, rgb, 8 * 8 * 3, NULL, NULL), "width");
    settings.width = 8;
    settings.time_limit_seconds = NAN;
    EXPECT_INVALID(mlt_render(scene, &camera, &settings, rgb, 8 * 8 * 3, NULL, NULL), "time_limit");
    settings.time_limit_seconds = 0.0;
    settings.spectral = 2;
    EXPECT_INVALID(mlt_render(scene, &camera, &settings, rgb, 8 * 8 * 3, NULL, NULL), "spectral");
    settings.spectral = 0;
    settings.filter_buffers = 1;
    EXPECT_INVALID(mlt_render(scene, &camera, &settings, rgb, 8 * 8 * 3, NULL, NULL), "filter");
    settings.filter_buffers = 0;
    camera.fov_y_deg = NAN;
    EXPECT_INVALID(mlt_render(scene, &camera, &settings, rgb, 8 * 8 * 3, NULL, NULL), "fov");
    camera = looking_down();
    camera.target[0] = camera.eye[0];
    camera.target[1] = camera.eye[1];
    camera.target[2] = camera.eye[2];
    EXPECT_INVALID(mlt_render(scene, &camera, &settings, rgb, 8 * 8 * 3, NULL, NULL), "target");
    camera = looking_down();
    EXPECT_OK(mlt_render_stats_default(&stats));
    stats.struct_size = 5;
    EXPECT_INVALID(mlt_render_ex(scene, &camera, &settings, rgb, 8 * 8 * 3, NULL, NULL, &stats),
                   "struct_size");

    /* Scene facts and ray queries. */
    EXPECT_OK(mlt_scene_info_default(&info));
    EXPECT_INVALID(mlt_scene_get_info(NULL, &info), "scene");
    EXPECT_INVALID(mlt_scene_get_info(scene, NULL), "out");
    EXPECT_INVALID(mlt_scene_get_info(released, &info), "not a live scene");
    EXPECT_INVALID(mlt_intersect(scene, NULL, 1, &hit), "rays");
    EXPECT_INVALID(mlt_intersect(scene, &ray, 1, NULL), "hits_out");
    EXPECT_INVALID(mlt_intersect(released, &ray, 1, &hit), "not a live scene");
    EXPECT_INVALID(mlt_occluded(scene, &ray, 1, NULL), "occluded_out");
    ray.direction[1] = 0.0f;
    EXPECT_INVALID(mlt_intersect(scene, &ray, 1, &hit), "direction");
    ray.direction[1] = -1.0f;
    ray.tmin = NAN;
    EXPECT_INVALID(mlt_occluded(scene, &ray, 1, &flag), "tmin");
    ray.tmin = 0.0f;
    EXPECT_OK(mlt_intersect(scene, &ray, 1, &hit));
    EXPECT_OK(mlt_intersect(scene, NULL, 0, NULL));

    /* Handles. */
    EXPECT_INVALID(mlt_scene_retain(NULL), "NULL");
    EXPECT_INVALID(mlt_scene_retain(released), "not a live scene");
    mlt_scene_release(released); /* a second release is ignored, with a message */
    EXPECT(strstr(mlt_last_error_message(), "not a live scene") != NULL,
           "a double release left no message");
    mlt_scene_release(NULL);
    EXPECT(mlt_status_string(12345) != NULL && mlt_status_string(-1) != NULL, "status strings");
    EXPECT(!mlt_backend_supported(-7), "backend -7 is supported");
    mlt_scene_release(scene);
}

int main(int argc, char **argv) {
    Rng rng = {argc > 1 ? strtoull(argv[1], NULL, 10) : 1};
    int scenes = argc > 2 ? atoi(argv[2]) : 24;
    many_scenes(&rng, scenes);
    printf("many scenes: %d rendered\n", scenes);
    shared_scene(&rng);
    printf("shared scene: %d host threads\n", HOST_THREADS);
    release_under_renders(&rng);
    printf("release under renders: done\n");
    bad_input(&rng);
    printf("bad input: done\n");
    if (atomic_load(&failures) != 0) {
        fprintf(stderr, "%d checks failed\n", atomic_load(&failures));
        return 1;
    }
    printf("all checks passed\n");
    return 0;
}
