//! The C ABI as a C host calls it, shared by the tests of `tests/capi_*.rs`: checking a
//! call's status and last error message, tables of bad inputs (`cases!`, `non_finite_cases!`,
//! `assert_cases`: each case a valid input with one change, labelled with that change's
//! source text, and what the message must contain; a table fails listing every failing
//! case), the structs' defaults, a small host-owned scene, and an owned scene handle.
// Each test file uses a part of these helpers.
#![allow(dead_code)]

use mlt::capi::*;
use mlt::error::*;
use std::ffi::CStr;
use std::ptr::null_mut;

pub fn last_error() -> String {
    // SAFETY: mlt returns a NUL-terminated string valid until the next call on this thread.
    unsafe { CStr::from_ptr(mlt_last_error_message()) }
        .to_str()
        .unwrap()
        .to_owned()
}

/// The outcome of checking one case: `Err` says what is wrong.
pub type Check = std::result::Result<(), String>;

/// Whether a call returned `expected` and left a last error message containing every one of
/// `needles`; the error says what differs.
pub fn check_error(status: MltStatus, expected: MltStatus, needles: &[impl AsRef<str>]) -> Check {
    let message = last_error();
    if status != expected {
        return Err(format!(
            "{status:?} instead of {expected:?}; message {message:?}"
        ));
    }
    let missing: Vec<&str> = needles
        .iter()
        .map(AsRef::as_ref)
        .filter(|needle| !message.contains(needle))
        .collect();
    if !missing.is_empty() {
        return Err(format!(
            "the message {message:?} should mention {missing:?}"
        ));
    }
    Ok(())
}

/// `Err(what)` unless `condition`: the "untouched on failure" checks of a case.
pub fn ensure(condition: bool, what: &str) -> Check {
    if condition {
        Ok(())
    } else {
        Err(what.to_owned())
    }
}

#[track_caller]
pub fn pass(result: Check) {
    if let Err(error) = result {
        panic!("{error}");
    }
}

/// Asserts `status` and that the last error message contains every one of `needles`.
#[track_caller]
pub fn assert_error(status: MltStatus, expected: MltStatus, needles: &[&str]) {
    pass(check_error(status, expected, needles));
}

#[track_caller]
pub fn assert_invalid(status: MltStatus, needles: &[&str]) {
    assert_error(status, MLT_STATUS_INVALID_ARGUMENT, needles);
}

/// Whether a call succeeded and cleared the last error.
pub fn check_ok(status: MltStatus) -> Check {
    let message = last_error();
    ensure(
        status == MLT_STATUS_OK,
        &format!("{status:?}; message {message:?}"),
    )?;
    ensure(message.is_empty(), "a success clears the last error")
}

#[track_caller]
pub fn assert_ok(status: MltStatus) {
    pass(check_ok(status));
}

/// One bad input of a table: the label that names it in failure messages, the input, and
/// what the last error message must contain.
pub struct Case<T> {
    pub label: String,
    pub input: T,
    pub needles: Vec<String>,
}

/// A table of cases, one a line: `cases![x = base; change => [needles], ...]` gives each
/// case the input `base` (evaluated anew for each) with `change` applied to it as `x` (an
/// assignment, or a block of them), labelled with the change's source text.
#[allow(unused_macros)] // Not every test file has tables.
macro_rules! cases {
    ($x:ident = $base:expr; $($change:expr => [$($needle:expr),* $(,)?]),+ $(,)?) => {
        vec![$({
            let mut $x = $base;
            $change;
            $crate::common::capi::Case {
                label: stringify!($change).to_owned(),
                input: $x,
                needles: vec![$($needle.to_string()),*],
            }
        }),+]
    };
}
#[allow(unused_imports)]
pub(crate) use cases;

/// NaN and both infinities: no float a host passes may be one (unless the header says so).
pub const NON_FINITE: [f32; 3] = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY];

