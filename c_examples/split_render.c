/*
 * split_render.c: one render split into jobs, as a render farm runs it.
 *
 * The frame is planned once (mlt_render_plan); each of 3 jobs renders its share of the
 * plan (mlt_render_job), as 3 machines would, and its partial result goes out as bytes (a
 * temporary file here: a network or a shared disk in a farm); they are read back in another
 * order, two of them added into one (mlt_render_combine, as a node of a merge tree does for
 * a large farm), and the merge (mlt_render_merge) makes the image. mlt sums every sample in fixed point,
 * so the merged image is the one a single mlt_render gives, bit for bit: the program checks
 * that, shows that a corrupted partial result is refused, writes the image as PFM (see
 * minimal.c for the conventions every mlt call follows) and exits non-zero on a mismatch.
 *
 * Usage:  split_render [out.pfm] [width height samples-per-pixel [path|bdpt]]
 *         (defaults: split.pfm 64 64 16 path)
 *
 * Build (from the crate root, after `cargo build --release`):
 *   cc -std=c99 -Wall -Wextra -I include c_examples/split_render.c \
 *      target/release/libmlt.a -lpthread -ldl -lm -o split_render
 */

#include <mlt.h>

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { JOBS = 3 };

/* The Cornell box of minimal.c (tests/scenes/cornell-box.obj). */
enum { QUAD_COUNT = 16, VERTEX_COUNT = QUAD_COUNT * 4, TRIANGLE_COUNT = QUAD_COUNT * 2 };

static const float positions[VERTEX_COUNT * 3] = {
    /* floor */
    552.8f, 0.0f, 0.0f,     0.0f, 0.0f, 0.0f,       0.0f, 0.0f, 559.2f,     549.6f, 0.0f, 559.2f,
    /* ceiling */
    556.0f, 548.8f, 0.0f,   556.0f, 548.8f, 559.2f, 0.0f, 548.8f, 559.2f,   0.0f, 548.8f, 0.0f,
    /* back wall */
    549.6f, 0.0f, 559.2f,   0.0f, 0.0f, 559.2f,     0.0f, 548.8f, 559.2f,   556.0f, 548.8f, 559.2f,
    /* right wall (green; x = 0 is on the right of the image) */
    0.0f, 0.0f, 559.2f,     0.0f, 0.0f, 0.0f,       0.0f, 548.8f, 0.0f,     0.0f, 548.8f, 559.2f,
    /* left wall (red) */
    552.8f, 0.0f, 0.0f,     549.6f, 0.0f, 559.2f,   556.0f, 548.8f, 559.2f, 556.0f, 548.8f, 0.0f,
    /* short block: top, then its four sides */
    130.0f, 165.0f, 65.0f,  82.0f, 165.0f, 225.0f,  240.0f, 165.0f, 272.0f, 290.0f, 165.0f, 114.0f,
    290.0f, 0.0f, 114.0f,   290.0f, 165.0f, 114.0f, 240.0f, 165.0f, 272.0f, 240.0f, 0.0f, 272.0f,
    130.0f, 0.0f, 65.0f,    130.0f, 165.0f, 65.0f,  290.0f, 165.0f, 114.0f, 290.0f, 0.0f, 114.0f,
    82.0f, 0.0f, 225.0f,    82.0f, 165.0f, 225.0f,  130.0f, 165.0f, 65.0f,  130.0f, 0.0f, 65.0f,
    240.0f, 0.0f, 272.0f,   240.0f, 165.0f, 272.0f, 82.0f, 165.0f, 225.0f,  82.0f, 0.0f, 225.0f,
    /* tall block: top, then its four sides */
    423.0f, 330.0f, 247.0f, 265.0f, 330.0f, 296.0f, 314.0f, 330.0f, 456.0f, 472.0f, 330.0f, 406.0f,
    423.0f, 0.0f, 247.0f,   423.0f, 330.0f, 247.0f, 472.0f, 330.0f, 406.0f, 472.0f, 0.0f, 406.0f,
    472.0f, 0.0f, 406.0f,   472.0f, 330.0f, 406.0f, 314.0f, 330.0f, 456.0f, 314.0f, 0.0f, 456.0f,
    314.0f, 0.0f, 456.0f,   314.0f, 330.0f, 456.0f, 265.0f, 330.0f, 296.0f, 265.0f, 0.0f, 296.0f,
    265.0f, 0.0f, 296.0f,   265.0f, 330.0f, 296.0f, 423.0f, 330.0f, 247.0f, 423.0f, 0.0f, 247.0f,
    /* the light, just below the ceiling */
    343.0f, 548.7f, 227.0f, 343.0f, 548.7f, 332.0f, 213.0f, 548.7f, 332.0f, 213.0f, 548.7f, 227.0f,
};

