//! The flags every render takes (DESIGN.md section 8), shared by `pt render` and the examples,
//! and what they resolve to: render options, the output path, the shard's sample range.

use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};

use clap::Args;
use pt_accel::AccelKind;
use pt_core::glam::Vec3;
use pt_core::{AdaptiveSampling, Aovs, LightStrategy, RenderOptions, SamplerKind};

use crate::Failure;

/// The defaults a program chooses for the common flags (shown in its `--help`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Defaults {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// Maximum path depth.
    pub max_depth: u32,
    /// Output path.
    pub out: &'static str,
}

impl Defaults {
    /// `pt render`'s defaults: 640x480, 64 spp, depth 16, `out/render.png`.
    pub const RENDER: Self = Self {
        width: 640,
        height: 480,
        spp: 64,
        max_depth: 16,
        out: "out/render.png",
    };
}

/// The flags of every render. Their defaults are the program's [`Defaults`], set by
/// [`crate::parse`].
#[derive(Args, Clone, Debug)]
pub struct RenderArgs {
    /// Samples per pixel
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    pub spp: u32,
    /// Image size
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Maximum number of bounces (0: emission only, 1: direct light)
    #[arg(long, value_name = "D")]
    pub max_depth: u32,
    /// Seed of every random number
    #[arg(long, value_name = "S", default_value_t = 0)]
    pub seed: u64,
    /// Worker threads [default: one per core]
    #[arg(long, value_name = "T")]
    pub threads: Option<usize>,
    /// Output file: .png (tone-mapped sRGB) or .exr (linear); a part of a render is always a
    /// partial EXR, named after its sample range when --out is not given or is a folder
    /// (`DIR/` or an existing one)
    #[arg(long, value_name = "PATH")]
    pub out: PathBuf,
    /// Render only the sample indices A..B of 0..spp, into a partial EXR (merge the parts with
    /// `pt merge`)
    #[arg(long, value_name = "A..B", value_parser = parse_range, conflicts_with = "shard")]
    pub spp_range: Option<Range<u32>>,
    /// Render the I-th (from 0) of N equal sample ranges; `env/N` takes I from the scheduler
    /// (PT_SHARD_INDEX, SLURM_ARRAY_TASK_ID or JOB_COMPLETION_INDEX)
    #[arg(long, value_name = "I/N", value_parser = parse_shard)]
    pub shard: Option<ShardSpec>,
    /// Scale down samples whose largest component exceeds MAX (biased; default off)
    #[arg(long, value_name = "MAX")]
    pub clamp: Option<f32>,
    /// Sample generator: independent, stratified or sobol
    #[arg(long, value_name = "NAME", default_value = "sobol", value_parser = parse_sampler)]
    pub sampler: SamplerKind,
    /// Direct light by mis, bsdf (sampling only) or light (sampling only)
    #[arg(long, value_name = "NAME", default_value = "mis", value_parser = parse_strategy)]
    pub strategy: LightStrategy,
    /// Russian roulette may end paths after this many bounces (a large value turns it off)
    #[arg(long, value_name = "D", default_value_t = 1)]
    pub rr_depth: u32,
    /// Russian roulette plays for paths whose throughput falls below T, each surviving with
    /// probability throughput / T
    #[arg(long, value_name = "T", default_value_t = 0.4)]
    pub rr_threshold: f32,
    /// Trace eight paths at once where the scene allows it (Lambertian, mirror and smooth glass
    /// materials, any lights, sobol, no absorbing media): the same image, bit for bit, faster. The
    /// default
    #[arg(long, overrides_with = "no_lanes")]
    pub lanes: bool,
    /// Trace one path at a time (the reference tracer) even where the lanes could run
    #[arg(long, overrides_with = "lanes")]
    pub no_lanes: bool,
    /// Adaptive sampling: a pixel stops at relative error T (--spp is the cap)
    #[arg(long, value_name = "T")]
    pub adaptive: Option<f32>,
    /// Samples before a pixel's error is first judged (with --adaptive)
    #[arg(long, value_name = "N", default_value_t = 16)]
    pub adaptive_min: u32,
    /// Auxiliary outputs of the first non-specular hit, comma-separated: albedo, normal. Layers
    /// of an .exr output (albedo.RGB, normal.XYZ), or NAME.albedo.png and NAME.normal.png beside
    /// a .png; kept in partial renders
    #[arg(long, value_name = "LIST", value_parser = parse_aovs)]
    pub aov: Option<Aovs>,
    /// Also write the image denoised by Intel Open Image Denoise, guided by albedo and normal,
    /// as NAME.denoised.EXT beside the unbiased image (needs pt built with the `denoise`
    /// feature and the library: OIDN_DIR or the system's library path)
    #[arg(long, conflicts_with_all = ["spp_range", "shard"])]
    pub denoise: bool,
    /// No progress bar and no summary line (errors are still printed)
    #[arg(long, short)]
    pub quiet: bool,
    /// Print the summary as one JSON object instead of the summary line
    #[arg(long)]
    pub json: bool,
}

