/*
 * mlt.hpp: a C++17 interface to mlt, header-only, over the C ABI of mlt.h.
 *
 * Written by hand (cbindgen generates only mlt.h). Link as for mlt.h: -lmlt (static: also
 * -lm -lpthread -ldl). Compiles warning-free with -Wall -Wextra -pedantic as C++17 and C++20.
 *
 *   - Errors are exceptions: every failing call throws mlt::Error, which carries the
 *     mlt::Status and the library's message (the field, index and value it rejected).
 *   - mlt::Scene owns a scene handle: move-only, released by its destructor.
 *   - Settings, camera, materials and lights are plain structs whose default member
 *     initializers are the library's defaults (each has library_defaults() to read the
 *     linked library's own), with enum classes instead of integer constants. They are
 *     converted to the C structs through the mlt_*_default() initializers, so struct_size
 *     is this header's and any field this header does not know keeps the library default.
 *   - Arrays are mlt::Span<T> (pointer and size), which any contiguous container converts
 *     to (std::vector, std::array, C arrays, and std::span in C++20).
 *   - The progress callback is any callable taking `const mlt::Progress &` and returning
 *     bool (false cancels) or void. Exceptions never cross into the library: one thrown by
 *     the callable is caught, the render is cancelled, and the exception is rethrown from
 *     mlt::render once the library has returned.
 *   - A render splits into jobs: mlt::render_plan gives the plan as mlt::Bytes (owned, freed
 *     by the destructor), mlt::render_job renders job k of N of it into a partial result,
 *     mlt::render_combine adds a few partial results into one (to merge in a tree), and
 *     mlt::render_merge merges the partial results, from any byte containers, into the
 *     image mlt::render gives, bit for bit.
 *
 *     mlt::Scene scene(desc);                          // throws mlt::Error on bad input
 *     mlt::RenderSettings settings;                    // the library's defaults
 *     settings.algorithm = mlt::Algorithm::Bdpt;
 *     mlt::Image image = mlt::render_image(scene, mlt::Camera{}, settings,
 *         [](const mlt::Progress &p) { std::printf("%.0f%%\r", 100.0 * p.fraction); });
 *
 * The C names stay available: mlt.h is included, and the C structs can be passed where a
 * finer control is needed (mlt::Scene accepts an MltSceneDesc, Scene::get() gives the
 * MltScene pointer).
 */

#ifndef MLT_HPP
#define MLT_HPP

#if __cplusplus < 201703L && !(defined(_MSVC_LANG) && _MSVC_LANG >= 201703L)
#  error "mlt.hpp needs C++17 or later (include mlt.h for the C interface)"
#endif

#include "mlt.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <iterator>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#if defined(__has_include)
#  if __has_include(<version>)
#    include <version>
#  endif
#endif
#if defined(__cpp_lib_span)
#  include <span>
#endif
#if defined(__cpp_lib_ranges)
#  include <ranges>
#endif

namespace mlt {

// ---------------------------------------------------------------------------------------
// Versions
// ---------------------------------------------------------------------------------------

/// The version of the header this program was compiled with, MAJOR * 10000 + MINOR * 100 +
/// PATCH (`version()` is the linked library's).
inline constexpr std::uint32_t header_version = MLT_VERSION;

/// The linked library's version, MAJOR * 10000 + MINOR * 100 + PATCH.
inline std::uint32_t version() noexcept { return mlt_version(); }

/// The linked library's version as "MAJOR.MINOR.PATCH".
inline const char *version_string() noexcept { return mlt_version_string(); }

// ---------------------------------------------------------------------------------------
// Enumerations: the C constants as enum classes, checked to keep the C values
// ---------------------------------------------------------------------------------------

/// Result of an mlt call (`MLT_STATUS_*`).
enum class Status : std::int32_t {
    Ok = MLT_STATUS_OK,
    InvalidArgument = MLT_STATUS_INVALID_ARGUMENT,
    Unsupported = MLT_STATUS_UNSUPPORTED,
    OutOfMemory = MLT_STATUS_OUT_OF_MEMORY,
    /// The progress callback cancelled the render (mlt::render returns it, with a valid image).
    Cancelled = MLT_STATUS_CANCELLED,
    /// The time limit stopped the render (mlt::render returns it, with a valid image).
    TimeLimitReached = MLT_STATUS_TIME_LIMIT_REACHED,
    InternalError = MLT_STATUS_INTERNAL_ERROR,
};

/// The rendering algorithm (`MLT_ALGORITHM_*`; mlt.h describes each).
enum class Algorithm : std::int32_t {
    Path = MLT_ALGORITHM_PATH,
    Bdpt = MLT_ALGORITHM_BDPT,
    Pssmlt = MLT_ALGORITHM_PSSMLT,
    Mmlt = MLT_ALGORITHM_MMLT,
    PssmltBdpt = MLT_ALGORITHM_PSSMLT_BDPT,
    PathSpaceMlt = MLT_ALGORITHM_PATH_SPACE_MLT,
    Erpt = MLT_ALGORITHM_ERPT,
};

/// The ray-tracing backend (`MLT_BACKEND_*`).
enum class Backend : std::int32_t {
    Bvh = MLT_BACKEND_BVH,
    Embree = MLT_BACKEND_EMBREE,
};

/// How much work the acceleration structure's build spends for faster rays
/// (`MLT_BUILD_QUALITY_*`).
enum class BuildQuality : std::int32_t {
    High = MLT_BUILD_QUALITY_HIGH,
    Medium = MLT_BUILD_QUALITY_MEDIUM,
    Fast = MLT_BUILD_QUALITY_FAST,
};

/// `MLT_MATERIAL_*`.
enum class MaterialKind : std::int32_t {
    Diffuse = MLT_MATERIAL_DIFFUSE,
    Mirror = MLT_MATERIAL_MIRROR,
    Dielectric = MLT_MATERIAL_DIELECTRIC,
    MetallicRoughness = MLT_MATERIAL_METALLIC_ROUGHNESS,
};

/// `MLT_ALPHA_*`.
enum class AlphaMode : std::int32_t {
    Opaque = MLT_ALPHA_OPAQUE,
    Mask = MLT_ALPHA_MASK,
    Blend = MLT_ALPHA_BLEND,
};

/// `MLT_TEXEL_*`.
enum class TexelType : std::int32_t {
    U8 = MLT_TEXEL_U8,
    F32 = MLT_TEXEL_F32,
};

/// `MLT_TEXTURE_*`.
enum class TextureEncoding : std::int32_t {
    Srgb = MLT_TEXTURE_SRGB,
    Linear = MLT_TEXTURE_LINEAR,
};

/// `MLT_WRAP_*`.
enum class Wrap : std::int32_t {
    Repeat = MLT_WRAP_REPEAT,
    ClampToEdge = MLT_WRAP_CLAMP_TO_EDGE,
    MirroredRepeat = MLT_WRAP_MIRRORED_REPEAT,
};

/// `MLT_FILTER_*` (a texture's lookup filter).
enum class TextureFilter : std::int32_t {
    Nearest = MLT_FILTER_NEAREST,
    Bilinear = MLT_FILTER_BILINEAR,
};

/// `MLT_LIGHT_*`.
enum class LightKind : std::int32_t {
    Point = MLT_LIGHT_POINT,
    Spot = MLT_LIGHT_SPOT,
    Directional = MLT_LIGHT_DIRECTIONAL,
};

/// The path-space mutations (`MLT_MUTATION_*`), indices of `RenderSettings::mutation_weights`
/// and of the per-mutation statistics: `settings.mutation_weights[index(Mutation::Lens)]`.
enum class Mutation : std::size_t {
    Bidirectional = MLT_MUTATION_BIDIRECTIONAL,
    Lens = MLT_MUTATION_LENS,
    Caustic = MLT_MUTATION_CAUSTIC,
    MultiChain = MLT_MUTATION_MULTI_CHAIN,
};

/// The array index of a mutation.
constexpr std::size_t index(Mutation mutation) noexcept {
    return static_cast<std::size_t>(mutation);
}

/// `MltTextureRef.texture` of a slot without a texture.
inline constexpr std::int32_t no_texture = MLT_NO_TEXTURE;
/// `Hit::triangle_id` of a ray that hit nothing.
inline constexpr std::uint32_t invalid_id = MLT_INVALID_ID;

namespace detail {
template <class E>
constexpr std::int32_t c_value(E value) noexcept {
    return static_cast<std::int32_t>(value);
}
} // namespace detail

// The enumerators are written as the C constants above; these pin the C values too, so a
// renumbered constant in mlt.h is a compile error here rather than a silent change.
static_assert(MLT_STATUS_OK == 0 && MLT_STATUS_INVALID_ARGUMENT == 1 &&
                  MLT_STATUS_UNSUPPORTED == 2 && MLT_STATUS_OUT_OF_MEMORY == 3 &&
                  MLT_STATUS_CANCELLED == 4 && MLT_STATUS_TIME_LIMIT_REACHED == 5 &&
                  MLT_STATUS_INTERNAL_ERROR == 6,
              "MltStatus values are stable");
static_assert(detail::c_value(Status::Ok) == MLT_STATUS_OK &&
                  detail::c_value(Status::InvalidArgument) == MLT_STATUS_INVALID_ARGUMENT &&
                  detail::c_value(Status::Unsupported) == MLT_STATUS_UNSUPPORTED &&
                  detail::c_value(Status::OutOfMemory) == MLT_STATUS_OUT_OF_MEMORY &&
                  detail::c_value(Status::Cancelled) == MLT_STATUS_CANCELLED &&
                  detail::c_value(Status::TimeLimitReached) == MLT_STATUS_TIME_LIMIT_REACHED &&
                  detail::c_value(Status::InternalError) == MLT_STATUS_INTERNAL_ERROR,
              "mlt::Status mirrors MltStatus");
static_assert(detail::c_value(Algorithm::Path) == MLT_ALGORITHM_PATH &&
                  detail::c_value(Algorithm::Bdpt) == MLT_ALGORITHM_BDPT &&
                  detail::c_value(Algorithm::Pssmlt) == MLT_ALGORITHM_PSSMLT &&
                  detail::c_value(Algorithm::Mmlt) == MLT_ALGORITHM_MMLT &&
                  detail::c_value(Algorithm::PssmltBdpt) == MLT_ALGORITHM_PSSMLT_BDPT &&
                  detail::c_value(Algorithm::PathSpaceMlt) == MLT_ALGORITHM_PATH_SPACE_MLT &&
                  detail::c_value(Algorithm::Erpt) == MLT_ALGORITHM_ERPT,
              "mlt::Algorithm mirrors MLT_ALGORITHM_*");
static_assert(detail::c_value(Backend::Bvh) == MLT_BACKEND_BVH &&
                  detail::c_value(Backend::Embree) == MLT_BACKEND_EMBREE,
              "mlt::Backend mirrors MLT_BACKEND_*");
static_assert(detail::c_value(BuildQuality::High) == MLT_BUILD_QUALITY_HIGH &&
                  detail::c_value(BuildQuality::Medium) == MLT_BUILD_QUALITY_MEDIUM &&
                  detail::c_value(BuildQuality::Fast) == MLT_BUILD_QUALITY_FAST,
              "mlt::BuildQuality mirrors MLT_BUILD_QUALITY_*");
static_assert(detail::c_value(MaterialKind::Diffuse) == MLT_MATERIAL_DIFFUSE &&
                  detail::c_value(MaterialKind::Mirror) == MLT_MATERIAL_MIRROR &&
                  detail::c_value(MaterialKind::Dielectric) == MLT_MATERIAL_DIELECTRIC &&
                  detail::c_value(MaterialKind::MetallicRoughness) ==
                      MLT_MATERIAL_METALLIC_ROUGHNESS,
              "mlt::MaterialKind mirrors MLT_MATERIAL_*");
static_assert(detail::c_value(AlphaMode::Opaque) == MLT_ALPHA_OPAQUE &&
                  detail::c_value(AlphaMode::Mask) == MLT_ALPHA_MASK &&
                  detail::c_value(AlphaMode::Blend) == MLT_ALPHA_BLEND,
              "mlt::AlphaMode mirrors MLT_ALPHA_*");
static_assert(detail::c_value(TexelType::U8) == MLT_TEXEL_U8 &&
                  detail::c_value(TexelType::F32) == MLT_TEXEL_F32,
              "mlt::TexelType mirrors MLT_TEXEL_*");
static_assert(detail::c_value(TextureEncoding::Srgb) == MLT_TEXTURE_SRGB &&
                  detail::c_value(TextureEncoding::Linear) == MLT_TEXTURE_LINEAR,
              "mlt::TextureEncoding mirrors MLT_TEXTURE_*");
static_assert(detail::c_value(Wrap::Repeat) == MLT_WRAP_REPEAT &&
                  detail::c_value(Wrap::ClampToEdge) == MLT_WRAP_CLAMP_TO_EDGE &&
                  detail::c_value(Wrap::MirroredRepeat) == MLT_WRAP_MIRRORED_REPEAT,
              "mlt::Wrap mirrors MLT_WRAP_*");
static_assert(detail::c_value(TextureFilter::Nearest) == MLT_FILTER_NEAREST &&
                  detail::c_value(TextureFilter::Bilinear) == MLT_FILTER_BILINEAR,
              "mlt::TextureFilter mirrors MLT_FILTER_*");
static_assert(detail::c_value(LightKind::Point) == MLT_LIGHT_POINT &&
                  detail::c_value(LightKind::Spot) == MLT_LIGHT_SPOT &&
                  detail::c_value(LightKind::Directional) == MLT_LIGHT_DIRECTIONAL,
              "mlt::LightKind mirrors MLT_LIGHT_*");
static_assert(index(Mutation::Bidirectional) == MLT_MUTATION_BIDIRECTIONAL &&
                  index(Mutation::Lens) == MLT_MUTATION_LENS &&
                  index(Mutation::Caustic) == MLT_MUTATION_CAUSTIC &&
                  index(Mutation::MultiChain) == MLT_MUTATION_MULTI_CHAIN,
              "mlt::Mutation mirrors MLT_MUTATION_*");

/// A static description of a status ("invalid argument", ...).
inline const char *status_string(Status status) noexcept {
    return mlt_status_string(static_cast<std::int32_t>(status));
}

/// Whether this build of the library can create scenes with `backend`.
inline bool backend_supported(Backend backend) noexcept {
    return mlt_backend_supported(static_cast<std::int32_t>(backend));
}

// ---------------------------------------------------------------------------------------
// Errors
// ---------------------------------------------------------------------------------------

/// A failed mlt call: its status, the library's message, and what() as
/// "<operation>: <status>: <message>" (e.g. "mlt_render: invalid argument: settings.width
/// is 0; it must be between 1 and 65536").
class Error : public std::runtime_error {
public:
    Error(Status status, const std::string &message, const std::string &operation = "mlt")
        : std::runtime_error(operation + ": " + status_string(status) + ": " + message),
          status_(status), message_(message) {}

