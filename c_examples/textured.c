/*
 * textured.c: a textured metallic-roughness surface with per-vertex normals and texture
 * coordinates.
 *
 * A 2 x 2 square at y = 0 whose base colour is a 2 x 2 checker texture (8-bit sRGB: dark
 * texels top-left and bottom-right, white ones top-right and bottom-left), under a uniform
 * white sky of radiance 1, seen from straight above and path traced. Texture coordinates
 * follow glTF: uv (0, 0) is the texture's top-left texel, v grows downwards; here they are
 * laid out so that the texture appears upright in the image. A second set of texture
 * coordinates (glTF's TEXCOORD_1) mirrors u: with `set` 1 the base colour texture reads it
 * (its bit of texcoord1_slots) and the checker appears mirrored. The program prints the
 * mean of each quarter of the image, and writes the image
 * as PFM (see minimal.c for the conventions every mlt call follows, and for write_pfm).
 *
 * Usage:  textured [out.pfm] [width height samples-per-pixel [set]]
 *         (defaults: textured.pfm 32 32 16 0)
 *
 * Build (from the crate root, after `cargo build --release`):
 *   cc -std=c99 -Wall -Wextra -I include c_examples/textured.c \
 *      target/release/libmlt.a -lpthread -ldl -lm -o textured
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

/* The square, counter-clockwise seen from above (+y). The camera below looks down with
 * image up along -z and image right along +x, so vertex 0 is the image's top-left corner. */
static const float positions[4 * 3] = {
    -1.0f, 0.0f, -1.0f,   1.0f, 0.0f, -1.0f,   1.0f, 0.0f, 1.0f,   -1.0f, 0.0f, 1.0f,
};
static const uint32_t indices[2 * 3] = {0, 2, 1, 0, 3, 2};
/* Per-vertex shading normals (x y z) and texture coordinates (u v). */
static const float normals[4 * 3] = {
    0.0f, 1.0f, 0.0f,   0.0f, 1.0f, 0.0f,   0.0f, 1.0f, 0.0f,   0.0f, 1.0f, 0.0f,
};
static const float texcoords[4 * 2] = {
    0.0f, 0.0f,   1.0f, 0.0f,   1.0f, 1.0f,   0.0f, 1.0f,
};
/* Texture coordinate set 1: u mirrored. */
static const float texcoords1[4 * 2] = {
    1.0f, 0.0f,   0.0f, 0.0f,   0.0f, 1.0f,   1.0f, 1.0f,
};
/* The checker: 2 x 2 texels of 8-bit sRGB RGB, rows from the top. sRGB 64 is about 0.05
 * linear, 255 is 1. */
static const uint8_t checker[2 * 2 * 3] = {
    64, 64, 64,      255, 255, 255,
    255, 255, 255,   64, 64, 64,
};

