//! Render any scene file: glTF 2.0 (`.gltf`, `.glb`), OBJ with MTL materials, or a PLY mesh.
//!
//! ```text
//! cargo run --release --example render -- scene.glb
//! cargo run --release --example render -- model.obj --look-from 0,1,4 --look-at 0,0.5,0 --fov 35
//! cargo run --release --example render -- model.glb --env ../shared/assets/env/venice_sunset_1k.hdr
//! ```
//!
//! It is `pt render` (crates/pt-cli) under the example's name; the scene flags are documented in
//! `pt_cli::scene`. The camera is the one `--look-from` and `--look-at` place (either alone takes
//! the other's default: the eye at 0,0,5, the target at the origin), else the file's first camera
//! (`--camera-from-file` insists on it: an unusable one is then an error), else one that frames the
//! scene, upright along `--up` (0,0,1 for a Z-up model), with a warning when it sees mostly back
//! faces (it is inside the model, or outside a closed one). `--fov` sets the lens of whichever is
//! used; the framing camera moves to keep the scene framed. The environment is `--env` (an
//! equirectangular `.hdr`/`.exr`, a cube-map directory, or `sunset`, `studio`, `cubemap` from the
//! assets). Without `--env`, a scene with no lights of its own, and a glTF file without punctual
//! lights (whose emissive materials are meant to be seen under a viewer's light), is lit as glTF
//! viewers light it, by the studio map (fetched like any asset; a uniform white sky when it cannot
//! be had), and the summary says so; `--env none` keeps it dark.

use std::path::PathBuf;

use clap::Parser;
use pt_cli::scene::SceneArgs;
use pt_cli::{Defaults, Job, RenderArgs};

const NAME: &str = "render";

/// Render any scene file: glTF 2.0, OBJ with MTL materials, or a PLY mesh (the `pt render`
/// command as an example).
#[derive(Parser)]
struct Cli {
    /// The scene file (.gltf, .glb, .obj or .ply)
    file: PathBuf,
    #[command(flatten)]
    render: RenderArgs,
    #[command(flatten)]
    scene: SceneArgs,
}

fn main() {
    let cli: Cli = pt_cli::parse(NAME, Defaults::RENDER);
    let job = Job::new(
        NAME,
        &cli.render,
        &Defaults::RENDER,
        &cli.file.display().to_string(),
    )
    .unwrap_or_else(|f| f.exit());
    let loaded = pt_cli::scene::load(&cli.file, &cli.scene, job.options.width, job.options.height)
        .unwrap_or_else(|f| f.exit());
    let out = job.render(&loaded.bundle.scene, &loaded.bundle.camera);
    job.finish(&out, &loaded.summary);
}