    /// The status the call returned (never Status::Ok).
    Status status() const noexcept { return status_; }
    /// The library's message alone: which field, index or value was rejected.
    const char *message() const noexcept { return message_.what(); }

private:
    Status status_;
    std::runtime_error message_; // copying it cannot throw, as an exception's copy must not
};

namespace detail {
/// Throws unless `status` is MLT_STATUS_OK, with the library's message, read at once: it is
/// the calling thread's and the next mlt call replaces it.
inline void check(MltStatus status, const char *operation) {
    if (status != MLT_STATUS_OK) {
        throw Error(static_cast<Status>(status), mlt_last_error_message(), operation);
    }
}
} // namespace detail

// ---------------------------------------------------------------------------------------
// Span: a pointer and a count, the array type of this header
// ---------------------------------------------------------------------------------------

template <class T>
class Span;

namespace detail {
template <class T>
struct is_view : std::false_type {};
template <class T>
struct is_view<Span<T>> : std::true_type {};
#if defined(__cpp_lib_span)
template <class T, std::size_t Extent>
struct is_view<std::span<T, Extent>> : std::true_type {};
#endif
template <class T>
using remove_cvref_t = std::remove_cv_t<std::remove_reference_t<T>>;
/// The element type of a contiguous container `C` (through std::data), if it has one.
template <class C, class = void>
struct data_element {};
template <class C>
struct data_element<C, std::void_t<decltype(std::data(std::declval<C &>())),
                                   decltype(std::size(std::declval<C &>()))>> {
    using type = std::remove_pointer_t<decltype(std::data(std::declval<C &>()))>;
};
} // namespace detail

/// A view of `size()` contiguous `T`s it does not own: std::span's small subset that mlt
/// needs, in C++17 as well. Converts implicitly from std::vector, std::array, C arrays,
/// std::span (C++20) and Span<U> where a U* converts to a T* without slicing (U = T, or
/// T = const U); from a temporary container only when T is const (a function argument
/// then outlives the call). In C++20, `std::span<T>(span)` converts back.
template <class T>
class Span {
public:
    using element_type = T;
    using value_type = std::remove_cv_t<T>;
    using size_type = std::size_t;
    using pointer = T *;
    using reference = T &;
    using iterator = T *;

    constexpr Span() noexcept = default;
    constexpr Span(T *data, std::size_t size) noexcept : data_(data), size_(size) {}

    template <class C,
              class U = typename detail::data_element<C>::type,
              std::enable_if_t<!std::is_same_v<detail::remove_cvref_t<C>, Span> &&
                                   (std::is_lvalue_reference_v<C> || std::is_const_v<T> ||
                                    detail::is_view<detail::remove_cvref_t<C>>::value) &&
                                   std::is_convertible_v<U (*)[], T (*)[]>,
                               int> = 0>
    constexpr Span(C &&container) noexcept
        : data_(std::data(container)), size_(static_cast<std::size_t>(std::size(container))) {}

    constexpr T *data() const noexcept { return data_; }
    constexpr std::size_t size() const noexcept { return size_; }
    constexpr bool empty() const noexcept { return size_ == 0; }
    constexpr T &operator[](std::size_t i) const noexcept { return data_[i]; }
    constexpr T *begin() const noexcept { return data_; }
    constexpr T *end() const noexcept { return data_ + size_; }

private:
    T *data_ = nullptr;
    std::size_t size_ = 0;
};

} // namespace mlt

#if defined(__cpp_lib_ranges)
// A Span refers to elements it does not own: std::span may be made from a temporary one.
namespace std::ranges {
template <class T>
inline constexpr bool enable_borrowed_range<mlt::Span<T>> = true;
} // namespace std::ranges
#endif

namespace mlt {

// ---------------------------------------------------------------------------------------
// Plain values
// ---------------------------------------------------------------------------------------

/// A point or direction, x y z.
using Vec3 = std::array<float, 3>;
/// Linear RGB.
using Rgb = std::array<float, 3>;

namespace detail {
template <class T, std::size_t N>
void copy_to(T (&out)[N], const std::array<T, N> &in) noexcept {
    for (std::size_t i = 0; i < N; ++i) out[i] = in[i];
}
template <class T, std::size_t N>
std::array<T, N> to_array(const T (&in)[N]) noexcept {
    std::array<T, N> out{};
    for (std::size_t i = 0; i < N; ++i) out[i] = in[i];
    return out;
}
template <class E>
E from_c(std::int32_t value) noexcept {
    return static_cast<E>(value);
}
} // namespace detail

/// A material's use of a texture (glTF's KHR_texture_transform: scale, rotate, offset).
struct TextureRef {
    /// Index into SceneDesc::textures, or no_texture.
    std::int32_t texture = no_texture;
    std::array<float, 2> offset{0.0f, 0.0f};
    float rotation = 0.0f;
    std::array<float, 2> scale{1.0f, 1.0f};
    /// The texture coordinate set it is looked up at: 0 (SceneDesc::texcoords) or 1
    /// (SceneDesc::texcoords1), glTF's texCoord. In C, a bit of MltMaterial.texcoord1_slots.
    std::uint32_t texcoord = 0;

