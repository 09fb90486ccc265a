//! Hot-path benches: neighbour search and the matrix-free PPE apply (pairs/s), 2D and 3D.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use isph::grid::CellList;
use isph::kernel::{Quintic, SUPPORT_IN_H};
use isph::particles::{Kind, NewParticle, Particles};
use isph::sph::{laplacian_coefficient, Neighbours};

fn lattice<const D: usize>(n: usize, dx: f64) -> (Particles<D>, CellList<D>, Quintic<D>) {
    let mut p = Particles::<D>::default();
    for k in 0..n.pow(D as u32) {
        let mut rest = k;
        let pos = std::array::from_fn(|_| {
            let c = rest % n;
            rest /= n;
            (c as f64 + 0.5) * dx
        });
        p.push(NewParticle {
            pos,
            kind: Kind::Fluid,
            normal: [0.0; D],
            fluid: 0,
            mass: 1000.0 * dx.powi(D as i32),
            rest_density: 1000.0,
            viscosity: 0.0,
        });
    }
    let kernel = Quintic::<D>::new(1.2 * dx);
    let mut grid = CellList::new([0.0; D], [n as f64 * dx; D], SUPPORT_IN_H * kernel.h());
    let (mut c, mut o, mut s) = (Vec::new(), Vec::new(), Vec::new());
    grid.sort(&p.pos, &mut c, &mut o).unwrap();
    p.permute(&o, &mut s);
    (p, grid, kernel)
}

fn bench<const D: usize>(c: &mut Criterion, n: usize) {
    let (p, grid, kernel) = lattice::<D>(n, 0.01);
    let nb = Neighbours::new(&grid, &p.pos, kernel);
    let pairs: usize = (0..p.len())
        .map(|i| {
            let mut k = 0;
            nb.for_each(i, |_, _, _| k += 1);
            k
        })
        .sum();
    let x: Vec<f64> = (0..p.len()).map(|i| (i % 17) as f64).collect();
    let mut y = vec![0.0; p.len()];
    let mut g = c.benchmark_group(format!("{D}d"));
    g.throughput(Throughput::Elements(pairs as u64));
    g.bench_function(format!("laplacian_apply_{}_particles", p.len()), |b| {
        b.iter(|| {
            isph::reduce::fill(&mut y, |i| {
                let mut s = 0.0;
                nb.for_each(i, |j, _, r| {
                    s += laplacian_coefficient(&nb, &p, i, j, r) * (x[i] - x[j])
                });
                s
            })
        })
    });
    let mut grid2 = grid.clone();
    let (mut cells, mut order) = (Vec::new(), Vec::new());
    g.throughput(Throughput::Elements(p.len() as u64));
    g.bench_function(format!("cell_sort_{}_particles", p.len()), |b| {
        b.iter(|| grid2.sort(&p.pos, &mut cells, &mut order).unwrap())
    });
    g.finish();
}

fn operators(c: &mut Criterion) {
    bench::<2>(c, 200);
    bench::<3>(c, 32);
}

criterion_group!(benches, operators);
criterion_main!(benches);
