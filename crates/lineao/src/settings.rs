//! User-facing settings of the LineAO pass chain. Each method's settings default to its paper's
//! values; [`ChainSettings::default()`] is the default preset ([`crate::Preset::Legible`]), which changes
//! LineAO's reach and every method's strength, as every front end does.

use crate::lighting::Lighting;
use crate::named::{Named, named};

// Each method's settings are its folder's (and the crate root's); named here for the crate.
pub(crate) use crate::colormap::{COLORMAP_ENTRIES, Colormap};
use crate::method::line_ao::settings::R0;
pub(crate) use crate::method::list::{AoMethod, for_each_method};
use crate::method::setting::Context;
use crate::method::vo_line::settings::VoCombine;

/// Object-space AO in the chain ([`crate::volume`], [`crate::passes::volume_ao`]): the
/// geometry's per-vertex octant visibilities ([`crate::passes::lines::VertexAttributes`])
/// turned into occlusion with each pixel's normal, alone (with [`AoMethod::None`]) or combined
/// with the screen-space method's.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct VolumeAoSettings {
    /// Light from each octant, in [0, 1], indexed as [`crate::volume::octant_signs`]
    /// ([`crate::volume::Sky::weights`]). Visibilities that already include a sky (the
    /// view-independent forms of [`crate::volume::scalar_visibility`]) take all ones. Default:
    /// all ones (an open sky).
    pub sky: [f32; 8],
    /// How it meets the screen-space method's occlusion. Default: brightness multiplies.
    pub combine: VoCombine,
}

impl Default for VolumeAoSettings {
    fn default() -> Self {
        VolumeAoSettings { sky: [1.0; 8], combine: VoCombine::Product }
    }
}

/// The separable depth-aware (bilateral) blur that can follow any method
/// (`lineao::passes::bilateral`).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct BilateralSettings {
    /// Taps on each side of the centre, 1..=16; the spatial Gaussian's σ is half of it.
    /// Default 4.
    pub radius_px: u32,
    /// σ of the depth Gaussian in world units: neighbours this much nearer or farther count
    /// e^(−1/2) as much, so occlusion does not bleed across depth edges. Default 1.
    pub depth_sigma_world: f32,
}

impl Default for BilateralSettings {
    fn default() -> Self {
        BilateralSettings { radius_px: 4, depth_sigma_world: 1.0 }
    }
}

impl BilateralSettings {
    /// Checks every range documented above.
    pub fn validate(&self) -> Result<(), crate::Error> {
        if !(1..=16).contains(&self.radius_px) {
            return Err(crate::Error::out_of_range("bilateral-radius", self.radius_px, "1..=16 px"));
        }
        if !(self.depth_sigma_world.is_finite() && self.depth_sigma_world > 0.0) {
            return Err(crate::Error::out_of_range("bilateral-sigma", self.depth_sigma_world, "> 0 world units"));
        }
        Ok(())
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
/// What the composite shows (`--debug-view`).
pub enum DebugView {
    /// color · (1 − strength · ao) + specular.
    #[default]
    Final,
    /// 1 − ao as gray.
    Ao,
    /// Level-0 normals as n · 0.5 + 0.5.
    Normals,
    /// Normalized linear depth.
    Depth,
    /// z(P) / z_max.
    Zoom,
    /// Normals of pyramid level k.
    Level(u32),
    /// The final image with each culled piece of line colored by the level of detail it is
    /// drawn at ([`crate::passes::cull`]): blue every point, green every 2nd, orange every 4th,
    /// red every 8th; lines drawn whole (not culled) and tubes gray.
    Pieces,
    /// [`DebugView::Pieces`] with the cull frozen: the pieces found visible in the frame before
    /// it was chosen, and no others, whatever the camera does — orbit away to see what the
    /// cull drew for that view and what it left out (behind them, outside the frustum).
    Frozen,
    /// [`DebugView::Frozen`] drawing every piece: those the cull drew blue, those it left out
    /// light gray where it found them outside the view, purple where behind what it drew (a
    /// piece of a group whose box was hidden counts as behind).
    Culled,
}

impl DebugView {
    pub(crate) fn code(self) -> (u32, u32) {
        match self {
            DebugView::Final => (0, 0),
            DebugView::Ao => (1, 0),
            DebugView::Normals => (2, 0),
            DebugView::Depth => (3, 0),
            DebugView::Zoom => (4, 0),
            DebugView::Level(k) => (5, k),
            // The geometry's colors say it.
            DebugView::Pieces | DebugView::Frozen | DebugView::Culled => (0, 0),
        }
    }
}

/// How lines are colored.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum LineColor {
    /// |T| of the world-space tangent as RGB (x red, y green, z blue: the DEC colormap of
    /// tractography, left-right red, anterior-posterior green, superior-inferior blue).
    Tangent,
    /// One linear RGB color.
    Constant([f32; 3]),
    /// What the cull drew each piece as ([`DebugView::Pieces`], which sets it for the frame).
    Pieces,
    /// The geometry's per-vertex scalar ([`crate::passes::lines::VertexAttributes::scalar`]:
    /// FA, curvature, a bundle index …) through `colormap`, `range` mapped to its ends (values
    /// beyond clamp). Geometry without scalars shows the colormap's low end.
    Scalar {
        /// The colormap.
        colormap: Colormap,
        /// The values at its two ends.
        range: [f32; 2],
    },
}

/// Streamlines as tubes (`lineao::passes::tubes`) instead of fixed-width lines.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct TubeSettings {
    /// Radius in world units (mm for tractograms) where the geometry carries no per-vertex
    /// radius, > 0. LineAO's r0 follows it (paper Eq. 16).
    pub radius_world: f32,
}

