//! Path-space Metropolis light transport (Veach & Guibas 1997; Veach's thesis, ch. 11): the
//! chain's states are light paths, lists of vertices from a light to the lens, and mutations
//! edit the vertices themselves.
//!
//! # Transfer ratios as ratios of unweighted contributions
//!
//! A mutation that keeps some vertices of x and samples the others anew, the way one of
//! BDPT's strategies would (s vertices from the light, the rest from the lens), proposes y
//! with density T(x→y) = q · p_s(y), where q is the probability of its discrete choices and
//! p_s the density of the sampled vertices given the kept ones. Its reverse regenerates x's
//! vertices the same way with a strategy s'. The acceptance ratio is then
//!
//! ```text
//! f(y) T(y→x)     f(y)/p_s(y)      q(y→x)
//! ----------- = -------------- · --------
//! f(x) T(x→y)    f(x)/p_s'(x)     q(x→y)
//! ```
//!
//! and f/p_s is what BDPT calls strategy s's unweighted contribution C_s. The kept vertices'
//! factors of f and of p_s (a vertex sampled from a kept one depends only on kept vertices)
//! are the same in x and y and cancel, so C_s can be evaluated over the whole path.
//!
//! Dirac (specular) scattering is where such ratios usually go wrong. C_s is a product of
//! the BSDF sampling weights f·|cos|/p of each sampled vertex, in the transport mode of the
//! side that sampled it, as BDPT computes them: each delta meets its own sampling density and
//! the refraction Jacobian is the one BDPT already gets right (its strategies agree with the
//! path tracer through glass). `unweighted_contribution` evaluates C_s for a given path and
//! the tests check it against BDPT's own numbers for every strategy.
//!
//! # Lobes
//!
//! A BSDF may have a Dirac lobe beside lobes with a density (a smooth coat over a diffuse or
//! transmissive base, a smooth clear coat over any base). Its f is then a sum f_δ + f_c of a Dirac part and a part with a
//! density, and a path's measurement contribution is a sum over its lobe signatures σ
//! (which part scatters at each such vertex) of terms f_σ, each with that part alone at each
//! vertex. The chain's state is (x, σ), the signature recorded in the vertices
//! (`PathVertex::dirac`), and its target f_σ(x), in the measure where σ's Dirac vertices
//! are constrained (Veach's treatment of `S` vertices, signature by signature): as
//! Σ_σ f_σ = f, the states integrate to the image. Within a signature every vertex is `S` or
//! `D` as on a surface with one kind of lobe (`PathSpace::is_specular`), and the ratios
//! above hold with the lobe's choice counted in the sampling:
//!
//! - a vertex sampled through its BSDF picks its lobe with the probability `sample` gives
//!   it, which `Bsdf::scatter_lobe` returns with the lobe's weight (the Dirac lobe's
//!   Fresnel factor and tint over that probability; the base's f·|cos| over it times its
//!   direction density): C_s with `lobes_sampled` divides by it, as BDPT does;
//! - a connection ends only where the recorded lobe has a density: a strategy that would
//!   connect at a Dirac vertex of σ cannot produce (x, σ) and has no C_s;
//! - the bidirectional mutation records the lobe it sampled at each vertex it sampled
//!   from (the kept ends x_a and x_b among them: their lobe is chosen anew) and the lobes
//!   with a density at the connection's ends;
//! - the perturbations keep σ: a retraced vertex takes x's lobe, and the move is refused
//!   where y's surface has no such lobe, the same way back, so no lobe probability enters
//!   T, and C_s with `lobes_sampled` false weighs a Dirac vertex by its lobe's Fresnel
//!   factor and tint alone.
//!
//! Where a BSDF has one kind of lobe the record is not read, and paths are what they were.
//!
//! Which Dirac lobe scatters at an `S` vertex is not recorded: the path says it. Reflection
//! and refraction differ by the sides of the directions; a smooth clear coat with a normal
//! of its own over a smooth base has two mirrors, and the path's direction lies on one of
//! them (`Bsdf::specular_lobe` names the nearer, since a direction rebuilt from vertices
//! is off by rounding). The two mirrors' constrained paths are disjoint sets, so f_δ is
//! the one mirror's there: `scatter_lobe` weighs the vertex by that mirror's reflectance
//! over its probability, and the perturbations retrace it through the same mirror.
//!
//! # Lights that are not triangles
//!
//! A path's light x_0 may be a point or spot light, or a light at infinity (the environment
//! and sun disc, or a directional light): `PathVertex::light` says which. A vertex at
//! infinity is a direction (`normal`, from the scene towards the light), as in BDPT:
//! densities towards it are in solid angle, light sides leave it from a uniform point of the
//! disc covering the scene's bounding sphere (x_1's area density is the disc's times its
//! |cos|, which cancels G's), and a lens side that leaves the scene ends on it. The
//! strategy that would have to hit a delta light (s = 0) has no density: C_0 is `None` there,
//! as BDPT gives it no weight. The mutations keep x_0's kind where they keep x_0, and where
//! they sample it they do so with the densities C_s divides by (see each module).
//!
//! # Wavelengths
//!
//! In a spectral render a chain's state is a path and its wavelengths: the random number u
//! they are drawn from (`SampledWavelengths::sample`), first the one its bootstrap sample
//! drew. The target is the luminance of the path's contribution measured at them, which
//! divides by their density, so it is a density over u (uniform for BDPT's samples), and a
//! move that draws a new u uniformly, or steps u symmetrically, leaves only the ratio of
//! the contributions. A path through a dispersive vertex exists at its hero wavelength
//! alone: it is measured there (`channels_of`, as the path tracer and BDPT keep it), and a
//! move changes its u only where it samples or retraces every dispersive vertex anew:
//!
//! - the bidirectional mutation draws a new u when no vertex it keeps disperses (then the
//!   kept vertices exist at any wavelength), and samples and measures y at it;
//! - the perturbations step u by a small amount (`step_wavelength_number`) under the same
//!   rule, and trace y at it: a path through a prism moves along its spectrum as well as
//!   across the film; otherwise they keep the path's wavelengths, as a dispersive path must
//!   be perturbed at its own.
//!
//! The rule depends only on the kept vertices, which x and y share, so a move and its
//! reverse follow it alike. What the kept vertices contribute is measured at each path's
//! own wavelengths. The densities with which they were sampled, which cancel between C_s(y)
//! and C_s(x) when the wavelengths stay, may not when they change (a metallic-roughness
//! surface picks its lobes by their spectral tints): the ratio is multiplied by theirs
//! (`kept_density_ratio`).

mod bidirectional;
mod chain;
mod erpt;
mod perturbation;
#[cfg(test)]
mod test_geometry;

pub(crate) use chain::{PathSpaceTarget, run};
pub(crate) use erpt::{BAND_ROWS as ERPT_BAND_ROWS, ErptSettings, run as run_erpt};
pub(crate) use perturbation::PerturbationSizes;

use crate::bsdf::{Bsdf, TransportMode};
use crate::integrators::PathVertex;
use crate::interaction::{SurfaceInteraction, vertex_bsdf};
use crate::scene::{CameraModel, Scene};
use crate::spectral::Channels;
use crate::spectrum::Spectrum;
use glam::Vec3A;

/// A vertex's class for the perturbations (see [`PathSpace::class`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum VertexClass {
    Diffuse,
    Glossy,
    Specular,
}

/// The scene and camera a path lives in, with the functions that evaluate paths, and the
/// channels its spectra are in: in a spectral render the wavelengths the chain's state
/// carries with its path (see "Wavelengths" in the module documentation).
#[derive(Clone, Copy)]
pub(crate) struct PathSpace<'a> {
    pub scene: &'a Scene,
    pub camera: &'a CameraModel,
    pub channels: Channels,
}

/// The unit direction from `from` to `to` and the squared distance (infinite towards or
/// from a light at infinity), or `None` for coincident points.
#[inline]
fn direction(from: &PathVertex, to: &PathVertex) -> Option<(Vec3A, f32)> {
    if to.is_at_infinity() {
        return Some((to.normal, f32::INFINITY));
    }
    if from.is_at_infinity() {
        return Some((-from.normal, f32::INFINITY));
    }
    let d = to.p - from.p;
    let distance2 = d.length_squared();
    (distance2 > 0.0).then(|| (d / distance2.sqrt(), distance2))
}

