//! The viewer's side panel: which method (or two, side by side), how lines look, and the chosen
//! methods' parameters with the papers' defaults, a reset and two presets.
//!
//! Everything here is plain state turned into [`Panel`]s by [`Controls::panels`]; the worker
//! renders what those say, so a control changes the picture by changing this state and nothing
//! else.

use egui::Ui;
use glam::Vec3;
use lineao::lighting::LineShading;
use lineao::method::setting::{Kind, Unit, Value};
use lineao::volume::{ScalarForm, Sky, VolumeAoOptions, VolumeMethod};
use lineao::{
    AoMethod, BilateralSettings, ChainSettings, Colormap, DebugView, LineColor, Named, Preset, Slab, SlabAxis,
    SliceSettings, TransparencySettings, TubeSettings, VoCombine, VolumeAoSettings,
};

use super::worker::Panel;
use crate::args::ColorArg;
use crate::cli::Method;

/// The methods the selector offers: `render --grid`'s ([`Method::all`], in its order), then
/// the ray-traced truth converging while the view rests. A web page leaves out object-space AO
/// ([`WEB_LEAVES_OUT`]).
pub fn methods() -> Vec<Method> {
    let web = cfg!(target_arch = "wasm32");
    Method::all().into_iter().chain([RAY_TRACED]).filter(|m| !web || m.volume.is_none()).collect()
}

/// Why a web page has no object-space AO: what it computes on the CPU runs on threads.
pub const WEB_LEAVES_OUT: &str = "Object-space AO (occlusion sweep, variance volume) is left out of the web page: it \
    computes on CPU threads, which a page does not have. `lineao view` has it.";

/// What the colour list's "anatomy" does.
const ANATOMY_COLOUR: &str = "the anatomy's value at each point (trilinear, as `--color volume:` of its file); a \
    tractogram streamed to the GPU is read again for its points";

/// The GPU ray tracer ([`lineao::method::raytraced`]), progressive.
pub const RAY_TRACED: Method = Method { screen: AoMethod::RayTraced, volume: None };

/// What a ray-traced panel shows while the camera moves, by default: LineAO.
pub const MOVING_DEFAULT: Method = Method { screen: AoMethod::LineAo, volume: None };

/// What the method selector calls a method: the registry's label, and the object-space AO's.
pub fn method_label(method: Method) -> String {
    let volume = |v| match v {
        VolumeMethod::Sweep => "sweep",
        VolumeMethod::VarianceVolume => "variance",
    };
    match (method.screen, method.volume) {
        (screen, None) => screen.info().label.into(),
        (AoMethod::None, Some(VolumeMethod::Sweep)) => "occlusion sweep".into(),
        (AoMethod::None, Some(VolumeMethod::VarianceVolume)) => "variance volume".into(),
        (screen, Some(v)) => format!("{} + {}", screen.info().label, volume(v)),
    }
}

/// Lines of a width in pixels, or ray-cast tubes of a radius in world units.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Geometry {
    Lines,
    Tubes,
}

/// How lines are colored.
#[derive(Clone, Debug, PartialEq)]
pub enum ColorMode {
    /// |tangent| as RGB (the DEC map of tractography).
    Tangent,
    /// A per-vertex field of the file through the colormap.
    Field(String),
    /// One sRGB color.
    Constant([u8; 3]),
    /// A colour per TRX group ([`Colormap::Categories`]), gray outside every group.
    Groups,
}

/// The methods' parameters. World-space lengths are in the data's units (mm for tractograms).
#[derive(Clone, Debug, PartialEq)]
pub struct Params {
    /// Line width, LineAO, SSAO, VO, blur, strength, zoom unit.
    pub chain: ChainSettings,
    pub tube_radius: f32,
    /// Object-space AO (its `method` is set per panel).
    pub volume: VolumeAoOptions,
    /// Light only from above (the octants toward the camera's up), else from everywhere.
    pub cloudy: bool,
    pub volume_combine: VoCombine,
}

impl Params {
    /// `preset`'s values for data whose zoom unit (1 mm for tractograms) is `zoom_unit` world
    /// units.
    pub fn preset(preset: Preset, zoom_unit: f32) -> Params {
        let mut chain = ChainSettings { zoom_unit, ..ChainSettings::default() };
        chain.ssao.radius_world *= zoom_unit;
        chain.ssao.range_world *= zoom_unit;
        chain.vo.radius_world *= zoom_unit;
        chain.raytraced.distance_world *= zoom_unit;
        // The picture keeps refining while the view rests (render's 256 is a reference's count).
        chain.raytraced.max_rays = 1024;
        // Few rays per pixel while the picture builds up: the edge-aware denoiser takes the
        // error of the first frames to about half (docs/ground-truth.md) and fades out.
        chain.raytraced.denoise = Some(lineao::RayDenoiseSettings::default());
        let mut volume = VolumeAoOptions::default();
        volume.density.occupancy_radius = 0.5 * zoom_unit;
        let mut params =
            Params { chain, tube_radius: 0.5 * zoom_unit, volume, cloudy: false, volume_combine: VoCombine::Product };
        // Each method's own reach from its preset (the panels share one chain's settings), the
        // strength from the chain's method's; `panel` scales the strength per method.
        params.chain = params.chain.with_preset_for_every_method(preset);
        if preset == Preset::Sparse {
            // Lines far apart are drawn wider, with more samples on LineAO's wider hemispheres,
            // and their density volume smoothed as far.
            params.chain.line_width_px = 3.0;
            params.chain.line_ao.s_h = 24;
            params.volume.density.occupancy_radius = zoom_unit;
        }
        params
    }
}

