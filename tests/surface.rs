//! Surface reconstruction (`isph::surface`): the kernels' normalisation, the lattice rule, and
//! meshes of balls and discs that must be closed, outward and of the right size; the same mesh
//! for any thread count.

use isph::scene::{CubeRule, SurfaceKernel, SurfaceSettings};
use isph::surface::kernels::Kernel;
use isph::surface::lattice::{cubes_per_axis, edge_for_max_cubes};
use isph::surface::table::Table;
use isph::surface::{reconstruct, Mesh, Points};
use std::collections::HashMap;
use std::f64::consts::PI;

const KERNELS: [SurfaceKernel; 4] = [
    SurfaceKernel::Rectangular,
    SurfaceKernel::Quadric,
    SurfaceKernel::Quartic,
    SurfaceKernel::Gaussian,
];

/// ∫ D over the plane (2D) or space (3D) by the midpoint rule in r.
fn integral(kernel: &Kernel, dimensions: usize) -> f64 {
    let steps = 200_000;
    let dr = kernel.support / steps as f64;
    (0..steps)
        .map(|k| {
            let r = (k as f64 + 0.5) * dr;
            let shell = if dimensions == 2 {
                2.0 * PI * r
            } else {
                4.0 * PI * r * r
            };
            kernel.value(r * r) * shell * dr
        })
        .sum()
}

#[test]
fn each_kernel_integrates_to_one_in_2d_and_3d() {
    for shape in KERNELS {
        for dimensions in [2, 3] {
            for radius in [0.02, 1.7] {
                let k = Kernel::new(shape, radius, radius / 2.5, dimensions);
                let total = integral(&k, dimensions);
                assert!(
                    (total - 1.0).abs() < 1e-6,
                    "{shape:?} in {dimensions}D, radius {radius}: ∫D = {total}"
                );
            }
        }
    }
}

#[test]
fn the_quadric_kernel_is_continuous_at_a_third_of_its_radius() {
    let k = Kernel::new(SurfaceKernel::Quadric, 0.3, 0.1, 3);
    let third = 0.1f64;
    let (below, above) = (
        k.value((third * (1.0 - 1e-12)).powi(2)),
        k.value((third * (1.0 + 1e-12)).powi(2)),
    );
    assert!(
        (below - above).abs() < 1e-9 * k.d0,
        "{below} against {above}"
    );
    assert!((below - 2.0 / 3.0 * k.d0).abs() < 1e-9 * k.d0);
    // And it falls to zero at the radius.
    assert!(k.value((0.3f64 * (1.0 - 1e-9)).powi(2)) < 1e-15 * k.d0);
}

#[test]
fn the_lattice_rule_matches_a_hand_computed_box() {
    // A box 2 × 1 × 0.5 m (1 m³) in at most 1000 cubes: cubes of 1e-3 m³, an edge of 0.1 m,
    // 20 × 10 × 5 cubes.
    let edge = edge_for_max_cubes([2.0, 1.0, 0.5], 1000);
    assert!((edge - 0.1).abs() < 1e-12, "{edge}");
    assert_eq!(cubes_per_axis([2.0, 1.0, 0.5], edge), [20.0, 10.0, 5.0]);
    // 3 × 1.5 m² in at most 200 squares: 0.0225 m², an edge of 0.15 m, 20 × 10 squares; a
    // side that is not a whole number of edges takes one more.
    let edge = edge_for_max_cubes([3.0, 1.5], 200);
    assert!((edge - 0.15).abs() < 1e-12, "{edge}");
    assert_eq!(cubes_per_axis([3.0, 1.55], edge), [20.0, 11.0]);
}

/// Particles on the lattice of spacing `dx` (cell centres) within `radius` of `centre`.
fn ball(dimensions: usize, radius: f64, dx: f64, centre: [f64; 3]) -> Points {
    let n = (radius / dx).ceil() as i64 + 1;
    let mut position = Vec::new();
    let zs = if dimensions == 3 { -n..n } else { 0..1 };
    for k in zs {
        for j in -n..n {
            for i in -n..n {
                let offset = [
                    (i as f64 + 0.5) * dx,
                    (j as f64 + 0.5) * dx,
                    if dimensions == 3 {
                        (k as f64 + 0.5) * dx
                    } else {
                        0.0
                    },
                ];
                if offset.iter().map(|c| c * c).sum::<f64>() < radius * radius {
                    position.push(
                        [0, 1, 2].map(|d| centre[d] + if d < dimensions { offset[d] } else { 0.0 }),
                    );
                }
            }
        }
    }
    let velocity = position.iter().map(|p| [p[1], -p[0], 0.5]).collect();
    Points {
        dimensions,
        spacing: dx,
        position,
        velocity,
    }
}