impl PathSpace<'_> {
    /// The same space with a state's other wavelengths.
    #[inline]
    fn with_channels(&self, channels: Channels) -> Self {
        PathSpace { channels, ..*self }
    }

    /// Whether vertex `k` of `path` is a surface whose index of refraction depends on the
    /// wavelength (never the lens, the last vertex, nor a light that is not a triangle).
    #[inline]
    fn disperses_at(&self, path: &[PathVertex], k: usize) -> bool {
        let v = &path[k];
        k + 1 < path.len() && v.light.is_none() && self.scene.disperses(v.triangle, &self.channels)
    }

    /// The channels `path`'s contribution is measured in: the state's wavelengths, or its
    /// hero alone (with its density divided by their number) where a vertex disperses, since
    /// such a path exists at that one wavelength.
    #[inline]
    fn channels_of(&self, path: &[PathVertex]) -> Channels {
        let mut channels = self.channels;
        if channels.hero().is_some() && (0..path.len()).any(|k| self.disperses_at(path, k)) {
            channels.keep_hero_only();
        }
        channels
    }

    /// The densities with which BDPT's strategies sample the kept vertices of a move, at
    /// `y_space`'s wavelengths over at `self`'s (1 where they are the same): the BSDF
    /// densities at x_1 … x_{prefix − 2} towards the light side's next vertex, and at
    /// x_{suffix + 1} … x_{n − 2} towards the lens side's next, where x_0 … x_{prefix − 1}
    /// and x_suffix … x_{n − 1} are kept. C_s divides by them, so a move that changes the
    /// wavelengths multiplies its ratio of C_s by this (module docs, "Wavelengths"). With
    /// `lobes_sampled` false a specular lobe's probability is not among them, as in
    /// `unweighted_contribution`.
    fn kept_density_ratio(
        &self,
        y_space: &PathSpace,
        path: &[PathVertex],
        [prefix, suffix]: [usize; 2],
        lobes_sampled: bool,
    ) -> f32 {
        if self.channels == y_space.channels {
            return 1.0;
        }
        let n = path.len();
        let density = |space: &PathSpace, from: usize, at: usize, to: usize, mode| {
            let v = &path[at];
            if v.light.is_some() {
                return Some(1.0);
            }
            let (wo, _) = direction(v, &path[from])?;
            let (wi, _) = direction(v, &path[to])?;
            let s = space.scatter(v, wo, wi, mode)?;
            Some(if s.specular && !lobes_sampled {
                1.0
            } else {
                s.pdf
            })
        };
        let ratio = |from: usize, at: usize, to: usize, mode| -> Option<f32> {
            Some(density(y_space, from, at, to, mode)? / density(self, from, at, to, mode)?)
        };
        let light_side = (1..prefix.saturating_sub(1))
            .map(|j| ratio(j - 1, j, j + 1, TransportMode::Importance));
        let lens_side = (suffix + 1..n.saturating_sub(1))
            .map(|j| ratio(j + 1, j, j - 1, TransportMode::Radiance));
        light_side
            .chain(lens_side)
            .map(|r| r.filter(|r| r.is_finite()).unwrap_or(0.0))
            .product()
    }

    /// The BSDF of surface vertex `v`.
    #[inline]
    fn surface_bsdf(&self, v: &PathVertex) -> Bsdf {
        vertex_bsdf(self.scene, v.triangle, v.barycentrics, &self.channels)
    }

    /// Whether the path scatters at surface vertex `v` through a Dirac lobe: its BSDF's
    /// only kind, or where it has both kinds the one the vertex records (see "Lobes" in the
    /// module documentation).
    #[inline]
    fn scatters_through_dirac(bsdf: &Bsdf, v: &PathVertex) -> bool {
        let lobes = bsdf.lobes();
        if lobes.is_mixed() {
            v.dirac
        } else {
            lobes.is_specular()
        }
    }

    /// Veach's classification of a surface vertex: `S` (true) if the path scatters there
    /// through a Dirac lobe (the BSDF's only kind, or the one the vertex records where it
    /// has both), else `D`: a glossy lobe has a density, so connections and the
    /// bidirectional mutation treat it as a diffuse one. (The perturbations tell glossy
    /// vertices apart: see [`Self::class`].) Lights that are not triangles are `D`: they
    /// have no surface to scatter.
    #[inline]
    fn is_specular(&self, v: &PathVertex) -> bool {
        v.light.is_none() && Self::scatters_through_dirac(&self.surface_bsdf(v), v)
    }

    /// Veach's classes with a third for the perturbations: `S`, `G` (every lobe glossy:
    /// a perturbation moves its microfacet and traces on, as through a specular vertex, so
    /// the path follows a sharp lobe instead of connecting across it) and `D` (which the
    /// lobes with a density of a BSDF that also has a Dirac one are).
    #[inline]
    fn class(&self, v: &PathVertex) -> VertexClass {
        if v.light.is_some() {
            return VertexClass::Diffuse;
        }
        let bsdf = self.surface_bsdf(v);
        if Self::scatters_through_dirac(&bsdf, v) {
            VertexClass::Specular
        } else if bsdf.is_glossy() {
            VertexClass::Glossy
        } else {
            VertexClass::Diffuse
        }
    }

    /// What sampling surface vertex `v`'s BSDF from `wo` into `wi` returns, through the
    /// lobe the vertex records where it has both kinds (`Bsdf::scatter_lobe`).
    #[inline]
    fn scatter(
        &self,
        v: &PathVertex,
        wo: Vec3A,
        wi: Vec3A,
        mode: TransportMode,
    ) -> Option<crate::bsdf::ScatterSample> {
        let bsdf = self.surface_bsdf(v);
        if bsdf.lobes().is_mixed() {
            bsdf.scatter_lobe(wo, wi, mode, v.dirac)
        } else {
            bsdf.scatter(wo, wi, mode)
        }
    }

    /// The vertex `ray` hits first, or `None` if it escapes.
    #[inline]
    fn trace(&self, ray: &crate::accel::Ray, rays: &mut u64) -> Option<PathVertex> {
        *rays += 1;
        let hit = self.scene.closest_hit(ray)?;
        Some(PathVertex::surface(&SurfaceInteraction::new(
            self.scene, ray, &hit,
        )))
    }

    /// The vertex `ray` hits first; if it escapes, the lights at infinity seen along it
    /// (`None` if the scene has none).
    #[inline]
    fn trace_or_escape(&self, ray: &crate::accel::Ray, rays: &mut u64) -> Option<PathVertex> {
        match self.trace(ray, rays) {
            Some(v) => Some(v),
            None => self
                .scene
                .lights
                .infinite_emitter()
                .map(|light| PathVertex::at_infinity(light, ray.direction)),
        }
    }

    /// Whether nothing blocks the segment between two vertices (`b_is_lens`: b is the lens,
    /// which has no surface to offset from), or the way from one to a light at infinity.
    #[inline]
    fn visible(&self, a: &PathVertex, b: &PathVertex, b_is_lens: bool, rays: &mut u64) -> bool {
        if a.is_at_infinity() || b.is_at_infinity() {
            let (near, far) = if a.is_at_infinity() { (b, a) } else { (a, b) };
            *rays += 1;
            let ray = crate::integrators::spawn_ray(self.scene, near.p, near.normal, far.normal);
            return !self.scene.blocked(&ray);
        }
        // Point lights and the lens have no surface to offset from.
        let normal_a = if a.is_delta_position() {
            Vec3A::ZERO
        } else {
            a.normal
        };
        let normal_b = if b_is_lens || b.is_delta_position() {
            Vec3A::ZERO
        } else {
            b.normal
        };
        let Some(ray) = crate::integrators::shadow_ray(self.scene, a.p, normal_a, b.p, normal_b)
        else {
            return false;
        };
        *rays += 1;
        !self.scene.blocked(&ray)
    }

    /// What the volumes the path's edges run through let pass (`Scene::transmittance`):
    /// a factor of its measurement contribution that no strategy samples, so every C_s has
    /// it whole.
    #[inline]
    fn transmittance(&self, path: &[PathVertex]) -> Option<Spectrum> {
        if !self.scene.has_media() {
            return Some(Spectrum::ONE);
        }
        let n = path.len();
        // The lens (last) and lights that are not triangles lie on no surface.
        let on_triangle = |k: usize| {
            let v = &path[k];
            (k + 1 < n && v.light.is_none()).then_some(v.triangle)
        };
        let mut transmittance = Spectrum::ONE;
        for k in 0..n.saturating_sub(1) {
            let (w, distance2) = direction(&path[k], &path[k + 1])?;
            transmittance *= self.scene.transmittance(
                on_triangle(k),
                on_triangle(k + 1),
                w,
                distance2.sqrt(),
                &self.channels,
            );
        }
        Some(transmittance)
    }

    /// The pixel the path's last edge (from the lens) lands in.
    #[inline]
    pub fn pixel(&self, path: &[PathVertex]) -> Option<u32> {
        let [.., previous, lens] = path else {
            return None;
        };
        let (w, _) = direction(lens, previous)?;
        let [x, y] = self.camera.raster_position(lens.p, w)?;
        Some(y as u32 * self.camera.width + x as u32)
    }

    /// The sampling weight of vertex `at` scattering between its neighbors, in the mode of
    /// the side that sampled it: `from` is where that side came from, `to` the vertex it
    /// sampled. With `lobes_sampled` false, a specular lobe is taken as given (the
    /// perturbations keep each vertex's lobe), so its choice probability is not divided out.
    #[inline]
    fn weight(
        &self,
        from: &PathVertex,
        at: &PathVertex,
        to: &PathVertex,
        mode: TransportMode,
        lobes_sampled: bool,
    ) -> Option<Spectrum> {
        let (wo, _) = direction(at, from)?;
        let (wi, _) = direction(at, to)?;
        let s = self.scatter(at, wo, wi, mode)?;
        Some(if s.specular && !lobes_sampled {
            s.weight * s.pdf
        } else {
            s.weight
        })
    }

    /// The BSDF of non-specular vertex `at` between its neighbors (zero for specular ones)
    /// as the side carrying `mode` sees it: `from` is that side's previous vertex.
    #[inline]
    fn bsdf(
        &self,
        from: &PathVertex,
        at: &PathVertex,
        to: &PathVertex,
        mode: TransportMode,
    ) -> Option<Spectrum> {
        let (wo, _) = direction(at, from)?;
        let (wi, _) = direction(at, to)?;
        Some(self.surface_bsdf(at).eval(wo, wi, mode))
    }

    /// f(x) / p_s(x): the measurement contribution of `path` (a light vertex first, the
    /// lens last, every edge unoccluded) divided by the density with which BDPT's strategy
    /// with `s` light vertices samples it, and the pixel it lands in. Strategies BDPT skips
    /// (s = 1 with t = 1, a connection at a specular vertex) and zero contributions give
    /// `None`. See the module documentation for `lobes_sampled`.
    pub fn unweighted_contribution(
        &self,
        path: &[PathVertex],
        s: usize,
        lobes_sampled: bool,
    ) -> Option<(Spectrum, u32)> {
        let n = path.len();
        if n < 2 || s >= n || (s == 1 && n == 2) {
            return None;
        }
        let pixel = self.pixel(path)?;
        let t = n - s;
        let light = &path[0];
        // Le towards x_1 (radiance; intensity for a point light, irradiance for a
        // directional one) and x_0's density as a light sample (`sample_vertex`'s, the same as
        // `sample_emission`'s): per unit area on a triangle, in solid angle at infinity.
        let emitter = light.emitter();
        // A delta light cannot be hit: strategy s = 0 has no density (BDPT skips it).
        if s == 0 && emitter.is_delta() {
            return None;
        }
        let (w_light, _) = direction(&path[0], &path[1])?;
        let (emission, origin_pdf) = self.scene.light_emitted(
            emitter,
            light.normal,
            light.barycentrics,
            w_light,
            &self.channels,
        )?;
        if s >= 1 && origin_pdf <= 0.0 {
            return None;
        }

        // Light side: x_0 .. x_{s-1}.
        let mut beta_light = Spectrum::ONE;
        if s >= 1 {
            beta_light = emission / origin_pdf;
            if s >= 2 {
                beta_light = self
                    .scene
                    .lights
                    .weight_first_direction(emitter, w_light, beta_light)?;
            }
            for j in 1..s.saturating_sub(1) {
                beta_light *= self.weight(
                    &path[j - 1],
                    &path[j],
                    &path[j + 1],
                    TransportMode::Importance,
                    lobes_sampled,
                )?;
            }
        }
        // Lens side: x_{n-1} .. x_s. The camera's importance is normalized so that the
        // first direction's weight is 1.
        let mut beta_eye = Spectrum::ONE;
        for j in (s + 1..n - 1).rev() {
            beta_eye *= self.weight(
                &path[j + 1],
                &path[j],
                &path[j - 1],
                TransportMode::Radiance,
                lobes_sampled,
            )?;
        }

        let value = if s == 0 {
            // The lens side reached the light.
            beta_eye * emission
        } else if t == 1 {
            // Light tracing: x_{s-1} connects to the lens.
            let (lens, qs) = (&path[n - 1], &path[n - 2]);
            if self.is_specular(qs) {
                return None;
            }
            let (w, distance2) = direction(lens, qs)?;
            let importance = self.camera.importance(lens.p, w)?;
            let cos_lens = w.dot(self.camera.forward);
            // The lens point's density in solid angle at qs.
            let pdf = distance2 / cos_lens / self.camera.lens_area();
            beta_light
                * self.bsdf(&path[n - 3], qs, lens, TransportMode::Importance)?
                * w.dot(qs.normal).abs()
                * (importance.importance / pdf)
        } else {
            let (qs, pt) = (&path[s - 1], &path[s]);
            if self.is_specular(pt) || (s >= 2 && self.is_specular(qs)) {
                return None;
            }
            let (w, distance2) = direction(qs, pt)?;
            let light_side = if s == 1 {
                // Next-event estimation: the light's own factor is in beta_light.
                Spectrum::ONE
            } else {
                self.bsdf(&path[s - 2], qs, pt, TransportMode::Importance)?
            };
            let geometry = if qs.is_at_infinity() {
                // Towards a direction: no distance, and no cosine at the light.
                w.dot(pt.normal).abs()
            } else if qs.is_delta_position() {
                w.dot(pt.normal).abs() / distance2
            } else {
                w.dot(qs.normal).abs() * w.dot(pt.normal).abs() / distance2
            };
            beta_light
                * light_side
                * geometry
                * self.bsdf(&path[s + 1], pt, qs, TransportMode::Radiance)?
                * beta_eye
        };
        let value = self
            .channels_of(path)
            .rgb_of(value * self.transmittance(path)?);
        (value.max_component() > 0.0 && value.is_finite()).then_some((value, pixel))
    }
}