/// The side panel's state.
#[derive(Clone, Debug, PartialEq)]
pub struct Controls {
    /// The left (or only) image's method, and the right one's in compare mode.
    pub methods: [Method; 2],
    pub compare: bool,
    pub geometry: Geometry,
    /// How lines are lit (tubes are Phong-shaded).
    pub line_shading: LineShading,
    pub color: ColorMode,
    pub colormap: Colormap,
    /// Direction toward the light in view space: degrees around the view axis's vertical
    /// (0 = straight at the viewer, positive to the right) and above the horizontal.
    pub light_azimuth: f32,
    pub light_elevation: f32,
    pub debug_view: DebugView,
    pub timings: bool,
    pub params: Params,
    pub preset: Preset,
    /// What a ray-traced panel shows while the camera moves (a screen-space method: the rays
    /// start again once the camera rests).
    pub moving_method: Method,
    /// The last slab the lines were cut to (`params.chain.slab`), kept while it is off.
    pub slab: Slab,
    /// The last transparency (`params.chain.transparency`), kept while it is off.
    pub transparency: TransparencySettings,
    /// How far the slab's centre slider reaches either way (world units): half the dataset's
    /// viewing distance.
    pub slab_reach: f32,
    /// The world box of the anatomy's voxel centres (`--volume`), which its slices' sliders span.
    pub slice_box: Option<([f32; 3], [f32; 3])>,
    /// The field the anatomy's values at the points are ([`ColorMode::Field`], `volume:FILE`),
    /// which the colour list offers.
    pub anatomy_field: Option<String>,
    /// The colour list's "anatomy" was chosen: a request the viewer takes
    /// ([`App::colour_by_anatomy`](super::app::App::colour_by_anatomy)), which samples the
    /// volume at the points.
    pub colour_by_anatomy: bool,
    /// Whether a volume's slices show its voxels without data (`--opaque-slices`, the page's
    /// `opaque-slices`), until the side panel's checkbox says otherwise.
    pub opaque_slices: bool,
    /// The share of the streamlines shown (1: all), drawn at random but the same ones for a share.
    pub subset: f32,
    /// The arc length range shown (world units), or all.
    pub length: Option<[f32; 2]>,
    /// The dataset's longest streamline, which the length sliders reach.
    pub max_length: f32,
    /// The dataset's groups (TRX), each shown or not.
    pub groups: Vec<(String, bool)>,
    /// The dataset's one-column per-streamline fields and their ranges.
    pub streamline_fields: Vec<(String, [f32; 2])>,
    /// The per-streamline field and the range of it shown, or every value.
    pub field: Option<(String, [f32; 2])>,
    /// The seed of [`Controls::subset`] (`--subset-seed`).
    pub subset_seed: u64,
    /// Include and exclude regions (mrview's rule), in world units.
    pub regions: Vec<RegionRule>,
    /// `--group`: the groups shown once a dataset's groups are known (none named: all).
    pub shown_groups: Vec<String>,
    /// Where a new region goes and how large it starts: the dataset's centre and a tenth of its
    /// viewing distance.
    pub region_home: ([f32; 3], f32),
    /// The methods' settings the command line gave (`view --ssao-samples 8`): kept over the
    /// preset's values when a dataset sets the zoom unit.
    pub given: lineao_session::method_args::MethodArgs,
}

/// An include or exclude region of the selection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RegionRule {
    /// A kept streamline passes through every include region and through no exclude region.
    pub include: bool,
    pub region: lineao_tracts::Region,
}

impl Controls {
    pub fn new(methods: [Method; 2], compare: bool, preset: Preset) -> Controls {
        let light = lineao::lighting::Lighting::default().lights[0].dir.normalize();
        Controls {
            methods,
            compare,
            geometry: Geometry::Lines,
            line_shading: LineShading::Specular,
            color: ColorMode::Tangent,
            colormap: Colormap::Viridis,
            light_azimuth: light.x.atan2(light.z).to_degrees(),
            light_elevation: light.y.asin().to_degrees(),
            debug_view: DebugView::Final,
            timings: false,
            params: Params::preset(preset, 1.0),
            preset,
            moving_method: MOVING_DEFAULT,
            slab: Slab { axis: SlabAxis::Z, center: 0.0, thickness: 10.0 },
            transparency: TransparencySettings { alpha: 0.3, ..TransparencySettings::default() },
            slab_reach: 100.0,
            slice_box: None,
            anatomy_field: None,
            colour_by_anatomy: false,
            opaque_slices: false,
            subset: 1.0,
            length: None,
            max_length: 0.0,
            groups: Vec::new(),
            streamline_fields: Vec::new(),
            field: None,
            subset_seed: 0,
            regions: Vec::new(),
            shown_groups: Vec::new(),
            region_home: ([0.0; 3], 10.0),
            given: Default::default(),
        }
    }

    /// The selection `render`'s flags ask for (`view --subset`, `--include`, …).
    pub fn set_selection(&mut self, select: &crate::cli::SelectArgs) {
        if let Some(share) = select.subset {
            self.subset = share as f32;
        }
        (self.subset_seed, self.length, self.field) = (select.subset_seed, select.length, select.field.clone());
        self.shown_groups = select.groups.clone();
        let rule = |include| move |&region| RegionRule { include, region };
        self.regions = select.include.iter().map(rule(true)).chain(select.exclude.iter().map(rule(false))).collect();
    }

    /// The streamlines shown: [`Controls::subset`], [`Controls::length`], the field's range, the
    /// groups and the regions.
    pub fn selection(&self) -> lineao_tracts::Selection {
        // Every group shown: no rule. None shown: no streamline (an empty list would be all).
        let all = self.groups.iter().all(|(_, on)| *on);
        let none = !self.groups.is_empty() && self.groups.iter().all(|(_, on)| !on);
        let groups = if all { Vec::new() } else { self.groups.iter().filter(|g| g.1).map(|g| g.0.clone()).collect() };
        lineao_tracts::Selection {
            subset: if none {
                Some((0.0, 0))
            } else {
                (self.subset < 1.0).then_some((self.subset as f64, self.subset_seed))
            },
            length: self.length,
            field: self.field.clone(),
            groups,
            include: self.regions.iter().filter(|r| r.include).map(|r| r.region).collect(),
            exclude: self.regions.iter().filter(|r| !r.include).map(|r| r.region).collect(),
        }
    }

    /// A dataset's per-streamline fields; a field rule on one it lacks is dropped.
    pub fn set_streamline_fields(&mut self, fields: &[(String, [f32; 2])]) {
        self.streamline_fields = fields.to_vec();
        if self.field.as_ref().is_some_and(|(name, _)| !fields.iter().any(|(f, _)| f == name)) {
            self.field = None;
        }
    }

    /// A dataset's groups (known once all of it has arrived: `complete`), all shown; colour by
    /// group only where it has some.
    pub fn set_groups(&mut self, groups: &[String], complete: bool) {
        if self.groups.iter().map(|(name, _)| name).ne(groups) {
            let shown = |name: &String| self.shown_groups.is_empty() || self.shown_groups.contains(name);
            self.groups = groups.iter().map(|name| (name.clone(), shown(name))).collect();
        }
        if self.color == ColorMode::Groups && groups.is_empty() && complete {
            self.color = ColorMode::Tangent;
        }
    }

