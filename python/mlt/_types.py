"""The value types of the mlt API: plain dataclasses mirroring the Rust structs.

The extension (``mlt._mlt``) reads them by attribute when it builds a scene or renders,
so any object with the same attributes works too. Defaults are the Rust crate's;
``tests/test_api.py`` checks them against it. Validation happens in Rust, which raises
:class:`mlt.InvalidArgumentError` naming the offending field.
"""

from __future__ import annotations

import dataclasses
import enum
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Optional, Sequence, Tuple, Union

if TYPE_CHECKING:
    import os

    import numpy.typing as npt

Vec3 = Tuple[float, float, float]


class Algorithm(str, enum.Enum):
    """The light-transport algorithm of a render (``RenderSettings.algorithm``).

    A member is its own string (``Algorithm.MMLT == "mmlt"``), so settings accept either.
    The names are ``mlt-render --algorithm``'s.
    """

    #: Unidirectional path tracing with next-event estimation and MIS.
    PATH = "path"
    #: Bidirectional path tracing: every connection strategy, combined by MIS.
    BDPT = "bdpt"
    #: Primary-sample-space Metropolis light transport (Kelemen) over the path tracer.
    PSSMLT = "pssmlt"
    #: Multiplexed MLT (Hachisuka) over BDPT: the default.
    MMLT = "mmlt"
    #: Primary-sample-space MLT over BDPT, all strategies of a sample summed.
    PSSMLT_BDPT = "pssmlt-bdpt"
    #: Path-space MLT (Veach & Guibas): chains over light paths.
    PATH_SPACE_MLT = "path-space-mlt"
    #: Energy redistribution path tracing (Cline, Talbot & Egbert).
    ERPT = "erpt"

    def __str__(self) -> str:
        return self.value


@dataclass
class TextureRef:
    """A material's use of a texture: its index in ``Scene.from_arrays(textures=...)`` and
    the ``KHR_texture_transform`` applied to the texture coordinates first (scale, then
    rotate by ``rotation`` radians counter-clockwise, then offset), at the texture
    coordinate set ``texcoord``: 0 (``texcoords``) or 1 (``texcoords1``), glTF's
    ``texCoord``."""

    texture: int
    offset: Tuple[float, float] = (0.0, 0.0)
    rotation: float = 0.0
    scale: Tuple[float, float] = (1.0, 1.0)
    texcoord: int = 0


