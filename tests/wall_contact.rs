//! `wall::face_contact`, the hard contact at the end of a step: a particle that crossed a face, or
//! came closer to it than `gap`, is put back `gap` inside and keeps no velocity into the face; one
//! that did not is left alone. Only the crossings count as penetrations.

use isph::scene::Aabb;
use isph::wall::{face_contact, Contact};

fn aabb(min: [f64; 2], max: [f64; 2]) -> Aabb {
    Aabb {
        min: min.to_vec(),
        max: max.to_vec(),
    }
}

#[test]
fn a_particle_beyond_the_container_is_put_back_inside() {
    let container = aabb([0.0, 0.0], [1.0, 1.0]);
    let (mut x, mut u) = ([-0.01, 1.02], [-2.0, 0.5]);
    assert_eq!(
        face_contact(&container, [false; 2], &[], 0.1, &mut x, &mut u),
        Contact::Crossed
    );
    assert_eq!(x, [0.1, 0.9]);
    // Beyond the left and the top face: both velocity components point into their faces.
    assert_eq!(u, [0.0, 0.0]);
    let (mut x, mut u) = ([1.5, 0.5], [-1.0, 0.3]);
    assert_eq!(
        face_contact(&container, [false; 2], &[], 0.1, &mut x, &mut u),
        Contact::Crossed
    );
    assert_eq!(
        (x, u),
        ([0.9, 0.5], [-1.0, 0.3]),
        "moving away from the face: velocity kept"
    );
}

#[test]
fn a_particle_inside_an_obstacle_leaves_through_the_nearest_face() {
    let container = aabb([0.0, 0.0], [1.0, 1.0]);
    let obstacle = aabb([0.4, 0.0], [0.6, 0.3]);
    let (mut x, mut u) = ([0.45, 0.28], [0.2, -1.0]);
    assert_eq!(
        face_contact(
            &container,
            [false; 2],
            &[obstacle.clone()],
            0.01,
            &mut x,
            &mut u
        ),
        Contact::Crossed
    );
    assert!(
        (x[0] - 0.45).abs() < 1e-15 && (x[1] - 0.31).abs() < 1e-12,
        "{x:?}"
    );
    assert_eq!(u, [0.2, 0.0]);
    let (mut x, mut u) = ([0.405, 0.1], [1.0, 0.0]);
    assert_eq!(
        face_contact(&container, [false; 2], &[obstacle], 0.01, &mut x, &mut u),
        Contact::Crossed
    );
    assert!((x[0] - 0.39).abs() < 1e-12, "{x:?}");
    assert_eq!(u, [0.0, 0.0]);
}

#[test]
fn a_particle_clear_of_every_face_is_left_alone() {
    let container = aabb([0.0, 0.0], [1.0, 1.0]);
    let obstacle = aabb([0.4, 0.0], [0.6, 0.3]);
    let (mut x, mut u) = ([0.2, 0.5], [3.0, -4.0]);
    assert_eq!(
        face_contact(&container, [false; 2], &[obstacle], 0.05, &mut x, &mut u),
        Contact::Clear
    );
    assert_eq!((x, u), ([0.2, 0.5], [3.0, -4.0]));
}

#[test]
fn a_particle_closer_than_the_gap_is_put_back_but_did_not_cross() {
    let container = aabb([0.0, 0.0], [1.0, 1.0]);
    let (mut x, mut u) = ([0.5, 0.02], [0.1, -0.3]);
    assert_eq!(
        face_contact(&container, [false; 2], &[], 0.05, &mut x, &mut u),
        Contact::Near
    );
    assert_eq!((x, u), ([0.5, 0.05], [0.1, 0.0]));
}