/// `non_finite_cases![x = base; place => "name" + "rule", ...]`: for each float `place` of
/// `x`, a case for each of NaN, +inf and -inf put there, whose message must say
/// "<name> is <value>" and contain each `rule` (what the valid values are).
#[allow(unused_macros)]
macro_rules! non_finite_cases {
    ($x:ident = $base:expr; $($place:expr => $name:literal $(+ $rule:literal)*),+ $(,)?) => {{
        let mut cases = Vec::new();
        $(for value in $crate::common::capi::NON_FINITE {
            let mut $x = $base;
            $place = value;
            cases.push($crate::common::capi::Case {
                label: format!("{} = {value}", stringify!($place)),
                input: $x,
                needles: vec![format!("{} is {value}", $name) $(, $rule.to_string())*],
            });
        })+
        cases
    }};
}
#[allow(unused_imports)]
pub(crate) use non_finite_cases;

/// Checks every case with `check` (given its input and needles), then fails listing each case
/// that failed by its label, with why.
#[track_caller]
pub fn assert_cases<T>(table: &str, cases: &[Case<T>], check: impl Fn(&T, &[String]) -> Check) {
    assert_all(
        table,
        cases
            .iter()
            .map(|case| (case.label.clone(), check(&case.input, &case.needles))),
    );
}

/// Fails listing every `(label, result)` that is an error, after looking at all of them.
#[track_caller]
pub fn assert_all(table: &str, results: impl IntoIterator<Item = (String, Check)>) {
    let results: Vec<_> = results.into_iter().collect();
    assert!(!results.is_empty(), "{table}: the table is empty");
    let failures: Vec<String> = results
        .iter()
        .filter_map(|(label, result)| result.as_ref().err().map(|e| format!("  {label}: {e}")))
        .collect();
    assert!(
        failures.is_empty(),
        "{table}: {} of {} cases failed:\n{}",
        failures.len(),
        results.len(),
        failures.join("\n")
    );
}

/// One row of a table of calls mlt must refuse: what the call passes wrong, the call (its
/// status, and whether it left its outputs untouched), and what the last error message must
/// contain.
pub type RefusedCall<'a> = (
    &'a str,
    Box<dyn Fn() -> (MltStatus, bool) + 'a>,
    &'a [&'a str],
);

/// Makes every call of `calls`, each to be refused as an invalid argument with its outputs
/// untouched, then fails listing each call that was not.
#[track_caller]
pub fn assert_calls_refused(table: &str, calls: Vec<RefusedCall>) {
    assert_all(
        table,
        calls.into_iter().map(|(label, call, needles)| {
            let (status, untouched) = call();
            let result = check_error(status, MLT_STATUS_INVALID_ARGUMENT, needles)
                .and_then(|()| ensure(untouched, "an output was written on failure"));
            (label.to_owned(), result)
        }),
    );
}

/// An aligned, non-null pointer value no allocation will ever have: the "untouched" marker
/// for out-parameters that are pointers.
pub fn sentinel_scene() -> *mut MltScene {
    std::ptr::dangling_mut::<u64>().wrapping_add(0x1000).cast()
}

pub const SENTINEL_F32: f32 = -12345.0;

/// An `MltBytes` holding nothing, as a host declares one before a call fills it.
pub fn empty_bytes() -> MltBytes {
    MltBytes {
        data: null_mut(),
        size: 0,
    }
}

pub fn default_material() -> MltMaterial {
    let mut m = std::mem::MaybeUninit::<MltMaterial>::uninit();
    // SAFETY: writable memory for an MltMaterial.
    assert_ok(unsafe { mlt_material_init(m.as_mut_ptr(), size_of::<MltMaterial>()) });
    // SAFETY: initialized on success.
    unsafe { m.assume_init() }
}

pub fn default_camera() -> MltCamera {
    let mut c = std::mem::MaybeUninit::<MltCamera>::uninit();
    // SAFETY: as above.
    assert_ok(unsafe { mlt_camera_init(c.as_mut_ptr(), size_of::<MltCamera>()) });
    unsafe { c.assume_init() }
}

