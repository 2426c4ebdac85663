//! A scene file made ready to render: the camera and environment flags of `pt render` (and the
//! `render` example), and the defaults that make any file render lit.
//!
//! The camera is the one `--look-from` and `--look-at` place (either alone takes the other's
//! default: the eye at 0,0,5, the target at the origin), else the file's first camera
//! (`--camera-from-file` insists on it: an unusable one is then an error), else one that frames the
//! scene, upright along `--up` (0,0,1 for a Z-up model), with a warning when it sees mostly back
//! faces (it is inside the model, or outside a closed one). `--fov` sets the lens of whichever is
//! used; the framing camera moves to keep the scene framed. The environment is `--env` (an
//! equirectangular `.hdr`/`.exr`, a cube-map directory, or `sunset`, `studio`, `cubemap` from the
//! assets). Without `--env`, a scene with no lights of its own, and a glTF file without punctual
//! lights (whose emissive materials are meant to be seen under a viewer's light), is lit as glTF
//! viewers light it, by the studio map (fetched like any asset; a uniform white sky when it cannot
//! be had), and the summary says so; `--env none` keeps it dark.

use std::path::Path;

use clap::Args;
use pt_core::glam::{Vec2, Vec3};
use pt_core::{
    BuiltinLight, Camera, CameraError, CameraSample, PinholeCamera, Rgb, Scene, UniformEnvironment,
};
use pt_scene::{BuildOptions, LoadError, SceneBundle, SceneDesc};

use crate::Failure;
use crate::args::parse_vec3;

/// The flags that turn a scene file into a scene and camera.
#[derive(Args, Clone, Debug, Default)]
pub struct SceneArgs {
    /// Use the file's first camera (the default when it has one; --fov changes its lens); an
    /// unusable one is an error
    #[arg(long, conflicts_with_all = ["look_from", "look_at", "up"])]
    pub camera_from_file: bool,
    /// Camera position [default: 0,0,5 with --look-at]
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub look_from: Option<Vec3>,
    /// Point the camera looks at [default: 0,0,0 with --look-from]
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub look_at: Option<Vec3>,
    /// Up direction; without --look-from and --look-at, of the camera that frames the scene
    /// (0,0,1 for a Z-up model) [default: 0,1,0]
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub up: Option<Vec3>,
    /// Vertical field of view in degrees of whichever camera is used: the one --look-from and
    /// --look-at place, the file's, or the one that frames the scene (moved to keep it
    /// framed) [default: 40, or the file camera's]
    #[arg(long, value_name = "DEG")]
    pub fov: Option<f32>,
    /// Environment: a .hdr/.exr file, a cube-map directory, sunset, studio, cubemap, or none
    #[arg(long, value_name = "ENV")]
    pub env: Option<String>,
    /// Multiply the environment's radiance
    #[arg(long, value_name = "S", default_value_t = 1.0)]
    pub env_intensity: f32,
    /// Emitting surfaces emit from both faces (as Blender Cycles does)
    #[arg(long)]
    pub two_sided_lights: bool,
    /// Sample emitting triangles by solid angle (less noise near large lights)
    #[arg(long)]
    pub solid_angle_lights: bool,
}

/// A loaded scene and what the summary line should say about it.
#[derive(Debug)]
pub struct Loaded {
    /// The scene and its camera.
    pub bundle: SceneBundle,
    /// `, FILE: N meshes, N objects, N lights` and how it is lit when pt chose.
    pub summary: String,
}

