//! The Intel Embree 3 backend (cargo feature `embree`): one triangle geometry holding the
//! scene's triangles in build order, so the internal triangle index is Embree's `primID` and
//! the mapping to the build order is the identity.
//!
//! Every Embree failure becomes an [`Error`]: a device error callback records the first error
//! and its message (from whatever thread Embree reports it on), and each step of the build
//! polls it. Queries report nothing: with valid rays on a committed scene Embree has nothing
//! to complain about.
//!
//! Semantics match the BVH backend (see [`super::Accel`]) up to one end of the interval:
//! `tmin` and `tmax` go to `tnear` and `tfar` as they are, and Embree accepts t in
//! (tnear, tfar] where the BVH accepts [tmin, tmax], so the two differ only for a hit at
//! exactly t = tmin. Embree's `u`, `v` are the barycentrics of vertices 1 and 2, the
//! convention of [`Hit`].
//!
//! Filtered queries (alpha cut-outs) use Embree's per-query context filter: the query's
//! intersection context is extended with a reference to the `accept` closure, and the filter
//! callback Embree calls for each candidate hit clears the candidates it rejects. A scene only
//! runs context filters when built with `RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION`, which
//! switches the whole scene to Embree's filter-capable kernels (slower for unfiltered queries
//! too), so only scenes built with [`Filtering::Filtered`] set it. Unfiltered queries pass no
//! filter and never call back into Rust. (Geometry filter functions would instead be called
//! for every query on a scene that has them, the unfiltered ones included.)

#[doc(hidden)]
pub mod ffi;
// Embree's own binary tree, for the traversal bench's diagnostic of tree against traversal.
#[cfg(any(test, feature = "internals"))]
pub(crate) mod tree;

use super::ray::{Hit, Ray};
use super::{BuildQuality, Filtering};
use crate::error::{
    Error, MLT_STATUS_INTERNAL_ERROR, MLT_STATUS_OUT_OF_MEMORY, MLT_STATUS_UNSUPPORTED, MltStatus,
    Result,
};
use ffi::*;
use glam::{Vec3A, Vec4};
use std::any::Any;
use std::cell::Cell;
use std::ffi::{CStr, c_char, c_void};
use std::panic::{AssertUnwindSafe, catch_unwind, resume_unwind};
use std::sync::atomic::{AtomicIsize, Ordering};
use std::sync::{Mutex, PoisonError};

/// Embree's build quality for ours. High (spatial splits) traces camera rays about 20% faster
/// than medium on a 130k-triangle mesh, for twice the build time.
fn embree_build_quality(quality: BuildQuality) -> RTCBuildQuality {
    match quality {
        BuildQuality::Fast => RTC_BUILD_QUALITY_LOW,
        BuildQuality::Medium => RTC_BUILD_QUALITY_MEDIUM,
        BuildQuality::High => RTC_BUILD_QUALITY_HIGH,
    }
}
/// No `RTC_SCENE_FLAG_ROBUST`: it would make edges watertight and tnear inclusive (exactly
/// the BVH's interval), but costs 15-30% of the ray rate on a 130k-triangle mesh (where the
/// high build quality then gains nothing over medium). Neither backend is watertight without it: a ray through the
/// exact edge shared by two triangles may pass between them, in either backend.
const SCENE_FLAGS: RTCSceneFlags = RTC_SCENE_FLAG_NONE;

/// The first error Embree reported since it was last taken.
#[derive(Default)]
struct ErrorLog(Mutex<Option<(RTCError, String)>>);

impl ErrorLog {
    fn take(&self) -> Option<(RTCError, String)> {
        self.0.lock().unwrap_or_else(PoisonError::into_inner).take()
    }
}

/// The device's error callback. Embree may call it from any thread, hence the mutex. It never
/// panics (a panic cannot unwind out of an `extern "C"` function).
unsafe extern "C" fn record_error(user_ptr: *mut c_void, code: RTCError, message: *const c_char) {
    // SAFETY: `user_ptr` is the `ErrorLog` registered in `Device::new`, which lives until
    // after `rtcReleaseDevice` (see `Device`).
    let log = unsafe { &*user_ptr.cast::<ErrorLog>() };
    let text = if message.is_null() {
        String::new()
    } else {
        // SAFETY: Embree passes a NUL-terminated string valid for the call.
        unsafe { CStr::from_ptr(message) }
            .to_string_lossy()
            .into_owned()
    };
    log.0
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .get_or_insert((code, text));
}

