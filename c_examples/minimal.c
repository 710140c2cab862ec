/*
 * minimal.c: the smallest complete mlt host.
 *
 * This program builds the Cornell box in code, renders it with mlt's default algorithm
 * (multiplexed Metropolis light transport) and writes
 * the result as a PFM image (a linear, floating-point format most image viewers and
 * tools such as ImageMagick or GIMP can open). Read it top to bottom: every mlt call is
 * explained where it is used.
 *
 * Usage:  minimal [out.pfm] [width height mutations-per-pixel]   (defaults: cornell.pfm 256 256 32)
 *
 * Build (from the crate root, after `cargo build --release`):
 *   cc -std=c99 -Wall -Wextra -I include c_examples/minimal.c \
 *      target/release/libmlt.a -lpthread -ldl -lm -o minimal
 * The file is also valid C++: `c++ -x c++ ...` compiles it unchanged.
 *
 * A few conventions hold for every mlt function; once you know them you know the API:
 *   - Structs you pass in (MltSceneDesc, MltMaterial, MltCamera, MltRenderSettings) are
 *     first filled by their mlt_*_default() initializer, then you change what you need.
 *     Structs mlt fills in (MltSceneInfo, MltRenderStats) are initialized the same way.
 *     The initializer also sets struct_size, so a future library with more fields still
 *     reads and writes exactly the fields this program was compiled with.
 *   - Every fallible call returns an MltStatus. MLT_STATUS_OK (0) means success. Otherwise
 *     mlt_status_string(status) says what kind of failure it was and
 *     mlt_last_error_message() says exactly which field, index or value was wrong.
 *   - Out-parameters are written only on success: on failure your variables keep whatever
 *     they held before.
 *   - Arrays are always passed as a pointer plus a number of elements, and mlt copies what
 *     it keeps: you may free your arrays as soon as the call returns.
 *   - Handles are released with mlt_*_release(), and releasing NULL does nothing.
 */

#include <mlt.h>

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------------------------- */
/* The scene: the classic Cornell box, in millimetres, y up (tests/scenes/cornell-box.obj). */
/* ------------------------------------------------------------------------------------- */

/*
 * Every surface of the box is a quad, given by its 4 corners in counter-clockwise order as
 * seen from its front side (the side the normal points to). mlt's rule is the usual
 * right-hand rule: triangle (v0, v1, v2) faces the side from which v0 -> v1 -> v2 turns
 * counter-clockwise. The walls face into the room, the blocks face outward, and the light
 * faces down (-y): an emitter only shines from its front side.
 */
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

/* ------------------------------------------------------------------------------------- */
/* Error handling: one helper that turns a status into a readable message.               */
/* ------------------------------------------------------------------------------------- */

/*
 * Returns 1 if `status` is MLT_STATUS_OK, else prints what went wrong and returns 0.
 * mlt_status_string() is the kind of failure ("invalid argument", ...), and
 * mlt_last_error_message() the sentence explaining it, e.g.
 *   "materials[2].emission.x is -1; emission must not be negative".
 * The message belongs to the calling thread and stays valid until its next mlt call.
 */
static int check(MltStatus status, const char *what) {
    if (status == MLT_STATUS_OK) return 1;
    fprintf(stderr, "%s failed: %s: %s\n", what, mlt_status_string((int32_t)status),
            mlt_last_error_message());
    return 0;
}

/* ------------------------------------------------------------------------------------- */
/* Progress: mlt calls this on our own thread about 20 times a second.                   */
/* ------------------------------------------------------------------------------------- */

static bool on_progress(float fraction, void *user_data) {
    (void)user_data; /* whatever pointer we passed to mlt_render; unused here */
    fprintf(stderr, "\rrendering: %3d%%", (int)(fraction * 100.0f + 0.5f));
    if (fraction >= 1.0f) fprintf(stderr, "\n");
    return true; /* return false to cancel: mlt_render then returns MLT_STATUS_CANCELLED */
}

