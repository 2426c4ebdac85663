//! What the caller of a render can do while it runs: watch it and stop it.

use std::fmt;
use std::sync::atomic::{AtomicBool, Ordering};

/// Progress of a running render, reported after each finished tile.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct Progress {
    /// Tiles finished.
    pub tiles_done: usize,
    /// Tiles in the image.
    pub tiles_total: usize,
}

/// What the caller of a render can do while it runs: watch its progress and stop it. Both
/// are optional; the library itself never prints.
///
/// ```
/// use std::sync::atomic::{AtomicBool, Ordering};
/// use pt_core::{RenderControl, RenderError, RenderOptions, render};
/// # use pt_core::{BuiltinMaterial, Emission, Mesh, Object, PinholeCamera, Rgb, SceneBuilder};
/// # use pt_core::pt_accel::TriangleMesh;
/// # use pt_core::glam::Vec3;
/// # let mut b = SceneBuilder::new();
/// # let tri = b.add_mesh(Mesh::new(TriangleMesh::new(
/// #     vec![Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)],
/// #     vec![[0, 1, 2]],
/// # )?));
/// # let m = b.add_material(BuiltinMaterial::diffuse(Rgb::splat(0.5)));
/// # b.add_object(Object::new(tri, m).with_emission(Emission::new(Rgb::splat(2.0))));
/// # let scene = b.build()?;
/// # let camera = PinholeCamera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 30.0)?;
/// // Stop after the first finished tile (a user interface would set the flag from its thread).
/// let stop = AtomicBool::new(false);
/// let on_tile = |_| stop.store(true, Ordering::Relaxed);
/// let control = RenderControl::new().progress(&on_tile).cancel(&stop);
/// let result = render(&scene, &camera, &RenderOptions::new(64, 64), Some(&control));
/// assert!(matches!(result, Err(RenderError::Cancelled)));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Copy, Default)]
#[non_exhaustive]
pub struct RenderControl<'a> {
    /// Called from worker threads after each finished tile.
    pub progress: Option<&'a (dyn Fn(Progress) + Sync)>,
    /// When this becomes true (set from any thread), pixels not yet rendered are skipped and
    /// the render returns [`RenderError::Cancelled`](crate::RenderError::Cancelled). It is checked before every pixel.
    pub cancel: Option<&'a AtomicBool>,
}

impl<'a> RenderControl<'a> {
    /// No progress callback and no cancellation.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Call `f` after each finished tile.
    #[must_use]
    pub fn progress(mut self, f: &'a (dyn Fn(Progress) + Sync)) -> Self {
        self.progress = Some(f);
        self
    }

    /// Stop the render when `flag` becomes true.
    #[must_use]
    pub fn cancel(mut self, flag: &'a AtomicBool) -> Self {
        self.cancel = Some(flag);
        self
    }

    #[inline]
    pub(crate) fn cancelled(&self) -> bool {
        self.cancel.is_some_and(|c| c.load(Ordering::Relaxed))
    }
}

impl fmt::Debug for RenderControl<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("RenderControl")
            .field("progress", &self.progress.is_some())
            .field("cancel", &self.cancel.map(|c| c.load(Ordering::Relaxed)))
            .finish()
    }
}