/// The device's memory monitor: keeps the balance of the bytes Embree allocates and frees
/// (scene structures and geometry buffers), and allows every allocation.
unsafe extern "C" fn count_memory(user_ptr: *mut c_void, bytes: isize, _post: bool) -> bool {
    // SAFETY: `user_ptr` is the counter registered in `Device::new`, which lives until after
    // `rtcReleaseDevice` (see `Device`).
    let allocated = unsafe { &*user_ptr.cast::<AtomicIsize>() };
    allocated.fetch_add(bytes, Ordering::Relaxed);
    true
}

fn error_name(code: RTCError) -> &'static str {
    match code {
        RTC_ERROR_NONE => "no error code",
        RTC_ERROR_UNKNOWN => "unknown error",
        RTC_ERROR_INVALID_ARGUMENT => "invalid argument",
        RTC_ERROR_INVALID_OPERATION => "invalid operation",
        RTC_ERROR_OUT_OF_MEMORY => "out of memory",
        RTC_ERROR_UNSUPPORTED_CPU => "unsupported CPU",
        RTC_ERROR_CANCELLED => "cancelled",
        _ => "unrecognized error code",
    }
}

fn status_of(code: RTCError) -> MltStatus {
    match code {
        RTC_ERROR_OUT_OF_MEMORY => MLT_STATUS_OUT_OF_MEMORY,
        RTC_ERROR_UNSUPPORTED_CPU => MLT_STATUS_UNSUPPORTED,
        // We validate everything we pass, so anything else is a bug on our side.
        _ => MLT_STATUS_INTERNAL_ERROR,
    }
}

/// "Embree: CALL failed: CODE NAME: DETAIL".
fn embree_error(call: &str, code: RTCError, detail: &str) -> Error {
    let mut message = format!("Embree: {call} failed: {} ({code})", error_name(code));
    if !detail.is_empty() {
        message.push_str(": ");
        message.push_str(detail);
    }
    Error::new(status_of(code), message)
}

/// An Embree device, the log its error callback writes to and the balance its memory
/// monitor keeps.
struct Device {
    raw: RTCDevice,
    /// Boxed so its address, registered with the device, stays put. Dropped after the
    /// device is released (fields drop after `Drop::drop`).
    errors: Box<ErrorLog>,
    /// Bytes Embree holds for this device; boxed and dropped like `errors`.
    allocated: Box<AtomicIsize>,
}

impl Device {
    fn new() -> Result<Device> {
        // SAFETY: a NULL configuration string selects Embree's defaults.
        let raw = unsafe { rtcNewDevice(std::ptr::null()) };
        if raw.is_null() {
            // SAFETY: with NULL, Embree returns this thread's error from the failed creation.
            let code = unsafe { rtcGetDeviceError(std::ptr::null_mut()) };
            return Err(embree_error("rtcNewDevice", code, "no device was created"));
        }
        let device = Device {
            raw,
            errors: Box::default(),
            allocated: Box::default(),
        };
        let log: *const ErrorLog = &*device.errors;
        let allocated: *const AtomicIsize = &*device.allocated;
        // SAFETY: a live device; the log and the counter outlive it (see the fields'
        // comments) and the callbacks only use them through shared references.
        unsafe {
            rtcSetDeviceErrorFunction(raw, Some(record_error), log.cast_mut().cast());
            rtcSetDeviceMemoryMonitorFunction(raw, Some(count_memory), allocated.cast_mut().cast());
        }
        device.check("rtcNewDevice")?;
        Ok(device)
    }