/// Lines seen through one another ([`crate::passes::transparency`]): the selected streamlines
/// at opacity `alpha`, the others (the context) at `context_alpha`, composited in depth order —
/// the `layers` nearest fragments of each pixel exactly, those beyond blended into a tail.
/// A line of opacity 1 is drawn as without it, into the G-buffer and its screen-space AO.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct TransparencySettings {
    /// Opacity of the selected streamlines (every one without a selection), in (0, 1]. Default 1.
    pub alpha: f32,
    /// Opacity of the streamlines the selection leaves out, in [0, 1]: 0 hides them (as
    /// without transparency). Default 0.
    pub context_alpha: f32,
    /// Fragments per pixel composited exactly (the K-buffer's K), in
    /// [`TransparencySettings::LAYERS`]. Default 8.
    pub layers: u32,
}

impl TransparencySettings {
    /// The layers a K-buffer may hold.
    pub const LAYERS: std::ops::RangeInclusive<u32> = 1..=16;

    /// Whether any line is drawn transparent (else the chain draws as without these settings).
    pub fn any(&self) -> bool {
        self.alpha < 1.0 || self.context_alpha > 0.0
    }

    /// Whether the selected lines are drawn transparent (else into the G-buffer).
    pub fn focus_transparent(&self) -> bool {
        self.alpha < 1.0
    }

    /// Checks the ranges above, naming each setting.
    pub fn validate(&self) -> Result<(), crate::Error> {
        if !(self.alpha > 0.0 && self.alpha <= 1.0) {
            return Err(crate::Error::out_of_range("alpha", self.alpha, "(0, 1]"));
        }
        if !(0.0..=1.0).contains(&self.context_alpha) {
            return Err(crate::Error::out_of_range("context-alpha", self.context_alpha, "[0, 1]"));
        }
        if !Self::LAYERS.contains(&self.layers) {
            let (lo, hi) = (Self::LAYERS.start(), Self::LAYERS.end());
            return Err(crate::Error::out_of_range("layers", self.layers, &format!("{lo}..={hi}")));
        }
        Ok(())
    }
}

impl Default for TransparencySettings {
    fn default() -> Self {
        TransparencySettings { alpha: 1.0, context_alpha: 0.0, layers: 8 }
    }
}

/// Context surfaces (`lineao::passes::meshes`) drawn with the lines.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct SurfaceSettings {
    /// Linear RGB of the surfaces. Default a light gray (0.8, 0.8, 0.8).
    pub color: [f32; 3],
}

impl Default for SurfaceSettings {
    fn default() -> Self {
        SurfaceSettings { color: [0.8; 3] }
    }
}

