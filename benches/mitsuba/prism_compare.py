#!/usr/bin/env python3
"""mlt's dispersion against Mitsuba 3's scalar_spectral variant with a dispersive dielectric
plugin (dispersive_dielectric.py: the same Cauchy index as mlt's, hero wavelength only past
the glass), on tests/scenes/prism (white light through a slit, spread by a flint prism,
n_d 1.5 and Abbe number 20, onto a white floor), with the same triangles, camera, size and
max depth (spectral_compare.py's reading of the scene).

Everything the camera sees is lit through the slit, and the spectrum on the floor is a
caustic (lamp, slit, prism, floor), which camera paths reach by chance only. mlt renders it
with bidirectional path tracing (`--algorithm bdpt --spectral`, checked against its path
tracer by its tests); Mitsuba 3 has no BDPT, so its image is the sum of two parts:
- its particle tracer (`ptracer`): light paths connected to the camera at each diffuse
  vertex, which is every path whose first vertex from the camera is diffuse;
- its path tracer (`path`) for the camera rays whose first hit is specular (the prism,
  which light paths cannot connect to the camera through), from a small Python integrator.
The plugin thus carries importance (particle tracer) and radiance (path tracer).

The script prints, each over independent renders with its standard error:
1. the plugin at constant index (Abbe number 0, yet hero-only) against Mitsuba's own
   `dielectric` on the prism scene: image means and the largest difference of a 4 x 4 grid
   of region means, as spectral_compare.py does;
2. mlt against Mitsuba with dispersion: the same, then the spectrum's region on the floor
   (SPECTRUM, fractions of the image) per channel: its mean and its centroid column and
   row in pixels, and the red-to-blue spread of the centroids.
Numbers are reported, never asserted (a bench, not a test). `pip install mitsuba`, build
mlt (`cargo build --release`; $CARGO_TARGET_DIR is honoured), then from the repository
root:

    python3 benches/mitsuba/prism_compare.py [WIDTH] [MLT_SPP] [MITSUBA_SPP] [RENDERS]

(defaults: 160 64 256 8; the height is 3/4 of the width, as in prism.camera.json; Mitsuba's
path-traced part of the prism takes a sixteenth of MITSUBA_SPP), about 3.5 minutes on 2
cores.
"""
import sys

import mitsuba as mi

from spectral_compare import glass_bsdf, mean_and_error, render_mitsuba, render_mlt, report

SCENE = "prism"
# Columns and rows (fractions of the width and height) holding the spectrum on the floor.
SPECTRUM = (0.44, 0.72, 0.5, 0.8)


def register_through_glass():
    """`through_glass`: Mitsuba's path tracer for camera rays first hitting a specular
    surface, 0 for the others (which the particle tracer renders)."""

    class ThroughGlass(mi.SamplingIntegrator):
        def __init__(self, props):
            mi.SamplingIntegrator.__init__(self, props)
            self.path = mi.load_dict({"type": "path", "max_depth": props.get("max_depth", 6)})

        def sample(self, scene, sampler, ray, medium, active):
            si = scene.ray_intersect(mi.Ray3f(ray))
            if si.is_valid() and mi.has_flag(si.bsdf().flags(), mi.BSDFFlags.Delta):
                return self.path.sample(scene, sampler, ray, medium, active)
            return mi.Spectrum(0.0), True, []

    mi.register_integrator("through_glass", lambda props: ThroughGlass(props))


