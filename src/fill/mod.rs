//! Initial particles on a lattice of spacing dx anchored at the container's lower corner:
//! fluid blocks, the container's dummy wall layers, solid obstacles and rigid bodies. The fluid particles
//! are moved off their lattice points by a small deterministic perturbation, except near a free
//! surface (`perturbation`).

mod perturbation;

use crate::boundary::faces::Faces;
use crate::math::lattice::for_each_lattice_point;
use crate::particles::{Kind, NewParticle, Particles, NO_FLUID};
use crate::scene::{Block, BodyMass, Scene};
pub use perturbation::lattice_reach;
use perturbation::{perturbed, NearOpenSpace};

/// Particles of the scene at t = 0: fluid first (in block order), then walls, then each body's
/// particles (in the order of the scene's bodies, so that a body's ids are contiguous). No
/// fluid starts inside a body.
pub fn build<const D: usize>(scene: &Scene) -> Particles<D> {
    let dx = scene.spacing;
    let volume = dx.powi(D as i32);
    let layers = scene.wall_layers() as i64;
    let cells = container_cells::<D>(scene);
    let point = |k: [i64; D]| lattice_point(scene, k);
    let in_obstacle = |x: &[f64; D]| in_obstacle(scene, x);
    let kept_clear = |x: &[f64; D]| near_obstacle(scene, x) || in_a_body(scene, x);

    // What each lattice point holds, found once: the fluid's points, and the open space that
    // the perturbation keeps its distance from.
    let mut filling = Vec::with_capacity(cells.iter().product::<i64>() as usize);
    for_each_lattice_point(std::array::from_fn(|_| 0), cells, |k| {
        let x = point(k);
        filling.push(match (block_of(scene, &x), kept_clear(&x)) {
            (Some(b), false) => Filling::Fluid(b.fluid as u16),
            (None, false) => Filling::Open,
            (_, true) => Filling::Solid,
        });
    });
    let amplitude = scene.perturbation * dx;
    let on_lattice = (amplitude > 0.0).then(|| {
        let open = filling.iter().map(|f| *f == Filling::Open).collect();
        NearOpenSpace::new(cells, open, lattice_reach(scene), &scene.periodic)
    });
    let mut particles = Particles::<D>::default();
    let mut points = filling.into_iter();
    for_each_lattice_point(std::array::from_fn(|_| 0), cells, |k| {
        let Some(Filling::Fluid(f)) = points.next() else {
            return;
        };
        let (x, fluid) = (point(k), &scene.fluids[f as usize]);
        let pos = match &on_lattice {
            Some(near) if !near.contains(k) => perturbed(x, k, amplitude),
            _ => x,
        };
        particles.push(NewParticle {
            pos,
            kind: Kind::Fluid,
            normal: [0.0; D],
            fluid: f,
            mass: fluid.density * volume,
            rest_density: fluid.density,
            viscosity: fluid.viscosity,
        });
    });
    let faces = Faces::new(&scene.container, &scene.periodic, &scene.obstacles);
    let wall_density = scene.fluids[0].density;
    let wall = |x: [f64; D]| NewParticle {
        pos: x,
        kind: Kind::Wall,
        normal: faces.wall_normal(x),
        fluid: NO_FLUID,
        mass: wall_density * volume,
        rest_density: wall_density,
        viscosity: 0.0,
    };
    if let Some(field) = &scene.initial_velocity {
        for i in 0..particles.len() {
            let u = field.at(&scene.container, particles.position(i));
            for (axis, u) in particles.vel.iter_mut().zip(u) {
                axis[i] = u;
            }
        }
    }
    // Container walls: every lattice point within `layers` of the box, outside it; none across
    // a periodic axis.
    let margin = |d: usize| if scene.periodic[d] { 0 } else { layers };
    let outer_lo = std::array::from_fn(|d| -margin(d));
    let outer_hi = std::array::from_fn(|d| cells[d] + margin(d));
    for_each_lattice_point(outer_lo, outer_hi, |k| {
        if (0..D).any(|d| k[d] < 0 || k[d] >= cells[d]) {
            particles.push(wall(point(k)));
        }
    });
    // Obstacles: solid boxes of wall particles.
    for_each_lattice_point(std::array::from_fn(|_| 0), cells, |k| {
        let x = point(k);
        if in_obstacle(&x) {
            particles.push(wall(x));
        }
    });
    for (b, body) in scene.bodies.iter().enumerate() {
        let mut points = Vec::new();
        for_each_lattice_point(std::array::from_fn(|_| 0), cells, |k| {
            let x = point(k);
            if body.shape.contains(&x) {
                points.push(x);
            }
        });
        let mass = match body.mass {
            BodyMass::Density(density) => density * volume,
            BodyMass::Total(mass) => mass / points.len() as f64,
        };
        for x in points {
            particles.push(NewParticle {
                pos: x,
                kind: Kind::Body,
                normal: [0.0; D],
                fluid: b as u16,
                mass,
                rest_density: mass / volume,
                viscosity: scene.fluids[0].viscosity,
            });
        }
    }
    particles
}

