//! numpy arrays in and out: shape checks, rays and points from rows, and the thread split that
//! every batched query shares.

use numpy::{PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use octoray::glam::Vec3;
use octoray::hit::Hit;
use octoray::prim::{PackedTriangle, Ray, VertexTriangle};
use octoray::tree::AllHits;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rayon::prelude::*;

/// A float32 column returned to Python.
pub type F32s<'py> = Bound<'py, PyArray1<f32>>;
/// An int64 column returned to Python (indices; −1 for none).
pub type I64s<'py> = Bound<'py, PyArray1<i64>>;
/// A bool column returned to Python.
pub type Bools<'py> = Bound<'py, PyArray1<bool>>;
/// Rows of three float32 (points, normals) returned to Python.
pub type Rows3<'py> = Bound<'py, PyArray2<f32>>;

/// Rows handed to one thread at a time: large enough that the split costs nothing, small
/// enough that the threads finish together.
const CHUNK: usize = 1024;

/// `a`'s rows as a slice of `width` floats each, or a `ValueError` naming `what`.
pub fn rows<'a, T: numpy::Element>(
    a: &'a PyReadonlyArray2<'_, T>,
    width: usize,
    what: &str,
) -> PyResult<&'a [T]> {
    let shape = a.shape();
    if shape[1] != width {
        return Err(PyValueError::new_err(format!(
            "{what} must have shape (n, {width}), got ({}, {})",
            shape[0], shape[1]
        )));
    }
    a.as_slice()
        .map_err(|_| PyValueError::new_err(format!("{what} must be C-contiguous")))
}

/// One value per row: a `ValueError` unless `a` has `n` entries.
pub fn column<'a, T: numpy::Element>(
    a: &'a PyReadonlyArray1<'_, T>,
    n: usize,
    what: &str,
) -> PyResult<&'a [T]> {
    let s = a
        .as_slice()
        .map_err(|_| PyValueError::new_err(format!("{what} must be C-contiguous")))?;
    if s.len() != n {
        return Err(PyValueError::new_err(format!(
            "{what} must have {n} entries (one per ray), got {}",
            s.len()
        )));
    }
    Ok(s)
}

/// Rays from rows `(ox, oy, oz, dx, dy, dz)` and their parameter ranges. Any values are
/// accepted: a ray the kernels cannot trace (a NaN, a zero direction, an empty range) misses.
pub fn rays(
    rows6: &PyReadonlyArray2<'_, f32>,
    t_min: &PyReadonlyArray1<'_, f32>,
    t_max: &PyReadonlyArray1<'_, f32>,
) -> PyResult<Vec<Ray>> {
    let r = rows(rows6, 6, "rays")?;
    let n = r.len() / 6;
    let (lo, hi) = (column(t_min, n, "t_min")?, column(t_max, n, "t_max")?);
    Ok(r.chunks_exact(6)
        .zip(lo.iter().zip(hi))
        .map(|(r, (&lo, &hi))| {
            let o = Vec3::new(r[0], r[1], r[2]);
            Ray::with_range(o, Vec3::new(r[3], r[4], r[5]), lo, hi)
        })
        .collect())
}

/// Triangles from `vertices` (n, 3) and `faces` (m, 3) indices into them: a `ValueError` for
/// a bad shape or an index out of range.
pub fn triangles(
    vertices: &PyReadonlyArray2<'_, f32>,
    faces: &PyReadonlyArray2<'_, i64>,
) -> PyResult<Vec<VertexTriangle>> {
    let v = rows(vertices, 3, "vertices")?;
    let f = rows(faces, 3, "faces")?;
    let n = v.len() / 3;
    let vertex = |i: i64| -> PyResult<Vec3> {
        usize::try_from(i)
            .ok()
            .filter(|&i| i < n)
            .map(|i| Vec3::new(v[3 * i], v[3 * i + 1], v[3 * i + 2]))
            .ok_or_else(|| {
                PyValueError::new_err(format!("face index {i} out of range for {n} vertices"))
            })
    };
    f.chunks_exact(3)
        .map(|t| {
            Ok(VertexTriangle::new(
                vertex(t[0])?,
                vertex(t[1])?,
                vertex(t[2])?,
            ))
        })
        .collect()
}

/// Each triangle's unit geometric normal `(v1 − v0) × (v2 − v0)`, formed in f64 (no overflow
/// or underflow at any scale) and rounded to f32; 0 for a degenerate or non-finite triangle.
pub fn unit_normals(tris: &[VertexTriangle]) -> Vec<[f32; 3]> {
    let f64s = |p: Vec3| [p.x, p.y, p.z].map(f64::from);
    tris.iter()
        .map(|t| {
            let [a, b, c] = t.vertices().map(f64s);
            let (e, f) = (
                [0, 1, 2].map(|k| b[k] - a[k]),
                [0, 1, 2].map(|k| c[k] - a[k]),
            );
            let n = [
                e[1] * f[2] - e[2] * f[1],
                e[2] * f[0] - e[0] * f[2],
                e[0] * f[1] - e[1] * f[0],
            ];
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if len > 0.0 && len.is_finite() {
                n.map(|x| (x / len) as f32)
            } else {
                [0.0; 3]
            }
        })
        .collect()
}

