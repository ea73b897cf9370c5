//! The render world: each camera's chains, their preparation and their passes in `Core3d`.
//!
//! ```text
//!  main world      extract: LineAo (+ the scene's bounds), Polylines (merged, on change)
//!       │
//!  Render/Prepare  per camera: the meshes' HostAo and the lines' OverlayAo made, resized,
//!       │          re-set when the settings change; the frame's uniforms written
//!  Core3d          Prepass ─▶ MainPass ─▶ [LineAoSystems::Draw] ─▶ EarlyPostProcess ─▶ …
//!                  Draw: prepass depth + normals ─▶ HostAo ─▶ main texture (post-process pair)
//!                        Polylines ─▶ OverlayAo ─▶ main texture + Bevy's depth
//! ```

use std::collections::{HashMap, HashSet};

use bevy::camera::primitives::Aabb;
use bevy::core_pipeline::prepass::{DepthPrepass, NormalPrepass, ViewPrepassTextures};
use bevy::core_pipeline::schedule::{Core3d, Core3dSystems};
use bevy::prelude::*;
use bevy::render::camera::ExtractedCamera;
use bevy::render::renderer::{RenderAdapter, RenderContext, RenderDevice, RenderQueue, ViewQuery};
use bevy::render::sync_world::{MainEntity, RenderEntity};
use bevy::render::view::{ExtractedView, Msaa, ViewDepthStencilTexture, ViewTarget};
use bevy::render::{Extract, ExtractSchedule, Render, RenderApp, RenderSystems};
use lineao::glam as lg;
use lineao::passes::nd_from_depth::{HostNormals, check_inputs};
use lineao::{AoChain, Bounds, ChainSettings, FrameView, HostAo, HostConfig, HostInputs, LineGeometry, OverlayAo};

use crate::{LineAo, PolylineSelection, Polylines};

/// Where the plugin's systems run, to order others around them.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LineAoSystems {
    /// `Render`, in `RenderSystems::Prepare`: chains made, resized and given the frame's view.
    Prepare,
    /// `Core3d`, after the main pass and before post-processing: the passes recorded.
    Draw,
}

pub(crate) fn build(_app: &mut App) {}

pub(crate) fn finish(app: &mut App) {
    let Some(render_app) = app.get_sub_app_mut(RenderApp) else {
        return;
    };
    let adapter: &wgpu::Adapter = render_app.world().resource::<RenderAdapter>();
    if let Err(error) = lineao::check_adapter(adapter) {
        warn!("LineAoPlugin not loaded, cameras with LineAo render without it: {error}");
        return;
    }
    render_app
        .init_resource::<LineAoViews>()
        .init_resource::<RenderLines>()
        .add_systems(ExtractSchedule, (extract_cameras, extract_lines))
        .add_systems(Render, prepare.in_set(LineAoSystems::Prepare).in_set(RenderSystems::Prepare))
        .add_systems(
            Core3d,
            draw.in_set(LineAoSystems::Draw).after(Core3dSystems::MainPass).before(Core3dSystems::EarlyPostProcess),
        );
}

use lineao::wgpu;

/// A camera's [`LineAo`] for one frame, with what the camera has and the scene's bounds.
#[derive(Component, Clone)]
struct ExtractedLineAo {
    ao: LineAo,
    /// The union of the visible meshes' boxes (what the prepass holds), unless `ao.bounds`.
    mesh_bounds: Option<Bounds>,
    samples: u32,
    depth_prepass: bool,
    normal_prepass: bool,
    name: String,
}

fn extract_cameras(
    mut commands: Commands,
    cameras: Extract<
        Query<(
            Entity,
            RenderEntity,
            &Camera,
            Option<&LineAo>,
            Option<&Msaa>,
            Has<DepthPrepass>,
            Has<NormalPrepass>,
            Option<&Name>,
        )>,
    >,
    meshes: Extract<Query<(&Aabb, &GlobalTransform, &InheritedVisibility), Without<Polylines>>>,
) {
    let mut mesh_bounds = None;
    for (entity, render_entity, camera, ao, msaa, depth_prepass, normal_prepass, name) in &cameras {
        let Some(ao) = ao.filter(|_| camera.is_active) else {
            commands.entity(render_entity).remove::<ExtractedLineAo>();
            continue;
        };
        let bounds = match ao.bounds {
            Some(bounds) => Some(bounds),
            None => *mesh_bounds.get_or_insert_with(|| bounds_of_boxes(&meshes)),
        };
        commands.entity(render_entity).insert(ExtractedLineAo {
            ao: ao.clone(),
            mesh_bounds: bounds,
            samples: msaa.map_or(1, Msaa::samples),
            depth_prepass,
            normal_prepass,
            name: name.map_or_else(|| format!("{entity}"), |n| format!("{n} ({entity})")),
        });
    }
}