/// Checks that every cell edge (3D) or vertex (2D) is shared by exactly two cells, traversed
/// once each way: the mesh is closed and consistently oriented. Returns the Euler
/// characteristic V − E + F (3D).
fn assert_closed_and_oriented(mesh: &Mesh) -> i64 {
    let n = mesh.vertices_per_cell();
    let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
    for cell in mesh.cells.chunks_exact(n) {
        assert!(cell.iter().all(|&v| (v as usize) < mesh.vertex_count()));
        if n == 3 {
            for k in 0..3 {
                *directed.entry((cell[k], cell[(k + 1) % 3])).or_default() += 1;
            }
        } else {
            *directed.entry((cell[0], cell[1])).or_default() += 1;
        }
    }
    if n == 3 {
        for (&(a, b), &count) in &directed {
            assert_eq!(count, 1, "edge {a}→{b} in {count} triangles the same way");
            assert_eq!(
                directed.get(&(b, a)),
                Some(&1),
                "edge {a}→{b} has no triangle across it"
            );
        }
        let edges = directed.len() as i64 / 2;
        mesh.vertex_count() as i64 - edges + mesh.cell_count() as i64
    } else {
        let mut starts = vec![0; mesh.vertex_count()];
        let mut ends = vec![0; mesh.vertex_count()];
        for cell in mesh.cells.chunks_exact(2) {
            starts[cell[0] as usize] += 1;
            ends[cell[1] as usize] += 1;
        }
        assert!(
            starts.iter().chain(&ends).all(|&c| c == 1),
            "an iso-line vertex not on exactly two segments"
        );
        0
    }
}

/// Prints how far `measured` is from `exact` and checks it is within 2%.
fn assert_within_2_percent(kernel: SurfaceKernel, what: &str, measured: f64, exact: f64) {
    let off = measured / exact - 1.0;
    println!("{kernel:?}: {what} {:+.3}%", 100.0 * off);
    assert!(
        off.abs() < 0.02,
        "{kernel:?}: {what} {measured} against {exact}"
    );
}

#[test]
fn a_ball_gives_a_closed_outward_sphere_of_its_volume_and_area_with_each_kernel() {
    let (radius, dx) = (0.2, 0.01); // 20 spacings
    let points = ball(3, radius, dx, [0.31, -0.17, 1.05]);
    for kernel in KERNELS {
        let settings = SurfaceSettings {
            kernel,
            radius: kernel.default_radius(),
            ..SurfaceSettings::default()
        };
        let mesh = reconstruct(&points, &settings).unwrap();
        assert_eq!(
            assert_closed_and_oriented(&mesh),
            2,
            "{kernel:?}: not a sphere's topology"
        );
        let exact_volume = 4.0 / 3.0 * PI * radius.powi(3);
        assert_within_2_percent(kernel, "volume", mesh.enclosed_measure(), exact_volume);
        let exact_area = 4.0 * PI * radius * radius;
        assert_within_2_percent(kernel, "area", mesh.boundary_measure(), exact_area);
        // Normals point away from the centre: every one within 15° of the radius, and 3° on
        // the mean (the particles' lattice shows as ripples of a few hundredths of a spacing).
        let angles: Vec<f32> = mesh
            .positions
            .iter()
            .zip(&mesh.normals)
            .map(|(p, n)| {
                let r = [p[0] - 0.31, p[1] + 0.17, p[2] - 1.05];
                let length = r.iter().map(|c| c * c).sum::<f32>().sqrt();
                ((0..3).map(|d| r[d] * n[d]).sum::<f32>() / length)
                    .min(1.0)
                    .acos()
                    .to_degrees()
            })
            .collect();
        let worst = angles.iter().cloned().fold(0.0, f32::max);
        let mean = angles.iter().sum::<f32>() / angles.len() as f32;
        println!(
            "{kernel:?}: normals off the radius by {mean:.2}° on the mean, {worst:.2}° at most"
        );
        assert!(
            worst < 15.0 && mean < 3.0,
            "{kernel:?}: normals {mean}° / {worst}° off the radius"
        );
        // The particles move as u = (y, −x, 0.5): the kernel-weighted mean gives the constant
        // part exactly, and the linear part at the weighted centroid of the particles in reach,
        // which a vertex on the surface has on one side only: at most 3/8 of the support
        // inwards (a half ball of uniform weight; measured 0.18–0.34 of it over the kernels),
        // times the gradient 1/s.
        let support = kernel.default_radius() * dx + dx / 2.0;
        let worst_u = mesh
            .positions
            .iter()
            .zip(&mesh.velocity)
            .map(|(p, u)| (u[0] - p[1]).abs().max((u[1] + p[0]).abs()))
            .fold(0.0f32, f32::max);
        println!(
            "{kernel:?}: velocity off the exact one by {:.3} of the support at most",
            worst_u / support as f32
        );
        for (p, u) in mesh.positions.iter().zip(&mesh.velocity) {
            assert!((u[2] - 0.5).abs() < 1e-5, "{kernel:?}: w = {}", u[2]);
            let exact = [p[1], -p[0]];
            for d in 0..2 {
                assert!(
                    (u[d] - exact[d]).abs() < 0.375 * support as f32,
                    "{kernel:?}: u = {u:?} at {p:?}"
                );
            }
        }
    }
}

