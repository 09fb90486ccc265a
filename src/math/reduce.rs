//! Data-parallel helpers whose results do not depend on the number of threads.
//!
//! Every per-particle loop writes only its own particle's result, and every sum is taken over
//! fixed chunks whose partial sums are added in chunk order: the same bits for any thread count.

use rayon::prelude::*;

/// Chunk length of the fixed-order sums: their partial sums, added in chunk order, give the
/// same bits for any thread count.
const CHUNK: usize = 2048;

/// Length of the blocks the per-particle loops (`fill`, `fill_vector`, …) hand to a thread. Their
/// results do not depend on how the work is split, so the blocks can be short: a 2D scene of a
/// couple of thousand fluid particles (fewer than one `CHUNK`) still keeps every thread busy.
const BLOCK: usize = 128;

/// Runs `f` on a worker thread of the global pool (in place when called from one): a run's
/// parallel loops (a few hundred a step, many of them short) then fork from inside the pool,
/// the calling worker taking a share, instead of waking the pool from outside and sleeping until
/// it is done.
pub fn in_pool<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    rayon::scope(|_| f())
}

/// Σ_i f(i) for i in 0..n, summed in fixed chunks (deterministic for any thread count).
pub fn sum(n: usize, f: impl Fn(usize) -> f64 + Sync) -> f64 {
    sums(n, |i| [f(i)])[0]
}

/// Σ_i f(i) of K quantities at once, in one pass over i in 0..n, summed like `sum` in fixed
/// chunks (each component from −0.0, as `Iterator::sum` of f64 starts).
pub fn sums<const K: usize>(n: usize, f: impl Fn(usize) -> [f64; K] + Sync) -> [f64; K] {
    let add = |mut a: [f64; K], b: [f64; K]| {
        for k in 0..K {
            a[k] += b[k];
        }
        a
    };
    let partial: Vec<[f64; K]> = (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            (c * CHUNK..((c + 1) * CHUNK).min(n))
                .map(&f)
                .fold([-0.0; K], add)
        })
        .collect();
    partial.into_iter().fold([-0.0; K], add)
}

/// max_i f(i) for i in 0..n (0 when n = 0), NaN if any f(i) is NaN: a NaN speed has to stop
/// the run as non-finite, not vanish from the maximum as it does from `f64::max`. A maximum
/// does not depend on the order.
pub fn max(n: usize, f: impl Fn(usize) -> f64 + Sync) -> f64 {
    (0..n)
        .into_par_iter()
        .map(&f)
        .reduce(|| 0.0, |a, b| if a >= b || a.is_nan() { a } else { b })
}

/// Number of i in 0..n with `pred(i)`.
pub fn count(n: usize, pred: impl Fn(usize) -> bool + Sync) -> usize {
    (0..n).into_par_iter().filter(|&i| pred(i)).count()
}

/// out[i] = f(i) for every i, in parallel.
pub fn fill<T: Send>(out: &mut [T], f: impl Fn(usize) -> T + Sync) {
    out.par_chunks_mut(BLOCK)
        .enumerate()
        .for_each(|(c, block)| {
            for (k, o) in block.iter_mut().enumerate() {
                *o = f(c * BLOCK + k);
            }
        });
}

/// out[i] ← f(i, out[i]) for every i, in parallel: a per-particle result that replaces the
/// value it is computed from.
pub fn update<T: Send + Copy>(out: &mut [T], f: impl Fn(usize, T) -> T + Sync) {
    out.par_chunks_mut(BLOCK)
        .enumerate()
        .for_each(|(c, block)| {
            for (k, o) in block.iter_mut().enumerate() {
                *o = f(c * BLOCK + k, *o);
            }
        });
}

/// (a[i], b[i]) = f(i) for every i: two results of one pass.
pub fn fill_pair<T: Send>(a: &mut [T], b: &mut [T], f: impl Fn(usize) -> [T; 2] + Sync) {
    debug_assert_eq!(a.len(), b.len(), "two results of one pass have one length");
    a.par_chunks_mut(BLOCK)
        .zip(b.par_chunks_mut(BLOCK))
        .enumerate()
        .for_each(|(c, (a, b))| {
            for (k, (a, b)) in a.iter_mut().zip(b).enumerate() {
                [*a, *b] = f(c * BLOCK + k);
            }
        });
}

