//! This thread's last error message, and panics caught at the boundary. No `extern` items and
//! nothing of the crate's: `tests/status.rs` compiles this file on its own.

use std::cell::RefCell;
use std::ffi::{c_char, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

/// Records `message` as this thread's last error (a NUL byte, which a C string cannot hold,
/// becomes a space).
pub(crate) fn record(message: String) {
    let text = message.replace('\0', " ");
    LAST_ERROR.with(|e| *e.borrow_mut() = CString::new(text).unwrap_or_default());
}

/// This thread's last error as a NUL-terminated string (empty after none), valid until the next
/// [`record`] on this thread. Never null.
pub(crate) fn last() -> *const c_char {
    LAST_ERROR.with(|e| e.borrow().as_ptr())
}

/// Runs `body`; a panic is recorded as `octoray panicked: <its message>` and answered `None`.
pub(crate) fn catch<T>(body: impl FnOnce() -> T) -> Option<T> {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(t) => Some(t),
        Err(p) => {
            let what = p
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| p.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            record(format!("octoray panicked: {what}"));
            None
        }
    }
}