    /// The C slot `name` of a material; sets `bit` (its MLT_TEXCOORD1_*) of `texcoord1_slots`
    /// for set 1. Throws for a set other than 0 and 1.
    MltTextureRef to_c(const char *name, std::uint32_t bit, std::uint32_t &texcoord1_slots) const {
        if (texcoord > 1) {
            throw Error(Status::InvalidArgument,
                        std::string("material.") + name + ".texcoord is " +
                            std::to_string(texcoord) + "; the texture coordinate sets are 0 and 1",
                        "mlt::Material::to_c");
        }
        if (texcoord == 1) texcoord1_slots |= bit;
        MltTextureRef c{};
        c.texture = texture;
        detail::copy_to(c.offset, offset);
        c.rotation = rotation;
        detail::copy_to(c.scale, scale);
        return c;
    }
    /// The slot `c` whose bit of MltMaterial.texcoord1_slots is `texcoord1_bit` (0: clear).
    static TextureRef from_c(const MltTextureRef &c, std::uint32_t texcoord1_bit) noexcept {
        TextureRef r;
        r.texture = c.texture;
        r.offset = detail::to_array(c.offset);
        r.rotation = c.rotation;
        r.scale = detail::to_array(c.scale);
        r.texcoord = texcoord1_bit != 0 ? 1u : 0u;
        return r;
    }
};

/// A material (MltMaterial; mlt.h documents each field). The defaults are
/// mlt_material_default's: a light grey (0.8) diffuse surface.
struct Material {
    // BEGIN GENERATED material members: tests/parameters.rs writes these lines from src/scene/material.rs
    /// The scattering model: diffuse (Lambertian), mirror, dielectric (smooth glass) or
    /// metallic-roughness (glTF 2.0's).
    MaterialKind kind = MaterialKind::Diffuse;
    /// Diffuse albedo, mirror reflectance, glass tint or metallic-roughness base colour, linear
    /// RGB.
    std::array<float, 3> color{0.8f, 0.8f, 0.8f};
    /// Radiance emitted from the front (counter-clockwise) side, linear RGB; emissive triangles are
    /// area lights.
    std::array<float, 3> emission{0.0f, 0.0f, 0.0f};
    /// Index of refraction of a dielectric and of the metallic-roughness model's dielectric part
    /// (there > 0).
    float ior = 1.5f;
    /// Metallic-roughness: metalness, 0 a dielectric, 1 a metal whose reflectance is the colour.
    float metallic = 0.0f;
    /// Metallic-roughness: perceptual roughness (GGX alpha = roughness squared; 0 is the exact
    /// specular lobe).
    float roughness = 1.0f;
    /// Metallic-roughness: the fraction of the non-metallic base transmitted, not diffusely
    /// reflected (KHR_materials_transmission).
    float transmission = 0.0f;
    /// Coverage, times the base colour texture's alpha and the vertex colour's; used by the mask
    /// and blend alpha modes.
    float alpha = 1.0f;
    /// What alpha does: opaque ignores it, mask cuts the surface out where alpha < alpha_cutoff
    /// (glTF's MASK), blend lets a fraction 1 - alpha of the light pass straight through (glTF's
    /// BLEND, as stochastic coverage).
    AlphaMode alpha_mode = AlphaMode::Opaque;
    /// The mask alpha mode's threshold (glTF's alphaCutoff).
    float alpha_cutoff = 0.5f;
    /// Multiplies the colour (RGB) and alpha (A), for every kind; usually 8-bit sRGB.
    TextureRef base_color_texture;
    /// Green multiplies the roughness, blue the metalness (glTF's packing); usually linear.
    TextureRef metallic_roughness_texture;
    /// A tangent-space normal map (glTF's convention: +Y up in the image); usually linear.
    TextureRef normal_texture;
    /// Multiplies the emission; usually 8-bit sRGB.
    TextureRef emission_texture;
    /// Scales the normal map's x and y (glTF's normalTexture.scale).
    float normal_scale = 1.0f;
    /// Metallic-roughness: give rough metals the light glTF's single-scattering model loses (Kulla
    /// and Conty 2017).
    bool energy_compensation = false;
    /// Dispersion as the Abbe number V_d (0: none; KHR_materials_dispersion's dispersion is 20 /
    /// V_d); spectral renders only.
    float abbe_number = 0.0f;
    /// Metallic-roughness: red multiplies the transmission (KHR_materials_transmission's
    /// transmissionTexture); usually linear.
    TextureRef transmission_texture;
    /// Metallic-roughness: a clear coat over the material, a white GGX reflection of index 1.5 with
    /// its own roughness and normal (KHR_materials_clearcoat's clearcoatFactor); 0 is none.
    float clearcoat = 0.0f;
    /// Metallic-roughness: the clear coat's perceptual roughness (GGX alpha = its square; 0 is an
    /// exact mirror).
    float clearcoat_roughness = 0.0f;
    /// Metallic-roughness: red multiplies the clear coat (KHR_materials_clearcoat's
    /// clearcoatTexture); usually linear.
    TextureRef clearcoat_texture;
    /// Metallic-roughness: green multiplies the clear coat's roughness (clearcoatRoughnessTexture);
    /// usually linear.
    TextureRef clearcoat_roughness_texture;
    /// Metallic-roughness: the clear coat's own tangent-space normal map (clearcoatNormalTexture);
    /// without it the coat follows the interpolated normal, not normal_texture.
    TextureRef clearcoat_normal_texture;
    /// Scales the clear coat's normal map's x and y (clearcoatNormalTexture.scale).
    float clearcoat_normal_scale = 1.0f;
    /// Dielectric and transmissive metallic-roughness: 0 is thin-walled, above 0 the mesh encloses
    /// an absorbing volume (KHR_materials_volume's thicknessFactor).
    float thickness = 0.0f;
    /// The volume's colour after attenuation_distance of travel inside it, linear RGB
    /// (KHR_materials_volume's attenuationColor).
    std::array<float, 3> attenuation_color{1.0f, 1.0f, 1.0f};
    /// The distance inside the volume after which white light has the attenuation colour; the
    /// largest float (FLT_MAX) is infinity, no absorption (KHR_materials_volume's
    /// attenuationDistance).
    float attenuation_distance = 3.4028235e38f;
    /// Metallic-roughness: strength of the dielectric's specular reflection, 0 a pure diffuse base
    /// (KHR_materials_specular's specularFactor).
    float specular = 1.0f;
    /// Metallic-roughness: scales the dielectric's F0 per channel, linear RGB, may exceed 1 (F0
    /// times it is clamped to 1; KHR_materials_specular's specularColorFactor).
    std::array<float, 3> specular_color{1.0f, 1.0f, 1.0f};
    /// Metallic-roughness: alpha multiplies the specular strength (KHR_materials_specular's
    /// specularTexture); usually linear.
    TextureRef specular_texture;
    /// Metallic-roughness: RGB multiplies the specular colour (KHR_materials_specular's
    /// specularColorTexture); usually 8-bit sRGB.
    TextureRef specular_color_texture;
    /// Metallic-roughness: colour of a sheen layer over the material (velvet, cloth), linear RGB;
    /// black is none (KHR_materials_sheen's sheenColorFactor).
    std::array<float, 3> sheen_color{0.0f, 0.0f, 0.0f};
    /// Metallic-roughness: the sheen's roughness (Charlie distribution, alpha = roughness squared,
    /// at least 0.07 squared; KHR_materials_sheen's sheenRoughnessFactor).
    float sheen_roughness = 0.0f;
    /// Metallic-roughness: RGB multiplies the sheen colour (KHR_materials_sheen's
    /// sheenColorTexture); usually 8-bit sRGB.
    TextureRef sheen_color_texture;
    /// Metallic-roughness: alpha multiplies the sheen roughness (KHR_materials_sheen's
    /// sheenRoughnessTexture); usually linear.
    TextureRef sheen_roughness_texture;
    /// Metallic-roughness: anisotropy of the microfacets (brushed metal), alpha along its direction
    /// = mix(alpha, 1, strength squared); 0 is isotropic (KHR_materials_anisotropy's
    /// anisotropyStrength).
    float anisotropy = 0.0f;
    /// Metallic-roughness: the anisotropy's direction in radians, counter-clockwise from the mesh's
    /// tangent towards its bitangent (KHR_materials_anisotropy's anisotropyRotation).
    float anisotropy_rotation = 0.0f;
    /// Metallic-roughness: red and green are the anisotropy's direction in the tangent plane mapped
    /// from [-1, 1] to [0, 1] (then rotated by anisotropy_rotation), blue multiplies its strength
    /// (KHR_materials_anisotropy's anisotropyTexture); linear.
    TextureRef anisotropy_texture;
    /// Metallic-roughness: strength of a thin film over the material, its interference colours
    /// (soap bubbles, oil); 0 is none (KHR_materials_iridescence's iridescenceFactor). Exact per
    /// wavelength in spectral renders, integrated over each RGB channel otherwise.
    float iridescence = 0.0f;
    /// Metallic-roughness: red multiplies the thin film's strength (KHR_materials_iridescence's
    /// iridescenceTexture); usually linear.
    TextureRef iridescence_texture;
    /// Metallic-roughness: the thin film's index of refraction (KHR_materials_iridescence's
    /// iridescenceIor).
    float iridescence_ior = 1.3f;
    /// Metallic-roughness: the thin film's thickness in nanometres where the thickness texture's
    /// green is 0 (KHR_materials_iridescence's iridescenceThicknessMinimum).
    float iridescence_thickness_minimum = 100.0f;
    /// Metallic-roughness: the thin film's thickness in nanometres where the thickness texture's
    /// green is 1, and everywhere without it; 0 is no film (KHR_materials_iridescence's
    /// iridescenceThicknessMaximum).
    float iridescence_thickness_maximum = 400.0f;
    /// Metallic-roughness: green interpolates the thin film's thickness from the minimum (0) to the
    /// maximum (1) (KHR_materials_iridescence's iridescenceThicknessTexture); usually linear.
    TextureRef iridescence_thickness_texture;
    // END GENERATED material members

    static Material diffuse(const Rgb &albedo) {
        Material m;
        m.color = albedo;
        return m;
    }
    static Material mirror(const Rgb &reflectance) {
        Material m;
        m.kind = MaterialKind::Mirror;
        m.color = reflectance;
        return m;
    }
    static Material dielectric(float ior, const Rgb &tint = {1.0f, 1.0f, 1.0f}) {
        Material m;
        m.kind = MaterialKind::Dielectric;
        m.color = tint;
        m.ior = ior;
        return m;
    }
    static Material metallic_roughness(const Rgb &base_color, float metallic, float roughness) {
        Material m;
        m.kind = MaterialKind::MetallicRoughness;
        m.color = base_color;
        m.metallic = metallic;
        m.roughness = roughness;
        return m;
    }
    /// A black diffuse surface emitting `radiance` from its front side: an area light.
    static Material emitter(const Rgb &radiance) {
        Material m;
        m.color = {0.0f, 0.0f, 0.0f};
        m.emission = radiance;
        return m;
    }

