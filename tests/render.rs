//! `isph render`: PNGs of the asked size that are pictures (not blank), the same bytes every
//! time, one numbered file per frame with `--all`, a shaded surface in 3D, and bad input
//! refused with the path named.

use crate::common::{run_scene, scene_from_text, water_block_scene, water_block_scene_3d, TempDir};
use isph::io::frames::FrameReader;
use isph::io::surface_files::SurfaceWriter;
use isph::render::bounds::{self, Bounds};
use isph::render::field::nice_ceiling;
use isph::render::survey::Survey;
use isph::render::{render_run, view_3d, ColorField, FrameChoice, RenderError, RenderOptions};
use isph::surface::Mesh;
use std::path::{Path, PathBuf};

/// A 2D run of three frames (t = 0, 0.02, 0.04 s) of a 10 × 10 block collapsing.
fn run_2d(dir: &Path) -> PathBuf {
    let run = dir.join("run");
    run_scene(&scene_from_text(&water_block_scene(0.04)), &run, 0.04);
    run
}

/// A 3D run of two frames: a 6 × 4 × 6 block (dx = 0.02 m) in a small closed tank.
fn run_3d(dir: &Path) -> PathBuf {
    let text = water_block_scene_3d([0.12, 0.08, 0.12], [0.24, 0.08, 0.16], 0.01, 0.01, "");
    let run = dir.join("run");
    run_scene(&scene_from_text(&text), &run, 0.01);
    run
}

fn options(
    frames: FrameChoice,
    color: ColorField,
    size: (u32, u32),
    output: &Path,
) -> RenderOptions {
    RenderOptions {
        frames,
        color,
        size,
        output: output.to_owned(),
    }
}

/// Width, height and the number of distinct colours of a PNG file.
fn decode(path: &Path) -> (u32, u32, usize) {
    let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    let mut colours: Vec<&[u8]> = buf[..info.buffer_size()].chunks_exact(3).collect();
    colours.sort_unstable();
    colours.dedup();
    (info.width, info.height, colours.len())
}

fn render(run: &Path, opts: &RenderOptions) -> Vec<PathBuf> {
    render_run(run, opts).unwrap_or_else(|e| panic!("{e}"))
}

/// Renders one frame into the .png of `opts` twice: a picture of the asked size, not blank, the
/// same bytes both times.
fn assert_picture_of_its_size_twice_the_same(run: &Path, opts: &RenderOptions) {
    let (png, color) = (&opts.output, opts.color.name());
    assert_eq!(render(run, opts), vec![png.clone()]);
    let (w, h, colours) = decode(png);
    assert_eq!((w, h), opts.size, "{color}");
    // Viridis discs or shading, grey walls, anti-aliased text: far more than a blank's one colour.
    assert!(colours > 40, "{color}: {colours} colours");
    let first = std::fs::read(png).unwrap();
    render(run, opts);
    assert_eq!(std::fs::read(png).unwrap(), first, "{color} bytes differ");
}

#[test]
fn a_2d_frame_is_a_picture_of_the_asked_size_the_same_every_time() {
    let dir = TempDir::new("render-2d");
    let run = run_2d(dir.path());
    for (color, size) in [
        (ColorField::Pressure, (640, 400)),
        (ColorField::Speed, (333, 517)),
        (ColorField::Fluid, (800, 600)),
    ] {
        let png = dir.path().join(format!("{}.png", color.name()));
        let opts = options(FrameChoice::One(2), color, size, &png);
        assert_picture_of_its_size_twice_the_same(&run, &opts);
    }
}

#[test]
fn all_writes_one_numbered_png_per_frame_and_last_the_newest() {
    let dir = TempDir::new("render-all");
    let run = run_2d(dir.path());
    let out = dir.path().join("frames");
    let opts = options(FrameChoice::All, ColorField::Pressure, (320, 240), &out);
    let written = render(&run, &opts);
    let names: Vec<String> = written
        .iter()
        .map(|p| p.strip_prefix(&out).unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names,
        ["frame_000000.png", "frame_000001.png", "frame_000002.png"]
    );
    for path in &written {
        assert_eq!(decode(path).0, 320);
    }
    // The newest frame into a directory takes its number as its name.
    let opts = options(FrameChoice::Last, ColorField::Speed, (320, 240), &out);
    assert_eq!(render(&run, &opts), vec![out.join("frame_000002.png")]);
    // Nothing but the pictures is written.
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), 3);
}

#[test]
fn a_3d_frame_is_a_picture_of_the_asked_size_the_same_every_time() {
    let dir = TempDir::new("render-3d");
    let run = run_3d(dir.path());
    for color in [ColorField::Speed, ColorField::Pressure, ColorField::Fluid] {
        let png = dir.path().join(format!("{}.png", color.name()));
        let opts = options(FrameChoice::Last, color, (480, 360), &png);
        assert_picture_of_its_size_twice_the_same(&run, &opts);
    }
}

