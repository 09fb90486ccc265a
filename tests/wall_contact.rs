//! The walls' faces (`faces`): the hard contact at the end of a step (a particle that crossed a
//! face, or came closer to it than `gap`, is put back `gap` inside and keeps no velocity into the
//! face; one that did not is left alone; only the crossings count as penetrations), the
//! kinematic condition of the particles touching a face, and the wall particles' normals.

use isph::boundary::faces::{Contact, Faces};
use isph::scene::Aabb;

fn aabb(min: [f64; 2], max: [f64; 2]) -> Aabb {
    Aabb {
        min: min.to_vec(),
        max: max.to_vec(),
    }
}

/// The unit box with these obstacles.
fn faces(obstacles: &[Aabb]) -> Faces {
    Faces {
        container: aabb([0.0, 0.0], [1.0, 1.0]),
        periodic: vec![false; 2],
        obstacles: obstacles.to_vec(),
    }
}

#[test]
fn a_particle_beyond_the_container_is_put_back_inside() {
    let (mut x, mut u) = ([-0.01, 1.02], [-2.0, 0.5]);
    assert_eq!(faces(&[]).contact(0.1, &mut x, &mut u), Contact::Crossed);
    assert_eq!(x, [0.1, 0.9]);
    // Beyond the left and the top face: both velocity components point into their faces.
    assert_eq!(u, [0.0, 0.0]);
    let (mut x, mut u) = ([1.5, 0.5], [-1.0, 0.3]);
    assert_eq!(faces(&[]).contact(0.1, &mut x, &mut u), Contact::Crossed);
    assert_eq!(
        (x, u),
        ([0.9, 0.5], [-1.0, 0.3]),
        "moving away from the face: velocity kept"
    );
}

#[test]
fn a_particle_inside_an_obstacle_leaves_through_the_nearest_face() {
    let obstacle = aabb([0.4, 0.0], [0.6, 0.3]);
    let (mut x, mut u) = ([0.45, 0.28], [0.2, -1.0]);
    assert_eq!(
        faces(std::slice::from_ref(&obstacle)).contact(0.01, &mut x, &mut u),
        Contact::Crossed
    );
    assert!(
        (x[0] - 0.45).abs() < 1e-15 && (x[1] - 0.31).abs() < 1e-12,
        "{x:?}"
    );
    assert_eq!(u, [0.2, 0.0]);
    let (mut x, mut u) = ([0.405, 0.1], [1.0, 0.0]);
    assert_eq!(
        faces(&[obstacle]).contact(0.01, &mut x, &mut u),
        Contact::Crossed
    );
    assert!((x[0] - 0.39).abs() < 1e-12, "{x:?}");
    assert_eq!(u, [0.0, 0.0]);
}

#[test]
fn a_particle_clear_of_every_face_is_left_alone() {
    let obstacle = aabb([0.4, 0.0], [0.6, 0.3]);
    let (mut x, mut u) = ([0.2, 0.5], [3.0, -4.0]);
    assert_eq!(
        faces(&[obstacle]).contact(0.05, &mut x, &mut u),
        Contact::Clear
    );
    assert_eq!((x, u), ([0.2, 0.5], [3.0, -4.0]));
}

#[test]
fn a_particle_closer_than_the_gap_is_put_back_but_did_not_cross() {
    let (mut x, mut u) = ([0.5, 0.02], [0.1, -0.3]);
    assert_eq!(faces(&[]).contact(0.05, &mut x, &mut u), Contact::Near);
    assert_eq!((x, u), ([0.5, 0.05], [0.1, 0.0]));
}

