//! Command-line handling shared by the examples (DESIGN.md section 8): `--spp N`, `--size WxH`,
//! `--max-depth D`, `--seed S`, `--threads T`, `--out PATH`, `--spp-range A..B` (a partial
//! render, written as a partial EXR for `examples/merge.rs`), `--clamp MAX`, `--sampler NAME`,
//! `--strategy NAME`, example-specific
//! flags, a progress bar on a terminal, and the one-line summary.

#![allow(dead_code)]

use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::exit;
use std::sync::{Mutex, Once};

use indicatif::{ProgressBar, ProgressStyle};
use pt::pt_core::{
    Camera, Light, Material, PartialRender, Progress, RenderControl, RenderOptions, RenderOutput,
    Scene,
};

/// Defaults an example chooses for the common flags.
#[derive(Clone, Copy)]
pub struct Defaults {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub max_depth: u32,
    pub out: &'static str,
}

/// An example-specific flag: name without dashes, value placeholder (None for a switch), help.
pub struct Flag {
    pub name: &'static str,
    pub value: Option<&'static str>,
    pub help: &'static str,
}

/// Parsed command line.
pub struct Args {
    pub name: &'static str,
    pub options: RenderOptions,
    pub out: PathBuf,
    extras: Vec<(&'static str, Option<String>)>,
    given: Vec<String>,
    positional: Vec<String>,
}

impl Args {
    /// The value of an example-specific flag, if given.
    pub fn value(&self, name: &str) -> Option<&str> {
        self.extras
            .iter()
            .find(|(n, _)| *n == name)
            .and_then(|(_, v)| v.as_deref())
    }

    /// What a partial render of these arguments is a part of: the example and every setting
    /// that changes the image (not the sample range, threads or output path). Partial EXRs
    /// merge only when their labels agree.
    pub fn label(&self) -> String {
        let o = &self.options;
        let mut s = format!(
            "{} {}x{} spp {} max-depth {} seed {}",
            self.name, o.width, o.height, o.spp, o.max_depth, o.seed
        );
        for f in &self.positional {
            s.push_str(&format!(" {f}"));
        }
        if let Some(c) = o.sample_clamp {
            s.push_str(&format!(" clamp {c}"));
        }
        s.push_str(&format!(
            " sampler {} strategy {}",
            o.sampler.name(),
            o.strategy.name()
        ));
        if let Some(a) = o.adaptive {
            s.push_str(&format!(" adaptive {} min {}", a.threshold, a.min_spp));
        }
        for (n, v) in &self.extras {
            s.push_str(&format!(" --{n}"));
            if let Some(v) = v {
                s.push_str(&format!(" {v}"));
            }
        }
        s
    }

    /// True when a flag (common or example-specific) was given on the command line.
    pub fn given(&self, name: &str) -> bool {
        self.given.iter().any(|g| g == name)
    }

    /// True when an example-specific switch was given.
    pub fn flag(&self, name: &str) -> bool {
        self.extras.iter().any(|(n, _)| *n == name)
    }