/// The sphere around the corners of every visible box, in world space.
fn bounds_of_boxes(
    boxes: &Query<(&Aabb, &GlobalTransform, &InheritedVisibility), Without<Polylines>>,
) -> Option<Bounds> {
    let corners: Vec<[f32; 3]> = boxes
        .iter()
        .filter(|(_, _, visible)| visible.get())
        .flat_map(|(aabb, transform, _)| {
            let (c, h) = (Vec3::from(aabb.center), Vec3::from(aabb.half_extents));
            (0..8).map(move |i| {
                let sign = Vec3::new([-1.0, 1.0][i & 1], [-1.0, 1.0][(i >> 1) & 1], [-1.0, 1.0][i >> 2]);
                transform.transform_point(c + sign * h).to_array()
            })
        })
        .collect();
    Bounds::of_points(&corners)
}

/// Every visible [`Polylines`] in world space: uploaded when it changed.
#[derive(Resource, Default)]
struct RenderLines {
    pending: Option<MergedLines>,
    /// The merged selection, when it changed (`None` inside: every polyline shown).
    pending_selection: Option<Option<Vec<bool>>>,
    geometry: Option<LineGeometry>,
    /// A load that failed, said once.
    error: Option<String>,
}

struct MergedLines {
    positions: Vec<[f32; 3]>,
    offsets: Vec<u64>,
    scalars: Option<Vec<f32>>,
}

fn extract_lines(
    mut lines: ResMut<RenderLines>,
    polylines: Extract<
        Query<(Entity, Ref<Polylines>, Ref<GlobalTransform>, &InheritedVisibility, Option<Ref<PolylineSelection>>)>,
    >,
    mut last: Local<(Vec<Entity>, Vec<bool>)>,
) {
    let visible: Vec<_> = polylines.iter().filter(|(_, _, _, v, _)| v.get()).collect();
    let entities: Vec<Entity> = visible.iter().map(|(e, ..)| *e).collect();
    // The selections: merged again when one changed, came or went (no upload of the points).
    let selected: Vec<bool> = visible.iter().map(|(.., s)| s.is_some()).collect();
    let selection_changed =
        selected != last.1 || visible.iter().any(|(.., s)| s.as_ref().is_some_and(|s| s.is_changed()));
    let changed = entities != last.0 || visible.iter().any(|(_, p, t, ..)| p.is_changed() || t.is_changed());
    if changed || selection_changed {
        lines.pending_selection =
            Some(merged_selection(&visible.iter().map(|(_, p, .., s)| (&**p, s.as_deref())).collect::<Vec<_>>()));
    }
    *last = (entities, selected);
    if !changed {
        return;
    }
    let points = visible.iter().map(|(_, p, ..)| p.positions().len()).sum();
    let mut merged = MergedLines {
        positions: Vec::with_capacity(points),
        offsets: vec![0],
        scalars: visible.iter().any(|(_, p, ..)| p.scalars().is_some()).then(|| Vec::with_capacity(points)),
    };
    for (_, polylines, transform, ..) in &visible {
        let base = merged.positions.len() as u64;
        let m = transform.affine();
        merged.positions.extend(polylines.positions().iter().map(|p| m.transform_point3(Vec3::from(*p)).to_array()));
        merged.offsets.extend(polylines.offsets()[1..].iter().map(|o| base + o));
        if let Some(scalars) = &mut merged.scalars {
            match polylines.scalars() {
                Some(s) => scalars.extend_from_slice(s),
                None => scalars.resize(merged.positions.len(), 0.0),
            }
        }
    }
    lines.pending = Some(merged);
}

/// One flag per merged polyline, or `None` where every one is shown. A selection whose count is
/// not its polylines' shows them all (and says so).
fn merged_selection(visible: &[(&Polylines, Option<&PolylineSelection>)]) -> Option<Vec<bool>> {
    visible.iter().any(|(_, s)| s.is_some()).then(|| {
        let mut keep = Vec::with_capacity(visible.iter().map(|(p, _)| p.len()).sum());
        for (polylines, selection) in visible {
            match selection {
                Some(PolylineSelection(flags)) if flags.len() == polylines.len() => keep.extend_from_slice(flags),
                Some(PolylineSelection(flags)) => {
                    warn!("a PolylineSelection of {} flags for {} polylines: all shown", flags.len(), polylines.len());
                    keep.resize(keep.len() + polylines.len(), true);
                }
                None => keep.resize(keep.len() + polylines.len(), true),
            }
        }
        keep
    })
}

