/*
 * FROZEN: a host's view of an older mlt header, for tests/c_hosts.rs. It is mlt 0.2's
 * include/mlt.h with MltRenderSettings and MltRenderStats cut back to their layout before
 * the post-process filter fields (the last time they grew): what a host built against an
 * earlier header of this ABI passes. Never regenerate it: the test checks that
 * c_examples/minimal.c built against it still links and renders the image a current host
 * gets (the fields it lacks take their defaults).
 */
/*
 * mlt: an embeddable Metropolis Light Transport kernel.
 *
 * Link: -lmlt (static: also -lm -lpthread -ldl), or the shared library libmlt.so.
 * Conventions: every fallible call returns an MltStatus; on failure
 * mlt_last_error_message() names the offending field, index and value. Out-parameters are
 * written only on success. Initialize every struct with its mlt_*_default() (it sets
 * struct_size, which lets a newer library work with this header).
 * The progress callback must return normally (no C++ exception or longjmp through it).
 */

/* MLT_API marks the exported functions: visible from the shared library when a host builds
 * with -fvisibility=hidden, and imported from a DLL on Windows when MLT_SHARED is defined. */
#ifndef MLT_API
#  if defined(_WIN32) && defined(MLT_SHARED)
#    define MLT_API __declspec(dllimport)
#  elif defined(__GNUC__) || defined(__clang__)
#    define MLT_API __attribute__((visibility("default")))
#  else
#    define MLT_API
#  endif
#endif

#ifndef MLT_H
#define MLT_H


#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

/**
 * Major version of the mlt library this header belongs to.
 */
#define MLT_VERSION_MAJOR 0

/**
 * Minor version.
 */
#define MLT_VERSION_MINOR 2

/**
 * Patch version.
 */
#define MLT_VERSION_PATCH 0

/**
 * The version as one number, MAJOR * 10000 + MINOR * 100 + PATCH, for `#if MLT_VERSION >= …`
 * checks; `mlt_version()` returns the linked library's.
 */
#define MLT_VERSION (((MLT_VERSION_MAJOR * 10000) + (MLT_VERSION_MINOR * 100)) + MLT_VERSION_PATCH)

/**
 * `MltMaterial.kind`: Lambertian diffuse with albedo `color` (two-sided).
 */
#define MLT_MATERIAL_DIFFUSE 0

/**
 * `MltMaterial.kind`: perfect mirror reflecting `color` (two-sided).
 */
#define MLT_MATERIAL_MIRROR 1

/**
 * `MltMaterial.kind`: smooth dielectric (glass) with index of refraction `ior`, tinted by `color`.
 */
#define MLT_MATERIAL_DIELECTRIC 2

/**
 * `MltSceneDesc.backend`: mlt's own SIMD BVH (8-wide with AVX2, else 4-wide; built with
 * obvhs), always available.
 */
#define MLT_BACKEND_BVH 0

/**
 * `MltSceneDesc.backend`: Intel Embree 3, only when mlt was built with the `embree` feature.
 */
#define MLT_BACKEND_EMBREE 1

/**
 * `MltRenderSettings.algorithm`: path tracing with next-event estimation and MIS.
 */
#define MLT_ALGORITHM_PATH 0

/**
 * `MltRenderSettings.algorithm`: bidirectional path tracing, all strategies combined by MIS
 * (including light tracing onto the film).
 */
#define MLT_ALGORITHM_BDPT 1

/**
 * `MltRenderSettings.algorithm`: primary-sample-space Metropolis light transport (Kelemen
 * et al. 2002) over the path tracer; uses the `mutations_per_pixel`, `bootstrap_samples`,
 * `chains`, `large_step_probability` and `small_step_sigma` settings.
 */
#define MLT_ALGORITHM_PSSMLT 2

/**
 * `MltRenderSettings.algorithm`: multiplexed Metropolis light transport (Hachisuka et al. 2014): primary-sample-space
 * chains over bidirectional path tracing that also pick the path depth and one connection
 * strategy; one group of chains per depth, each normalized by its own bootstrap estimate.
 */
#define MLT_ALGORITHM_MMLT 3

/**
 * `MltRenderSettings.algorithm`: primary-sample-space MLT over bidirectional path tracing,
 * all strategies of a sample summed.
 */
