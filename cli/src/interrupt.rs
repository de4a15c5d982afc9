//! Ctrl-C, SIGTERM and SIGHUP during a write: the temporary file of the atomic write in progress
//! is removed before the process exits (with 128 + the signal's number, as a shell reports it), so
//! an interrupted bake leaves nothing behind, and the previous output, which only the final rename
//! replaces, stays intact.
//!
//! One of the crate's two `unsafe` places (the other is `gpu_env`): a POSIX signal handler may
//! only call async-signal-safe functions, so it reads the registered path from an atomic pointer
//! and calls `unlink` and `_exit` (both async-signal-safe), nothing else.
#![allow(unsafe_code)]

use std::ffi::CString;
use std::path::Path;
use std::sync::atomic::{AtomicPtr, Ordering};

/// The temporary file to remove if a signal arrives, or null.
static TEMP_FILE: AtomicPtr<libc::c_char> = AtomicPtr::new(std::ptr::null_mut());

extern "C" fn on_signal(signal: libc::c_int) {
    let path = TEMP_FILE.load(Ordering::SeqCst);
    // SAFETY: `path` is null or a NUL-terminated string leaked by `TempFileGuard::new`, so never
    // freed; unlink and _exit are async-signal-safe.
    unsafe {
        if !path.is_null() {
            libc::unlink(path);
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

/// Registers `path` as the file a signal removes, until dropped.
#[derive(Debug)]
pub struct TempFileGuard;

impl TempFileGuard {
    pub fn new(path: &Path) -> Self {
        use std::os::unix::ffi::OsStrExt;
        if let Ok(c) = CString::new(path.as_os_str().as_bytes()) {
            // Leaked on purpose: a signal handler may still be reading it after the guard is gone
            // (a few bytes per output file).
            TEMP_FILE.store(c.into_raw(), Ordering::SeqCst);
        }
        Self
    }
}

impl Drop for TempFileGuard {
    fn drop(&mut self) {
        TEMP_FILE.store(std::ptr::null_mut(), Ordering::SeqCst);
    }
}