/* Our four materials, by index into the materials array below. */
enum { WHITE, RED, GREEN, LIGHT, MATERIAL_COUNT };

/* The material of each quad, in the order of `positions`. */
static const uint32_t quad_material[QUAD_COUNT] = {
    WHITE, WHITE, WHITE, GREEN, RED,        /* floor, ceiling, back, right, left */
    WHITE, WHITE, WHITE, WHITE, WHITE,      /* short block */
    WHITE, WHITE, WHITE, WHITE, WHITE,      /* tall block */
    LIGHT,
};

static int check(MltStatus status, const char *what) {
    if (status == MLT_STATUS_OK) return 1;
    fprintf(stderr, "%s failed: %s: %s\n", what, mlt_status_string((int32_t)status),
            mlt_last_error_message());
    return 0;
}

static void put_float_le(float value, FILE *file) {
    uint32_t bits;
    unsigned char bytes[4];
    memcpy(&bits, &value, sizeof bits);
    bytes[0] = (unsigned char)(bits & 0xffu);
    bytes[1] = (unsigned char)((bits >> 8) & 0xffu);
    bytes[2] = (unsigned char)((bits >> 16) & 0xffu);
    bytes[3] = (unsigned char)((bits >> 24) & 0xffu);
    fwrite(bytes, 1, 4, file);
}

/* PFM: rows from the bottom up (mlt's buffer goes from the top down). */
static int write_pfm(const char *path, const float *rgb, uint32_t width, uint32_t height) {
    FILE *file = fopen(path, "wb");
    uint32_t row;
    size_t i;
    if (!file) {
        perror(path);
        return 0;
    }
    fprintf(file, "PF\n%u %u\n-1.0\n", (unsigned)width, (unsigned)height);
    for (row = height; row-- > 0;) {
        const float *line = rgb + (size_t)row * width * 3;
        for (i = 0; i < (size_t)width * 3; ++i) put_float_le(line[i], file);
    }
    if (fclose(file) != 0) {
        perror(path);
        return 0;
    }
    return 1;
}

/* What a job sends: its partial result's bytes, written to `file`. */
static int send_bytes(const MltBytes *bytes, FILE *file) {
    return fwrite(bytes->data, 1, bytes->size, file) == bytes->size && fflush(file) == 0;
}

/* What the merge receives: the whole of `file`, in a buffer of the host's (the merge takes
 * any memory: a pointer and a size). */
static uint8_t *receive_bytes(FILE *file, size_t *size) {
    long length;
    uint8_t *data;
    if (fseek(file, 0, SEEK_END) != 0 || (length = ftell(file)) <= 0 ||
        fseek(file, 0, SEEK_SET) != 0)
        return NULL;
    data = (uint8_t *)malloc((size_t)length);
    if (data && fread(data, 1, (size_t)length, file) != (size_t)length) {
        free(data);
        return NULL;
    }
    *size = (size_t)length;
    return data;
}

