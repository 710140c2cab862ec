//! Host memory and failures: checks of the pointers and counts a host passes, the panic
//! guard every export runs in, and the thread's last error message.

use crate::error::*;
use std::cell::RefCell;
use std::ffi::CString;
use std::panic::{AssertUnwindSafe, catch_unwind};

thread_local! {
    pub(super) static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

pub(super) fn set_last_error(message: &str) {
    let text = CString::new(message.replace('\0', " ")).unwrap_or_default();
    LAST_ERROR.with(|e| *e.borrow_mut() = text);
}

/// Runs an export: converts errors and panics to a status and the thread's last message.
pub(super) fn guard(f: impl FnOnce() -> Result<MltStatus>) -> MltStatus {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(status)) => {
            if status == MLT_STATUS_OK {
                set_last_error("");
            }
            status
        }
        Ok(Err(error)) => {
            set_last_error(&error.message);
            error.status
        }
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            set_last_error(&format!("internal error (please report): {what}"));
            MLT_STATUS_INTERNAL_ERROR
        }
    }
}

pub(super) fn check_pointer<T>(pointer: *const T, name: &str) -> Result<()> {
    if pointer.is_null() {
        return Err(Error::invalid(format!("{name} is NULL")));
    }
    if !pointer.is_aligned() {
        return Err(Error::invalid(format!(
            "{name} ({pointer:p}) is not aligned to {} bytes",
            std::mem::align_of::<T>()
        )));
    }
    Ok(())
}

/// A slice from a host pointer and element count; NULL is allowed only with a count of 0.
///
/// # Safety
/// If `len > 0`, `pointer` must point to `len` valid, initialized `T`s.
pub(super) unsafe fn host_slice<'a, T>(
    pointer: *const T,
    len: usize,
    name: &str,
) -> Result<&'a [T]> {
    if len == 0 {
        return Ok(&[]);
    }
    check_pointer(pointer, name)?;
    if len
        .checked_mul(std::mem::size_of::<T>())
        .is_none_or(|b| b > isize::MAX as usize)
    {
        return Err(Error::invalid(format!(
            "{name} claims {len} elements, more than the address space holds"
        )));
    }
    // SAFETY: non-null, aligned, size within isize::MAX (checked); the host guarantees
    // `len` initialized elements.
    Ok(unsafe { std::slice::from_raw_parts(pointer, len) })
}

/// A mutable slice from a host pointer and element count.
///
/// # Safety
/// `pointer` must point to `len` writable `T`s not aliased during the call.
pub(super) unsafe fn host_slice_mut<'a, T>(
    pointer: *mut T,
    len: usize,
    name: &str,
) -> Result<&'a mut [T]> {
    check_pointer(pointer, name)?;
    if len
        .checked_mul(std::mem::size_of::<T>())
        .is_none_or(|b| b > isize::MAX as usize)
    {
        return Err(Error::invalid(format!(
            "{name} claims {len} elements, more than the address space holds"
        )));
    }
    // SAFETY: as host_slice, and the host guarantees exclusive access for the call.
    Ok(unsafe { std::slice::from_raw_parts_mut(pointer, len) })
}