#define MLT_ALGORITHM_PSSMLT_BDPT 4

/**
 * `MltRenderSettings.algorithm`: path-space Metropolis light transport (Veach & Guibas
 * 1997): the chains' states are light paths, changed by Veach's mutations; seeded and
 * normalized by a bidirectional bootstrap. Uses `mutations_per_pixel`, `bootstrap_samples`
 * and `chains`.
 */
#define MLT_ALGORITHM_PATH_SPACE_MLT 5

/**
 * `MltRenderSettings.algorithm`: energy redistribution path tracing (Cline, Talbot & Egbert
 * 2005): each of `samples_per_pixel` BDPT camera samples per pixel starts short chains of
 * lens, caustic and multi-chain perturbations that spread its energy over nearby paths.
 * Unbiased. Uses `erpt_chain_length`, `erpt_deposit_energy` and the perturbation weights
 * of `mutation_weights`.
 */
#define MLT_ALGORITHM_ERPT 6

/**
 * Index of the bidirectional mutation in `MltRenderSettings.mutation_weights` and the
 * per-mutation counts of `MltRenderStats`.
 */
#define MLT_MUTATION_BIDIRECTIONAL 0

/**
 * Index of the lens perturbation.
 */
#define MLT_MUTATION_LENS 1

/**
 * Index of the caustic perturbation.
 */
#define MLT_MUTATION_CAUSTIC 2

/**
 * Index of the multi-chain perturbation.
 */
#define MLT_MUTATION_MULTI_CHAIN 3

/**
 * `MltHit.triangle_id` of a ray that hit nothing.
 */
#define MLT_INVALID_ID UINT32_MAX

/**
 * Fewest partial images the filter accepts: two already give a spread.
 */
#define MLT_MIN_FILTER_BUFFERS 2

/**
 * Most partial images the filter accepts (each costs 12 bytes per pixel).
 */
#define MLT_MAX_FILTER_BUFFERS 32

/**
 * Largest accepted filter strength.
 */
#define MLT_MAX_FILTER_STRENGTH 100.0

/**
 * Largest accepted filter search radius in pixels.
 */
#define MLT_MAX_FILTER_RADIUS 32

/**
 * Largest accepted image width or height.
 */
#define MLT_MAX_IMAGE_SIDE (1 << 16)

/**
 * Largest accepted samples (or mutations) per pixel.
 */
#define MLT_MAX_SAMPLES_PER_PIXEL (1 << 24)

/**
 * Largest accepted max depth.
 */
#define MLT_MAX_DEPTH_LIMIT 1024

/**
 * Largest accepted thread count.
 */
#define MLT_MAX_THREADS 4096

/**
 * Largest accepted time limit in seconds.
 */
#define MLT_MAX_TIME_LIMIT_SECONDS 1.0e7

/**
 * Largest accepted ERPT chain length.
 */
#define MLT_MAX_ERPT_CHAIN_LENGTH (1 << 20)

/**
 * Largest accepted ERPT deposit energy.
 */
#define MLT_MAX_ERPT_DEPOSIT_ENERGY 1.0e30

/**
 * Largest accepted number of Metropolis bootstrap samples.
 */
#define MLT_MAX_BOOTSTRAP_SAMPLES (1 << 28)

/**
 * Largest accepted share of a Metropolis render's rays spent on its normalization pass.
 */
#define MLT_MAX_NORMALIZATION_WORK_FRACTION 0.9

/**
 * Result of every fallible mlt call. Values are stable: hosts may store them.
 */
typedef enum MltStatus {
  /**
   * The call succeeded.
   */
  MLT_STATUS_OK = 0,
  /**
   * A pointer, count, index, float or enum value the host passed is invalid; the
   * message names it.
   */
  MLT_STATUS_INVALID_ARGUMENT = 1,
  /**
   * The request is valid but not supported by this build (e.g. a backend not compiled in).
   */
  MLT_STATUS_UNSUPPORTED = 2,
  /**
   * Memory for the scene or image could not be allocated.
   */
  MLT_STATUS_OUT_OF_MEMORY = 3,
  /**
   * The progress callback asked to stop. The image is valid: every pixel is normalized by
   * the samples actually taken.
   */
  MLT_STATUS_CANCELLED = 4,
  /**
   * The time limit was reached before the requested samples. The image is valid: every
   * pixel is normalized by the samples actually taken.
   */
  MLT_STATUS_TIME_LIMIT_REACHED = 5,
  /**
   * A bug inside mlt (a caught panic). The message says where; please report it.
   */
  MLT_STATUS_INTERNAL_ERROR = 6,
} MltStatus;