/// The camera the view flags ask for (`None`: the one [`SceneDesc::build`] chooses, the file's
/// or the default framing one), and whether the render's camera frames the scene.
fn choose_camera(
    desc: &SceneDesc,
    args: &SceneArgs,
    file: &Path,
) -> Result<(Option<PinholeCamera>, bool), Failure> {
    let camera_error = |e: CameraError| Failure::usage(format!("camera: {e}"));
    if let Some(up) = args.up
        && up.try_normalize().is_none()
    {
        let (x, y, z) = (up.x, up.y, up.z);
        return Err(Failure::usage(format!(
            "--up {x},{y},{z} is not a direction"
        )));
    }
    if let Some(fov) = args.fov
        && !(fov > 0.0 && fov < 180.0)
    {
        return Err(camera_error(CameraError::InvalidFov(fov)));
    }
    // A view placed by position or target.
    if args.look_from.is_some() || args.look_at.is_some() {
        let from = args.look_from.unwrap_or(Vec3::new(0.0, 0.0, 5.0));
        let at = args.look_at.unwrap_or(Vec3::ZERO);
        let camera = PinholeCamera::look_at(
            from,
            at,
            args.up.unwrap_or(Vec3::Y),
            args.fov.unwrap_or(40.0),
        )
        .map_err(camera_error)?;
        return Ok((Some(camera), false));
    }
    // The file's camera, asked for or not: an unusable one is an error when asked for; when
    // not, the scene is framed (with a warning, which `build` gives when it frames it itself).
    let file_camera = match desc.try_file_camera() {
        Ok(camera) => camera,
        Err(e) if args.camera_from_file => {
            return Err(Failure::usage(format!("--camera-from-file: {e}")));
        }
        Err(e) => {
            if args.up.is_some() || args.fov.is_some() {
                log::warn!("{e}; using a camera that frames the scene");
            }
            None
        }
    };
    if let Some(camera) = file_camera {
        if args.up.is_some() {
            log::warn!(
                "--up has no effect on the camera of {}; pass --look-from and --look-at to \
                 replace that camera",
                file.display()
            );
        }
        let Some(fov) = args.fov else {
            return Ok((Some(camera), false));
        };
        // The file's view through another lens.
        let eye = camera.eye();
        let camera = PinholeCamera::look_at(eye, eye + camera.forward(), camera.up(), fov)
            .map_err(camera_error)?;
        return Ok((Some(camera), false));
    }
    if args.camera_from_file {
        log::warn!("{} has no camera; framing the scene", file.display());
    }
    if args.up.is_none() && args.fov.is_none() {
        return Ok((None, true));
    }
    // Framed upright along --up, through --fov's lens; a scene without finite bounds gets
    // `build`'s fallback.
    let up = args.up.unwrap_or(Vec3::Y);
    let camera = desc.framing_camera_with(up, args.fov.unwrap_or(40.0));
    Ok((camera, true))
}

/// Load `file` and build it with these flags for an image of `width x height`.
///
/// # Errors
///
/// A file or flag that is bad is exit code 2 (naming it); a named asset that cannot be fetched
/// is exit code 1.
pub fn load(file: &Path, args: &SceneArgs, width: u32, height: u32) -> Result<Loaded, Failure> {
    let desc = pt_scene::load_scene(file).map_err(Failure::usage)?;
    let mut options = BuildOptions::default();
    let (camera, framing) = choose_camera(&desc, args, file)?;
    options.camera = camera;
    let mut lit_by = String::new();
    match args.env.as_deref() {
        Some("none") => {}
        Some(env) => options.environment = Some(environment(env, args.env_intensity)?),
        // glTF viewers light a file by their environment unless it brings punctual lights: its
        // emissive materials (labels, screens) are meant to be seen under that light too. So a
        // glTF file without punctual lights gets the default environment, as does any file
        // without emitters at all.
        None if !desc.has_lights() || (is_gltf(file) && desc.lights.is_empty()) => {
            let (light, what) = default_environment(args.env_intensity)?;
            options.environment = Some(light);
            let why = if desc.has_lights() {
                "no punctual lights in the glTF file"
            } else {
                "no lights in the file"
            };
            lit_by = format!(", {why}: lit by {what} (--env none for none)");
        }
        None => {}
    }
    options.solid_angle_light_sampling = args.solid_angle_lights;
    options.two_sided_lights = args.two_sided_lights;
    let bundle = desc.build(&options).map_err(Failure::run)?;
    if framing {
        let aspect = width as f32 / height.max(1) as f32;
        let back = back_face_fraction(&bundle.scene, &bundle.camera, aspect);
        if back > 0.5 {
            log::warn!(
                "{}: {:.0}% of what the framing camera sees are back faces: it is inside the model \
                 or outside a room; pass --look-from X,Y,Z --look-at X,Y,Z (and --fov)",
                file.display(),
                back * 100.0
            );
        }
    }
    let stats = bundle.scene.stats();
    let summary = format!(
        ", {}: {} meshes, {} objects, {} lights{lit_by}",
        file.display(),
        stats.meshes,
        stats.objects,
        stats.lights
    );
    Ok(Loaded { bundle, summary })
}