    MltMaterial to_c() const {
        MltMaterial c;
        detail::check(mlt_material_default(&c), "mlt_material_default");
        // BEGIN GENERATED material to C
        c.kind = detail::c_value(kind);
        detail::copy_to(c.color, color);
        detail::copy_to(c.emission, emission);
        c.ior = ior;
        c.metallic = metallic;
        c.roughness = roughness;
        c.transmission = transmission;
        c.alpha = alpha;
        c.alpha_mode = detail::c_value(alpha_mode);
        c.alpha_cutoff = alpha_cutoff;
        c.base_color_texture =
            base_color_texture.to_c("base_color_texture", MLT_TEXCOORD1_BASE_COLOR, c.texcoord1_slots);
        c.metallic_roughness_texture =
            metallic_roughness_texture.to_c("metallic_roughness_texture", MLT_TEXCOORD1_METALLIC_ROUGHNESS, c.texcoord1_slots);
        c.normal_texture =
            normal_texture.to_c("normal_texture", MLT_TEXCOORD1_NORMAL, c.texcoord1_slots);
        c.emission_texture =
            emission_texture.to_c("emission_texture", MLT_TEXCOORD1_EMISSION, c.texcoord1_slots);
        c.normal_scale = normal_scale;
        c.energy_compensation = energy_compensation ? 1u : 0u;
        c.abbe_number = abbe_number;
        c.transmission_texture =
            transmission_texture.to_c("transmission_texture", MLT_TEXCOORD1_TRANSMISSION, c.texcoord1_slots);
        c.clearcoat = clearcoat;
        c.clearcoat_roughness = clearcoat_roughness;
        c.clearcoat_texture =
            clearcoat_texture.to_c("clearcoat_texture", MLT_TEXCOORD1_CLEARCOAT, c.texcoord1_slots);
        c.clearcoat_roughness_texture =
            clearcoat_roughness_texture.to_c("clearcoat_roughness_texture", MLT_TEXCOORD1_CLEARCOAT_ROUGHNESS, c.texcoord1_slots);
        c.clearcoat_normal_texture =
            clearcoat_normal_texture.to_c("clearcoat_normal_texture", MLT_TEXCOORD1_CLEARCOAT_NORMAL, c.texcoord1_slots);
        c.clearcoat_normal_scale = clearcoat_normal_scale;
        c.thickness = thickness;
        detail::copy_to(c.attenuation_color, attenuation_color);
        c.attenuation_distance = attenuation_distance;
        c.specular = specular;
        detail::copy_to(c.specular_color, specular_color);
        c.specular_texture =
            specular_texture.to_c("specular_texture", MLT_TEXCOORD1_SPECULAR, c.texcoord1_slots);
        c.specular_color_texture =
            specular_color_texture.to_c("specular_color_texture", MLT_TEXCOORD1_SPECULAR_COLOR, c.texcoord1_slots);
        detail::copy_to(c.sheen_color, sheen_color);
        c.sheen_roughness = sheen_roughness;
        c.sheen_color_texture =
            sheen_color_texture.to_c("sheen_color_texture", MLT_TEXCOORD1_SHEEN_COLOR, c.texcoord1_slots);
        c.sheen_roughness_texture =
            sheen_roughness_texture.to_c("sheen_roughness_texture", MLT_TEXCOORD1_SHEEN_ROUGHNESS, c.texcoord1_slots);
        c.anisotropy = anisotropy;
        c.anisotropy_rotation = anisotropy_rotation;
        c.anisotropy_texture =
            anisotropy_texture.to_c("anisotropy_texture", MLT_TEXCOORD1_ANISOTROPY, c.texcoord1_slots);
        c.iridescence = iridescence;
        c.iridescence_texture =
            iridescence_texture.to_c("iridescence_texture", MLT_TEXCOORD1_IRIDESCENCE, c.texcoord1_slots);
        c.iridescence_ior = iridescence_ior;
        c.iridescence_thickness_minimum = iridescence_thickness_minimum;
        c.iridescence_thickness_maximum = iridescence_thickness_maximum;
        c.iridescence_thickness_texture =
            iridescence_thickness_texture.to_c("iridescence_thickness_texture", MLT_TEXCOORD1_IRIDESCENCE_THICKNESS, c.texcoord1_slots);
        // END GENERATED material to C
        return c;
    }
    static Material from_c(const MltMaterial &c) noexcept {
        Material m;
        // BEGIN GENERATED material from C
        m.kind = detail::from_c<MaterialKind>(c.kind);
        m.color = detail::to_array(c.color);
        m.emission = detail::to_array(c.emission);
        m.ior = c.ior;
        m.metallic = c.metallic;
        m.roughness = c.roughness;
        m.transmission = c.transmission;
        m.alpha = c.alpha;
        m.alpha_mode = detail::from_c<AlphaMode>(c.alpha_mode);
        m.alpha_cutoff = c.alpha_cutoff;
        m.base_color_texture =
            TextureRef::from_c(c.base_color_texture, c.texcoord1_slots & MLT_TEXCOORD1_BASE_COLOR);
        m.metallic_roughness_texture =
            TextureRef::from_c(c.metallic_roughness_texture, c.texcoord1_slots & MLT_TEXCOORD1_METALLIC_ROUGHNESS);
        m.normal_texture =
            TextureRef::from_c(c.normal_texture, c.texcoord1_slots & MLT_TEXCOORD1_NORMAL);
        m.emission_texture =
            TextureRef::from_c(c.emission_texture, c.texcoord1_slots & MLT_TEXCOORD1_EMISSION);
        m.normal_scale = c.normal_scale;
        m.energy_compensation = c.energy_compensation != 0;
        m.abbe_number = c.abbe_number;
        m.transmission_texture =
            TextureRef::from_c(c.transmission_texture, c.texcoord1_slots & MLT_TEXCOORD1_TRANSMISSION);
        m.clearcoat = c.clearcoat;
        m.clearcoat_roughness = c.clearcoat_roughness;
        m.clearcoat_texture =
            TextureRef::from_c(c.clearcoat_texture, c.texcoord1_slots & MLT_TEXCOORD1_CLEARCOAT);
        m.clearcoat_roughness_texture =
            TextureRef::from_c(c.clearcoat_roughness_texture, c.texcoord1_slots & MLT_TEXCOORD1_CLEARCOAT_ROUGHNESS);
        m.clearcoat_normal_texture =
            TextureRef::from_c(c.clearcoat_normal_texture, c.texcoord1_slots & MLT_TEXCOORD1_CLEARCOAT_NORMAL);
        m.clearcoat_normal_scale = c.clearcoat_normal_scale;
        m.thickness = c.thickness;
        m.attenuation_color = detail::to_array(c.attenuation_color);
        m.attenuation_distance = c.attenuation_distance;
        m.specular = c.specular;
        m.specular_color = detail::to_array(c.specular_color);
        m.specular_texture =
            TextureRef::from_c(c.specular_texture, c.texcoord1_slots & MLT_TEXCOORD1_SPECULAR);
        m.specular_color_texture =
            TextureRef::from_c(c.specular_color_texture, c.texcoord1_slots & MLT_TEXCOORD1_SPECULAR_COLOR);
        m.sheen_color = detail::to_array(c.sheen_color);
        m.sheen_roughness = c.sheen_roughness;
        m.sheen_color_texture =
            TextureRef::from_c(c.sheen_color_texture, c.texcoord1_slots & MLT_TEXCOORD1_SHEEN_COLOR);
        m.sheen_roughness_texture =
            TextureRef::from_c(c.sheen_roughness_texture, c.texcoord1_slots & MLT_TEXCOORD1_SHEEN_ROUGHNESS);
        m.anisotropy = c.anisotropy;
        m.anisotropy_rotation = c.anisotropy_rotation;
        m.anisotropy_texture =
            TextureRef::from_c(c.anisotropy_texture, c.texcoord1_slots & MLT_TEXCOORD1_ANISOTROPY);
        m.iridescence = c.iridescence;
        m.iridescence_texture =
            TextureRef::from_c(c.iridescence_texture, c.texcoord1_slots & MLT_TEXCOORD1_IRIDESCENCE);
        m.iridescence_ior = c.iridescence_ior;
        m.iridescence_thickness_minimum = c.iridescence_thickness_minimum;
        m.iridescence_thickness_maximum = c.iridescence_thickness_maximum;
        m.iridescence_thickness_texture =
            TextureRef::from_c(c.iridescence_thickness_texture, c.texcoord1_slots & MLT_TEXCOORD1_IRIDESCENCE_THICKNESS);
        // END GENERATED material from C
        return m;
    }
    /// The linked library's defaults (equal to a default-constructed Material).
    static Material library_defaults() {
        MltMaterial c;
        detail::check(mlt_material_default(&c), "mlt_material_default");
        return from_c(c);
    }
};

/// A texture (MltTexture). `texels` is not owned: it must stay valid until the Scene is
/// created (mlt copies it). The factories check the number of values.
struct Texture {
    std::uint32_t width = 0;
    std::uint32_t height = 0;
    /// 1 (grey), 2 (grey, alpha), 3 (RGB) or 4 (RGBA).
    std::uint32_t channels = 4;
    TexelType texel_type = TexelType::U8;
    /// width × height × channels values of texel_type, rows from the top.
    const void *texels = nullptr;
    TextureEncoding encoding = TextureEncoding::Srgb;
    Wrap wrap_u = Wrap::Repeat;
    Wrap wrap_v = Wrap::Repeat;
    TextureFilter filter = TextureFilter::Bilinear;

    /// 8-bit texels, 255 meaning 1 (sRGB colour channels by default).
    static Texture u8(std::uint32_t width, std::uint32_t height, std::uint32_t channels,
                      Span<const std::uint8_t> texels,
                      TextureEncoding encoding = TextureEncoding::Srgb) {
        check_count(width, height, channels, texels.size());
        Texture t;
        t.width = width;
        t.height = height;
        t.channels = channels;
        t.texel_type = TexelType::U8;
        t.texels = texels.data();
        t.encoding = encoding;
        return t;
    }
    /// Linear float texels.
    static Texture f32(std::uint32_t width, std::uint32_t height, std::uint32_t channels,
                       Span<const float> texels) {
        check_count(width, height, channels, texels.size());
        Texture t;
        t.width = width;
        t.height = height;
        t.channels = channels;
        t.texel_type = TexelType::F32;
        t.texels = texels.data();
        t.encoding = TextureEncoding::Linear;
        return t;
    }