pub fn default_settings() -> MltRenderSettings {
    let mut s = std::mem::MaybeUninit::<MltRenderSettings>::uninit();
    // SAFETY: as above.
    assert_ok(unsafe { mlt_render_settings_init(s.as_mut_ptr(), size_of::<MltRenderSettings>()) });
    unsafe { s.assume_init() }
}

pub fn default_desc() -> MltSceneDesc {
    let mut d = std::mem::MaybeUninit::<MltSceneDesc>::uninit();
    // SAFETY: as above.
    assert_ok(unsafe { mlt_scene_desc_init(d.as_mut_ptr(), size_of::<MltSceneDesc>()) });
    unsafe { d.assume_init() }
}

pub fn render_stats_default() -> MltRenderStats {
    let mut s = MltRenderStats::default();
    // SAFETY: writable memory of this size.
    assert_ok(unsafe { mlt_render_stats_init(&mut s, size_of::<MltRenderStats>()) });
    s
}

pub fn scene_info_default() -> MltSceneInfo {
    let mut i = MltSceneInfo::default();
    // SAFETY: writable memory of this size.
    assert_ok(unsafe { mlt_scene_info_init(&mut i, size_of::<MltSceneInfo>()) });
    i
}

pub fn small_settings(width: u32, height: u32, spp: u32) -> MltRenderSettings {
    MltRenderSettings {
        width,
        height,
        algorithm: MLT_ALGORITHM_PATH,
        samples_per_pixel: spp,
        ..default_settings()
    }
}

/// Host-owned arrays of a scene; `desc()` points into them like a C host's struct would.
#[derive(Clone)]
pub struct HostScene {
    pub positions: Vec<f32>,
    pub indices: Vec<u32>,
    pub material_ids: Vec<u32>,
    pub materials: Vec<MltMaterial>,
    pub backend: i32,
}

impl HostScene {
    /// A floor quad (y = 0, facing +y, material 0) under a light quad (y = 2, facing -y,
    /// material 1): 8 vertices, 4 triangles, 2 materials.
    pub fn floor_and_light() -> Self {
        let floor = default_material();
        let light = MltMaterial {
            color: [0.0; 3],
            emission: [1.0, 1.0, 1.0],
            ..default_material()
        };
        HostScene {
            positions: vec![
                -1.0, 0.0, -1.0, -1.0, 0.0, 1.0, 1.0, 0.0, 1.0, 1.0, 0.0, -1.0, // floor
                -1.0, 2.0, -1.0, 1.0, 2.0, -1.0, 1.0, 2.0, 1.0, -1.0, 2.0, 1.0, // light
            ],
            indices: vec![0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7],
            material_ids: vec![0, 0, 1, 1],
            materials: vec![floor, light],
            backend: MLT_BACKEND_BVH,
        }
    }

    pub fn cornell_box() -> Self {
        let mesh = super::scenes::cornell_box();
        HostScene {
            materials: mesh.c_materials(),
            positions: mesh.positions,
            indices: mesh.indices,
            material_ids: mesh.material_ids,
            backend: MLT_BACKEND_BVH,
        }
    }

    pub fn desc(&self) -> MltSceneDesc {
        MltSceneDesc {
            positions: self.positions.as_ptr(),
            positions_len: self.positions.len(),
            indices: self.indices.as_ptr(),
            indices_len: self.indices.len(),
            material_ids: self.material_ids.as_ptr(),
            material_ids_len: self.material_ids.len(),
            materials: self.materials.as_ptr(),
            materials_len: self.materials.len(),
            backend: self.backend,
            ..default_desc()
        }
    }

    /// `mlt_scene_create`, expecting success.
    pub fn create(&self) -> Handle {
        let mut out = null_mut();
        // SAFETY: the desc points into live vectors of the stated lengths.
        assert_ok(unsafe { mlt_scene_create(&self.desc(), &mut out) });
        assert!(!out.is_null());
        Handle(out)
    }
}