/// How many lattice points of the fluid blocks each body keeps clear of fluid (inside it, and
/// clear of the obstacles and of the bodies before it).
pub fn displaced_by_bodies<const D: usize>(scene: &Scene) -> Vec<usize> {
    let mut displaced = vec![0; scene.bodies.len()];
    for_each_lattice_point([0; D], container_cells::<D>(scene), |k| {
        let x = lattice_point(scene, k);
        if block_of(scene, &x).is_none() || near_obstacle(scene, &x) {
            return;
        }
        let first = scene.bodies.iter().position(|b| b.shape.contains(&x));
        if let Some(b) = first {
            displaced[b] += 1;
        }
    });
    displaced
}

/// Whether x lies inside a body: no fluid particle starts there. The lattice points outside
/// keep their fluid, whose nearest body particle is then a spacing off, on the same lattice; one
/// less than a quarter spacing off a curved surface is moved there by the first step's contact
/// (`Bodies::keep_out`), by a fraction of that quarter. Leaving out the points within half a
/// spacing of the surface instead, as at an obstacle, left holes in the water beside a curved
/// body: water rushing into them stirred the still water around a neutral circle at 0.2 m/s in
/// its first step (docs/bodies.md, "Measured").
fn in_a_body<const D: usize>(scene: &Scene, x: &[f64; D]) -> bool {
    scene.bodies.iter().any(|b| b.shape.contains(x))
}

/// The block lattice point x belongs to: the first that holds it strictly inside. A point on
/// a block's face (within 1e-9 dx) belongs to the first block whose face it lies on when the
/// blocks cover more than half of its cell (counted at the centres of its 2^D sub-cells): two
/// blocks stacked on a face through a lattice plane leave no empty layer between them (which
/// fell in, or took a whole plane of fluid for free surface), while the face of a lone block
/// keeps its points out, as half their cell lies outside.
fn block_of<'a, const D: usize>(scene: &'a Scene, x: &[f64; D]) -> Option<&'a Block> {
    let blocks = &scene.blocks;
    if let Some(b) = blocks.iter().find(|b| b.contains(x)) {
        return Some(b);
    }
    let on_face = blocks
        .iter()
        .find(|b| b.region.contains_within(x, 1e-9 * scene.spacing))?;
    let quarter = 0.25 * scene.spacing;
    let covered = (0..1usize << D)
        .filter(|corner| {
            let probe: [f64; D] = std::array::from_fn(|d| {
                x[d] + if corner >> d & 1 == 1 {
                    quarter
                } else {
                    -quarter
                }
            });
            blocks.iter().any(|b| b.contains(&probe))
        })
        .count();
    (2 * covered > 1 << D).then_some(on_face)
}

/// Whether the fluid fills the container: every lattice point inside it and clear of the
/// obstacles and bodies holds a fluid particle. Incompressible fluid that fills a closed or periodic box
/// has no free surface, and can never make one.
pub fn fills_container<const D: usize>(scene: &Scene, particles: &Particles<D>) -> bool {
    let mut room = 0;
    for_each_lattice_point([0; D], container_cells::<D>(scene), |k| {
        let x = lattice_point(scene, k);
        room += !(near_obstacle(scene, &x) || in_a_body(scene, &x)) as usize;
    });
    particles.fluid_count() == room
}

/// What a lattice point of the container holds at t = 0.
#[derive(Clone, Copy, PartialEq)]
enum Filling {
    /// A fluid particle, of this fluid.
    Fluid(u16),
    /// Nothing: open space, above a free surface.
    Open,
    /// An obstacle or a body, or the half spacing kept clear beside an obstacle.
    Solid,
}

/// Lattice points per axis inside the container.
fn container_cells<const D: usize>(scene: &Scene) -> [i64; D] {
    let (lo, hi) = (&scene.container.min, &scene.container.max);
    std::array::from_fn(|d| ((hi[d] - lo[d]) / scene.spacing).round() as i64)
}

/// Lattice point k (per axis): container.min + (k + ½) dx.
fn lattice_point<const D: usize>(scene: &Scene, k: [i64; D]) -> [f64; D] {
    let lo = &scene.container.min;
    std::array::from_fn(|d| lo[d] + (k[d] as f64 + 0.5) * scene.spacing)
}

fn in_obstacle<const D: usize>(scene: &Scene, x: &[f64; D]) -> bool {
    scene.obstacles.iter().any(|o| o.contains(x))
}

/// Whether x lies inside an obstacle or less than half a spacing outside it: no fluid particle
/// starts there. With the obstacle's faces between lattice points (container.min + k dx) the
/// nearest fluid is half a spacing off, as at the container's walls; a face through lattice
/// points would otherwise put fluid on the face itself, pushed back and counted as crossing it
/// in the first step.
fn near_obstacle<const D: usize>(scene: &Scene, x: &[f64; D]) -> bool {
    let margin = 0.5 * scene.spacing * (1.0 - 1e-9);
    scene.obstacles.iter().any(|o| o.contains_within(x, margin))
}
