//! Hands freed heap pages back to the kernel before the lines stage, where a bake's memory peaks.
//!
//! glibc keeps a freed block in the arena of the thread that freed it, and every rayon worker has
//! its own arena. Since bounds and normals run side by side, the blocks they free stay spread over
//! those arenas: at the dragon's peak 30–60 MB of freed memory still counted as resident (494 MB
//! against 443 MB with the stages in turn), and 180 MB at the 2.18M-triangle level of the scaling
//! benchmark. `malloc_trim` returns the free pages of every arena; called as the lines stage
//! starts, the peak is back below where it was (dragon 430 MB, 2.18M level 581 MB); the bake's wall
//! time did not measurably change (interleaved runs, docs/bench.md).
//!
//! The crate's one `unsafe` place: a call into the C library with no preconditions. Off glibc
//! (musl, macOS, Windows) there is nothing to call.
#![allow(unsafe_code)]

/// Returns the free pages of glibc's arenas to the kernel; a no-op off glibc. Only unused memory is
/// touched: the bake's data and its output do not change.
pub(crate) fn release_free_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: `malloc_trim` only gives unused heap pages back to the kernel; any thread may call it
    // at any time.
    unsafe {
        libc::malloc_trim(0);
    }
}