@dataclass
class Material:
    """A surface material (``mlt::Material``).

    ``kind`` is ``"diffuse"`` (Lambertian, albedo ``color``), ``"mirror"`` (a perfect
    mirror reflecting ``color``), ``"dielectric"`` (smooth glass of index ``ior``, tinted
    by ``color``) or ``"metallic_roughness"`` (glTF 2.0's model: base colour ``color``,
    ``metallic``, perceptual ``roughness``, ``ior``, ``transmission``).

    Any material emits ``emission`` (linear RGB radiance) from its front side
    (counter-clockwise winding): emissive triangles are area lights. Colours are linear
    RGB in [0, 1]. The defaults are ``mlt::Material``'s, a light grey (0.8) diffuse surface;
    ``docs/settings.md`` lists every field with its valid values.

    Textures (``TextureRef``) refer to ``Scene.from_arrays(textures=...)`` and need
    ``texcoords``: ``base_color_texture`` multiplies ``color`` and ``alpha``,
    ``metallic_roughness_texture`` multiplies ``roughness`` (green) and ``metallic``
    (blue), ``normal_texture`` is a tangent-space normal map scaled by ``normal_scale``,
    ``emission_texture`` multiplies ``emission``. ``alpha_mode="mask"`` cuts the surface
    out where alpha < ``alpha_cutoff``; ``alpha_mode="blend"`` lets a fraction 1 - alpha of
    the light pass straight through.

    ``energy_compensation`` (metallic-roughness) adds Kulla and Conty's multiple-scattering
    lobe to rough metals. ``abbe_number`` (0: none) makes a dielectric disperse light in
    spectral renders.
    """

    # BEGIN GENERATED material: tests/parameters.rs writes these lines from src/scene/material.rs
    #: The scattering model: diffuse (Lambertian), mirror, dielectric (smooth glass) or
    #: metallic-roughness (glTF 2.0's).
    kind: str = "diffuse"
    #: Diffuse albedo, mirror reflectance, glass tint or metallic-roughness base colour, linear RGB.
    color: Vec3 = (0.8, 0.8, 0.8)
    #: Radiance emitted from the front (counter-clockwise) side, linear RGB; emissive triangles are
    #: area lights.
    emission: Vec3 = (0.0, 0.0, 0.0)
    #: Index of refraction of a dielectric and of the metallic-roughness model's dielectric part
    #: (there > 0).
    ior: float = 1.5
    #: Metallic-roughness: metalness, 0 a dielectric, 1 a metal whose reflectance is the colour.
    metallic: float = 0.0
    #: Metallic-roughness: perceptual roughness (GGX alpha = roughness squared; 0 is the exact
    #: specular lobe).
    roughness: float = 1.0
    #: Metallic-roughness: the fraction of the non-metallic base transmitted, not diffusely
    #: reflected (KHR_materials_transmission).
    transmission: float = 0.0
    #: Coverage, times the base colour texture's alpha and the vertex colour's; used by the mask and
    #: blend alpha modes.
    alpha: float = 1.0
    #: What alpha does: opaque ignores it, mask cuts the surface out where alpha < alpha_cutoff
    #: (glTF's MASK), blend lets a fraction 1 - alpha of the light pass straight through (glTF's
    #: BLEND, as stochastic coverage).
    alpha_mode: str = "opaque"
    #: The mask alpha mode's threshold (glTF's alphaCutoff).
    alpha_cutoff: float = 0.5
    #: Multiplies the colour (RGB) and alpha (A), for every kind; usually 8-bit sRGB.
    base_color_texture: Optional[TextureRef] = None
    #: Green multiplies the roughness, blue the metalness (glTF's packing); usually linear.
    metallic_roughness_texture: Optional[TextureRef] = None
    #: A tangent-space normal map (glTF's convention: +Y up in the image); usually linear.
    normal_texture: Optional[TextureRef] = None
    #: Multiplies the emission; usually 8-bit sRGB.
    emission_texture: Optional[TextureRef] = None
    #: Scales the normal map's x and y (glTF's normalTexture.scale).
    normal_scale: float = 1.0
    #: Metallic-roughness: give rough metals the light glTF's single-scattering model loses (Kulla
    #: and Conty 2017).
    energy_compensation: bool = False
    #: Dispersion as the Abbe number V_d (0: none; KHR_materials_dispersion's dispersion is 20 /
    #: V_d); spectral renders only.
    abbe_number: float = 0.0
    #: Metallic-roughness: red multiplies the transmission (KHR_materials_transmission's
    #: transmissionTexture); usually linear.
    transmission_texture: Optional[TextureRef] = None
    #: Metallic-roughness: a clear coat over the material, a white GGX reflection of index 1.5 with
    #: its own roughness and normal (KHR_materials_clearcoat's clearcoatFactor); 0 is none.
    clearcoat: float = 0.0
    #: Metallic-roughness: the clear coat's perceptual roughness (GGX alpha = its square; 0 is an
    #: exact mirror).
    clearcoat_roughness: float = 0.0
    #: Metallic-roughness: red multiplies the clear coat (KHR_materials_clearcoat's
    #: clearcoatTexture); usually linear.
    clearcoat_texture: Optional[TextureRef] = None
    #: Metallic-roughness: green multiplies the clear coat's roughness (clearcoatRoughnessTexture);
    #: usually linear.
    clearcoat_roughness_texture: Optional[TextureRef] = None
    #: Metallic-roughness: the clear coat's own tangent-space normal map (clearcoatNormalTexture);
    #: without it the coat follows the interpolated normal, not normal_texture.
    clearcoat_normal_texture: Optional[TextureRef] = None
    #: Scales the clear coat's normal map's x and y (clearcoatNormalTexture.scale).
    clearcoat_normal_scale: float = 1.0
    #: Dielectric and transmissive metallic-roughness: 0 is thin-walled, above 0 the mesh encloses
    #: an absorbing volume (KHR_materials_volume's thicknessFactor).
    thickness: float = 0.0
    #: The volume's colour after attenuation_distance of travel inside it, linear RGB
    #: (KHR_materials_volume's attenuationColor).
    attenuation_color: Vec3 = (1.0, 1.0, 1.0)
    #: The distance inside the volume after which white light has the attenuation colour; the
    #: largest float (FLT_MAX) is infinity, no absorption (KHR_materials_volume's
    #: attenuationDistance).
    attenuation_distance: float = 3.4028235e38
    #: Metallic-roughness: strength of the dielectric's specular reflection, 0 a pure diffuse base
    #: (KHR_materials_specular's specularFactor).
    specular: float = 1.0
    #: Metallic-roughness: scales the dielectric's F0 per channel, linear RGB, may exceed 1 (F0
    #: times it is clamped to 1; KHR_materials_specular's specularColorFactor).
    specular_color: Vec3 = (1.0, 1.0, 1.0)
    #: Metallic-roughness: alpha multiplies the specular strength (KHR_materials_specular's
    #: specularTexture); usually linear.
    specular_texture: Optional[TextureRef] = None
    #: Metallic-roughness: RGB multiplies the specular colour (KHR_materials_specular's
    #: specularColorTexture); usually 8-bit sRGB.
    specular_color_texture: Optional[TextureRef] = None
    #: Metallic-roughness: colour of a sheen layer over the material (velvet, cloth), linear RGB;
    #: black is none (KHR_materials_sheen's sheenColorFactor).
    sheen_color: Vec3 = (0.0, 0.0, 0.0)
    #: Metallic-roughness: the sheen's roughness (Charlie distribution, alpha = roughness squared,
    #: at least 0.07 squared; KHR_materials_sheen's sheenRoughnessFactor).
    sheen_roughness: float = 0.0
    #: Metallic-roughness: RGB multiplies the sheen colour (KHR_materials_sheen's
    #: sheenColorTexture); usually 8-bit sRGB.
    sheen_color_texture: Optional[TextureRef] = None
    #: Metallic-roughness: alpha multiplies the sheen roughness (KHR_materials_sheen's
    #: sheenRoughnessTexture); usually linear.
    sheen_roughness_texture: Optional[TextureRef] = None
    #: Metallic-roughness: anisotropy of the microfacets (brushed metal), alpha along its direction
    #: = mix(alpha, 1, strength squared); 0 is isotropic (KHR_materials_anisotropy's
    #: anisotropyStrength).
    anisotropy: float = 0.0
    #: Metallic-roughness: the anisotropy's direction in radians, counter-clockwise from the mesh's
    #: tangent towards its bitangent (KHR_materials_anisotropy's anisotropyRotation).
    anisotropy_rotation: float = 0.0
    #: Metallic-roughness: red and green are the anisotropy's direction in the tangent plane mapped
    #: from [-1, 1] to [0, 1] (then rotated by anisotropy_rotation), blue multiplies its strength
    #: (KHR_materials_anisotropy's anisotropyTexture); linear.
    anisotropy_texture: Optional[TextureRef] = None
    #: Metallic-roughness: strength of a thin film over the material, its interference colours (soap
    #: bubbles, oil); 0 is none (KHR_materials_iridescence's iridescenceFactor). Exact per
    #: wavelength in spectral renders, integrated over each RGB channel otherwise.
    iridescence: float = 0.0
    #: Metallic-roughness: red multiplies the thin film's strength (KHR_materials_iridescence's
    #: iridescenceTexture); usually linear.
    iridescence_texture: Optional[TextureRef] = None
    #: Metallic-roughness: the thin film's index of refraction (KHR_materials_iridescence's
    #: iridescenceIor).
    iridescence_ior: float = 1.3
    #: Metallic-roughness: the thin film's thickness in nanometres where the thickness texture's
    #: green is 0 (KHR_materials_iridescence's iridescenceThicknessMinimum).
    iridescence_thickness_minimum: float = 100.0
    #: Metallic-roughness: the thin film's thickness in nanometres where the thickness texture's
    #: green is 1, and everywhere without it; 0 is no film (KHR_materials_iridescence's
    #: iridescenceThicknessMaximum).
    iridescence_thickness_maximum: float = 400.0
    #: Metallic-roughness: green interpolates the thin film's thickness from the minimum (0) to the
    #: maximum (1) (KHR_materials_iridescence's iridescenceThicknessTexture); usually linear.
    iridescence_thickness_texture: Optional[TextureRef] = None
    # END GENERATED material

    @classmethod
    def diffuse(cls, albedo: Sequence[float], emission: Sequence[float] = (0.0, 0.0, 0.0)) -> Material:
        """Lambertian reflection with the given albedo."""
        return cls(kind="diffuse", color=_vec3(albedo), emission=_vec3(emission))

    @classmethod
    def mirror(cls, reflectance: Sequence[float] = (1.0, 1.0, 1.0)) -> Material:
        """A perfect mirror."""
        return cls(kind="mirror", color=_vec3(reflectance))

    @classmethod
    def dielectric(cls, ior: float = 1.5, tint: Sequence[float] = (1.0, 1.0, 1.0), abbe_number: float = 0.0) -> Material:
        """Smooth glass with index of refraction ``ior``."""
        return cls(kind="dielectric", color=_vec3(tint), ior=ior, abbe_number=abbe_number)

    @classmethod
    def metallic_roughness(
        cls, base_color: Sequence[float], metallic: float, roughness: float, **fields: object
    ) -> Material:
        """glTF's metallic-roughness model (index of refraction 1.5, no transmission
        unless given in ``fields``)."""
        return cls(
            kind="metallic_roughness",
            color=_vec3(base_color),
            metallic=metallic,
            roughness=roughness,
            **fields,  # type: ignore[arg-type]
        )

    def with_emission(self, radiance: Sequence[float]) -> Material:
        """A copy that emits ``radiance``."""
        return dataclasses.replace(self, emission=_vec3(radiance))


