//! The Cornell box from Cornell's measured data.
//!
//! Geometry, camera and spectra are those published by the Cornell University Program of Computer
//! Graphics (see [`cornell_data`](super::cornell_data)). Reflectances and the light's radiance are
//! converted from the measured spectra to linear sRGB (see [`spectrum`](super::spectrum)):
//!
//! | surface | linear sRGB |
//! |---|---|
//! | white (floor, ceiling, back wall, blocks) | (0.738, 0.736, 0.737) |
//! | red wall (viewer's left) | (0.472, 0.047, 0.049) |
//! | green wall (viewer's right) | (0.088, 0.398, 0.084) |
//! | light, radiance | (17.20, 11.47, 3.06) |
//! | light, albedo | 0.78 |
//!
//! Units are millimetres, `+y` is up, the camera looks along `+z`. As in Mitsuba's version of the
//! scene, the light is moved 0.5 mm below the ceiling so the two are not coplanar.

use glam::{Affine3A, Vec3};
use pt_core::pt_accel::{Bounds3, TriangleMesh};
use pt_core::{
    BuiltinLight, BuiltinMaterial, Emission, Light, Material, MaterialId, Mesh, Object,
    PinholeCamera, Rgb, SceneBuilder, SceneError,
};

use crate::SceneBundle;
use crate::presets::cornell_data as data;
use crate::presets::spectrum::{sampled_spectrum_to_rgb, spectrum_to_rgb};

/// Distance the light is lowered below the ceiling, mm.
const LIGHT_DROP_MM: f32 = 0.5;

/// Albedo of the light fixture (from the data).
const LIGHT_ALBEDO: f32 = 0.78;

fn v(p: [f32; 3]) -> Vec3 {
    Vec3::from_array(p)
}

/// A mesh of quads (each split into two triangles, keeping the winding).
fn quads_mesh(quads: &[[[f32; 3]; 4]]) -> Mesh {
    let positions = quads.iter().flatten().map(|&p| v(p)).collect();
    let indices = (0..quads.len() as u32)
        .flat_map(|q| [[4 * q, 4 * q + 1, 4 * q + 2], [4 * q, 4 * q + 2, 4 * q + 3]])
        .collect();
    Mesh::new(TriangleMesh::new(positions, indices).expect("preset quads are well formed"))
}

/// The Cornell box under construction: the room and its light, plus whatever is added.
///
/// ```
/// use pt_scene::presets::CornellBox;
/// use pt_core::{BuiltinMaterial, Rgb};
///
/// // The room with a dark grey tall block and no short block.
/// let mut cb = CornellBox::empty();
/// let grey = cb.builder().add_material(BuiltinMaterial::diffuse(Rgb::splat(0.2)));
/// cb.add_tall_block(grey);
/// let bundle = cb.build()?;
/// assert_eq!(bundle.scene.lights().len(), 2);
/// # Ok::<(), pt_core::SceneError>(())
/// ```
///
/// For user material or light types (enums made with `material_enum!`/`light_enum!` that include
/// the built-in ones), [`CornellBox::empty_with`] builds the same room into a
/// `SceneBuilder<M, L>`.
#[derive(Clone, Debug)]
pub struct CornellBox<M = BuiltinMaterial, L = BuiltinLight> {
    builder: SceneBuilder<M, L>,
    white: MaterialId,
    red: MaterialId,
    green: MaterialId,
}

impl CornellBox {
    /// The room (floor, ceiling, back, red and green walls) and the ceiling light.
    #[must_use]
    pub fn empty() -> Self {
        Self::empty_with()
    }

    /// The classic scene: the room, the light and both blocks, all diffuse.
    #[must_use]
    pub fn classic() -> Self {
        let mut cb = Self::empty();
        let white = cb.white;
        cb.add_short_block(white).add_tall_block(white);
        cb
    }

    /// Albedo of the white surfaces.
    #[must_use]
    pub fn white_albedo() -> Rgb {
        sampled_spectrum_to_rgb(data::START_NM, data::STEP_NM, &data::WHITE)
    }

    /// Radiance of the light.
    #[must_use]
    pub fn light_radiance() -> Rgb {
        spectrum_to_rgb(&data::LIGHT_EMISSION)
    }

    /// The inside of the room, for placing objects: the floor is at `y = 0`.
    #[must_use]
    pub fn interior() -> Bounds3 {
        Bounds3::new(Vec3::ZERO, Vec3::new(549.6, 548.8, 559.2))
    }

    /// The camera of the classic view (square images).
    #[must_use]
    pub fn camera() -> PinholeCamera {
        let eye = v(data::CAMERA_EYE);
        PinholeCamera::look_at(
            eye,
            eye + v(data::CAMERA_DIR),
            v(data::CAMERA_UP),
            data::CAMERA_FOV_DEGREES,
        )
        .expect("the preset camera is valid")
    }
}