/// Anatomy slices ([`crate::passes::slices`]) drawn with the lines: up to three planes of a
/// scalar volume ([`crate::SliceVolume`]), each orthogonal to a world axis (RAS+ mm for
/// tractograms), its values through a window and a colormap.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct SliceSettings {
    /// Where the sagittal (x), coronal (y) and axial (z) slices cut their axis, world units, or
    /// none for no slice on that axis. Default the axial slice at 0.
    pub positions: [Option<f32>; 3],
    /// The values at the colormap's ends, or none for the volume's 2nd and 98th percentiles
    /// ([`crate::SliceVolume::percentiles`]). Default none.
    pub window: Option<[f32; 2]>,
    /// Default gray.
    pub colormap: Colormap,
    /// Show the voxels that hold no data (0 or NaN: a skull-stripped T1's background, a masked
    /// map's outside) as the colormap's low end too. Default false: a slice is transparent
    /// where such voxels weigh half or more of its trilinear sample, so it shows the data's
    /// cross-section and hides no line behind the empty rest of the volume's box.
    pub opaque: bool,
}

impl Default for SliceSettings {
    fn default() -> Self {
        SliceSettings { positions: [None, None, Some(0.0)], window: None, colormap: Colormap::Gray, opaque: false }
    }
}

/// The axis a [`Slab`] is thick along.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SlabAxis {
    /// Sagittal: along x.
    X,
    /// Coronal: along y.
    Y,
    #[default]
    /// Axial: along z.
    Z,
    /// The view direction, the slab's centre measured from the middle of the scene's depth
    /// range (the bounding sphere's centre, unless the eye is inside it).
    View,
}

named!(SlabAxis {
    Z => "Between two axial planes (z = centre ± thickness / 2)",
    X => "Between two sagittal planes",
    Y => "Between two coronal planes",
    View => "Between two planes facing the eye, the centre measured from the middle of the scene",
});

impl SlabAxis {
    /// Its name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            SlabAxis::X => "x",
            SlabAxis::Y => "y",
            SlabAxis::Z => "z",
            SlabAxis::View => "view",
        }
    }
}

/// Lines (and tubes) cut per fragment to what lies between two parallel planes: a thick slice
/// of a whole brain, seen inside.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Slab {
    /// The axis it is thick along.
    pub axis: SlabAxis,
    /// The slab's middle along its axis, world units.
    pub center: f32,
    /// The distance between its planes, world units, > 0.
    pub thickness: f32,
}

impl Slab {
    /// The slab as a plane in `view`'s eye space, (n, d) with dot(n, p) + d the signed distance
    /// of eye-space point p from its middle, and its half thickness.
    pub fn in_view(&self, view: &crate::FrameView) -> ([f32; 4], f32) {
        use glam::Vec3;
        let (n, d) = match self.axis {
            SlabAxis::View => (Vec3::NEG_Z, -(0.5 * (view.near + view.far) + self.center)),
            axis => {
                let n_world = Vec3::AXES[axis as usize];
                let n = view.view.transform_vector3(n_world);
                let on_plane = view.view.transform_point3(self.center * n_world);
                (n, -n.dot(on_plane))
            }
        };
        ([n.x, n.y, n.z, d], 0.5 * self.thickness)
    }
}

