//! Wall-clock timing for the scene report: the best of several runs, alone or in alternation.

use std::hint::black_box;
use std::time::Instant;

/// Best wall time of `runs` runs of `f`, seconds, and `f`'s last answer.
pub fn best(runs: usize, mut f: impl FnMut() -> u64) -> (f64, u64) {
    let mut t = f64::INFINITY;
    let mut r = 0;
    for _ in 0..runs {
        let s = Instant::now();
        r = black_box(f());
        t = t.min(s.elapsed().as_secs_f64());
    }
    (t, r)
}

/// `f` timed over `n` rays, best of `runs`: Mrays/s and `f`'s answer.
pub fn rate(runs: usize, n: usize, f: &mut dyn FnMut() -> u64) -> (f64, u64) {
    let (t, hits) = best(runs, f);
    (n as f64 / t / 1e6, hits)
}

/// The columns of one comparison row, timed in alternation (`runs` rounds, each running every
/// column once) so that a slow spell of a shared machine hits every column alike: best Mrays/s
/// and answer per column.
pub fn alternating(runs: usize, n: usize, fs: &mut [&mut dyn FnMut() -> u64]) -> Vec<(f64, u64)> {
    let mut out = vec![(0.0f64, 0u64); fs.len()];
    for _ in 0..runs {
        for (f, o) in fs.iter_mut().zip(out.iter_mut()) {
            let s = Instant::now();
            let hits = black_box(f());
            let r = n as f64 / s.elapsed().as_secs_f64() / 1e6;
            *o = (o.0.max(r), hits);
        }
    }
    out
}