    /// The first error reported (by the callback or to this thread) since the last check.
    fn check(&self, call: &str) -> Result<()> {
        // SAFETY: a live device; reading its error code for this thread clears it.
        let polled = unsafe { rtcGetDeviceError(self.raw) };
        match (self.errors.take(), polled) {
            (Some((code, message)), _) => Err(embree_error(call, code, &message)),
            (None, RTC_ERROR_NONE) => Ok(()),
            (None, code) => Err(embree_error(call, code, "")),
        }
    }

    /// `check`, and an error also when `handle` is NULL without a reported error.
    fn check_handle<T>(&self, call: &str, handle: *mut T) -> Result<()> {
        self.check(call)?;
        if handle.is_null() {
            return Err(embree_error(call, RTC_ERROR_UNKNOWN, "it returned NULL"));
        }
        Ok(())
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        // SAFETY: created by rtcNewDevice and released once, here.
        unsafe { rtcReleaseDevice(self.raw) };
    }
}

/// A triangle geometry, released on drop (an attached scene keeps its own reference).
struct Geometry(RTCGeometry);

impl Geometry {
    fn triangles(device: &Device) -> Result<Geometry> {
        // SAFETY: a live device.
        let raw = unsafe { rtcNewGeometry(device.raw, RTC_GEOMETRY_TYPE_TRIANGLE) };
        let geometry = Geometry(raw);
        device.check_handle("rtcNewGeometry", raw)?;
        Ok(geometry)
    }

    /// A new buffer of `count` items of `T` (12-byte `FLOAT3` or `UINT3` items) in slot 0,
    /// for us to fill before the geometry is committed.
    fn new_buffer<T: Copy>(
        &mut self,
        device: &Device,
        kind: RTCBufferType,
        format: RTCFormat,
        count: usize,
    ) -> Result<&mut [T]> {
        debug_assert_eq!(std::mem::size_of::<T>(), 12);
        debug_assert!(std::mem::align_of::<T>() <= 4);
        // SAFETY: a live geometry; Embree checks the sizes and reports what it rejects.
        let data = unsafe {
            rtcSetNewGeometryBuffer(self.0, kind, 0, format, std::mem::size_of::<T>(), count)
        };
        device.check_handle("rtcSetNewGeometryBuffer", data)?;
        // SAFETY: Embree allocated `count` items of the stride (16-byte aligned), owned by the
        // geometry, which `&mut self` borrows for the slice's lifetime; nothing else accesses
        // the buffer until the geometry is committed. Any bit pattern is a valid f32 or u32.
        Ok(unsafe { std::slice::from_raw_parts_mut(data.cast::<T>(), count) })
    }
}

impl Drop for Geometry {
    fn drop(&mut self) {
        if !self.0.is_null() {
            // SAFETY: created by rtcNewGeometry; this reference is released once, here.
            unsafe { rtcReleaseGeometry(self.0) };
        }
    }
}

pub struct EmbreeAccel {
    /// Committed in `build`; NULL only while a failed build unwinds.
    scene: RTCScene,
    /// Released after the scene: fields drop after `Drop::drop`.
    device: Device,
    /// The identity: Embree's primID is the build order.
    build_order: Vec<u32>,
    /// Whether the scene runs context filters (`Filtering::Filtered`).
    filterable: bool,
}

// SAFETY: after `rtcCommitScene` the scene is never modified, and Embree documents committed
// scenes as safe to traverse (rtcIntersect1 / rtcOccluded1) from any number of threads at
// once. The device's only state we touch afterwards is the error log, behind a mutex. Handles
// may be released from any thread; `Drop` has exclusive access.
unsafe impl Send for EmbreeAccel {}
// SAFETY: as for Send: `&self` methods only traverse the committed scene.
unsafe impl Sync for EmbreeAccel {}