@dataclass
class Camera:
    """A perspective camera (``mlt::Camera``) looking from ``eye`` towards ``target``.

    ``fov_y_deg`` is the vertical field of view in degrees, in (0, 180). A positive
    ``lens_radius`` makes a thin lens focused at ``focus_distance`` (0: the distance from
    eye to target). The defaults are the Cornell box's camera (``mlt::Camera::default``).
    """

    eye: Vec3 = (278.0, 273.0, -800.0)
    target: Vec3 = (278.0, 273.0, -799.0)
    up: Vec3 = (0.0, 1.0, 0.0)
    fov_y_deg: float = 39.307648
    lens_radius: float = 0.0
    focus_distance: float = 0.0


@dataclass(kw_only=True)
class RenderSettings:
    """What a render is asked for (``mlt::RenderSettings``), with the Rust defaults.

    Metropolis algorithms (``pssmlt``, ``mmlt``, ``pssmlt-bdpt``, ``path-space-mlt``) do
    ``mutations_per_pixel``; the others take ``samples_per_pixel`` (0 for either: until
    ``time_limit_seconds``). ``threads`` 0 shares one pool of one thread per core between
    renders; the image never depends on the thread count, only on ``seed``. See the Rust
    documentation of ``mlt::RenderSettings`` for every field.
    """

    # BEGIN GENERATED render settings: tests/parameters.rs writes these lines from src/render/settings.rs
    #: Image width in pixels.
    width: int = 256
    #: Image height in pixels.
    height: int = 256
    #: The light-transport algorithm.
    algorithm: Union[Algorithm, str] = Algorithm.MMLT
    #: Path tracing, BDPT and ERPT: samples per pixel (0: until the time limit).
    samples_per_pixel: int = 64
    #: Most scattering vertices between camera and light (0: emitters seen directly).
    max_depth: int = 5
    #: Worker threads (0: a pool of one per core shared by such renders); the image does not depend
    #: on it.
    threads: int = 0
    #: Seed of every random number: equal seeds and settings give equal images.
    seed: int = 0
    #: Stop after this many seconds (0: no limit).
    time_limit_seconds: float = 0.0
    #: Metropolis: mutations per pixel (0: until the time limit).
    mutations_per_pixel: int = 32
    #: Metropolis: samples seeding the chains and the brightness estimate (0: one per 8 planned
    #: mutations, at least 65536; 262144 for a render planned by time alone).
    bootstrap_samples: int = 0
    #: Metropolis: number of Markov chains, at most the bootstrap samples.
    chains: int = 1024
    #: PSSMLT: probability of a large (independent) step.
    large_step_probability: float = 0.3
    #: PSSMLT: standard deviation of a small step in primary sample space.
    small_step_sigma: float = 0.01
    #: Metropolis: path-traced samples of depths 0 and 1 per chain mutation (0: the chains render
    #: every depth).
    direct_samples_per_mutation: int = 1
    #: Path-space MLT: relative probabilities of the bidirectional mutation and the lens, caustic
    #: and multi-chain perturbations (the first positive).
    mutation_weights: Tuple[float, float, float, float] = (0.5, 0.25, 0.25, 0.25)
    #: ERPT: perturbations per chain.
    erpt_chain_length: int = 10
    #: ERPT: energy (luminance) each chain step deposits (0: one chain per camera sample on
    #: average).
    erpt_deposit_energy: float = 0.0
    #: Path-space MLT: after a warm-up, weight each mutation by its acceptance rate there.
    adapt_mutation_weights: bool = False
    #: Path-space MLT and ERPT: perturb directions in the BSDF's sample space instead of within a
    #: cone.
    perturb_in_sample_space: bool = False
    #: Metropolis and ERPT: partial images of the post-process noise filter (0: no filter; 8 is a
    #: good start).
    filter_buffers: int = 0
    #: The filter's strength (higher smooths more).
    filter_strength: float = 0.45
    #: The filter's search radius in pixels.
    filter_radius: int = 7
    #: Metropolis: share of the rays spent on samples that go on estimating the brightness (0: the
    #: bootstrap and large steps alone).
    normalization_work_fraction: float = 0.05
    #: Spectral transport: four wavelengths per path instead of RGB; dispersive glass splits light.
    spectral: bool = False
    #: Path tracing and PSSMLT: scattering vertices after which Russian roulette may end a path.
    roulette_start_depth: int = 3
    #: Path tracing and PSSMLT: the highest probability with which Russian roulette lets a path go
    #: on.
    roulette_max_survival: float = 0.95
    #: Path tracing: read textures at full resolution, as the other algorithms do (by default camera
    #: paths filter them over the pixel's footprint, mip-mapped, until their first diffuse or glossy
    #: bounce).
    full_resolution_textures: bool = False
    # END GENERATED render settings