    /// Slices of an anatomy read from `name` whose voxel centres span `world_box`, at
    /// `positions` (default: all three through its centre).
    pub fn set_anatomy(&mut self, name: &str, world_box: ([f32; 3], [f32; 3]), positions: Option<[Option<f32>; 3]>) {
        self.anatomy_field = ColorArg::Volume(name.into()).field();
        let (lo, hi) = world_box;
        let center = std::array::from_fn(|a| Some(0.5 * (lo[a] + hi[a])));
        let positions = positions.unwrap_or(center);
        // The chain smooths the occlusion's sampling noise on the slices' pixels
        // (`ChainSettings::bilateral`).
        let opaque = self.params.chain.slices.as_ref().map_or(self.opaque_slices, |s| s.opaque);
        self.params.chain.slices = Some(SliceSettings { positions, opaque, ..SliceSettings::default() });
        self.slice_box = Some(world_box);
    }

    /// Turns transparency on (as it was last) or off: the `t` key.
    pub fn toggle_transparency(&mut self) {
        let chain = &mut self.params.chain;
        chain.transparency = match chain.transparency.take() {
            Some(_) => None,
            None => Some(self.transparency.clone()),
        };
    }

    /// Moves the slab (when it is on) by `steps` quarters of its thickness: the `[` and `]` keys.
    pub fn move_slab(&mut self, steps: f32) {
        if let Some(slab) = &mut self.params.chain.slab {
            slab.center = (slab.center + 0.25 * steps * slab.thickness).clamp(-self.slab_reach, self.slab_reach);
            self.slab = *slab;
        }
    }

    /// The data's zoom unit changed (a new file): the parameters take the preset's values in it,
    /// except the ray counts (`view --rays`) and the denoiser's switch, which are no lengths.
    pub fn set_zoom_unit(&mut self, zoom_unit: f32) {
        let (rays, slab, slices, transparency) = (
            self.params.chain.raytraced.clone(),
            self.params.chain.slab,
            self.params.chain.slices.take(),
            self.params.chain.transparency.take(),
        );
        self.params = Params::preset(self.preset, zoom_unit);
        (self.params.chain.slab, self.params.chain.slices) = (slab, slices);
        self.params.chain.transparency = transparency;
        let r = &mut self.params.chain.raytraced;
        (r.rays_per_frame, r.max_rays, r.denoise) = (rays.rays_per_frame, rays.max_rays, rays.denoise);
        self.given.apply(&mut self.params.chain);
    }

    /// What a link keeps of the controls, as `lineao view`'s options (flag without dashes,
    /// value; empty for a switch): the shown methods' described settings that differ from the
    /// preset's, the colour (a file's values as `volume:FILE` or `tsf:FILE`, see
    /// [`colours_by_a_file`]), the slab and the selection's rules.
    pub fn link_flags(&self) -> Vec<(String, String)> {
        let mut flags = Vec::new();
        // The preset's values with the flags so far written in, as the page will open them (a
        // setting may set another: SSAO's radius its range check).
        let mut opened = Params::preset(self.preset, self.params.chain.zoom_unit).chain;
        let shown = if self.compare { &self.methods[..] } else { &self.methods[..1] };
        for (method, setting) in lineao_session::method_args::described() {
            let chain = &self.params.chain;
            let value = setting.get(chain);
            if !shown.iter().any(|m| m.screen == method) || !setting.applies(chain) || value == setting.get(&opened) {
                continue;
            }
            let text = match setting.kind {
                // A switch's flag only gives its `given` value; the other is the preset's.
                Kind::Switch { given } if value == Value::Switch(given) => String::new(),
                Kind::Switch { .. } => continue,
                _ => value.to_string(),
            };
            flags.push((setting.flag.to_string(), text));
            setting.set(&mut opened, value);
        }
        let color = match &self.color {
            ColorMode::Tangent => None,
            // A file's values are named as `--color` takes them.
            ColorMode::Field(name) if colours_by_a_file(name) => Some(name.clone()),
            ColorMode::Field(name) => Some(format!("field:{name}")),
            ColorMode::Groups => Some("groups".into()),
            ColorMode::Constant(rgb) => Some(rgb.map(|c| format!("{:.4}", f32::from(c) / 255.0)).join(",")),
        };
        if let Some(color) = color {
            if matches!(self.color, ColorMode::Field(_)) && self.colormap != Colormap::Viridis {
                flags.push(("colormap".into(), self.colormap.name().into()));
            }
            flags.push(("color".into(), color));
        }
        if let Some(Slab { axis, center, thickness }) = self.params.chain.slab {
            flags.push(("slab".into(), format!("{},{center},{thickness}", axis.name())));
        }
        if let Some(t) = &self.params.chain.transparency {
            flags.push(("alpha".into(), t.alpha.to_string()));
            flags.push(("context-alpha".into(), t.context_alpha.to_string()));
            flags.push(("layers".into(), t.layers.to_string()));
        }
        let selection = self.selection();
        let pair = |[a, b]: [f32; 2]| format!("{a},{b}");
        if let Some((share, seed)) = selection.subset {
            flags.push(("subset".into(), share.to_string()));
            if seed != 0 {
                flags.push(("subset-seed".into(), seed.to_string()));
            }
        }
        if let Some(range) = selection.length {
            flags.push(("length".into(), pair(range)));
        }
        if let Some((name, range)) = &selection.field {
            flags.push(("field".into(), format!("{name},{}", pair(*range))));
        }
        flags.extend(selection.groups.iter().map(|g| ("group".to_string(), g.clone())));
        for rule in &self.regions {
            let key = if rule.include { "include" } else { "exclude" };
            let numbers = |values: &[f32]| values.iter().map(f32::to_string).collect::<Vec<_>>().join(",");
            let text = match rule.region {
                lineao_tracts::Region::Sphere { center, radius } => {
                    format!("sphere:{}", numbers(&[center[0], center[1], center[2], radius]))
                }
                lineao_tracts::Region::Box { min, max } => format!("box:{}", numbers(&[min, max].concat())),
            };
            flags.push((key.to_string(), text));
        }
        flags
    }

