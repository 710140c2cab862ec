//! Byte buffers mlt gives the host (`MltBytes`: render plans and partial results). Each is a
//! boxed slice handed over as its pointer and length, and mlt keeps the address and length
//! of every buffer the host holds, as it keeps its live scenes (`handles`):
//! - `mlt_bytes_release` frees a buffer only if it is live with that very length, so a
//!   buffer released twice through two copies of its `MltBytes`, or a pointer mlt never
//!   gave, is refused with a message instead of freed;
//! - the box is rebuilt with the length it was made with, so it is freed by the allocator
//!   that made it, with its layout.

use super::types::MltBytes;
use crate::error::*;
use std::collections::BTreeMap;
use std::sync::{Mutex, MutexGuard};

/// Live buffers: address → length. Every update is one insert or remove, so a poisoned
/// table (nothing panics while holding it) is still consistent.
static LIVE_BUFFERS: Mutex<BTreeMap<usize, usize>> = Mutex::new(BTreeMap::new());

fn table() -> MutexGuard<'static, BTreeMap<usize, usize>> {
    LIVE_BUFFERS
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Hands `bytes` to the host as a live buffer (an empty one as NULL: no allocation).
pub(super) fn give(bytes: Vec<u8>) -> MltBytes {
    if bytes.is_empty() {
        return MltBytes {
            data: std::ptr::null_mut(),
            size: 0,
        };
    }
    let boxed = bytes.into_boxed_slice();
    let size = boxed.len();
    let data = Box::into_raw(boxed).cast::<u8>();
    table().insert(data as usize, size);
    MltBytes { data, size }
}

/// Frees a live buffer. Errs, freeing nothing, if `bytes` is not one (with its length).
pub(super) fn take_back(bytes: MltBytes, name: &str) -> Result<()> {
    let MltBytes { data, size } = bytes;
    {
        let mut table = table();
        match table.get(&(data as usize)) {
            Some(&live) if live == size => {
                table.remove(&(data as usize));
            }
            Some(&live) => {
                return Err(Error::invalid(format!(
                    "{name}.size is {size} but mlt gave {live} bytes at {data:p}: pass the MltBytes as mlt filled it"
                )));
            }
            None => {
                return Err(Error::invalid(format!(
                    "{name}.data ({data:p}) is not a buffer mlt gave: it was released already (through a copy of its MltBytes?), or did not come from mlt"
                )));
            }
        }
    }
    // SAFETY: `data` and `size` are those of a boxed slice `give` leaked (the table says so)
    // and no longer in the table, so it is rebuilt and freed exactly once.
    drop(unsafe { Box::from_raw(std::ptr::slice_from_raw_parts_mut(data, size)) });
    Ok(())
}
