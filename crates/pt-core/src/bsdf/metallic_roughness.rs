//! glTF's metallic-roughness model: [`MetallicRoughness`].

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3};

use crate::bsdf::fresnel::reflect;
use crate::bsdf::microfacet::{SMOOTH_ALPHA, TrowbridgeReitz, roughness_to_alpha};
use crate::bsdf::thin_film::thin_film_fresnel;
use crate::bsdf::{Bsdf, BsdfFlags, BsdfSample, TransportMode, same_hemisphere};
use crate::color::Rgb;
use crate::frame::Frame;
use crate::sampling::sample_cosine_hemisphere;

/// The metallic-roughness model of glTF 2.0 (the specification's Appendix B, "BRDF
/// Implementation"): a metal and a dielectric mixed by `metallic`.
///
/// - metal: `specular * (base + (1 - base) (1 - |v.h|)^5)` (Schlick's Fresnel with `F0` = the
///   base colour);
/// - dielectric: the specification's `fresnel_mix(diffuse, specular)`, a specular coating `F
///   specular` with `F = F0 + (1 - F0) (1 - |v.h|)^5` and `F0 = ((ior - 1) / (ior + 1))^2` (0.04
///   for 1.5), over a diffuse base `base / pi` weighted by what the coating lets through both
///   ways, `(1 - F(n.v)) (1 - F(n.l))`. The specification weights the base by `1 - F(v.h)`
///   instead, which is not reciprocal and reflects more than it receives near grazing angles
///   (directional albedo 1.36 for a rough white-ish dielectric at 84 degrees, 1.6 at 88,
///   measured by pt's energy check); the coupled weights keep the look (a 4% coating over the
///   base colour) and conserve energy;
/// - `specular = D G / (4 |n.l| |n.v|)`: Trowbridge-Reitz (GGX) with `alpha = roughness^2`,
///   Smith's height-correlated shadowing.
///
/// `f = (1 - metallic) dielectric + metallic metal`, reflection only (both faces act alike).
/// Sampled as a mixture: the specular lobe by visible normals (Heitz 2018) with probability
/// `p = w_s / (w_s + w_d)`, `w_s = metallic + (1 - metallic) F(n.v)`, `w_d = (1 - metallic)
/// (1 - F(n.v)) luminance(base)`, a cosine-weighted direction otherwise; the density is the
/// mixture's, `p pdf_spec + (1 - p) cos/pi`, so every sample weighs `f cos / pdf` exactly.
///
/// | parameter | meaning |
/// |---|---|
/// | `base_color` | linear RGB in `[0, 1]` (clamped) |
/// | `metallic` | `[0, 1]` (clamped) |
/// | `roughness` | perceptual, `[0, 1]`; `alpha = roughness^2`, at least `SMOOTH_ALPHA` (a mirror-smooth glTF surface is a very sharp glossy lobe, not a delta, so that its diffuse part keeps next-event estimation) |
/// | `ior` | of the dielectric, for `F0` (glTF's default 1.5; `KHR_materials_ior`) |
///
/// Extensions (builder methods):
///
/// - [`with_specular`](MetallicRoughness::with_specular) (`KHR_materials_specular`): the
///   dielectric's Fresnel becomes `F = F0 + (F90 - F0) (1 - |v.h|)^5` with the coloured
///   `F0 = min(F0(ior) specularColor, 1) specular` and `F90 = specular`, and the base is
///   weighted by `(1 - max F(n.v)) (1 - max F(n.l))`;
/// - [`with_clearcoat`](MetallicRoughness::with_clearcoat) (`KHR_materials_clearcoat`): a
///   second GGX lobe on top, `c Fc(v.h) D G / (4 |n.l| |n.v|)` with `Fc` Schlick's for IOR 1.5
///   and `c` the clearcoat factor, over the material weighted by `(1 - c Fc(n.v)) (1 - c
///   Fc(n.l))` (what the coat lets through both ways, reciprocal like the base's weight; the
///   extension weights by `1 - c Fc(n.v)` alone). Sampled with probability `c Fc(n.v)`, else
///   as above. The coat shares the shading normal unless
///   [`with_coat_normal`](MetallicRoughness::with_coat_normal) gives it its own `n_c` (glTF's
///   coat is not normal-mapped with the base, and may have a map of its own): then its cosines
///   are taken about `n_c` and the lobe is `c Fc D(h) G / (4 max(n_c.v n.l, n_c.l n.v))`,
///   which is the lobe above when `n_c = n`, stays reciprocal, and reflects at most what the
///   coat's own lobe about `n_c` would (the renderer weights by `n.l`). Directions the coat
///   samples below the shading horizon are failed samples.
/// - [`with_sheen`](MetallicRoughness::with_sheen) (`KHR_materials_sheen`): a sheen lobe
///   `sheenColor D(h) V` between the base and the coat, with Estevez and Kulla's "Charlie"
///   distribution `D = (2 + 1/a) sin(theta_h)^(1/a) / (2 pi)`, `a = sheenRoughness^2`, and
///   Ashikhmin's visibility `V = 1 / (4 (n.l + n.v - n.l n.v))`; the base is weighted by
///   `(1 - s E(n.v)) (1 - s E(n.l))` with `s` the colour's largest channel and `E` the
///   sheen's directional albedo (tabulated once by quadrature, at most 1 here), so the sum
///   conserves energy and stays reciprocal (the extension scales by `1 - s E(n.v)` alone).
///   Where the lobe's own albedo exceeds 1 (grazing views of sharp sheens: Ashikhmin's
///   visibility does not conserve energy there) it is divided by `max(1, E(n.v), E(n.l))`.
///   Sampled by cosine with probability `s E(n.v)`.
/// - [`with_iridescence`](MetallicRoughness::with_iridescence) (`KHR_materials_iridescence`):
///   the dielectric's and the metal's Fresnel terms mixed with the thin-film reflectance of
///   Belcour and Barla ([`thin_film_fresnel`]) over the layer's own `F0`.
/// - [`with_anisotropy`](MetallicRoughness::with_anisotropy) (`KHR_materials_anisotropy`): the
///   base's GGX lobes (metal and dielectric) become anisotropic, `alpha_t = mix(alpha, 1,
///   strength^2)` along a direction in the shading plane and `alpha` across it, as the
///   extension defines; the coat stays isotropic.
///
/// The model is reciprocal (`|v.h| = |l.h|`), and its directional albedo is below 1: the GGX lobe
/// loses the energy of multiple scattering at high roughness, as in the specification.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MetallicRoughness {
    base_color: Rgb,
    metallic: f32,
    distribution: TrowbridgeReitz,
    /// The dielectric's reflectance at normal incidence.
    f0: Rgb,
    /// The dielectric's reflectance at grazing incidence (1 without `KHR_materials_specular`).
    f90: f32,
    /// Clearcoat weight in `[0, 1]` (0: no coat).
    coat: f32,
    /// The coat's microfacet distribution.
    coat_distribution: TrowbridgeReitz,
    /// The coat's normal in the shading frame (`z` unless the coat has its own normal).
    coat_normal: Vec3,
    /// Thin-film iridescence weight in `[0, 1]` (0: none), the film's index of refraction and
    /// thickness in nanometres.
    iridescence: f32,
    film_ior: f32,
    film_thickness: f32,
    /// Sheen colour (black: no sheen).
    sheen_color: Rgb,
    /// Sheen distribution width `a = sheenRoughness^2`.
    sheen_alpha: f32,
    /// The anisotropy direction in the shading frame as `(cos, sin)` of its angle from `x`
    /// (`(1, 0)` when isotropic): directions are turned by minus that angle before the
    /// distribution, whose `x` axis is the direction, sees them.
    rotation: (f32, f32),
}

