//! Run time against error: renders a figure scene at spp = 1, 2, 4, ... for every sampler and
//! direct-lighting strategy, measures the error of each against a converged reference, and
//! writes a CSV, a log-log plot of relMSE against time, and the efficiency of each
//! configuration.
//!
//! ```text
//! cargo run --release --example convergence -- --scene cornell_box
//! cargo run --release --example convergence -- --scene glass_bunny --size 128x128 --spp 256
//! ```
//!
//! - The reference is rendered once (Sobol, MIS, `--ref-spp` samples, a seed no study render
//!   uses) and cached as `out/convergence/SCENE-WxH-dD-REFSPP.ref.exr`; the file records its
//!   settings and is used again only when they match.
//! - Errors, per pixel and channel against the reference `r`: relMSE = mean `(v - r)^2 / (r +
//!   0.01)^2` (pbrt's definition), MSE = mean `(v - r)^2`, MAE = mean `|v - r|`. Each point is
//!   the mean over `--seeds` independent renders (one render's relMSE is noisy), and its time
//!   is the mean render time (scene building excluded).
//! - Efficiency = 1 / (relMSE x seconds) at `--at-spp` (default: the cap): higher is better,
//!   and it does not depend on the spp for an estimator whose error falls as 1/spp.
//! - Configurations: every sampler x strategy (`mis`, `bsdf` sampling only, `light` sampling
//!   only), and adaptive sampling (`--adaptive-threshold`, default 0.01, at least 8 samples per
//!   pixel) on MIS with every sampler, whose spp is the cap per pixel.
//!
//! Writes `out/convergence/SCENE.csv` and `out/convergence/SCENE.png` (or under `--out-dir`).
//!
//! With `--denoise` (pt built with the `denoise` feature, Open Image Denoise installed) it
//! measures the denoiser instead: Sobol with MIS at each spp, rendered with the albedo and
//! normal AOVs, then denoised guided (the default, `cleanAux` off), guided with `cleanAux` on,
//! and from the colour alone; it prints the relMSE of each against the reference and the time
//! of the pass, and writes the noisy and denoised images of seed 0 and the reference as
//! `SCENE-SPPspp-noisy.png`, `SCENE-SPPspp-denoised.png` and `SCENE-reference.png`.
//!
//! ```text
//! cargo run --release --features denoise --example convergence -- --scene glass_bunny \
//!     --size 256x256 --spp 64 --denoise
//! ```

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use clap::Parser;
use pt::pt_core::{
    AdaptiveSampling, Image, LightStrategy, PartialRender, RenderOptions, SamplerKind,
};
use pt::pt_scene::presets::{FIGURES, figure};
use pt_cli::{Defaults, Failure, Job, RenderArgs};

const NAME: &str = "convergence";

/// Russian roulette's first depth in every configuration but those of `--rr-depths` (the
/// renderer's default, `RenderOptions::rr_depth`).
const RR_DEPTH: u32 = 1;

/// Samples every pixel takes before adaptive sampling first judges its error; adaptive curves
/// start at twice this many.
const ADAPTIVE_MIN: u32 = 8;

/// One configuration of the study.
#[derive(Clone, Copy)]
struct Config {
    sampler: SamplerKind,
    strategy: LightStrategy,
    adaptive: Option<AdaptiveSampling>,
    /// Russian roulette's first depth.
    rr_depth: u32,
}

impl Config {
    fn label(&self) -> String {
        let mut s = format!("{}+{}", self.sampler.name(), self.strategy.name());
        if self.adaptive.is_some() {
            s.push_str("+adaptive");
        }
        if self.rr_depth != RR_DEPTH {
            s.push_str(&format!("+rr{}", self.rr_depth));
        }
        s
    }
}

/// The mean errors and time of one (configuration, spp) point.
#[derive(Clone, Copy, Default)]
struct Point {
    spp: u32,
    seconds: f64,
    samples: f64,
    rel_mse: f64,
    mse: f64,
    mae: f64,
}

/// Time against error for every sampler and strategy on a figure scene.
#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    render: RenderArgs,
    /// The figure scene (list with --scene list)
    #[arg(long, value_name = "NAME", default_value = "cornell_box")]
    scene: String,
    /// Samples per pixel of the reference
    #[arg(long, value_name = "N", default_value_t = 4096)]
    ref_spp: u32,
    /// Renders averaged per point
    #[arg(long, value_name = "K", default_value_t = 4)]
    seeds: u64,
    /// Spp at which efficiency is reported [default: --spp, the cap]
    #[arg(long, value_name = "N")]
    at_spp: Option<u32>,
    /// Relative error at which adaptive configurations stop a pixel
    #[arg(long, value_name = "T", default_value_t = 0.01)]
    adaptive_threshold: f32,
    /// Where the CSV, plot and reference go
    #[arg(long, value_name = "DIR", default_value = "out/convergence")]
    out_dir: PathBuf,
    /// Also Sobol with MIS with Russian roulette starting at each of these depths (a depth at
    /// or above --max-depth turns it off), e.g. `5,8,1000`
    #[arg(long, value_name = "D,D,...", value_delimiter = ',')]
    rr_depths: Vec<u32>,
    /// Only the Sobol with MIS configurations (the default one and those of --rr-depths)
    #[arg(long)]
    sobol_mis_only: bool,
}

