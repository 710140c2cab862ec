/*
 * sky.c: a scene lit by an environment instead of emissive triangles.
 *
 * A grey ground square (diffuse, albedo 0.5) under a uniform white sky of radiance 1, seen
 * from straight above and path traced. The ground receives pi from the whole sky and
 * reflects albedo / pi of it towards the camera: every pixel converges to 0.5. The program
 * prints the image's mean and writes it as PFM (see minimal.c for the conventions every mlt
 * call follows, and for write_pfm).
 *
 * Usage:  sky [out.pfm] [width height samples-per-pixel]   (defaults: sky.pfm 64 64 64)
 *
 * Build (from the crate root, after `cargo build --release`):
 *   cc -std=c99 -Wall -Wextra -I include c_examples/sky.c \
 *      target/release/libmlt.a -lpthread -ldl -lm -o sky
 */

#include <mlt.h>

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

/* The ground: a 2 x 2 square at y = 0, counter-clockwise seen from above (+y). */
static const float positions[4 * 3] = {
    -1.0f, 0.0f, -1.0f,   -1.0f, 0.0f, 1.0f,   1.0f, 0.0f, 1.0f,   1.0f, 0.0f, -1.0f,
};
static const uint32_t indices[2 * 3] = {0, 1, 2, 0, 2, 3};

int main(int argc, char **argv) {
    const char *out_path = argc > 1 ? argv[1] : "sky.pfm";
    /* The sky's radiance, linear RGB. A constant environment is a 1 x 1 map; for an HDR
     * image, point `pixels` at width * height * 3 floats (rows from the top, the map's
     * centre looking along +Z, +Y up) and set width and height instead. */
    const float sky[3] = {1.0f, 1.0f, 1.0f};
    MltMaterial ground;
    MltEnvironment environment;
    MltSceneDesc desc;
    MltScene *scene = NULL;
    MltCamera camera;
    MltRenderSettings settings;
    float *image = NULL;
    size_t image_len, i;
    double sum = 0.0;
    int ok = 0;

    if (argc != 1 && argc != 2 && argc != 5) {
        fprintf(stderr, "usage: %s [out.pfm] [width height samples-per-pixel]\n", argv[0]);
        return 2;
    }
    if (!check(mlt_material_default(&ground), "mlt_material_default")) return 1;
    ground.color[0] = ground.color[1] = ground.color[2] = 0.5f;

    /* The environment: mlt_environment_constant points it at `sky`, which must stay valid
     * until mlt_scene_create returns (mlt copies it). */
    if (!check(mlt_environment_constant(&environment, sky), "mlt_environment_constant"))
        return 1;
    /* environment.scale and environment.rotation_degrees could scale and turn it; a sun
     * (MltSun, mlt_sun_default) and point, spot or directional lights (an array of
     * MltPunctualLight, each from mlt_punctual_light_default) go into the same desc. */

    if (!check(mlt_scene_desc_default(&desc), "mlt_scene_desc_default")) return 1;
    desc.positions = positions;
    desc.positions_len = 4 * 3;
    desc.indices = indices;
    desc.indices_len = 2 * 3;
    desc.materials = &ground;
    desc.materials_len = 1;
    desc.environment = &environment;
    if (!check(mlt_scene_create(&desc, &scene), "mlt_scene_create")) return 1;

    /* Straight down at the ground, which fills the image. */
    if (!check(mlt_camera_default(&camera), "mlt_camera_default")) goto done;
    camera.eye[0] = 0.0f;    camera.eye[1] = 2.0f;    camera.eye[2] = 0.0f;
    camera.target[0] = 0.0f; camera.target[1] = 0.0f; camera.target[2] = 0.0f;
    camera.up[0] = 0.0f;     camera.up[1] = 0.0f;     camera.up[2] = 1.0f;
    camera.fov_y_deg = 40.0f;

    if (!check(mlt_render_settings_default(&settings), "mlt_render_settings_default"))
        goto done;
    settings.algorithm = MLT_ALGORITHM_PATH;
    settings.width = settings.height = 64;
    settings.samples_per_pixel = 64;
    if (argc == 5) {
        settings.width = (uint32_t)strtoul(argv[2], NULL, 10);
        settings.height = (uint32_t)strtoul(argv[3], NULL, 10);
        settings.samples_per_pixel = (uint32_t)strtoul(argv[4], NULL, 10);
    }
    image_len = (size_t)settings.width * settings.height * 3;
    image = (float *)malloc(sizeof(float) * (image_len > 0 ? image_len : 1));
    if (!image) goto done;
    if (!check(mlt_render(scene, &camera, &settings, image, image_len, NULL, NULL),
               "mlt_render"))
        goto done;

    for (i = 0; i < image_len; ++i) sum += image[i];
    printf("mean %.6f (converges to 0.5)\n", sum / (double)image_len);
    ok = write_pfm(out_path, image, settings.width, settings.height);

done:
    free(image);
    mlt_scene_release(scene);
    return ok ? 0 : 1;
}