/// `--shard I/N` as given: an index, or `env` (from the scheduler), and the count.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShardSpec {
    /// The index, or `None` for `env/N`.
    pub index: Option<u32>,
    /// The number of shards.
    pub count: u32,
}

/// The environment variables `--shard env/N` reads the index from, in order: pt's own, a Slurm
/// job array's, a Kubernetes Indexed Job's.
pub const SHARD_INDEX_VARIABLES: [&str; 3] = [
    "PT_SHARD_INDEX",
    "SLURM_ARRAY_TASK_ID",
    "JOB_COMPLETION_INDEX",
];

impl ShardSpec {
    /// The shard's index: given, or from the first of [`SHARD_INDEX_VARIABLES`] that is set.
    ///
    /// # Errors
    ///
    /// No variable is set, or its value is not an index below the count.
    pub fn resolve_index(&self, var: impl Fn(&str) -> Option<String>) -> Result<u32, String> {
        let index = match self.index {
            Some(i) => i,
            None => {
                let (name, value) = SHARD_INDEX_VARIABLES
                    .iter()
                    .find_map(|n| var(n).map(|v| (*n, v)))
                    .ok_or_else(|| {
                        format!(
                            "--shard env/{}: none of {} is set",
                            self.count,
                            SHARD_INDEX_VARIABLES.join(", ")
                        )
                    })?;
                value.trim().parse().map_err(|_| {
                    format!(
                        "--shard env/{}: {name} is {value:?}, not an index",
                        self.count
                    )
                })?
            }
        };
        if index >= self.count {
            return Err(format!(
                "--shard {index}/{}: the index must be below the count",
                self.count
            ));
        }
        Ok(index)
    }
}

/// The sample range of shard `index` of `count` over `0..spp`: equal parts, the remainder
/// spread over them (`floor(i spp / n) .. floor((i + 1) spp / n)`), so the shards tile `0..spp`.
#[must_use]
pub fn shard_range(index: u32, count: u32, spp: u32) -> Range<u32> {
    let at = |i: u32| (u64::from(i) * u64::from(spp) / u64::from(count)) as u32;
    at(index)..at(index + 1)
}

/// What the flags resolve to.
#[derive(Clone, Debug)]
pub struct Resolved {
    /// The render options.
    pub options: RenderOptions,
    /// Where the output goes.
    pub out: PathBuf,
}

impl RenderArgs {
    /// The AOVs the render takes: those of `--aov`, and both guides with `--denoise`.
    #[must_use]
    pub fn render_aovs(&self) -> Aovs {
        let asked = self.aov.unwrap_or_default();
        if self.denoise {
            asked.union(Aovs::ALL)
        } else {
            asked
        }
    }

    /// The render options and output path these flags ask for, checked before any work. A part
    /// of a render (`--spp-range`, `--shard`) without its own `--out` is written beside the
    /// default output, named after its range (`out/render.0-16.exr`).
    ///
    /// # Errors
    ///
    /// A [`Failure`] with exit code 2 naming the flag: options out of range, a shard that
    /// cannot be resolved or is empty, an output that is not `.png`/`.exr` or cannot be written.
    pub fn resolve(&self, defaults: &Defaults) -> Result<Resolved, Failure> {
        self.resolve_with(defaults, |v| std::env::var(v).ok())
    }

