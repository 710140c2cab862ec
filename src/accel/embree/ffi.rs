//! The part of the Embree 3 C API (`embree3/rtcore.h`, 3.13) that the backend uses, declared
//! by hand. Layouts and constants are checked against the installed header by
//! `tests/embree_layout.rs`.
//!
//! Enums that come back from Embree (`RTCError`) are plain integers: an unexpected value in a
//! Rust enum would be undefined behaviour. Debian's build has `RTC_MAX_INSTANCE_LEVEL_COUNT`
//! 1 and `RTC_MIN_WIDTH` 0, which shape `RTCHit` and `RTCIntersectContext`; the layout test
//! fails if the installed header differs.

#![allow(non_camel_case_types, non_snake_case)]
#![cfg_attr(
    not(any(test, feature = "internals")),
    expect(
        dead_code,
        reason = "the builder API and some flags serve only the traversal bench and the layout test"
    )
)]

use std::ffi::{c_char, c_int, c_uint, c_void};

/// Opaque handles.
#[repr(C)]
pub struct RTCDeviceTy {
    _private: [u8; 0],
}
#[repr(C)]
pub struct RTCSceneTy {
    _private: [u8; 0],
}
#[repr(C)]
pub struct RTCGeometryTy {
    _private: [u8; 0],
}
pub type RTCDevice = *mut RTCDeviceTy;
pub type RTCScene = *mut RTCSceneTy;
pub type RTCGeometry = *mut RTCGeometryTy;

/// `enum RTCError`.
pub type RTCError = c_int;
pub const RTC_ERROR_NONE: RTCError = 0;
pub const RTC_ERROR_UNKNOWN: RTCError = 1;
pub const RTC_ERROR_INVALID_ARGUMENT: RTCError = 2;
pub const RTC_ERROR_INVALID_OPERATION: RTCError = 3;
pub const RTC_ERROR_OUT_OF_MEMORY: RTCError = 4;
pub const RTC_ERROR_UNSUPPORTED_CPU: RTCError = 5;
pub const RTC_ERROR_CANCELLED: RTCError = 6;

/// `enum RTCBuildQuality`.
pub type RTCBuildQuality = c_int;
pub const RTC_BUILD_QUALITY_LOW: RTCBuildQuality = 0;
pub const RTC_BUILD_QUALITY_MEDIUM: RTCBuildQuality = 1;
pub const RTC_BUILD_QUALITY_HIGH: RTCBuildQuality = 2;

/// `enum RTCSceneFlags`.
pub type RTCSceneFlags = c_int;
pub const RTC_SCENE_FLAG_NONE: RTCSceneFlags = 0;
pub const RTC_SCENE_FLAG_ROBUST: RTCSceneFlags = 1 << 2;
pub const RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION: RTCSceneFlags = 1 << 3;

/// `enum RTCGeometryType`.
pub type RTCGeometryType = c_int;
pub const RTC_GEOMETRY_TYPE_TRIANGLE: RTCGeometryType = 0;

/// `enum RTCBufferType`.
pub type RTCBufferType = c_int;
pub const RTC_BUFFER_TYPE_INDEX: RTCBufferType = 0;
pub const RTC_BUFFER_TYPE_VERTEX: RTCBufferType = 1;

/// `enum RTCFormat`.
pub type RTCFormat = c_int;
pub const RTC_FORMAT_UINT3: RTCFormat = 0x5003;
pub const RTC_FORMAT_FLOAT3: RTCFormat = 0x9003;

/// `enum RTCIntersectContextFlags`.
pub type RTCIntersectContextFlags = c_int;
pub const RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT: RTCIntersectContextFlags = 0;

/// `RTC_INVALID_GEOMETRY_ID`: `hit.geomID` of a miss.
pub const RTC_INVALID_GEOMETRY_ID: c_uint = c_uint::MAX;

/// `RTC_MAX_INSTANCE_LEVEL_COUNT` of the Debian build.
pub const RTC_MAX_INSTANCE_LEVEL_COUNT: usize = 1;

/// `RTCErrorFunction`.
pub type RTCErrorFunction =
    Option<unsafe extern "C" fn(user_ptr: *mut c_void, code: RTCError, message: *const c_char)>;