impl EmbreeAccel {
    /// Builds at `quality` over triangles given as vertex triples (a triangle soup: three
    /// vertices per triangle, 32-bit indices). None of them may be degenerate. Filtered
    /// queries need `Filtering::Filtered`.
    pub fn build(
        triangles: &[[Vec3A; 3]],
        quality: BuildQuality,
        filtering: Filtering,
    ) -> Result<Self> {
        let count = triangles.len();
        let vertex_count = count.checked_mul(3).filter(|&n| n <= 1 << 32);
        let Some(vertex_count) = vertex_count else {
            return Err(Error::new(
                MLT_STATUS_UNSUPPORTED,
                format!(
                    "the Embree backend holds at most {} triangles (3 vertices each, 32-bit indices), but the scene has {count}; use the BVH backend",
                    (1u64 << 32) / 3
                ),
            ));
        };
        let device = Device::new()?;
        // SAFETY: a live device.
        let scene = unsafe { rtcNewScene(device.raw) };
        let accel = EmbreeAccel {
            scene,
            device,
            build_order: (0..count as u32).collect(),
            filterable: filtering == Filtering::Filtered,
        };
        let flags = match filtering {
            Filtering::Unfiltered => SCENE_FLAGS,
            Filtering::Filtered => SCENE_FLAGS | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION,
        };
        let device = &accel.device;
        device.check_handle("rtcNewScene", scene)?;
        // SAFETY: a live, uncommitted scene; valid enum values.
        unsafe {
            rtcSetSceneBuildQuality(scene, embree_build_quality(quality));
            rtcSetSceneFlags(scene, flags);
        }
        device.check("rtcSetSceneBuildQuality")?;
        if count > 0 {
            let mut geometry = Geometry::triangles(device)?;
            let vertices = geometry.new_buffer::<[f32; 3]>(
                device,
                RTC_BUFFER_TYPE_VERTEX,
                RTC_FORMAT_FLOAT3,
                vertex_count,
            )?;
            for (out, triangle) in vertices.chunks_exact_mut(3).zip(triangles) {
                for (o, v) in out.iter_mut().zip(triangle) {
                    *o = v.to_array();
                }
            }
            let indices = geometry.new_buffer::<[u32; 3]>(
                device,
                RTC_BUFFER_TYPE_INDEX,
                RTC_FORMAT_UINT3,
                count,
            )?;
            for (i, out) in indices.iter_mut().enumerate() {
                let first = 3 * i as u32;
                *out = [first, first + 1, first + 2];
            }
            // SAFETY: a live geometry with both buffers filled.
            unsafe { rtcCommitGeometry(geometry.0) };
            device.check("rtcCommitGeometry")?;
            // SAFETY: live scene and committed geometry of the same device.
            let id = unsafe { rtcAttachGeometry(scene, geometry.0) };
            device.check("rtcAttachGeometry")?;
            if id != 0 {
                return Err(embree_error(
                    "rtcAttachGeometry",
                    RTC_ERROR_UNKNOWN,
                    &format!("the only geometry got id {id}, not 0"),
                ));
            }
        }
        // SAFETY: a live scene whose geometry is committed.
        unsafe { rtcCommitScene(scene) };
        device.check("rtcCommitScene")?;
        Ok(accel)
    }

    pub fn internal_to_build_order(&self) -> &[u32] {
        &self.build_order
    }

    /// The bytes Embree holds for this scene (its BVH and the geometry's vertex and index
    /// buffers, as its memory monitor counts them) plus our build-order array.
    pub fn memory_bytes(&self) -> usize {
        let embree = self.device.allocated.load(Ordering::Relaxed).max(0) as usize;
        embree + std::mem::size_of_val(self.build_order.as_slice())
    }