    /// [`RenderArgs::resolve`] with the environment given by `var` (for tests).
    ///
    /// # Errors
    ///
    /// As [`RenderArgs::resolve`].
    pub fn resolve_with(
        &self,
        defaults: &Defaults,
        var: impl Fn(&str) -> Option<String>,
    ) -> Result<Resolved, Failure> {
        let (width, height) = self.size;
        let mut options = RenderOptions::new(width, height)
            .spp(self.spp)
            .max_depth(self.max_depth)
            .seed(self.seed)
            .threads(self.threads)
            .sample_clamp(self.clamp)
            .strategy(self.strategy)
            .rr_depth(self.rr_depth)
            .rr_threshold(self.rr_threshold)
            .lanes(!self.no_lanes)
            .aovs(self.render_aovs())
            .sampler(self.sampler);
        if let Some(t) = self.adaptive {
            options = options.adaptive(Some(AdaptiveSampling::new(t, self.adaptive_min)));
        }
        let range = match (&self.spp_range, &self.shard) {
            (Some(r), _) => Some(r.clone()),
            (None, Some(shard)) => {
                let index = shard.resolve_index(var).map_err(Failure::usage)?;
                if shard.count > self.spp {
                    return Err(Failure::usage(format!(
                        "--shard {index}/{}: more shards than samples per pixel ({})",
                        shard.count, self.spp
                    )));
                }
                Some(shard_range(index, shard.count, self.spp))
            }
            (None, None) => None,
        };
        if let Some(r) = &range {
            options = options.spp_range(r.clone());
        }
        options.validate().map_err(Failure::usage)?;

        let mut out = self.out.clone();
        // A folder (an existing one, or a path ending in a separator) takes the default's file
        // name: farm tasks name only where their parts go.
        let named_by_range =
            out.as_os_str() == std::ffi::OsStr::new(defaults.out) || is_folder(&out);
        if is_folder(&out) {
            out = out.join(Path::new(defaults.out).file_name().unwrap_or_default());
        }
        if let Some(r) = &range {
            if named_by_range {
                out.set_extension(format!("{}-{}.exr", r.start, r.end));
            } else if !has_extension(&out, "exr") {
                return Err(Failure::usage(format!(
                    "a part of a render is a partial EXR: --out must end in .exr, got {}",
                    out.display()
                )));
            }
        }
        if !has_extension(&out, "png") && !has_extension(&out, "exr") {
            return Err(Failure::usage(format!(
                "--out must end in .png or .exr, got {}",
                out.display()
            )));
        }
        check_writable(&out)
            .map_err(|e| Failure::usage(format!("--out {}: {e}", out.display())))?;
        Ok(Resolved { options, out })
    }
}

fn is_folder(path: &Path) -> bool {
    path.is_dir()
        || path
            .as_os_str()
            .to_string_lossy()
            .ends_with(std::path::MAIN_SEPARATOR)
}

fn has_extension(path: &Path, ext: &str) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case(ext))
}

