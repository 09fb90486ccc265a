use isph::scene::Scene;
use isph::simulation::Simulation;
fn main() {
    let scene = Scene::load(std::path::Path::new("scenes/hydrostatic_2d.toml")).unwrap();
    let steps: usize = std::env::args().nth(1).unwrap().parse().unwrap();
    let every: usize = std::env::args().nth(2).unwrap().parse().unwrap();
    let mut sim = Simulation::<2>::new(&scene).unwrap();
    for s in 1..=steps {
        sim.advance_towards(100.0).unwrap();
        if s % every != 0 {
            continue;
        }
        let p = &sim.particles;
        // original lattice ids of the top-left 3x3 corner: row r from top, col c
        print!("t={:.3} ", sim.time);
        for r in 0..6 {
            for c in [0usize, 20] {
                let id = (39 - r) * 40 + c;
                let i = p.id.iter().position(|&x| x == id as u64).unwrap();
                print!(
                    "[{r}{c} {:+.4},{:+.4} P{:.0}] ",
                    p.vel[0][i] * 1e3,
                    p.vel[1][i] * 1e3,
                    p.pressure[i]
                );
            }
        }
        println!();
    }
}