/// `RTCMemoryMonitorFunction`: called with the bytes Embree is about to allocate (positive,
/// `post` false) or has freed (negative, `post` true); returning false fails the allocation.
pub type RTCMemoryMonitorFunction =
    Option<unsafe extern "C" fn(user_ptr: *mut c_void, bytes: isize, post: bool) -> bool>;

/// `RTCFilterFunctionN`: called with candidate hits, it clears `valid[i]` of those it
/// rejects.
pub type RTCFilterFunctionN =
    Option<unsafe extern "C" fn(args: *const RTCFilterFunctionNArguments)>;

/// `struct RTCFilterFunctionNArguments`: `N` rays and their candidate hits in
/// structure-of-arrays layout (`RTCRayN`, `RTCHitN`: each field an array of `N`), and
/// `valid[i]`, -1 for a ray that has a candidate, 0 for one that has none or was rejected.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RTCFilterFunctionNArguments {
    pub valid: *mut c_int,
    pub geometryUserPtr: *mut c_void,
    pub context: *mut RTCIntersectContext,
    pub ray: *mut c_void,
    pub hit: *mut c_void,
    pub N: c_uint,
}

/// `struct RTCRay`: a single ray.
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default)]
pub struct RTCRay {
    pub org_x: f32,
    pub org_y: f32,
    pub org_z: f32,
    pub tnear: f32,
    pub dir_x: f32,
    pub dir_y: f32,
    pub dir_z: f32,
    pub time: f32,
    pub tfar: f32,
    pub mask: c_uint,
    pub id: c_uint,
    pub flags: c_uint,
}

/// `struct RTCHit`: the hit of a single ray.
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default)]
pub struct RTCHit {
    pub Ng_x: f32,
    pub Ng_y: f32,
    pub Ng_z: f32,
    pub u: f32,
    pub v: f32,
    pub primID: c_uint,
    pub geomID: c_uint,
    pub instID: [c_uint; RTC_MAX_INSTANCE_LEVEL_COUNT],
}

/// `struct RTCRayHit`: ray and hit, as `rtcIntersect1` takes them.
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default)]
pub struct RTCRayHit {
    pub ray: RTCRay,
    pub hit: RTCHit,
}

/// `struct RTCIntersectContext` (with `RTC_MAX_INSTANCE_LEVEL_COUNT` 1 and `RTC_MIN_WIDTH` 0:
/// no `instStackSize`, no `minWidthDistanceFactor`).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RTCIntersectContext {
    pub flags: RTCIntersectContextFlags,
    pub filter: RTCFilterFunctionN,
    pub instID: [c_uint; RTC_MAX_INSTANCE_LEVEL_COUNT],
}

impl RTCIntersectContext {
    /// What the header's inline `rtcInitIntersectContext` does: incoherent rays, no filter,
    /// an empty instance stack.
    pub fn new() -> Self {
        RTCIntersectContext {
            flags: RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT,
            filter: None,
            instID: [RTC_INVALID_GEOMETRY_ID; RTC_MAX_INSTANCE_LEVEL_COUNT],
        }
    }
}

impl Default for RTCIntersectContext {
    fn default() -> Self {
        Self::new()
    }
}

// Linked by build.rs (`cargo:rustc-link-lib=embree3`).
unsafe extern "C" {
    pub fn rtcNewDevice(config: *const c_char) -> RTCDevice;
    pub fn rtcReleaseDevice(device: RTCDevice);
    pub fn rtcGetDeviceError(device: RTCDevice) -> RTCError;
    pub fn rtcSetDeviceErrorFunction(
        device: RTCDevice,
        error: RTCErrorFunction,
        user_ptr: *mut c_void,
    );
    pub fn rtcSetDeviceMemoryMonitorFunction(
        device: RTCDevice,
        monitor: RTCMemoryMonitorFunction,
        user_ptr: *mut c_void,
    );

    pub fn rtcNewScene(device: RTCDevice) -> RTCScene;
    pub fn rtcSetSceneBuildQuality(scene: RTCScene, quality: RTCBuildQuality);
    pub fn rtcSetSceneFlags(scene: RTCScene, flags: RTCSceneFlags);
    pub fn rtcAttachGeometry(scene: RTCScene, geometry: RTCGeometry) -> c_uint;
    pub fn rtcCommitScene(scene: RTCScene);
    pub fn rtcReleaseScene(scene: RTCScene);

    pub fn rtcNewGeometry(device: RTCDevice, kind: RTCGeometryType) -> RTCGeometry;
    pub fn rtcSetNewGeometryBuffer(
        geometry: RTCGeometry,
        kind: RTCBufferType,
        slot: c_uint,
        format: RTCFormat,
        byte_stride: usize,
        item_count: usize,
    ) -> *mut c_void;
    pub fn rtcCommitGeometry(geometry: RTCGeometry);
    pub fn rtcReleaseGeometry(geometry: RTCGeometry);

    pub fn rtcIntersect1(
        scene: RTCScene,
        context: *mut RTCIntersectContext,
        rayhit: *mut RTCRayHit,
    );
    pub fn rtcOccluded1(scene: RTCScene, context: *mut RTCIntersectContext, ray: *mut RTCRay);
}

