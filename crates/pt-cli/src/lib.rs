//! `pt`, the command-line renderer, and the command-line code its subcommands share with the
//! example programs (DESIGN.md section 8): the flags every render takes, progress on a
//! terminal, the summary line, shards for render farms, and exit codes.
//!
//! Exit codes: **0** done; **1** failed during the run (an asset that cannot be fetched, a file
//! that cannot be written); **2** bad arguments or bad input named on the command line (a usage
//! message or a message naming the flag, file and problem, before any rendering).
//!
//! A program of its own parses with [`parse`], resolves the common flags into a [`Job`], and
//! renders:
//!
//! ```no_run
//! use clap::Parser;
//! use pt_cli::{Defaults, Job, RenderArgs};
//!
//! /// Render the Cornell box.
//! #[derive(Parser)]
//! struct Cli {
//!     #[command(flatten)]
//!     render: RenderArgs,
//! }
//!
//! let defaults = Defaults { width: 256, height: 256, spp: 16, max_depth: 8, out: "box.png" };
//! let cli: Cli = pt_cli::parse("my_box", defaults);
//! let job = Job::new("my_box", &cli.render, &defaults, "").unwrap_or_else(|f| f.exit());
//! let bundle = pt_scene::presets::cornell_box().unwrap_or_else(|e| pt_cli::Failure::run(e).exit());
//! let out = job.render(&bundle.scene, &bundle.camera);
//! job.finish(&out, "");
//! ```
#![forbid(unsafe_code)]

pub mod args;
pub mod farm;
pub mod info;
pub mod output;
mod progress;
pub mod scene;

use std::ffi::OsString;
use std::fmt;
use std::path::PathBuf;

use clap::CommandFactory;
use pt_core::{Aovs, Camera, Light, Material, PartialRender, RenderOptions, RenderOutput, Scene};

pub use args::{Defaults, RenderArgs, Resolved, ShardSpec};
pub use progress::{init, warnings};

/// Exit code of a run that failed while it ran.
pub const EXIT_FAILED: i32 = 1;
/// Exit code of bad arguments or bad input named on the command line.
pub const EXIT_USAGE: i32 = 2;

/// Why a program stops: the message and the exit code ([`EXIT_FAILED`] or [`EXIT_USAGE`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Failure {
    /// The exit code.
    pub code: i32,
    /// What went wrong, naming the flag, file or asset.
    pub message: String,
}

impl Failure {
    /// Bad arguments or bad input named on the command line (exit code 2).
    pub fn usage(e: impl fmt::Display) -> Self {
        Self {
            code: EXIT_USAGE,
            message: e.to_string(),
        }
    }

    /// A failure during the run (exit code 1).
    pub fn run(e: impl fmt::Display) -> Self {
        Self {
            code: EXIT_FAILED,
            message: e.to_string(),
        }
    }