/**
 * An immutable scene: triangles, materials, lights and the acceleration structure. Thread
 * safe: any number of threads may render and query one scene at the same time.
 */
typedef struct MltScene MltScene;

/**
 * A material. Initialize with `mlt_material_default`.
 */
typedef struct MltMaterial {
  /**
   * sizeof(MltMaterial) of the header the host was built with: set by `mlt_material_default`, do not change
   * it. An older header's smaller struct is read as far as it goes (the rest defaults).
   */
  uint32_t struct_size;
  /**
   * One of `MLT_MATERIAL_*`.
   */
  int32_t kind;
  /**
   * Diffuse albedo, mirror reflectance or glass tint; linear RGB, each in [0, 1].
   */
  float color[3];
  /**
   * Radiance emitted from the front (counter-clockwise) side; linear RGB, each >= 0.
   * Any material may emit: its triangles become area lights.
   */
  float emission[3];
  /**
   * Index of refraction of a dielectric (> 0; the outside is vacuum). Must be finite for
   * every kind; only dielectrics use it.
   */
  float ior;
} MltMaterial;

/**
 * Everything `mlt_scene_create` needs, as plain arrays the host keeps ownership of (they are
 * copied; the host may free them once the call returns). Initialize with
 * `mlt_scene_desc_default`.
 *
 * Degenerate triangles (zero area, e.g. repeated or collinear vertices) are accepted: they
 * keep their id but are never hit and never emit. `mlt_scene_get_info` counts them.
 */
typedef struct MltSceneDesc {
  /**
   * sizeof(MltSceneDesc) of the header the host was built with: set by `mlt_scene_desc_default`, do not change
   * it. An older header's smaller struct is read as far as it goes (the rest defaults).
   */
  uint32_t struct_size;
  /**
   * Vertex positions, x y z per vertex; all finite.
   */
  const float *positions;
  /**
   * Number of floats in `positions` (3 per vertex).
   */
  size_t positions_len;
  /**
   * Vertex indices, 3 per triangle, each < vertex count. Counter-clockwise is the front.
   */
  const uint32_t *indices;
  /**
   * Number of entries in `indices` (3 per triangle).
   */
  size_t indices_len;
  /**
   * One material index per triangle, each < `materials_len`. May be NULL (with length 0):
   * every triangle then uses material 0.
   */
  const uint32_t *material_ids;
  /**
   * Number of entries in `material_ids`: 0 or the triangle count.
   */
  size_t material_ids_len;
  const struct MltMaterial *materials;
  size_t materials_len;
  /**
   * One of `MLT_BACKEND_*`.
   */
  int32_t backend;
} MltSceneDesc;

/**
 * A perspective camera. Image right is normalize(cross(target - eye, up)). Initialize with
 * `mlt_camera_default` (the Cornell box's camera).
 */
typedef struct MltCamera {
  /**
   * sizeof(MltCamera) of the header the host was built with: set by `mlt_camera_default`, do not change
   * it. An older header's smaller struct is read as far as it goes (the rest defaults).
   */
  uint32_t struct_size;
  float eye[3];
  /**
   * Must differ from `eye`.
   */
  float target[3];
  /**
   * Must not be parallel to target - eye.
   */
  float up[3];
  /**
   * Vertical field of view in degrees, in (0, 180).
   */
  float fov_y_deg;
  /**
   * Thin-lens aperture radius; 0 for a pinhole.
   */
  float lens_radius;
  /**
   * Distance of the plane in focus; 0 means |target - eye|.
   */
  float focus_distance;
} MltCamera;

/**
 * How to render. Initialize with `mlt_render_settings_default`.
 */
