//! Renders every figure of the report into `docs/figures/` and writes `docs/figures.md`, a
//! gallery with each image, the command that renders it alone, its spp, time and estimated
//! error.
//!
//! ```text
//! cargo run --example figures                     # all figures (about 10 minutes)
//! cargo run --example figures -- --only glass_bunny
//! cargo run --example figures -- --scale 0.25    # quick look: a quarter of the spp, half the size
//! ```
//!
//! Each figure is rendered as two halves of its sample range (`0..spp/2` and `spp/2..spp`),
//! merged exactly into the image (bit for bit the single render). The two halves give the error
//! estimate without a reference: per pixel and channel, with half-means `a` and `b` and mean
//! `m`, `(a - b)^2 / 4` estimates the squared error of `m`, so relMSE is estimated as the mean of
//! `(a - b)^2 / 4 / (m + 0.01)^2`. With independent samples this is unbiased; with the Sobol
//! sampler the halves are strata of one point set, negatively correlated, and the estimate is
//! conservative. `docs/PERFORMANCE.md` has reference-based errors from `examples/convergence.rs`.

use std::fmt::Write as _;
use std::path::PathBuf;

use clap::Parser;
use pt::pt_core::{Image, PartialRender, RenderOptions};
use pt::pt_scene::presets::{FIGURES, figure};
use pt_cli::{Defaults, Failure, RenderArgs};

const NAME: &str = "figures";

/// Render every figure of the report into docs/figures/ and write docs/figures.md.
#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    render: RenderArgs,
    /// Render one figure (names: --only list)
    #[arg(long, value_name = "NAME")]
    only: Option<String>,
    /// Multiply every figure's spp by F and its size by sqrt(F)
    #[arg(long, value_name = "F", default_value_t = 1.0)]
    scale: f64,
    /// Also write each figure as linear EXR (to compare versions bit for bit)
    #[arg(long)]
    exr: bool,
    /// Where the images and figures.md go [default: docs/figures and docs]
    #[arg(long, value_name = "DIR")]
    dir: Option<PathBuf>,
}

const DEFAULTS: Defaults = Defaults {
    width: 512,
    height: 512,
    spp: 128,
    max_depth: 16,
    out: "docs/figures/gallery.png",
};

fn die(e: impl std::fmt::Display) -> ! {
    Failure::run(e).exit()
}

fn main() {
    let cli: Cli = pt_cli::parse(NAME, DEFAULTS);
    let only = cli.only.as_deref();
    if only == Some("list") {
        println!("{}", FIGURES.join("\n"));
        return;
    }
    if cli.render.aov.is_some() || cli.render.denoise {
        Failure::usage(
            "figures writes the gallery's PNGs only: --aov and --denoise belong to each figure's \
             own example (`cargo run --example glass_bunny -- --denoise`)",
        )
        .exit();
    }
    let scale = cli.scale;
    if !(scale > 0.0 && scale <= 1.0) {
        Failure::usage(format!("--scale must be in (0, 1], got {scale}")).exit();
    }
    let (image_dir, md_path) = match &cli.dir {
        Some(d) => (d.clone(), d.join("figures.md")),
        None => (
            PathBuf::from("docs/figures"),
            PathBuf::from("docs/figures.md"),
        ),
    };
    std::fs::create_dir_all(&image_dir)
        .unwrap_or_else(|e| die(format!("{}: {e}", image_dir.display())));

    let names: Vec<&str> = match only {
        Some(n) => vec![
            FIGURES
                .iter()
                .copied()
                .find(|f| *f == n)
                .unwrap_or_else(|| {
                    Failure::usage(format!(
                        "unknown figure {n:?} (expected one of {})",
                        FIGURES.join(", ")
                    ))
                    .exit()
                }),
        ],
        None => FIGURES.to_vec(),
    };
    let mut md = String::from(
        "# Figures\n\nEvery figure of the report, rendered by `cargo run --example figures` \
         (2 cores, default sampler and strategy: Sobol and MIS). Each row gives the command that \
         renders the figure alone, its samples per pixel, the render time (scene building \
         excluded) and the relMSE estimated from two halves of the samples (see \
         `examples/figures.rs`; reference-based errors and convergence plots are in \
         [PERFORMANCE.md](PERFORMANCE.md)).\n\n",
    );
    if scale < 1.0 {
        let _ = writeln!(
            md,
            "Rendered at `--scale {scale}` (fewer samples, smaller images).\n"
        );
    }
    for name in names {
        let fig = figure(name).unwrap_or_else(|e| die(e));
        let side = scale.sqrt();
        let (w, h) = (
            ((f64::from(fig.width) * side).round() as u32).max(8),
            ((f64::from(fig.height) * side).round() as u32).max(8),
        );
        let spp = (((f64::from(fig.spp) * scale).round() as u32).max(2) / 2) * 2;
        let base = RenderOptions::new(w, h)
            .spp(spp)
            .max_depth(fig.max_depth)
            .threads(cli.render.threads)
            .seed(cli.render.seed);
        let halves: Vec<_> = [0..spp / 2, spp / 2..spp]
            .into_iter()
            .map(|range| {
                pt::pt_core::render(
                    &fig.bundle.scene,
                    &fig.bundle.camera,
                    &base.clone().spp_range(range),
                    None,
                )
                .unwrap_or_else(|e| die(e))
            })
            .collect();
        let seconds: f64 = halves.iter().map(|o| o.stats.elapsed.as_secs_f64()).sum();
        let mut whole = PartialRender::new(&halves[0], name);
        whole
            .merge(&PartialRender::new(&halves[1], name))
            .unwrap_or_else(|e| die(e));
        let image = whole.film.to_image();
        let rel_mse = half_estimate(&halves[0].image, &halves[1].image, &image);
        if cli.exr {
            let path = image_dir.join(format!("{name}.exr"));
            image.write_exr(&path).unwrap_or_else(|e| die(e));
        }
        let path = image_dir.join(format!("{name}.png"));
        image.write_png(&path).unwrap_or_else(|e| die(e));
        let samples = halves[0].stats.samples + halves[1].stats.samples;
        println!(
            "{NAME}: {name}: {w}x{h}, {spp} spp, {seconds:.2} s, {:.3} Msamples/s, estimated relMSE {rel_mse:.2e}",
            samples as f64 / seconds / 1e6
        );
        let rel = path
            .strip_prefix(md_path.parent().unwrap_or(std::path::Path::new("")))
            .unwrap_or(&path)
            .display()
            .to_string();
        let _ = writeln!(
            md,
            "## {name}\n\n{}\n\n![{name}]({rel})\n\n`{}` | {w}x{h}, {spp} spp, max depth {} | \
             {seconds:.1} s ({:.2} Msamples/s) | estimated relMSE {rel_mse:.2e}\n",
            fig.caption,
            fig.command,
            fig.max_depth,
            samples as f64 / seconds / 1e6
        );
    }
    if only.is_none() {
        std::fs::write(&md_path, md).unwrap_or_else(|e| die(format!("{}: {e}", md_path.display())));
        println!("{NAME}: wrote {}", md_path.display());
    }
}

/// relMSE of `whole` estimated from its two halves `a` and `b` (see the module documentation).
fn half_estimate(a: &Image, b: &Image, whole: &Image) -> f64 {
    let n = whole.as_slice().len() as f64;
    a.as_slice()
        .iter()
        .zip(b.as_slice())
        .zip(whole.as_slice())
        .map(|((&a, &b), &m)| {
            let d = f64::from(a) - f64::from(b);
            d * d / 4.0 / (f64::from(m) + 0.01).powi(2)
        })
        .sum::<f64>()
        / n
}
