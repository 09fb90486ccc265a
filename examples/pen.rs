use isph::scene::Scene;
use isph::simulation::Simulation;
fn main() {
    let scene = Scene::load(std::path::Path::new("scenes/dam_break_2d.toml")).unwrap();
    let steps: usize = std::env::args().nth(1).unwrap().parse().unwrap();
    let id: u64 = std::env::args()
        .nth(2)
        .map(|s| s.parse().unwrap())
        .unwrap_or(u64::MAX);
    let mut sim = Simulation::<2>::new(&scene).unwrap();
    for s in 1..=steps {
        sim.advance_towards(100.0).unwrap();
        let p = &sim.particles;
        if id != u64::MAX && s + 12 > steps {
            let i = p.id.iter().position(|&x| x == id).unwrap();
            println!(
                "step {s} id {id} x={:.5} y={:.5} v=({:.3},{:.3}) P={:.0} rho={:.0}",
                p.pos[0][i], p.pos[1][i], p.vel[0][i], p.vel[1][i], p.pressure[i], p.density[i]
            );
        }
    }
    let p = &sim.particles;
    let bad: Vec<u64> = (0..p.len())
        .filter(|&i| p.is_fluid(i) && (p.pos[1][i] < 0.0 || p.pos[0][i] < 0.0))
        .map(|i| p.id[i])
        .collect();
    println!("outside: {bad:?}");
}
