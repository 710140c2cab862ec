//! Embree's own SAH builder (`rtcBuildBVH`) making a binary tree in obvhs's form, which the
//! BVH backend then collapses to its wide tree as it does obvhs's. Only for the traversal
//! bench's diagnostic row `mlt bvh (embree tree)`: it tells how much of the difference
//! between the BVH and Embree is the tree and how much the traversal.

use super::Device;
use super::ffi::*;
use crate::error::Result;
use glam::Vec3A;
use obvhs::aabb::Aabb;
use obvhs::bvh2::{Bvh2, node::Bvh2Node};
use std::ffi::{c_uint, c_void};

/// The most triangles a leaf may hold (the 8-wide tree's two blocks).
const MAX_LEAF: usize = 8;

/// A node or leaf as the callbacks build it in Embree's thread-local memory.
#[repr(C)]
struct Built {
    /// 0 for a node, else the number of primitives of a leaf.
    count: u32,
    ids: [u32; MAX_LEAF],
    children: [*mut Built; 2],
    bounds: [Aabb; 2],
}

unsafe extern "C" fn create_node(
    allocator: RTCThreadLocalAllocator,
    _: c_uint,
    _: *mut c_void,
) -> *mut c_void {
    // SAFETY: Embree's allocator, valid during the callback; the memory is written whole.
    unsafe {
        let node = rtcThreadLocalAlloc(allocator, size_of::<Built>(), 32).cast::<Built>();
        node.write(Built {
            count: 0,
            ids: [0; MAX_LEAF],
            children: [std::ptr::null_mut(); 2],
            bounds: [Aabb::empty(); 2],
        });
        node.cast()
    }
}

unsafe extern "C" fn set_children(
    node: *mut c_void,
    children: *mut *mut c_void,
    count: c_uint,
    _: *mut c_void,
) {
    // SAFETY: `node` is one `create_node` made; `children` has `count` (2) entries.
    unsafe {
        let node = &mut *node.cast::<Built>();
        for i in 0..count as usize {
            node.children[i] = (*children.add(i)).cast();
        }
    }
}

unsafe extern "C" fn set_bounds(
    node: *mut c_void,
    bounds: *mut *const RTCBounds,
    count: c_uint,
    _: *mut c_void,
) {
    // SAFETY: as `set_children`.
    unsafe {
        let node = &mut *node.cast::<Built>();
        for i in 0..count as usize {
            let b = &**bounds.add(i);
            node.bounds[i] = Aabb::new(
                Vec3A::new(b.lower_x, b.lower_y, b.lower_z),
                Vec3A::new(b.upper_x, b.upper_y, b.upper_z),
            );
        }
    }
}

unsafe extern "C" fn create_leaf(
    allocator: RTCThreadLocalAllocator,
    primitives: *const RTCBuildPrimitive,
    count: usize,
    user: *mut c_void,
) -> *mut c_void {
    // SAFETY: as `create_node`; `primitives` has `count` entries, at most `maxLeafSize`.
    unsafe {
        let leaf = create_node(allocator, 0, user).cast::<Built>();
        (*leaf).count = count as u32;
        for i in 0..count {
            (*leaf).ids[i] = (*primitives.add(i)).primID;
        }
        leaf.cast()
    }
}

/// Embree's high-quality binary SAH tree over `vertices` (at least one), with leaves of at most `max_leaf`
/// (at most 8) triangles and the SAH counting them in blocks of four, as obvhs's `Bvh2`.
pub fn binary_tree(vertices: &[[Vec3A; 3]], max_leaf: u32) -> Result<Bvh2> {
    assert!(
        (1..=MAX_LEAF as u32).contains(&max_leaf),
        "leaves of 1 to {MAX_LEAF}"
    );
    let device = Device::new()?;
    let mut primitives: Vec<RTCBuildPrimitive> = vertices
        .iter()
        .enumerate()
        .map(|(id, [a, b, c])| {
            let (lower, upper) = (a.min(*b).min(*c), a.max(*b).max(*c));
            RTCBuildPrimitive {
                lower_x: lower.x,
                lower_y: lower.y,
                lower_z: lower.z,
                geomID: 0,
                upper_x: upper.x,
                upper_y: upper.y,
                upper_z: upper.z,
                primID: id as u32,
            }
        })
        .collect();
    // SAFETY: a live device; the arguments point at live primitives, and the callbacks
    // write only the memory they allocate. The BVH (and its memory) is released after the
    // tree has been copied out.
    unsafe {
        let bvh = rtcNewBVH(device.raw);
        device.check_handle("rtcNewBVH", bvh)?;
        let args = RTCBuildArguments {
            byteSize: size_of::<RTCBuildArguments>(),
            buildQuality: RTC_BUILD_QUALITY_HIGH,
            buildFlags: 0,
            maxBranchingFactor: 2,
            maxDepth: 1024,
            sahBlockSize: 4,
            minLeafSize: 1,
            maxLeafSize: max_leaf,
            traversalCost: 1.0,
            intersectionCost: 1.0,
            bvh,
            primitives: primitives.as_mut_ptr(),
            primitiveCount: primitives.len(),
            primitiveArrayCapacity: primitives.len(),
            createNode: Some(create_node),
            setNodeChildren: Some(set_children),
            setNodeBounds: Some(set_bounds),
            createLeaf: Some(create_leaf),
            splitPrimitive: None,
            buildProgress: None,
            userPtr: std::ptr::null_mut(),
        };
        let root = rtcBuildBVH(&args).cast::<Built>();
        if let Err(error) = device.check_handle("rtcBuildBVH", root) {
            rtcReleaseBVH(bvh);
            return Err(error);
        }
        let mut bvh2 = Bvh2::default();
        let root_box = vertices.iter().fold(Aabb::empty(), |mut b, [a, c, d]| {
            b.extend(*a);
            b.extend(*c);
            b.extend(*d);
            b
        });
        bvh2.nodes.push(Bvh2Node::default());
        copy(&mut bvh2, 0, &*root, root_box);
        rtcReleaseBVH(bvh);
        Ok(bvh2)
    }
}

/// Writes `built` (box `aabb`) into `bvh2.nodes[index]`, its children after the nodes so far.
fn copy(bvh2: &mut Bvh2, index: usize, built: &Built, aabb: Aabb) {
    if built.count > 0 {
        bvh2.nodes[index] = Bvh2Node {
            aabb,
            prim_count: built.count,
            first_index: bvh2.primitive_indices.len() as u32,
            ..Default::default()
        };
        bvh2.primitive_indices
            .extend_from_slice(&built.ids[..built.count as usize]);
        return;
    }
    let first = bvh2.nodes.len();
    bvh2.nodes[index] = Bvh2Node {
        aabb,
        prim_count: 0,
        first_index: first as u32,
        ..Default::default()
    };
    bvh2.nodes.push(Bvh2Node::default());
    bvh2.nodes.push(Bvh2Node::default());
    for i in 0..2 {
        // SAFETY: the builder set both children of every node it made.
        let child = unsafe { &*built.children[i] };
        copy(bvh2, first + i, child, built.bounds[i]);
    }
}