/// Each camera's chains, by its main-world entity: what tools and tests read (the AO of the
/// last frame, its timing) after the frame.
#[derive(Resource, Default)]
pub struct LineAoViews {
    views: HashMap<Entity, ViewAo>,
}

impl LineAoViews {
    /// The chains of the camera `entity` (main world), once it has rendered with a [`LineAo`].
    pub fn get(&self, entity: Entity) -> Option<&ViewAo> {
        self.views.get(&entity)
    }

    /// Every camera's chains.
    pub fn iter(&self) -> impl Iterator<Item = &ViewAo> {
        self.views.values()
    }

    /// As [`LineAoViews::get`], to turn timing on ([`AoChain::set_timing`]).
    pub fn get_mut(&mut self, entity: Entity) -> Option<&mut ViewAo> {
        self.views.get_mut(&entity)
    }
}

/// One camera's chains: the meshes' AO over the prepass and the polylines' overlay.
pub struct ViewAo {
    meshes: Slot<HostAo>,
    lines: Slot<OverlayAo>,
    /// Whether each chain was prepared for this frame (else `draw` records nothing).
    meshes_ready: bool,
    lines_ready: bool,
    /// The camera's size in pixels, this frame.
    size: (u32, u32),
    name: String,
    /// Every warning already given for this camera: each is logged once.
    said: HashSet<String>,
}

impl ViewAo {
    /// The AO of the meshes (Bevy's prepass), once made.
    pub fn meshes(&self) -> Option<&HostAo> {
        self.meshes.pass.as_ref()
    }

    /// The meshes' chain, to turn timing on.
    pub fn meshes_mut(&mut self) -> Option<&mut HostAo> {
        self.meshes.pass.as_mut()
    }

    /// The polylines' overlay, once made.
    pub fn lines(&self) -> Option<&OverlayAo> {
        self.lines.pass.as_ref()
    }

    /// Every warning given for this camera so far (each also logged once): what a UI shows.
    pub fn warnings(&self) -> impl Iterator<Item = &str> {
        self.said.iter().map(String::as_str)
    }

    fn say(&mut self, message: String) {
        if self.said.insert(message.clone()) {
            warn!("LineAo on camera {}: {message}", self.name);
        }
    }
}

/// What [`HostAo`] and [`OverlayAo`] share: a chain inside.
trait Wrapped: Sized {
    fn chain(&self) -> &AoChain;
    fn chain_mut(&mut self) -> &mut AoChain;
}

impl Wrapped for HostAo {
    fn chain(&self) -> &AoChain {
        HostAo::chain(self)
    }
    fn chain_mut(&mut self) -> &mut AoChain {
        HostAo::chain_mut(self)
    }
}

impl Wrapped for OverlayAo {
    fn chain(&self) -> &AoChain {
        OverlayAo::chain(self)
    }
    fn chain_mut(&mut self) -> &mut AoChain {
        OverlayAo::chain_mut(self)
    }
}

/// A chain made for the target's format, following the component's settings and the size.
struct Slot<T> {
    pass: Option<T>,
    format: Option<wgpu::TextureFormat>,
    /// Settings lineao refused: not tried again until they change (the effect stays off).
    refused: Option<ChainSettings>,
}

impl<T> Default for Slot<T> {
    fn default() -> Self {
        Slot { pass: None, format: None, refused: None }
    }
}

impl<T: Wrapped> Slot<T> {
    /// The chain for `settings` at `size`, made (`make`) or updated; `Ok(None)` while these
    /// settings stay refused.
    fn update(
        &mut self,
        device: &wgpu::Device,
        format: wgpu::TextureFormat,
        settings: &ChainSettings,
        (width, height): (u32, u32),
        make: impl FnOnce(AoChain) -> Result<T, lineao::Error>,
    ) -> Result<Option<&mut T>, lineao::Error> {
        if self.refused.as_ref() == Some(settings) {
            return Ok(None);
        }
        let result = (|| {
            match &mut self.pass {
                Some(pass) if self.format == Some(format) => {
                    if pass.chain().settings() != settings {
                        pass.chain_mut().set_settings(device, settings.clone())?;
                    }
                }
                _ => {
                    self.pass = None;
                    self.pass = Some(make(AoChain::new(device, format, settings.clone())?)?);
                    self.format = Some(format);
                }
            }
            self.pass.as_mut().expect("made above").chain_mut().resize(width, height)
        })();
        match result {
            Ok(()) => {
                self.refused = None;
                Ok(self.pass.as_mut())
            }
            Err(error) => {
                self.refused = Some(settings.clone());
                Err(error)
            }
        }
    }
}