/// `mlt_scene_create` of a bad description: the status, the message, and `*out` untouched.
pub fn check_create_refused(
    desc: &MltSceneDesc,
    expected: MltStatus,
    needles: &[impl AsRef<str>],
) -> Check {
    let mut out = sentinel_scene();
    // SAFETY: every pointer in `desc` references an array of its length, or is one mlt must
    // refuse before reading (NULL, misaligned, or with a length no memory holds).
    let status = unsafe { mlt_scene_create(desc, &mut out) };
    if status == MLT_STATUS_OK {
        // SAFETY: a scene mlt created (wrongly), released once.
        unsafe { mlt_scene_release(out) };
    }
    check_error(status, expected, needles)?;
    ensure(out == sentinel_scene(), "*out must be untouched on failure")
}

/// Every case's description (`desc` of its input) is refused as invalid (`check_create_refused`).
#[track_caller]
pub fn assert_create_refuses<T>(table: &str, cases: &[Case<T>], desc: impl Fn(&T) -> MltSceneDesc) {
    assert_cases(table, cases, |input, needles| {
        check_create_refused(&desc(input), MLT_STATUS_INVALID_ARGUMENT, needles)
    });
}

/// Owns a scene, as a C++ host's RAII wrapper would.
pub struct Handle(pub *mut MltScene);

// SAFETY: the header promises that scenes are thread safe for rendering and queries.
unsafe impl Send for Handle {}
unsafe impl Sync for Handle {}

impl Drop for Handle {
    fn drop(&mut self) {
        // SAFETY: created by mlt_scene_create, released once.
        unsafe { mlt_scene_release(self.0) };
    }
}

impl Handle {
    pub fn info(&self) -> MltSceneInfo {
        let mut info = scene_info_default();
        // SAFETY: live scene, writable out.
        assert_ok(unsafe { mlt_scene_get_info(self.0, &mut info) });
        info
    }

    /// Renders into a buffer pre-filled with the sentinel; returns the status and buffer.
    pub fn render(
        &self,
        camera: &MltCamera,
        settings: &MltRenderSettings,
        out_len: usize,
    ) -> (MltStatus, Vec<f32>) {
        let mut image = vec![SENTINEL_F32; out_len];
        // SAFETY: valid pointers; the buffer holds out_len floats.
        let status = unsafe {
            mlt_render(
                self.0,
                camera,
                settings,
                image.as_mut_ptr(),
                out_len,
                None,
                null_mut(),
            )
        };
        (status, image)
    }

    /// A render of 4 × 4 pixels that must succeed: the image and the stats.
    #[track_caller]
    pub fn render_4x4_with_stats(
        &self,
        camera: &MltCamera,
        settings: &MltRenderSettings,
    ) -> (Vec<f32>, MltRenderStats) {
        let mut rgb = vec![0.0f32; 4 * 4 * 3];
        let mut stats = render_stats_default();
        // SAFETY: valid pointers; `rgb` holds the 48 floats passed.
        let status = unsafe {
            mlt_render_ex(
                self.0,
                camera,
                settings,
                rgb.as_mut_ptr(),
                rgb.len(),
                None,
                null_mut(),
                &mut stats,
            )
        };
        assert_eq!(status, MLT_STATUS_OK, "algorithm {}", settings.algorithm);
        (rgb, stats)
    }

    /// A render mlt must refuse as invalid: the needles in the message, and neither the
    /// image nor the stats written.
    pub fn check_render_refused(
        &self,
        camera: &MltCamera,
        settings: &MltRenderSettings,
        needles: &[impl AsRef<str>],
    ) -> Check {
        let len = 16 * 16 * 3;
        let mut image = vec![SENTINEL_F32; len];
        let mut stats = MltRenderStats {
            samples: 77,
            ..render_stats_default()
        };
        // SAFETY: valid pointers; `len` floats.
        let status = unsafe {
            mlt_render_ex(
                self.0,
                camera,
                settings,
                image.as_mut_ptr(),
                len,
                None,
                null_mut(),
                &mut stats,
            )
        };
        check_error(status, MLT_STATUS_INVALID_ARGUMENT, needles)?;
        ensure(
            image.iter().all(|&v| v == SENTINEL_F32),
            "rgb_out must be untouched on failure",
        )?;
        ensure(
            stats.samples == 77,
            "stats_out must be untouched on failure",
        )
    }

