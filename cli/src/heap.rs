//! Hands freed heap pages back to the kernel between bake stages.
//!
//! glibc keeps a freed block in the arena of the thread that freed it, and every rayon worker has
//! its own arena. After the bake's bounds and normals stages (which run side by side) 30–60 MB of
//! freed memory still counted in the dragon's resident set when the lines stage, where a bake peaks,
//! began: 500 MB at the peak against 443 MB when the stages ran one after the other. `malloc_trim`
//! returns the free pages of every arena; called as the lines stage starts, the peak is back where
//! it was. It costs under a millisecond there.
//!
//! The crate's third `unsafe` place (with `interrupt` and `gpu_env`): a call into the C library with
//! no preconditions. Elsewhere (musl, macOS) there is nothing to call.
#![allow(unsafe_code)]

/// Returns the free pages of glibc's arenas to the kernel; a no-op off glibc.
pub fn release_free_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: `malloc_trim` only gives unused heap pages back to the kernel; any thread may call it
    // at any time.
    unsafe {
        libc::malloc_trim(0);
    }
}
