//! Giving freed memory back to the system after a large request, when the service runs on
//! glibc's malloc (built without the default `jemalloc` feature; jemalloc purges by itself).
//!
//! glibc's malloc keeps what a thread freed in that thread's arena, so after a large body (a
//! 28 MiB training set) the process stayed 12–55 MiB above idle long after the answer
//! (benches/RESULTS.md, "Memory per body"). `malloc_trim(0)` walks every arena and returns its
//! free pages to the kernel. It runs on a blocking thread after the answer to a request whose
//! body was at least [`LARGE_BODY_BYTES`], one trim at a time; elsewhere (musl, other systems)
//! this does nothing, as those allocators return memory themselves or have no such call.

/// Requests with a body at least this large hand their freed memory back after the answer.
pub const LARGE_BODY_BYTES: usize = 1 << 20;

/// How long after the answer the trim waits (the response is still being written when the
/// request's layer sees it).
#[cfg(all(target_os = "linux", target_env = "gnu", not(feature = "jemalloc")))]
const SETTLE: std::time::Duration = std::time::Duration::from_millis(200);

/// Give freed memory back to the system, off the caller's thread (at most one trim at a time).
pub fn give_back() {
    #[cfg(all(target_os = "linux", target_env = "gnu", not(feature = "jemalloc")))]
    {
        use std::sync::atomic::{AtomicBool, Ordering};
        static RUNNING: AtomicBool = AtomicBool::new(false);
        if RUNNING.swap(true, Ordering::AcqRel) {
            return;
        }
        let run = || {
            // After the answer has gone out and the connection's buffers are freed too.
            std::thread::sleep(SETTLE);
            trim();
            RUNNING.store(false, Ordering::Release);
        };
        match tokio::runtime::Handle::try_current() {
            Ok(rt) => drop(rt.spawn_blocking(run)),
            Err(_) => run(),
        }
    }
}

/// `malloc_trim(0)`: every arena's free pages back to the kernel (live memory untouched).
#[cfg(all(target_os = "linux", target_env = "gnu", not(feature = "jemalloc")))]
#[expect(
    unsafe_code,
    reason = "malloc_trim is a glibc extension reached only through FFI"
)]
fn trim() {
    // SAFETY: malloc_trim takes no pointers and has no preconditions; glibc locks each arena
    // while it trims it, so it is safe beside allocating threads.
    unsafe {
        libc::malloc_trim(0);
    }
}
