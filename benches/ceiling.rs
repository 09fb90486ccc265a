//! The machine's ceilings on every core (rayon's pool: all of them unless RAYON_NUM_THREADS
//! says otherwise), against which the PPE apply of `operators` is read (docs/performance.md,
//! "Ceilings"):
//!
//! * memory bandwidth: the STREAM triad a_i = b_i + s c_i over arrays of 2²⁵ f64 (256 MiB each,
//!   far beyond any cache), counted as STREAM counts it, 24 bytes per element;
//! * floating-point throughput: independent fused multiply-add chains in the pair loops' SIMD
//!   lanes (`lanes::F64s`), enough of them per core to hide the FMA latency, counted as two
//!   operations per lane and FMA;
//! * the square root and division every lane of a pair loop takes (|r_ij|, and the radial
//!   factor of Eq. (27)): independent chains of one of each, counted in lanes.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use isph::math::lanes::{F64s, LANES};
use rayon::prelude::*;
use std::hint::black_box;

/// Elements of each triad array.
const TRIAD_LEN: usize = 1 << 25;
/// Elements a thread takes at a time in the triad.
const TRIAD_CHUNK: usize = 1 << 16;
/// Independent FMA chains per core: more than the FMA latency (4 cycles) times the FMA units (2).
const CHAINS: usize = 12;
/// FMAs per chain per core in one iteration.
const FMA_ROUNDS: usize = 1 << 20;
/// Square roots and divisions per chain per core in one iteration.
const SQRT_DIV_ROUNDS: usize = 1 << 16;

fn triad(c: &mut Criterion) {
    let (mut a, b, cc) = (
        vec![0.0; TRIAD_LEN],
        vec![1.0; TRIAD_LEN],
        vec![2.0; TRIAD_LEN],
    );
    let mut g = c.benchmark_group("ceiling");
    g.throughput(Throughput::Bytes((3 * 8 * TRIAD_LEN) as u64));
    g.bench_function(
        format!("triad_{}_threads", rayon::current_num_threads()),
        |bench| {
            bench.iter(|| {
                a.par_chunks_mut(TRIAD_CHUNK)
                    .zip(b.par_chunks(TRIAD_CHUNK))
                    .zip(cc.par_chunks(TRIAD_CHUNK))
                    .for_each(|((a, b), c)| {
                        for ((a, b), c) in a.iter_mut().zip(b).zip(c) {
                            *a = b + 3.0 * c;
                        }
                    })
            })
        },
    );
    g.finish();
    black_box(&a);
}

fn fma(c: &mut Criterion) {
    on_every_core(c, "fma", 2 * LANES * CHAINS * FMA_ROUNDS, fma_chains);
}

fn sqrt_div(c: &mut Criterion) {
    on_every_core(
        c,
        "sqrt_div",
        LANES * CHAINS * SQRT_DIV_ROUNDS,
        sqrt_div_chains,
    );
}

/// Benches `work` run at once on every thread of the pool, `elements` of it per thread.
fn on_every_core(c: &mut Criterion, name: &str, elements: usize, work: fn() -> f64) {
    let threads = rayon::current_num_threads();
    let mut g = c.benchmark_group("ceiling");
    g.throughput(Throughput::Elements((elements * threads) as u64));
    g.bench_function(format!("{name}_{threads}_threads"), |bench| {
        bench.iter(|| black_box(rayon::broadcast(|_| work())))
    });
    g.finish();
}

/// CHAINS independent chains of FMA_ROUNDS fused multiply-adds each; returns their sum so that
/// none is optimised away.
fn fma_chains() -> f64 {
    let (x, y) = (
        black_box(F64s::splat(0.999_999)),
        black_box(F64s::splat(1e-7)),
    );
    let mut acc = [F64s::ONE; CHAINS];
    for _ in 0..FMA_ROUNDS {
        for a in &mut acc {
            *a = a.mul_add(x, y);
        }
    }
    acc.iter().map(|a| a.reduce_add()).sum()
}

/// CHAINS independent chains of SQRT_DIV_ROUNDS rounds of one square root and one division
/// each, on values that stay near 1; returns their sum.
fn sqrt_div_chains() -> f64 {
    let y = black_box(F64s::splat(1.000_001));
    let mut acc = [F64s::ONE; CHAINS];
    for _ in 0..SQRT_DIV_ROUNDS {
        for a in &mut acc {
            *a = y / a.sqrt();
        }
    }
    acc.iter().map(|a| a.reduce_add()).sum()
}

criterion_group!(benches, triad, fma, sqrt_div);
criterion_main!(benches);