typedef struct MltRenderSettings {
  /**
   * sizeof(MltRenderSettings) of the header the host was built with: set by `mlt_render_settings_default`, do not change
   * it. An older header's smaller struct is read as far as it goes (the rest defaults).
   */
  uint32_t struct_size;
  /**
   * Image size in pixels, each in [1, 65536].
   */
  uint32_t width;
  uint32_t height;
  /**
   * One of `MLT_ALGORITHM_*`; the default is `MLT_ALGORITHM_MMLT`.
   */
  int32_t algorithm;
  /**
   * Path tracing and BDPT: samples per pixel, at most 2^24. 0 renders until
   * `time_limit_seconds`. The Metropolis algorithms use `mutations_per_pixel` instead.
   */
  uint32_t samples_per_pixel;
  /**
   * Most scattering vertices between camera and light (0: only directly visible
   * emitters), at most 1024.
   */
  uint32_t max_depth;
  /**
   * Worker threads; 0 runs on one pool of one thread per core that every such render in
   * the process shares (renders from several host threads at once then share the cores
   * instead of oversubscribing them); a count gives the render a pool of its own. The
   * image does not depend on it.
   */
  uint32_t threads;
  /**
   * Seed of every random number; equal seeds and settings give bitwise equal images.
   */
  uint64_t seed;
  /**
   * Stop after this many seconds (0: no limit). Finite, at most 1e7.
   */
  double time_limit_seconds;
  /**
   * Metropolis: mutations per pixel, at most 2^24; 0 renders until `time_limit_seconds`.
   */
  uint32_t mutations_per_pixel;
  /**
   * Metropolis: independent samples that seed the chains and start the estimate of the
   * image normalization, at most 2^28. 0 (the default) sizes it to the render: one
   * sample per 8 planned mutations, at least 2^16 (2^18 for a render planned by its time
   * limit alone).
   */
  uint32_t bootstrap_samples;
  /**
   * Metropolis: number of Markov chains, from 1 to the bootstrap samples. The image does
   * not depend on the thread count.
   */
  uint32_t chains;
  /**
   * PSSMLT: probability of a large (independent) step, in [0, 1].
   */
  float large_step_probability;
  /**
   * PSSMLT: standard deviation of a small step in primary sample space, in (0, 1].
   */
  float small_step_sigma;
  /**
   * Metropolis: camera samples of the direct pass per chain mutation (both per pixel);
   * mutations_per_pixel × this is at most 2^24. The direct pass path-traces the paths of
   * depth 0 and 1 (emitters seen directly, direct lighting) and leaves the longer ones to
   * the chains; the two alternate, so a render stopped early keeps the ratio. 0: no direct
   * pass, the chains render every depth.
   */
  uint32_t direct_samples_per_mutation;
  /**
   * `MLT_ALGORITHM_PATH_SPACE_MLT`: relative probabilities of the mutations, indexed by
   * `MLT_MUTATION_*` (bidirectional, lens, caustic, multi-chain). Each step picks among
   * those the current path admits. Finite, in [0, 1e6]; the bidirectional weight must be
   * positive.
   */
  float mutation_weights[4];
  /**
   * `MLT_ALGORITHM_ERPT`: perturbations per chain (L), in [1, 2^20]; default 10.
   */
  uint32_t erpt_chain_length;
  /**
   * `MLT_ALGORITHM_ERPT`: the energy (luminance) each chain step deposits, e_d; a camera
   * sample's energy e starts floor(e / (L e_d) + uniform) chains. 0 (the default) picks
   * e_d so that a camera sample starts one chain on average. Finite, in [0, 1e30].
   */
  float erpt_deposit_energy;
  /**
   * `MLT_ALGORITHM_PATH_SPACE_MLT`, 0 or 1: run a warm-up of about one mutation per pixel
   * with `mutation_weights`, then weight each mutation by its acceptance rate there
   * (within a factor of 8) for the rest of the render, on chains seeded anew. The weights
   * used are reported in `MltRenderStats::mutation_weights`. Default 0.
   */
  uint32_t adapt_mutation_weights;
  /**
   * `MLT_ALGORITHM_PATH_SPACE_MLT` and `MLT_ALGORITHM_ERPT`, 0 or 1: perturb directions at
   * diffuse vertices and lights by small steps in their cosine-weighted sample space
   * instead of within a cone. Default 0.
   */
  uint32_t perturb_in_sample_space;
} MltRenderSettings;