/// Whether `out` can be written, found before the render rather than after it: its folder is
/// created, and a file is created beside it and removed (an existing `out` is left untouched).
fn check_writable(out: &Path) -> std::io::Result<()> {
    let dir = out
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
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

/// `WxH`.
///
/// # Errors
///
/// Anything else, with what was expected.
pub fn parse_size(v: &str) -> Result<(u32, u32), String> {
    let bad = || format!("expects WxH (for example 640x480), got {v:?}");
    let (w, h) = v.split_once(['x', 'X']).ok_or_else(bad)?;
    Ok((w.parse().map_err(|_| bad())?, h.parse().map_err(|_| bad())?))
}

/// `A..B`.
///
/// # Errors
///
/// Anything else, with what was expected.
pub fn parse_range(v: &str) -> Result<Range<u32>, String> {
    v.split_once("..")
        .and_then(|(a, b)| Some(a.parse::<u32>().ok()?..b.parse::<u32>().ok()?))
        .ok_or_else(|| format!("expects A..B (for example 0..64), got {v:?}"))
}

/// `I/N` or `env/N`, with `N >= 1`.
///
/// # Errors
///
/// Anything else, with what was expected.
pub fn parse_shard(v: &str) -> Result<ShardSpec, String> {
    let bad = || format!("expects I/N or env/N (for example 0/4), got {v:?}");
    let (i, n) = v.split_once('/').ok_or_else(bad)?;
    let count: u32 = n.parse().map_err(|_| bad())?;
    if count == 0 {
        return Err(format!("the shard count must be at least 1, got {v:?}"));
    }
    let index = match i {
        "env" => None,
        i => Some(i.parse().map_err(|_| bad())?),
    };
    Ok(ShardSpec { index, count })
}

/// `X,Y,Z`, three finite numbers.
///
/// # Errors
///
/// Anything else, with what was expected.
pub fn parse_vec3(v: &str) -> Result<Vec3, String> {
    let bad = || format!("expects three numbers X,Y,Z, got {v:?}");
    let parts: Vec<f32> = v
        .split(',')
        .map(|x| x.trim().parse::<f32>().ok().filter(|x| x.is_finite()))
        .collect::<Option<_>>()
        .ok_or_else(bad)?;
    match parts[..] {
        [x, y, z] => Ok(Vec3::new(x, y, z)),
        _ => Err(bad()),
    }
}

/// A sampler by name (`independent`, `stratified`, `sobol`).
///
/// # Errors
///
/// An unknown name, listing the known ones.
pub fn parse_sampler(v: &str) -> Result<SamplerKind, String> {
    v.parse()
}

/// A list of auxiliary outputs (`albedo,normal`, `albedo`, `normal`, `none`).
///
/// # Errors
///
/// An unknown name, listing the known ones.
pub fn parse_aovs(v: &str) -> Result<Aovs, String> {
    v.parse()
}

/// A direct-lighting strategy by name (`mis`, `bsdf`, `light`).
///
/// # Errors
///
/// An unknown name, listing the known ones.
pub fn parse_strategy(v: &str) -> Result<LightStrategy, String> {
    v.parse()
}

/// An accelerator by name (`auto`, `brute`, `bvh`, `two-level`).
///
/// # Errors
///
/// An unknown name, listing the known ones.
pub fn parse_accel(v: &str) -> Result<AccelKind, String> {
    match v {
        "auto" => Ok(AccelKind::Auto),
        "brute" => Ok(AccelKind::BruteForce),
        "bvh" => Ok(AccelKind::Bvh),
        "two-level" => Ok(AccelKind::TwoLevel),
        other => Err(format!(
            "expects auto, brute, bvh or two-level, got {other:?}"
        )),
    }
}

/// What a partial render of a program's arguments is a part of: the program and every setting
/// that changes the image (not the sample range, threads or output path). Partial EXRs merge
/// only when their labels agree.
#[must_use]
pub fn label(name: &str, options: &RenderOptions, extra: &str) -> String {
    let mut s = format!(
        "{name} {}x{} spp {} max-depth {} seed {}",
        options.width, options.height, options.spp, options.max_depth, options.seed
    );
    if let Some(c) = options.sample_clamp {
        s.push_str(&format!(" clamp {c}"));
    }
    s.push_str(&format!(
        " sampler {} strategy {}",
        options.sampler.name(),
        options.strategy.name()
    ));
    if let Some(a) = options.adaptive {
        s.push_str(&format!(" adaptive {} min {}", a.threshold, a.min_spp));
    }
    if !extra.is_empty() {
        s.push(' ');
        s.push_str(extra);
    }
    s
}

impl fmt::Display for ShardSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.index {
            Some(i) => write!(f, "{i}/{}", self.count),
            None => write!(f, "env/{}", self.count),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_tile_the_samples_exactly() {
        for (n, spp) in [(1, 1), (4, 64), (3, 10), (7, 7), (5, 1000)] {
            let mut next = 0;
            for i in 0..n {
                let r = shard_range(i, n, spp);
                assert_eq!(r.start, next);
                assert!(r.end > r.start, "{n} shards of {spp}: shard {i} is empty");
                next = r.end;
            }
            assert_eq!(next, spp);
        }
    }

    #[test]
    fn the_shard_index_comes_from_the_scheduler() {
        let spec = parse_shard("env/4").unwrap();
        let env = |pairs: &'static [(&'static str, &'static str)]| {
            move |k: &str| {
                pairs
                    .iter()
                    .find(|(n, _)| *n == k)
                    .map(|(_, v)| v.to_string())
            }
        };
        assert_eq!(
            spec.resolve_index(env(&[("SLURM_ARRAY_TASK_ID", "2")])),
            Ok(2)
        );
        assert_eq!(
            spec.resolve_index(env(&[("JOB_COMPLETION_INDEX", "3")])),
            Ok(3)
        );
        assert_eq!(
            spec.resolve_index(env(&[
                ("PT_SHARD_INDEX", "1"),
                ("SLURM_ARRAY_TASK_ID", "2")
            ])),
            Ok(1)
        );
        assert!(
            spec.resolve_index(env(&[]))
                .unwrap_err()
                .contains("SLURM_ARRAY_TASK_ID")
        );
        assert!(
            spec.resolve_index(env(&[("JOB_COMPLETION_INDEX", "4")]))
                .unwrap_err()
                .contains("below")
        );
        assert!(spec.resolve_index(env(&[("PT_SHARD_INDEX", "x")])).is_err());
        assert_eq!(parse_shard("2/8").unwrap().index, Some(2));
        assert!(parse_shard("1/0").is_err() && parse_shard("1").is_err());
    }

    #[test]
    fn values_parse_or_say_what_they_expect() {
        assert_eq!(parse_size("64x48"), Ok((64, 48)));
        assert!(parse_size("64").unwrap_err().contains("WxH"));
        assert_eq!(parse_range("3..9"), Ok(3..9));
        assert!(parse_range("3-9").is_err());
        assert_eq!(parse_vec3("1, 2,3"), Ok(Vec3::new(1.0, 2.0, 3.0)));
        assert!(parse_vec3("1,2").is_err() && parse_vec3("1,nan,2").is_err());
        assert!(parse_accel("octree").unwrap_err().contains("two-level"));
        assert!(parse_sampler("halton").is_err() && parse_strategy("path").is_err());
    }

    #[derive(clap::Parser)]
    struct Cli {
        #[command(flatten)]
        render: RenderArgs,
    }

    const D: Defaults = Defaults {
        width: 32,
        height: 16,
        spp: 8,
        max_depth: 5,
        out: "out/test.png",
    };

    fn parse(args: &[&str]) -> Cli {
        let mut v = vec!["test"];
        v.extend(args);
        crate::parse_from("test", D, v)
    }

    #[test]
    fn every_flag_reaches_the_options() {
        let dir = std::env::temp_dir().join(format!("pt-cli-args-{}", std::process::id()));
        let out = dir.join("x.exr");
        let cli = parse(&[
            "--spp",
            "64",
            "--size",
            "20x10",
            "--max-depth",
            "3",
            "--seed",
            "9",
            "--threads",
            "2",
            "--clamp",
            "4",
            "--sampler",
            "stratified",
            "--strategy",
            "bsdf",
            "--adaptive",
            "0.05",
            "--adaptive-min",
            "8",
            "--out",
            out.to_str().unwrap(),
        ]);
        let r = cli.render.resolve(&D).unwrap();
        let expected = RenderOptions::new(20, 10)
            .spp(64)
            .max_depth(3)
            .seed(9)
            .threads(Some(2))
            .sample_clamp(Some(4.0))
            .sampler(SamplerKind::Stratified)
            .strategy(LightStrategy::BsdfOnly)
            .adaptive(Some(AdaptiveSampling::new(0.05, 8)));
        assert_eq!(r.options, expected);
        assert_eq!(r.out, out);
        // The program's defaults, and a part of a render named after its range.
        let cli = parse(&["--spp-range", "2..6", "--out", "out/test.png"]);
        let r = cli.render.resolve(&D).unwrap();
        assert_eq!((r.options.width, r.options.spp), (32, 8));
        assert_eq!(r.options.spp_range, Some(2..6));
        assert_eq!(r.out, PathBuf::from("out/test.2-6.exr"));
        let folder = format!("{}/", dir.display());
        let cli = parse(&["--shard", "1/4", "--out", &folder]);
        assert_eq!(
            cli.render.resolve(&D).unwrap().out,
            dir.join("test.2-4.exr")
        );
        let cli = parse(&["--out", &folder]);
        assert_eq!(cli.render.resolve(&D).unwrap().out, dir.join("test.png"));
        let cli = parse(&["--shard", "3/4"]);
        assert_eq!(
            cli.render.resolve(&D).unwrap().options.spp_range,
            Some(6..8)
        );
        // Later flags win.
        let cli = parse(&["--spp", "2", "--spp", "4"]);
        assert_eq!(cli.render.spp, 4);
        // Options out of range are usage errors naming the option.
        let f = parse(&["--threads", "0"]).render.resolve(&D).unwrap_err();
        assert_eq!(f.code, crate::EXIT_USAGE);
        assert!(f.message.contains("thread"), "{f}");
        let f = parse(&["--shard", "0/9"]).render.resolve(&D).unwrap_err();
        assert!(f.message.contains("more shards than samples"), "{f}");
        let f = parse(&["--out", "x.tiff"]).render.resolve(&D).unwrap_err();
        assert!(f.message.contains(".png or .exr"), "{f}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