/// `struct RTCBuildPrimitive` (`rtcore_builder.h`).
#[repr(C, align(32))]
#[derive(Clone, Copy, Debug, Default)]
pub struct RTCBuildPrimitive {
    pub lower_x: f32,
    pub lower_y: f32,
    pub lower_z: f32,
    pub geomID: c_uint,
    pub upper_x: f32,
    pub upper_y: f32,
    pub upper_z: f32,
    pub primID: c_uint,
}

/// `struct RTCBounds` (`rtcore_common.h`).
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default)]
pub struct RTCBounds {
    pub lower_x: f32,
    pub lower_y: f32,
    pub lower_z: f32,
    pub align0: f32,
    pub upper_x: f32,
    pub upper_y: f32,
    pub upper_z: f32,
    pub align1: f32,
}

pub type RTCThreadLocalAllocator = *mut c_void;
pub type RTCCreateNodeFunction = Option<
    unsafe extern "C" fn(
        allocator: RTCThreadLocalAllocator,
        child_count: c_uint,
        user_ptr: *mut c_void,
    ) -> *mut c_void,
>;
pub type RTCSetNodeChildrenFunction = Option<
    unsafe extern "C" fn(
        node: *mut c_void,
        children: *mut *mut c_void,
        child_count: c_uint,
        user_ptr: *mut c_void,
    ),
>;
pub type RTCSetNodeBoundsFunction = Option<
    unsafe extern "C" fn(
        node: *mut c_void,
        bounds: *mut *const RTCBounds,
        child_count: c_uint,
        user_ptr: *mut c_void,
    ),
>;
pub type RTCCreateLeafFunction = Option<
    unsafe extern "C" fn(
        allocator: RTCThreadLocalAllocator,
        primitives: *const RTCBuildPrimitive,
        primitive_count: usize,
        user_ptr: *mut c_void,
    ) -> *mut c_void,
>;

/// `struct RTCBuildArguments` (`rtcore_builder.h`); the split and progress callbacks are
/// never set.
#[repr(C)]
pub struct RTCBuildArguments {
    pub byteSize: usize,
    pub buildQuality: RTCBuildQuality,
    pub buildFlags: c_int,
    pub maxBranchingFactor: c_uint,
    pub maxDepth: c_uint,
    pub sahBlockSize: c_uint,
    pub minLeafSize: c_uint,
    pub maxLeafSize: c_uint,
    pub traversalCost: f32,
    pub intersectionCost: f32,
    pub bvh: *mut c_void,
    pub primitives: *mut RTCBuildPrimitive,
    pub primitiveCount: usize,
    pub primitiveArrayCapacity: usize,
    pub createNode: RTCCreateNodeFunction,
    pub setNodeChildren: RTCSetNodeChildrenFunction,
    pub setNodeBounds: RTCSetNodeBoundsFunction,
    pub createLeaf: RTCCreateLeafFunction,
    pub splitPrimitive: Option<unsafe extern "C" fn()>,
    pub buildProgress: Option<unsafe extern "C" fn()>,
    pub userPtr: *mut c_void,
}

// The builder API, for the traversal bench's "mlt bvh over embree's tree" diagnostic.
unsafe extern "C" {
    pub fn rtcNewBVH(device: RTCDevice) -> *mut c_void;
    pub fn rtcBuildBVH(args: *const RTCBuildArguments) -> *mut c_void;
    pub fn rtcThreadLocalAlloc(
        allocator: RTCThreadLocalAllocator,
        bytes: usize,
        align: usize,
    ) -> *mut c_void;
    pub fn rtcReleaseBVH(bvh: *mut c_void);
}