/**
 * What a render did (filled by `mlt_render_ex`). Initialize with `mlt_render_stats_default`.
 */
typedef struct MltRenderStats {
  /**
   * sizeof(MltRenderStats) of the header the host was built with: set by `mlt_render_stats_default` before the
   * call. An older header's smaller struct receives the fields it has.
   */
  uint32_t struct_size;
  /**
   * Camera samples taken over the whole image (path tracing, BDPT, the direct pass of a
   * Metropolis render).
   */
  uint64_t samples;
  /**
   * Rays traced, closest-hit and shadow.
   */
  uint64_t rays;
  /**
   * Samples with a non-finite value, dropped (they count as black samples).
   */
  uint64_t invalid_samples;
  /**
   * Wall-clock seconds of the render.
   */
  double seconds;
  /**
   * Worker threads used.
   */
  uint32_t threads;
  /**
   * Metropolis: accepted mutations, of `mutations`.
   */
  uint64_t accepted_mutations;
  /**
   * Metropolis: the normalization b (mean luminance of the path contribution) the image
   * was scaled by, its final estimate. `MLT_ALGORITHM_ERPT`: the deposit energy used.
   */
  double normalization;
  /**
   * Metropolis: mutations made by all chains.
   */
  uint64_t mutations;
  /**
   * `MLT_ALGORITHM_PATH_SPACE_MLT`: proposals of each mutation, indexed by
   * `MLT_MUTATION_*`.
   */
  uint64_t mutations_proposed[4];
  /**
   * `MLT_ALGORITHM_PATH_SPACE_MLT`: accepted proposals of each mutation.
   */
  uint64_t mutations_accepted[4];
  /**
   * `MLT_ALGORITHM_PATH_SPACE_MLT`: the mutation weights the chains ran with (after the
   * warm-up, with `adapt_mutation_weights`). `MLT_ALGORITHM_ERPT`: its weights.
   */
  float mutation_weights[4];
} MltRenderStats;

/**
 * Facts about a created scene (filled by `mlt_scene_get_info`). Initialize with
 * `mlt_scene_info_default`.
 */
typedef struct MltSceneInfo {
  /**
   * sizeof(MltSceneInfo) of the header the host was built with: set by `mlt_scene_info_default` before the
   * call. An older header's smaller struct receives the fields it has.
   */
  uint32_t struct_size;
  uint64_t triangle_count;
  /**
   * Triangles with zero area: never hit, never emit.
   */
  uint64_t degenerate_triangle_count;
  /**
   * Emissive triangles (area lights).
   */
  uint64_t emitter_count;
  float bounds_min[3];
  float bounds_max[3];
  /**
   * The `MLT_BACKEND_*` the scene was built with.
   */
  int32_t backend;
} MltSceneInfo;

/**
 * Progress callback: called on the thread that called `mlt_render` (never from a worker),
 * about 20 times a second and once with 1.0 at the end, with the fraction done in [0, 1].
 * Return `true` to continue and `false` to cancel. It must return normally: a C++
 * exception thrown through it, or a `longjmp` out of it, skips mlt's cleanup (worker
 * threads keep running on freed memory) and is undefined behavior; catch inside the
 * callback and return `false` instead.
 */
typedef bool (*MltProgressCallback)(float fraction, void *user_data);

/**
 * A ray for the batch queries: points origin + t·direction with t in [tmin, tmax] (with
 * `MLT_BACKEND_EMBREE`: (tmin, tmax], which differs only for a hit at exactly t = tmin).
 * `direction` need not be unit length; t is measured in multiples of it.
 */
typedef struct MltRay {
  float origin[3];
  /**
   * Finite, >= 0.
   */
  float tmin;
  /**
   * Finite and non-zero.
   */
  float direction[3];
  /**
   * >= tmin; may be INFINITY.
   */
  float tmax;
} MltRay;

/**
 * A closest hit. The hit point is (1-u-v)·v0 + u·v1 + v·v2 of the triangle's vertices in
 * the order the host gave them.
 */