    /// Every case's settings, rendered with `camera`, are refused (`check_render_refused`).
    #[track_caller]
    pub fn assert_refuses_settings(
        &self,
        table: &str,
        camera: &MltCamera,
        cases: &[Case<MltRenderSettings>],
    ) {
        assert_cases(table, cases, |settings, needles| {
            self.check_render_refused(camera, settings, needles)
        });
    }

    pub fn intersect(&self, rays: &[MltRay]) -> (MltStatus, Vec<MltHit>) {
        let mut hits = vec![SENTINEL_HIT; rays.len()];
        // SAFETY: both arrays hold rays.len() elements.
        let status = unsafe { mlt_intersect(self.0, rays.as_ptr(), rays.len(), hits.as_mut_ptr()) };
        (status, hits)
    }

    pub fn occluded(&self, rays: &[MltRay]) -> (MltStatus, Vec<u8>) {
        let mut flags = vec![0xAB; rays.len()];
        // SAFETY: both arrays hold rays.len() elements.
        let status = unsafe { mlt_occluded(self.0, rays.as_ptr(), rays.len(), flags.as_mut_ptr()) };
        (status, flags)
    }
}

pub const SENTINEL_HIT: MltHit = MltHit {
    triangle_id: 0xDEAD,
    t: SENTINEL_F32,
    u: SENTINEL_F32,
    v: SENTINEL_F32,
};

pub fn ray(origin: [f32; 3], direction: [f32; 3]) -> MltRay {
    MltRay {
        origin,
        tmin: 0.0,
        direction,
        tmax: f32::INFINITY,
    }
}

/// Camera for the floor-and-light scene: from the front, slightly above the floor.
pub fn floor_camera() -> MltCamera {
    MltCamera {
        eye: [0.0, 1.0, -4.0],
        target: [0.0, 1.0, 0.0],
        up: [0.0, 1.0, 0.0],
        fov_y_deg: 60.0,
        ..default_camera()
    }
}

pub fn assert_valid_image(image: &[f32], what: &str) {
    assert!(
        image.iter().all(|v| v.is_finite() && *v >= 0.0),
        "{what}: every value must be finite and non-negative"
    );
}

/// `mlt_render` with a Rust closure as the progress callback.
pub fn render_with_progress(
    scene: *const MltScene,
    camera: &MltCamera,
    settings: &MltRenderSettings,
    image: &mut [f32],
    on_progress: &mut dyn FnMut(f32) -> bool,
) -> MltStatus {
    unsafe extern "C" fn trampoline(fraction: f32, user_data: *mut std::ffi::c_void) -> bool {
        // SAFETY: `user_data` is the `&mut dyn FnMut` below, alive for the render.
        let callback = unsafe { &mut *user_data.cast::<&mut dyn FnMut(f32) -> bool>() };
        callback(fraction)
    }
    let mut callback = on_progress;
    // SAFETY: valid pointers; `image` holds the floats passed; the callback's user data
    // outlives the call.
    unsafe {
        mlt_render(
            scene,
            camera,
            settings,
            image.as_mut_ptr(),
            image.len(),
            Some(trampoline),
            (&raw mut callback).cast(),
        )
    }
}

/// The backends `mlt_backend_supported` says this build has.
pub fn supported_backends() -> Vec<i32> {
    [MLT_BACKEND_BVH, MLT_BACKEND_EMBREE]
        .into_iter()
        .filter(|&b| mlt_backend_supported(b))
        .collect()
}

/// The size of a layout whose fields end where `first_missing` starts, padded as C pads it.
pub fn earlier_size<T>(first_missing: usize) -> u32 {
    first_missing.next_multiple_of(align_of::<T>()) as u32
}