/// Schlick's Fresnel of the clearcoat (IOR 1.5): `F0 = 0.04`.
const COAT_F0: f32 = 0.04;

/// `(1 - c)^5`, Schlick's weight.
#[inline]
fn schlick_weight(c: f32) -> f32 {
    let m = (1.0 - c).clamp(0.0, 1.0);
    let m2 = m * m;
    m2 * m2 * m
}

/// `w` in the upper hemisphere (both faces reflect alike).
#[inline]
fn upper(w: Vec3) -> Vec3 {
    Vec3::new(w.x, w.y, w.z.abs())
}

impl MetallicRoughness {
    /// The model for these parameters (clamped to their ranges; NaN becomes 0, an IOR that is
    /// not finite or not above 0 becomes 1.5).
    #[must_use]
    pub fn new(base_color: Rgb, metallic: f32, roughness: f32, ior: f32) -> Self {
        let unit = |v: f32| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
        let base_color = Rgb::new(unit(base_color.r), unit(base_color.g), unit(base_color.b));
        let alpha = roughness_to_alpha(unit(roughness)).max(SMOOTH_ALPHA);
        let ior = if ior.is_finite() && ior > 0.0 {
            ior
        } else {
            1.5
        };
        let r = (ior - 1.0) / (ior + 1.0);
        Self {
            base_color,
            metallic: unit(metallic),
            distribution: TrowbridgeReitz::isotropic(alpha),
            f0: Rgb::splat(r * r),
            f90: 1.0,
            coat: 0.0,
            coat_distribution: TrowbridgeReitz::isotropic(SMOOTH_ALPHA),
            coat_normal: Vec3::Z,
            rotation: (1.0, 0.0),
            sheen_color: Rgb::BLACK,
            sheen_alpha: 1.0,
            iridescence: 0.0,
            film_ior: 1.3,
            film_thickness: 0.0,
        }
    }