/// Bevy's matrices in lineao's glam (Bevy 0.20 is on glam 0.33, lineao on 0.34).
fn mat4(m: Mat4) -> lg::Mat4 {
    lg::Mat4::from_cols_array(&m.to_cols_array())
}

/// The lineao camera Bevy's view and projection describe (lineao makes its own projection for
/// its G-buffer, with the guard band; the overlay writes depth by Bevy's `proj`).
fn lineao_camera(view: &ExtractedView) -> lineao::Camera {
    let m = view.world_from_view.affine();
    let eye = lg::Vec3::from_array(m.translation.to_array());
    let forward = lg::Vec3::from_array((-m.matrix3.z_axis).normalize().to_array());
    let up = lg::Vec3::from_array(m.matrix3.y_axis.normalize().to_array());
    let proj = view.clip_from_view;
    let projection = if proj.w_axis.w == 1.0 {
        lineao::Projection::Orthographic { height: 2.0 / proj.y_axis.y }
    } else {
        lineao::Projection::Perspective { fov_y_deg: (2.0 * (1.0 / proj.y_axis.y).atan()).to_degrees() }
    };
    lineao::Camera { eye, target: eye + forward, up, projection }
}

/// The merged polylines on the GPU, with their scalars.
fn upload(device: &wgpu::Device, queue: &wgpu::Queue, merged: &MergedLines) -> Result<LineGeometry, lineao::Error> {
    let mut geometry = LineGeometry::new(device, queue, &merged.positions, &merged.offsets)?;
    if let Some(scalars) = &merged.scalars {
        let attributes = lineao::passes::lines::VertexAttributes { scalar: Some(scalars), ..Default::default() };
        geometry.set_attributes(device, queue, &attributes)?;
    }
    Ok(geometry)
}

fn prepare(
    mut views: ResMut<LineAoViews>,
    mut lines: ResMut<RenderLines>,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
    cameras: Query<(&MainEntity, &ExtractedLineAo, &ExtractedView, &ExtractedCamera, &ViewTarget)>,
) {
    let (device, queue): (&wgpu::Device, &wgpu::Queue) = (device.wgpu_device(), &queue);
    if let Some(merged) = lines.pending.take() {
        // No visible polylines (all removed or hidden): nothing to draw, nothing to say.
        let made = (!merged.positions.is_empty()).then(|| upload(device, queue, &merged)).transpose();
        match made {
            Ok(geometry) => (lines.geometry, lines.error) = (geometry.filter(|g| g.bounds.is_some()), None),
            Err(error) => {
                lines.geometry = None;
                let error = error.to_string();
                if lines.error.as_ref() != Some(&error) {
                    warn!("Polylines not drawn: {error}");
                }
                lines.error = Some(error);
            }
        }
    }
    // The selection, on the GPU (a bit per cluster; the points stay).
    if let Some(selection) = lines.pending_selection.take()
        && let Some(geometry) = &mut lines.geometry
        && let Err(error) = geometry.set_selection(device, queue, selection.as_deref())
    {
        warn!("PolylineSelection not applied: {error}");
    }
    let mut seen = HashSet::new();
    for (main, extracted, view, camera, target) in &cameras {
        let main = main.id();
        seen.insert(main);
        let state = views.views.entry(main).or_insert_with(|| ViewAo {
            meshes: Slot::default(),
            lines: Slot::default(),
            meshes_ready: false,
            lines_ready: false,
            size: (0, 0),
            name: extracted.name.clone(),
            said: HashSet::new(),
        });
        (state.meshes_ready, state.lines_ready) = (false, false);
        let Some(size) = camera.physical_viewport_size.map(|s| (s.x, s.y)).filter(|&(w, h)| w > 0 && h > 0) else {
            continue; // minimised: nothing recorded
        };
        state.size = size;
        if camera.viewport.as_ref().is_some_and(|v| Some(v.physical_size) != camera.physical_target_size) {
            state.say("a camera viewport smaller than its target is not supported yet: no AO".into());
            continue;
        }
        let format = target.main_texture_format();
        let ao = &extracted.ao;
        let (view_matrix, proj) = (mat4(view.world_from_view.to_matrix().inverse()), mat4(view.clip_from_view));

        // The meshes: HostAo over the prepass.
        if !extracted.depth_prepass {
            state.say("the camera has no DepthPrepass: add DepthPrepass (and NormalPrepass) to it for AO".into());
        } else if let Some(bounds) = extracted.mesh_bounds {
            let config = HostConfig {
                depth_samples: extracted.samples,
                reversed_z: true,
                // With MSAA the normal prepass is multisampled: lineao reconstructs normals from
                // the depth then.
                normals: (extracted.normal_prepass && extracted.samples == 1)
                    .then_some(HostNormals { world_space: true, unorm: true }),
            };
            let made =
                state.meshes.update(device, format, &ao.settings, size, |chain| HostAo::new(device, chain, config));
            let prepared = made.and_then(|host| {
                let Some(host) = host else { return Ok(false) };
                host.set_config(device, config)?;
                let frame = FrameView::from_matrices(view_matrix, proj, size.0, size.1, &bounds);
                Ok(host.prepare(device, queue, frame)?.is_some())
            });
            match prepared {
                Ok(ready) => state.meshes_ready = ready,
                Err(error) => state.say(format!("the meshes' AO is off: {error}")),
            }
        }

        // The polylines: OverlayAo drawing into the main texture and depth.
        let Some(geometry) = &lines.geometry else { continue };
        if extracted.samples != 1 {
            state.say(format!(
                "Polylines need Msaa::Off on the camera (it has {} samples): not drawn",
                extracted.samples
            ));
            continue;
        }
        let bounds = ao.bounds.or(geometry.bounds).expect("geometry without bounds is dropped above");
        let depth = Some(lineao::OverlayDepth { format: wgpu::TextureFormat::Depth32Float, proj });
        let made = state.lines.update(device, format, &ao.lines, size, |chain| OverlayAo::new(device, chain, depth));
        let prepared = made.and_then(|overlay| {
            let Some(overlay) = overlay else { return Ok(false) };
            overlay.set_depth(device, depth)?;
            Ok(overlay.chain_mut().prepare(device, queue, &lineao_camera(view), &bounds).is_some())
        });
        match prepared {
            Ok(ready) => state.lines_ready = ready,
            Err(error) => state.say(format!("the polylines are not drawn: {error}")),
        }
    }
    views.views.retain(|entity, _| seen.contains(entity));
}

