//! The scene analysis (DESIGN.md section 6): what a scene needs is found once at build time,
//! the render leaves out the rest and says so, and leaving it out never changes the image.
//!
//! The equivalence test renders scenes twice: with the built-in materials, whose
//! `Material::properties` let the renderer skip work, and with the same materials behind a
//! wrapper that keeps the trait's conservative default (claims every need), so nothing is
//! skipped. The images must be bit-identical.

use pt::prelude::*;
use pt::pt_core::{Material, MaterialContext, Mirror, SceneFeatures, Texture, UniformEnvironment};
use pt::pt_scene::presets::CornellBox;

/// A built-in material that claims every need (the trait's default `properties`).
#[derive(Clone, Debug)]
struct Conservative(BuiltinMaterial);

impl Material for Conservative {
    type Bsdf = <BuiltinMaterial as Material>::Bsdf;
    fn bsdf(&self, ctx: &MaterialContext) -> Self::Bsdf {
        self.0.bsdf(ctx)
    }
}

impl From<BuiltinMaterial> for Conservative {
    fn from(m: BuiltinMaterial) -> Self {
        Self(m)
    }
}

/// Bit-identical images, or a message naming the first pixel that differs.
fn assert_same(a: &Image, b: &Image, what: &str) {
    let first = a
        .as_slice()
        .iter()
        .zip(b.as_slice())
        .position(|(x, y)| x.to_bits() != y.to_bits());
    assert!(
        first.is_none(),
        "{what}: images differ at value {first:?} (pixel {:?})",
        first.map(|i| (i / 3) as u32 % a.width())
    );
}

fn features<M, L>(scene: &Scene<M, L>) -> SceneFeatures {
    *scene.features()
}

#[test]
fn the_cornell_box_needs_lights_but_no_environment_or_textures() {
    let b = presets::cornell_box().unwrap();
    let f = features(&b.scene);
    assert!(f.light_sampling && f.non_delta_materials);
    assert!(!f.environment && !f.texture_coordinates);
    let out = render(&b.scene, &b.camera, &RenderOptions::new(8, 8).spp(1), None).unwrap();
    let line = out.stats.to_string();
    assert!(
        line.contains("skipped: environment lookups (no environment), texture coordinates (no textures), lens samples (pinhole camera)"),
        "{line}"
    );
}

#[test]
fn mirrors_under_an_environment_need_no_light_sampling() {
    let mut s = SceneBuilder::new();
    let mesh = s.add_mesh(Mesh::new(
        pt::pt_accel::TriangleMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]])
            .unwrap(),
    ));
    let m = s.add_material(Mirror::new(Rgb::splat(0.9)));
    s.add_object(Object::new(mesh, m));
    s.add_light(UniformEnvironment::new(Rgb::WHITE).unwrap());
    let scene = s.build().unwrap();
    let f = features(&scene);
    assert!(f.environment && f.light_sampling && !f.non_delta_materials);
    assert_eq!(
        f.skipped(),
        [
            "light sampling and MIS (only delta BSDFs)",
            "texture coordinates (no textures)"
        ]
    );
}

#[test]
fn textured_materials_need_texture_coordinates() {
    let mut s = SceneBuilder::new();
    let mesh = s.add_mesh(Mesh::new(
        pt::pt_accel::TriangleMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]])
            .unwrap(),
    ));
    let texture = Texture::new(Image::new(2, 2));
    let pbr = pt::pt_core::PbrMaterial {
        base_color_texture: Some(texture.into()),
        ..Default::default()
    };
    let m = s.add_material(pbr);
    s.add_object(Object::new(mesh, m));
    let f = features(&s.build().unwrap());
    assert!(f.texture_coordinates && f.non_delta_materials && !f.light_sampling);
    assert!(f.skipped().contains(&"light sampling (no lights)"));
}

/// Skipping never changes the image: the Cornell box with a mirror block and an environment
/// (so every skip that applies is exercised: texture coordinates here, and in the mirror scene
/// below light sampling), rendered with and without the analysis, bit for bit.
#[test]
fn skipping_work_never_changes_the_image() {
    fn cornell<M: Material + From<BuiltinMaterial>>() -> SceneBundle<M> {
        let mut cb = CornellBox::<M>::empty_with();
        let mirror = cb
            .builder()
            .add_material(BuiltinMaterial::mirror(Rgb::splat(0.9)));
        let white = cb.white();
        cb.add_tall_block(mirror);
        cb.add_short_block(white);
        cb.build().unwrap()
    }
    let opts = RenderOptions::new(24, 24).spp(8).seed(5);
    let skipping = cornell::<BuiltinMaterial>();
    let full = cornell::<Conservative>();
    let a = render(&skipping.scene, &skipping.camera, &opts, None).unwrap();
    let b = render(&full.scene, &full.camera, &opts, None).unwrap();
    assert!(a.stats.skipped.len() > b.stats.skipped.len());
    assert_same(&a.image, &b.image, "Cornell box with a mirror block");

    // Only mirrors, lit by a uniform environment: light sampling is skipped.
    fn mirrors<M: Material + From<BuiltinMaterial>>() -> Scene<M> {
        let mut s = SceneBuilder::<M>::default();
        let mesh = s.add_mesh(pt::pt_scene::shapes::sphere(1.0, 16, 32));
        let m = s.add_material(BuiltinMaterial::mirror(Rgb::splat(0.8)));
        s.add_object(Object::new(mesh, m));
        s.add_light(UniformEnvironment::new(Rgb::splat(0.7)).unwrap());
        s.build().unwrap()
    }
    let camera =
        PinholeCamera::look_at(Vec3::new(0.0, 0.5, 4.0), Vec3::ZERO, Vec3::Y, 40.0).unwrap();
    let a = render(&mirrors::<BuiltinMaterial>(), &camera, &opts, None).unwrap();
    let b = render(&mirrors::<Conservative>(), &camera, &opts, None).unwrap();
    assert!(
        a.stats
            .skipped
            .iter()
            .any(|s| s.starts_with("light sampling"))
    );
    assert!(
        !b.stats
            .skipped
            .iter()
            .any(|s| s.starts_with("light sampling"))
    );
    assert_eq!(a.image, b.image);
}