/// Makes [`ChainSettings`] of the list of methods (`crate::method::list`'s
/// `for_each_method!`): one field per method with settings of its own, which its line names
/// (`LineAo => line_ao { line_ao: LineAoSettings }`, the type in its folder), so that a
/// method's settings are in the chain's — and in its `--settings` JSON under that key —
/// without this file naming them.
macro_rules! chain_settings {
    // The list's lines: keep those with a field, with their `cfg`.
    ($( $(#[doc = $doc:literal])* $(#[cfg($cfg:meta)])? $variant:ident => $folder:ident $({ $field:ident: $ty:ident })? ),+ $(,)?) => {
        chain_settings!(@own [] $( [$(cfg($cfg))?] $variant [$($field: crate::method::$folder::$ty)?] )+);
    };
    (@own [$($own:tt)*] [$($cfg:tt)*] $variant:ident [] $($rest:tt)*) => {
        chain_settings!(@own [$($own)*] $($rest)*);
    };
    (@own [$($own:tt)*] [$($cfg:tt)*] $variant:ident [$field:ident: $ty:ty] $($rest:tt)*) => {
        chain_settings!(@own [$($own)* ([$($cfg)*] $variant $field: $ty)] $($rest)*);
    };
    (@own [$( ([$($attr:meta)?] $variant:ident $field:ident: $ty:ty) )*]) => {
        /// Everything the pass chain needs to know besides the camera.
        #[derive(Clone, Debug, PartialEq)]
        #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
        #[cfg_attr(feature = "serde", serde(default))]
        #[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
        pub struct ChainSettings {
            /// The method. Default LineAO.
            pub method: AoMethod,
            $( $(#[$attr])? #[doc = concat!("The settings of [`AoMethod::", stringify!($variant), "`] (its registry line's field).")] pub $field: $ty, )*
            /// The bilateral blur after the method, or none. Default none. After the ray tracer it is
            /// its denoiser for low ray counts (`lineao score` scores the rays undenoised).
            pub blur: Option<BilateralSettings>,
            /// Object-space AO from the geometry's attributes, or none. Default none.
            pub volume: Option<VolumeAoSettings>,
            /// The lights and the BRDF's coefficients (LineAO's g_light and the specular).
            pub lighting: Lighting,
            /// Line width in pixels, > 0. Default 2.
            pub line_width_px: f32,
            /// Tubes instead of lines, or none. Default none.
            pub tubes: Option<TubeSettings>,
            /// Context surfaces drawn with the lines ([`crate::AoChain::encode`]'s `meshes`), or none.
            /// Default none.
            pub surfaces: Option<SurfaceSettings>,
            /// Anatomy slices drawn with the lines ([`crate::AoChain::set_slice_volume`] gives their volume), or none.
            /// Default none.
            pub slices: Option<SliceSettings>,
            /// Lines cut to a slab, or none. Default none.
            pub slab: Option<Slab>,
            /// Lines seen through one another, or none (every line opaque). Default none.
            pub transparency: Option<TransparencySettings>,
            /// How lines are coloured. Default by tangent.
            pub line_color: LineColor,
            /// Linear RGB of the background.
            pub background: [f32; 3],
            /// AO strength in the composite, ≥ 0. Default 1.
            pub strength: f32,
            /// What the composite shows. Default the final image.
            pub debug_view: DebugView,
            /// World units per zoom unit (1 mm for tractography). Default 1.
            pub zoom_unit: f32,
            /// Upper bound of the guard band in pixels, whatever the method. Default 128.
            pub guard_max_px: u32,
            /// Draw only the lines (or tubes) that can be seen, culled on the GPU against the last frame's depth
            /// ([`crate::passes::cull`]): the full strip's G-buffer exactly, a fraction of the cost
            /// where lines hide lines (a whole brain) from the second frame of a view on. Default on:
            /// a chain draws frames one after another. A single picture has no frame before it, and
            /// culled it costs the full strip and the tests (`lineao render` turns it off).
            pub cull: bool,
            /// Where it culls lines or tubes, draw each visible piece at the coarsest level of detail
            /// that lies within half a pixel of it on screen ([`crate::passes::cull`]'s level of
            /// detail): fewer vertices for lines and tubes seen from afar, a G-buffer that differs
            /// from the full one by sub-pixel shifts (and a tube's normals by the turn that bounds).
            /// Off: every segment exactly. Default on (but for the ray tracer:
            /// [`ChainSettings::levels_of_detail`]).
            pub lod: bool,
        }

        impl ChainSettings {
            /// The papers' values for every setting (LineAO s_r 3, r0 1.5 × the line width, δ
            /// scale 1, strength 1; VO and SSAO spheres of 2 world units): `ChainSettings::default()`
            /// before the default preset is applied, and what [`crate::Preset::Paper`] restores.
            pub fn papers() -> Self {
                ChainSettings {
                    method: AoMethod::LineAo,
                    $( $(#[$attr])? $field: <$ty>::default(), )*
                    blur: None,
                    volume: None,
                    lighting: Lighting::default(),
                    line_width_px: 2.0,
                    tubes: None,
                    surfaces: None,
                    slices: None,
                    slab: None,
                    transparency: None,
                    line_color: LineColor::Tangent,
                    background: [1.0, 1.0, 1.0],
                    strength: 1.0,
                    debug_view: DebugView::Final,
                    zoom_unit: 1.0,
                    guard_max_px: 128,
                    cull: true,
                    lod: true,
                }
            }
        }
    };
}

for_each_method!(chain_settings);

impl ChainSettings {
    /// The transparency the frame draws, where any line is transparent.
    pub fn transparent(&self) -> Option<&TransparencySettings> {
        self.transparency.as_ref().filter(|t| t.any())
    }
}

impl ChainSettings {
    /// Settings for a host's triangle meshes ([`crate::HostAo`]) in a scene of bounding
    /// radius `scene_radius` (world units), chosen against the ray-traced truth: Volumetric
    /// Obscurance with line samples, the normal clamp and a thickness of one radius, reaching
    /// a tenth of the scene's radius, strength 1.75, then the bilateral blur.
    ///
    /// `cargo run --release --example embed_renderer -- --fit` scores every method on that
    /// example's meshes on a ground plane (binary AO to the same reach, 128 rays, each method at
    /// its least-squares strength; docs/embedding.md has the table): this one has the least
    /// RMSE (0.053, correlation 0.95; LineAO's best 0.118, SSAO 0.162, VO area 0.155), leaves
    /// the open ground at 0.0007 and darkens the contacts by 0.50 where the truth says 0.53.
    /// Without the clamp VO darkens every open surface; without the thickness it darkens
    /// around every silhouette; LineAO, made for lines, darkens open ground by 3–8 %.
    pub fn for_meshes(scene_radius: f32) -> ChainSettings {
        let reach = 0.1 * scene_radius;
        let mut settings = ChainSettings {
            method: AoMethod::VoLine,
            strength: 1.75,
            blur: Some(BilateralSettings::default()),
            ..ChainSettings::default()
        };
        settings.vo.radius_world = reach;
        settings.vo.thickness_world = reach;
        settings.vo.normal_clamp = true;
        settings
    }

    /// What a method's settings need of the chain around them: the line width, the tubes, the
    /// zoom unit.
    pub fn context(&self) -> Context {
        Context { line_width_px: self.line_width_px, tubes: self.tubes.is_some(), zoom_unit: self.zoom_unit }
    }

    /// r0's constant part in pixels: the explicit value, or `r0_per_width` × the line width
    /// (tubes: 0).
    pub fn r0_px(&self) -> f32 {
        self.line_ao.r0_px(&self.context())
    }

    /// r0(P) of LineAO (paper §3.2.3, Eq. 16): for tubes 1.5 · z(P) · t_s, t_s = 2 × the radius
    /// in zoom units; an explicit `r0_px` replaces the default constant part.
    pub fn r0(&self) -> R0 {
        let per_zoom = self.tubes.as_ref().map_or(0.0, |t| 1.5 * 2.0 * t.radius_world / self.zoom_unit);
        R0 { px: self.r0_px(), per_zoom }
    }

    /// The bilateral blur the frame runs after its method, and whether it smooths only the
    /// anatomy slices' pixels: [`ChainSettings::blur`] over every pixel; without it, with
    /// [`ChainSettings::slices`], the default blur over the slices alone (a method's sampling
    /// noise, hidden in the lines, is grain on a smooth slice; the lines keep their own
    /// occlusion). None after no method.
    pub fn bilateral(&self) -> Option<(BilateralSettings, bool)> {
        if self.method == AoMethod::None {
            return None;
        }
        match (&self.blur, &self.slices) {
            (Some(blur), _) => Some((blur.clone(), false)),
            (None, Some(_)) => Some((BilateralSettings::default(), true)),
            (None, None) => None,
        }
    }

    /// Checks every range documented above but the methods' own settings' (which
    /// [`ChainSettings::validate`] checks after these).
    pub(crate) fn validate_chain(&self) -> Result<(), crate::Error> {
        if let Some(blur) = &self.blur {
            blur.validate()?;
        }
        if !(self.line_width_px.is_finite() && self.line_width_px > 0.0 && self.line_width_px <= 256.0) {
            return Err(crate::Error::out_of_range("line-width", self.line_width_px, "(0, 256] px"));
        }
        if let Some(tubes) = &self.tubes
            && !(tubes.radius_world.is_finite() && tubes.radius_world > 0.0)
        {
            return Err(crate::Error::out_of_range("tube-radius", tubes.radius_world, "> 0 world units"));
        }
        if let Some(volume) = &self.volume
            && !volume.sky.iter().all(|w| (0.0..=1.0).contains(w))
        {
            return Err(crate::Error::out_of_range("sky", format!("{:?}", volume.sky), "intensities in [0, 1]"));
        }
        if !(self.strength.is_finite() && self.strength >= 0.0) {
            return Err(crate::Error::out_of_range("strength", self.strength, "≥ 0"));
        }
        if !(self.zoom_unit.is_finite() && self.zoom_unit > 0.0) {
            return Err(crate::Error::out_of_range("zoom-unit", self.zoom_unit, "> 0"));
        }
        if self.lighting.lights.len() > crate::lighting::MAX_LIGHTS {
            return Err(crate::Error::out_of_range(
                "ChainSettings::lighting",
                format!("{} lights", self.lighting.lights.len()),
                &format!("at most {} lights", crate::lighting::MAX_LIGHTS),
            ));
        }
        if let Some(slab) = &self.slab
            && !(slab.center.is_finite() && slab.thickness.is_finite() && slab.thickness > 0.0)
        {
            return Err(crate::Error::out_of_range(
                "slab",
                format!("centre {} and thickness {}", slab.center, slab.thickness),
                "a finite centre and a thickness > 0",
            ));
        }
        if let Some(transparency) = &self.transparency {
            transparency.validate()?;
            if transparency.any() && self.tubes.is_some() {
                let why = "transparency draws lines: tubes are opaque only";
                return Err(crate::Error::Conflict { setting: "alpha", with: "geometry", why });
            }
        }
        if let Some(slices) = &self.slices {
            if let Some(p) = slices.positions.iter().flatten().find(|p| !p.is_finite()) {
                return Err(crate::Error::out_of_range("slices", p, "finite positions"));
            }
            if let Some([lo, hi]) = slices.window
                && !(lo.is_finite() && hi.is_finite() && lo < hi)
            {
                return Err(crate::Error::out_of_range("window", format!("{lo}, {hi}"), "finite min < max"));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod preset_tests {
    use super::*;
    use crate::Preset;
    use crate::method::line_ao::settings::LineAoVariant;

    /// The fitted table (docs/ground-truth.md), written out here apart from the methods' own
    /// `preset` functions: (strength, s_r, r0 per width, δ scale, reference radius, the method's
    /// sphere radius in zoom units) for each preset and method, at a zoom unit of 2.
    #[test]
    fn each_method_takes_its_presets_values_and_the_others_keep_the_papers() {
        use AoMethod::*;
        use LineAoVariant::{Paper as P, Reference as R};
        let paper = (1.0, 3, 1.5, 1.0, 2.0, 2.0);
        let table = [
            (Preset::Legible, LineAo, P, (0.6, 2, 4.5, 1.0, 2.0, 2.0)),
            (Preset::Legible, LineAo, R, (0.6, 3, 1.5, 1.0, 2.0, 2.0)),
            (Preset::Legible, VoLine, P, (0.8, 3, 1.5, 1.0, 2.0, 2.0)),
            (Preset::Legible, VoArea, P, (0.8, 3, 1.5, 1.0, 2.0, 1.0)),
            (Preset::Legible, Ssao, P, (1.0, 3, 1.5, 1.0, 2.0, 8.0)),
            (Preset::Physical, LineAo, P, (0.58, 2, 1.5, 0.1, 2.0, 2.0)),
            (Preset::Physical, LineAo, R, (0.46, 3, 1.5, 1.0, 1.0, 2.0)),
            (Preset::Physical, VoLine, P, (0.22, 3, 1.5, 1.0, 2.0, 1.5)),
            (Preset::Physical, VoArea, P, (0.22, 3, 1.5, 1.0, 2.0, 1.0)),
            (Preset::Physical, Ssao, P, (0.68, 3, 1.5, 1.0, 2.0, 3.0)),
            (Preset::Sparse, LineAo, P, (0.8, 4, 1.5, 1.0, 2.0, 2.0)),
            (Preset::Sparse, LineAo, R, (0.8, 3, 1.5, 1.0, 2.0, 2.0)),
            (Preset::Sparse, VoLine, P, (0.8, 3, 1.5, 1.0, 2.0, 6.0)),
            (Preset::Sparse, VoArea, P, (0.8, 3, 1.5, 1.0, 2.0, 6.0)),
            (Preset::Sparse, Ssao, P, (0.8, 3, 1.5, 1.0, 2.0, 6.0)),
            (Preset::Legible, None, P, paper),
            (Preset::Physical, RayTraced, P, paper),
            (Preset::Sparse, RayTraced, P, paper),
        ];
        let cases = table.into_iter().chain([LineAo, VoLine, VoArea, Ssao].map(|m| (Preset::Paper, m, P, paper)));
        for (preset, method, variant, expected) in cases {
            let mut start = ChainSettings { method, zoom_unit: 2.0, ..ChainSettings::papers() };
            start.line_ao.variant = variant;
            // Whatever an earlier preset left is replaced.
            let s = start.with_preset(Preset::Physical).with_preset(Preset::Legible).with_preset(preset);
            let ao = &s.line_ao;
            let (strength, s_r, r0_per_width, delta_scale, reference_radius, radius) = expected;
            let sphere = match method {
                VoLine | VoArea => s.vo.radius_world,
                _ => s.ssao.radius_world,
            };
            let got = (s.strength, ao.s_r, ao.r0_per_width, ao.delta_scale, ao.reference_radius_px, sphere / 2.0);
            assert_eq!(
                got,
                (strength, s_r, r0_per_width, delta_scale, reference_radius, radius),
                "{preset:?} {method}"
            );
            assert_eq!((ao.r0_px, s.ssao.range_world), (Option::None, s.ssao.radius_world), "{preset:?} {method}");
            // The other methods' spheres are the papers'.
            let other = if matches!(method, VoLine | VoArea) { s.ssao.radius_world } else { s.vo.radius_world };
            assert_eq!(other, 4.0, "{preset:?} {method}");
        }
    }
}

#[cfg(all(test, feature = "serde"))]
mod serde_tests {
    use super::*;
    use crate::method::line_ao::settings::LineAoVariant;
    use crate::method::ssao::settings::SsaoSettings;

    #[test]
    fn settings_round_trip_through_json_with_names_as_the_command_line_writes_them() {
        let mut settings = ChainSettings { method: AoMethod::VoArea, ..ChainSettings::default() };
        settings.line_ao.variant = LineAoVariant::Reference;
        settings.line_color = LineColor::Scalar { colormap: Colormap::CoolWarm, range: [0.0, 1.0] };
        settings.debug_view = DebugView::Level(1);
        settings.blur = Some(BilateralSettings::default());
        let json = serde_json::to_value(&settings).unwrap();
        assert_eq!(json["method"], "vo-area");
        assert_eq!(json["line_ao"]["variant"], "reference");
        assert_eq!(json["line_color"]["scalar"]["colormap"], "coolwarm");
        assert_eq!(serde_json::from_value::<ChainSettings>(json).unwrap(), settings);
    }

    #[test]
    fn what_is_left_out_is_the_default_and_a_typo_is_named() {
        let settings: ChainSettings = serde_json::from_str(r#"{"method": "ssao", "ssao": {"samples": 12}}"#).unwrap();
        let expected = ChainSettings { method: AoMethod::Ssao, ..ChainSettings::default() };
        assert_eq!(settings.ssao, SsaoSettings { samples: 12, ..expected.ssao.clone() });
        assert_eq!(settings.line_ao, expected.line_ao);
        let typo = serde_json::from_str::<ChainSettings>(r#"{"ssao": {"sample": 12}}"#).unwrap_err().to_string();
        assert!(typo.contains("unknown field `sample`"), "{typo}");
        let method = serde_json::from_str::<ChainSettings>(r#"{"method": "gtao"}"#).unwrap_err().to_string();
        assert!(method.contains("unknown value 'gtao' (one of none, lineao, vo-line"), "{method}");
    }
}