    /// The same model under a thin film (`KHR_materials_iridescence`): its Fresnel terms (the
    /// dielectric's and the metal's) become [`thin_film_fresnel`] of a film of index
    /// `film_ior` and `thickness` nanometres over the layer's own `F0`, mixed in with weight
    /// `iridescence` (`[0, 1]`).
    #[must_use]
    pub fn with_iridescence(mut self, iridescence: f32, film_ior: f32, thickness: f32) -> Self {
        self.iridescence = if iridescence.is_nan() {
            0.0
        } else {
            iridescence.clamp(0.0, 1.0)
        };
        self.film_ior = if film_ior.is_finite() && film_ior >= 1.0 {
            film_ior
        } else {
            1.3
        };
        self.film_thickness = if thickness.is_finite() {
            thickness.max(0.0)
        } else {
            0.0
        };
        self
    }

    /// The dielectric's Fresnel at cosine `c` (to the microfacet or the surface normal), with
    /// the film mixed in.
    #[inline]
    fn dielectric_fresnel(&self, c: f32) -> Rgb {
        let f = self.fresnel(schlick_weight(c));
        if self.iridescence == 0.0 {
            return f;
        }
        let film = thin_film_fresnel(1.0, self.film_ior, self.film_thickness, c, self.f0);
        f + (film - f) * self.iridescence
    }

    /// The metal's Fresnel at cosine `c`, with the film mixed in.
    #[inline]
    fn metal_fresnel(&self, c: f32) -> Rgb {
        let base = self.base_color;
        let f = base + (Rgb::WHITE - base) * schlick_weight(c);
        if self.iridescence == 0.0 {
            return f;
        }
        let film = thin_film_fresnel(1.0, self.film_ior, self.film_thickness, c, base);
        f + (film - f) * self.iridescence
    }

    /// The same model with `KHR_materials_sheen`: a sheen of `color` (linear RGB, clamped to
    /// `[0, 1]`) and perceptual `roughness` (`[0, 1]`), as the type's docs say.
    #[must_use]
    pub fn with_sheen(mut self, color: Rgb, roughness: f32) -> Self {
        let unit = |v: f32| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
        self.sheen_color = color.map(unit);
        self.sheen_alpha = sheen_alpha(unit(roughness));
        self
    }

    /// The sheen lobe's largest channel times its albedo seen from cosine `c`: what it takes
    /// from the layers below, and its sampling probability.
    #[inline]
    fn sheen_weight(&self, c: f32) -> f32 {
        self.sheen_color.max_component() * sheen_albedo(c, self.sheen_alpha).min(1.0)
    }

    /// The same model with `KHR_materials_anisotropy`: `strength` in `[0, 1]` stretches the
    /// roughness along `direction` (in the shading frame's `xy` plane; normalised here) to
    /// `alpha_t = alpha + (1 - alpha) strength^2`. A zero or non-finite direction, or
    /// strength 0, leaves the model isotropic.
    #[must_use]
    pub fn with_anisotropy(mut self, strength: f32, direction: Vec2) -> Self {
        let strength = if strength.is_nan() {
            0.0
        } else {
            strength.clamp(0.0, 1.0)
        };
        let d = direction.normalize_or_zero();
        if strength == 0.0 || d == Vec2::ZERO || !d.is_finite() {
            return self;
        }
        let alpha = self.distribution.alpha().0;
        let alpha_t = alpha + (1.0 - alpha) * strength * strength;
        self.distribution = TrowbridgeReitz::new(alpha_t, alpha);
        self.rotation = (d.x, d.y);
        self
    }

