//! The one parallel map of the crate, on the process's rayon pool.
//!
//! No module spawns threads itself: a sweep hands its independent work items to [`par_map`] (or
//! [`par_map_while`] when it must stop early) with the number of workers its [`Budget`] allows. The
//! service runs every calculation inside the same rayon pool (sized by `--compute-threads`), so the
//! workers of all jobs together never exceed that pool: admission (`--compute-slots`) and the pool
//! size bound the CPU, whatever a request asks for.
//!
//! Work is claimed one item at a time from a shared counter (dynamic load balancing: sweep nodes
//! differ widely in cost) and every result lands at its item's index, so the output is identical
//! for any number of threads.
//!
//! [`Budget`]: crate::numerics::Budget

use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// `f(i, &items[i])` for every item, on at most `threads` workers; results in item order.
///
/// With `threads <= 1` or fewer than two items the map runs inline on the calling thread. A panic
/// in `f` propagates to the caller (the service turns it into a logged 500).
pub fn par_map<T, R, F>(threads: usize, items: &[T], f: F) -> Vec<R>
where
    T: Sync,
    R: Send,
    F: Fn(usize, &T) -> R + Sync,
{
    par_map_while(threads, items, |i, t| Some(f(i, t)))
        .into_iter()
        .map(|r| r.unwrap_or_else(|| unreachable!("par_map's closure never stops the map")))
        .collect()
}

/// Like [`par_map`], but `f` may stop the whole map by returning `None` (a spent budget, a fatal
/// error recorded elsewhere): items not yet started are then left as `None`. Items already
/// claimed by other workers finish, so which items are `None` after a stop depends on timing;
/// callers report such a partial result with an honest stop reason.
pub fn par_map_while<T, R, F>(threads: usize, items: &[T], f: F) -> Vec<Option<R>>
where
    T: Sync,
    R: Send,
    F: Fn(usize, &T) -> Option<R> + Sync,
{
    let n = items.len();
    let workers = threads.clamp(1, n.max(1));
    if workers <= 1 {
        let mut out = Vec::with_capacity(n);
        for (i, t) in items.iter().enumerate() {
            match f(i, t) {
                Some(r) => out.push(Some(r)),
                None => break,
            }
        }
        out.resize_with(n, || None);
        return out;
    }
    let next = AtomicUsize::new(0);
    let stopped = AtomicBool::new(false);
    let parts: Mutex<Vec<Vec<(usize, R)>>> = Mutex::new(Vec::with_capacity(workers));
    let worker = || {
        let mut local = Vec::new();
        while !stopped.load(Ordering::Relaxed) {
            let i = next.fetch_add(1, Ordering::Relaxed);
            let Some(t) = items.get(i) else { break };
            match f(i, t) {
                Some(r) => local.push((i, r)),
                None => stopped.store(true, Ordering::Relaxed),
            }
        }
        // A poisoned lock means another worker panicked; that panic is re-raised by the scope.
        if let Ok(mut p) = parts.lock() {
            p.push(local);
        }
    };
    rayon::scope(|s| {
        for _ in 1..workers {
            s.spawn(|_| worker());
        }
        worker();
    });
    let mut out: Vec<Option<R>> = std::iter::repeat_with(|| None).take(n).collect();
    let parts = parts
        .into_inner()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    for (i, r) in parts.into_iter().flatten() {
        out[i] = Some(r);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn order_is_kept_for_any_thread_count() {
        let items: Vec<u64> = (0..1000).collect();
        let serial = par_map(1, &items, |i, x| x * x + i as u64);
        for threads in [2, 3, 8, 5000] {
            assert_eq!(par_map(threads, &items, |i, x| x * x + i as u64), serial);
        }
    }

    #[test]
    fn workers_are_capped_by_threads() {
        let items: Vec<u32> = (0..64).collect();
        let live = AtomicUsize::new(0);
        let peak = AtomicUsize::new(0);
        let _ = par_map(2, &items, |_, _| {
            let now = live.fetch_add(1, Ordering::SeqCst) + 1;
            peak.fetch_max(now, Ordering::SeqCst);
            std::thread::sleep(std::time::Duration::from_millis(1));
            live.fetch_sub(1, Ordering::SeqCst);
        });
        assert!(peak.load(Ordering::SeqCst) <= 2);
    }

    #[test]
    fn stop_leaves_unstarted_items_empty() {
        let items: Vec<u32> = (0..100).collect();
        let out = par_map_while(1, &items, |i, _| (i < 10).then_some(i));
        assert_eq!(out.iter().filter(|o| o.is_some()).count(), 10);
        let out = par_map_while(4, &items, |i, _| (i < 10).then_some(i));
        assert!(out[..10].iter().all(Option::is_some));
        assert!(out[10..].iter().all(Option::is_none));
    }

    #[test]
    fn empty_input() {
        let items: Vec<u8> = Vec::new();
        assert!(par_map(4, &items, |_, x| *x).is_empty());
    }
}
