//! Checkpoint throughput (MB/s) of a 3D run of 10⁵ and 10⁶ particles: a durable write (temporary
//! file, fsync, rename, fsync of the folder) and a read (map, checksum, copy into the particle
//! arrays), the read both from the page cache and from disk (pages evicted first).

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use isph::io::checkpoint::{Checkpoint, RunState};
use isph::io::checkpoint_folder;
use isph::particles::{Kind, NewParticle, Particles};
use std::os::unix::io::AsRawFd;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// n particles on a cubic lattice, with velocities and pressures that are not all alike.
fn particles(n: usize) -> Particles<3> {
    let side = (n as f64).cbrt().ceil() as usize;
    let mut p = Particles::<3>::default();
    for k in 0..n {
        let pos = [k % side, (k / side) % side, k / (side * side)].map(|c| c as f64 * 0.01);
        p.push(NewParticle {
            pos,
            kind: if k % 10 == 0 { Kind::Wall } else { Kind::Fluid },
            normal: [0.0; 3],
            fluid: 0,
            mass: 1e-3,
            rest_density: 1000.0,
            viscosity: 1e-6,
        });
        p.vel[0][k] = (k as f64).sin();
        p.pressure[k] = k as f64;
    }
    p
}

fn state() -> RunState {
    RunState {
        step: 1,
        time: 0.5,
        dt: 1e-4,
        wall_seconds: 10.0,
        frames_written: 3,
        next_output: 3,
        scene_hash: 0,
        scene_path: PathBuf::from("/scenes/bench.toml"),
    }
}

/// Drops the file's pages from the page cache, so the next read comes from the disk.
fn evict(path: &Path) {
    let file = std::fs::File::open(path).unwrap();
    // SAFETY: a plain advisory call on an open descriptor.
    let r = unsafe { libc::posix_fadvise(file.as_raw_fd(), 0, 0, libc::POSIX_FADV_DONTNEED) };
    assert_eq!(r, 0, "posix_fadvise failed");
}

/// Reads a checkpoint into `p`, whose arrays already have its size, as on resume (where the
/// scene's particles are built first).
fn read(path: &Path, p: &mut Particles<3>) {
    let c = Checkpoint::open(path).unwrap();
    c.restore(p).unwrap();
}

fn bench(c: &mut Criterion, n: usize) {
    let dir = std::env::temp_dir().join(format!("isph-bench-checkpoint-{}", std::process::id()));
    let mut p = particles(n);
    let path = checkpoint_folder::save(&dir, &state(), &mut p, &[], 1).unwrap();
    let bytes = std::fs::metadata(&path).unwrap().len();
    let mut g = c.benchmark_group(format!("checkpoint_3d_{n}_particles"));
    g.sample_size(10)
        .measurement_time(Duration::from_secs(10))
        .throughput(Throughput::Bytes(bytes));
    g.bench_function("write (fsync, rename)", |b| {
        b.iter(|| checkpoint_folder::save(&dir, &state(), &mut p, &[], 1).unwrap())
    });
    g.bench_function("read (page cache)", |b| b.iter(|| read(&path, &mut p)));
    g.bench_function("read (from disk)", |b| {
        b.iter_batched(
            || evict(&path),
            |_| read(&path, &mut p),
            BatchSize::PerIteration,
        )
    });
    g.finish();
    std::fs::remove_dir_all(&dir).unwrap();
}

fn checkpoints(c: &mut Criterion) {
    bench(c, 100_000);
    bench(c, 1_000_000);
}

criterion_group!(benches, checkpoints);
criterion_main!(benches);