    /// Parse the value of an example-specific flag, exiting with the usage message on error.
    pub fn parsed<T: std::str::FromStr>(&self, name: &str, what: &str) -> Option<T> {
        self.value(name).map(|v| {
            v.parse().unwrap_or_else(|_| {
                eprintln!("{}: --{name} expects {what}, got {v:?}", self.name);
                exit(2)
            })
        })
    }
}

fn usage(name: &str, d: &Defaults, flags: &[Flag]) -> String {
    let mut s = format!(
        "usage: cargo run --release --example {name} -- [options]\n\n\
         options:\n  \
         --spp N          samples per pixel (default {})\n  \
         --size WxH       image size (default {}x{})\n  \
         --max-depth D    maximum bounces (default {})\n  \
         --seed S         random seed (default 0)\n  \
         --threads T      worker threads (default: all cores)\n  \
         --out PATH       output file, .png (tone-mapped sRGB) or .exr (linear) (default {})\n  \
         --spp-range A..B render only sample indices A..B of 0..spp, into a partial EXR\n                   \
         (merge the parts with `cargo run --example merge`)\n  \
         --clamp MAX      scale samples whose largest component exceeds MAX (biased; default off)\n  \
         --sampler NAME   independent, stratified or sobol (default {})\n  \
         --adaptive T     adaptive sampling: a pixel stops at relative error T (--spp is the cap)\n  \
         --adaptive-min N samples before a pixel's error is first judged (default 16)\n  \
         --strategy NAME  direct light by mis, bsdf (sampling only) or light (sampling only)\n                   \
         (default {})\n",
        d.spp,
        d.width,
        d.height,
        d.max_depth,
        d.out,
        RenderOptions::default().sampler.name(),
        RenderOptions::default().strategy.name()
    );
    for f in flags {
        let left = match f.value {
            Some(v) => format!("--{} {v}", f.name),
            None => format!("--{}", f.name),
        };
        s.push_str(&format!("  {left:<16} {}\n", f.help));
    }
    s.push_str("  --help           print this message\n");
    s
}

fn fail(name: &str, d: &Defaults, flags: &[Flag], msg: &str) -> ! {
    eprintln!("{name}: {msg}\n\n{}", usage(name, d, flags));
    exit(2)
}

fn number<T: std::str::FromStr>(
    name: &str,
    d: &Defaults,
    flags: &[Flag],
    flag: &str,
    v: &str,
) -> T {
    v.parse().unwrap_or_else(|_| {
        fail(
            name,
            d,
            flags,
            &format!("--{flag} expects a number, got {v:?}"),
        )
    })
}

/// What every example shows its user besides its own output: the library's warnings on stderr
/// (`RUST_LOG=info`, `debug`, ... shows more, `RUST_LOG=error` fewer) and, for each asset
/// fetched on first use, one line saying what comes from where and a progress bar on a
/// terminal. Called by [`parse`]; safe to call again.
pub fn init(name: &'static str) {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn"))
            .format_timestamp(None)
            .init();
        init_download_progress(name);
    });
}

fn init_download_progress(name: &'static str) {
    use pt::pt_scene::assets::{DownloadEvent, set_download_observer};
    let bar: Mutex<Option<ProgressBar>> = Mutex::new(None);
    set_download_observer(move |event| {
        let mut bar = bar
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        match *event {
            DownloadEvent::Started {
                name: asset,
                url,
                size,
                dest,
            } => {
                eprintln!(
                    "{name}: fetching asset {asset} ({:.1} MiB) from {url} into {}",
                    size as f64 / (1u64 << 20) as f64,
                    dest.display()
                );
                *bar = std::io::stderr().is_terminal().then(|| {
                    let b = ProgressBar::new(size);
                    b.set_style(
                        ProgressStyle::with_template(
                            "{prefix} [{elapsed_precise}] {wide_bar} {bytes}/{total_bytes} ({bytes_per_sec}, eta {eta})",
                        )
                        .expect("valid template"),
                    );
                    b.set_prefix(name);
                    b
                });
            }
            DownloadEvent::Progress { bytes, total, .. } => {
                if let Some(b) = bar.as_ref() {
                    if total > 0 {
                        b.set_length(total);
                    }
                    b.set_position(bytes);
                }
            }
            _ => {
                if let Some(b) = bar.take() {
                    b.finish_and_clear();
                }
            }
        }
    });
}

/// Parse `std::env::args()`; prints usage and exits with code 2 on bad arguments.
pub fn parse(name: &'static str, d: Defaults, flags: &[Flag]) -> Args {
    parse_impl(name, d, flags, false).0
}

/// Like [`parse`], for examples that take one file argument besides the flags.
#[allow(dead_code)]
pub fn parse_with_file(name: &'static str, d: Defaults, flags: &[Flag]) -> (Args, PathBuf) {
    let usage_line = "a scene file argument (.gltf, .glb, .obj or .ply) is required";
    let (args, mut files) = parse_impl(name, d, flags, true);
    match files.len() {
        1 => {
            let f = files.remove(0);
            (args, PathBuf::from(f))
        }
        0 => {
            eprintln!("{name}: {usage_line}\n\n{}", usage(name, &d, flags));
            exit(2)
        }
        _ => {
            eprintln!("{name}: one scene file, got {files:?}");
            exit(2)
        }
    }
}

