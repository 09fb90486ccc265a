//! Surface reconstruction throughput (particles/s) at 10⁵ and 10⁶ particles: a 3D frame of a
//! wavy water body with drops above it, particles jittered off their lattice as a flow leaves
//! them, the default settings (quartic kernel of 2.5 dx, cubes of dx/2). The side-by-side with
//! splashsurf is `tools/splashsurf_compare.sh` (docs/surface.md).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use isph::scene::SurfaceSettings;
use isph::surface::{reconstruct, Points};
use std::time::Duration;

/// About `n` particles at spacing 0.01 m: water below a wavy surface over a square floor, and a
/// drop of 5 spacings' radius above every 40th column.
pub fn wavy_water(n: usize) -> Points {
    let dx = 0.01;
    // Side s and depth s/2 (mean) hold n particles: s³/2 = n.
    let side = (2.0 * n as f64).cbrt().round() as i64;
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut jitter = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.2 * dx
    };
    let mut position = Vec::new();
    for i in 0..side {
        for j in 0..side {
            let (x, y) = (i as f64 * dx, j as f64 * dx);
            let s = side as f64 * dx;
            let depth = s / 2.0 * (1.0 + 0.3 * (6.0 * x / s).sin() * (4.0 * y / s).cos());
            let mut k = 0;
            while (k as f64) * dx < depth {
                position.push([x + jitter(), y + jitter(), k as f64 * dx + jitter()]);
                k += 1;
            }
            if (i * side + j) % 40 == 0 {
                for (a, b, c) in (-5i64..=5).flat_map(|a| {
                    (-5i64..=5).flat_map(move |b| (-5i64..=5).map(move |c| (a, b, c)))
                }) {
                    if a * a + b * b + c * c <= 25 {
                        let z = depth + 0.15 * s;
                        position.push([x + a as f64 * dx, y + b as f64 * dx, z + c as f64 * dx]);
                    }
                }
            }
        }
    }
    Points {
        dimensions: 3,
        spacing: dx,
        velocity: position.iter().map(|p| [p[2], 0.0, -p[0]]).collect(),
        position,
    }
}

fn reconstruction(c: &mut Criterion) {
    let mut group = c.benchmark_group("surface");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(20));
    let settings = SurfaceSettings::default();
    for n in [100_000, 1_000_000] {
        let points = wavy_water(n);
        group.throughput(Throughput::Elements(points.position.len() as u64));
        group.bench_function(
            format!("reconstruct {} particles", points.position.len()),
            |b| b.iter(|| reconstruct(&points, &settings).unwrap()),
        );
    }
    group.finish();
}

criterion_group!(benches, reconstruction);
criterion_main!(benches);
