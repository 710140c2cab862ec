//! The hand-written Embree declarations (`mlt::accel::embree::ffi`) against the installed
//! header: a small C program prints the size, alignment and every field offset of the structs
//! we pass to Embree, the enum values we use, the memory monitor's signature, and what the header's inline
//! `rtcInitIntersectContext` writes; each must equal its Rust counterpart.
//!
//! Built only with the `embree` feature: CI's Embree step runs it (`.ci/run`), in about 2 s
//! on 2 cores (its C program's compilation included).
#![cfg(feature = "embree")]

mod common {
    pub mod compiler;
}

use mlt::accel::embree::ffi::*;
use std::mem::{align_of, offset_of, size_of};
use std::process::Command;

/// (C expression, the Rust value it must equal).
fn expectations() -> Vec<(String, i64)> {
    let mut list: Vec<(String, i64)> = Vec::new();
    macro_rules! layout {
        ($($ty:ident { $($field:ident),* $(,)? })*) => {$(
            list.push((format!("sizeof(struct {})", stringify!($ty)), size_of::<$ty>() as i64));
            list.push((format!("_Alignof(struct {})", stringify!($ty)), align_of::<$ty>() as i64));
            $(
                list.push((
                    format!("offsetof(struct {}, {})", stringify!($ty), stringify!($field)),
                    offset_of!($ty, $field) as i64,
                ));
                list.push((
                    format!("sizeof(((struct {}*)0)->{})", stringify!($ty), stringify!($field)),
                    size_of_field(|v: &$ty| &v.$field) as i64,
                ));
            )*
        )*};
    }
    layout! {
        RTCRay { org_x, org_y, org_z, tnear, dir_x, dir_y, dir_z, time, tfar, mask, id, flags }
        RTCHit { Ng_x, Ng_y, Ng_z, u, v, primID, geomID, instID }
        RTCRayHit { ray, hit }
        RTCIntersectContext { flags, filter, instID }
        RTCFilterFunctionNArguments { valid, geometryUserPtr, context, ray, hit, N }
        RTCBuildPrimitive { lower_x, lower_y, lower_z, geomID, upper_x, upper_y, upper_z, primID }
        RTCBounds { lower_x, lower_y, lower_z, align0, upper_x, upper_y, upper_z, align1 }
        RTCBuildArguments {
            byteSize, buildQuality, buildFlags, maxBranchingFactor, maxDepth, sahBlockSize,
            minLeafSize, maxLeafSize, traversalCost, intersectionCost, bvh, primitives,
            primitiveCount, primitiveArrayCapacity, createNode, setNodeChildren, setNodeBounds,
            createLeaf, splitPrimitive, buildProgress, userPtr,
        }
    }
    macro_rules! constants {
        ($($name:ident),* $(,)?) => {$(
            list.push((stringify!($name).to_string(), $name as i64));
        )*};
    }
    constants!(
        RTC_ERROR_NONE,
        RTC_ERROR_UNKNOWN,
        RTC_ERROR_INVALID_ARGUMENT,
        RTC_ERROR_INVALID_OPERATION,
        RTC_ERROR_OUT_OF_MEMORY,
        RTC_ERROR_UNSUPPORTED_CPU,
        RTC_ERROR_CANCELLED,
        RTC_BUILD_QUALITY_MEDIUM,
        RTC_BUILD_QUALITY_HIGH,
        RTC_SCENE_FLAG_NONE,
        RTC_SCENE_FLAG_ROBUST,
        RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION,
        RTC_GEOMETRY_TYPE_TRIANGLE,
        RTC_BUFFER_TYPE_INDEX,
        RTC_BUFFER_TYPE_VERTEX,
        RTC_FORMAT_UINT3,
        RTC_FORMAT_FLOAT3,
        RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT,
        RTC_INVALID_GEOMETRY_ID,
        RTC_MAX_INSTANCE_LEVEL_COUNT,
    );
    // Enums we declare as plain ints must be int-sized in C.
    for e in [
        "RTCError",
        "RTCBuildQuality",
        "RTCSceneFlags",
        "RTCGeometryType",
        "RTCBufferType",
        "RTCFormat",
        "RTCIntersectContextFlags",
    ] {
        list.push((
            format!("sizeof(enum {e})"),
            size_of::<std::ffi::c_int>() as i64,
        ));
    }
    // The memory monitor's signature, `fn(*mut c_void, isize, bool) -> bool` in ffi.rs
    // (GCC and Clang's builtin compares the C types).
    list.push(("sizeof(ssize_t)".into(), size_of::<isize>() as i64));
    list.push(("sizeof(bool)".into(), size_of::<bool>() as i64));
    list.push((
        "__builtin_types_compatible_p(RTCMemoryMonitorFunction, bool (*)(void *, ssize_t, bool))"
            .into(),
        1,
    ));
    // The filter callback's signature, `fn(*const RTCFilterFunctionNArguments)` in ffi.rs.
    list.push((
        "__builtin_types_compatible_p(RTCFilterFunctionN, void (*)(const struct RTCFilterFunctionNArguments *))"
            .into(),
        1,
    ));
    // Our reimplementation of the inline rtcInitIntersectContext.
    let context = RTCIntersectContext::new();
    list.push(("context.flags".into(), context.flags as i64));
    list.push((
        "context.filter == NULL".into(),
        context.filter.is_none() as i64,
    ));
    for (i, &id) in context.instID.iter().enumerate() {
        list.push((format!("context.instID[{i}]"), id as i64));
    }
    list
}