/// Whether a ray along `dir` meets the side a normal `n` points to (`n·d ≤ 0`, in f64).
pub fn meets_front(n: [f32; 3], dir: Vec3) -> bool {
    let d = [dir.x, dir.y, dir.z].map(f64::from);
    (0..3).map(|k| f64::from(n[k]) * d[k]).sum::<f64>() <= 0.0
}

/// The standard tier's layout of `tris`.
pub fn packed(tris: &[VertexTriangle]) -> Vec<PackedTriangle> {
    tris.iter()
        .map(|t| {
            let [a, b, c] = t.vertices();
            PackedTriangle::new(a, b, c)
        })
        .collect()
}

/// Points from rows `(x, y, z)`.
pub fn points(rows3: &PyReadonlyArray2<'_, f32>) -> PyResult<Vec<Vec3>> {
    let r = rows(rows3, 3, "points")?;
    Ok(r.chunks_exact(3)
        .map(|p| Vec3::new(p[0], p[1], p[2]))
        .collect())
}

/// The worker threads of one call: `None` for rayon's global pool (one per core), or `n ≥ 1`.
pub fn pool(threads: Option<usize>) -> PyResult<Option<rayon::ThreadPool>> {
    match threads {
        None => Ok(None),
        Some(0) => Err(PyValueError::new_err("threads must be at least 1")),
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map(Some)
            .map_err(|e| PyValueError::new_err(e.to_string())),
    }
}

/// `f(first, input chunk, out chunk)` over chunks of `input` and `out` (the same length)
/// spread over `pool`'s threads, `first` the chunk's first index (the answer does not depend on
/// the split).
pub fn map_into<I: Sync, O: Send>(
    pool: Option<&rayon::ThreadPool>,
    input: &[I],
    out: &mut [O],
    f: impl Fn(usize, &[I], &mut [O]) + Sync,
) {
    let mut run = || {
        input
            .par_chunks(CHUNK)
            .zip(out.par_chunks_mut(CHUNK))
            .enumerate()
            .for_each(|(c, (i, o))| f(c * CHUNK, i, o));
    };
    match pool {
        Some(p) => p.install(run),
        None => run(),
    }
}

/// Hits collected per walk of an all-hits query: a ray with more walks again after the last.
const PAGE: usize = 64;

/// Every item a paged query reports (`walk(after, page)`, as the library's all-hits and box
/// queries take a cursor and a page), one page at a time, to `f`.
pub fn pages<T: Copy + Default>(
    mut walk: impl FnMut(Option<T>, &mut [T]) -> AllHits,
    mut f: impl FnMut(T),
) {
    let mut page = [T::default(); PAGE];
    let mut after = None;
    loop {
        let found = walk(after, &mut page);
        page[..found.stored].iter().for_each(|x| f(*x));
        if found.complete || found.stored == 0 {
            return;
        }
        after = Some(page[found.stored - 1]);
    }
}

/// Ray `i`'s hits from a paged all-hits `walk`, appended to `out` with the ray's index.
pub fn paged(
    i: usize,
    out: &mut Vec<(usize, Hit)>,
    walk: impl FnMut(Option<Hit>, &mut [Hit]) -> AllHits,
) {
    pages(walk, |h| out.push((i, h)));
}

/// `each(i, &input[i], out)` for every `i`, spread over `pool`'s threads in chunks, the outputs
/// concatenated in input order.
pub fn collect<I: Sync, O: Send>(
    pool: Option<&rayon::ThreadPool>,
    input: &[I],
    each: impl Fn(usize, &I, &mut Vec<O>) + Sync,
) -> Vec<O> {
    let run = || -> Vec<O> {
        let chunks: Vec<Vec<O>> = input
            .par_chunks(CHUNK)
            .enumerate()
            .map(|(c, chunk)| {
                let mut out = Vec::new();
                for (k, x) in chunk.iter().enumerate() {
                    each(c * CHUNK + k, x, &mut out);
                }
                out
            })
            .collect();
        chunks.into_iter().flatten().collect()
    };
    match pool {
        Some(p) => p.install(run),
        None => run(),
    }
}

/// `f` of every point of `points`, spread over `threads` without the GIL; `init` fills the
/// answers first.
pub fn per_point<T: Clone + Send>(
    py: Python<'_>,
    points: &PyReadonlyArray2<'_, f32>,
    threads: Option<usize>,
    init: T,
    f: impl Fn(Vec3) -> T + Sync,
) -> PyResult<Vec<T>> {
    let points = self::points(points)?;
    let pool = pool(threads)?;
    let mut out = vec![init; points.len()];
    py.detach(|| {
        map_into(pool.as_ref(), &points, &mut out, |_, p, o| {
            for (p, o) in p.iter().zip(o) {
                *o = f(*p);
            }
        })
    });
    Ok(out)
}