def render_mitsuba_complete(width, height, spp, seed, glass=glass_bsdf):
    """Particle tracer plus the path-traced view through the glass, and seconds."""
    light, light_seconds = render_mitsuba("scalar_spectral", SCENE, width, height, spp, seed,
                                          "ptracer", glass)
    seen, seen_seconds = render_mitsuba("scalar_spectral", SCENE, width, height,
                                        max(1, spp // 16), seed, "through_glass", glass)
    return [a + b for a, b in zip(light, seen)], light_seconds + seen_seconds


def spectrum_region(image, width, height):
    """Per channel: the mean over SPECTRUM, then its centroid column and row (pixels)."""
    x0, x1, y0, y1 = SPECTRUM
    columns = range(int(x0 * width), int(x1 * width))
    rows = range(int(y0 * height), int(y1 * height))
    means, centroids = [], []
    for c in range(3):
        total = sum_x = sum_y = 0.0
        for y in rows:
            for x in columns:
                v = image[(y * width + x) * 3 + c]
                total, sum_x, sum_y = total + v, sum_x + v * (x + 0.5), sum_y + v * (y + 0.5)
        means.append(total / (len(rows) * len(columns)))
        centroids += [sum_x / total, sum_y / total]
    # The red-to-blue spread of the centroid, column and row.
    spread = [centroids[0] - centroids[4], centroids[1] - centroids[5]]
    return means + centroids + spread


def report_spectrum(ours, theirs, width, height):
    (a, ea), (b, eb) = (mean_and_error([spectrum_region(im, width, height) for im in images])
                        for images in (ours, theirs))

    def line(label, i, unit=""):
        sigma = abs(a[i] - b[i]) / max((ea[i] ** 2 + eb[i] ** 2) ** 0.5, 1e-12)
        print(f"    {label}: mlt {a[i]:.5g} ± {ea[i]:.2g}{unit}, Mitsuba {b[i]:.5g} ± {eb[i]:.2g}"
              f"{unit} ({sigma:.1f} standard errors)")

    print(f"  spectrum region (columns {SPECTRUM[0]}-{SPECTRUM[1]}, rows {SPECTRUM[2]}-"
          f"{SPECTRUM[3]} of the image):")
    for c, name in enumerate("RGB"):
        line(f"{name} mean", c)
        line(f"{name} centroid column", 3 + 2 * c, " px")
        line(f"{name} centroid row", 4 + 2 * c, " px")
    line("red minus blue centroid column", 9, " px")
    line("red minus blue centroid row", 10, " px")


def constant_index_plugin(material, variant):
    return {"type": "dispersive_dielectric", "ior": material["Ni"], "abbe": 0.0}


def dielectric(material, variant):
    return {"type": "dielectric", "int_ior": material["Ni"], "ext_ior": 1.0}


def renders_of(render, seeds):
    """The images `render(seed)` gives for each seed, and their total seconds."""
    results = [render(seed) for seed in seeds]
    return [image for image, _ in results], sum(seconds for _, seconds in results)


def main():
    width = int(sys.argv[1]) if len(sys.argv) > 1 else 160
    mlt_spp = int(sys.argv[2]) if len(sys.argv) > 2 else 64
    spp = int(sys.argv[3]) if len(sys.argv) > 3 else 256
    renders = int(sys.argv[4]) if len(sys.argv) > 4 else 8
    height = width * 3 // 4
    mi.set_variant("scalar_spectral")
    register_through_glass()
    size = f"{renders} renders of {width} x {height}"

    plugin, plugin_seconds = renders_of(
        lambda seed: render_mitsuba_complete(width, height, spp, seed, constant_index_plugin),
        range(renders))
    builtin, builtin_seconds = renders_of(
        lambda seed: render_mitsuba_complete(width, height, spp, seed, dielectric),
        range(renders, 2 * renders))
    print(f"{SCENE} at constant index: Mitsuba with the plugin {plugin_seconds:.1f} s, with "
          f"`dielectric` {builtin_seconds:.1f} s ({size}, {spp} light paths per pixel)")
    report(plugin, builtin, width, height, "plugin", "dielectric")

    ours, our_seconds = renders_of(
        lambda seed: render_mlt(True, SCENE, width, height, mlt_spp, seed, "bdpt"),
        range(renders))
    theirs, their_seconds = renders_of(
        lambda seed: render_mitsuba_complete(width, height, spp, seed), range(renders))
    print(f"{SCENE}, dispersive: mlt BDPT {our_seconds:.1f} s ({mlt_spp} spp), Mitsuba ptracer "
          f"+ path through the glass {their_seconds:.1f} s ({spp} light paths per pixel) "
          f"({size})")
    report(ours, theirs, width, height)
    report_spectrum(ours, theirs, width, height)


if __name__ == "__main__":
    main()
