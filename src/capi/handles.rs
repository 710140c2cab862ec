//! Scene handles. The pointer a host gets from `mlt_scene_create` is the address of a
//! reference-counted scene that the library also keeps in a table of live handles:
//! - every call that takes a scene looks it up and holds its own reference for the call, so
//!   a host thread may release a scene while other threads still render or query it (the
//!   last of them frees it);
//! - a pointer that is not in the table (released, never created, or garbage) is refused
//!   with a message instead of being dereferenced;
//! - `mlt_scene_retain` adds a host reference, `mlt_scene_release` drops one.
//!
//! A handle's memory stays allocated while any reference exists, so its address cannot be
//! reused by another scene until the last reference is gone.

use super::types::MltScene;
use crate::error::*;
use std::collections::BTreeMap;
use std::sync::{Arc, RwLock, RwLockReadGuard, RwLockWriteGuard};

/// A live scene and how many references its host holds.
struct LiveScene {
    scene: Arc<MltScene>,
    host_references: usize,
}

/// Live scenes by address. Lookups (every render and query) take the read lock; only
/// create, retain and release write.
static LIVE_SCENES: RwLock<BTreeMap<usize, LiveScene>> = RwLock::new(BTreeMap::new());

// Nothing panics while holding the lock, but a poisoned table is still consistent: every
// update is a single insert, remove or increment.
fn read_table() -> RwLockReadGuard<'static, BTreeMap<usize, LiveScene>> {
    LIVE_SCENES
        .read()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

fn write_table() -> RwLockWriteGuard<'static, BTreeMap<usize, LiveScene>> {
    LIVE_SCENES
        .write()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Makes `scene` live with one host reference; returns its handle.
pub(super) fn register(scene: MltScene) -> *mut MltScene {
    let scene = Arc::new(scene);
    let handle = Arc::as_ptr(&scene).cast_mut();
    write_table().insert(
        handle as usize,
        LiveScene {
            scene,
            host_references: 1,
        },
    );
    handle
}

fn not_live(handle: *const MltScene, name: &str) -> Error {
    if handle.is_null() {
        Error::invalid(format!("{name} is NULL"))
    } else {
        Error::invalid(format!(
            "{name} ({handle:p}) is not a live scene: it was released, or did not come from mlt_scene_create"
        ))
    }
}

/// The scene behind a handle, held for as long as the caller keeps the `Arc`.
pub(super) fn acquire(handle: *const MltScene, name: &str) -> Result<Arc<MltScene>> {
    read_table()
        .get(&(handle as usize))
        .map(|live| Arc::clone(&live.scene))
        .ok_or_else(|| not_live(handle, name))
}

/// Adds a host reference to a live scene.
pub(super) fn retain(handle: *const MltScene) -> Result<()> {
    let mut table = write_table();
    let live = table
        .get_mut(&(handle as usize))
        .ok_or_else(|| not_live(handle, "scene"))?;
    live.host_references += 1;
    Ok(())
}

/// Drops a host reference. When it was the last, the handle stops being live, and the scene
/// is freed once no call is using it any more. Errs, changing nothing, if `handle` is not
/// live.
pub(super) fn release(handle: *const MltScene) -> Result<()> {
    let last = {
        let mut table = write_table();
        let live = table
            .get_mut(&(handle as usize))
            .ok_or_else(|| not_live(handle, "scene"))?;
        live.host_references -= 1;
        if live.host_references > 0 {
            return Ok(());
        }
        table.remove(&(handle as usize))
    };
    // Dropped outside the lock: freeing a large scene takes a while, and other threads'
    // lookups should not wait for it.
    drop(last);
    Ok(())
}