    /// The committed scene, for calling Embree directly (the traversal benchmark's baseline).
    #[cfg(any(test, feature = "internals"))]
    pub fn raw_scene(&self) -> RTCScene {
        self.scene
    }

    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let mut context = RTCIntersectContext::new();
        let mut rayhit = rtc_rayhit(ray);
        // SAFETY: a committed scene (see `build`), alive as long as `self`; `context` and
        // `rayhit` are initialized, correctly aligned locals that Embree writes only during
        // the call.
        unsafe { rtcIntersect1(self.scene, &mut context, &mut rayhit) };
        hit_of(&rayhit)
    }

    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        let mut context = RTCIntersectContext::new();
        let mut ray = rtc_ray(ray);
        // SAFETY: as in `intersect`.
        unsafe { rtcOccluded1(self.scene, &mut context, &mut ray) };
        // A blocked ray comes back with tfar = -inf.
        ray.tfar == f32::NEG_INFINITY
    }

    /// The closest hit that `accept(triangle, u, v)` keeps. Panics if the scene was built
    /// without `Filtering::Filtered` (Embree would ignore the filter), or if `accept` panics.
    #[inline]
    pub fn intersect_filtered<F: Fn(u32, f32, f32) -> bool>(
        &self,
        ray: &Ray,
        accept: &F,
    ) -> Option<Hit> {
        assert!(self.filterable, "{NOT_FILTERABLE}");
        let mut context = FilterContext::new(accept);
        let mut rayhit = rtc_rayhit(ray);
        // SAFETY: as in `intersect`; `context` starts with the `RTCIntersectContext` that
        // `filter_hits::<F>` expects to find a `FilterContext<F>` around, and Embree passes
        // this pointer to it unchanged. It is derived from the whole local, which outlives
        // the call.
        unsafe {
            rtcIntersect1(
                self.scene,
                (&raw mut context).cast::<RTCIntersectContext>(),
                &mut rayhit,
            )
        };
        context.resume_panic();
        hit_of(&rayhit)
    }

    /// Whether a hit that `accept(triangle, u, v)` keeps lies on the ray; panics as
    /// `intersect_filtered`.
    #[inline]
    pub fn occluded_filtered<F: Fn(u32, f32, f32) -> bool>(&self, ray: &Ray, accept: &F) -> bool {
        assert!(self.filterable, "{NOT_FILTERABLE}");
        let mut context = FilterContext::new(accept);
        let mut ray = rtc_ray(ray);
        // SAFETY: as in `intersect_filtered`.
        unsafe {
            rtcOccluded1(
                self.scene,
                (&raw mut context).cast::<RTCIntersectContext>(),
                &mut ray,
            )
        };
        context.resume_panic();
        ray.tfar == f32::NEG_INFINITY
    }
}

const NOT_FILTERABLE: &str =
    "a filtered query on an Embree scene built without Filtering::Filtered";

/// An intersection context extended with what the filter callback needs: Embree passes the
/// context pointer of the query to the callback as it was given.
#[repr(C)]
struct FilterContext<'a, F> {
    /// First, so a pointer to the whole is a pointer to it (`repr(C)`).
    context: RTCIntersectContext,
    accept: &'a F,
    /// What `accept` panicked with: caught in the callback, since a panic must not unwind
    /// through Embree's C++ frames, and resumed once the query has returned.
    panic: Cell<Option<Box<dyn Any + Send>>>,
}

impl<'a, F: Fn(u32, f32, f32) -> bool> FilterContext<'a, F> {
    fn new(accept: &'a F) -> Self {
        let mut context = RTCIntersectContext::new();
        context.filter = Some(filter_hits::<F>);
        FilterContext {
            context,
            accept,
            panic: Cell::new(None),
        }
    }

    /// Goes on with the panic of `accept`, if it panicked during the query.
    fn resume_panic(self) {
        if let Some(payload) = self.panic.into_inner() {
            resume_unwind(payload);
        }
    }
}

/// The context filter of filtered queries: clears `valid[i]` of the candidate hits that the
/// query's `accept` rejects. Never unwinds: a panic of `accept` is stored in the context (the
/// candidates after it are kept, so the query ends soon) and resumed by the caller.
unsafe extern "C" fn filter_hits<F: Fn(u32, f32, f32) -> bool>(
    args: *const RTCFilterFunctionNArguments,
) {
    // SAFETY: Embree passes valid arguments for the duration of the call.
    let args = unsafe { &*args };
    // SAFETY: this function is only installed by `FilterContext::<F>::new`, in the context
    // at the start of a `FilterContext<F>` that the querying thread keeps alive (and only
    // reads through shared references) during the query.
    let context = unsafe { &*args.context.cast_const().cast::<FilterContext<F>>() };
    let rays = args.N as usize;
    // `RTCHitN` holds each field as an array of N: Ng_x, Ng_y, Ng_z, u, v, primID, ... (the
    // header's `RTCHitN_u`, `RTCHitN_v`, `RTCHitN_primID`).
    let hit_floats = args.hit.cast::<f32>().cast_const();
    let hit_ids = args.hit.cast::<u32>().cast_const();
    for i in 0..rays {
        // SAFETY: `valid` and each field of `hit` have N entries.
        let (valid, u, v, primitive) = unsafe {
            (
                &mut *args.valid.add(i),
                *hit_floats.add(3 * rays + i),
                *hit_floats.add(4 * rays + i),
                *hit_ids.add(5 * rays + i),
            )
        };
        if *valid == 0 {
            continue;
        }
        let earlier_panic = context.panic.take();
        if earlier_panic.is_some() {
            context.panic.set(earlier_panic);
            continue;
        }
        // The internal triangle index is the primID, as in `intersect`.
        match catch_unwind(AssertUnwindSafe(|| (context.accept)(primitive, u, v))) {
            Ok(true) => {}
            Ok(false) => *valid = 0,
            Err(payload) => context.panic.set(Some(payload)),
        }
    }
}