@dataclass
class Environment:
    """Light arriving from infinitely far away: an equirectangular (latitude-longitude)
    map of linear RGB radiance, ``pixels`` of shape (height, width, 3), +Y up, its centre
    looking along +Z; turned about +Y by ``rotation_degrees`` and multiplied by
    ``scale``."""

    pixels: npt.ArrayLike
    rotation_degrees: float = 0.0
    scale: float = 1.0

    @classmethod
    def constant(cls, radiance: Sequence[float]) -> Environment:
        """A sky of one radiance in every direction (a 1 x 1 map)."""
        return cls(pixels=[[_vec3(radiance)]])

    @classmethod
    def from_file(cls, path: Union[str, os.PathLike[str]], rotation_degrees: float = 0.0, scale: float = 1.0) -> Environment:
        """Reads a ``.hdr`` or ``.exr`` map (what ``mlt-render --env`` reads)."""
        from . import _mlt

        return cls(pixels=_mlt.load_environment(path), rotation_degrees=rotation_degrees, scale=scale)


@dataclass
class Sun:
    """The sun: a disc of uniform radiance in ``direction`` (from the scene towards it)
    with half-angle ``angular_radius_degrees`` (0: a delta direction; the real sun is
    0.27, the default, as ``mlt-render --sun``'s), giving ``irradiance`` (linear RGB) on
    a plane facing it."""

    direction: Vec3
    irradiance: Vec3
    angular_radius_degrees: float = 0.27

    @classmethod
    def from_radiance(cls, direction: Sequence[float], radiance: Sequence[float], angular_radius_degrees: float = 0.27) -> Sun:
        """A sun whose disc (radius > 0) has the given radiance: its irradiance is the
        radiance times pi sin^2 of the radius (``mlt::SunDesc::from_radiance``)."""
        solid = math.pi * math.sin(math.radians(angular_radius_degrees)) ** 2
        return cls(
            direction=_vec3(direction),
            irradiance=_vec3([c * solid for c in radiance]),
            angular_radius_degrees=angular_radius_degrees,
        )