    /// `w` turned into the anisotropy frame (its `x` the anisotropy direction).
    #[inline]
    fn aniso_local(&self, w: Vec3) -> Vec3 {
        let (c, s) = self.rotation;
        Vec3::new(c * w.x + s * w.y, -s * w.x + c * w.y, w.z)
    }

    /// `w` turned back from the anisotropy frame.
    #[inline]
    fn aniso_world(&self, w: Vec3) -> Vec3 {
        let (c, s) = self.rotation;
        Vec3::new(c * w.x - s * w.y, s * w.x + c * w.y, w.z)
    }

    /// The same model with `KHR_materials_specular`: `specular` (the factor, `[0, 1]`) scales
    /// the dielectric's reflection and `color` tints its `F0` (see the type's docs).
    #[must_use]
    pub fn with_specular(mut self, specular: f32, color: Rgb) -> Self {
        let unit = |v: f32| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
        let specular = unit(specular);
        let color = color.map(|c| if c.is_finite() { c.max(0.0) } else { 1.0 });
        self.f0 = (self.f0 * color).map(|c| c.min(1.0)) * specular;
        self.f90 = specular;
        self
    }

    /// The same model under a clearcoat (`KHR_materials_clearcoat`) of weight `coat` and
    /// perceptual `roughness` (both `[0, 1]`).
    #[must_use]
    pub fn with_clearcoat(mut self, coat: f32, roughness: f32) -> Self {
        let unit = |v: f32| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
        self.coat = unit(coat);
        self.coat_distribution =
            TrowbridgeReitz::isotropic(roughness_to_alpha(unit(roughness)).max(SMOOTH_ALPHA));
        self
    }

    /// The dielectric's Fresnel for Schlick weight `w`, and its largest channel.
    #[inline]
    fn fresnel(&self, w: f32) -> Rgb {
        self.f0 + (Rgb::splat(self.f90) - self.f0) * w
    }

    /// The same model whose clearcoat has its own normal `normal` (in the shading frame;
    /// normalised here, and ignored when zero, not finite or below the shading horizon).
    #[must_use]
    pub fn with_coat_normal(mut self, normal: Vec3) -> Self {
        let n = normal.normalize_or_zero();
        if n.is_finite() && n.z > 0.0 {
            self.coat_normal = n;
        }
        self
    }

    /// The coat normal in the space `eval_upper` works in, for an outgoing `wo` in the
    /// shading frame (turned with the anisotropy frame, and mirrored with the directions on
    /// the lower side, where the surface is seen from below).
    #[inline]
    fn coat_normal_for(&self, wo: Vec3) -> Vec3 {
        if self.coat_normal == Vec3::Z {
            return Vec3::Z;
        }
        let n = self.aniso_local(self.coat_normal);
        if wo.z < 0.0 {
            Vec3::new(-n.x, -n.y, n.z)
        } else {
            n
        }
    }

    /// What the clearcoat lets through at cosine `c`: `1 - coat Fc(c)`.
    #[inline]
    fn coat_through(&self, c: f32) -> f32 {
        1.0 - self.coat * (COAT_F0 + (1.0 - COAT_F0) * schlick_weight(c))
    }

    /// Probability of sampling the clearcoat lobe, seen from `wo` (upper hemisphere) whose
    /// cosine about the coat normal is `co` (none when the coat is seen from behind).
    #[inline]
    fn coat_probability(&self, co: f32) -> f32 {
        if co > 0.0 {
            1.0 - self.coat_through(co)
        } else {
            0.0
        }
    }

    /// Probability of sampling the specular lobe (given that the coat is not), seen from `wo`
    /// (upper hemisphere).
    #[inline]
    fn specular_probability(&self, wo: Vec3) -> f32 {
        let f = self.fresnel(schlick_weight(wo.z)).max_component();
        let m = self.metallic;
        let w_spec = m + (1.0 - m) * f;
        let w_diff = (1.0 - m) * (1.0 - f) * self.base_color.luminance().max(0.0);
        if w_spec + w_diff > 0.0 {
            w_spec / (w_spec + w_diff)
        } else {
            1.0
        }
    }