#[test]
fn an_obstacle_on_the_floor_has_no_face_there() {
    // The obstacle stands on the container's floor: a particle inside it near its bottom
    // leaves through its side, not through the floor, and the wall particles of its bottom
    // row take the normal of the face the fluid meets.
    let obstacle = aabb([0.4, 0.0], [0.6, 0.3]);
    let f = faces(&[obstacle]);
    let (mut x, mut u) = ([0.43, 0.02], [1.0, -1.0]);
    assert_eq!(f.contact(0.01, &mut x, &mut u), Contact::Crossed);
    assert!((x[0] - 0.39).abs() < 1e-12 && x[1] == 0.02, "{x:?}");
    assert_eq!(u, [0.0, -1.0]);
    assert_eq!(f.wall_normal([0.425, 0.025]), [-1.0, 0.0]);
}

#[test]
fn an_obstacle_edge_particle_has_the_diagonal_normal() {
    let f = faces(&[aabb([0.4, 0.0], [0.6, 0.3])]);
    let n = f.wall_normal([0.425, 0.275]);
    let h = std::f64::consts::FRAC_1_SQRT_2;
    assert!(
        (n[0] + h).abs() < 1e-12 && (n[1] - h).abs() < 1e-12,
        "{n:?}"
    );
    assert_eq!(f.wall_normal([0.5, 0.29]), [0.0, 1.0]);
}

#[test]
fn a_particle_touching_a_face_keeps_no_velocity_into_it() {
    let f = faces(&[aabb([0.4, 0.0], [0.6, 0.3])]);
    // On the floor: the downward part goes, the rest stays.
    assert_eq!(
        f.no_penetration([0.2, 0.004], [1.0, -2.0], 0.005),
        [1.0, 0.0]
    );
    assert_eq!(
        f.no_penetration([0.2, 0.004], [1.0, 2.0], 0.005),
        [1.0, 2.0]
    );
    // In front of the obstacle's left face, and off its top-left edge (towards the edge).
    assert_eq!(
        f.no_penetration([0.397, 0.1], [3.0, 1.0], 0.005),
        [0.0, 1.0]
    );
    let v = f.no_penetration([0.398, 0.302], [1.0, -1.0], 0.005);
    assert!(v[0].abs() < 1e-12 && v[1].abs() < 1e-12, "{v:?}");
    // Out of reach: untouched.
    assert_eq!(
        f.no_penetration([0.3, 0.5], [3.0, -4.0], 0.005),
        [3.0, -4.0]
    );
}

/// An obstacle whose faces pass through lattice points (x = 0.05 = container.min + 2.5 dx):
/// no fluid particle starts on a face or closer than half a spacing to it, and none crosses it.
/// It guards against fluid starting on the faces, which the contact pushes back and counts as
/// crossings (docs/scene-format.md, "`[[obstacle]]`").
#[test]
fn an_obstacle_with_faces_through_lattice_points_starts_and_stays_clear_of_fluid() {
    let text = crate::common::water_block_scene(0.1).replace(
        "[container]",
        "[[obstacle]]\nmin = [0.05, 0.05]\nmax = [0.13, 0.11]\n\n[container]",
    );
    let scene = crate::common::scene_from_text(&text);
    let dir = crate::common::TempDir::new("obstacle-faces");
    crate::common::run_scene(&scene, dir.path(), 0.1);
    let kind: Vec<i32> = crate::common::read_frame(dir.path(), 0, "kind");
    let pos: Vec<f64> = crate::common::read_frame(dir.path(), 0, "position");
    let (lo, hi, half) = ([0.05, 0.05], [0.13, 0.11], 0.5 * 0.02 * (1.0 - 1e-9));
    for i in (0..kind.len()).filter(|&i| kind[i] == 0) {
        let x = [pos[3 * i], pos[3 * i + 1]];
        let near = (0..2).all(|d| x[d] > lo[d] - half && x[d] < hi[d] + half);
        assert!(
            !near,
            "fluid particle at {x:?} starts within half a spacing of the obstacle"
        );
    }
    let crossings: f64 = crate::common::stats_column(dir.path(), "penetrations")
        .iter()
        .sum();
    assert_eq!(crossings, 0.0);
}