const DEFAULTS: Defaults = Defaults {
    width: 128,
    height: 128,
    spp: 64,
    max_depth: 16,
    out: "out/convergence/plot.png",
};

fn die(e: impl std::fmt::Display) -> ! {
    Failure::run(e).exit()
}

fn main() {
    let cli: Cli = pt_cli::parse(NAME, DEFAULTS);
    if cli.render.aov.is_some() {
        Failure::usage("convergence writes no images of its renders: --aov does not apply").exit();
    }
    let job = Job::new(NAME, &cli.render, &DEFAULTS, "").unwrap_or_else(|f| f.exit());
    let scene_name = cli.scene.clone();
    if scene_name == "list" {
        println!("{}", FIGURES.join("\n"));
        return;
    }
    let ref_spp = cli.ref_spp;
    let seeds = cli.seeds.max(1);
    let cap = job.options.spp;
    let at_spp = cli.at_spp.unwrap_or(cap);
    let dir = cli.out_dir.clone();
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| die(format!("{}: {e}", dir.display())));

    let fig = figure(&scene_name).unwrap_or_else(|e| die(e));
    let (w, h, depth) = (job.options.width, job.options.height, job.options.max_depth);
    let base = RenderOptions::new(w, h)
        .max_depth(depth)
        .threads(job.options.threads);

    // The reference, cached under a name and label that carry every setting it depends on.
    let key = format!("{scene_name}-{w}x{h}-d{depth}-{ref_spp}");
    let label = format!("convergence reference {key} sobol mis v1");
    let ref_path = dir.join(format!("{key}.ref.exr"));
    let reference = load_reference(&ref_path, &label).unwrap_or_else(|| {
        eprintln!(
            "{NAME}: rendering the reference ({w}x{h}, {ref_spp} spp); cached as {}",
            ref_path.display()
        );
        let opts = base
            .clone()
            .spp(ref_spp)
            .seed(0x5eed_f00d_7e7e)
            .sampler(SamplerKind::Sobol)
            .strategy(LightStrategy::Mis);
        let out = job.render_with(&fig.bundle.scene, &fig.bundle.camera, &opts);
        PartialRender::new(&out, label.clone())
            .write_exr(&ref_path)
            .unwrap_or_else(|e| die(e));
        eprintln!("{NAME}: reference: {}", out.stats);
        out.image
    });

    if job.denoise {
        denoise_study(
            &job,
            &fig.bundle,
            &base,
            &reference,
            &scene_name,
            &dir,
            seeds,
        );
        return;
    }

    let threshold = cli.adaptive_threshold;
    let mut configs = Vec::new();
    for sampler in SamplerKind::ALL {
        for strategy in LightStrategy::ALL {
            configs.push(Config {
                sampler,
                strategy,
                adaptive: None,
                rr_depth: RR_DEPTH,
            });
        }
    }
    // Adaptive sampling on top of MIS with each sampler: each pixel takes at least
    // ADAPTIVE_MIN samples and at most the point's spp.
    for sampler in SamplerKind::ALL {
        configs.push(Config {
            sampler,
            strategy: LightStrategy::Mis,
            adaptive: Some(AdaptiveSampling::new(threshold, ADAPTIVE_MIN)),
            rr_depth: RR_DEPTH,
        });
    }
    for &rr_depth in &cli.rr_depths {
        configs.push(Config {
            sampler: SamplerKind::Sobol,
            strategy: LightStrategy::Mis,
            adaptive: None,
            rr_depth,
        });
    }
    if cli.sobol_mis_only {
        configs.retain(|c| {
            c.sampler == SamplerKind::Sobol
                && c.strategy == LightStrategy::Mis
                && c.adaptive.is_none()
        });
    }
    let spps: Vec<u32> = std::iter::successors(Some(1u32), |s| s.checked_mul(2))
        .take_while(|&s| s <= cap)
        .collect();
    let mut csv = String::from(
        "scene,sampler,strategy,adaptive,rr_depth,spp,seconds,samples,relmse,mse,mae\n",
    );
    let mut curves: Vec<(Config, Vec<Point>)> = Vec::new();
    for config in &configs {
        let mut points = Vec::new();
        for &spp in spps
            .iter()
            .filter(|&&s| config.adaptive.is_none() || s >= 2 * ADAPTIVE_MIN)
        {
            let mut p = Point {
                spp,
                ..Point::default()
            };
            for seed in 0..seeds {
                let opts = base
                    .clone()
                    .spp(spp)
                    .seed(seed)
                    .sampler(config.sampler)
                    .strategy(config.strategy)
                    .rr_depth(config.rr_depth)
                    .adaptive(config.adaptive);
                let out = pt::pt_core::render(&fig.bundle.scene, &fig.bundle.camera, &opts, None)
                    .unwrap_or_else(|e| die(e));
                let d = out.image.difference(&reference).unwrap_or_else(|e| die(e));
                let (rel, mse, mae) = (d.rel_mse, d.mse, d.mae);
                p.seconds += out.stats.elapsed.as_secs_f64() / seeds as f64;
                p.samples += out.stats.samples as f64 / seeds as f64;
                p.rel_mse += rel / seeds as f64;
                p.mse += mse / seeds as f64;
                p.mae += mae / seeds as f64;
            }
            let _ = writeln!(
                csv,
                "{scene_name},{},{},{},{},{spp},{:.6},{:.0},{:.6e},{:.6e},{:.6e}",
                config.sampler.name(),
                config.strategy.name(),
                config
                    .adaptive
                    .map_or("off".to_string(), |a| a.threshold.to_string()),
                config.rr_depth,
                p.seconds,
                p.samples,
                p.rel_mse,
                p.mse,
                p.mae
            );
            points.push(p);
        }
        eprintln!("{NAME}: {} done", config.label());
        curves.push((*config, points));
    }
    let csv_path = dir.join(format!("{scene_name}.csv"));
    std::fs::write(&csv_path, &csv).unwrap_or_else(|e| die(format!("{}: {e}", csv_path.display())));

    // Efficiency at the chosen spp, best first.
    let mut table: Vec<(String, Point)> = curves
        .iter()
        .filter_map(|(c, pts)| {
            pts.iter()
                .find(|p| p.spp == at_spp)
                .map(|p| (c.label(), *p))
        })
        .collect();
    table.sort_by(|a, b| efficiency(&b.1).total_cmp(&efficiency(&a.1)));
    println!(
        "{NAME}: {scene_name}, {w}x{h}, max depth {depth}, reference {ref_spp} spp, {seeds} seeds per point"
    );
    println!(
        "| configuration | spp (cap) | mean spp | time (s) | relMSE | efficiency 1/(relMSE x s) |"
    );
    println!("|---|---|---|---|---|---|");
    let pixels = f64::from(w) * f64::from(h);
    for (label, p) in &table {
        println!(
            "| {label} | {} | {:.1} | {:.3} | {:.4e} | {:.1} |",
            p.spp,
            p.samples / pixels,
            p.seconds,
            p.rel_mse,
            efficiency(p)
        );
    }
    let plot_path = dir.join(format!("{scene_name}.png"));
    match plot(&plot_path, &scene_name, &curves) {
        Ok(()) => println!(
            "{NAME}: wrote {} and {}",
            csv_path.display(),
            plot_path.display()
        ),
        Err(e) => die(format!("{}: {e}", plot_path.display())),
    }
}