/* ------------------------------------------------------------------------------------- */
/* Output: PFM, the simplest floating-point image format.                                */
/* ------------------------------------------------------------------------------------- */

/* Writes one float as 4 little-endian bytes, whatever the byte order of this machine. */
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

/*
 * A PFM file is a text header "PF\n<width> <height>\n-1.0\n" (PF: RGB; a negative scale:
 * little-endian floats) followed by the pixels, rows from the BOTTOM of the image to the
 * top. mlt's buffer goes from the top row down, so we write its rows in reverse.
 */
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

/* ------------------------------------------------------------------------------------- */

int main(int argc, char **argv) {
    const char *out_path = argc > 1 ? argv[1] : "cornell.pfm";
    uint32_t indices[TRIANGLE_COUNT * 3];
    uint32_t material_ids[TRIANGLE_COUNT];
    MltMaterial materials[MATERIAL_COUNT];
    MltSceneDesc desc;
    MltScene *scene = NULL;
    MltSceneInfo info;
    MltCamera camera;
    MltRenderSettings settings;
    float *image = NULL;
    size_t image_len;
    MltStatus status;
    int q, m, ok = 0;

    if (argc != 1 && argc != 2 && argc != 5) {
        fprintf(stderr, "usage: %s [out.pfm] [width height mutations-per-pixel]\n", argv[0]);
        return 2;
    }
    printf("mlt %s\n", mlt_version_string());
#if MLT_VERSION < 200
#error "this example needs mlt 0.2 or later"
#endif
    /* A library at least as new as the header works: it reads an older header's structs
     * by their struct_size. An older library may lack what this header declares. */
    if (mlt_version() < MLT_VERSION) {
        fprintf(stderr, "linked mlt %u is older than the header %u\n", (unsigned)mlt_version(),
                (unsigned)MLT_VERSION);
        return 1;
    }

    /* 1. Triangles. Each quad (a, b, c, d) becomes the triangles (a, b, c) and (a, c, d),
     *    which keeps the counter-clockwise order, so both face the same way as the quad.
     *    material_ids gives each triangle an index into the materials array. */
    for (q = 0; q < QUAD_COUNT; ++q) {
        uint32_t a = (uint32_t)q * 4;
        uint32_t *t = indices + q * 6;
        t[0] = a; t[1] = a + 1; t[2] = a + 2;
        t[3] = a; t[4] = a + 2; t[5] = a + 3;
        material_ids[q * 2] = material_ids[q * 2 + 1] = quad_material[q];
    }

    /* 2. Materials. mlt_material_default() gives a white diffuse material; we set the
     *    albedo (linear RGB in [0, 1]) and, for the light, the emitted radiance. Any
     *    material with a non-zero emission turns its triangles into area lights. */
    for (m = 0; m < MATERIAL_COUNT; ++m) {
        if (!check(mlt_material_default(&materials[m]), "mlt_material_default")) return 1;
        materials[m].kind = MLT_MATERIAL_DIFFUSE;
    }
    materials[WHITE].color[0] = 0.725f; materials[WHITE].color[1] = 0.71f;  materials[WHITE].color[2] = 0.68f;
    materials[RED].color[0] = 0.63f;    materials[RED].color[1] = 0.065f;   materials[RED].color[2] = 0.05f;
    materials[GREEN].color[0] = 0.14f;  materials[GREEN].color[1] = 0.45f;  materials[GREEN].color[2] = 0.091f;
    materials[LIGHT].color[0] = 0.0f;   materials[LIGHT].color[1] = 0.0f;   materials[LIGHT].color[2] = 0.0f;
    materials[LIGHT].emission[0] = 17.0f;
    materials[LIGHT].emission[1] = 12.0f;
    materials[LIGHT].emission[2] = 4.0f;

    /* 3. The scene. The description only points at our arrays (pointer + element count);
     *    mlt_scene_create validates everything, copies it and builds the BVH. On success
     *    `scene` receives a handle; on failure it stays NULL and check() says why. */
    if (!check(mlt_scene_desc_default(&desc), "mlt_scene_desc_default")) return 1;
    desc.positions = positions;
    desc.positions_len = VERTEX_COUNT * 3; /* floats, not vertices */
    desc.indices = indices;
    desc.indices_len = TRIANGLE_COUNT * 3; /* entries, not triangles */
    desc.material_ids = material_ids;
    desc.material_ids_len = TRIANGLE_COUNT;
    desc.materials = materials;
    desc.materials_len = MATERIAL_COUNT;
    desc.backend = MLT_BACKEND_BVH; /* the default; MLT_BACKEND_EMBREE needs a special build */
    if (!check(mlt_scene_create(&desc, &scene), "mlt_scene_create")) return 1;

    /* Structs mlt fills in are initialized too: their struct_size tells mlt which fields
     * this program's header has. */
    if (!check(mlt_scene_info_default(&info), "mlt_scene_info_default")) goto done;
    if (!check(mlt_scene_get_info(scene, &info), "mlt_scene_get_info")) goto done;
    printf("scene: %llu triangles, %llu lights, %llu degenerate\n",
           (unsigned long long)info.triangle_count, (unsigned long long)info.emitter_count,
           (unsigned long long)info.degenerate_triangle_count);

    /* 4. The camera. The default already is the Cornell box's camera; we spell it out.
     *    Image right is cross(target - eye, up): here the red wall (x = 552.8) is on the left. */
    if (!check(mlt_camera_default(&camera), "mlt_camera_default")) goto done;
    camera.eye[0] = 278.0f;    camera.eye[1] = 273.0f;    camera.eye[2] = -800.0f;
    camera.target[0] = 278.0f; camera.target[1] = 273.0f; camera.target[2] = -799.0f;
    camera.up[0] = 0.0f;       camera.up[1] = 1.0f;       camera.up[2] = 0.0f;
    camera.fov_y_deg = 39.307648f; /* vertical field of view, in degrees */

    /* 5. Render settings: start from the defaults (Metropolis light transport, 256 x 256,
     *    32 mutations per pixel), then pick size and mutations per pixel, the quality knob
     *    of the Metropolis algorithms (settings.algorithm = MLT_ALGORITHM_PATH with
     *    settings.samples_per_pixel would path-trace instead). The seed makes the render
     *    reproducible: same seed, same image, whatever the number of threads (threads = 0
     *    uses every core). */
    if (!check(mlt_render_settings_default(&settings), "mlt_render_settings_default")) goto done;
    if (argc == 5) {
        settings.width = (uint32_t)strtoul(argv[2], NULL, 10);
        settings.height = (uint32_t)strtoul(argv[3], NULL, 10);
        settings.mutations_per_pixel = (uint32_t)strtoul(argv[4], NULL, 10);
    }

    /* 6. Render. The image is width x height x 3 floats of linear RGB radiance, rows from
     *    top to bottom. We pass its length so mlt can check it is big enough. A bad size
     *    from the command line (say 0) is reported by mlt_render, not by us. */
    image_len = (size_t)settings.width * settings.height * 3;
    image = (float *)malloc(image_len > 0 ? image_len * sizeof(float) : 1);
    if (!image) {
        fprintf(stderr, "out of memory\n");
        goto done;
    }
    status = mlt_render(scene, &camera, &settings, image, image_len, on_progress, NULL);
    if (!check(status, "mlt_render")) goto done;

    /* 7. Save. */
    if (!write_pfm(out_path, image, settings.width, settings.height)) goto done;
    printf("wrote %s (%u x %u, %u mutations per pixel)\n", out_path, (unsigned)settings.width,
           (unsigned)settings.height, (unsigned)settings.mutations_per_pixel);
    ok = 1;

done:
    /* 8. Clean up. mlt_scene_release(NULL) is a no-op, so no need to test `scene`. */
    free(image);
    mlt_scene_release(scene);
    return ok ? 0 : 1;
}