/// out[d][i] = f(i)[d] for every i: a per-particle vector result written into SoA components.
pub fn fill_vector<const D: usize>(out: &mut [Vec<f64>; D], f: impl Fn(usize) -> [f64; D] + Sync) {
    component_blocks(out)
        .into_par_iter()
        .enumerate()
        .for_each(|(c, mut block)| {
            for k in 0..block[0].len() {
                set(&mut block, k, f(c * BLOCK + k));
            }
        });
}

/// (a[i], b[i]) ← f(i, b[i]) for every i, with a[i] and b[i] the vectors of particle i in the
/// SoA components of `a` and `b`: two per-particle vector results of one pass, the second
/// replacing the vector it is computed from.
pub fn fill_vector_and_update<const D: usize>(
    a: &mut [Vec<f64>; D],
    b: &mut [Vec<f64>; D],
    f: impl Fn(usize, [f64; D]) -> ([f64; D], [f64; D]) + Sync,
) {
    update_vectors([a, b], |i, [_, b]| {
        let (a, b) = f(i, b);
        [a, b]
    });
}

/// v_k[i] ← f(i, [v_0[i], …])[k] for every i and each of the K arrays of vectors `v` (SoA
/// components): K per-particle vector results of one pass, each handed its old value.
pub fn update_vectors<const D: usize, const K: usize>(
    v: [&mut [Vec<f64>; D]; K],
    f: impl Fn(usize, [[f64; D]; K]) -> [[f64; D]; K] + Sync,
) {
    let n = v[0][0].len();
    assert!(
        v.iter().all(|a| a[0].len() == n),
        "one vector per particle in each"
    );
    let mut blocks = v.map(|a| component_blocks(a).into_iter());
    let blocks: Vec<[[&mut [f64]; D]; K]> = (0..n.div_ceil(BLOCK))
        .map(|_| {
            blocks
                .each_mut()
                .map(|b| b.next().expect("arrays have equal length"))
        })
        .collect();
    blocks
        .into_par_iter()
        .enumerate()
        .for_each(|(c, mut block)| {
            for k in 0..block[0][0].len() {
                let old = std::array::from_fn(|a| std::array::from_fn(|d| block[a][d][k]));
                let new = f(c * BLOCK + k, old);
                for (b, v) in block.iter_mut().zip(new) {
                    set(b, k, v);
                }
            }
        });
}

/// (s[i], v[i]) ← f(i) for every i: a scalar and a vector per particle from one pass, the
/// vector into the SoA components of `v`.
pub fn fill_scalar_and_vector<T: Send, const D: usize>(
    s: &mut [T],
    v: &mut [Vec<f64>; D],
    f: impl Fn(usize) -> (T, [f64; D]) + Sync,
) {
    assert_eq!(
        s.len(),
        v[0].len(),
        "one scalar and one vector per particle"
    );
    s.par_chunks_mut(BLOCK)
        .zip(component_blocks(v))
        .enumerate()
        .for_each(|(c, (block_s, mut block_v))| {
            for k in 0..block_s.len() {
                let (x, y) = f(c * BLOCK + k);
                block_s[k] = x;
                set(&mut block_v, k, y);
            }
        });
}

/// The SoA components of `out` in blocks of `BLOCK` particles: block c holds particles
/// c·BLOCK … of every component.
fn component_blocks<const D: usize>(out: &mut [Vec<f64>; D]) -> Vec<[&mut [f64]; D]> {
    let n = out[0].len();
    let mut chunks = out.each_mut().map(|v| v.chunks_mut(BLOCK));
    (0..n.div_ceil(BLOCK))
        .map(|_| {
            chunks
                .each_mut()
                .map(|c| c.next().expect("components have equal length"))
        })
        .collect()
}

/// Writes vector v into row k of a block of components.
#[inline]
fn set<const D: usize>(block: &mut [&mut [f64]; D], k: usize, v: [f64; D]) {
    for d in 0..D {
        block[d][k] = v[d];
    }
}

/// Σ_i a[i] b[i] in fixed chunks.
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    sum(a.len(), |i| a[i] * b[i])
}