    /// Print `NAME: message` to stderr and exit with the code. The program name is the one
    /// given to [`parse`] or [`init`].
    pub fn exit(&self) -> ! {
        eprintln!("{}: {}", progress::program(), self.message);
        std::process::exit(self.code)
    }
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

/// Parse the process's arguments into `C` with `name` as the program name and `defaults` for the
/// common flags (so `--help` shows them), after [`init`]. Bad arguments print the problem and
/// the usage and exit with code 2; `--help` and `--version` exit with 0.
pub fn parse<C: clap::Parser>(name: &'static str, defaults: Defaults) -> C {
    parse_from(name, defaults, std::env::args_os())
}

/// [`parse`] from the given arguments (the first is the program's path).
pub fn parse_from<C: clap::Parser>(
    name: &'static str,
    defaults: Defaults,
    args: impl IntoIterator<Item = impl Into<OsString> + Clone>,
) -> C {
    parse_matches_from(name, defaults, args).0
}

/// [`parse`], also returning clap's matches (to ask, with [`given`], which flags the user gave).
pub fn parse_matches<C: clap::Parser>(
    name: &'static str,
    defaults: Defaults,
) -> (C, clap::ArgMatches) {
    parse_matches_from(name, defaults, std::env::args_os())
}

fn parse_matches_from<C: clap::Parser>(
    name: &'static str,
    defaults: Defaults,
    args: impl IntoIterator<Item = impl Into<OsString> + Clone>,
) -> (C, clap::ArgMatches) {
    init(name);
    let matches = get_matches(command::<C>(name, defaults), args);
    let parsed = C::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    (parsed, matches)
}

/// Parse `args` with `cmd`. On bad arguments: the problem, then the usage, on stderr, and exit
/// code 2 (clap alone shows the usage for some errors only); `--help` and `--version` print and
/// exit with 0.
pub fn get_matches(
    mut cmd: clap::Command,
    args: impl IntoIterator<Item = impl Into<OsString> + Clone>,
) -> clap::ArgMatches {
    match cmd.try_get_matches_from_mut(args) {
        Ok(m) => m,
        Err(e) if !e.use_stderr() => e.exit(),
        Err(e) => {
            let usage = cmd.render_usage();
            let text = e.render().to_string();
            eprint!("{text}");
            if !text.contains("Usage:") {
                eprintln!("\n{usage}");
            }
            std::process::exit(EXIT_USAGE)
        }
    }
}

/// Whether the flag with clap id `id` (the field name: `spp`, `size`, `max_depth`) was given on
/// the command line rather than taken from its default.
#[must_use]
pub fn given(matches: &clap::ArgMatches, id: &str) -> bool {
    matches.value_source(id) == Some(clap::parser::ValueSource::CommandLine)
}

/// The clap command of `C` named `name`, with `defaults` for the common flags when it has them.
#[must_use]
pub fn command<C: CommandFactory>(name: &'static str, defaults: Defaults) -> clap::Command {
    // A flag given twice takes its last value, as in most command lines (a script's defaults
    // followed by the user's).
    with_defaults(
        C::command()
            .name(name)
            .bin_name(name)
            .args_override_self(true),
        defaults,
    )
}

/// Set the defaults of the common flags of `cmd` (those it has).
#[must_use]
pub fn with_defaults(mut cmd: clap::Command, d: Defaults) -> clap::Command {
    let set = |cmd: clap::Command, id: &'static str, value: String| {
        if cmd.get_arguments().any(|a| a.get_id() == id) {
            cmd.mut_arg(id, |a| a.default_value(value).required(false))
        } else {
            cmd
        }
    };
    cmd = set(cmd, "spp", d.spp.to_string());
    cmd = set(cmd, "size", format!("{}x{}", d.width, d.height));
    cmd = set(cmd, "max_depth", d.max_depth.to_string());
    set(cmd, "out", d.out.to_string())
}

/// One render asked for on a command line: its options, output, label and how to report.
#[derive(Clone, Debug)]
pub struct Job {
    /// The program's name, first word of every line it prints.
    pub name: &'static str,
    /// The render options.
    pub options: RenderOptions,
    /// Where the image (or partial EXR) goes.
    pub out: PathBuf,
    /// What a part of this render is a part of (see [`args::label`]).
    pub label: String,
    /// No progress bar and no summary line.
    pub quiet: bool,
    /// The summary as JSON.
    pub json: bool,
    /// The auxiliary outputs to write beside the image (`--aov`).
    pub aovs: Aovs,
    /// Also write the denoised image (`--denoise`).
    pub denoise: bool,
}

impl Job {
    /// The job of these flags; `extra` is added to the label of partial renders (the settings
    /// of the program's own flags that change the image).
    ///
    /// # Errors
    ///
    /// As [`RenderArgs::resolve`].
    pub fn new(
        name: &'static str,
        args: &RenderArgs,
        defaults: &Defaults,
        extra: &str,
    ) -> Result<Self, Failure> {
        let Resolved { options, out } = args.resolve(defaults)?;
        if args.denoise {
            // Before the render: a missing library should not cost the user a render.
            output::check_denoiser()?;
        }
        Ok(Self {
            name,
            label: args::label(name, &options, extra),
            options,
            out,
            quiet: args.quiet,
            json: args.json,
            aovs: args.aov.unwrap_or_default(),
            denoise: args.denoise,
        })
    }

