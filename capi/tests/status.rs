//! The last-error record and the panic guard behind every entry point (`src/status.rs`, compiled
//! here on its own, so the library is not built a second time as a test harness).
#[path = "../src/status.rs"]
mod status;

use std::ffi::CStr;

/// This thread's last error as Rust text.
fn last_error() -> String {
    // SAFETY: `status::last` returns a valid NUL-terminated string that lives until the next
    // `record` on this thread; it is copied before any.
    unsafe { CStr::from_ptr(status::last()) }
        .to_str()
        .expect("UTF-8")
        .to_owned()
}

#[test]
fn a_panic_is_caught_with_its_message() {
    assert_eq!(status::catch(|| -> u32 { panic!("deliberate") }), None);
    assert_eq!(last_error(), "octoray panicked: deliberate");
    let n = 3;
    assert_eq!(status::catch(|| -> u32 { panic!("formatted {n}") }), None);
    assert_eq!(last_error(), "octoray panicked: formatted 3");
    // A call that does not panic answers its value and leaves the record alone.
    assert_eq!(status::catch(|| 7), Some(7));
    assert_eq!(last_error(), "octoray panicked: formatted 3");
}

#[test]
fn a_message_with_a_nul_is_kept() {
    status::record("a\0b".into());
    assert_eq!(last_error(), "a b");
}