/// Load `file` as a description only (for `pt info`).
///
/// # Errors
///
/// The file cannot be read or is invalid.
pub fn describe(file: &Path) -> Result<SceneDesc, LoadError> {
    pt_scene::load_scene(file)
}

/// The environment `--env` names, its radiance scaled by `intensity`.
fn environment(spec: &str, intensity: f32) -> Result<BuiltinLight, Failure> {
    // A named asset that cannot be had is a failure of the run (exit 1); a bad file named on
    // the command line is bad input (exit 2).
    let light: BuiltinLight = match spec {
        "sunset" => pt_scene::load_equirect_asset("env/venice_sunset_1k.hdr")
            .map_err(Failure::run)?
            .into(),
        "studio" => pt_scene::load_equirect_asset("env/studio_small_03_1k.hdr")
            .map_err(Failure::run)?
            .into(),
        "cubemap" => pt_scene::load_cubemap_asset("env/cubemap-Park3Med")
            .map_err(Failure::run)?
            .into(),
        path if Path::new(path).is_dir() => {
            pt_scene::load_cubemap(path).map_err(Failure::usage)?.into()
        }
        path => pt_scene::load_equirect(path)
            .map_err(Failure::usage)?
            .into(),
    };
    let scaled = match light {
        BuiltinLight::EquirectEnvironment(m) => m.with_scale(intensity).map(Into::into),
        BuiltinLight::CubemapEnvironment(m) => m.with_scale(intensity).map(Into::into),
        other => Ok(other),
    };
    scaled.map_err(|e| Failure::usage(format!("--env-intensity: {e}")))
}

fn is_gltf(file: &Path) -> bool {
    file.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}

/// The studio map glTF viewers light with, fetched like any asset; a uniform white sky when it
/// cannot be had (offline, say), with a warning saying why.
fn default_environment(intensity: f32) -> Result<(BuiltinLight, &'static str), Failure> {
    const STUDIO: &str = "env/studio_small_03_1k.hdr";
    let studio = pt_scene::load_equirect_asset(STUDIO)
        .map_err(|e| e.to_string())
        .and_then(|m| m.with_scale(intensity).map_err(|e| e.to_string()));
    match studio {
        Ok(m) => Ok((m.into(), "the studio environment")),
        Err(e) => {
            log::warn!(
                "the default environment {STUDIO} is not available ({e}); using a uniform sky"
            );
            let sky = UniformEnvironment::new(Rgb::splat(intensity))
                .map_err(|e| Failure::usage(format!("--env-intensity: {e}")))?;
            Ok((sky.into(), "a uniform white sky"))
        }
    }
}

/// Of a 16x16 grid of primary rays, the fraction of those that hit something that hit a surface
/// from behind (against its geometric normal): near 1 when the camera is inside a model or
/// outside a room. 0 when nothing is hit.
fn back_face_fraction<C: Camera>(scene: &Scene, camera: &C, aspect: f32) -> f32 {
    let n = 16;
    let (mut back, mut hits) = (0, 0);
    for j in 0..n {
        for i in 0..n {
            let film = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
            let ray = camera.generate_ray(&CameraSample::new(film, aspect));
            if let Some(hit) = scene.intersect(&ray) {
                hits += 1;
                if hit.point.n.dot(ray.dir) > 0.0 {
                    back += 1;
                }
            }
        }
    }
    back as f32 / hits.max(1) as f32
}