    /// The panels to render: one, or two in compare mode. `up` is the camera's (a cloudy sky
    /// comes from the world axis nearest to it), `range` the scalar field's colormap range;
    /// while the camera is `moving`, a ray-traced panel shows [`Controls::moving_method`].
    pub fn panels(&self, up: Vec3, range: Option<[f32; 2]>, moving: bool) -> Vec<Panel> {
        let count = if self.compare { 2 } else { 1 };
        let shown = |method: Method| if moving && method == RAY_TRACED { self.moving_method } else { method };
        self.methods[..count].iter().map(|&method| self.panel(shown(method), up, range)).collect()
    }

    fn panel(&self, method: Method, up: Vec3, range: Option<[f32; 2]>) -> Panel {
        let p = &self.params;
        let sky = if p.cloudy { Sky::above_nearest_axis(up.to_array()) } else { Sky::Uniform };
        let mut settings = p.chain.clone();
        settings.method = method.screen;
        // The slider holds the strength of the chain's method (LineAO) at the preset; another
        // method keeps its own strength of the preset relative to it.
        let preset = |method| ChainSettings { method, ..ChainSettings::default() }.with_preset(self.preset).strength;
        settings.strength *= preset(method.screen) / preset(p.chain.method);
        settings.volume = method.volume.map(|_| VolumeAoSettings {
            // The view-independent forms hold the sky already.
            sky: if p.volume.form.is_none() { sky.weights() } else { [1.0; 8] },
            combine: p.volume_combine,
        });
        settings.tubes = (self.geometry == Geometry::Tubes).then_some(TubeSettings { radius_world: p.tube_radius });
        // Tubes are opaque only.
        if settings.tubes.is_some() {
            settings.transparency = None;
        }
        settings.line_color = match (&self.color, range) {
            (ColorMode::Field(_), Some(range)) => LineColor::Scalar { colormap: self.colormap, range },
            (ColorMode::Groups, Some(range)) => LineColor::Scalar { colormap: Colormap::Categories, range },
            (ColorMode::Constant(rgb), _) => LineColor::Constant(rgb.map(|c| srgb_to_linear(c as f32 / 255.0))),
            _ => LineColor::Tangent,
        };
        let (az, el) = (self.light_azimuth.to_radians(), self.light_elevation.to_radians());
        settings.lighting.lights[0].dir = Vec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos());
        settings.lighting.line_shading = self.line_shading;
        // A pyramid level the method does not have shows its deepest.
        settings.debug_view = match self.debug_view {
            DebugView::Level(k) => DebugView::Level(k.min(settings.levels() - 1)),
            view => view,
        };
        let volume = method.volume.map(|m| VolumeAoOptions { method: m, sky, ..p.volume.clone() });
        Panel { settings, volume }
    }

    /// Draws the panel; `fields` are the file's one-column per-vertex fields.
    pub fn ui(&mut self, ui: &mut Ui, fields: &[(String, [f32; 2])]) {
        ui.heading("Method");
        method_combo(ui, "method", &mut self.methods[0]);
        ui.checkbox(&mut self.compare, "Compare side by side").on_hover_text("Drag the divider to move it");
        if self.compare {
            method_combo(ui, "method-right", &mut self.methods[1]);
        }
        if cfg!(target_arch = "wasm32") {
            ui.small(WEB_LEAVES_OUT);
        }
        ui.separator();

        ui.heading("Lines");
        ui.horizontal(|ui| {
            ui.selectable_value(&mut self.geometry, Geometry::Lines, "Lines");
            ui.selectable_value(&mut self.geometry, Geometry::Tubes, "Tubes");
        });
        let p = &mut self.params;
        match self.geometry {
            Geometry::Lines => {
                ui.add(egui::Slider::new(&mut p.chain.line_width_px, 0.5..=8.0).text("width (px)"));
                ui.checkbox(&mut p.chain.cull, "draw only what is seen")
                    .on_hover_text("cull hidden lines on the GPU against the last frame: the same picture, faster when lines hide lines");
                ui.add_enabled(p.chain.cull, egui::Checkbox::new(&mut p.chain.lod, "level of detail")).on_hover_text(
                    "draw each visible piece of line with fewer points where that moves it by under half a pixel",
                );
                ui.horizontal(|ui| {
                    ui.label("lit");
                    ui.selectable_value(&mut self.line_shading, LineShading::Specular, "specular")
                        .on_hover_text("Illuminated lines' highlight on top of the AO (the paper's)");
                    ui.selectable_value(&mut self.line_shading, LineShading::CylinderAveraged, "cylinder")
                        .on_hover_text("Diffuse and specular averaged around the line (Mallo et al. 2005)");
                });
            }
            Geometry::Tubes => {
                let max = 5.0 * p.chain.zoom_unit;
                ui.add(
                    egui::Slider::new(&mut p.tube_radius, 0.05 * p.chain.zoom_unit..=max)
                        .logarithmic(true)
                        .text("radius"),
                );
            }
        }
        self.color_ui(ui, fields);
        ui.add(egui::Slider::new(&mut self.light_azimuth, -180.0..=180.0).text("light azimuth (°)"));
        ui.add(egui::Slider::new(&mut self.light_elevation, -89.0..=89.0).text("light elevation (°)"));
        self.transparency_ui(ui);
        self.slab_ui(ui);
        self.slices_ui(ui);
        self.selection_ui(ui);
        self.groups_ui(ui);
        ui.separator();

        ui.heading("Parameters");
        ui.horizontal(|ui| {
            for (preset, label, hint) in [
                (Preset::Legible, "Legible", "Darker lines lie deeper: chosen by legibility (lineao score --fit)"),
                (Preset::Physical, "Physical", "Fitted to binary AO within 2 mm: faint on whole brains"),
                (Preset::Paper, "Paper (dense)", "The papers' values, made for whole-brain tractography"),
                (Preset::Sparse, "Sparse streamlines", "Wider lines, every method reaching farther"),
            ] {
                if ui.selectable_label(self.preset == preset, label).on_hover_text(hint).clicked() {
                    self.preset = preset;
                    self.params = Params::preset(preset, self.params.chain.zoom_unit);
                }
            }
        });
        if ui.button("Reset to defaults").on_hover_text("The selected preset's values").clicked() {
            self.params = Params::preset(self.preset, self.params.chain.zoom_unit);
        }
        let shown = if self.compare { &self.methods[..] } else { &self.methods[..1] };
        let screen = |m: AoMethod| shown.iter().any(|s| s.screen == m);
        let volume = shown.iter().any(|s| s.volume.is_some());
        let p = &mut self.params;
        ui.add(egui::Slider::new(&mut p.chain.strength, 0.0..=2.0).text("strength"));
        // Each method's panel: its settings' descriptions (object-space AO's, not a method of
        // the registry, below is written out).
        for method in AoMethod::REGISTRY.iter().copied().filter(|&m| screen(m) && m.info().settings().next().is_some())
        {
            egui::CollapsingHeader::new(method.info().label)
                .default_open(true)
                .show(ui, |ui| described_ui(ui, method, &mut p.chain));
        }
        if volume {
            egui::CollapsingHeader::new("Object-space AO").default_open(true).show(ui, |ui| volume_ui(ui, p));
        }
        if shown.iter().any(|m| m.screen.info().traces_scene) {
            moving_ui(ui, &mut self.moving_method);
        }
        let mut blur = p.chain.blur.is_some();
        ui.checkbox(&mut blur, "Bilateral blur");
        if blur != p.chain.blur.is_some() {
            p.chain.blur = blur.then(BilateralSettings::default);
        }
        if let Some(b) = &mut p.chain.blur {
            ui.add(egui::Slider::new(&mut b.radius_px, 1..=16).text("taps per side"));
            let z = p.chain.zoom_unit;
            ui.add(egui::Slider::new(&mut b.depth_sigma_world, 0.05 * z..=10.0 * z).logarithmic(true).text("depth σ"));
        }
        ui.separator();

        ui.heading("Show");
        let levels = shown.iter().map(|m| ChainSettings { method: m.screen, ..p.chain.clone() }.levels()).max();
        let levels = levels.unwrap_or(1);
        let mut views = vec![
            (DebugView::Final, "final image".to_string()),
            (DebugView::Ao, "AO only".into()),
            (DebugView::Normals, "normals".into()),
            (DebugView::Depth, "depth".into()),
            (DebugView::Zoom, "zoom map z(P)".into()),
        ];
        views.extend((0..levels).map(|k| (DebugView::Level(k), format!("pyramid level {k}"))));
        views.push((DebugView::Pieces, "pieces: level of detail".into()));
        views.push((DebugView::Frozen, "pieces: cull frozen (orbit away)".into()));
        views.push((DebugView::Culled, "pieces: frozen, what it left out".into()));
        let current =
            views.iter().find(|(v, _)| *v == self.debug_view).map_or("final image".into(), |(_, l)| l.clone());
        egui::ComboBox::from_id_salt("debug-view").selected_text(current).show_ui(ui, |ui| {
            for (view, label) in views {
                ui.selectable_value(&mut self.debug_view, view, label);
            }
        });
        ui.checkbox(&mut self.timings, "GPU time per pass");
    }

    /// Transparency: on or off, the selection's opacity and the context's, the K-buffer's K.
    fn transparency_ui(&mut self, ui: &mut Ui) {
        let lines = self.geometry == Geometry::Lines;
        let mut on = self.params.chain.transparency.is_some();
        ui.add_enabled(lines, egui::Checkbox::new(&mut on, "see through (t)")).on_hover_text(
            "lines composited in depth order, each darkened by its object-space AO (a method with sweep); tubes are opaque",
        );
        let chain = &mut self.params.chain;
        let Some(t) = on.then(|| chain.transparency.get_or_insert_with(|| self.transparency.clone())) else {
            chain.transparency = None;
            return;
        };
        ui.add(egui::Slider::new(&mut t.alpha, 0.02..=1.0).text("opacity"))
            .on_hover_text("of the lines shown: 1 draws them opaque, with the method's AO");
        ui.add(egui::Slider::new(&mut t.context_alpha, 0.0..=1.0).text("context opacity"))
            .on_hover_text("of the lines the selection leaves out: 0 hides them");
        let (lo, hi) = (*TransparencySettings::LAYERS.start(), *TransparencySettings::LAYERS.end());
        ui.add(egui::Slider::new(&mut t.layers, lo..=hi).text("exact layers"))
            .on_hover_text("the nearest fragments of each pixel composited exactly; those behind are blended");
        self.transparency = t.clone();
    }

    /// The slab: on or off, its axis, centre and thickness.
    fn slab_ui(&mut self, ui: &mut Ui) {
        let mut on = self.params.chain.slab.is_some();
        ui.checkbox(&mut on, "slab").on_hover_text("show only the lines between two parallel planes ([ and ] move it)");
        // Turned off, the slab is kept for when it is turned on again.
        let chain = &mut self.params.chain;
        let Some(slab) = on.then(|| chain.slab.get_or_insert(self.slab)) else {
            chain.slab = None;
            return;
        };
        ui.horizontal(|ui| {
            for axis in SlabAxis::VALUES {
                ui.selectable_value(&mut slab.axis, *axis, axis.name()).on_hover_text(axis.help());
            }
        });
        let reach = self.slab_reach;
        ui.add(egui::Slider::new(&mut slab.center, -reach..=reach).text("centre"));
        ui.add(egui::Slider::new(&mut slab.thickness, (0.005 * reach).max(1e-3)..=reach).text("thickness"));
        self.slab = *slab;
    }

    /// The streamlines shown: a random share, a length range (the GPU selects: no upload).
    fn selection_ui(&mut self, ui: &mut Ui) {
        let mut percent = 100.0 * self.subset;
        ui.add(egui::Slider::new(&mut percent, 1.0..=100.0).text("% of streamlines").logarithmic(true))
            .on_hover_text("a random share, the same streamlines for the same share");
        self.subset = percent / 100.0;
        let max = self.max_length.max(1.0);
        let mut on = self.length.is_some();
        ui.checkbox(&mut on, "by length").on_hover_text("only the streamlines whose arc length lies in the range");
        self.length = on.then(|| {
            let [mut lo, mut hi] = self.length.unwrap_or([0.0, max]);
            ui.add(egui::Slider::new(&mut lo, 0.0..=max).text("shortest"));
            ui.add(egui::Slider::new(&mut hi, 0.0..=max).text("longest"));
            [lo, hi.max(lo)]
        });
        self.field_ui(ui);
        self.regions_ui(ui);
    }

    /// Include and exclude regions: each a sphere or a box placed in world units, a button to
    /// add one at the data's centre, one to remove each (outlined over the picture).
    fn regions_ui(&mut self, ui: &mut Ui) {
        let (home, size) = self.region_home;
        ui.horizontal(|ui| {
            ui.label("regions").on_hover_text(
                "a streamline is kept when it passes through every include region and no exclude region (mrview's rule)",
            );
            if ui.button("+ sphere").clicked() {
                let region = lineao_tracts::Region::Sphere { center: home, radius: size };
                self.regions.push(RegionRule { include: true, region });
            }
            if ui.button("+ box").clicked() {
                let (min, max) = (home.map(|c| c - size), home.map(|c| c + size));
                self.regions.push(RegionRule { include: true, region: lineao_tracts::Region::Box { min, max } });
            }
        });
        let step = f64::from(0.01 * size);
        let mut removed = None;
        for (i, rule) in self.regions.iter_mut().enumerate() {
            ui.push_id(("region", i), |ui| {
                ui.horizontal(|ui| {
                    ui.selectable_value(&mut rule.include, true, "include");
                    ui.selectable_value(&mut rule.include, false, "exclude");
                    if ui.small_button("remove").clicked() {
                        removed = Some(i);
                    }
                });
                let xyz = |ui: &mut Ui, label: &str, p: &mut [f32; 3]| {
                    ui.horizontal(|ui| {
                        ui.label(label);
                        for c in p.iter_mut() {
                            ui.add(egui::DragValue::new(c).speed(step).max_decimals(1));
                        }
                    });
                };
                match &mut rule.region {
                    lineao_tracts::Region::Sphere { center, radius } => {
                        xyz(ui, "centre", center);
                        ui.add(egui::Slider::new(radius, 0.01 * size..=10.0 * size).logarithmic(true).text("radius"));
                    }
                    lineao_tracts::Region::Box { min, max } => {
                        xyz(ui, "from", min);
                        xyz(ui, "to", max);
                        for axis in 0..3 {
                            max[axis] = max[axis].max(min[axis]);
                        }
                    }
                }
            });
        }
        if let Some(i) = removed {
            self.regions.remove(i);
        }
    }

    /// A range of a per-streamline field (.trk properties, TRX dps): the streamlines within it.
    fn field_ui(&mut self, ui: &mut Ui) {
        let Some((first, first_range)) = self.streamline_fields.first().cloned() else { return };
        let mut on = self.field.is_some();
        ui.checkbox(&mut on, "by field")
            .on_hover_text("only the streamlines whose per-streamline value lies in the range");
        if !on {
            self.field = None;
            return;
        }
        let (mut name, mut range) = self.field.clone().unwrap_or((first, first_range));
        egui::ComboBox::from_id_salt("streamline-field").selected_text(name.clone()).show_ui(ui, |ui| {
            for (field, _) in &self.streamline_fields {
                ui.selectable_value(&mut name, field.clone(), field.as_str());
            }
        });
        let [lo, hi] = self.streamline_fields.iter().find(|(f, _)| *f == name).map_or(first_range, |(_, r)| *r);
        if self.field.as_ref().is_some_and(|(old, _)| *old != name) {
            range = [lo, hi];
        }
        ui.add(egui::Slider::new(&mut range[0], lo..=hi).text("from"));
        ui.add(egui::Slider::new(&mut range[1], lo..=hi).text("to"));
        range[1] = range[1].max(range[0]);
        self.field = Some((name, range));
    }

    /// The anatomy's slices (with `--volume`): each axis's on or off and where it cuts.
    fn slices_ui(&mut self, ui: &mut Ui) {
        let (Some((lo, hi)), Some(slices)) = (self.slice_box, &mut self.params.chain.slices) else { return };
        ui.label("anatomy slices");
        for (axis, name) in ["x (sagittal)", "y (coronal)", "z (axial)"].into_iter().enumerate() {
            ui.horizontal(|ui| {
                let mut on = slices.positions[axis].is_some();
                ui.checkbox(&mut on, "");
                let mut at = slices.positions[axis].unwrap_or(0.5 * (lo[axis] + hi[axis]));
                ui.add_enabled(on, egui::Slider::new(&mut at, lo[axis]..=hi[axis]).text(name));
                slices.positions[axis] = on.then_some(at);
            });
        }
        ui.checkbox(&mut slices.opaque, "voxels without data (0, NaN) shown")
            .on_hover_text("Off: a slice is transparent where the volume holds no data (its section only)");
    }

    fn color_ui(&mut self, ui: &mut Ui, fields: &[(String, [f32; 2])]) {
        let label = match &self.color {
            ColorMode::Tangent => "direction".to_string(),
            ColorMode::Field(name) => self.field_label(name),
            ColorMode::Constant(_) => "constant".into(),
            ColorMode::Groups => "groups".into(),
        };
        ui.horizontal(|ui| {
            ui.label("Color");
            egui::ComboBox::from_id_salt("color").selected_text(label).show_ui(ui, |ui| {
                ui.selectable_value(&mut self.color, ColorMode::Tangent, "direction").on_hover_text(
                    "|tangent| as RGB: left-right red, anterior-posterior green, superior-inferior blue",
                );
                for (name, _) in fields {
                    let label = self.field_label(name);
                    ui.selectable_value(&mut self.color, ColorMode::Field(name.clone()), label);
                }
                // The anatomy's values, until they are one of the fields above.
                if let Some(field) = &self.anatomy_field
                    && !fields.iter().any(|(name, _)| name == field)
                    && ui.selectable_label(false, "anatomy").on_hover_text(ANATOMY_COLOUR).clicked()
                {
                    self.colour_by_anatomy = true;
                }
                if !self.groups.is_empty() {
                    ui.selectable_value(&mut self.color, ColorMode::Groups, "groups")
                        .on_hover_text("a colour per TRX group (16 colours in turn), gray outside every group");
                }
                if !matches!(self.color, ColorMode::Constant(_)) && ui.selectable_label(false, "constant").clicked() {
                    self.color = ColorMode::Constant([200, 170, 120]);
                }
            });
        });
        match &mut self.color {
            ColorMode::Field(name) => {
                egui::ComboBox::from_id_salt("colormap").selected_text(self.colormap.name()).show_ui(ui, |ui| {
                    for map in Colormap::ALL {
                        ui.selectable_value(&mut self.colormap, map, map.name());
                    }
                });
                if let Some((_, range)) = fields.iter().find(|(field, _)| field == name) {
                    colour_bar(ui, self.colormap, *range);
                }
            }
            ColorMode::Constant(rgb) => {
                ui.color_edit_button_srgb(rgb);
            }
            ColorMode::Tangent | ColorMode::Groups => {}
        }
    }

    /// What the colour list calls the field `name`: "anatomy" for the anatomy's values.
    fn field_label(&self, name: &str) -> String {
        match &self.anatomy_field {
            Some(field) if field == name => "anatomy".into(),
            _ => format!("field: {name}"),
        }
    }

    /// The groups (TRX): each shown or not, with its colour when the lines are coloured by group.
    fn groups_ui(&mut self, ui: &mut Ui) {
        if self.groups.is_empty() {
            return;
        }
        ui.label("groups");
        let table = Colormap::Categories.table();
        let coloured = self.color == ColorMode::Groups;
        for (k, (name, on)) in self.groups.iter_mut().enumerate() {
            ui.horizontal(|ui| {
                if coloured {
                    let [r, g, b] = [0, 1, 2].map(|c| crate::label::srgb8(table[k % table.len()][c]));
                    let (rect, _) = ui.allocate_exact_size(egui::vec2(12.0, 12.0), egui::Sense::hover());
                    ui.painter().rect_filled(rect, 2.0, egui::Color32::from_rgb(r, g, b));
                }
                ui.checkbox(on, name.as_str());
            });
        }
    }
}