fn parse_impl(
    name: &'static str,
    d: Defaults,
    flags: &[Flag],
    positional: bool,
) -> (Args, Vec<String>) {
    init(name);
    let mut files = Vec::new();
    let mut options = RenderOptions::new(d.width, d.height)
        .spp(d.spp)
        .max_depth(d.max_depth);
    let mut out = PathBuf::from(d.out);
    let mut extras = Vec::new();
    let mut given = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let Some(flag) = arg.strip_prefix("--") else {
            if positional {
                files.push(arg);
                continue;
            }
            fail(name, &d, flags, &format!("unexpected argument {arg:?}"));
        };
        given.push(flag.to_string());
        if flag == "help" {
            print!("{}", usage(name, &d, flags));
            exit(0);
        }
        let mut value = |f: &str| {
            args.next()
                .unwrap_or_else(|| fail(name, &d, flags, &format!("--{f} needs a value")))
        };
        match flag {
            "spp" => {
                options.spp = number(name, &d, flags, flag, &value(flag));
                if options.spp == 0 {
                    fail(name, &d, flags, "--spp must be at least 1");
                }
            }
            "size" => {
                let v = value(flag);
                let (w, h) = v.split_once(['x', 'X']).unwrap_or_else(|| {
                    fail(name, &d, flags, &format!("--size expects WxH, got {v:?}"))
                });
                options.width = number(name, &d, flags, flag, w);
                options.height = number(name, &d, flags, flag, h);
            }
            "max-depth" => options.max_depth = number(name, &d, flags, flag, &value(flag)),
            "seed" => options.seed = number(name, &d, flags, flag, &value(flag)),
            "threads" => {
                let t: usize = number(name, &d, flags, flag, &value(flag));
                options.threads = Some(t);
            }
            "out" => out = PathBuf::from(value(flag)),
            "spp-range" => {
                let v = value(flag);
                let range = v
                    .split_once("..")
                    .and_then(|(a, b)| Some(a.parse::<u32>().ok()?..b.parse::<u32>().ok()?))
                    .unwrap_or_else(|| {
                        fail(
                            name,
                            &d,
                            flags,
                            &format!("--spp-range expects A..B, got {v:?}"),
                        )
                    });
                options.spp_range = Some(range);
            }
            "clamp" => options.sample_clamp = Some(number(name, &d, flags, flag, &value(flag))),
            "sampler" => {
                options.sampler = value(flag)
                    .parse()
                    .unwrap_or_else(|e: String| fail(name, &d, flags, &format!("--sampler: {e}")));
            }
            "adaptive" => {
                let t: f32 = number(name, &d, flags, flag, &value(flag));
                let min = options.adaptive.map_or(16, |a| a.min_spp);
                options.adaptive = Some(pt::pt_core::AdaptiveSampling::new(t, min));
            }
            "adaptive-min" => {
                let m: u32 = number(name, &d, flags, flag, &value(flag));
                let a = options.adaptive.unwrap_or_default();
                options.adaptive = Some(pt::pt_core::AdaptiveSampling::new(a.threshold, m));
            }
            "strategy" => {
                options.strategy = value(flag)
                    .parse()
                    .unwrap_or_else(|e: String| fail(name, &d, flags, &format!("--strategy: {e}")));
            }
            other => match flags.iter().find(|f| f.name == other) {
                Some(f) => {
                    let v = f.value.map(|_| value(other));
                    extras.push((f.name, v));
                }
                None => fail(name, &d, flags, &format!("unknown option --{other}")),
            },
        }
    }
    if let Err(e) = options.validate() {
        fail(name, &d, flags, &e.to_string());
    }
    if let Some(r) = &options.spp_range {
        if !given.iter().any(|g| g == "out") {
            out.set_extension(format!("{}-{}.exr", r.start, r.end));
        } else if !out
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
        {
            fail(
                name,
                &d,
                flags,
                &format!(
                    "--spp-range writes a partial EXR: --out must end in .exr, got {}",
                    out.display()
                ),
            );
        }
    }
    let ext = out
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if !matches!(ext.as_deref(), Some("png" | "exr")) {
        fail(
            name,
            &d,
            flags,
            &format!("--out must end in .png or .exr, got {}", out.display()),
        );
    }
    if let Err(e) = check_writable(&out) {
        fail(name, &d, flags, &format!("--out {}: {e}", out.display()));
    }
    (
        Args {
            name,
            options,
            out,
            extras,
            given,
            positional: files.clone(),
        },
        files,
    )
}