    MltTexture to_c() const {
        MltTexture c;
        detail::check(mlt_texture_default(&c), "mlt_texture_default");
        c.width = width;
        c.height = height;
        c.channels = channels;
        c.texel_type = detail::c_value(texel_type);
        c.texels = texels;
        c.encoding = detail::c_value(encoding);
        c.wrap_u = detail::c_value(wrap_u);
        c.wrap_v = detail::c_value(wrap_v);
        c.filter = detail::c_value(filter);
        return c;
    }
    static Texture from_c(const MltTexture &c) noexcept {
        Texture t;
        t.width = c.width;
        t.height = c.height;
        t.channels = c.channels;
        t.texel_type = detail::from_c<TexelType>(c.texel_type);
        t.texels = c.texels;
        t.encoding = detail::from_c<TextureEncoding>(c.encoding);
        t.wrap_u = detail::from_c<Wrap>(c.wrap_u);
        t.wrap_v = detail::from_c<Wrap>(c.wrap_v);
        t.filter = detail::from_c<TextureFilter>(c.filter);
        return t;
    }
    static Texture library_defaults() {
        MltTexture c;
        detail::check(mlt_texture_default(&c), "mlt_texture_default");
        return from_c(c);
    }

private:
    static void check_count(std::uint32_t width, std::uint32_t height, std::uint32_t channels,
                            std::size_t count) {
        const unsigned long long expected =
            static_cast<unsigned long long>(width) * height * channels;
        if (count != expected) {
            throw Error(Status::InvalidArgument,
                        "the texture's texels hold " + std::to_string(count) + " values, but " +
                            std::to_string(width) + " x " + std::to_string(height) + " x " +
                            std::to_string(channels) + " need " + std::to_string(expected),
                        "mlt::Texture");
        }
    }
};

/// An environment (MltEnvironment): an equirectangular map of `pixels` (width × height ×
/// 3 floats, rows from the top; see mlt.h for its orientation), or, while `pixels` is
/// empty, the constant radiance `radiance` (a 1 × 1 map). Unlike the C struct, a
/// default-constructed Environment is usable: a constant white sky.
struct Environment {
    Span<const float> pixels;
    std::uint32_t width = 0;
    std::uint32_t height = 0;
    /// The radiance of a constant environment (used while `pixels` is empty).
    Rgb radiance{1.0f, 1.0f, 1.0f};
    float rotation_degrees = 0.0f;
    float scale = 1.0f;

    static Environment constant(const Rgb &radiance) {
        Environment e;
        e.radiance = radiance;
        return e;
    }
    static Environment map(Span<const float> pixels, std::uint32_t width, std::uint32_t height) {
        if (pixels.size() != static_cast<unsigned long long>(width) * height * 3) {
            throw Error(Status::InvalidArgument,
                        "the environment's pixels hold " + std::to_string(pixels.size()) +
                            " floats, but a " + std::to_string(width) + " x " +
                            std::to_string(height) + " RGB map needs " +
                            std::to_string(static_cast<unsigned long long>(width) * height * 3),
                        "mlt::Environment");
        }
        Environment e;
        e.pixels = pixels;
        e.width = width;
        e.height = height;
        return e;
    }

    /// The C struct, pointing into `pixels` or into this object's `radiance`: keep this
    /// Environment alive and unmoved while the C struct is used.
    MltEnvironment to_c() const {
        MltEnvironment c;
        detail::check(mlt_environment_default(&c), "mlt_environment_default");
        if (pixels.empty()) {
            c.pixels = radiance.data();
            c.width = 1;
            c.height = 1;
        } else {
            if (pixels.size() < static_cast<unsigned long long>(width) * height * 3) {
                throw Error(Status::InvalidArgument,
                            "the environment's pixels hold " + std::to_string(pixels.size()) +
                                " floats, fewer than its " + std::to_string(width) + " x " +
                                std::to_string(height) + " RGB texels",
                            "mlt::Environment");
            }
            c.pixels = pixels.data();
            c.width = width;
            c.height = height;
        }
        c.rotation_degrees = rotation_degrees;
        c.scale = scale;
        return c;
    }
};

/// The sun (MltSun): a distant disc. The defaults are mlt_sun_default's.
struct Sun {
    /// From the scene towards the sun.
    Vec3 direction{0.0f, 1.0f, 0.0f};
    float angular_radius_degrees = 0.27f;
    Rgb irradiance{1.0f, 1.0f, 1.0f};

    MltSun to_c() const {
        MltSun c;
        detail::check(mlt_sun_default(&c), "mlt_sun_default");
        detail::copy_to(c.direction, direction);
        c.angular_radius_degrees = angular_radius_degrees;
        detail::copy_to(c.irradiance, irradiance);
        return c;
    }
    static Sun from_c(const MltSun &c) noexcept {
        Sun s;
        s.direction = detail::to_array(c.direction);
        s.angular_radius_degrees = c.angular_radius_degrees;
        s.irradiance = detail::to_array(c.irradiance);
        return s;
    }
    static Sun library_defaults() {
        MltSun c;
        detail::check(mlt_sun_default(&c), "mlt_sun_default");
        return from_c(c);
    }
};

/// A point, spot or directional light (MltPunctualLight). The defaults are
/// mlt_punctual_light_default's: a white point light at the origin.
struct PunctualLight {
    LightKind kind = LightKind::Point;
    Vec3 position{0.0f, 0.0f, 0.0f};
    Vec3 direction{0.0f, 0.0f, -1.0f};
    Rgb intensity{1.0f, 1.0f, 1.0f};
    float inner_cone_degrees = 0.0f;
    float outer_cone_degrees = 45.0f;

    static PunctualLight point(const Vec3 &position, const Rgb &intensity) {
        PunctualLight l;
        l.position = position;
        l.intensity = intensity;
        return l;
    }
    static PunctualLight spot(const Vec3 &position, const Vec3 &direction, const Rgb &intensity,
                              float inner_cone_degrees, float outer_cone_degrees) {
        PunctualLight l;
        l.kind = LightKind::Spot;
        l.position = position;
        l.direction = direction;
        l.intensity = intensity;
        l.inner_cone_degrees = inner_cone_degrees;
        l.outer_cone_degrees = outer_cone_degrees;
        return l;
    }
    /// Light travelling along `direction`, of irradiance `irradiance`.
    static PunctualLight directional(const Vec3 &direction, const Rgb &irradiance) {
        PunctualLight l;
        l.kind = LightKind::Directional;
        l.direction = direction;
        l.intensity = irradiance;
        return l;
    }

    MltPunctualLight to_c() const {
        MltPunctualLight c;
        detail::check(mlt_punctual_light_default(&c), "mlt_punctual_light_default");
        c.kind = detail::c_value(kind);
        detail::copy_to(c.position, position);
        detail::copy_to(c.direction, direction);
        detail::copy_to(c.intensity, intensity);
        c.inner_cone_degrees = inner_cone_degrees;
        c.outer_cone_degrees = outer_cone_degrees;
        return c;
    }
    static PunctualLight from_c(const MltPunctualLight &c) noexcept {
        PunctualLight l;
        l.kind = detail::from_c<LightKind>(c.kind);
        l.position = detail::to_array(c.position);
        l.direction = detail::to_array(c.direction);
        l.intensity = detail::to_array(c.intensity);
        l.inner_cone_degrees = c.inner_cone_degrees;
        l.outer_cone_degrees = c.outer_cone_degrees;
        return l;
    }
    static PunctualLight library_defaults() {
        MltPunctualLight c;
        detail::check(mlt_punctual_light_default(&c), "mlt_punctual_light_default");
        return from_c(c);
    }
};

/// Everything a Scene is made of (MltSceneDesc; mlt.h documents each array). The spans
/// refer to the host's arrays, which must stay valid until the Scene constructor returns:
/// mlt copies what it keeps.
struct SceneDesc {
    /// x y z per vertex.
    Span<const float> positions;
    /// 3 vertex indices per triangle, counter-clockwise seen from the front.
    Span<const std::uint32_t> indices;
    /// One material index per triangle, or empty: every triangle uses material 0.
    Span<const std::uint32_t> material_ids;
    Span<const Material> materials;
    Backend backend = Backend::Bvh;
    BuildQuality build_quality = BuildQuality::High;
    std::optional<Environment> environment;
    std::optional<Sun> sun;
    Span<const PunctualLight> punctual_lights;
    /// Per-vertex attributes, each empty or as many as the vertices: normals (x y z),
    /// texture coordinates (u v), tangents (x y z w) and linear RGBA colours.
    Span<const float> normals;
    Span<const float> texcoords;
    Span<const float> tangents;
    Span<const float> colors;
    Span<const Texture> textures;
    /// Texture coordinate set 1 (u v per vertex, glTF's TEXCOORD_1), or empty: read by the
    /// texture slots whose TextureRef::texcoord is 1.
    Span<const float> texcoords1;
};

/// A perspective camera (MltCamera). The defaults are mlt_camera_default's: the Cornell
/// box's pinhole camera.
struct Camera {
    Vec3 eye{278.0f, 273.0f, -800.0f};
    Vec3 target{278.0f, 273.0f, -799.0f};
    Vec3 up{0.0f, 1.0f, 0.0f};
    float fov_y_deg = 39.307648f;
    /// 0 for a pinhole.
    float lens_radius = 0.0f;
    /// 0 means |target - eye|.
    float focus_distance = 0.0f;