@dataclass
class PunctualLight:
    """A point, spot or directional light (``KHR_lights_punctual``): reached by
    connections only, never hit by a ray.

    ``intensity`` is linear RGB radiant intensity (W/sr) for point and spot lights and
    irradiance for a directional one. ``direction`` is a spot's axis or the direction a
    directional light travels; spots fall off smoothly between ``inner_cone_degrees`` and
    ``outer_cone_degrees``."""

    kind: str
    position: Vec3 = (0.0, 0.0, 0.0)
    direction: Vec3 = (0.0, 0.0, -1.0)
    intensity: Vec3 = (1.0, 1.0, 1.0)
    inner_cone_degrees: float = 0.0
    outer_cone_degrees: float = 45.0

    @classmethod
    def point(cls, position: Sequence[float], intensity: Sequence[float]) -> PunctualLight:
        return cls(kind="point", position=_vec3(position), intensity=_vec3(intensity))

    @classmethod
    def spot(
        cls,
        position: Sequence[float],
        direction: Sequence[float],
        intensity: Sequence[float],
        inner_cone_degrees: float,
        outer_cone_degrees: float,
    ) -> PunctualLight:
        return cls(
            kind="spot",
            position=_vec3(position),
            direction=_vec3(direction),
            intensity=_vec3(intensity),
            inner_cone_degrees=inner_cone_degrees,
            outer_cone_degrees=outer_cone_degrees,
        )

    @classmethod
    def directional(cls, direction: Sequence[float], irradiance: Sequence[float]) -> PunctualLight:
        return cls(kind="directional", direction=_vec3(direction), intensity=_vec3(irradiance))


@dataclass
class Texture:
    """A texture the materials refer to by index (``TextureRef.texture``).

    ``data`` is (height, width) or (height, width, channels) with 1 to 4 channels (grey,
    grey + alpha, RGB, RGBA), rows from the top: uint8 (255 is 1) or float32 (linear,
    finite, >= 0). ``encoding`` is ``"srgb"`` (8-bit colour images: base colour,
    emission) or ``"linear"``; ``wrap_u``/``wrap_v`` are ``"repeat"``,
    ``"clamp_to_edge"`` or ``"mirrored_repeat"``; ``filter`` is ``"bilinear"`` or
    ``"nearest"``."""

    data: npt.ArrayLike
    encoding: str = "linear"
    wrap_u: str = "repeat"
    wrap_v: str = "repeat"
    filter: str = "bilinear"


def _vec3(value: Sequence[float]) -> Vec3:
    x, y, z = value
    return (float(x), float(y), float(z))


__all__ = [
    "Algorithm",
    "Camera",
    "Environment",
    "Material",
    "PunctualLight",
    "RenderSettings",
    "Sun",
    "Texture",
    "TextureRef",
]