impl<M: Material + From<BuiltinMaterial>, L: Light + From<BuiltinLight>> CornellBox<M, L> {
    /// The room and light of [`CornellBox::empty`] in a builder for material type `M` and light
    /// type `L`: `CornellBox::<MyMaterial>::empty_with()`.
    #[must_use]
    pub fn empty_with() -> Self {
        let mut builder = SceneBuilder::<M, L>::default();
        let white = builder.add_material(BuiltinMaterial::diffuse(CornellBox::white_albedo()));
        let red = builder.add_material(BuiltinMaterial::diffuse(sampled_spectrum_to_rgb(
            data::START_NM,
            data::STEP_NM,
            &data::RED,
        )));
        let green = builder.add_material(BuiltinMaterial::diffuse(sampled_spectrum_to_rgb(
            data::START_NM,
            data::STEP_NM,
            &data::GREEN,
        )));
        let fixture = builder.add_material(BuiltinMaterial::diffuse(Rgb::splat(LIGHT_ALBEDO)));

        for (quad, material) in [
            (data::FLOOR, white),
            (data::CEILING, white),
            (data::BACK_WALL, white),
            (data::GREEN_WALL, green),
            (data::RED_WALL, red),
        ] {
            let mesh = builder.add_mesh(quads_mesh(&[quad]));
            builder.add_object(Object::new(mesh, material));
        }
        let light = builder.add_mesh(quads_mesh(&[data::LIGHT]));
        builder.add_object(
            Object::new(light, fixture)
                .with_transform(Affine3A::from_translation(Vec3::new(
                    0.0,
                    -LIGHT_DROP_MM,
                    0.0,
                )))
                .with_emission(Emission::new(CornellBox::light_radiance())),
        );
        Self {
            builder,
            white,
            red,
            green,
        }
    }

    /// Add the short block with the given material.
    pub fn add_short_block(&mut self, material: MaterialId) -> &mut Self {
        let mesh = self.builder.add_mesh(quads_mesh(&data::SHORT_BLOCK));
        self.builder.add_object(Object::new(mesh, material));
        self
    }

    /// Add the tall block with the given material.
    pub fn add_tall_block(&mut self, material: MaterialId) -> &mut Self {
        let mesh = self.builder.add_mesh(quads_mesh(&data::TALL_BLOCK));
        self.builder.add_object(Object::new(mesh, material));
        self
    }

    /// Place `mesh` standing on the floor: uniformly scaled to `height_mm` tall, turned by
    /// `rotation_y` radians about the vertical, centred at `(x, z)` on the floor. Returns the
    /// transform used. A mesh without finite extent is added untransformed.
    pub fn add_mesh_on_floor(
        &mut self,
        mesh: Mesh,
        material: MaterialId,
        height_mm: f32,
        center_xz: [f32; 2],
        rotation_y: f32,
    ) -> Affine3A {
        let b = mesh.geometry().bounds();
        let size = b.diagonal();
        let transform = if size.y > 0.0 && size.is_finite() {
            let s = height_mm / size.y;
            let base = Vec3::new(
                (b.min.x + b.max.x) * 0.5,
                b.min.y,
                (b.min.z + b.max.z) * 0.5,
            );
            Affine3A::from_translation(Vec3::new(center_xz[0], 0.0, center_xz[1]))
                * Affine3A::from_rotation_y(rotation_y)
                * Affine3A::from_scale(Vec3::splat(s))
                * Affine3A::from_translation(-base)
        } else {
            Affine3A::IDENTITY
        };
        let id = self.builder.add_mesh(mesh);
        self.builder
            .add_object(Object::new(id, material).with_transform(transform));
        transform
    }

    /// The scene builder, to add materials and objects.
    pub fn builder(&mut self) -> &mut SceneBuilder<M, L> {
        &mut self.builder
    }

    /// The white material.
    #[must_use]
    pub fn white(&self) -> MaterialId {
        self.white
    }

    /// The red material (left wall).
    #[must_use]
    pub fn red(&self) -> MaterialId {
        self.red
    }

    /// The green material (right wall).
    #[must_use]
    pub fn green(&self) -> MaterialId {
        self.green
    }

    /// Build the scene.
    pub fn build(self) -> Result<SceneBundle<M, L>, SceneError> {
        Ok(SceneBundle {
            scene: self.builder.build()?,
            camera: CornellBox::camera(),
        })
    }
}

/// The classic Cornell box: room, light and two diffuse blocks, with its camera.
pub fn cornell_box() -> Result<SceneBundle, SceneError> {
    CornellBox::classic().build()
}

#[cfg(test)]
mod tests {
    use super::*;
    use pt_core::pt_accel::Ray;

    #[test]
    fn classic_scene_has_the_expected_parts() {
        let b = cornell_box().unwrap();
        let s = b.scene.stats();
        assert_eq!(s.objects, 8);
        assert_eq!(s.unique_triangles, 5 * 2 + 2 + 2 * 10);
        assert_eq!(b.scene.lights().len(), 2);
        assert_eq!(s.accel.skipped_triangles, 0);
        // The light faces down and is seen from the floor below it.
        let hit = b
            .scene
            .intersect(&Ray::new(Vec3::new(278.0, 1.0, 280.0), Vec3::Y))
            .unwrap();
        assert!(hit.light.is_some());
        assert!((hit.point.p.y - (548.8 - LIGHT_DROP_MM)).abs() < 1e-3);
    }

    #[test]
    fn red_is_left_and_green_is_right_in_the_camera_view() {
        let cb = CornellBox::classic();
        let (red, green) = (cb.red(), cb.green());
        let b = cb.build().unwrap();
        let cam = CornellBox::camera();
        use pt_core::{Camera, CameraSample};
        let ray_at = |x: f32| cam.generate_ray(&CameraSample::new(glam::Vec2::new(x, 0.5), 1.0));
        let left = b.scene.intersect(&ray_at(0.02)).unwrap();
        let right = b.scene.intersect(&ray_at(0.98)).unwrap();
        assert_eq!(left.material, red.0, "red on the left");
        assert_eq!(right.material, green.0, "green on the right");
    }
}