    /// `f` for `wo`, `wi` in the upper hemisphere, `cn` the coat normal there.
    #[inline]
    fn eval_upper(&self, wo: Vec3, wi: Vec3, cn: Vec3) -> Rgb {
        let wm = wo + wi;
        if wm.length_squared() == 0.0 || wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::BLACK;
        }
        let wm = wm.normalize();
        let w5 = schlick_weight(wo.dot(wm).abs());
        let d = &self.distribution;
        let specular = d.d(wm) * d.g(wo, wi) / (4.0 * wo.z * wi.z);
        let cos_h = wo.dot(wm).abs();
        let f_dielectric = self.dielectric_fresnel(cos_h);
        // The base layer gets what the coating transmits on the way in and on the way out.
        let through = (1.0 - self.dielectric_fresnel(wo.z).max_component())
            * (1.0 - self.dielectric_fresnel(wi.z).max_component());
        let base = self.base_color;
        let f_metal = self.metal_fresnel(cos_h);
        let m = self.metallic;
        let dielectric = base * (through * FRAC_1_PI) + f_dielectric * specular;
        let mut material = dielectric * (1.0 - m) + f_metal * (specular * m);
        if !self.sheen_color.is_black() {
            // Normalised where the lobe's albedo exceeds 1 (grazing, sharp sheen: Ashikhmin's
            // visibility is not energy-conserving there), symmetrically in both directions.
            let e = sheen_albedo(wo.z, self.sheen_alpha)
                .max(sheen_albedo(wi.z, self.sheen_alpha))
                .max(1.0);
            let sheen = charlie_d(wm.z, self.sheen_alpha) * ashikhmin_v(wo.z, wi.z) / e;
            material = material
                * ((1.0 - self.sheen_weight(wo.z)) * (1.0 - self.sheen_weight(wi.z)))
                + self.sheen_color * sheen;
        }
        if self.coat == 0.0 {
            return material;
        }
        let c = &self.coat_distribution;
        if cn == Vec3::Z {
            let coat = self.coat
                * (COAT_F0 + (1.0 - COAT_F0) * w5)
                * (c.d(wm) * c.g(wo, wi) / (4.0 * wo.z * wi.z));
            return material * (self.coat_through(wo.z) * self.coat_through(wi.z))
                + Rgb::splat(coat);
        }
        let (co, ci) = (cn.dot(wo), cn.dot(wi));
        let through = material * (self.coat_through(co) * self.coat_through(ci));
        if co <= 0.0 || ci <= 0.0 {
            return through;
        }
        let frame = Frame::from_z(cn);
        let (wo_c, wi_c, wm_c) = (frame.to_local(wo), frame.to_local(wi), frame.to_local(wm));
        let coat = self.coat
            * (COAT_F0 + (1.0 - COAT_F0) * w5)
            * (c.d(wm_c) * c.g(wo_c, wi_c) / (4.0 * (co * wi.z).max(ci * wo.z)));
        through + Rgb::splat(coat)
    }

    /// The mixture density for `wo`, `wi` in the upper hemisphere, `cn` the coat normal there.
    #[inline]
    fn pdf_upper(&self, wo: Vec3, wi: Vec3, cn: Vec3) -> f32 {
        let wm = wo + wi;
        if wm.length_squared() == 0.0 || wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let wm = wm.normalize();
        let p = self.specular_probability(wo);
        let jacobian = 4.0 * wo.dot(wm).abs();
        let spec = self.distribution.pdf(wo, wm) / jacobian;
        let mut material = p * spec + (1.0 - p) * wi.z * FRAC_1_PI;
        if !self.sheen_color.is_black() {
            let ps = self.sheen_weight(wo.z);
            material = ps * wi.z * FRAC_1_PI + (1.0 - ps) * material;
        }
        if self.coat == 0.0 {
            return material;
        }
        if cn == Vec3::Z {
            let pc = self.coat_probability(wo.z);
            return pc * self.coat_distribution.pdf(wo, wm) / jacobian + (1.0 - pc) * material;
        }
        let pc = self.coat_probability(cn.dot(wo));
        if pc == 0.0 {
            return material;
        }
        if cn.dot(wm) <= 0.0 {
            // A half vector the coat's distribution never produces.
            return (1.0 - pc) * material;
        }
        let frame = Frame::from_z(cn);
        let coat = self
            .coat_distribution
            .pdf(frame.to_local(wo), frame.to_local(wm));
        pc * coat / jacobian + (1.0 - pc) * material
    }
}