int main(int argc, char **argv) {
    const char *out_path = argc > 1 ? argv[1] : "split.pfm";
    /* The order the partial results arrive in: not the jobs' order. */
    static const int arrival[JOBS] = {2, 0, 1};
    uint32_t indices[TRIANGLE_COUNT * 3];
    uint32_t material_ids[TRIANGLE_COUNT];
    MltMaterial materials[MATERIAL_COUNT];
    MltSceneDesc desc;
    MltScene *scene = NULL;
    MltCamera camera;
    MltRenderSettings settings;
    MltRenderStats stats;
    MltBytes plan = {NULL, 0};
    MltBytes partial = {NULL, 0};
    MltBytes pair = {NULL, 0};
    const uint8_t *tree[2];
    size_t tree_sizes[2];
    FILE *files[JOBS] = {NULL, NULL, NULL};
    uint8_t *received[JOBS] = {NULL, NULL, NULL};
    const uint8_t *partials[JOBS];
    size_t sizes[JOBS];
    float *merged = NULL, *whole = NULL;
    size_t image_len;
    MltStatus status;
    uint32_t job;
    int q, m, i, ok = 0;

    if (argc != 1 && argc != 2 && argc != 5 && argc != 6) {
        fprintf(stderr, "usage: %s [out.pfm] [width height samples-per-pixel [path|bdpt]]\n",
                argv[0]);
        return 2;
    }

    /* The scene, as minimal.c builds it. Every job builds its scene from the same arrays:
     * a plan names its scene by a fingerprint of them, and a job refuses any other. */
    for (q = 0; q < QUAD_COUNT; ++q) {
        uint32_t a = (uint32_t)q * 4;
        uint32_t *t = indices + q * 6;
        t[0] = a; t[1] = a + 1; t[2] = a + 2;
        t[3] = a; t[4] = a + 2; t[5] = a + 3;
        material_ids[q * 2] = material_ids[q * 2 + 1] = quad_material[q];
    }
    for (m = 0; m < MATERIAL_COUNT; ++m) {
        if (!check(mlt_material_default(&materials[m]), "mlt_material_default")) return 1;
    }
    materials[WHITE].color[0] = 0.725f; materials[WHITE].color[1] = 0.71f;  materials[WHITE].color[2] = 0.68f;
    materials[RED].color[0] = 0.63f;    materials[RED].color[1] = 0.065f;   materials[RED].color[2] = 0.05f;
    materials[GREEN].color[0] = 0.14f;  materials[GREEN].color[1] = 0.45f;  materials[GREEN].color[2] = 0.091f;
    materials[LIGHT].color[0] = 0.0f;   materials[LIGHT].color[1] = 0.0f;   materials[LIGHT].color[2] = 0.0f;
    materials[LIGHT].emission[0] = 17.0f;
    materials[LIGHT].emission[1] = 12.0f;
    materials[LIGHT].emission[2] = 4.0f;
    if (!check(mlt_scene_desc_default(&desc), "mlt_scene_desc_default")) return 1;
    desc.positions = positions;
    desc.positions_len = VERTEX_COUNT * 3;
    desc.indices = indices;
    desc.indices_len = TRIANGLE_COUNT * 3;
    desc.material_ids = material_ids;
    desc.material_ids_len = TRIANGLE_COUNT;
    desc.materials = materials;
    desc.materials_len = MATERIAL_COUNT;
    if (!check(mlt_scene_create(&desc, &scene), "mlt_scene_create")) return 1;

    /* The Cornell box's camera is the default. Every algorithm splits into jobs; this
     * example takes the path tracer or BDPT. */
    if (!check(mlt_camera_default(&camera), "mlt_camera_default")) goto done;
    if (!check(mlt_render_settings_default(&settings), "mlt_render_settings_default"))
        goto done;
    settings.algorithm = MLT_ALGORITHM_PATH;
    settings.width = settings.height = 64;
    settings.samples_per_pixel = 16;
    settings.seed = 7;
    if (argc >= 5) {
        settings.width = (uint32_t)strtoul(argv[2], NULL, 10);
        settings.height = (uint32_t)strtoul(argv[3], NULL, 10);
        settings.samples_per_pixel = (uint32_t)strtoul(argv[4], NULL, 10);
    }
    if (argc == 6) {
        if (strcmp(argv[5], "bdpt") == 0) {
            settings.algorithm = MLT_ALGORITHM_BDPT;
        } else if (strcmp(argv[5], "path") != 0) {
            fprintf(stderr, "the algorithm is path or bdpt, not %s\n", argv[5]);
            goto done;
        }
    }

    /* 1. The plan: cheap, a few hundred bytes that every job and the merge get. It holds the
     *    camera and settings, so the jobs need only the scene and the plan. */
    if (!check(mlt_render_plan(scene, &camera, &settings, &plan), "mlt_render_plan")) goto done;
    printf("plan: %zu bytes\n", plan.size);

    /* 2. The jobs, here one after the other in this process. Each could run anywhere that
     *    holds the scene and the plan's bytes, with its own thread count (0: every core),
     *    progress callback and time limit (the plan's). */
    for (job = 0; job < JOBS; ++job) {
        if (!check(mlt_render_stats_default(&stats), "mlt_render_stats_default")) goto done;
        status = mlt_render_job(scene, plan.data, plan.size, job, JOBS, 0, NULL, NULL,
                                &partial, &stats);
        /* CANCELLED and TIME_LIMIT_REACHED also give a partial result, which merges into the
         * image of a render stopped the same way; any other failure gives none. */
        if (!check(status, "mlt_render_job")) goto done;
        files[job] = tmpfile();
        if (!files[job] || !send_bytes(&partial, files[job])) {
            perror("tmpfile");
            goto done;
        }
        printf("job %u of %d: %llu samples, %zu bytes\n", (unsigned)job, JOBS,
               (unsigned long long)stats.samples, partial.size);
        mlt_bytes_release(&partial); /* frees the bytes mlt gave; partial is empty again */
    }

    /* 3. The merge: the partial results in any order, each job given once. A farm of many
     *    jobs merges in a tree: a node adds a few partial results into one, which merges
     *    (or combines again) like any other. Here the first two arrivals are combined. */
    image_len = (size_t)settings.width * settings.height * 3;
    merged = (float *)malloc(sizeof(float) * image_len);
    whole = (float *)malloc(sizeof(float) * image_len);
    if (!merged || !whole) goto done;
    for (i = 0; i < JOBS; ++i) {
        received[i] = receive_bytes(files[arrival[i]], &sizes[i]);
        if (!received[i]) {
            fprintf(stderr, "could not read job %d's partial result back\n", arrival[i]);
            goto done;
        }
        partials[i] = received[i];
    }
    if (!check(mlt_render_combine(plan.data, plan.size, partials, sizes, 2, &pair),
               "mlt_render_combine"))
        goto done;
    printf("combined 2 partial results: %zu bytes\n", pair.size);
    tree[0] = pair.data;
    tree_sizes[0] = pair.size;
    tree[1] = partials[2];
    tree_sizes[1] = sizes[2];
    if (!check(mlt_render_stats_default(&stats), "mlt_render_stats_default")) goto done;
    status = mlt_render_merge(plan.data, plan.size, tree, tree_sizes, 2, merged, image_len,
                              &stats);
    if (!check(status, "mlt_render_merge")) goto done;
    printf("merged %d jobs: %llu samples, %llu rays\n", JOBS,
           (unsigned long long)stats.samples, (unsigned long long)stats.rays);

    /* The partial results carry a checksum: a flipped bit is an error, never a wrong image. */
    received[1][sizes[1] / 2] ^= 0x20;
    status = mlt_render_merge(plan.data, plan.size, partials, sizes, JOBS, whole, image_len,
                              NULL);
    if (status != MLT_STATUS_INVALID_ARGUMENT) {
        fprintf(stderr, "a corrupted partial result was not refused\n");
        goto done;
    }
    printf("a corrupted partial result is refused: %s\n", mlt_last_error_message());

    /* 4. The same frame on one machine: the same bits. */
    if (!check(mlt_render(scene, &camera, &settings, whole, image_len, NULL, NULL),
               "mlt_render"))
        goto done;
    if (memcmp(merged, whole, sizeof(float) * image_len) != 0) {
        fprintf(stderr, "the merged image differs from mlt_render's\n");
        goto done;
    }
    printf("the merged image equals mlt_render's bit for bit\n");
    ok = write_pfm(out_path, merged, settings.width, settings.height);

done:
    for (i = 0; i < JOBS; ++i) {
        free(received[i]);
        if (files[i]) fclose(files[i]);
    }
    free(merged);
    free(whole);
    mlt_bytes_release(&partial); /* release of an empty MltBytes is a no-op */
    mlt_bytes_release(&pair);
    mlt_bytes_release(&plan);
    mlt_scene_release(scene);
    return ok ? 0 : 1;
}
