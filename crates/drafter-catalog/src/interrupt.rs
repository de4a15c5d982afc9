//! Ctrl-C, SIGTERM and SIGHUP during a write: the temporary files of the atomic writes in progress
//! (a bake stages all its outputs before it renames any; a cache entry is written under the
//! cache's `tmp/`) are removed before the process exits (with 128 + the signal's number, as a shell
//! reports it), so an interrupted bake leaves nothing behind, and the previous output, which only
//! the final rename replaces, stays intact.
//!
//! A batch asks for a graceful stop first ([`set_graceful`]): the first signal only sets a flag
//! ([`stop_requested`]), the batch admits no more files, and the files being baked finish and are
//! written; a second signal removes the temporary files and exits at once.
//!
//! Installed by the `drafter` binary only: a library that embeds the bake (the Python package)
//! keeps its host's signal handling, and a registered path is then simply never used.
//!
//! The crate's one `unsafe` place: a POSIX signal handler may only call async-signal-safe
//! functions, so it reads the registered paths from atomic pointers and calls `unlink` and `_exit`
//! (both async-signal-safe), nothing else. Off Unix there is no handler: [`install`] does nothing
//! and a guard registers nothing (the graceful stop's flag stays unset), so an interrupted write
//! may leave its temporary file there; the previous output stays intact all the same.
#![allow(unsafe_code)]

use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};
#[cfg(unix)]
use std::{ffi::CString, sync::atomic::AtomicPtr};

/// Set by [`set_graceful`]: the first signal asks for a stop instead of exiting.
static GRACEFUL: AtomicBool = AtomicBool::new(false);
/// The signal that asked for a stop (0: none).
static STOP_SIGNAL: AtomicI32 = AtomicI32::new(0);

/// The first signal only requests a stop ([`stop_requested`]); the next one exits.
pub fn set_graceful(graceful: bool) {
    GRACEFUL.store(graceful, Ordering::SeqCst);
}

/// The signal that requested a graceful stop, if one did.
pub fn stop_requested() -> Option<i32> {
    match STOP_SIGNAL.load(Ordering::SeqCst) {
        0 => None,
        signal => Some(signal),
    }
}

/// Slots for the temporary files to remove if a signal arrives (null: free). A bake stages its
/// main file, a .gltf's .bin, the report and one PNG per texture at once; a file past the last
/// slot is still removed on every other path out, only not by a signal.
#[cfg(unix)]
static TEMP_FILES: [AtomicPtr<libc::c_char>; 64] = [const { AtomicPtr::new(std::ptr::null_mut()) }; 64];

#[cfg(unix)]
extern "C" fn on_signal(signal: libc::c_int) {
    if GRACEFUL.load(Ordering::SeqCst)
        && STOP_SIGNAL.compare_exchange(0, signal, Ordering::SeqCst, Ordering::SeqCst).is_ok()
    {
        return;
    }
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
    #[cfg(unix)]
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
    #[cfg(not(unix))]
    pub fn new(_path: &Path) -> Self {
        Self(None)
    }

    #[cfg(unix)]
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
        #[cfg(not(unix))]
        let _ = self.0;
        #[cfg(unix)]
        if let Some(slot) = self.0 {
            TEMP_FILES[slot].store(std::ptr::null_mut(), Ordering::SeqCst);
        }
    }
}