/// Whether the field `name` (of [`ColorMode::Field`]) holds a file's values beside the
/// tractogram, named as `--color` takes them (`volume:FILE`, `tsf:FILE`), not one of its own.
pub fn colours_by_a_file(name: &str) -> bool {
    matches!(crate::args::parse_color(name), Ok(ColorArg::Volume(_) | ColorArg::Tsf(_)))
}

/// The legend of a field's colours: the colormap over `range`, its ends' and middle's numbers
/// (those of `render --legend`).
fn colour_bar(ui: &mut Ui, colormap: Colormap, range: [f32; 2]) {
    let (rect, _) = ui.allocate_exact_size(egui::vec2(ui.available_width().min(220.0), 12.0), egui::Sense::hover());
    let steps = 64;
    for i in 0..steps {
        let [r, g, b] = colormap.color((i as f32 + 0.5) / steps as f32).map(crate::label::srgb8);
        let x0 = rect.left() + rect.width() * i as f32 / steps as f32;
        let x1 = rect.left() + rect.width() * (i + 1) as f32 / steps as f32;
        let cell = egui::Rect::from_x_y_ranges(x0..=x1, rect.y_range());
        ui.painter().rect_filled(cell, 0.0, egui::Color32::from_rgb(r, g, b));
    }
    let [low, middle, high] = crate::label::legend_labels(range);
    ui.horizontal(|ui| {
        ui.set_width(rect.width());
        ui.small(low);
        ui.add_space((rect.width() / 2.0 - 40.0).max(0.0));
        ui.small(middle);
        ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| ui.small(high));
    });
}

fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

fn method_combo(ui: &mut Ui, id: &str, method: &mut Method) {
    egui::ComboBox::from_id_salt(id).selected_text(method_label(*method)).width(180.0).show_ui(ui, |ui| {
        for m in methods() {
            ui.selectable_value(method, m, method_label(m));
        }
    });
}

/// A method's panel from its settings' descriptions ([`lineao::method::setting`]): a slider for
/// each number (by factors where the description says so; lengths in the data's units span
/// the description's range times the zoom unit), buttons for each set of values, a checkbox
/// for each switch, each with its flag's help on hover — those that apply under the settings
/// shown. After a control moves, the method keeps the others valid ([`MethodInfo::conform`]).
///
/// [`MethodInfo::conform`]: lineao::method::MethodInfo::conform
pub fn described_ui(ui: &mut Ui, method: AoMethod, chain: &mut ChainSettings) {
    let info = method.info();
    let scale = chain.zoom_unit;
    for setting in info.settings() {
        if !setting.applies(chain) {
            continue;
        }
        let label = match setting.unit {
            Unit::None => setting.label.to_string(),
            unit => format!("{} ({})", setting.label, unit.name()),
        };
        let world = if setting.unit == Unit::WorldUnits { scale } else { 1.0 };
        let changed = match (setting.kind, setting.get(chain)) {
            (Kind::Number { min, max, log, .. }, Value::Number(mut x)) => {
                let slider = egui::Slider::new(&mut x, min * world..=max * world).logarithmic(log).text(label);
                ui.add(slider).on_hover_text(setting.help).changed().then_some(Value::Number(x))
            }
            (Kind::Above { slider: [min, max], log, .. }, Value::Number(mut x)) => {
                let slider = egui::Slider::new(&mut x, min * world..=max * world).logarithmic(log).text(label);
                ui.add(slider).on_hover_text(setting.help).changed().then_some(Value::Number(x))
            }
            (Kind::Count { min, max }, Value::Count(mut n)) => {
                // Wide ranges by factors, the slider spanning at most 65536 (typed beyond it).
                let span = max.min(min.saturating_add(1 << 16));
                let slider = egui::Slider::new(&mut n, min..=span)
                    .logarithmic(span >= 64 * min.max(1))
                    .clamping(if span < max { egui::SliderClamping::Never } else { egui::SliderClamping::Always })
                    .text(label);
                let changed = ui.add(slider).on_hover_text(setting.help).changed();
                changed.then_some(Value::Count(n.clamp(min, max)))
            }
            (Kind::Reach { slider: [min, max] }, Value::Number(mut x)) => {
                let slider = egui::Slider::new(&mut x, min * world..=max * world).logarithmic(true).text(label);
                ui.add(slider).on_hover_text(setting.help).changed().then_some(Value::Number(x))
            }
            (Kind::Reach { .. }, Value::Share(share)) => {
                let mut percent = 100.0 * share;
                let slider =
                    egui::Slider::new(&mut percent, 1.0..=100.0).logarithmic(true).suffix(" %").text(setting.label);
                let changed = ui.add(slider).on_hover_text(setting.help).changed();
                changed.then_some(Value::Share(percent / 100.0))
            }
            (Kind::Counts(counts), Value::Count(n)) => {
                let options: Vec<Value> = counts.iter().map(|&c| Value::Count(c)).collect();
                values_ui(ui, &label, setting.help, Value::Count(n), &options)
            }
            (Kind::Choice(names), value) => {
                let options: Vec<Value> = names.iter().map(|&name| Value::Choice(name)).collect();
                values_ui(ui, &label, setting.help, value, &options)
            }
            (_, value) => {
                let mut on = value.is_on();
                ui.checkbox(&mut on, label).on_hover_text(setting.help).changed().then_some(Value::Switch(on))
            }
        };
        if let Some(value) = changed {
            setting.set(chain, value);
            info.conform(chain);
        }
    }
}