/// The hit Embree wrote into `rayhit`, if any (its primID is the internal triangle index).
#[inline]
fn hit_of(rayhit: &RTCRayHit) -> Option<Hit> {
    (rayhit.hit.geomID != RTC_INVALID_GEOMETRY_ID).then_some(Hit {
        triangle: rayhit.hit.primID,
        t: rayhit.ray.tfar,
        u: rayhit.hit.u,
        v: rayhit.hit.v,
    })
}

/// Our ray as Embree's: every mask bit set (Debian's Embree is built with ray masks, and a
/// zero mask would hit nothing), time 0.
///
/// Written as three 16-byte vectors (origin and tnear, direction and time, tfar with mask, id
/// and flags), the way Embree reads it: a 16-byte load that spans several narrower stores
/// cannot be forwarded from them and waits for them to reach the cache. Built field by field,
/// that stall cost 10-20% of Embree's ray rate (`benches/traversal.rs`, mlt embree against
/// raw embree).
#[inline]
#[doc(hidden)]
pub fn rtc_ray(ray: &Ray) -> RTCRay {
    let rows = [
        ray.origin.extend(ray.tmin),
        ray.direction.extend(0.0),
        Vec4::new(ray.tmax, f32::from_bits(u32::MAX), 0.0, 0.0),
    ];
    // SAFETY: `RTCRay` is 12 four-byte fields in this order, 48 bytes (checked against the
    // header by tests/embree_layout.rs), and every bit pattern is valid for each: mask =
    // u32::MAX, id = flags = 0.
    unsafe { std::mem::transmute::<[Vec4; 3], RTCRay>(rows) }
}

/// Our ray as Embree's closest-hit query: the ray of [`rtc_ray`] and no hit yet.
#[inline]
#[doc(hidden)]
pub fn rtc_rayhit(ray: &Ray) -> RTCRayHit {
    RTCRayHit {
        ray: rtc_ray(ray),
        hit: RTCHit {
            primID: RTC_INVALID_GEOMETRY_ID,
            geomID: RTC_INVALID_GEOMETRY_ID,
            instID: [RTC_INVALID_GEOMETRY_ID; RTC_MAX_INSTANCE_LEVEL_COUNT],
            ..RTCHit::default()
        },
    }
}