#[cfg(all(test, feature = "cli"))]
mod tests {
    use super::*;
    use crate::accel::Backend;
    use crate::integrators::SampleCounters;
    use crate::integrators::bdpt::Bdpt;
    use crate::sampling::Rng;
    use crate::scene::{Camera, SceneDesc};

    /// A scene of tests/scenes with its camera.
    fn canonical(name: &str) -> (Scene, Camera) {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes");
        let data = crate::io::load_scene(&dir.join(format!("{name}.obj"))).unwrap();
        let scene = Scene::new(&SceneDesc {
            positions: &data.positions,
            indices: &data.indices,
            material_ids: &data.material_ids,
            materials: &data.materials,
            lights: Default::default(),
            backend: Backend::Bvh,
            ..Default::default()
        })
        .unwrap();
        let camera = crate::io::load_camera_json(&dir.join(format!("{name}.camera.json")))
            .unwrap()
            .camera;
        (scene, camera)
    }

    /// Compares, for every strategy of `samples` BDPT samples (depth ≤ `max_depth`), the
    /// contribution evaluated on the path the strategy built with BDPT's own (its weighted
    /// value over its MIS weight). Returns per (s, t): the strategies compared, those
    /// through a specular vertex, those whose light is a direction at infinity, and those
    /// through a glossy vertex.
    fn compare_with_bdpt(
        name: &str,
        scene: &Scene,
        camera: &Camera,
        max_depth: u32,
        samples: u32,
    ) -> std::collections::BTreeMap<(usize, usize), (u32, u32, u32, u32)> {
        compare_with_bdpt_in(name, scene, camera, max_depth, samples, false, false)
    }