int main(int argc, char **argv) {
    const char *out_path = argc > 1 ? argv[1] : "textured.pfm";
    const float sky[3] = {1.0f, 1.0f, 1.0f};
    MltTexture texture;
    MltMaterial surface;
    MltEnvironment environment;
    MltSceneDesc desc;
    MltScene *scene = NULL;
    MltCamera camera;
    MltRenderSettings settings;
    float *image = NULL;
    size_t image_len;
    uint32_t x, y, w, h;
    double sums[4] = {0.0, 0.0, 0.0, 0.0};
    size_t counts[4] = {0, 0, 0, 0};
    int ok = 0;
    const int set = argc == 6 ? atoi(argv[5]) : 0;

    if ((argc != 1 && argc != 2 && argc != 5 && argc != 6) || set < 0 || set > 1) {
        fprintf(stderr, "usage: %s [out.pfm] [width height samples-per-pixel [set]]\n",
                argv[0]);
        return 2;
    }

    /* The texture: 8-bit sRGB (the default encoding), nearest texel, clamped at the edges.
     * mlt copies the texels in mlt_scene_create. */
    if (!check(mlt_texture_default(&texture), "mlt_texture_default")) return 1;
    texture.width = 2;
    texture.height = 2;
    texture.channels = 3;
    texture.texel_type = MLT_TEXEL_U8;
    texture.texels = checker;
    texture.encoding = MLT_TEXTURE_SRGB;
    texture.wrap_u = texture.wrap_v = MLT_WRAP_CLAMP_TO_EDGE;
    texture.filter = MLT_FILTER_NEAREST;

    /* glTF's metallic-roughness model: a rough dielectric whose base colour (white, times
     * the texture) is the checker. Every texture slot of mlt_material_default is
     * MLT_NO_TEXTURE with the identity transform; the base colour slot takes texture 0. */
    if (!check(mlt_material_default(&surface), "mlt_material_default")) return 1;
    surface.kind = MLT_MATERIAL_METALLIC_ROUGHNESS;
    surface.color[0] = surface.color[1] = surface.color[2] = 1.0f;
    surface.metallic = 0.0f;
    surface.roughness = 1.0f;
    surface.base_color_texture.texture = 0;
    /* Each texture slot reads texture coordinate set 0 unless its MLT_TEXCOORD1_* bit is set. */
    if (set == 1) surface.texcoord1_slots = MLT_TEXCOORD1_BASE_COLOR;

    if (!check(mlt_environment_constant(&environment, sky), "mlt_environment_constant"))
        return 1;

    if (!check(mlt_scene_desc_default(&desc), "mlt_scene_desc_default")) return 1;
    desc.positions = positions;
    desc.positions_len = 4 * 3;
    desc.indices = indices;
    desc.indices_len = 2 * 3;
    desc.normals = normals;
    desc.normals_len = 4 * 3;
    desc.texcoords = texcoords;
    desc.texcoords_len = 4 * 2;
    desc.texcoords1 = texcoords1;
    desc.texcoords1_len = 4 * 2;
    desc.textures = &texture;
    desc.textures_len = 1;
    desc.materials = &surface;
    desc.materials_len = 1;
    desc.environment = &environment;
    if (!check(mlt_scene_create(&desc, &scene), "mlt_scene_create")) return 1;

    /* Straight down at the square, which fills the image, with -z up in the image. */
    if (!check(mlt_camera_default(&camera), "mlt_camera_default")) goto done;
    camera.eye[0] = 0.0f;    camera.eye[1] = 2.0f;    camera.eye[2] = 0.0f;
    camera.target[0] = 0.0f; camera.target[1] = 0.0f; camera.target[2] = 0.0f;
    camera.up[0] = 0.0f;     camera.up[1] = 0.0f;     camera.up[2] = -1.0f;
    camera.fov_y_deg = 43.0f;

    if (!check(mlt_render_settings_default(&settings), "mlt_render_settings_default"))
        goto done;
    settings.algorithm = MLT_ALGORITHM_PATH;
    settings.width = settings.height = 32;
    settings.samples_per_pixel = 16;
    if (argc >= 5) {
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

    /* The mean of each quarter (top-left, top-right, bottom-left, bottom-right). */
    w = settings.width;
    h = settings.height;
    for (y = 0; y < h; ++y) {
        for (x = 0; x < w; ++x) {
            int quarter = (y >= h / 2 ? 2 : 0) + (x >= w / 2 ? 1 : 0);
            const float *p = image + ((size_t)y * w + x) * 3;
            sums[quarter] += (p[0] + p[1] + p[2]) / 3.0;
            counts[quarter] += 1;
        }
    }
    printf("quarters: top-left %.4f top-right %.4f bottom-left %.4f bottom-right %.4f\n",
           sums[0] / (double)(counts[0] ? counts[0] : 1),
           sums[1] / (double)(counts[1] ? counts[1] : 1),
           sums[2] / (double)(counts[2] ? counts[2] : 1),
           sums[3] / (double)(counts[3] ? counts[3] : 1));
    ok = write_pfm(out_path, image, settings.width, settings.height);

done:
    free(image);
    mlt_scene_release(scene);
    return ok ? 0 : 1;
}