    MltCamera to_c() const {
        MltCamera c;
        detail::check(mlt_camera_default(&c), "mlt_camera_default");
        detail::copy_to(c.eye, eye);
        detail::copy_to(c.target, target);
        detail::copy_to(c.up, up);
        c.fov_y_deg = fov_y_deg;
        c.lens_radius = lens_radius;
        c.focus_distance = focus_distance;
        return c;
    }
    static Camera from_c(const MltCamera &c) noexcept {
        Camera cam;
        cam.eye = detail::to_array(c.eye);
        cam.target = detail::to_array(c.target);
        cam.up = detail::to_array(c.up);
        cam.fov_y_deg = c.fov_y_deg;
        cam.lens_radius = c.lens_radius;
        cam.focus_distance = c.focus_distance;
        return cam;
    }
    static Camera library_defaults() {
        MltCamera c;
        detail::check(mlt_camera_default(&c), "mlt_camera_default");
        return from_c(c);
    }
};

/// How to render (MltRenderSettings; mlt.h documents each field and its range). The
/// defaults are mlt_render_settings_default's: 256 × 256, multiplexed MLT with 32
/// mutations per pixel. The library validates the values when rendering.
struct RenderSettings {
    // BEGIN GENERATED settings members: tests/parameters.rs writes these lines from src/render/settings.rs
    /// Image width in pixels.
    std::uint32_t width = 256;
    /// Image height in pixels.
    std::uint32_t height = 256;
    /// The light-transport algorithm.
    Algorithm algorithm = Algorithm::Mmlt;
    /// Path tracing, BDPT and ERPT: samples per pixel (0: until the time limit).
    std::uint32_t samples_per_pixel = 64;
    /// Most scattering vertices between camera and light (0: emitters seen directly).
    std::uint32_t max_depth = 5;
    /// Worker threads (0: a pool of one per core shared by such renders); the image does not depend
    /// on it.
    std::uint32_t threads = 0;
    /// Seed of every random number: equal seeds and settings give equal images.
    std::uint64_t seed = 0;
    /// Stop after this many seconds (0: no limit).
    double time_limit_seconds = 0.0;
    /// Metropolis: mutations per pixel (0: until the time limit).
    std::uint32_t mutations_per_pixel = 32;
    /// Metropolis: samples seeding the chains and the brightness estimate (0: one per 8 planned
    /// mutations, at least 65536; 262144 for a render planned by time alone).
    std::uint32_t bootstrap_samples = 0;
    /// Metropolis: number of Markov chains, at most the bootstrap samples.
    std::uint32_t chains = 1024;
    /// PSSMLT: probability of a large (independent) step.
    float large_step_probability = 0.3f;
    /// PSSMLT: standard deviation of a small step in primary sample space.
    float small_step_sigma = 0.01f;
    /// Metropolis: path-traced samples of depths 0 and 1 per chain mutation (0: the chains render
    /// every depth).
    std::uint32_t direct_samples_per_mutation = 1;
    /// Path-space MLT: relative probabilities of the bidirectional mutation and the lens, caustic
    /// and multi-chain perturbations (the first positive).
    std::array<float, 4> mutation_weights{0.5f, 0.25f, 0.25f, 0.25f};
    /// ERPT: perturbations per chain.
    std::uint32_t erpt_chain_length = 10;
    /// ERPT: energy (luminance) each chain step deposits (0: one chain per camera sample on
    /// average).
    float erpt_deposit_energy = 0.0f;
    /// Path-space MLT: after a warm-up, weight each mutation by its acceptance rate there.
    bool adapt_mutation_weights = false;
    /// Path-space MLT and ERPT: perturb directions in the BSDF's sample space instead of within a
    /// cone.
    bool perturb_in_sample_space = false;
    /// Metropolis and ERPT: partial images of the post-process noise filter (0: no filter; 8 is a
    /// good start).
    std::uint32_t filter_buffers = 0;
    /// The filter's strength (higher smooths more).
    float filter_strength = 0.45f;
    /// The filter's search radius in pixels.
    std::uint32_t filter_radius = 7;
    /// Metropolis: share of the rays spent on samples that go on estimating the brightness (0: the
    /// bootstrap and large steps alone).
    float normalization_work_fraction = 0.05f;
    /// Spectral transport: four wavelengths per path instead of RGB; dispersive glass splits light.
    bool spectral = false;
    /// Path tracing and PSSMLT: scattering vertices after which Russian roulette may end a path.
    std::uint32_t roulette_start_depth = 3;
    /// Path tracing and PSSMLT: the highest probability with which Russian roulette lets a path go
    /// on.
    float roulette_max_survival = 0.95f;
    /// Path tracing: read textures at full resolution, as the other algorithms do (by default
    /// camera paths filter them over the pixel's footprint, mip-mapped, until their first diffuse
    /// or glossy bounce).
    bool full_resolution_textures = false;
    // END GENERATED settings members

    /// The C struct: mlt_render_settings_default, then every field of this struct.
    MltRenderSettings to_c() const {
        MltRenderSettings c;
        detail::check(mlt_render_settings_default(&c), "mlt_render_settings_default");
        // BEGIN GENERATED settings to C
        c.width = width;
        c.height = height;
        c.algorithm = detail::c_value(algorithm);
        c.samples_per_pixel = samples_per_pixel;
        c.max_depth = max_depth;
        c.threads = threads;
        c.seed = seed;
        c.time_limit_seconds = time_limit_seconds;
        c.mutations_per_pixel = mutations_per_pixel;
        c.bootstrap_samples = bootstrap_samples;
        c.chains = chains;
        c.large_step_probability = large_step_probability;
        c.small_step_sigma = small_step_sigma;
        c.direct_samples_per_mutation = direct_samples_per_mutation;
        detail::copy_to(c.mutation_weights, mutation_weights);
        c.erpt_chain_length = erpt_chain_length;
        c.erpt_deposit_energy = erpt_deposit_energy;
        c.adapt_mutation_weights = adapt_mutation_weights ? 1u : 0u;
        c.perturb_in_sample_space = perturb_in_sample_space ? 1u : 0u;
        c.filter_buffers = filter_buffers;
        c.filter_strength = filter_strength;
        c.filter_radius = filter_radius;
        c.normalization_work_fraction = normalization_work_fraction;
        c.spectral = spectral ? 1u : 0u;
        c.roulette_start_depth = roulette_start_depth;
        c.roulette_max_survival = roulette_max_survival;
        c.full_resolution_textures = full_resolution_textures ? 1u : 0u;
        // END GENERATED settings to C
        return c;
    }
    static RenderSettings from_c(const MltRenderSettings &c) noexcept {
        RenderSettings s;
        // BEGIN GENERATED settings from C
        s.width = c.width;
        s.height = c.height;
        s.algorithm = detail::from_c<Algorithm>(c.algorithm);
        s.samples_per_pixel = c.samples_per_pixel;
        s.max_depth = c.max_depth;
        s.threads = c.threads;
        s.seed = c.seed;
        s.time_limit_seconds = c.time_limit_seconds;
        s.mutations_per_pixel = c.mutations_per_pixel;
        s.bootstrap_samples = c.bootstrap_samples;
        s.chains = c.chains;
        s.large_step_probability = c.large_step_probability;
        s.small_step_sigma = c.small_step_sigma;
        s.direct_samples_per_mutation = c.direct_samples_per_mutation;
        s.mutation_weights = detail::to_array(c.mutation_weights);
        s.erpt_chain_length = c.erpt_chain_length;
        s.erpt_deposit_energy = c.erpt_deposit_energy;
        s.adapt_mutation_weights = c.adapt_mutation_weights != 0;
        s.perturb_in_sample_space = c.perturb_in_sample_space != 0;
        s.filter_buffers = c.filter_buffers;
        s.filter_strength = c.filter_strength;
        s.filter_radius = c.filter_radius;
        s.normalization_work_fraction = c.normalization_work_fraction;
        s.spectral = c.spectral != 0;
        s.roulette_start_depth = c.roulette_start_depth;
        s.roulette_max_survival = c.roulette_max_survival;
        s.full_resolution_textures = c.full_resolution_textures != 0;
        // END GENERATED settings from C
        return s;
    }
    /// The linked library's defaults (equal to a default-constructed RenderSettings when
    /// the library is the one this header belongs to).
    static RenderSettings library_defaults() {
        MltRenderSettings c;
        detail::check(mlt_render_settings_default(&c), "mlt_render_settings_default");
        return from_c(c);
    }
};

/// What a render did (MltRenderStats; mlt.h documents each field).
struct RenderStats {
    std::uint64_t samples = 0;
    std::uint64_t rays = 0;
    std::uint64_t invalid_samples = 0;
    double seconds = 0.0;
    std::uint32_t threads = 0;
    std::uint64_t accepted_mutations = 0;
    double normalization = 0.0;
    std::uint64_t mutations = 0;
    /// Indexed by index(Mutation::...).
    std::array<std::uint64_t, 4> mutations_proposed{};
    std::array<std::uint64_t, 4> mutations_accepted{};
    std::array<float, 4> mutation_weights{};
    double filter_changed_fraction = 0.0;
    double filter_mean_neighbours = 0.0;
    std::uint64_t normalization_samples = 0;
    double normalization_relative_error = 0.0;
    double normalization_largest_share = 0.0;

    static RenderStats from_c(const MltRenderStats &c) noexcept {
        RenderStats s;
        s.samples = c.samples;
        s.rays = c.rays;
        s.invalid_samples = c.invalid_samples;
        s.seconds = c.seconds;
        s.threads = c.threads;
        s.accepted_mutations = c.accepted_mutations;
        s.normalization = c.normalization;
        s.mutations = c.mutations;
        s.mutations_proposed = detail::to_array(c.mutations_proposed);
        s.mutations_accepted = detail::to_array(c.mutations_accepted);
        s.mutation_weights = detail::to_array(c.mutation_weights);
        s.filter_changed_fraction = c.filter_changed_fraction;
        s.filter_mean_neighbours = c.filter_mean_neighbours;
        s.normalization_samples = c.normalization_samples;
        s.normalization_relative_error = c.normalization_relative_error;
        s.normalization_largest_share = c.normalization_largest_share;
        return s;
    }
};

/// Facts about a scene (MltSceneInfo).
struct SceneInfo {
    std::uint64_t triangle_count = 0;
    /// Zero-area triangles: never hit, never emit.
    std::uint64_t degenerate_triangle_count = 0;
    /// Emissive triangles.
    std::uint64_t emitter_count = 0;
    Vec3 bounds_min{};
    Vec3 bounds_max{};
    Backend backend = Backend::Bvh;
    BuildQuality build_quality = BuildQuality::High;
    /// Bytes the acceleration structure holds, and the seconds its build took.
    std::uint64_t accel_memory_bytes = 0;
    double accel_build_seconds = 0.0;