impl Drop for EmbreeAccel {
    fn drop(&mut self) {
        if !self.scene.is_null() {
            // SAFETY: created by rtcNewScene and released once, here, before the device
            // (`self.device` drops after this).
            unsafe { rtcReleaseScene(self.scene) };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_scene_misses() {
        let accel =
            EmbreeAccel::build(&[], BuildQuality::default(), Filtering::Unfiltered).unwrap();
        let ray = Ray::new(Vec3A::ZERO, Vec3A::Z, 0.0, f32::INFINITY);
        assert_eq!(accel.intersect(&ray), None);
        assert!(!accel.occluded(&ray));
        assert!(accel.internal_to_build_order().is_empty());
    }

    fn facing_triangle() -> [Vec3A; 3] {
        [
            Vec3A::new(-1.0, -1.0, 1.0),
            Vec3A::new(1.0, -1.0, 1.0),
            Vec3A::new(0.0, 1.0, 1.0),
        ]
    }

    /// A panic of the filter closure does not unwind through Embree: it is caught in the
    /// callback and resumed once the query has returned, and the scene still works after.
    #[test]
    fn filter_panics_reach_the_caller() {
        let accel = EmbreeAccel::build(
            &[facing_triangle()],
            BuildQuality::default(),
            Filtering::Filtered,
        )
        .unwrap();
        let ray = Ray::new(Vec3A::ZERO, Vec3A::Z, 0.0, f32::INFINITY);
        let panicking = |_, _, _| -> bool { panic!("the filter panicked") };
        for occlusion in [false, true] {
            let payload = std::panic::catch_unwind(|| {
                if occlusion {
                    accel.occluded_filtered(&ray, &panicking);
                } else {
                    accel.intersect_filtered(&ray, &panicking);
                }
            })
            .unwrap_err();
            assert_eq!(
                payload.downcast_ref::<&str>(),
                Some(&"the filter panicked"),
                "occlusion {occlusion}"
            );
        }
        assert!(accel.intersect_filtered(&ray, &|_, _, _| true).is_some());
        assert!(accel.occluded_filtered(&ray, &|_, _, _| true));
    }

    /// Embree ignores the context filter in a scene built without its flag: a filtered query
    /// there would silently be unfiltered, so it panics instead.
    #[test]
    #[should_panic(expected = "built without Filtering::Filtered")]
    fn filtered_query_needs_a_filterable_scene() {
        let accel = EmbreeAccel::build(
            &[facing_triangle()],
            BuildQuality::default(),
            Filtering::Unfiltered,
        )
        .unwrap();
        let ray = Ray::new(Vec3A::ZERO, Vec3A::Z, 0.0, f32::INFINITY);
        accel.intersect_filtered(&ray, &|_, _, _| false);
    }

    /// The memory monitor counts what a build allocates: at least the vertex and index
    /// buffers (48 bytes a triangle).
    #[test]
    fn memory_monitor_counts_the_build() {
        let triangles: Vec<[Vec3A; 3]> = (0..1000)
            .map(|i| {
                let x = i as f32;
                [
                    Vec3A::new(x, 0.0, 0.0),
                    Vec3A::new(x + 1.0, 0.0, 0.0),
                    Vec3A::new(x, 1.0, 0.0),
                ]
            })
            .collect();
        let accel =
            EmbreeAccel::build(&triangles, BuildQuality::default(), Filtering::Unfiltered).unwrap();
        let bytes = accel.memory_bytes();
        assert!(bytes >= 1000 * 48, "{bytes}");
        assert!(bytes < 100 << 20, "{bytes}");
    }

    /// An error Embree reports becomes an `Error` naming the call, the code and Embree's
    /// message, and the log is empty again afterwards.
    #[test]
    fn embree_errors_become_errors() {
        let device = Device::new().unwrap();
        let mut geometry = Geometry::triangles(&device).unwrap();
        let error = geometry
            .new_buffer::<[f32; 3]>(&device, RTC_BUFFER_TYPE_VERTEX, RTC_FORMAT_FLOAT3, 1 << 60)
            .unwrap_err();
        assert_eq!(error.status, MLT_STATUS_INTERNAL_ERROR);
        assert!(
            error
                .message
                .starts_with("Embree: rtcSetNewGeometryBuffer failed: invalid argument (2): "),
            "{}",
            error.message
        );
        assert!(error.message.len() > 60, "Embree's own text: {error:?}");
        device.check("nothing").unwrap();
        let error = embree_error("rtcCommitScene", RTC_ERROR_OUT_OF_MEMORY, "");
        assert_eq!(error.status, MLT_STATUS_OUT_OF_MEMORY);
        assert_eq!(
            error.message,
            "Embree: rtcCommitScene failed: out of memory (4)"
        );
        assert_eq!(
            embree_error("rtcNewDevice", RTC_ERROR_UNSUPPORTED_CPU, "").status,
            MLT_STATUS_UNSUPPORTED
        );
    }
}
