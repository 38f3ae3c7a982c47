//! `map` over a slice on all cores with scoped threads (items taken one at a time from a shared
//! counter, so uneven items balance), for load-time work: image decoding, mesh analysis.

use std::sync::atomic::{AtomicUsize, Ordering};

/// `items.iter().map(f)` computed on up to `available_parallelism` threads, in order.
pub fn map<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(items.len());
    if threads <= 1 {
        return items.iter().map(f).collect();
    }
    let next = AtomicUsize::new(0);
    let mut out: Vec<(usize, R)> = std::thread::scope(|s| {
        let workers: Vec<_> = (0..threads)
            .map(|_| {
                s.spawn(|| {
                    let mut done = Vec::new();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        let Some(item) = items.get(i) else {
                            return done;
                        };
                        done.push((i, f(item)));
                    }
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
            .collect()
    });
    out.sort_unstable_by_key(|(i, _)| *i);
    out.into_iter().map(|(_, r)| r).collect()
}

#[cfg(test)]
mod tests {
    #[test]
    fn same_as_sequential() {
        let v: Vec<u64> = (0..1000).collect();
        let f = |x: &u64| x * x + 1;
        assert_eq!(super::map(&v, f), v.iter().map(f).collect::<Vec<_>>());
        assert!(super::map(&[] as &[u64], f).is_empty());
    }
}