typedef struct MltHit {
  /**
   * The host's triangle index, or `MLT_INVALID_ID` for a miss (then t = INFINITY).
   */
  uint32_t triangle_id;
  float t;
  float u;
  float v;
} MltHit;



#ifdef __cplusplus
extern "C" {
#endif // __cplusplus

/**
 * The library version as MAJOR * 10000 + MINOR * 100 + PATCH.
 */
MLT_API uint32_t mlt_version(void);

/**
 * The library version as "MAJOR.MINOR.PATCH" (static storage).
 */
MLT_API const char *mlt_version_string(void);

/**
 * A static description of a status (any integer is accepted).
 */
MLT_API const char *mlt_status_string(int32_t status);

/**
 * The message of the last failed mlt call on this thread ("" after a success). The pointer
 * stays valid until the next mlt call on this thread.
 */
MLT_API const char *mlt_last_error_message(void);

/**
 * Whether `mlt_scene_create` can build scenes with `backend` (one of `MLT_BACKEND_*`) in
 * this build of the library: true for `MLT_BACKEND_BVH`; for `MLT_BACKEND_EMBREE` only if
 * mlt was compiled with the `embree` feature (otherwise scene creation with it returns
 * `MLT_STATUS_UNSUPPORTED`); false for any other value.
 */
MLT_API bool mlt_backend_supported(int32_t backend);

/**
 * Fills `out` with a white diffuse, non-emissive material (ior 1.5 for dielectrics) and
 * `struct_size`. Call it through the header's inline `mlt_material_default(out)`, which
 * passes the host's `sizeof(MltMaterial)`; the other `*_init` functions likewise.
 *
 * # Safety
 * `out` must be NULL or point to `struct_size` writable bytes.
 */
MLT_API enum MltStatus mlt_material_init(struct MltMaterial *out, size_t struct_size);

/**
 * Fills `out` with an empty description (no arrays, BVH backend).
 *
 * # Safety
 * `out` must be NULL or point to `struct_size` writable bytes.
 */
MLT_API enum MltStatus mlt_scene_desc_init(struct MltSceneDesc *out, size_t struct_size);

/**
 * Fills `out` with the Cornell box's pinhole camera.
 *
 * # Safety
 * `out` must be NULL or point to `struct_size` writable bytes.
 */
MLT_API enum MltStatus mlt_camera_init(struct MltCamera *out, size_t struct_size);

/**
 * Fills `out` with the default settings: 256 x 256, multiplexed MLT with the direct pass
 * (32 mutations per pixel and one direct sample per mutation, an automatic bootstrap
 * (2^18 samples at this size), 5% of the rays for the normalization pass,
 * 1024 chains, large steps 0.3, small steps 0.01), 64 samples per pixel for path tracing and
 * BDPT, max depth 5, seed 0, all cores, no time limit, no post-process filter (strength
 * 0.45 and radius 7 when `filter_buffers` turns it on).
 *
 * # Safety
 * `out` must be NULL or point to `struct_size` writable bytes.
 */
MLT_API enum MltStatus mlt_render_settings_init(struct MltRenderSettings *out, size_t struct_size);

/**
 * Prepares `out` to receive a render's statistics: zeros and `struct_size`.
 *
 * # Safety
 * `out` must be NULL or point to `struct_size` writable bytes.
 */
MLT_API enum MltStatus mlt_render_stats_init(struct MltRenderStats *out, size_t struct_size);

/**
 * Prepares `out` to receive a scene's facts: zeros and `struct_size`.
 *
 * # Safety
 * `out` must be NULL or point to `struct_size` writable bytes.
 */
MLT_API enum MltStatus mlt_scene_info_init(struct MltSceneInfo *out, size_t struct_size);

/**
 * Validates `desc`, copies its arrays and builds the acceleration structure. On success
 * `*out` receives a scene to release with `mlt_scene_release`; on failure `*out` is untouched.
 *
 * # Safety
 * `desc` must point to an `MltSceneDesc` whose pointers reference arrays of at least the
 * given lengths; `out` must be writable.
 */
MLT_API enum MltStatus mlt_scene_create(const struct MltSceneDesc *desc, struct MltScene **out);

/**
 * Releases a scene. NULL is a no-op. The scene must not be in use by another thread.
 *
 * # Safety
 * `scene` must be NULL or a pointer returned by `mlt_scene_create` not yet released.
 */
MLT_API void mlt_scene_release(struct MltScene *scene);

/**
 * Facts about a scene: triangle, degenerate and emitter counts, bounds, backend.
 *
 * # Safety
 * `scene` must be a live scene; `out` writable.
 */
MLT_API enum MltStatus mlt_scene_get_info(const struct MltScene *scene, struct MltSceneInfo *out);

/**
 * Renders `scene` seen by `camera` into `rgb_out`: width × height × 3 floats, linear RGB
 * radiance, rows from top to bottom, left to right. `out_len` is the number of floats
 * `rgb_out` holds (at least width·height·3). `progress` may be NULL.
 *
 * Returns `MLT_STATUS_OK` when every sample was taken. `MLT_STATUS_CANCELLED` or
 * `MLT_STATUS_TIME_LIMIT_REACHED` also leave a valid image in `rgb_out`, each pixel
 * normalized by the samples it actually received. A cancel or time limit takes effect once
 * every pixel has at least one sample (the first pass is never interrupted). On any other status `rgb_out` is untouched.
 *
 * # Safety
 * Pointers must be valid as described; `rgb_out` must not be accessed by the host until
 * the call returns.
 */
MLT_API enum MltStatus mlt_render(const struct MltScene *scene, const struct MltCamera *camera, const struct MltRenderSettings *settings, float *rgb_out, size_t out_len, MltProgressCallback progress, void *user_data);

/**
 * `mlt_render` that also fills `stats_out` (may be NULL) whenever it writes the image.
 *
 * # Safety
 * As `mlt_render`; `stats_out` NULL or writable.
 */
MLT_API enum MltStatus mlt_render_ex(const struct MltScene *scene, const struct MltCamera *camera, const struct MltRenderSettings *settings, float *rgb_out, size_t out_len, MltProgressCallback progress, void *user_data, struct MltRenderStats *stats_out);

/**
 * Closest hit for each of `count` rays, written to `hits_out[i]` (a miss has triangle_id
 * `MLT_INVALID_ID` and t = INFINITY). Runs on the calling thread. Every ray is validated
 * before any result is written.
 *
 * # Safety
 * `rays` and `hits_out` must hold `count` elements.
 */
MLT_API enum MltStatus mlt_intersect(const struct MltScene *scene, const struct MltRay *rays, size_t count, struct MltHit *hits_out);

/**
 * For each of `count` rays, `occluded_out[i]` = 1 if any triangle lies on it within
 * [tmin, tmax], else 0. Runs on the calling thread.
 *
 * # Safety
 * `rays` and `occluded_out` must hold `count` elements.
 */
MLT_API enum MltStatus mlt_occluded(const struct MltScene *scene, const struct MltRay *rays, size_t count, uint8_t *occluded_out);

#ifdef __cplusplus
}  // extern "C"
#endif  // __cplusplus