fn size_of_field<T, F>(_: impl Fn(&T) -> &F) -> usize {
    size_of::<F>()
}

fn c_program(expressions: &[&str]) -> String {
    let mut source = String::from(
        "#include <embree3/rtcore.h>\n#include <stddef.h>\n#include <stdio.h>\n\nint main(void) {\n    struct RTCIntersectContext context;\n    rtcInitIntersectContext(&context);\n",
    );
    for e in expressions {
        source.push_str(&format!("    printf(\"%lld\\n\", (long long)({e}));\n"));
    }
    source.push_str("    return 0;\n}\n");
    source
}

/// Compiles and runs the program, returning one value per expression.
fn values_from_c(expressions: &[&str]) -> Vec<i64> {
    let dir = std::env::temp_dir().join(format!("mlt-embree-layout-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let source = dir.join("layout.c");
    let exe = dir.join("layout");
    std::fs::write(&source, c_program(expressions)).unwrap();
    let mut cmd = common::compiler::compiler(false);
    cmd.args(["-std=c11", "-Wall", "-Werror"])
        .arg(&source)
        .arg("-o")
        .arg(&exe);
    let output = cmd.output().expect("running the C compiler");
    assert!(
        output.status.success(),
        "compiling the layout program failed: {cmd:?}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let output = Command::new(&exe)
        .output()
        .expect("running the layout program");
    assert!(output.status.success());
    let _ = std::fs::remove_dir_all(&dir);
    String::from_utf8(output.stdout)
        .unwrap()
        .lines()
        .map(|l| l.parse().unwrap())
        .collect()
}

#[test]
fn ffi_declarations_match_the_installed_header() {
    let expected = expectations();
    let expressions: Vec<&str> = expected.iter().map(|(e, _)| e.as_str()).collect();
    let from_c = values_from_c(&expressions);
    assert_eq!(from_c.len(), expected.len());
    let mismatches: Vec<String> = expected
        .iter()
        .zip(&from_c)
        .filter(|((_, rust), c)| rust != *c)
        .map(|((e, rust), c)| format!("{e}: C says {c}, Rust says {rust}"))
        .collect();
    assert!(
        mismatches.is_empty(),
        "the Embree FFI differs from the header:\n{}",
        mismatches.join("\n")
    );
    // The checks cover what matters most.
    assert!(expressions.contains(&"_Alignof(struct RTCRayHit)"));
    assert_eq!(align_of::<RTCRayHit>(), 16);
}
