//! The heap policy a process that bakes may choose: freed arrays kept and reused between stages.
//!
//! A bake allocates and frees arrays of tens of megabytes stage after stage. Two glibc habits cost
//! memory or time there:
//!
//! * Every rayon worker has its own arena, and a freed block stays in the arena of the thread that
//!   freed it. Since bounds and normals run side by side, the blocks they free stay spread over those
//!   arenas and still count as resident when the lines stage peaks.
//! * Every block above the mmap threshold (at most 32 MB) gets a mapping of its own, unmapped on free,
//!   so the next stage's arrays fault in and zero fresh pages again: a large bake touches about twice
//!   its peak in new pages, and the page faults are a sizeable share of its system time.
//!
//! [`keep_freed_memory`], for a process that bakes (the command-line tool calls it first thing), turns
//! both off: one arena, no block mappings, no trimming. Freed blocks stay in one heap and the next
//! stage reuses them: about half the page faults, at the same peak (docs/bench.md, "Heap reuse", has
//! the figures and the command; mimalloc, measured there too, kept more at the peak).
//!
//! The allocator is the process's, so the policy is the program's choice: a bake itself sets none
//! and trims nothing. A process that does not call these functions (Python, a library user with its
//! own allocator policy, the tests) bakes under glibc's defaults.
//!
//! The crate's one `unsafe` place: calls into the C library with no preconditions beyond the one
//! stated. Off glibc (musl, macOS, Windows) there is nothing to call.
#![allow(unsafe_code)]

/// Keeps freed heap memory in one glibc arena for reuse instead of unmapping or trimming it (see the
/// module docs). Call it first thing in `main`, while the process has one thread; the memory a bake
/// frees then stays with the process until it exits, which suits a command-line bake. A no-op off glibc.
pub fn keep_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: `mallopt` only changes glibc's allocator parameters and has no preconditions; it is
    // called before other threads exist so that no thread has an arena of its own yet.
    unsafe {
        // One heap for all threads: a block freed by one worker is reused by any other.
        libc::mallopt(libc::M_ARENA_MAX, 1);
        // No block is served by a mapping of its own, so no free unmaps one.
        libc::mallopt(libc::M_MMAP_MAX, 0);
        // The top of the heap is never given back while the process runs.
        libc::mallopt(libc::M_TRIM_THRESHOLD, i32::MAX);
    }
}

/// [`keep_freed_memory`] with up to `arenas` heaps instead of one, for a process that bakes several
/// files at once (a batch): with one heap, the threads of concurrent bakes queue on its lock (3–5%
/// of a batch's profile in glibc's lock and the kernel's futex wake-ups), and a bake's freed blocks
/// are still reused by the threads that share its arena. Call it first thing in `main`.
pub fn keep_freed_memory_in(arenas: usize) {
    keep_freed_memory();
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: as in `keep_freed_memory`: allocator parameters only, before other threads exist.
    unsafe {
        libc::mallopt(libc::M_ARENA_MAX, i32::try_from(arenas.max(1)).unwrap_or(i32::MAX));
    }
    // Other allocators have no such setting.
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    let _ = arenas;
}
