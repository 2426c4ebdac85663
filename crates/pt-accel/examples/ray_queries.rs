//! pt-accel on the ray sets that `../shared/anchors/embree-direct` traces through Embree 4.
//!
//! Writes the mesh's triangles and two ray sets as `.npy` files (the format of
//! `../shared/anchors/README.md`), with pt-accel's closest-hit distances as the reference Embree
//! cross-checks, then times pt-accel on the same rays with the same harness as embree-direct
//! (one `intersect` or `occluded` call per ray, rays read from the same arrays, the median of
//! `REPS` repetitions, 1 and 2 threads) and prints the same table. Run the two programs in
//! turn, several times, on the same machine:
//!
//! ```text
//! PT_ASSETS_DIR=../shared/assets cargo run --release -p pt-accel --example ray_queries -- \
//!     meshes/stanford-bunny.obj /tmp/rays-bunny [REPS] [LAYOUT] [1t]
//! ~/.cache/pt-anchors/embree-direct/release/embree-direct /tmp/rays-bunny 5
//! ```
//!
//! Ray sets (1,000,000 rays each): `primary`, a 1000x1000 pinhole camera framing the mesh from
//! the front; `incoherent`, origins uniform in the mesh's bounds and directions uniform on the
//! sphere. `LAYOUT` is `eight` (the default), `four`, `wide` or `binary`, or `eight-lanes`: the
//! eight-wide BVH queried eight consecutive rays at a time (`Accel::intersect_lanes` and
//! `occluded_lanes`, one dispatch per eight rays, each answer the one-ray query's); a fifth argument `1t`
//! skips the two-thread runs; a sixth, `read`, traces the ray sets already in `DIR` instead and
//! writes nothing there (embree-direct may be reading the files at the same time).
//!
//! `MESH` may also be `bumpy-sphere`, a closed surface of 3,968 triangles made here (no asset):
//! its tree (under a megabyte) stays in the level-2 cache, so its incoherent rays (59% of
//! them hit it) time the kernels' arithmetic without waits on memory, and two runs of
//! one build agree within about 1% where the bunny's spread 5-25% on a busy machine.

use std::fs;
use std::io::Write;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use glam::Vec3;
use pt_accel::lanes::WIDTH;
use pt_accel::{Accel, AccelKind, AccelOptions, BvhLayout, Instance, Ray, RayLanes, TriangleMesh};
use rand::{Rng, SeedableRng};

const RAYS: usize = 1_000_000;

/// A closed sphere of 64 x 32 segments whose radius varies by 10% (`bumpy-sphere`).
fn bumpy_sphere() -> TriangleMesh {
    let (rings, segments) = (32u32, 64u32);
    let mut positions = Vec::new();
    for i in 0..=rings {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..segments {
            let phi = std::f32::consts::TAU * j as f32 / segments as f32;
            let r = 1.0 + 0.1 * (5.0 * theta).sin() * (7.0 * phi).cos();
            positions.push(Vec3::new(
                r * theta.sin() * phi.cos(),
                r * theta.cos(),
                r * theta.sin() * phi.sin(),
            ));
        }
    }
    let mut indices = Vec::new();
    for i in 0..rings {
        for j in 0..segments {
            let (a, b) = (i * segments + j, i * segments + (j + 1) % segments);
            let (c, d) = (a + segments, b + segments);
            // The poles' rings collapse to a point: no triangles of zero area there.
            if i > 0 {
                indices.push([a, b, d]);
            }
            if i + 1 < rings {
                indices.push([a, d, c]);
            }
        }
    }
    TriangleMesh::new(positions, indices).expect("a valid mesh")
}
/// Rays per work item on two threads, as embree-direct.
const CHUNK: usize = 4096;

fn primary(mesh: &TriangleMesh) -> Vec<Ray> {
    let (c, r) = mesh.bounds().bounding_sphere();
    let eye = c + Vec3::new(0.3, 0.2, 1.0).normalize() * r * 2.5;
    let f = (c - eye).normalize();
    let right = f.cross(Vec3::Y).normalize();
    let up = right.cross(f);
    let n = 1000;
    let h = 25f32.to_radians().tan();
    (0..n * n)
        .map(|i| {
            let (x, y) = ((i % n) as f32 + 0.5, (i / n) as f32 + 0.5);
            let d = f
                + right * ((2.0 * x / n as f32 - 1.0) * h)
                + up * ((1.0 - 2.0 * y / n as f32) * h);
            Ray::new(eye, d.normalize())
        })
        .collect()
}

fn incoherent(mesh: &TriangleMesh) -> Vec<Ray> {
    let b = mesh.bounds();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(1);
    (0..RAYS)
        .map(|_| {
            let o = b.min + b.diagonal() * Vec3::new(rng.random(), rng.random(), rng.random());
            let z: f32 = rng.random_range(-1.0..1.0);
            let phi: f32 = rng.random_range(0.0..std::f32::consts::TAU);
            let s = (1.0 - z * z).sqrt();
            Ray::new(o, Vec3::new(s * phi.cos(), s * phi.sin(), z))
        })
        .collect()
}