    /// `compare_with_bdpt`, in spectral mode with `spectral`: the path space carries the
    /// wavelengths each BDPT sample drew. A strategy whose subpaths kept the hero alone (one
    /// of them met a dispersive vertex) while its path has no dispersive vertex is BDPT's own
    /// other estimate of that path, and is skipped. With `well_conditioned`, so are paths
    /// with an edge shorter than 30 units (in a box of 550) or more than 70° from an inner
    /// vertex's normal (see the coated box's test).
    fn compare_with_bdpt_in(
        name: &str,
        scene: &Scene,
        camera: &Camera,
        max_depth: u32,
        samples: u32,
        spectral: bool,
        well_conditioned: bool,
    ) -> std::collections::BTreeMap<(usize, usize), (u32, u32, u32, u32)> {
        let camera = camera.model(32, 32);
        let bdpt = Bdpt {
            scene,
            max_depth,
            min_depth: 0,
            spectral,
        };
        let mut space = PathSpace {
            scene,
            camera: &camera,
            channels: Channels::Rgb,
        };
        let mut scratch = crate::integrators::PixelEstimator::scratch(&bdpt);
        let mut counters = SampleCounters::default();
        let mut rng = Rng::new(7, 0);
        let mut path = Vec::new();
        let mut compared =
            std::collections::BTreeMap::<(usize, usize), (u32, u32, u32, u32)>::new();
        for _ in 0..samples {
            let [x, y] = rng.uniform2();
            let (n_camera, n_light) = bdpt.trace_subpaths(
                &camera,
                x * 32.0,
                y * 32.0,
                max_depth as usize + 2,
                max_depth as usize + 1,
                &mut rng,
                &mut scratch,
                &mut counters,
            );
            space.channels = scratch.drawn_channels();
            for t in 1..=n_camera {
                for s in 0..=n_light {
                    if s + t < 2 || s + t - 2 > max_depth as usize || (s == 1 && t == 1) {
                        continue;
                    }
                    let c = bdpt.connect(&camera, &mut scratch, s, t, &mut rng, &mut counters);
                    // Strategies BDPT gives no weight (s = 0 onto a delta light) or no
                    // value: the path, if any, is built from the subpaths as they are.
                    let Some(c) = c.filter(|c| c.weight > 0.0) else {
                        continue;
                    };
                    bdpt.strategy_path(&scratch, s, t, &mut path);
                    if space.channels_of(&path) != scratch.channels() {
                        continue;
                    }
                    let ill_conditioned = (1..path.len() - 1).any(|k| {
                        [k - 1, k + 1].into_iter().any(|j| {
                            direction(&path[k], &path[j]).is_none_or(|(w, distance2)| {
                                w.dot(path[k].normal).abs() < 0.35 || distance2 < 900.0
                            })
                        })
                    });
                    if well_conditioned && ill_conditioned {
                        continue;
                    }
                    let expected = c.value / c.weight;
                    let (value, pixel) = space
                        .unweighted_contribution(&path, s, true)
                        .unwrap_or_else(|| {
                            panic!("{name} ({s}, {t}): none, BDPT {expected}: {path:?}")
                        });
                    let error = ((value - expected).abs()
                        / expected.abs().max(Spectrum::splat(1e-6)))
                    .max_component();
                    assert!(
                        error < 2e-3,
                        "{name} ({s}, {t}): {value} vs BDPT's {expected}: {path:?}"
                    );
                    if let Some(splat) = c.splat_pixel {
                        assert_eq!(pixel, splat, "{name} ({s}, {t})");
                    }
                    // The strategy BDPT gives no weight has no unweighted contribution
                    // either: s = 0 on a delta light.
                    if path[0].light.is_some_and(|e| e.is_delta()) {
                        assert!(space.unweighted_contribution(&path, 0, true).is_none());
                    }
                    let specular = path.iter().any(|v| space.is_specular(v));
                    let glossy = path[1..path.len() - 1]
                        .iter()
                        .any(|v| space.class(v) == VertexClass::Glossy);
                    let entry = compared.entry((s, t)).or_default();
                    entry.0 += 1;
                    entry.1 += specular as u32;
                    entry.2 += path[0].is_at_infinity() as u32;
                    entry.3 += glossy as u32;
                }
            }
        }
        compared
    }

    /// A scene of tests/scenes without its ceiling (the triangles at its top), so that
    /// light from infinity gets in, with the given lights besides its emissive triangles.
    fn open(name: &str, lights: crate::scene::LightsDesc) -> (Scene, Camera) {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes");
        let data = crate::io::load_scene(&dir.join(format!("{name}.obj"))).unwrap();
        let top = data
            .positions
            .chunks(3)
            .map(|p| p[1])
            .fold(f32::MIN, f32::max);
        let mut indices = Vec::new();
        let mut material_ids = Vec::new();
        for (triangle, &material) in data.indices.chunks(3).zip(&data.material_ids) {
            if triangle
                .iter()
                .all(|&v| data.positions[3 * v as usize + 1] >= top)
            {
                continue;
            }
            indices.extend_from_slice(triangle);
            material_ids.push(material);
        }
        assert!(indices.len() < data.indices.len(), "{name}: no ceiling");
        let scene = Scene::new(&SceneDesc {
            positions: &data.positions,
            indices: &indices,
            material_ids: &material_ids,
            materials: &data.materials,
            lights,
            backend: Backend::Bvh,
            ..Default::default()
        })
        .unwrap();
        let camera = crate::io::load_camera_json(&dir.join(format!("{name}.camera.json")))
            .unwrap()
            .camera;
        (scene, camera)
    }

    /// A small environment map: a brighter band and a few coloured texels.
    fn small_environment_map() -> Vec<f32> {
        let (width, height) = (8, 4);
        let mut pixels = Vec::with_capacity(width * height * 3);
        for row in 0..height {
            for column in 0..width {
                let v = 0.2 + 0.3 * row as f32 + 0.1 * (column % 3) as f32;
                pixels.extend_from_slice(&[v, 0.8 * v + 0.05 * column as f32, 0.5 + 0.1 * v]);
            }
        }
        pixels
    }

    /// The same for the lights besides emissive triangles, in the box without a ceiling (its
    /// ceiling light stays, and its front is open): a constant environment and a sun disc, a
    /// small environment map and a sun disc (also through glass), a point light, a spot light,
    /// a directional light and a delta sun. Strategies of every kind of connection to each
    /// kind of light, and escaped camera subpaths (s = 0 at infinity), were compared.
    #[test]
    fn unweighted_contributions_match_bdpt_with_every_kind_of_light() {
        use crate::scene::{EnvironmentDesc, LightsDesc, PunctualLight, SunDesc};
        let sky = [0.4f32, 0.5, 0.7];
        let map = small_environment_map();
        let environment = EnvironmentDesc {
            pixels: &map,
            width: 8,
            height: 4,
            rotation_degrees: 30.0,
            scale: 1.0,
        };
        let sun = SunDesc::from_radiance([-0.3, 1.0, -0.6], 5.0, [200.0, 180.0, 150.0]);
        let point = [PunctualLight::point([278.0, 400.0, 280.0], [4e4, 3e4, 2e4])];
        let spot = [PunctualLight::spot(
            [278.0, 540.0, 280.0],
            [0.1, -1.0, 0.2],
            [6e4, 5e4, 4e4],
            15.0,
            35.0,
        )];
        let directional = [PunctualLight::directional(
            [0.3, -1.0, 0.5],
            [3.0, 2.5, 2.0],
        )];
        let delta_sun = SunDesc {
            direction: [-0.2, 1.0, -0.4],
            angular_radius_degrees: 0.0,
            irradiance: [2.0, 2.0, 1.5],
        };
        let cases: [(&str, &str, LightsDesc); 6] = [
            (
                "constant sky + sun",
                "cornell-box",
                LightsDesc {
                    environment: Some(EnvironmentDesc::constant(&sky)),
                    sun: Some(sun),
                    punctual: &[],
                },
            ),
            (
                "map + sun, glass",
                "cornell-glass",
                LightsDesc {
                    environment: Some(environment),
                    sun: Some(sun),
                    punctual: &[],
                },
            ),
            (
                "point",
                "cornell-box",
                LightsDesc {
                    punctual: &point,
                    ..Default::default()
                },
            ),
            (
                "spot",
                "cornell-glass",
                LightsDesc {
                    punctual: &spot,
                    ..Default::default()
                },
            ),
            (
                "directional",
                "cornell-box",
                LightsDesc {
                    punctual: &directional,
                    ..Default::default()
                },
            ),
            (
                "delta sun + sky",
                "cornell-box",
                LightsDesc {
                    environment: Some(EnvironmentDesc::constant(&sky)),
                    sun: Some(delta_sun),
                    punctual: &[],
                },
            ),
        ];
        for (label, name, lights) in cases {
            let (scene, camera) = open(name, lights);
            let compared = compare_with_bdpt(label, &scene, &camera, 4, 6_000);
            println!("{label}: {compared:?}");
            for (s, t) in [(1, 2), (2, 2), (3, 1), (1, 3), (2, 3), (3, 2)] {
                let (count, ..) = compared.get(&(s, t)).copied().unwrap_or_default();
                assert!(count > 50, "{label}: ({s}, {t}) compared {count} times");
            }
            if lights.environment.is_some() {
                // Escaped camera subpaths (s = 0) and light subpaths from infinity.
                for (s, t) in [(0, 2), (0, 3), (0, 4), (2, 2), (3, 1)] {
                    let (_, _, at_infinity, _) = compared.get(&(s, t)).copied().unwrap_or_default();
                    assert!(
                        at_infinity > 20,
                        "{label}: ({s}, {t}) at infinity {at_infinity} times"
                    );
                }
            }
        }
    }

