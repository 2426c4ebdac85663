//! `pt`: render scene files, spread a render over a render farm, merge the parts.
//!
//! ```text
//! pt render scene.glb --spp 256 --out scene.png
//! pt render scene.glb --spp 256 --shard 2/8          # one of 8 farm tasks: out/render.64-96.exr
//! pt render scene.glb --spp 256 --shard env/8        # the index from SLURM_ARRAY_TASK_ID, ...
//! pt merge out/render.*.exr --expect 8 --out scene.png
//! pt info scene.glb
//! pt completions bash > ~/.local/share/bash-completion/completions/pt
//! ```
//!
//! Exit codes: 0 done, 1 failed during the run, 2 bad arguments or input.
#![forbid(unsafe_code)]

use std::path::PathBuf;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use pt_cli::scene::SceneArgs;
use pt_cli::{Defaults, Job, RenderArgs};

/// pt, a physically based path tracer: render glTF, OBJ and PLY scenes, spread renders over
/// render farms, merge the parts.
///
/// Exit codes: 0 done, 1 failed during the run, 2 bad arguments or input.
#[derive(Parser)]
#[command(name = "pt", version, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene file (.gltf, .glb, .obj with its .mtl, .ply) to .png or .exr
    Render {
        /// The scene file
        file: PathBuf,
        #[command(flatten)]
        render: RenderArgs,
        #[command(flatten)]
        scene: SceneArgs,
    },
    /// Merge partial renders (--spp-range or --shard) into one image, bit for bit the single
    /// render
    Merge {
        /// The partial EXRs, in any order
        #[arg(required = true)]
        parts: Vec<PathBuf>,
        /// Output: .exr keeps the exact sums (it can be merged again), .png is tone-mapped
        #[arg(long, value_name = "PATH")]
        out: PathBuf,
        /// Refuse the merge unless the parts are the N shards of `--shard I/N`, complete
        #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
        expect: Option<u32>,
        /// Also write the merged image denoised by Intel Open Image Denoise (NAME.denoised.EXT;
        /// guided by albedo and normal when the parts were rendered with them, `--aov` or
        /// `--denoise`)
        #[arg(long)]
        denoise: bool,
        /// Print only errors
        #[arg(long, short)]
        quiet: bool,
    },
    /// Describe a scene file: geometry, materials by model, lights, textures, the camera a
    /// render would use, what pt ignores, a memory estimate
    Info {
        /// The scene file
        file: PathBuf,
        /// Print one JSON object
        #[arg(long)]
        json: bool,
    },
    /// Print a shell completion script (bash, zsh, fish, elvish, powershell)
    Completions {
        /// The shell
        shell: clap_complete::Shell,
    },
}

fn main() {
    pt_cli::init("pt");
    let cmd = Cli::command().args_override_self(true);
    // `pt render`'s defaults on its common flags, so `pt render --help` shows them.
    let cmd = cmd.mut_subcommand("render", |r| {
        pt_cli::with_defaults(r.args_override_self(true), Defaults::RENDER)
    });
    let matches = pt_cli::get_matches(cmd, std::env::args_os());
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    match cli.command {
        Command::Render {
            file,
            render,
            scene,
        } => {
            let job = Job::new(
                "pt",
                &render,
                &Defaults::RENDER,
                &file.display().to_string(),
            )
            .unwrap_or_else(|f| f.exit());
            let loaded = pt_cli::scene::load(&file, &scene, job.options.width, job.options.height)
                .unwrap_or_else(|f| f.exit());
            let out = job.render(&loaded.bundle.scene, &loaded.bundle.camera);
            job.finish(&out, &loaded.summary);
        }
        Command::Merge {
            parts,
            out,
            expect,
            denoise,
            quiet,
        } => {
            if denoise {
                pt_cli::output::check_denoiser().unwrap_or_else(|f| f.exit());
            }
            let merged = pt_cli::farm::merge(&parts, expect).unwrap_or_else(|f| f.exit());
            pt_cli::farm::write(&merged.render, &out).unwrap_or_else(|f| f.exit());
            let denoised = denoise.then(|| {
                let film = &merged.render.film;
                pt_cli::output::write_denoised(
                    &film.to_image(),
                    film.albedo_image().as_ref(),
                    film.normal_image().as_ref(),
                    &out,
                )
                .unwrap_or_else(|f| f.exit())
            });
            if !quiet {
                for line in &merged.lines {
                    println!("pt merge: {line}");
                }
                println!(
                    "{}",
                    pt_cli::farm::summary("pt merge", parts.len(), &out, &merged.render)
                );
                if let Some((path, took)) = denoised {
                    println!(
                        "pt merge: denoised in {:.2} s -> {}",
                        took.as_secs_f64(),
                        path.display()
                    );
                }
            }
        }
        Command::Info { file, json } => {
            let info = pt_cli::info::info(&file).unwrap_or_else(|f| f.exit());
            if json {
                println!("{}", info.json());
            } else {
                print!("{}", info.text());
            }
        }
        Command::Completions { shell } => {
            clap_complete::generate(shell, &mut Cli::command(), "pt", &mut std::io::stdout());
        }
    }
}