/// A little-endian float32 `.npy` file of the given shape.
fn write_npy(path: &Path, shape: &[usize], data: &[f32]) -> std::io::Result<()> {
    let dims: Vec<String> = shape.iter().map(usize::to_string).collect();
    let dims = if dims.len() == 1 {
        format!("{},", dims[0])
    } else {
        dims.join(", ")
    };
    let mut header = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': ({dims}), }}");
    // Pad so that the data starts at a multiple of 64 bytes, ending the header with a newline.
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut out = Vec::with_capacity(10 + header.len() + 4 * data.len());
    out.extend_from_slice(b"\x93NUMPY\x01\x00");
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    for v in data {
        out.extend_from_slice(&v.to_le_bytes());
    }
    fs::File::create(path)?.write_all(&out)
}

/// The data of a little-endian float32 `.npy` file (any shape).
fn read_npy(path: &Path) -> Result<Vec<f32>, Box<dyn std::error::Error>> {
    let b = fs::read(path)?;
    if b.len() < 10 || &b[..6] != b"\x93NUMPY" {
        return Err(format!("{}: not an .npy file", path.display()).into());
    }
    let header = 10 + u16::from_le_bytes([b[8], b[9]]) as usize;
    Ok(b[header..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect())
}

/// Origins and directions as flat arrays, as embree-direct reads them.
fn flatten(rays: &[Ray]) -> (Vec<f32>, Vec<f32>) {
    let o = rays.iter().flat_map(|r| r.origin.to_array()).collect();
    let d = rays.iter().flat_map(|r| r.dir.to_array()).collect();
    (o, d)
}

/// `f(first, end)` over `0..n` in chunks on `threads` threads (embree-direct's `par_for`).
fn par_for(threads: usize, n: usize, f: impl Fn(usize, usize) + Sync) {
    if threads <= 1 {
        f(0, n);
        return;
    }
    let next = AtomicUsize::new(0);
    std::thread::scope(|s| {
        for _ in 0..threads {
            s.spawn(|| {
                loop {
                    let a = next.fetch_add(CHUNK, Ordering::Relaxed);
                    if a >= n {
                        break;
                    }
                    f(a, (a + CHUNK).min(n));
                }
            });
        }
    });
}

#[inline(always)]
fn ray_at(o: &[f32], d: &[f32], i: usize) -> Ray {
    Ray::new(
        Vec3::new(o[i * 3], o[i * 3 + 1], o[i * 3 + 2]),
        Vec3::new(d[i * 3], d[i * 3 + 1], d[i * 3 + 2]),
    )
}

/// Rays `a..b` (at most eight) as the lane queries take them, and the mask of the lanes used.
#[inline(always)]
fn rays_at(o: &[f32], d: &[f32], a: usize, b: usize) -> (RayLanes, u32) {
    let mut rays = RayLanes::splat(Ray::new(Vec3::ZERO, Vec3::Z));
    for k in 0..WIDTH {
        rays.set(k, &ray_at(o, d, (a + k).min(b - 1)));
    }
    (rays, (1u32 << (b - a)) - 1)
}

/// Answer every ray with `one` (a query per ray) or, with `lanes`, with `eight` (up to eight
/// rays per query, the lanes in its mask), storing each answer; the elapsed time.
fn run(
    o: &[f32],
    d: &[f32],
    threads: usize,
    out: &[AtomicF32],
    lanes: bool,
    one: impl Fn(&Ray) -> f32 + Sync,
    eight: impl Fn(&RayLanes, u32) -> [f32; WIDTH] + Sync,
) -> Duration {
    let start = Instant::now();
    par_for(threads, out.len(), |a, b| {
        if lanes {
            for i in (a..b).step_by(WIDTH) {
                let (rays, mask) = rays_at(o, d, i, (i + WIDTH).min(b));
                let answers = eight(&rays, mask);
                for k in pt_accel::lanes::bits(mask) {
                    out[i + k].store(answers[k]);
                }
            }
        } else {
            for i in a..b {
                out[i].store(one(&ray_at(o, d, i)));
            }
        }
    });
    start.elapsed()
}

/// A float written by one thread per index (the results must be stored for the work to count).
struct AtomicF32(std::sync::atomic::AtomicU32);

impl AtomicF32 {
    fn store(&self, v: f32) {
        self.0.store(v.to_bits(), Ordering::Relaxed);
    }
    fn load(&self) -> f32 {
        f32::from_bits(self.0.load(Ordering::Relaxed))
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args
        .first()
        .cloned()
        .unwrap_or_else(|| "meshes/stanford-bunny.obj".into());
    let dir = args
        .get(1)
        .cloned()
        .unwrap_or_else(|| "/tmp/pt-rays".into());
    let reps: usize = args.get(2).map_or(Ok(5), |s| s.parse())?;
    let lanes = args.get(3).is_some_and(|a| a == "eight-lanes");
    let layout = match args.get(3).map_or("eight", String::as_str) {
        "eight" | "eight-lanes" => BvhLayout::Eight,
        "four" => BvhLayout::Four,
        "wide" => BvhLayout::Wide,
        "binary" => BvhLayout::Binary,
        other => return Err(format!("unknown layout {other}").into()),
    };
    let one_thread = args.get(4).is_some_and(|a| a == "1t");
    let mesh = if name == "bumpy-sphere" {
        bumpy_sphere()
    } else {
        pt_scene::load_mesh(pt_scene::find_asset(&name)?)?
            .geometry()
            .clone()
    };
    let dir = Path::new(&dir);
    fs::create_dir_all(dir)?;

    // `read` leaves `DIR`'s files alone, so that embree-direct can read them at the same time.
    let read = args.get(5).is_some_and(|a| a == "read");
    if !read {
        let tris: Vec<f32> = (0..mesh.triangle_count())
            .flat_map(|i| mesh.triangle(i).into_iter().flat_map(|v| v.to_array()))
            .collect();
        write_npy(&dir.join("tris.npy"), &[mesh.triangle_count(), 9], &tris)?;
    }

    let build = |_| {
        Accel::build(
            &[&mesh],
            &[Instance::new(0)],
            &AccelOptions::new().kind(AccelKind::Bvh).layout(layout),
        )
    };
    let accel = build(());
    let build_ms = median(
        (0..5)
            .map(|_| build(()).stats().build_time.as_secs_f64() * 1e3)
            .collect(),
    );
    println!(
        "# pt-accel {layout:?}: {} triangles, {name}, {} nodes, {:.1} MiB",
        mesh.triangle_count(),
        accel.stats().nodes,
        accel.stats().memory_bytes as f64 / (1 << 20) as f64
    );
    println!(
        "| pt layout | build ms | ray set | closest 1T | closest 2T | occl 1T | occl 2T | hit% | occl = hit |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for (set, rays) in [
        ("primary", primary(&mesh)),
        ("incoherent", incoherent(&mesh)),
    ] {
        let (o, d) = if read {
            (
                read_npy(&dir.join(format!("{set}_o.npy")))?,
                read_npy(&dir.join(format!("{set}_d.npy")))?,
            )
        } else {
            flatten(&rays)
        };
        let n = o.len() / 3;
        if !read {
            write_npy(&dir.join(format!("{set}_o.npy")), &[n, 3], &o)?;
            write_npy(&dir.join(format!("{set}_d.npy")), &[n, 3], &d)?;
        }
        let t: Vec<AtomicF32> = (0..n)
            .map(|_| AtomicF32(std::sync::atomic::AtomicU32::new(0)))
            .collect();
        let oc: Vec<AtomicF32> = (0..n)
            .map(|_| AtomicF32(std::sync::atomic::AtomicU32::new(0)))
            .collect();
        let measure = |threads: usize, occl: bool| -> f64 {
            // Closest hits store their distance (infinite for a miss), any-hit queries 1 when
            // blocked.
            let dist = |h: Option<pt_accel::Hit>| h.map_or(f32::INFINITY, |h| h.t);
            let blocked = |b: bool| f32::from(u8::from(b));
            let pass = || {
                if occl {
                    run(
                        &o,
                        &d,
                        threads,
                        &oc,
                        lanes,
                        |ray| blocked(accel.occluded(ray)),
                        |rays, mask| {
                            let hit = accel.occluded_lanes(rays, mask);
                            std::array::from_fn(|k| blocked(hit & (1 << k) != 0))
                        },
                    )
                } else {
                    run(
                        &o,
                        &d,
                        threads,
                        &t,
                        lanes,
                        |ray| dist(accel.intersect(ray)),
                        |rays, mask| accel.intersect_lanes(rays, mask).map(dist),
                    )
                }
            };
            pass();
            if std::env::var_os("PT_BEST").is_some() {
                return (0..reps)
                    .map(|_| n as f64 / pass().as_secs_f64() / 1e6)
                    .fold(0.0, f64::max);
            }
            median(
                (0..reps)
                    .map(|_| n as f64 / pass().as_secs_f64() / 1e6)
                    .collect(),
            )
        };
        let c1 = measure(1, false);
        let c2 = if one_thread { 0.0 } else { measure(2, false) };
        let o1 = measure(1, true);
        let o2 = if one_thread { 0.0 } else { measure(2, true) };
        let reference: Vec<f32> = t.iter().map(AtomicF32::load).collect();
        if !read {
            write_npy(
                &dir.join(format!("reference_t_{set}.npy")),
                &[n],
                &reference,
            )?;
        }
        let hits = reference.iter().filter(|v| v.is_finite()).count();
        let agree = reference
            .iter()
            .zip(&oc)
            .all(|(t, o)| t.is_finite() == (o.load() != 0.0));
        println!(
            "| {layout:?} | {build_ms:.2} | {set} | {c1:.2} | {c2:.2} | {o1:.2} | {o2:.2} | {:.1} | {agree} |",
            100.0 * hits as f64 / n as f64
        );
    }
    Ok(())
}
