//! Hot-path benches in 2D and 3D, on the dam break of `isph bench` (in 2D its x–z section) a few
//! steps after the release: the cell sort (particles/s), the pair loop of the summation density
//! and the PPE operator apply (pair interactions/s), one BiCGSTAB solve with the multigrid
//! preconditioner of the step (fluid particles/s), and a full `Simulation` step (fluid
//! particles/s).
//!
//! The PPE operator is the step's own, built by its stages on the settled state
//! (`Simulation::advance_probing`), handed over in one more step.

use criterion::{criterion_group, criterion_main, Criterion, SamplingMode, Throughput};
use isph::math::kernel::KernelKind;
use isph::math::reduce::fill;
use isph::neighbours::Neighbours;
use isph::particles::Particles;
use isph::simulation::Simulation;
use isph::solver::krylov::{BiCgStab, LinearOperator, Preconditioner, SolverParams};
use isph::solver::multigrid::Multigrid;
use isph::sph;
use isph::tools::bench::{apply_pairs, dam_break_scene};
use std::time::Duration;

/// Steps taken before the state is benched: past the PPE's cold start from rest.
const SETTLE_STEPS: usize = 3;

fn bench<const D: usize>(c: &mut Criterion, spacing: f64) {
    let scene = dam_break_scene(D, spacing, KernelKind::Quintic).unwrap();
    let mut sim = Simulation::<D>::new(&scene).unwrap();
    for _ in 0..SETTLE_STEPS {
        sim.advance_towards(scene.end_time).unwrap();
    }
    let gravity: [f64; D] = std::array::from_fn(|d| scene.gravity[d]);
    let (n, fluid) = (sim.particles.len(), sim.particles.fluid_count());
    let label = |what: &str| format!("{what}_{fluid}_fluid_{n}_particles");
    let mut g = c.benchmark_group(format!("{D}d"));
    sim.advance_probing(scene.end_time, |op| {
        let (nb, p) = (op.nb, op.p);

        g.throughput(Throughput::Elements(n as u64));
        let mut grid = nb.grid().clone();
        let (mut cells, mut order) = (Vec::new(), Vec::new());
        g.bench_function(label("cell_sort"), |b| {
            b.iter(|| grid.sort(&p.pos, &p.kind, &mut cells, &mut order).unwrap())
        });

        g.sample_size(50)
            .throughput(Throughput::Elements(fluid_pairs(nb, p) as u64));
        let mut density = vec![0.0; n];
        g.bench_function(label("pair_loop_density"), |b| {
            b.iter(|| {
                fill(&mut density, |i| {
                    if p.is_fluid(i) {
                        sph::density(nb, p, i)
                    } else {
                        0.0
                    }
                })
            })
        });

        g.throughput(Throughput::Elements(apply_pairs(op) as u64));
        let x = p.pressure[..op.len()].to_vec();
        let mut y = vec![0.0; op.len()];
        g.bench_function(label("ppe_apply"), |b| b.iter(|| op.apply(&x, &mut y)));

        // A known solution: the hydrostatic pressure under the highest fluid particle.
        let height = |i: usize| -(0..D).map(|d| gravity[d] * p.pos[d][i]).sum::<f64>();
        let top = (0..fluid).map(height).fold(f64::MIN, f64::max);
        let exact: Vec<f64> = (0..fluid)
            .map(|i| p.rest_density[i] * (top - height(i)))
            .collect();
        let mut rhs = vec![0.0; fluid];
        op.apply(&exact, &mut rhs);
        let params = SolverParams {
            tolerance: scene.solver.tolerance,
            max_iterations: scene.solver.max_iterations,
        };
        let (mut solver, mut multigrid, mut solution) = (
            BiCgStab::default(),
            Multigrid::<D>::default(),
            vec![0.0; fluid],
        );
        multigrid.setup(op).unwrap();
        let info = solver
            .solve(op, &mut multigrid, &rhs, &mut solution, params)
            .unwrap();
        eprintln!(
            "{D}d: BiCGSTAB + multigrid from zero to the hydrostatic pressure: {} iterations, relative residual {:.1e}",
            info.iterations, info.relative_residual
        );
        g.sample_size(10)
            .sampling_mode(SamplingMode::Flat)
            .measurement_time(Duration::from_secs(20))
            .throughput(Throughput::Elements(fluid as u64));
        g.bench_function(label("bicgstab_solve"), |b| {
            b.iter(|| {
                solution.fill(0.0);
                multigrid.setup(op).unwrap();
                solver
                    .solve(op, &mut multigrid, &rhs, &mut solution, params)
                    .unwrap()
            })
        });
    })
    .unwrap();

    g.bench_function(label("step"), |b| {
        b.iter(|| sim.advance_towards(scene.end_time).unwrap())
    });
    g.finish();
}

/// Neighbour pairs of the fluid particles: the pair interactions of the summation density.
fn fluid_pairs<const D: usize>(nb: &Neighbours<D>, p: &Particles<D>) -> usize {
    (0..p.len())
        .filter(|&i| p.is_fluid(i))
        .map(|i| {
            let mut k = 0;
            nb.for_each(i, |_, _, _| k += 1);
            k
        })
        .sum()
}

fn operators(c: &mut Criterion) {
    // 60 × 100 fluid particles in 2D, 15 × 20 × 25 in 3D (the spacing of dam_break_3d.toml).
    bench::<2>(c, 0.005);
    bench::<3>(c, 0.02);
}

criterion_group!(benches, operators);
criterion_main!(benches);