fn draw(
    view: ViewQuery<(&MainEntity, &ViewTarget, Option<&ViewPrepassTextures>, Option<&ViewDepthStencilTexture>)>,
    mut views: ResMut<LineAoViews>,
    lines: Res<RenderLines>,
    mut ctx: RenderContext,
) {
    let (main, target, prepass, depth) = view.into_inner();
    let Some(state) = views.views.get_mut(&main.id()) else { return };
    let device = ctx.render_device().wgpu_device().clone();

    if let (true, Some(host)) = (state.meshes_ready, &state.meshes.pass) {
        let config = host.config();
        let depth = prepass.and_then(ViewPrepassTextures::depth_only_view);
        let normals = prepass.and_then(ViewPrepassTextures::normal_view);
        let result = match depth {
            None => Err(lineao::Error::Usage(lineao::Misuse::Missing {
                input: "the prepass depth",
                fix: "add DepthPrepass to the camera",
            })),
            Some(depth) => {
                let normals = config.normals.and(normals.map(|n| &**n));
                let inputs = HostInputs { depth, normals, color: Some(target.main_texture_view()) };
                // Checked before taking the post-process pair: once taken, the destination
                // must be written.
                check_inputs(&config, &inputs, state.size).and_then(|()| {
                    let post = target.post_process_write();
                    let inputs = HostInputs { color: Some(post.source), ..inputs };
                    host.encode(&device, ctx.command_encoder(), &inputs, Some(post.destination))
                })
            }
        };
        if let Err(error) = result {
            state.say(format!("the meshes' AO is off: {error}"));
        }
    }

    if let (true, Some(overlay), Some(geometry), Some(depth)) =
        (state.lines_ready, &state.lines.pass, &lines.geometry, depth)
    {
        let depth = &depth.attachment.texture.default_view;
        // A command buffer of their own (after the meshes' one, in order): each chain opens a
        // `lineao` debug label, and Mesa's Vulkan drivers (lavapipe here, as Intel's in
        // ash-rs/ash#700) crash in vkCmdBeginDebugUtilsLabelEXT on a second label in one
        // command buffer, which Bevy's debug builds (wgpu's DEBUG flag) record.
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("lineao_bevy::lines") });
        match overlay.encode(&mut encoder, geometry, &[], target.main_texture_view(), Some(depth)) {
            Ok(()) => ctx.add_command_buffer(encoder.finish()),
            Err(error) => state.say(format!("the polylines are not drawn: {error}")),
        }
    }
}