/// The denoiser against the reference at spp 1, 2, 4, ... up to the cap (Sobol, MIS): the
/// mean relMSE over `seeds` renders of the noisy image and of three denoised ones, and the mean
/// time of the render and of the guided pass.
fn denoise_study(
    job: &Job,
    bundle: &pt::pt_scene::SceneBundle,
    base: &RenderOptions,
    reference: &Image,
    scene: &str,
    dir: &Path,
    seeds: u64,
) {
    use pt::pt_core::{Aovs, Denoiser};
    let denoiser = Denoiser::new().unwrap_or_else(|e| die(e));
    let clean = Denoiser::new().unwrap_or_else(|e| die(e)).clean_aux(true);
    let (w, h) = (base.width, base.height);
    println!(
        "{NAME}: {scene}, {w}x{h}, max depth {}, {seeds} seeds per row; relMSE against the \
         reference",
        base.max_depth
    );
    println!(
        "| spp | render (s) | noisy | denoised | denoised, cleanAux | colour only | denoise (s) |"
    );
    println!("|---|---|---|---|---|---|---|");
    let error = |image: &Image| {
        image
            .difference(reference)
            .unwrap_or_else(|e| die(e))
            .rel_mse
    };
    let write = |image: &Image, name: String| {
        let path = dir.join(name);
        image.write(&path).unwrap_or_else(|e| die(e));
    };
    write(reference, format!("{scene}-reference.png"));
    let spps = std::iter::successors(Some(1u32), |s| s.checked_mul(2))
        .take_while(|&s| s <= job.options.spp);
    for spp in spps {
        let mut sums = [0.0f64; 6];
        for seed in 0..seeds {
            let opts = base.clone().spp(spp).seed(seed).aovs(Aovs::ALL);
            let out = pt::pt_core::render(&bundle.scene, &bundle.camera, &opts, None)
                .unwrap_or_else(|e| die(e));
            let (albedo, normal) = (out.albedo.as_ref(), out.normal.as_ref());
            let start = std::time::Instant::now();
            let guided = denoiser
                .denoise(&out.image, albedo, normal)
                .unwrap_or_else(|e| die(e));
            let pass = start.elapsed().as_secs_f64();
            let cleaned = clean
                .denoise(&out.image, albedo, normal)
                .unwrap_or_else(|e| die(e));
            let bare = denoiser
                .denoise(&out.image, None, None)
                .unwrap_or_else(|e| die(e));
            let row = [
                out.stats.elapsed.as_secs_f64(),
                error(&out.image),
                error(&guided),
                error(&cleaned),
                error(&bare),
                pass,
            ];
            for (s, v) in sums.iter_mut().zip(row) {
                *s += v / seeds as f64;
            }
            if seed == 0 {
                write(&out.image, format!("{scene}-{spp}spp-noisy.png"));
                write(&guided, format!("{scene}-{spp}spp-denoised.png"));
            }
        }
        let [render_s, noisy, guided, cleaned, bare, pass] = sums;
        println!(
            "| {spp} | {render_s:.3} | {noisy:.3e} | {guided:.3e} | {cleaned:.3e} | {bare:.3e} | \
             {pass:.3} |"
        );
    }
}