    /// The same in spectral mode for the lights whose emission is converted to the sampled
    /// wavelengths on its own (not through a triangle's material): a point light, a
    /// directional light and a delta sun under a constant sky, in the box without a ceiling.
    #[test]
    fn unweighted_contributions_match_bdpt_in_spectral_mode_with_lights_that_are_not_triangles() {
        use crate::scene::{EnvironmentDesc, LightsDesc, PunctualLight, SunDesc};
        let sky = [0.4f32, 0.5, 0.7];
        let point = [PunctualLight::point([278.0, 400.0, 280.0], [4e4, 3e4, 2e4])];
        let directional = [PunctualLight::directional(
            [0.3, -1.0, 0.5],
            [3.0, 1.5, 0.5],
        )];
        let delta_sun = SunDesc {
            direction: [-0.2, 1.0, -0.4],
            angular_radius_degrees: 0.0,
            irradiance: [0.5, 2.0, 1.5],
        };
        let cases: [(&str, LightsDesc); 3] = [
            (
                "point",
                LightsDesc {
                    punctual: &point,
                    ..Default::default()
                },
            ),
            (
                "directional",
                LightsDesc {
                    punctual: &directional,
                    ..Default::default()
                },
            ),
            (
                "delta sun + sky",
                LightsDesc {
                    environment: Some(EnvironmentDesc::constant(&sky)),
                    sun: Some(delta_sun),
                    punctual: &[],
                },
            ),
        ];
        for (label, lights) in cases {
            let (scene, camera) = open("cornell-box", lights);
            let compared = compare_with_bdpt_in(label, &scene, &camera, 3, 2_000, true, false);
            println!("{label}: {compared:?}");
            for (s, t) in [(1, 2), (2, 2), (1, 3)] {
                let (count, ..) = compared.get(&(s, t)).copied().unwrap_or_default();
                assert!(count > 20, "{label}: ({s}, {t}) compared {count} times");
            }
        }
    }

    /// Fixed perturbation moves: a film offset, directions turned by a fixed rotation.
    struct FixedKernel {
        film_offset: [f32; 2],
        rotation: glam::Quat,
    }

    impl perturbation::Kernel for FixedKernel {
        fn film_offset(&mut self) -> [f32; 2] {
            self.film_offset
        }
        fn turn(&mut self, w: Vec3A) -> Vec3A {
            Vec3A::from(self.rotation * glam::Vec3::from(w))
        }
        fn step(&mut self, u: [f32; 2]) -> [f32; 2] {
            u
        }
        fn in_sample_space(&self) -> bool {
            false
        }
        fn wavelength_step(&mut self, u: f32) -> f32 {
            u
        }
    }

    /// The perturbations of paths whose light is a direction at infinity or a delta light
    /// are reversible with exact, reciprocal ratios: for BDPT's strategy paths x in the
    /// open glass box under each kind of light, a lens, multi-chain or caustic perturbation
    /// with a fixed move gives y, the opposite move takes y back to x (the same light
    /// kind; an eye ray through the glass that escaped escapes again), the product of the
    /// two ratios is 1, and y admits the same
    /// perturbations as x (the chains pick them with x's probabilities). The caustic
    /// perturbation does not apply where its specular chain starts at a light that is not
    /// a triangle.
    #[test]
    fn perturbations_with_every_kind_of_light_are_reversible() {
        use super::perturbation::{self, applicable};
        use crate::scene::{EnvironmentDesc, LightsDesc, PunctualLight, SunDesc};
        let sky = [0.4f32, 0.5, 0.7];
        let sun = SunDesc::from_radiance([-0.3, 1.0, -0.6], 5.0, [200.0, 180.0, 150.0]);
        let point = [PunctualLight::point([278.0, 400.0, 280.0], [4e4, 3e4, 2e4])];
        let directional = [PunctualLight::directional(
            [0.3, -1.0, 0.5],
            [3.0, 2.5, 2.0],
        )];
        let cases: [(&str, LightsDesc); 3] = [
            (
                "sky + sun",
                LightsDesc {
                    environment: Some(EnvironmentDesc::constant(&sky)),
                    sun: Some(sun),
                    punctual: &[],
                },
            ),
            (
                "point",
                LightsDesc {
                    punctual: &point,
                    ..Default::default()
                },
            ),
            (
                "directional",
                LightsDesc {
                    punctual: &directional,
                    ..Default::default()
                },
            ),
        ];
        let rotation =
            glam::Quat::from_axis_angle(glam::Vec3::new(0.3, 0.8, -0.5).normalize(), 2e-4);
        for (label, lights) in cases {
            let (scene, camera) = open("cornell-glass", lights);
            let camera = camera.model(32, 32);
            let space = PathSpace {
                scene: &scene,
                camera: &camera,
                channels: Channels::Rgb,
            };
            let bdpt = Bdpt {
                scene: &scene,
                max_depth: 5,
                min_depth: 0,
                spectral: false,
            };
            let mut scratch = crate::integrators::PixelEstimator::scratch(&bdpt);
            let mut counters = SampleCounters::default();
            let mut rng = Rng::new(11, 0);
            let (mut x, mut y, mut back) = (Vec::new(), Vec::new(), Vec::new());
            // Per (perturbation, light kind of x_0): moves checked.
            let mut checked = std::collections::BTreeMap::<(usize, &str), u32>::new();
            for _ in 0..4_000 {
                let [fx, fy] = rng.uniform2();
                let (n_camera, n_light) = bdpt.trace_subpaths(
                    &camera,
                    fx * 32.0,
                    fy * 32.0,
                    7,
                    6,
                    &mut rng,
                    &mut scratch,
                    &mut counters,
                );
                for t in 1..=n_camera {
                    for s in 0..=n_light {
                        if s + t < 2 || s + t - 2 > 5 || (s == 1 && t == 1) {
                            continue;
                        }
                        let c = bdpt.connect(&camera, &mut scratch, s, t, &mut rng, &mut counters);
                        if !c.is_some_and(|c| c.weight > 0.0) {
                            continue;
                        }
                        bdpt.strategy_path(&scratch, s, t, &mut x);
                        let kind = match x[0].light {
                            None => continue,
                            Some(light) if !light.is_delta() => "infinite",
                            Some(light) if light.is_delta_position() => "point",
                            Some(_) => "directional",
                        };
                        // Paths into a corner (an edge of a few units in a box of 550) or
                        // grazing a surface are too ill-conditioned for the round trip's
                        // rounding (rays leave surfaces from offset origins).
                        let n = x.len();
                        let short = x.windows(2).enumerate().any(|(i, e)| {
                            let Some((w, _)) = direction(&e[0], &e[1]) else {
                                return true;
                            };
                            let grazing = |v: &PathVertex| w.dot(v.normal).abs() < 0.1;
                            (!e[0].is_at_infinity() && (e[0].p - e[1].p).length() < 20.0)
                                || (i > 0 && grazing(&e[0]))
                                || (i + 2 < n && grazing(&e[1]))
                        });
                        if short {
                            continue;
                        }
                        // The sky seen through the glass: the lens perturbation's eye ray
                        // leaves the scene.
                        let kind = if kind == "infinite"
                            && x[1..x.len() - 1].iter().all(|v| space.is_specular(v))
                        {
                            "infinite, seen"
                        } else {
                            kind
                        };
                        let admits = applicable(&space, &x);
                        if admits.caustic {
                            let start = (1..x.len() - 3)
                                .rev()
                                .find(|&k| !space.is_specular(&x[k]))
                                .unwrap_or(0);
                            assert!(start > 0, "{label}: caustic from a {kind} light");
                        }
                        for which in 0..3 {
                            let mut forward = FixedKernel {
                                film_offset: [0.05, -0.03],
                                rotation,
                            };
                            let mut reverse = FixedKernel {
                                film_offset: [-0.05, 0.03],
                                rotation: rotation.inverse(),
                            };
                            let perturb =
                                |kernel: &mut FixedKernel,
                                 from: &[PathVertex],
                                 to: &mut Vec<PathVertex>| {
                                    match which {
                                        0 => perturbation::lens(
                                            &space, kernel, false, from, to, &mut 0,
                                        ),
                                        1 => perturbation::lens(
                                            &space, kernel, true, from, to, &mut 0,
                                        ),
                                        _ => {
                                            perturbation::caustic(&space, kernel, from, to, &mut 0)
                                        }
                                    }
                                };
                            let Some(p) = perturb(&mut forward, &x, &mut y) else {
                                continue;
                            };
                            assert_eq!(applicable(&space, &y), admits, "{label} {which}");
                            assert_eq!(y[0].light, x[0].light, "{label} {which}");
                            // Across an edge of the tessellated sphere the normal jumps: the
                            // opposite move need not come back.
                            if x.iter().zip(&y).any(|(a, b)| a.triangle != b.triangle) {
                                continue;
                            }
                            let Some(q) = perturb(&mut reverse, &y, &mut back) else {
                                panic!("{label} {which} {kind}: no way back from {y:?} to {x:?}");
                            };
                            if x.iter().zip(&back).any(|(a, b)| a.triangle != b.triangle) {
                                continue;
                            }
                            for (a, b) in x.iter().zip(&back) {
                                assert_eq!(a.light, b.light, "{label} {which}");
                                let scale = if a.is_at_infinity() { 1e-2 } else { 2.0 };
                                assert!(
                                    (a.p - b.p).length() < scale
                                        && (a.normal - b.normal).length() < 2e-2,
                                    "{label} {which} {kind}: {x:?} came back as {back:?}"
                                );
                            }
                            assert!(
                                (p.ratio * q.ratio - 1.0).abs() < 5e-2,
                                "{label} {which} {kind}: ratios {} and {}: {x:?} → {y:?} → {back:?}, values {} {} {}",
                                p.ratio,
                                q.ratio,
                                space
                                    .unweighted_contribution(&x, s, false)
                                    .map_or(Spectrum::ZERO, |c| c.0),
                                p.value,
                                q.value
                            );
                            *checked.entry((which, kind)).or_default() += 1;
                        }
                    }
                }
            }
            println!("{label}: {checked:?}");
            let wanted: &[(usize, &str)] = match label {
                "sky + sun" => &[
                    (0, "infinite"),
                    (0, "infinite, seen"),
                    (1, "infinite"),
                    (2, "infinite"),
                ],
                "point" => &[(0, "point"), (1, "point"), (2, "point")],
                _ => &[(0, "directional"), (1, "directional"), (2, "directional")],
            };
            for key in wanted {
                let count = checked.get(key).copied().unwrap_or_default();
                assert!(count >= 20, "{label}: {key:?} checked {count} times");
            }
        }
    }