    static SceneInfo from_c(const MltSceneInfo &c) noexcept {
        SceneInfo i;
        i.triangle_count = c.triangle_count;
        i.degenerate_triangle_count = c.degenerate_triangle_count;
        i.emitter_count = c.emitter_count;
        i.bounds_min = detail::to_array(c.bounds_min);
        i.bounds_max = detail::to_array(c.bounds_max);
        i.backend = detail::from_c<Backend>(c.backend);
        i.build_quality = detail::from_c<BuildQuality>(c.build_quality);
        i.accel_memory_bytes = c.accel_memory_bytes;
        i.accel_build_seconds = c.accel_build_seconds;
        return i;
    }
};

// ---------------------------------------------------------------------------------------
// Ray queries: the C structs themselves, so batches go to mlt without a copy
// ---------------------------------------------------------------------------------------

/// origin + t · direction for t in [tmin, tmax] (MltRay).
using Ray = MltRay;
/// A closest hit (MltHit): triangle_id is the host's triangle index, or invalid_id.
using Hit = MltHit;

/// The ray from `origin` along `direction` (any nonzero length; t counts in it).
inline Ray ray(const Vec3 &origin, const Vec3 &direction, float tmin = 0.0f,
               float tmax = std::numeric_limits<float>::infinity()) noexcept {
    Ray r{};
    detail::copy_to(r.origin, origin);
    detail::copy_to(r.direction, direction);
    r.tmin = tmin;
    r.tmax = tmax;
    return r;
}

/// The ray from `from` towards `to`: t = 1 at `to`, so (0, 1) is "between them".
inline Ray segment(const Vec3 &from, const Vec3 &to, float tmin = 0.0f,
                   float tmax = std::numeric_limits<float>::infinity()) noexcept {
    return ray(from, {to[0] - from[0], to[1] - from[1], to[2] - from[2]}, tmin, tmax);
}

/// Whether a hit found a triangle.
inline bool is_hit(const Hit &hit) noexcept { return hit.triangle_id != invalid_id; }

// ---------------------------------------------------------------------------------------
// Scene: the RAII handle
// ---------------------------------------------------------------------------------------

/// An immutable scene, sharing ownership of its MltScene: a copy holds one more reference
/// (mlt_scene_retain), and the last Scene destroyed releases it. Thread safe: any number
/// of threads may render and query one scene at once, and a render keeps the scene alive
/// even if every Scene is destroyed meanwhile.
class Scene {
public:
    /// An empty handle (what a moved-from Scene is). Using it throws.
    Scene() noexcept = default;

    /// Validates `desc`, copies its arrays and builds the acceleration structure; throws
    /// Error on invalid input (the message names the array, index and value).
    explicit Scene(const SceneDesc &desc) {
        std::vector<MltMaterial> materials;
        materials.reserve(desc.materials.size());
        for (const Material &m : desc.materials) materials.push_back(m.to_c());
        std::vector<MltPunctualLight> lights;
        lights.reserve(desc.punctual_lights.size());
        for (const PunctualLight &l : desc.punctual_lights) lights.push_back(l.to_c());
        std::vector<MltTexture> textures;
        textures.reserve(desc.textures.size());
        for (const Texture &t : desc.textures) textures.push_back(t.to_c());
        std::optional<MltEnvironment> environment;
        if (desc.environment) environment = desc.environment->to_c();
        std::optional<MltSun> sun;
        if (desc.sun) sun = desc.sun->to_c();

        MltSceneDesc c;
        detail::check(mlt_scene_desc_default(&c), "mlt_scene_desc_default");
        c.positions = desc.positions.data();
        c.positions_len = desc.positions.size();
        c.indices = desc.indices.data();
        c.indices_len = desc.indices.size();
        c.material_ids = desc.material_ids.data();
        c.material_ids_len = desc.material_ids.size();
        c.materials = materials.data();
        c.materials_len = materials.size();
        c.backend = detail::c_value(desc.backend);
        c.build_quality = detail::c_value(desc.build_quality);
        c.environment = environment ? &*environment : nullptr;
        c.sun = sun ? &*sun : nullptr;
        c.punctual_lights = lights.data();
        c.punctual_lights_len = lights.size();
        c.normals = desc.normals.data();
        c.normals_len = desc.normals.size();
        c.texcoords = desc.texcoords.data();
        c.texcoords_len = desc.texcoords.size();
        c.tangents = desc.tangents.data();
        c.tangents_len = desc.tangents.size();
        c.colors = desc.colors.data();
        c.colors_len = desc.colors.size();
        c.textures = textures.data();
        c.textures_len = textures.size();
        c.texcoords1 = desc.texcoords1.data();
        c.texcoords1_len = desc.texcoords1.size();
        detail::check(mlt_scene_create(&c, &handle_), "mlt_scene_create");
    }

    /// From the C description (initialized with mlt_scene_desc_default).
    explicit Scene(const MltSceneDesc &desc) {
        detail::check(mlt_scene_create(&desc, &handle_), "mlt_scene_create");
    }

    /// Takes over a reference to a scene (from mlt_scene_create or mlt_scene_retain, or
    /// NULL).
    static Scene adopt(MltScene *scene) noexcept {
        Scene s;
        s.handle_ = scene;
        return s;
    }

    ~Scene() { mlt_scene_release(handle_); }
    Scene(Scene &&other) noexcept : handle_(std::exchange(other.handle_, nullptr)) {}
    Scene &operator=(Scene &&other) noexcept {
        if (this != &other) {
            mlt_scene_release(handle_);
            handle_ = std::exchange(other.handle_, nullptr);
        }
        return *this;
    }
    Scene(const Scene &other) : handle_(other.handle_) {
        if (handle_) detail::check(mlt_scene_retain(handle_), "mlt_scene_retain");
    }
    Scene &operator=(const Scene &other) {
        Scene copy(other);
        std::swap(handle_, copy.handle_);
        return *this;
    }

    /// Whether this holds a scene.
    explicit operator bool() const noexcept { return handle_ != nullptr; }
    /// The C handle, still owned by this Scene.
    const MltScene *get() const noexcept { return handle_; }
    /// Gives up this Scene's reference: the caller releases the result with
    /// mlt_scene_release.
    MltScene *release() noexcept { return std::exchange(handle_, nullptr); }

    SceneInfo info() const {
        MltSceneInfo c;
        detail::check(mlt_scene_info_default(&c), "mlt_scene_info_default");
        detail::check(mlt_scene_get_info(handle_, &c), "mlt_scene_get_info");
        return SceneInfo::from_c(c);
    }

    /// Closest hits of `rays` into `hits` (at least as many), on the calling thread.
    void intersect(Span<const Ray> rays, Span<Hit> hits) const {
        if (hits.size() < rays.size()) throw_too_short("hits", hits.size(), rays.size());
        detail::check(mlt_intersect(handle_, rays.data(), rays.size(), hits.data()),
                      "mlt_intersect");
    }
    std::vector<Hit> intersect(Span<const Ray> rays) const {
        std::vector<Hit> hits(rays.size());
        intersect(rays, hits);
        return hits;
    }

    /// For each ray, 1 if any triangle lies on it, else 0, into `occluded` (at least as
    /// many).
    void occluded(Span<const Ray> rays, Span<std::uint8_t> results) const {
        if (results.size() < rays.size())
            throw_too_short("occluded", results.size(), rays.size());
        detail::check(mlt_occluded(handle_, rays.data(), rays.size(), results.data()),
                      "mlt_occluded");
    }
    std::vector<bool> occluded(Span<const Ray> rays) const {
        std::vector<std::uint8_t> flags(rays.size());
        occluded(rays, flags);
        return std::vector<bool>(flags.begin(), flags.end());
    }

private:
    [[noreturn]] static void throw_too_short(const char *name, std::size_t size,
                                             std::size_t rays) {
        throw Error(Status::InvalidArgument,
                    std::string(name) + " holds " + std::to_string(size) + " results for " +
                        std::to_string(rays) + " rays",
                    "mlt::Scene");
    }

    MltScene *handle_ = nullptr;
};

// ---------------------------------------------------------------------------------------
// Rendering
// ---------------------------------------------------------------------------------------

/// What the progress callback is told.
struct Progress {
    /// The fraction done, in [0, 1]; a finished render reports 1 last.
    float fraction = 0.0f;
};

/// How a render ended. Errors are thrown instead: status is Ok, Cancelled or
/// TimeLimitReached, and with each the image is valid (a stopped render's pixels are
/// normalized by the samples they received).
struct RenderResult {
    Status status = Status::Ok;
    /// The library's message when the render stopped early ("" when it completed).
    std::string message;
    RenderStats stats;

    /// Whether every requested sample was taken.
    bool completed() const noexcept { return status == Status::Ok; }
};

/// A rendered image: width × height × 3 floats of linear RGB radiance, rows from the top.
struct Image {
    std::uint32_t width = 0;
    std::uint32_t height = 0;
    std::vector<float> rgb;
    RenderResult result;

    /// The 3 floats of pixel (x, y), y counted from the top.
    Span<const float> pixel(std::uint32_t x, std::uint32_t y) const noexcept {
        return Span<const float>(rgb.data() + (std::size_t(y) * width + x) * 3, 3);
    }
};

namespace detail {

/// The progress callback handed to mlt: calls the host's callable and keeps its exception
/// away from the library's frames (the render is cancelled, the exception kept for later).
template <class F>
struct ProgressForwarder {
    F &callable;
    std::exception_ptr error;