fn efficiency(p: &Point) -> f64 {
    1.0 / (p.rel_mse * p.seconds).max(1e-300)
}

/// The cached reference, when the file exists and was made with the same settings.
fn load_reference(path: &Path, label: &str) -> Option<Image> {
    let part = PartialRender::read_exr(path).ok()?;
    (part.label == label).then(|| part.film.to_image())
}

/// Log-log plot of relMSE against seconds, one line (with a dot per spp) per configuration.
fn plot(path: &Path, scene: &str, curves: &[(Config, Vec<Point>)]) -> Result<(), String> {
    use plotters::prelude::*;
    register_font()?;
    let (width, height) = (960u32, 640u32);
    let mut buffer = vec![255u8; (width * height * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let all = curves.iter().flat_map(|(_, p)| p.iter());
        let (mut t0, mut t1, mut e0, mut e1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for p in all.filter(|p| p.seconds > 0.0 && p.rel_mse > 0.0) {
            t0 = t0.min(p.seconds);
            t1 = t1.max(p.seconds);
            e0 = e0.min(p.rel_mse);
            e1 = e1.max(p.rel_mse);
        }
        if t0 > t1 {
            return Err("no points to plot".into());
        }
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!("{scene}: relMSE against render time"),
                ("sans-serif", 24),
            )
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(72)
            .build_cartesian_2d(
                (t0 * 0.8..t1 * 1.25).log_scale(),
                (e0 * 0.8..e1 * 1.25).log_scale(),
            )
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc("seconds")
            .y_desc("relMSE")
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(|e| e.to_string())?;
        for (i, (config, points)) in curves.iter().enumerate() {
            let color = Palette99::pick(i).to_rgba();
            let data: Vec<(f64, f64)> = points
                .iter()
                .filter(|p| p.seconds > 0.0 && p.rel_mse > 0.0)
                .map(|p| (p.seconds, p.rel_mse))
                .collect();
            chart
                .draw_series(LineSeries::new(data.clone(), color.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(config.label())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                });
            chart
                .draw_series(
                    data.into_iter()
                        .map(|(x, y)| Circle::new((x, y), 3, color.filled())),
                )
                .map_err(|e| e.to_string())?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    image::save_buffer(path, &buffer, width, height, image::ColorType::Rgb8)
        .map_err(|e| e.to_string())
}

/// Give plotters a TTF for its text: `PT_PLOT_FONT`, or DejaVu Sans / Liberation Sans where
/// Linux distributions install them.
fn register_font() -> Result<(), String> {
    let candidates = [
        std::env::var("PT_PLOT_FONT").unwrap_or_default(),
        "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf".into(),
        "/usr/share/fonts/TTF/DejaVuSans.ttf".into(),
        "/usr/share/fonts/dejavu/DejaVuSans.ttf".into(),
        "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf".into(),
    ];
    for c in candidates.iter().filter(|c| !c.is_empty()) {
        if let Ok(bytes) = std::fs::read(c) {
            let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
            if plotters::style::register_font(
                "sans-serif",
                plotters::style::FontStyle::Normal,
                bytes,
            )
            .is_ok()
            {
                return Ok(());
            }
        }
    }
    Err("no TTF font found for the plot's text: set PT_PLOT_FONT to a .ttf file".into())
}