#[test]
fn a_disc_gives_a_closed_counter_clockwise_circle_of_its_area_and_perimeter_with_each_kernel() {
    let (radius, dx) = (0.2, 0.01);
    let points = ball(2, radius, dx, [-0.4, 0.23, 0.0]);
    for kernel in KERNELS {
        let settings = SurfaceSettings {
            kernel,
            radius: kernel.default_radius(),
            ..SurfaceSettings::default()
        };
        let mesh = reconstruct(&points, &settings).unwrap();
        assert_closed_and_oriented(&mesh);
        let exact_area = PI * radius * radius;
        assert_within_2_percent(kernel, "area", mesh.enclosed_measure(), exact_area);
        let exact_perimeter = 2.0 * PI * radius;
        assert_within_2_percent(
            kernel,
            "perimeter",
            mesh.boundary_measure(),
            exact_perimeter,
        );
    }
}

/// A cloud of particles in clumps, drops and thin sheets, from a fixed linear congruential
/// sequence: surfaces with every case of the tables, saddles included.
fn cloud(dimensions: usize, count: usize, seed: u64) -> Points {
    let mut state = seed;
    let mut next = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let position = (0..count)
        .map(|_| [0, 1, 2].map(|d| if d < dimensions { next() * 0.3 } else { 0.0 }))
        .collect::<Vec<_>>();
    Points {
        dimensions,
        spacing: 0.01,
        velocity: vec![[0.0; 3]; position.len()],
        position,
    }
}

#[test]
fn scattered_particles_give_closed_oriented_surfaces_at_any_iso_value() {
    for (dimensions, count) in [(2, 600), (3, 12_000)] {
        for seed in 1..4 {
            let points = cloud(dimensions, count, seed);
            for iso in [0.2, 0.4, 0.6] {
                for cubes in [CubeRule::Size(0.5), CubeRule::Size(0.37)] {
                    let settings = SurfaceSettings {
                        iso,
                        cubes,
                        radius: 2.0,
                        ..SurfaceSettings::default()
                    };
                    let mesh = reconstruct(&points, &settings).unwrap();
                    assert!(mesh.cell_count() > 10);
                    assert_closed_and_oriented(&mesh);
                    assert!(mesh.enclosed_measure() > 0.0);
                }
            }
        }
    }
}

#[test]
fn every_case_of_the_cube_table_closes_against_its_neighbours() {
    // Each of the 256 cases, alone in a cube whose other corners are outside, gives loops of
    // triangles whose boundary edges lie on the cube's faces only.
    let table = Table::cubes();
    assert_eq!(table.cases.len(), 256);
    assert!(table.cases[0].is_empty() && table.cases[255].is_empty());
    for (case, cells) in table.cases.iter().enumerate() {
        let mut directed: HashMap<(u8, u8), i32> = HashMap::new();
        for t in cells {
            for k in 0..3 {
                *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
            }
        }
        // An edge between two crossings inside the cube is shared; one along a face is not.
        for &(a, b) in directed.keys() {
            if !directed.contains_key(&(b, a)) {
                let (ea, eb) = (table.edges[a as usize], table.edges[b as usize]);
                let on_face = (0..3).any(|axis| {
                    let bit = 1 << axis;
                    let side = |(c, ax): (usize, usize)| (ax != axis).then_some(c & bit);
                    side(ea).is_some() && side(ea) == side(eb)
                });
                assert!(
                    on_face,
                    "case {case}: edge {a}→{b} crosses the cube's inside unmatched"
                );
            }
        }
    }
}

#[test]
fn the_mesh_is_the_same_on_one_and_two_threads() {
    let points = cloud(3, 20_000, 7);
    let settings = SurfaceSettings::default();
    let on = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| reconstruct(&points, &settings).unwrap())
    };
    let (one, two) = (on(1), on(2));
    assert!(one.cell_count() > 1000);
    assert_eq!(one, two);
}

#[test]
fn a_cube_size_that_is_not_positive_or_makes_too_many_cubes_or_points_is_refused() {
    let points = ball(3, 0.05, 0.01, [0.0; 3]);
    for size in [0.0, -1.0, 1e-5] {
        let settings = SurfaceSettings {
            cubes: CubeRule::Size(size),
            ..SurfaceSettings::default()
        };
        let error = reconstruct(&points, &settings).unwrap_err().to_string();
        assert!(error.contains("cubes"), "{error}");
    }
    // A kernel 400 cubes wide makes blocks of 400³ points: refused before they are allocated.
    let settings = SurfaceSettings {
        radius: 20.0,
        cubes: CubeRule::Size(0.05),
        ..SurfaceSettings::default()
    };
    let error = reconstruct(&points, &settings).unwrap_err().to_string();
    assert!(
        error.contains("lattice points") && error.contains("limit of 1e9"),
        "{error}"
    );
}