    static bool call(float fraction, void *user_data) noexcept {
        auto &self = *static_cast<ProgressForwarder *>(user_data);
        if (self.error) return false; // it threw: cancel, and do not call it again
        try {
            const Progress progress{fraction};
            if constexpr (std::is_void_v<std::invoke_result_t<F &, const Progress &>>) {
                self.callable(progress);
                return true;
            } else {
                return static_cast<bool>(self.callable(progress));
            }
        } catch (...) {
            self.error = std::current_exception();
            return false;
        }
    }
};

/// How a render, job or merge that returned `status` ended: throws Error unless it is Ok,
/// Cancelled or TimeLimitReached (each of which wrote its outputs).
inline RenderResult result_of(MltStatus status, const char *operation,
                              const MltRenderStats &c_stats) {
    RenderResult result;
    result.status = static_cast<Status>(status);
    if (status == MLT_STATUS_CANCELLED || status == MLT_STATUS_TIME_LIMIT_REACHED) {
        result.message = mlt_last_error_message();
    } else {
        check(status, operation);
    }
    result.stats = RenderStats::from_c(c_stats);
    return result;
}

inline RenderResult render(const Scene &scene, const Camera &camera,
                           const RenderSettings &settings, Span<float> rgb_out,
                           MltProgressCallback callback, void *user_data,
                           const std::exception_ptr *callback_error) {
    const MltCamera c_camera = camera.to_c();
    const MltRenderSettings c_settings = settings.to_c();
    MltRenderStats c_stats;
    check(mlt_render_stats_default(&c_stats), "mlt_render_stats_default");
    const MltStatus status =
        mlt_render_ex(scene.get(), &c_camera, &c_settings, rgb_out.data(), rgb_out.size(),
                      callback, user_data, &c_stats);
    // The library has returned: the callable's exception may go on.
    if (callback_error && *callback_error) std::rethrow_exception(*callback_error);
    return result_of(status, "mlt_render", c_stats);
}

} // namespace detail

/// Renders `scene` seen by `camera` into `rgb_out` (at least width × height × 3 floats;
/// linear RGB, rows from the top). Throws Error on invalid input; returns how the render
/// ended (see RenderResult).
inline RenderResult render(const Scene &scene, const Camera &camera,
                           const RenderSettings &settings, Span<float> rgb_out) {
    return detail::render(scene, camera, settings, rgb_out, nullptr, nullptr, nullptr);
}

/// As above, calling `progress(const Progress &)` on this thread about 20 times a second.
/// It returns bool (false cancels the render, which stops once every pixel has a sample)
/// or void (go on). If it throws, the render is cancelled, `progress` is not called again,
/// and the exception is rethrown here once the library has returned.
template <class F>
RenderResult render(const Scene &scene, const Camera &camera, const RenderSettings &settings,
                    Span<float> rgb_out, F &&progress) {
    static_assert(std::is_invocable_v<F &, const Progress &>,
                  "the progress callback is called as progress(const mlt::Progress &)");
    using Result = std::invoke_result_t<F &, const Progress &>;
    static_assert(std::is_void_v<Result> || std::is_convertible_v<Result, bool>,
                  "the progress callback returns bool (false cancels) or void");
    detail::ProgressForwarder<std::remove_reference_t<F>> forwarder{progress, nullptr};
    return detail::render(scene, camera, settings, rgb_out, &decltype(forwarder)::call,
                          &forwarder, &forwarder.error);
}

namespace detail {
/// An image of the settings' size, its pixels allocated only for a size mlt accepts (for
/// any other, the render reports the setting).
inline Image image_for(const RenderSettings &settings) {
    Image image;
    image.width = settings.width;
    image.height = settings.height;
    const auto most = static_cast<std::uint32_t>(MLT_MAX_IMAGE_SIDE);
    if (settings.width <= most && settings.height <= most)
        image.rgb.resize(std::size_t(settings.width) * settings.height * 3);
    return image;
}
} // namespace detail

/// Renders into a new image of settings.width × settings.height.
inline Image render_image(const Scene &scene, const Camera &camera,
                          const RenderSettings &settings) {
    Image image = detail::image_for(settings);
    image.result = render(scene, camera, settings, image.rgb);
    return image;
}

/// Renders into a new image, with a progress callback as for render().
template <class F>
Image render_image(const Scene &scene, const Camera &camera, const RenderSettings &settings,
                   F &&progress) {
    Image image = detail::image_for(settings);
    image.result = render(scene, camera, settings, image.rgb, std::forward<F>(progress));
    return image;
}

// ---------------------------------------------------------------------------------------
// A render split into jobs: plan, job k of N, combine, merge
// ---------------------------------------------------------------------------------------

/// Bytes mlt made, a plan (render_plan) or a partial result (render_job, render_combine), owned:
/// move-only, freed by the destructor (mlt_bytes_release). data() and size() are what to
/// keep or send to another machine. A Span<const std::uint8_t> converts from it, as from
/// any contiguous container of bytes, which is what render_job and render_merge take: the
/// bytes may come back in the host's own buffers.
class Bytes {
public:
    Bytes() noexcept = default;
    ~Bytes() { mlt_bytes_release(&bytes_); }
    Bytes(Bytes &&other) noexcept : bytes_(std::exchange(other.bytes_, empty_bytes())) {}
    Bytes &operator=(Bytes &&other) noexcept {
        if (this != &other) {
            mlt_bytes_release(&bytes_);
            bytes_ = std::exchange(other.bytes_, empty_bytes());
        }
        return *this;
    }
    Bytes(const Bytes &) = delete;
    Bytes &operator=(const Bytes &) = delete;

    /// Takes over bytes mlt gave (an MltBytes a C call filled).
    static Bytes adopt(MltBytes bytes) noexcept {
        Bytes b;
        b.bytes_ = bytes;
        return b;
    }

    const std::uint8_t *data() const noexcept { return bytes_.data; }
    std::size_t size() const noexcept { return bytes_.size; }
    bool empty() const noexcept { return bytes_.size == 0; }
    const std::uint8_t *begin() const noexcept { return bytes_.data; }
    const std::uint8_t *end() const noexcept { return bytes_.data + bytes_.size; }
    /// A copy in a vector.
    std::vector<std::uint8_t> to_vector() const { return {begin(), end()}; }

    /// Frees what this holds and gives its MltBytes for a C call to fill.
    MltBytes *reset() noexcept {
        mlt_bytes_release(&bytes_);
        return &bytes_;
    }
    /// Gives up ownership: the caller frees the result with mlt_bytes_release.
    MltBytes release() noexcept { return std::exchange(bytes_, empty_bytes()); }

private:
    static constexpr MltBytes empty_bytes() noexcept { return MltBytes{nullptr, 0}; }

    MltBytes bytes_ = empty_bytes();
};

/// Most jobs a render splits into.
inline constexpr std::uint32_t max_jobs = MLT_MAX_JOBS;

/// Plans a render of `scene` seen by `camera` with `settings`, to be split into jobs
/// (mlt_render_plan): the bytes every job and the merge take. Throws Error on invalid input.
inline Bytes render_plan(const Scene &scene, const Camera &camera,
                         const RenderSettings &settings) {
    const MltCamera c_camera = camera.to_c();
    const MltRenderSettings c_settings = settings.to_c();
    Bytes plan;
    detail::check(mlt_render_plan(scene.get(), &c_camera, &c_settings, plan.reset()),
                  "mlt_render_plan");
    return plan;
}

/// What a job rendered: its partial result, for render_merge, and how it ended (a
/// cancelled or timed-out job still gives its partial result).
struct JobResult {
    Bytes partial;
    RenderResult result;
};

namespace detail {
inline JobResult render_job(const Scene &scene, Span<const std::uint8_t> plan,
                            std::uint32_t job, std::uint32_t jobs, std::uint32_t threads,
                            MltProgressCallback callback, void *user_data,
                            const std::exception_ptr *callback_error) {
    MltRenderStats c_stats;
    check(mlt_render_stats_default(&c_stats), "mlt_render_stats_default");
    JobResult out;
    const MltStatus status =
        mlt_render_job(scene.get(), plan.data(), plan.size(), job, jobs, threads, callback,
                       user_data, out.partial.reset(), &c_stats);
    // The library has returned: the callable's exception may go on (out.partial frees
    // what the job gave).
    if (callback_error && *callback_error) std::rethrow_exception(*callback_error);
    out.result = result_of(status, "mlt_render_job", c_stats);
    return out;
}
} // namespace detail

/// Renders job `job` of `jobs` (numbered from 0) of `plan` (mlt_render_job) on `scene`,
/// which must be built from the same description as the plan's, with `threads` of its own
/// (0: every core). Throws Error on invalid input (a corrupted plan, job >= jobs, another
/// scene; Status::Unsupported for an algorithm that does not split yet).
inline JobResult render_job(const Scene &scene, Span<const std::uint8_t> plan,
                            std::uint32_t job, std::uint32_t jobs, std::uint32_t threads = 0) {
    return detail::render_job(scene, plan, job, jobs, threads, nullptr, nullptr, nullptr);
}

/// As above, calling `progress(const Progress &)` as render() does.
template <class F>
JobResult render_job(const Scene &scene, Span<const std::uint8_t> plan, std::uint32_t job,
                     std::uint32_t jobs, std::uint32_t threads, F &&progress) {
    static_assert(std::is_invocable_v<F &, const Progress &>,
                  "the progress callback is called as progress(const mlt::Progress &)");
    detail::ProgressForwarder<std::remove_reference_t<F>> forwarder{progress, nullptr};
    return detail::render_job(scene, plan, job, jobs, threads, &decltype(forwarder)::call,
                              &forwarder, &forwarder.error);
}

/// Merges the partial results of every job of `plan` (render_job's or render_combine's),
/// holding each job once, in any order, into
/// `rgb_out` (at least width × height × 3 floats): the image render() gives, bit for bit
/// (mlt_render_merge). `partials` is a range of contiguous byte containers (Bytes,
/// std::vector<std::uint8_t>, Span<const std::uint8_t>, ...). Throws Error on invalid input
/// (a partial result corrupted, of another plan, missing or given twice); returns how the
/// jobs ended, with their stats added up.
namespace detail {
/// The pointers and sizes of a range of contiguous byte containers, for the C calls.
template <class Partials>
std::pair<std::vector<const std::uint8_t *>, std::vector<std::size_t>>
partial_pointers(const Partials &partials) {
    std::vector<const std::uint8_t *> pointers;
    std::vector<std::size_t> sizes;
    for (const auto &partial : partials) {
        const Span<const std::uint8_t> bytes(partial);
        pointers.push_back(bytes.data());
        sizes.push_back(bytes.size());
    }
    return {std::move(pointers), std::move(sizes)};
}
} // namespace detail

/// Adds partial results of `plan` that hold disjoint sets of jobs (render_job's, or earlier
/// render_combine's; a range of contiguous byte containers) into one partial result holding
/// all their jobs (mlt_render_combine), for render_merge or a further combine: merging it
/// gives the bits merging its parts would. Throws Error on invalid input (a partial result
/// corrupted, of another plan, or a job held twice).
template <class Partials>
Bytes render_combine(Span<const std::uint8_t> plan, const Partials &partials) {
    const auto [pointers, sizes] = detail::partial_pointers(partials);
    Bytes combined;
    detail::check(mlt_render_combine(plan.data(), plan.size(), pointers.data(), sizes.data(),
                                     pointers.size(), combined.reset()),
                  "mlt_render_combine");
    return combined;
}

template <class Partials>
RenderResult render_merge(Span<const std::uint8_t> plan, const Partials &partials,
                          Span<float> rgb_out) {
    const auto [pointers, sizes] = detail::partial_pointers(partials);
    MltRenderStats c_stats;
    detail::check(mlt_render_stats_default(&c_stats), "mlt_render_stats_default");
    const MltStatus status =
        mlt_render_merge(plan.data(), plan.size(), pointers.data(), sizes.data(),
                         pointers.size(), rgb_out.data(), rgb_out.size(), &c_stats);
    return detail::result_of(status, "mlt_render_merge", c_stats);
}

} // namespace mlt

#endif // MLT_HPP