/// The pictures (the reconstructed surface included) are the same bytes whatever the number
/// of threads (habit 5 of STYLE.md).
#[test]
fn pictures_do_not_depend_on_the_thread_count() {
    let dir = TempDir::new("render-threads");
    let run = run_3d(dir.path());
    let bytes = |threads: usize, color: ColorField| {
        let png = dir.path().join(format!("{threads}-{}.png", color.name()));
        let opts = options(FrameChoice::Last, color, (320, 240), &png);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| render(&run, &opts));
        std::fs::read(&png).unwrap()
    };
    for color in [ColorField::Speed, ColorField::Pressure] {
        assert_eq!(bytes(1, color), bytes(2, color), "{}", color.name());
    }
}

/// A closed sphere of radius `r` around `c`, a UV mesh with outward normals, its velocity
/// growing with height.
fn sphere_mesh(c: [f64; 3], r: f64) -> Mesh {
    let (rings, segments) = (16, 32);
    let mut mesh = Mesh {
        dimensions: 3,
        ..Mesh::default()
    };
    for i in 0..=rings {
        let theta = std::f64::consts::PI * i as f64 / rings as f64;
        for j in 0..segments {
            let phi = 2.0 * std::f64::consts::PI * j as f64 / segments as f64;
            let n = [
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            ];
            mesh.positions
                .push(std::array::from_fn(|d| (c[d] + r * n[d]) as f32));
            mesh.normals.push(n.map(|x| x as f32));
            mesh.velocity.push([0.0, 0.0, (1.0 + n[2]) as f32]);
        }
    }
    let at = |i: usize, j: usize| (i * segments + j % segments) as u32;
    for i in 0..rings {
        for j in 0..segments {
            mesh.cells
                .extend([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            mesh.cells
                .extend([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    mesh
}

/// The surface rasteriser on a mesh made by hand (until the run's own surface is
/// reconstructed): a ball of water drawn shaded and coloured by speed, in front of the floor,
/// where the particles alone would draw no ball.
#[test]
fn a_surface_mesh_is_drawn_shaded_and_coloured_by_speed() {
    let dir = TempDir::new("render-mesh");
    let run = run_3d(dir.path());
    let reader = FrameReader::open(&run).unwrap();
    let frame = reader.read(0).unwrap();
    let mut survey = Survey::new(3, 0.02, ColorField::Speed);
    survey.add(&frame);
    survey.colouring.max = 2.0;
    assert!(view_3d::shows_surface(&survey));
    let ball = sphere_mesh([0.12, 0.04, 0.08], 0.05);
    let image = view_3d::draw(&frame, &ball, &survey, (400, 300)).unwrap();
    let again = view_3d::draw(&frame, &ball, &survey, (400, 300)).unwrap();
    assert_eq!(image, again);
    // The ball is where the camera looks, coloured from the low end of viridis at its bottom
    // to the top at its top: shading and interpolation make many colours of it.
    let middle = image.get(image.width as i32 * 2 / 5, image.height as i32 / 2);
    assert_ne!(middle, [255; 3], "nothing drawn in the middle");
    let mut colours: Vec<[u8; 3]> = (0..image.height as i32)
        .flat_map(|y| (0..image.width as i32).map(move |x| (x, y)))
        .map(|(x, y)| image.get(x, y))
        .collect();
    colours.sort_unstable();
    colours.dedup();
    assert!(colours.len() > 500, "{} colours", colours.len());
    // With no surface (an empty mesh), the fluid particles are drawn instead.
    let empty = Mesh {
        dimensions: 3,
        ..Mesh::default()
    };
    let particles = view_3d::draw(&frame, &empty, &survey, (400, 300)).unwrap();
    assert_ne!(particles, image);
    let inked = particles
        .rgb
        .chunks_exact(3)
        .filter(|c| c != &[255; 3])
        .count();
    assert!(inked > 400 * 300 / 20, "{inked} pixels drawn");
}

/// A surface that surface.h5 holds for a frame (from `isph surface`) is drawn rather than one
/// reconstructed; pictures of particles do not read it.
#[test]
fn a_stored_surface_is_drawn_in_place_of_a_reconstructed_one() {
    let dir = TempDir::new("render-stored");
    let run = run_3d(dir.path());
    let bytes = |color: ColorField| {
        let png = dir.path().join(format!("{}.png", color.name()));
        render(&run, &options(FrameChoice::Last, color, (320, 240), &png));
        std::fs::read(&png).unwrap()
    };
    let (speed, pressure) = (bytes(ColorField::Speed), bytes(ColorField::Pressure));
    let time = FrameReader::open(&run).unwrap().times().unwrap()[1];
    let mut writer = SurfaceWriter::create(&run).unwrap();
    writer
        .write(1, time, &sphere_mesh([0.12, 0.04, 0.08], 0.05), false)
        .unwrap();
    drop(writer);
    assert_ne!(bytes(ColorField::Speed), speed);
    assert_eq!(bytes(ColorField::Pressure), pressure);
}

#[test]
fn bad_input_is_refused_with_the_path_named() {
    let dir = TempDir::new("render-bad");
    let run = run_2d(dir.path());
    let out = dir.path().join("out.png");
    let opts = |frames, size| options(frames, ColorField::Pressure, size, &out);
    let message = |run: &Path, opts: RenderOptions| match render_run(run, &opts) {
        Ok(paths) => panic!("rendered {paths:?}"),
        Err(e) => (e.to_string(), e),
    };

    let empty = dir.path().join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let (text, e) = message(&empty, opts(FrameChoice::Last, (64, 64)));
    assert!(matches!(e, RenderError::NoRun { .. }), "{e:?}");
    assert!(
        text.contains(&*empty.to_string_lossy()) && text.contains("particles.h5"),
        "{text}"
    );

    let (text, e) = message(&run, opts(FrameChoice::One(7), (64, 64)));
    assert!(matches!(e, RenderError::NoSuchFrame { .. }), "{e:?}");
    assert!(
        text.contains("frame 7") && text.contains("3 frames") && text.contains("run"),
        "{text}"
    );

    for size in [(0, 100), (100, 0), (16385, 100)] {
        let (text, e) = message(&run, opts(FrameChoice::Last, size));
        assert!(matches!(e, RenderError::Size { .. }), "{e:?}");
        assert!(text.contains(&format!("{}x{}", size.0, size.1)), "{text}");
    }

    let (text, e) = message(&run, opts(FrameChoice::All, (64, 64)));
    assert!(matches!(e, RenderError::SequenceIntoFile { .. }), "{e:?}");
    assert!(
        text.contains("out.png") && text.contains("3 frames"),
        "{text}"
    );

    // A file that is not a PNG is never written over, whatever its name.
    std::fs::write(&out, "notes").unwrap();
    let (text, e) = message(&run, opts(FrameChoice::Last, (64, 64)));
    assert!(matches!(e, RenderError::NotPng { .. }), "{e:?}");
    assert!(text.contains("out.png"), "{text}");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "notes");

    // The run's own files as the output: a file where a directory is wanted.
    let stats = run.join("stats.csv");
    let before = std::fs::read(&stats).unwrap();
    let (text, e) = message(
        &run,
        options(FrameChoice::All, ColorField::Speed, (64, 64), &stats),
    );
    assert!(matches!(e, RenderError::NotADirectory { .. }), "{e:?}");
    assert!(text.contains("stats.csv"), "{text}");
    assert_eq!(std::fs::read(&stats).unwrap(), before);
}

#[test]
fn colour_scales_end_on_round_numbers() {
    assert_eq!(nice_ceiling(1121.0), 1200.0);
    assert_eq!(nice_ceiling(1200.0), 1200.0);
    assert_eq!(nice_ceiling(0.0031), 0.004);
    assert_eq!(nice_ceiling(7.2e4), 8e4);
    assert_eq!(nice_ceiling(0.0), 1.0);
    assert_eq!(nice_ceiling(f64::NAN), 1.0);
}

/// The container's inner box comes back from its wall layers: three layers of lattice points
/// (at half-spacing offsets, as `fill` places them) around a 10 × 4 × 6 box.
#[test]
fn the_container_is_found_inside_its_wall_layers() {
    let dx = 0.1;
    let (n, layers) = ([10i64, 4, 6], 3i64);
    let mut walls = Vec::new();
    for i in -layers..n[0] + layers {
        for j in -layers..n[1] + layers {
            for k in -layers..n[2] + layers {
                let inside = [i, j, k].iter().zip(&n).all(|(&c, &n)| c >= 0 && c < n);
                if !inside {
                    walls.push([i, j, k].map(|c| (c as f64 + 0.5) * dx));
                }
            }
        }
    }
    let inner = bounds::container(&walls, dx, 3).unwrap();
    let expected = Bounds {
        min: [0.0; 3],
        max: n.map(|c| c as f64 * dx),
    };
    for d in 0..3 {
        assert!((inner.min[d] - expected.min[d]).abs() < 1e-9, "{inner:?}");
        assert!((inner.max[d] - expected.max[d]).abs() < 1e-9, "{inner:?}");
    }
}
