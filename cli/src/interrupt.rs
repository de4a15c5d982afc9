//! Ctrl-C, SIGTERM and SIGHUP during a write: the temporary files of the atomic writes in progress
//! (a bake stages all its outputs before it renames any) are removed before the process exits (with 128 + the signal's number, as a shell reports it), so
//! an interrupted bake leaves nothing behind, and the previous output, which only the final rename
//! replaces, stays intact.
//!
//! One of the crate's two `unsafe` places (the other is `gpu_env`): a POSIX signal handler may
//! only call async-signal-safe functions, so it reads the registered paths from atomic pointers
//! and calls `unlink` and `_exit` (both async-signal-safe), nothing else.
#![allow(unsafe_code)]

use std::ffi::CString;
use std::path::Path;
use std::sync::atomic::{AtomicPtr, Ordering};

/// Slots for the temporary files to remove if a signal arrives (null: free). A bake stages its
/// main file, a .gltf's .bin, the report and one PNG per texture at once; a file past the last
/// slot is still removed on every other path out, only not by a signal.
static TEMP_FILES: [AtomicPtr<libc::c_char>; 64] = [const { AtomicPtr::new(std::ptr::null_mut()) }; 64];

extern "C" fn on_signal(signal: libc::c_int) {
    // SAFETY: each path is null or a NUL-terminated string leaked by `TempFileGuard::new`, so never
    // freed; unlink and _exit are async-signal-safe.
    unsafe {
        for slot in &TEMP_FILES {
            let path = slot.load(Ordering::SeqCst);
            if !path.is_null() {
                libc::unlink(path);
            }
        }
        libc::_exit(128 + signal);
    }
}

/// Installs the handler for SIGINT, SIGTERM and SIGHUP (once, before the first write).
pub fn install() {
    for signal in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
        // SAFETY: a zeroed sigaction is a valid value; the handler only calls async-signal-safe
        // functions (see the module docs).
        unsafe {
            let mut action: libc::sigaction = std::mem::zeroed();
            action.sa_sigaction = on_signal as *const () as libc::sighandler_t;
            libc::sigemptyset(&mut action.sa_mask);
            libc::sigaction(signal, &action, std::ptr::null_mut());
        }
    }
}

/// Registers `path` as a file a signal removes, until dropped.
#[derive(Debug)]
pub struct TempFileGuard(Option<usize>);

impl TempFileGuard {
    pub fn new(path: &Path) -> Self {
        use std::os::unix::ffi::OsStrExt;
        let Ok(c) = CString::new(path.as_os_str().as_bytes()) else { return Self(None) };
        // Leaked on purpose: a signal handler may still be reading it after the guard is gone
        // (a few bytes per output file).
        let raw = c.into_raw();
        let null = std::ptr::null_mut();
        let slot =
            TEMP_FILES.iter().position(|s| s.compare_exchange(null, raw, Ordering::SeqCst, Ordering::SeqCst).is_ok());
        Self(slot)
    }
}

impl Drop for TempFileGuard {
    fn drop(&mut self) {
        if let Some(slot) = self.0 {
            TEMP_FILES[slot].store(std::ptr::null_mut(), Ordering::SeqCst);
        }
    }
}
