"""A smooth dielectric with a wavelength-dependent index, as a Mitsuba 3 BSDF plugin for the
scalar_spectral variant (Mitsuba's own `dielectric` has one index for all wavelengths).

The index is KHR_materials_dispersion's Cauchy form, the one mlt uses:
n(λ) = n_d + (n_d − 1) / V · (523655 / λ² − 1.5168), λ in nm, at least 1 (V = 0: n_d).

A Mitsuba path carries four wavelengths (`si.wavelengths`, lane 0 the hero), each drawn
from the same density (the sensor's or the emitter's, one random number shifted by a
quarter per lane) and weighted by its inverse; the film averages the four lanes. Refraction
sends each wavelength its own way, so the path goes on with the hero's index alone: from its
first scattering at such an interface on, the other lanes carry 0 and the hero 4 times its
weight. The lanes' average is then the hero's estimate, and the hero is a wavelength drawn
from the full density: unbiased. Reflection and refraction are chosen by the hero's Fresnel
reflectance F, so the hero's weight is 1 (reflection) or, carrying radiance, (η_i / η_t)²
(refraction), as in `dielectric`.

The factor 4 is owed once per path, but a plugin sees single scatterings and cannot mark
the path (its `si` is a copy). A path keeps its wavelengths from end to end and a scalar
render thread traces one path at a time, so the plugin remembers, per thread id, the
wavelengths of the last path it made hero-only: the same four again are the same path. (A
`threading.local` forgets between calls: Mitsuba's threads enter Python afresh each time.)
"""
import threading

import mitsuba as mi

LANES = 4
_hero_only_paths = {}  # thread id -> wavelengths of its last path made hero-only


def cauchy_index(ior_d, abbe_number, wavelength):
    if abbe_number == 0:
        return ior_d
    dispersion = (ior_d - 1) / abbe_number * (523655 / wavelength**2 - 1.5168)
    return max(1.0, ior_d + dispersion)


def register():
    """Makes `dispersive_dielectric` loadable in the current (spectral) variant: its base
    class, `mi.BSDF`, exists once a variant is set."""

    class DispersiveDielectric(mi.BSDF):
        """Parameters: `ior` (n_d, 1.5) and `abbe` (V, 0 = no dispersion); outside index 1."""

        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            self.ior = props.get("ior", 1.5)
            self.abbe = props.get("abbe", 0.0)
            sides = mi.BSDFFlags.FrontSide | mi.BSDFFlags.BackSide
            self.reflection = mi.BSDFFlags.DeltaReflection | sides
            self.transmission = mi.BSDFFlags.DeltaTransmission | sides | mi.BSDFFlags.NonSymmetric
            self.m_components = [self.reflection, self.transmission]
            self.m_flags = self.reflection | self.transmission

        def sample(self, ctx, si, sample1, sample2, active):
            wavelengths = tuple(si.wavelengths[i] for i in range(LANES))
            eta = cauchy_index(self.ior, self.abbe, wavelengths[0])
            reflectance, cos_theta_t, eta_it, eta_ti = mi.fresnel(mi.Frame3f.cos_theta(si.wi), eta)
            bs = mi.BSDFSample3f()
            if sample1 < reflectance:
                bs.wo, bs.pdf, bs.eta = mi.reflect(si.wi), reflectance, 1.0
                bs.sampled_type, bs.sampled_component = int(mi.BSDFFlags.DeltaReflection), 0
                weight = 1.0
            else:
                bs.wo = mi.refract(si.wi, cos_theta_t, eta_ti)
                bs.pdf, bs.eta = 1 - reflectance, eta_it
                bs.sampled_type, bs.sampled_component = int(mi.BSDFFlags.DeltaTransmission), 1
                weight = eta_ti**2 if ctx.mode == mi.TransportMode.Radiance else 1.0
            thread = threading.get_ident()
            if _hero_only_paths.get(thread) != wavelengths:
                _hero_only_paths[thread] = wavelengths
                weight *= LANES
            return bs, mi.Spectrum(weight, 0, 0, 0)

        def eval(self, ctx, si, wo, active):
            return mi.Spectrum(0.0)

        def pdf(self, ctx, si, wo, active):
            return 0.0

        def eval_pdf(self, ctx, si, wo, active):
            return mi.Spectrum(0.0), 0.0

        def to_string(self):
            return f"DispersiveDielectric[ior={self.ior}, abbe={self.abbe}]"

    mi.register_bsdf("dispersive_dielectric", lambda props: DispersiveDielectric(props))
