//! Helpers shared by the end-to-end tests: simple geometry and the statistics that turn sample
//! counts into tolerances.

#![allow(dead_code)]

use pt::pt_core::Mesh;

/// Mean and sample standard deviation.
pub fn mean_std(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, var.sqrt())
}

/// Two-sided standard normal quantile for a family of `tests` tests at overall significance
/// `alpha` with the Šidák correction: |z| beyond this rejects.
pub fn sidak_z(alpha: f64, tests: usize) -> f64 {
    let per_test = 1.0 - (1.0 - alpha).powf(1.0 / tests as f64);
    normal_quantile(1.0 - per_test / 2.0)
}

/// Standard normal quantile (Acklam's rational approximation, relative error < 1.2e-9).
pub fn normal_quantile(p: f64) -> f64 {
    assert!(p > 0.0 && p < 1.0);
    const A: [f64; 6] = [
        -3.969683028665376e1,
        2.209460984245205e2,
        -2.759285104469687e2,
        1.38357751867269e2,
        -3.066479806614716e1,
        2.506628277459239,
    ];
    const B: [f64; 5] = [
        -5.447609879822406e1,
        1.615858368580409e2,
        -1.556989798598866e2,
        6.680131188771972e1,
        -1.328068155288572e1,
    ];
    const C: [f64; 6] = [
        -7.784894002430293e-3,
        -3.223964580411365e-1,
        -2.400758277161838,
        -2.549732539343734,
        4.374664141464968,
        2.938163982698783,
    ];
    const D: [f64; 4] = [
        7.784695709041462e-3,
        3.224671290700398e-1,
        2.445134137142996,
        3.754408661907416,
    ];
    let q_low = 0.02425;
    if p < q_low {
        let q = (-2.0 * p.ln()).sqrt();
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    } else if p <= 1.0 - q_low {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    } else {
        -normal_quantile(1.0 - p)
    }
}

#[test]
fn normal_quantile_is_right() {
    assert!((normal_quantile(0.975) - 1.959964).abs() < 1e-5);
    assert!((normal_quantile(0.5)).abs() < 1e-9);
    assert!((sidak_z(0.01, 1) - 2.575829).abs() < 1e-5);
}

/// `pt_scene::shapes::sphere` without its vertex normals: shading uses the flat facets, so tests
/// exercise the BSDFs and the integrator, not shading-normal approximations.
pub fn uv_sphere(radius: f32, rings: u32, segments: u32) -> Mesh {
    Mesh::new(
        pt::pt_scene::shapes::sphere(radius, rings, segments)
            .geometry()
            .clone(),
    )
}

/// Every `.rs` file of the library crates (the facade and the three crates), for tests that
/// check properties of the sources themselves.
pub fn workspace_sources() -> Vec<std::path::PathBuf> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    for dir in [
        "src",
        "crates/pt-accel/src",
        "crates/pt-core/src",
        "crates/pt-scene/src",
    ] {
        collect_rs(&root.join(dir), &mut files);
    }
    assert!(
        files.len() > 20,
        "sources not found under {}",
        root.display()
    );
    files.sort();
    files
}

fn collect_rs(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        if p.is_dir() {
            collect_rs(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// The built example `name`, beside this test binary (`target/<profile>/examples/`), or `None`
/// (after saying so) when it is not built and the run does not require it.
pub fn example(name: &str) -> Option<std::path::PathBuf> {
    let exe = std::env::current_exe().unwrap();
    let dir = exe
        .parent()
        .and_then(std::path::Path::parent)
        .unwrap()
        .join("examples");
    let path = dir.join(format!("{name}{}", std::env::consts::EXE_SUFFIX));
    if path.is_file() {
        return Some(path);
    }
    let msg = format!(
        "example {name} is not built ({} missing): run `cargo build --workspace --bins --examples` (or `--example {name}`) first",
        path.display()
    );
    if std::env::var("PT_REQUIRE_ASSETS").is_ok_and(|v| v == "1") {
        panic!("{msg}");
    }
    // Straight to the terminal: cargo test shows this even for a passing test.
    use std::io::Write;
    let _ = writeln!(std::io::stderr(), "SKIPPED: {msg}");
    None
}

/// A folder of its own for one test under the system's temporary folder, `pt-NAME-PID`:
/// emptied when made, removed when dropped, so that test runs leave nothing behind. A test that
/// fails keeps it (its path is printed) for a look at what it wrote.
pub struct Scratch(std::path::PathBuf);

impl Scratch {
    pub fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("pt-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir)
            .unwrap_or_else(|e| panic!("cannot make {}: {e}", dir.display()));
        Self(dir)
    }
}

impl std::ops::Deref for Scratch {
    type Target = std::path::PathBuf;
    fn deref(&self) -> &std::path::PathBuf {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if std::thread::panicking() {
            eprintln!("kept {} (the test failed)", self.0.display());
        } else {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}