/// Whether `out` can be written, found before the render rather than after it: its folder is
/// created, and a file is created beside it and removed (an existing `out` is left untouched).
fn check_writable(out: &std::path::Path) -> std::io::Result<()> {
    let dir = out
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(std::path::Path::new("."));
    std::fs::create_dir_all(dir)?;
    if out.is_dir() {
        return Err(std::io::Error::other("is a directory"));
    }
    let probe = dir.join(format!(".pt-write-check-{}", std::process::id()));
    std::fs::File::create(&probe)?;
    std::fs::remove_file(&probe)?;
    if out.exists() {
        std::fs::OpenOptions::new().append(true).open(out)?;
    }
    Ok(())
}

/// Parse `X,Y,Z` as three finite numbers.
pub fn parse_vec3(v: &str) -> Option<pt::pt_core::glam::Vec3> {
    let parts: Vec<f32> = v
        .split(',')
        .map(|x| x.trim().parse::<f32>().ok().filter(|x| x.is_finite()))
        .collect::<Option<_>>()?;
    match parts[..] {
        [x, y, z] => Some(pt::pt_core::glam::Vec3::new(x, y, z)),
        _ => None,
    }
}

/// Print an error about bad input named on the command line and exit with code 2.
pub fn bad_input(name: &str, what: impl std::fmt::Display) -> ! {
    eprintln!("{name}: {what}");
    exit(2)
}

/// The accelerator named by `--accel` (`auto`, `brute`, `bvh`, `two-level`); exits with a
/// message naming the example on anything else.
pub fn accel_kind(example: &str, name: &str) -> pt::pt_accel::AccelKind {
    use pt::pt_accel::AccelKind;
    match name {
        "auto" => AccelKind::Auto,
        "brute" => AccelKind::BruteForce,
        "bvh" => AccelKind::Bvh,
        "two-level" => AccelKind::TwoLevel,
        other => {
            eprintln!("{example}: --accel expects auto, brute, bvh or two-level, got {other:?}");
            exit(2)
        }
    }
}

/// Print an error and exit with code 1.
pub fn die(name: &str, what: impl std::fmt::Display) -> ! {
    eprintln!("{name}: {what}");
    exit(1)
}

/// Render with a progress bar on stderr when it is a terminal.
pub fn render<M: Material, L: Light, C: Camera>(
    args: &Args,
    scene: &Scene<M, L>,
    camera: &C,
) -> RenderOutput {
    render_with(args, scene, camera, &args.options)
}

/// [`render`] with other options than the command line's.
pub fn render_with<M: Material, L: Light, C: Camera>(
    args: &Args,
    scene: &Scene<M, L>,
    camera: &C,
    options: &RenderOptions,
) -> RenderOutput {
    let bar = std::io::stderr().is_terminal().then(|| {
        let bar = ProgressBar::new(0);
        bar.set_style(
            ProgressStyle::with_template(
                "{prefix} [{elapsed_precise}] {wide_bar} {pos}/{len} tiles (eta {eta})",
            )
            .expect("valid template"),
        );
        bar.set_prefix(args.name);
        bar
    });
    let progress = |p: Progress| {
        if let Some(bar) = &bar {
            bar.set_length(p.tiles_total as u64);
            bar.set_position(p.tiles_done as u64);
        }
    };
    let control = RenderControl::new().progress(&progress);
    let out = pt::pt_core::render(scene, camera, options, Some(&control))
        .unwrap_or_else(|e| die(args.name, e));
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    out
}

/// Write the image (creating the folder) and print the summary line with optional extra notes.
pub fn finish(args: &Args, out: &RenderOutput, extra: &str) {
    if let Some(dir) = args.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .unwrap_or_else(|e| die(args.name, format!("{}: {e}", dir.display())));
    }
    if args.options.spp_range.is_some() {
        PartialRender::new(out, args.label())
            .write_exr(&args.out)
            .unwrap_or_else(|e| die(args.name, e));
    } else {
        out.image
            .write(&args.out)
            .unwrap_or_else(|e| die(args.name, e));
    }
    println!("{}: {}{extra}", args.name, out.stats);
}