    /// Render with a progress bar (with ETA) on a terminal, nothing otherwise; exits with code
    /// 1 if the render fails.
    pub fn render<M: Material, L: Light, C: Camera>(
        &self,
        scene: &Scene<M, L>,
        camera: &C,
    ) -> RenderOutput {
        self.render_with(scene, camera, &self.options)
    }

    /// [`Job::render`] with other options (the job's output and reporting).
    pub fn render_with<M: Material, L: Light, C: Camera>(
        &self,
        scene: &Scene<M, L>,
        camera: &C,
        options: &RenderOptions,
    ) -> RenderOutput {
        progress::render(self.name, !self.quiet, scene, camera, options)
            .unwrap_or_else(|e| Failure::run(e).exit())
    }

    /// Write the image (a partial EXR for a part of a render) with the AOVs asked for, and the
    /// denoised image beside it when asked for (`NAME.denoised.EXT`), and print the summary
    /// line (`NAME: WxH, N spp, T s, ...` followed by `extra`), or the JSON summary; exits with
    /// code 1 if a file cannot be written or denoising fails.
    pub fn finish(&self, out: &RenderOutput, extra: &str) {
        if let Some(dir) = self.out.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)
                .unwrap_or_else(|e| Failure::run(format!("{}: {e}", dir.display())).exit());
        }
        let mut written = vec![self.out.clone()];
        if self.options.spp_range.is_some() {
            PartialRender::new(out, self.label.clone())
                .write_exr(&self.out)
                .unwrap_or_else(|e| Failure::run(e).exit());
        } else {
            written = output::write_render(out, &self.out, self.aovs).unwrap_or_else(|f| f.exit());
        }
        let mut denoised = None;
        if self.denoise {
            let (path, took) = output::write_denoised(
                &out.image,
                out.albedo.as_ref(),
                out.normal.as_ref(),
                &self.out,
            )
            .unwrap_or_else(|f| f.exit());
            written.push(path.clone());
            denoised = Some((path, took));
        }
        if self.json {
            let mut summary = summary_json(self.name, out, &self.out, extra);
            summary["files"] = written
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .into();
            if let Some((path, took)) = &denoised {
                summary["denoised"] = path.display().to_string().into();
                summary["denoise_seconds"] = took.as_secs_f64().into();
            }
            println!("{summary}");
        } else if !self.quiet {
            println!("{}: {}{extra}", self.name, out.stats);
            if let Some((path, took)) = &denoised {
                println!(
                    "{}: denoised in {:.2} s -> {}",
                    self.name,
                    took.as_secs_f64(),
                    path.display()
                );
            }
        }
    }
}

/// The machine-readable summary of a finished render.
#[must_use]
pub fn summary_json(
    name: &str,
    out: &RenderOutput,
    path: &std::path::Path,
    extra: &str,
) -> serde_json::Value {
    let s = &out.stats;
    serde_json::json!({
        "program": name,
        "width": s.width,
        "height": s.height,
        "spp": s.spp,
        "sample_range": [s.sample_range.start, s.sample_range.end],
        "total_spp": s.total_spp,
        "seed": s.seed,
        "seconds": s.elapsed.as_secs_f64(),
        "samples": s.samples,
        "rays": s.rays,
        "msamples_per_second": s.msamples_per_second(),
        "mrays_per_second": s.mrays_per_second(),
        "non_finite_samples": s.non_finite_samples,
        "clamped_samples": s.clamped_samples,
        "saturated_samples": s.saturated_samples,
        "adaptive_saved": s.adaptive_saved,
        "skipped": s.skipped,
        "out": path.display().to_string(),
        "notes": extra.trim_start_matches(", "),
    })
}