#endif  /* MLT_H */

#ifndef MLT_H_INITIALIZERS
#define MLT_H_INITIALIZERS
/* The initializers: each fills a struct with its defaults and sets struct_size to this
 * header's sizeof, so a newer library reads (and writes) only the fields this host has.
 * Call one on every struct before filling it in or passing it to receive results. */
static inline MltStatus mlt_material_default(MltMaterial *out) {
    return mlt_material_init(out, sizeof(MltMaterial));
}
static inline MltStatus mlt_scene_desc_default(MltSceneDesc *out) {
    return mlt_scene_desc_init(out, sizeof(MltSceneDesc));
}
static inline MltStatus mlt_camera_default(MltCamera *out) {
    return mlt_camera_init(out, sizeof(MltCamera));
}
static inline MltStatus mlt_render_settings_default(MltRenderSettings *out) {
    return mlt_render_settings_init(out, sizeof(MltRenderSettings));
}
static inline MltStatus mlt_render_stats_default(MltRenderStats *out) {
    return mlt_render_stats_init(out, sizeof(MltRenderStats));
}
static inline MltStatus mlt_scene_info_default(MltSceneInfo *out) {
    return mlt_scene_info_init(out, sizeof(MltSceneInfo));
}
#endif  /* MLT_H_INITIALIZERS */
