//! A work-sharing parallel map for the evaluation programs (std threads, no dependency).

use std::sync::atomic::{AtomicUsize, Ordering};

/// Runs `f` on every item with `threads` workers pulling from a shared counter; results in
/// item order. `f` gets the item's index and the item.
pub fn parallel_map<I: Sync, O: Send>(
    items: &[I],
    threads: usize,
    f: impl Fn(usize, &I) -> O + Sync,
) -> Vec<O> {
    let next = AtomicUsize::new(0);
    let mut results: Vec<(usize, O)> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads.max(1))
            .map(|_| {
                scope.spawn(|| {
                    let mut mine = Vec::new();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        let Some(item) = items.get(i) else { break };
                        mine.push((i, f(i, item)));
                    }
                    mine
                })
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().expect("worker thread")).collect()
    });
    results.sort_by_key(|(i, _)| *i);
    results.into_iter().map(|(_, o)| o).collect()
}