/// A row of buttons, one per value: the one clicked, if any.
fn values_ui(ui: &mut Ui, label: &str, help: &str, current: Value, options: &[Value]) -> Option<Value> {
    ui.horizontal(|ui| {
        ui.label(label).on_hover_text(help);
        let clicked =
            options.iter().filter(|&&option| ui.selectable_label(option == current, option.to_string()).clicked());
        clicked.last().copied()
    })
    .inner
}

/// What a ray-traced panel shows while the camera moves (the viewer's own choice).
fn moving_ui(ui: &mut Ui, moving: &mut Method) {
    egui::ComboBox::from_label("while moving").selected_text(method_label(*moving)).show_ui(ui, |ui| {
        for m in methods().into_iter().filter(|m| m.volume.is_none() && *m != RAY_TRACED) {
            ui.selectable_value(moving, m, method_label(m));
        }
    });
}

fn volume_ui(ui: &mut Ui, p: &mut Params) {
    let v = &mut p.volume;
    let z = p.chain.zoom_unit;
    ui.add(egui::Slider::new(&mut v.density.resolution, 32..=256).text("voxels (longest axis)"))
        .on_hover_text("Computed once per setting on the CPU: 1–3 s for 1 M vertices at 256");
    ui.add(
        egui::Slider::new(&mut v.density.occupancy_radius, 0.1 * z..=5.0 * z)
            .logarithmic(true)
            .text("occupancy radius"),
    );
    ui.add(egui::Slider::new(&mut v.sweep.alpha, 0.05..=1.0).text("sweep opacity α"));
    ui.checkbox(&mut p.cloudy, "cloudy sky (light from above)");
    let forms = [
        (None, "per pixel (paper)"),
        (Some(ScalarForm::AroundTangent), "around tangent"),
        (Some(ScalarForm::NoGeometryTerm), "no geometry term"),
    ];
    ui.horizontal_wrapped(|ui| {
        ui.label("normal");
        for (form, label) in forms {
            ui.selectable_value(&mut v.form, form, label);
        }
    });
    ui.horizontal(|ui| {
        ui.label("with screen space");
        ui.selectable_value(&mut p.volume_combine, VoCombine::Product, "product");
        ui.selectable_value(&mut p.volume_combine, VoCombine::Min, "darker");
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_command_lines_settings_outlast_a_datasets_zoom_unit() {
        // `view --ssao-samples 8 --ssao-radius 7`: the panel shows them once a file has set the
        // zoom unit (which takes the preset's values in it).
        let ssao = methods().into_iter().find(|m| m.screen == AoMethod::Ssao).unwrap();
        let mut controls = Controls::new([ssao, ssao], false, Preset::Legible);
        controls.given.give("ssao-samples", Value::Count(8));
        controls.given.give("ssao-radius", Value::Number(7.0));
        controls.given.apply(&mut controls.params.chain);
        controls.set_zoom_unit(2.0);
        let ssao = &controls.params.chain.ssao;
        assert_eq!((ssao.samples, ssao.radius_world, controls.params.chain.zoom_unit), (8, 7.0, 2.0));
    }

    #[test]
    fn every_preset_and_method_gives_valid_settings() {
        for preset in Preset::ALL {
            for zoom_unit in [1.0, 0.01] {
                let mut controls = Controls::new([methods()[1], methods()[4]], true, preset);
                controls.set_zoom_unit(zoom_unit);
                for method in methods() {
                    controls.methods[1] = method;
                    for geometry in [Geometry::Lines, Geometry::Tubes] {
                        controls.geometry = geometry;
                        controls.debug_view = DebugView::Level(2);
                        for panel in controls.panels(Vec3::Z, Some([0.0, 1.0]), false) {
                            panel.settings.validate().unwrap_or_else(|e| panic!("{preset:?} {method:?}: {e}"));
                        }
                    }
                }
            }
        }
    }

    /// The viewer's library presets give each method what `render` gives it: LineAO's and
    /// SSAO's reach and strength of the preset (SSAO's 8 mm under `legible`).
    #[test]
    fn library_presets_give_each_method_its_own_values() {
        for preset in Preset::ALL {
            let library = preset;
            let controls = Controls::new([methods()[1], methods()[4]], true, preset);
            let panels = controls.panels(Vec3::Z, None, false);
            for panel in &panels {
                let method = panel.settings.method;
                // The viewer's own line width (3 px under `sparse`) sets r0 in pixels.
                let width = panel.settings.line_width_px;
                let expected =
                    ChainSettings { method, line_width_px: width, ..ChainSettings::default() }.with_preset(library);
                let s = &panel.settings;
                assert!(
                    (s.strength - expected.strength).abs() < 1e-6,
                    "{preset:?} {method:?}: strength {}",
                    s.strength
                );
                match method {
                    AoMethod::LineAo => assert_eq!(
                        (s.line_ao.s_r, s.r0_px(), s.line_ao.delta_scale),
                        (expected.line_ao.s_r, expected.r0_px(), expected.line_ao.delta_scale)
                    ),
                    AoMethod::Ssao => assert_eq!(s.ssao.radius_world, expected.ssao.radius_world, "{preset:?}"),
                    other => panic!("unexpected {other:?}"),
                }
                s.validate().unwrap();
            }
        }
    }

    #[test]
    fn a_ray_traced_panel_shows_the_chosen_method_while_the_camera_moves() {
        let mut controls = Controls::new([RAY_TRACED, methods()[4]], true, Preset::Legible);
        let method = |panels: Vec<Panel>| panels.iter().map(|p| p.settings.method).collect::<Vec<_>>();
        assert_eq!(method(controls.panels(Vec3::Z, None, false)), [AoMethod::RayTraced, AoMethod::Ssao]);
        assert_eq!(method(controls.panels(Vec3::Z, None, true)), [AoMethod::LineAo, AoMethod::Ssao]);
        controls.moving_method = methods()[2];
        assert_eq!(method(controls.panels(Vec3::Z, None, true)), [AoMethod::VoLine, AoMethod::Ssao]);
    }

    #[test]
    fn the_default_light_is_the_contracts() {
        let controls = Controls::new([methods()[1]; 2], false, Preset::Paper);
        let panel = &controls.panels(Vec3::Z, None, false)[0];
        let expected = lineao::lighting::Lighting::default().lights[0].dir.normalize();
        assert!(panel.settings.lighting.lights[0].dir.distance(expected) < 1e-5);
    }
}