/// Sizes no header ever had: never initialized, too small, between layouts (2 short of
/// today's: a layout's size is a multiple of the alignment, at least 4, and the last two may
/// be only 4 apart), from the future.
pub fn unknown_sizes<T>() -> [usize; 4] {
    unknown_sizes_of(size_of::<T>())
}

/// [`unknown_sizes`] of a struct of `size` bytes.
pub fn unknown_sizes_of(size: usize) -> [usize; 4] {
    [0, 3, size - 2, size + 8]
}

/// The Cornell box at 8 × 8: every pixel sees a lit surface.
pub fn cornell() -> (Handle, MltCamera) {
    (HostScene::cornell_box().create(), default_camera())
}

pub fn default_environment() -> MltEnvironment {
    let mut e = std::mem::MaybeUninit::<MltEnvironment>::uninit();
    // SAFETY: writable memory for an MltEnvironment.
    assert_ok(unsafe { mlt_environment_init(e.as_mut_ptr(), size_of::<MltEnvironment>()) });
    // SAFETY: initialized on success.
    unsafe { e.assume_init() }
}

pub fn default_sun() -> MltSun {
    let mut s = std::mem::MaybeUninit::<MltSun>::uninit();
    // SAFETY: as above.
    assert_ok(unsafe { mlt_sun_init(s.as_mut_ptr(), size_of::<MltSun>()) });
    unsafe { s.assume_init() }
}

pub fn default_punctual_light() -> MltPunctualLight {
    let mut l = std::mem::MaybeUninit::<MltPunctualLight>::uninit();
    // SAFETY: as above.
    assert_ok(unsafe { mlt_punctual_light_init(l.as_mut_ptr(), size_of::<MltPunctualLight>()) });
    unsafe { l.assume_init() }
}

pub fn default_texture() -> MltTexture {
    let mut t = std::mem::MaybeUninit::<MltTexture>::uninit();
    // SAFETY: writable memory for an MltTexture.
    assert_ok(unsafe { mlt_texture_init(t.as_mut_ptr(), size_of::<MltTexture>()) });
    // SAFETY: initialized on success.
    unsafe { t.assume_init() }
}

/// A texture slot of `texture` with the identity transform.
pub fn slot(texture: i32) -> MltTextureRef {
    MltTextureRef {
        texture,
        ..default_material().base_color_texture
    }
}

/// A C initializer under test (`mlt_*_init`), through a closure that forwards its arguments.
pub type Initializer = fn(*mut u8, usize) -> MltStatus;

/// Each initializer (its default's name, its struct's size, the call): refuses NULL and
/// every size no header had without writing, and writes its own size into `struct_size`.
pub fn assert_initializers_refuse_null_and_unknown_sizes(
    table: &str,
    initializers: &[(&str, usize, Initializer)],
) {
    let mut results = Vec::new();
    for &(name, size, init) in initializers {
        // Holds any size tried (size + 8 < 1024 - 8 for every struct).
        let mut storage = [0xABu8; 1024];
        let aligned = storage
            .as_mut_ptr()
            .wrapping_add(storage.as_ptr().align_offset(8));
        let status = init(null_mut(), size);
        results.push((
            format!("{name}: out NULL"),
            check_error(status, MLT_STATUS_INVALID_ARGUMENT, &["out", "NULL"]),
        ));
        assert!(size + 8 < storage.len() - 8, "{name}: storage too small");
        for bad in unknown_sizes_of(size) {
            let status = init(aligned, bad);
            let needles = ["out.struct_size", &bad.to_string(), name];
            let result = check_error(status, MLT_STATUS_INVALID_ARGUMENT, &needles)
                .and_then(|()| ensure(storage.iter().all(|&b| b == 0xAB), "out written"));
            results.push((format!("{name}: struct_size {bad}"), result));
        }
        let status = init(aligned, size);
        // SAFETY: 4 aligned bytes of `storage`, initialized.
        let written = unsafe { aligned.cast::<u32>().read() };
        let result =
            check_ok(status).and_then(|()| ensure(written as usize == size, "struct_size not set"));
        results.push((format!("{name}: its own size {size}"), result));
    }
    assert_all(table, results);
}