/// The Charlie distribution's width for a perceptual sheen roughness (at least 1e-3, where
/// `sin^(1/a)` stays representable).
#[inline]
fn sheen_alpha(roughness: f32) -> f32 {
    (roughness * roughness).max(1e-3)
}

/// Estevez and Kulla's "Charlie" sheen distribution at half-vector cosine `cos_h`.
#[inline]
fn charlie_d(cos_h: f32, a: f32) -> f32 {
    let inv = 1.0 / a;
    let sin2 = (1.0 - cos_h * cos_h).max(0.0);
    (2.0 + inv) * sin2.powf(0.5 * inv) * (0.5 * FRAC_1_PI)
}

/// Ashikhmin's visibility term for sheen.
#[inline]
fn ashikhmin_v(cos_o: f32, cos_i: f32) -> f32 {
    let d = 4.0 * (cos_i + cos_o - cos_i * cos_o);
    if d > 0.0 { 1.0 / d } else { 0.0 }
}

/// Resolution of the sheen albedo table: cosines and roughnesses.
const SHEEN_TABLE: (usize, usize) = (32, 16);

/// The directional albedo of a white sheen lobe seen from cosine `c`, for width `a` (above 1
/// at grazing angles for sharp sheens):
/// bilinear in a table over `(cos, sqrt(a))` computed once by midpoint quadrature.
fn sheen_albedo(c: f32, a: f32) -> f32 {
    use std::sync::OnceLock;
    static TABLE: OnceLock<Vec<f32>> = OnceLock::new();
    let (nc, nr) = SHEEN_TABLE;
    let table = TABLE.get_or_init(|| {
        let (nt, np) = (64, 64);
        let mut t = Vec::with_capacity(nc * nr);
        for j in 0..nr {
            let a = sheen_alpha(j as f32 / (nr - 1) as f32);
            for i in 0..nc {
                let cos_o = (i as f32 / (nc - 1) as f32).max(1e-3);
                let wo = Vec3::new((1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o);
                let mut e = 0.0f64;
                for k in 0..nt {
                    let theta = (k as f32 + 0.5) / nt as f32 * std::f32::consts::FRAC_PI_2;
                    let (st, ct) = theta.sin_cos();
                    for l in 0..np {
                        let phi = (l as f32 + 0.5) / np as f32 * 2.0 * std::f32::consts::PI;
                        let wi = Vec3::new(st * phi.cos(), st * phi.sin(), ct);
                        let h = (wo + wi).normalize();
                        let f = charlie_d(h.z, a) * ashikhmin_v(cos_o, ct);
                        e += f64::from(f * ct * st);
                    }
                }
                let dw = (std::f32::consts::FRAC_PI_2 / nt as f32)
                    * (2.0 * std::f32::consts::PI / np as f32);
                t.push(e as f32 * dw);
            }
        }
        t
    });
    let x = c.clamp(0.0, 1.0) * (nc - 1) as f32;
    let y = a.sqrt().clamp(0.0, 1.0) * (nr - 1) as f32;
    let (x0, y0) = ((x as usize).min(nc - 2), (y as usize).min(nr - 2));
    let (fx, fy) = (x - x0 as f32, y - y0 as f32);
    let at = |i: usize, j: usize| table[j * nc + i];
    (at(x0, y0) * (1.0 - fx) + at(x0 + 1, y0) * fx) * (1.0 - fy)
        + (at(x0, y0 + 1) * (1.0 - fx) + at(x0 + 1, y0 + 1) * fx) * fy
}

impl Bsdf for MetallicRoughness {
    #[inline]
    fn flags(&self) -> BsdfFlags {
        BsdfFlags::DIFFUSE_REFLECTION | BsdfFlags::GLOSSY_REFLECTION
    }

    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> Rgb {
        if !same_hemisphere(wo, wi) {
            return Rgb::BLACK;
        }
        self.eval_upper(
            upper(self.aniso_local(wo)),
            upper(self.aniso_local(wi)),
            self.coat_normal_for(wo),
        )
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> f32 {
        if !same_hemisphere(wo, wi) {
            return 0.0;
        }
        self.pdf_upper(
            upper(self.aniso_local(wo)),
            upper(self.aniso_local(wi)),
            self.coat_normal_for(wo),
        )
    }

    #[inline]
    fn sample(&self, wo: Vec3, uc: f32, u: Vec2, _mode: TransportMode) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let wo_u = upper(self.aniso_local(wo));
        let cn = self.coat_normal_for(wo);
        // The coat with its probability, then the specular lobe or the base, reusing `uc`.
        let pc = if self.coat > 0.0 {
            self.coat_probability(cn.dot(wo_u))
        } else {
            0.0
        };
        let (coat, uc) = if uc < pc {
            (true, 0.0)
        } else {
            (
                false,
                ((uc - pc) / (1.0 - pc)).min(1.0 - f32::EPSILON / 2.0),
            )
        };
        // Then the sheen (sampled by cosine) with its probability.
        let ps = if coat || self.sheen_color.is_black() {
            0.0
        } else {
            self.sheen_weight(wo_u.z)
        };
        let (sheen, uc) = if !coat && uc < ps {
            (true, 0.0)
        } else if coat {
            (false, uc)
        } else {
            (
                false,
                ((uc - ps) / (1.0 - ps)).min(1.0 - f32::EPSILON / 2.0),
            )
        };
        let specular = coat || (!sheen && uc < self.specular_probability(wo_u));
        let mut wi = if coat && cn != Vec3::Z {
            let frame = Frame::from_z(cn);
            let wm = self.coat_distribution.sample_wm(frame.to_local(wo_u), u);
            reflect(wo_u, frame.from_local(wm))
        } else if coat {
            reflect(wo_u, self.coat_distribution.sample_wm(wo_u, u))
        } else if specular {
            reflect(wo_u, self.distribution.sample_wm(wo_u, u))
        } else {
            sample_cosine_hemisphere(u)
        };
        if wi.z <= 0.0 {
            return None;
        }
        let pdf = self.pdf_upper(wo_u, wi, cn);
        if !(pdf.is_finite() && pdf > 0.0) {
            return None;
        }
        let f = self.eval_upper(wo_u, wi, cn);
        if wo.z < 0.0 {
            wi.z = -wi.z;
        }
        let wi = self.aniso_world(wi);
        Some(BsdfSample {
            wi,
            f,
            pdf,
            flags: if specular {
                BsdfFlags::GLOSSY_REFLECTION
            } else {
                BsdfFlags::DIFFUSE_REFLECTION
            },
            eta: 1.0,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A white dielectric's `F0` is the Fresnel reflectance at normal incidence: 0.04 for IOR
    /// 1.5; metallic 1 with a white base reflects everything the GGX lobe keeps.
    #[test]
    fn parameters_map_as_the_specification_says() {
        let m = MetallicRoughness::new(Rgb::WHITE, 0.0, 0.5, 1.5);
        assert!((m.f0.r - 0.04).abs() < 1e-6);
        let clamped = MetallicRoughness::new(Rgb::new(2.0, -1.0, f32::NAN), 3.0, f32::NAN, -1.0);
        assert_eq!(clamped.base_color, Rgb::new(1.0, 0.0, 0.0));
        assert_eq!(clamped.metallic, 1.0);
        assert!((clamped.f0.r - 0.04).abs() < 1e-6);
        // Normal incidence, a half vector along the normal: the metal's Fresnel is its base.
        let metal = MetallicRoughness::new(Rgb::new(0.9, 0.6, 0.3), 1.0, 0.5, 1.5);
        let f = metal.eval(Vec3::Z, Vec3::Z, TransportMode::Radiance);
        let d = &metal.distribution;
        let spec = d.d(Vec3::Z) * d.g(Vec3::Z, Vec3::Z) / 4.0;
        assert!((f.r - 0.9 * spec).abs() < 1e-4 * spec && (f.b - 0.3 * spec).abs() < 1e-4 * spec);
        // A rough black dielectric is only its specular coating: 0.04 of the lobe there.
        let black = MetallicRoughness::new(Rgb::BLACK, 0.0, 0.5, 1.5);
        let f = black.eval(Vec3::Z, Vec3::Z, TransportMode::Radiance);
        assert!((f.g - 0.04 * spec).abs() < 1e-4 * spec);
    }
}