    /// The Cornell box with its glass sphere, made dispersive (Abbe number 20).
    fn dispersive_glass_box() -> (Scene, Camera) {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes");
        let mut data = crate::io::load_scene(&dir.join("cornell-glass.obj")).unwrap();
        for m in &mut data.materials {
            if m.kind == crate::scene::MaterialKind::Dielectric {
                m.abbe_number = 20.0;
            }
        }
        let scene = Scene::new(&SceneDesc {
            positions: &data.positions,
            indices: &data.indices,
            material_ids: &data.material_ids,
            materials: &data.materials,
            backend: Backend::Bvh,
            ..Default::default()
        })
        .unwrap();
        let camera = crate::io::load_camera_json(&dir.join("cornell-glass.camera.json"))
            .unwrap()
            .camera;
        (scene, camera)
    }

    /// A kernel that moves the wavelengths only: the film position stays, and the
    /// wavelengths' random number takes the chains' own step, or (`to`) jumps there.
    struct WavelengthKernel<'a> {
        rng: &'a mut Rng,
        to: Option<f32>,
    }

    impl perturbation::Kernel for WavelengthKernel<'_> {
        fn film_offset(&mut self) -> [f32; 2] {
            [0.0; 2]
        }
        fn turn(&mut self, w: Vec3A) -> Vec3A {
            w
        }
        fn step(&mut self, u: [f32; 2]) -> [f32; 2] {
            u
        }
        fn in_sample_space(&self) -> bool {
            false
        }
        fn wavelength_step(&mut self, u: f32) -> f32 {
            self.to
                .unwrap_or_else(|| perturbation::step_wavelength_number(u, self.rng))
        }
    }

    /// Detailed balance of the wavelength step. A path L D S S E of the dispersive glass
    /// box (a light, the floor seen through the sphere's two refractions, the lens) moved by
    /// lens perturbations that keep its film position and step only its wavelengths'
    /// random number u has, over u, the target density of its luminance (the path moved to
    /// each u of a fine grid gives it). Chains started from that density are still in it
    /// after 100 steps (χ² over 16 bins of u, 4000 chains), and chains whose ratio leaves
    /// out the wavelengths' density (times p(λ')/p(λ): a target per nanometre, not per unit
    /// of u) are not.
    #[test]
    fn wavelength_steps_keep_the_target_over_the_wavelengths() {
        use crate::integrators::mlt::acceptance;
        use crate::sampling::chi_square::{Z_999, pooled_statistic, quantile};
        let (scene, camera) = dispersive_glass_box();
        let camera = camera.model(32, 32);
        let bdpt = Bdpt {
            scene: &scene,
            max_depth: 4,
            min_depth: 0,
            spectral: true,
        };
        let mut scratch = crate::integrators::PixelEstimator::scratch(&bdpt);
        let mut counters = SampleCounters::default();
        let mut rng = Rng::new(5, 0);
        let mut x = Vec::new();
        let space = loop {
            let [fx, fy] = rng.uniform2();
            let (n_camera, _) = bdpt.trace_subpaths(
                &camera,
                fx * 32.0,
                fy * 32.0,
                6,
                5,
                &mut rng,
                &mut scratch,
                &mut counters,
            );
            if n_camera < 4 {
                continue;
            }
            let c = bdpt.connect(&camera, &mut scratch, 1, 4, &mut rng, &mut counters);
            if !c.is_some_and(|c| c.weight > 0.0) {
                continue;
            }
            bdpt.strategy_path(&scratch, 1, 4, &mut x);
            let space = PathSpace {
                scene: &scene,
                camera: &camera,
                channels: scratch.drawn_channels(),
            };
            if x.len() == 5
                && x[0].light.is_none()
                && !space.is_specular(&x[1])
                && space.disperses_at(&x, 2)
                && space.disperses_at(&x, 3)
            {
                break space;
            }
        };
        // The path moved to u, with its wavelengths, and its luminance.
        let moved_to = |u: f32, y: &mut Vec<PathVertex>| {
            let mut unused = Rng::new(0, 0);
            let mut kernel = WavelengthKernel {
                rng: &mut unused,
                to: Some(u),
            };
            perturbation::lens(&space, &mut kernel, false, &x, y, &mut 0)
                .map(|p| (p.channels, p.value.luminance() as f64))
        };
        const GRID: usize = 4096;
        const BINS: usize = 16;
        let mut y = Vec::new();
        let density: Vec<f64> = (0..GRID)
            .map(|i| moved_to((i as f32 + 0.5) / GRID as f32, &mut y).map_or(0.0, |m| m.1))
            .collect();
        let total: f64 = density.iter().sum();
        let mut expected = [0.0; BINS];
        for (i, d) in density.iter().enumerate() {
            expected[i * BINS / GRID] += d / total;
        }
        let pdf = |channels: &Channels| match channels {
            Channels::Wavelengths(w) => w.pdf[0],
            Channels::Rgb => unreachable!(),
        };
        let bin = |channels: &Channels| match channels {
            Channels::Wavelengths(w) => ((w.u * BINS as f32) as usize).min(BINS - 1),
            Channels::Rgb => unreachable!(),
        };
        let chains = 4000u64;
        let mut final_bins = |flawed: bool| {
            let mut counts = [0u64; BINS];
            let mut rng = Rng::new(17, 0);
            let mut accepted = 0u64;
            for _ in 0..chains {
                // A start drawn from the density: a grid cell, then a point within it.
                let goal = rng.uniform() as f64 * total;
                let mut sum = 0.0;
                let cell = density
                    .iter()
                    .position(|d| {
                        sum += d;
                        sum > goal
                    })
                    .unwrap_or(GRID - 1);
                let u = (cell as f32 + rng.uniform()) / GRID as f32;
                let mut current = Vec::new();
                let Some((mut channels, _)) = moved_to(u, &mut current) else {
                    continue;
                };
                for _ in 0..100 {
                    let mut kernel = WavelengthKernel {
                        rng: &mut rng,
                        to: None,
                    };
                    let here = space.with_channels(channels);
                    let Some(p) =
                        perturbation::lens(&here, &mut kernel, false, &current, &mut y, &mut 0)
                    else {
                        continue;
                    };
                    let ratio = if flawed {
                        p.ratio * pdf(&p.channels) / pdf(&channels)
                    } else {
                        p.ratio
                    };
                    if rng.uniform() < acceptance(1.0, 1.0, ratio) {
                        std::mem::swap(&mut current, &mut y);
                        channels = p.channels;
                        accepted += 1;
                    }
                }
                counts[bin(&channels)] += 1;
            }
            let total: u64 = counts.iter().sum();
            let (statistic, cells) = pooled_statistic(&counts, total, &expected);
            eprintln!(
                "flawed {flawed}: χ² {statistic:.1} on {cells} cells, accepted {:.2}",
                accepted as f64 / (chains * 100) as f64
            );
            (statistic, quantile(cells, Z_999))
        };
        let (statistic, bound) = final_bins(false);
        assert!(statistic < bound, "χ² {statistic} ≥ {bound}");
        let (statistic, bound) = final_bins(true);
        assert!(
            statistic > bound,
            "the flawed ratio passes: χ² {statistic} < {bound}"
        );
    }

    /// In spectral mode, with the glass sphere dispersive (Abbe number 20), the same: the
    /// path space measures a path in the wavelengths its sample drew, at its hero alone
    /// where a vertex disperses, as BDPT does.
    #[test]
    fn spectral_contributions_match_bdpt_through_dispersive_glass() {
        let (scene, camera) = dispersive_glass_box();
        let compared =
            compare_with_bdpt_in("dispersive glass", &scene, &camera, 6, 20_000, true, false);
        assert_through_glass(
            "dispersive glass",
            &compared,
            &[
                (0, 8, 5),
                (1, 4, 300),
                (2, 4, 200),
                (4, 1, 200),
                (6, 1, 500),
            ],
        );
    }

    /// Asserts that each strategy (s, t) was compared through glass at least `least` times.
    fn assert_through_glass(
        name: &str,
        compared: &std::collections::BTreeMap<(usize, usize), (u32, u32, u32, u32)>,
        least: &[(usize, usize, u32)],
    ) {
        for &(s, t, least) in least {
            let (_, through_glass, ..) = compared.get(&(s, t)).copied().unwrap_or_default();
            assert!(
                through_glass >= least,
                "{name}: ({s}, {t}) through glass {through_glass} times"
            );
        }
    }

    /// The Cornell box with smooth coats (metallic-roughness at roughness 0, non-metal)
    /// over its floor's white base, its short block's red one, and its tall block's half
    /// diffuse, half transmissive one: a Dirac lobe (and a Dirac refraction) beside a
    /// diffuse one. Its walls have smooth clear coats: over a rough non-metal (right), a
    /// rough metal (left) and, at the back, a smooth metal whose normal map tilts its
    /// normal 17° from the coat's (two mirrors about different normals); the floor's
    /// smooth dielectric has one too (its mirror and the coat's are one).
    fn coated_box() -> (Scene, Camera) {
        use crate::scene::Material;
        use crate::texture::{TexelData, TextureDesc, TextureEncoding, TextureFilter, WrapMode};
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes");
        let mut data = crate::io::load_scene(&dir.join("cornell-box.obj")).unwrap();
        let first = data.materials.len() as u32;
        let coat = |m: Material, factor: f32| Material {
            clearcoat: factor,
            clearcoat_roughness: 0.0,
            ..m
        };
        data.materials.extend([
            coat(Material::metallic_roughness([0.8; 3], 0.0, 0.0), 0.7),
            Material::metallic_roughness([0.7, 0.25, 0.15], 0.0, 0.0),
            Material {
                transmission: 0.5,
                ..Material::metallic_roughness([0.6, 0.8, 0.9], 0.0, 0.0)
            },
            coat(Material::metallic_roughness([0.2, 0.7, 0.3], 0.0, 0.6), 1.0),
            coat(Material::metallic_roughness([0.9, 0.5, 0.4], 1.0, 0.4), 1.0),
            Material {
                normal_texture: Some(crate::TextureRef::new(0)),
                ..coat(Material::metallic_roughness([0.9, 0.8, 0.6], 1.0, 0.0), 1.0)
            },
        ]);
        for (triangle, material) in data.material_ids.iter_mut().enumerate() {
            match triangle {
                0..2 => *material = first,
                4..6 => *material = first + 5,
                6..8 => *material = first + 3,
                8..10 => *material = first + 4,
                10..20 => *material = first + 1,
                20..30 => *material = first + 2,
                _ => {}
            }
        }
        // The normal map's one texel, (0.3, 0, 0.95) in tangent space; texture
        // coordinates (x, y) / 550, a frame for the back wall.
        let normal_map = TextureDesc {
            width: 1,
            height: 1,
            channels: 3,
            data: TexelData::U8(std::borrow::Cow::Owned(vec![166, 128, 249])),
            encoding: TextureEncoding::Linear,
            wrap_u: WrapMode::Repeat,
            wrap_v: WrapMode::Repeat,
            filter: TextureFilter::Nearest,
        };
        let texcoords: Vec<f32> = data
            .positions
            .chunks(3)
            .flat_map(|p| [p[0] / 550.0, p[1] / 550.0])
            .collect();
        let scene = Scene::new(&SceneDesc {
            positions: &data.positions,
            indices: &data.indices,
            material_ids: &data.material_ids,
            materials: &data.materials,
            texcoords: &texcoords,
            textures: &[normal_map],
            backend: Backend::Bvh,
            ..Default::default()
        })
        .unwrap();
        let camera = crate::io::load_camera_json(&dir.join("cornell-box.camera.json"))
            .unwrap()
            .camera;
        (scene, camera)
    }

    /// Where a BSDF has a Dirac lobe beside a diffuse one, the path records which lobe it
    /// scattered through at each vertex (BDPT's strategy paths carry what its subpaths
    /// sampled), and the contribution of every strategy evaluated on the path equals
    /// BDPT's own, through the coats' reflections and refractions on both sides. (The box
    /// has no purely specular surface: every path counted through a specular vertex went
    /// through a coat's Dirac lobe.) Paths with a short or grazing edge are left out:
    /// rebuilt from its points, such an edge's direction differs from the ray BDPT sampled
    /// from an offset origin by enough for the base's albedo scaling, steep at grazing
    /// angles, to differ by more than the tolerance (0.6% at 83°, 0.24% at 74° after an
    /// edge of 12 units).
    #[test]
    fn unweighted_contributions_match_bdpt_through_smooth_coats() {
        let (scene, camera) = coated_box();
        let compared = compare_with_bdpt_in("coated box", &scene, &camera, 6, 20_000, false, true);
        println!("{compared:?}");
        assert_through_glass(
            "coated box",
            &compared,
            &[
                (0, 5, 2),
                (0, 6, 1),
                (1, 4, 100),
                (1, 6, 90),
                (2, 4, 30),
                (2, 5, 40),
                (3, 4, 30),
                (4, 1, 10),
                (4, 3, 15),
                (5, 1, 15),
                (7, 1, 12),
            ],
        );
    }

    /// The perturbations keep the lobes of paths through smooth coats and are reversible
    /// with reciprocal ratios: for BDPT's strategy paths of the coated box through a coat's
    /// Dirac lobe, a lens, multi-chain or caustic perturbation with a fixed move gives y
    /// with x's lobe at every vertex (and the same perturbations admitted), the opposite
    /// move takes y back to x, and the product of the two ratios is 1.
    #[test]
    fn perturbations_through_smooth_coats_keep_the_lobes_and_are_reversible() {
        use super::perturbation::{self, applicable};
        let (scene, camera) = coated_box();
        let camera = camera.model(32, 32);
        let space = PathSpace {
            scene: &scene,
            camera: &camera,
            channels: Channels::Rgb,
        };
        let bdpt = Bdpt {
            scene: &scene,
            max_depth: 5,
            min_depth: 0,
            spectral: false,
        };
        let rotation =
            glam::Quat::from_axis_angle(glam::Vec3::new(0.3, 0.8, -0.5).normalize(), 2e-4);
        let mut scratch = crate::integrators::PixelEstimator::scratch(&bdpt);
        let mut counters = SampleCounters::default();
        let mut rng = Rng::new(13, 0);
        let (mut x, mut y, mut back) = (Vec::new(), Vec::new(), Vec::new());
        let mut checked = [0u32; 3];
        for _ in 0..3_000 {
            let [fx, fy] = rng.uniform2();
            let (n_camera, n_light) = bdpt.trace_subpaths(
                &camera,
                fx * 32.0,
                fy * 32.0,
                7,
                6,
                &mut rng,
                &mut scratch,
                &mut counters,
            );
            for t in 1..=n_camera {
                for s in 0..=n_light {
                    if s + t < 2 || s + t - 2 > 5 || (s == 1 && t == 1) {
                        continue;
                    }
                    let c = bdpt.connect(&camera, &mut scratch, s, t, &mut rng, &mut counters);
                    if !c.is_some_and(|c| c.weight > 0.0) {
                        continue;
                    }
                    bdpt.strategy_path(&scratch, s, t, &mut x);
                    // Through a Dirac lobe, away from corners and grazing angles, the
                    // light's included (too ill-conditioned for the round trip's
                    // rounding).
                    let n = x.len();
                    let ill_conditioned = x.windows(2).enumerate().any(|(i, e)| {
                        let Some((w, distance2)) = direction(&e[0], &e[1]) else {
                            return true;
                        };
                        let grazing = |v: &PathVertex| w.dot(v.normal).abs() < 0.1;
                        distance2 < 2500.0 || grazing(&e[0]) || (i + 2 < n && grazing(&e[1]))
                    });
                    if !x.iter().any(|v| space.is_specular(v)) || ill_conditioned {
                        continue;
                    }
                    let admits = applicable(&space, &x);
                    for (which, count) in checked.iter_mut().enumerate() {
                        let mut forward = FixedKernel {
                            film_offset: [0.05, -0.03],
                            rotation,
                        };
                        let mut reverse = FixedKernel {
                            film_offset: [-0.05, 0.03],
                            rotation: rotation.inverse(),
                        };
                        let perturb =
                            |kernel: &mut FixedKernel,
                             from: &[PathVertex],
                             to: &mut Vec<PathVertex>| match which {
                                0 => perturbation::lens(&space, kernel, false, from, to, &mut 0),
                                1 => perturbation::lens(&space, kernel, true, from, to, &mut 0),
                                _ => perturbation::caustic(&space, kernel, from, to, &mut 0),
                            };
                        let Some(p) = perturb(&mut forward, &x, &mut y) else {
                            continue;
                        };
                        let lobes = |path: &[PathVertex]| -> Vec<bool> {
                            path.iter().map(|v| space.is_specular(v)).collect()
                        };
                        assert_eq!(lobes(&y), lobes(&x), "{which}: {x:?} → {y:?}");
                        assert_eq!(applicable(&space, &y), admits, "{which}");
                        let Some(q) = perturb(&mut reverse, &y, &mut back) else {
                            panic!("{which}: no way back from {y:?} to {x:?}");
                        };
                        if x.iter().zip(&back).any(|(a, b)| a.triangle != b.triangle) {
                            continue;
                        }
                        for (a, b) in x.iter().zip(&back) {
                            assert!(
                                (a.p - b.p).length() < 2.0 && a.dirac == b.dirac,
                                "{which}: {x:?} came back as {back:?}"
                            );
                        }
                        // A round trip that comes back only roughly (the walls' glossy
                        // lobes under their coats make f steep along some paths) says
                        // little about the ratios.
                        let farthest = x
                            .iter()
                            .zip(&back)
                            .map(|(a, b)| (a.p - b.p).length())
                            .fold(0.0, f32::max);
                        if farthest > 0.05 {
                            continue;
                        }
                        assert!(
                            (p.ratio * q.ratio - 1.0).abs() < 5e-2,
                            "{which}: ratios {} and {} (back within {farthest}): {x:?} → {y:?}",
                            p.ratio,
                            q.ratio,
                        );
                        *count += 1;
                    }
                }
            }
        }
        println!("{checked:?}");
        for (which, count) in checked.into_iter().enumerate() {
            assert!(count >= 100, "perturbation {which} checked {count} times");
        }
    }

    /// For every strategy of many BDPT samples, the contribution evaluated on the path the
    /// strategy built equals BDPT's own (its weighted value over its MIS weight), on the
    /// diffuse box and through glass.
    #[test]
    fn unweighted_contributions_match_bdpt_for_every_strategy() {
        for name in ["cornell-box", "cornell-glass"] {
            let (scene, camera) = canonical(name);
            // Per (s, t): strategies compared, and those through a specular vertex.
            let compared = compare_with_bdpt(name, &scene, &camera, 6, 20_000);
            // Every kind of connection, and (in glass) paths through specular vertices on
            // both sides, were compared.
            for (s, t) in [(0, 3), (1, 2), (2, 2), (3, 1), (2, 4), (4, 2)] {
                let (count, ..) = compared.get(&(s, t)).copied().unwrap_or_default();
                assert!(count > 50, "{name}: ({s}, {t}) compared {count} times");
            }
            if name == "cornell-glass" {
                assert_through_glass(
                    name,
                    &compared,
                    &[
                        (0, 8, 5),
                        (1, 5, 100),
                        (2, 5, 100),
                        (3, 4, 100),
                        (4, 2, 50),
                        (6, 1, 100),
                    ],
                );
            }
        }
    }

    /// cornell-glass with its glass's material replaced by `glass(material)`.
    fn cornell_glass_with(
        glass: impl Fn(&crate::scene::Material) -> crate::scene::Material,
    ) -> (Scene, Camera) {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes");
        let data = crate::io::load_scene(&dir.join("cornell-glass.obj")).unwrap();
        let camera = crate::io::load_camera_json(&dir.join("cornell-glass.camera.json"))
            .unwrap()
            .camera;
        let materials: Vec<_> = data
            .materials
            .iter()
            .map(|m| match m.kind {
                crate::scene::MaterialKind::Dielectric => glass(m),
                _ => *m,
            })
            .collect();
        let scene = Scene::new(&SceneDesc {
            positions: &data.positions,
            indices: &data.indices,
            material_ids: &data.material_ids,
            materials: &materials,
            backend: Backend::Bvh,
            ..Default::default()
        })
        .unwrap();
        (scene, camera)
    }

    /// The glass of cornell-glass filled with an absorbing volume: the contribution path
    /// space evaluates, with the absorption along every edge, is BDPT's for every strategy.
    /// (Rough glass is left to the image tests, tests/volume.rs, and to
    /// `unweighted_contributions_match_bdpt_through_rough_glass`, which says why its paths
    /// need a smaller ray offset and no short or grazing edge to agree within 0.2%.)
    #[test]
    fn unweighted_contributions_match_bdpt_through_an_absorbing_volume() {
        let (scene, camera) = cornell_glass_with(|m| crate::scene::Material {
            thickness: 1.0,
            attenuation_color: [0.3, 0.6, 0.9],
            attenuation_distance: 100.0,
            ..*m
        });
        assert!(scene.has_media());
        let compared = compare_with_bdpt("absorbing glass", &scene, &camera, 5, 10_000);
        let through: u32 = compared.values().map(|c| c.1).sum();
        assert!(through > 1000, "{through} paths through the glass");
    }

    /// Through rough glass (cornell-glass's sphere made a transmissive metallic-roughness
    /// material of roughness 0.3 and index 1.5) the contribution evaluated on the path
    /// equals BDPT's for every strategy, within the same 0.2%, on paths without a short or
    /// grazing edge, with a tenth of the scene's ray offset.
    ///
    /// The two evaluate the same formulas at slightly different directions: BDPT's BSDFs
    /// see the rays it traced, which leave an origin moved off the surface by the scene's
    /// ray offset, the path space the directions between the vertices. They differ by
    /// about offset / edge length, and a rough refraction is steep in places: its f goes
    /// as the cosine to the microfacet, which vanishes where the outside direction grazes
    /// it (the inside one at the critical angle to it), and its lobe choice as the square
    /// root of the macro normal's distance to the critical angle inside. With the scene's
    /// own offset (2e-5 of its size) the worst of 20 000 samples' well-conditioned paths
    /// then differs by 0.65% (every path: 9.8%; a hundredth of the paths by 0.04%); the
    /// differences scale with the offset, 6.5% at ten times it and 0.065% at a tenth, as
    /// no difference of formulas would (the BSDF's importance mode is its radiance mode's
    /// adjoint to 4e-7 relative). A tenth of the offset (still 18 ulps of the box's
    /// coordinates) leaves the tolerance its use: a factor of 1.003 on the path space's
    /// contributions through the glass fails the test.
    #[test]
    fn unweighted_contributions_match_bdpt_through_rough_glass() {
        let (mut scene, camera) = cornell_glass_with(|_| crate::scene::Material {
            transmission: 1.0,
            ior: 1.5,
            ..crate::scene::Material::metallic_roughness([1.0; 3], 0.0, 0.3)
        });
        scene.ray_epsilon *= 0.1;
        let compared = compare_with_bdpt_in("rough glass", &scene, &camera, 6, 20_000, false, true);
        // Every kind of strategy was compared through the rough glass (a glossy vertex).
        for (s, t, least) in [
            (0, 5, 3),
            (1, 4, 300),
            (2, 1, 130),
            (2, 5, 75),
            (3, 4, 70),
            (4, 1, 120),
            (4, 4, 50),
            (6, 1, 90),
        ] {
            let (.., glossy) = compared.get(&(s, t)).copied().unwrap_or_default();
            assert!(
                glossy >= least,
                "({s}, {t}) through rough glass {glossy} times"
            );
        }
    }
}
