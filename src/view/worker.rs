//! The viewer's render thread. It owns its own wgpu device (not the window's): one lavapipe frame
//! of 11 M vertices takes seconds, and a queue runs its work in order, so on the window's queue a
//! long LineAO submission would hold up every window frame behind it. Here the window keeps
//! drawing and answering input while frames render; finished frames come back as RGBA images.
//!
//! Requests are coalesced: only the newest view is rendered. A load opens its source as it
//! arrives ([`super::loading`]): each step reads and uploads a little, and the newest view is
//! drawn again whenever more of the data is on the GPU, so the first picture comes within a
//! second whatever the file's size and the window stays interactive.
//! While the camera moves the app asks for *preview* frames: every k-th streamline (at most
//! [`PREVIEW_VERTICES`] vertices) at half resolution — visibly coarser, and replaced by the full
//! frame as soon as the camera rests.
//!
//! **Progressive frames.** A view with the ray-traced method is a picture that gets better with
//! each frame: while nothing new is asked, the worker renders the same view again (each frame
//! adds `rays_per_frame` rays per pixel) and sends every frame, until each ray-traced panel has
//! its `max_rays`. Any request ends it; the app asks for the view again (restarting the picture)
//! when the camera or a setting changes. The ray tracer's scene (its BVH) is built once per
//! dataset, on first use.
//!
//! **In a web page** there are no threads and one device, the page's: the app steps a
//! [`Worker`] itself once per UI frame ([`Output::Textures`]), and frames stay on the GPU in
//! textures the window's renderer draws, since reading one back would wait on the page.

use std::sync::Arc;
#[cfg(not(target_arch = "wasm32"))]
use std::sync::mpsc::{Receiver, Sender, TryRecvError};

use lineao::Camera;
use lineao::method::raytraced::RayProgress;
use lineao::passes::lines::VertexAttributes;
use lineao::timing::PassTime;
use lineao::volume::VolumeAoOptions;
use lineao::{AoChain, AoMethod, ChainSettings, Gpu, LineColor, RayScene, SliceVolume};
use lineao_tracts::ViewHint;

use super::loading::{Opening, PREVIEW_VERTICES, Preview, SceneRef, Selected, Step};
pub use crate::source::Source;
use crate::source::{AttributeKey, FrameScene, Lines, Sampled};

/// One image of a frame: the chain's settings, and the object-space AO it needs.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    pub settings: ChainSettings,
    pub volume: Option<VolumeAoOptions>,
}

/// A frame to render.
#[derive(Clone, Debug, PartialEq)]
pub struct View {
    /// Pixels of the full-detail image.
    pub size: (u32, u32),
    pub camera: Camera,
    /// One panel, or two (the split screen).
    pub panels: Vec<Panel>,
    pub preview: bool,
    pub timings: bool,
    /// The per-vertex field colored by [`LineColor::Scalar`], if any.
    pub scalar_field: Option<String>,
    /// The streamlines shown: the subset and length rules (`lineao_tracts::Selection`), which
    /// the lengths kept on the CPU decide.
    pub selection: lineao_tracts::Selection,
}

pub enum ToWorker {
    /// Open a source, sampling a volume at its vertices where one is given, judging each
    /// streamline by include and exclude regions (a selection of them alone) as it arrives.
    Load(Source, Option<Arc<Sampled>>, lineao_tracts::Selection),
    /// The anatomy whose slices are shown (`--volume`, a volume opened or dropped), or none:
    /// it stays on the GPU across datasets, and the newest view is drawn again with it.
    Anatomy(Option<Arc<lineao_tracts::Volume>>),
    /// Values for the dataset shown or arriving (a .tsf opened beside it), a field to colour
    /// by: for what has arrived at once, for the rest as it arrives.
    Values(Arc<Sampled>),
    Render(View),
}

/// What the app learns about a loaded dataset: first when part of it is on screen, then when
/// all of it is (`complete`).
#[derive(Clone, Debug)]
pub struct Dataset {
    pub name: String,
    pub streamlines: usize,
    pub vertices: usize,
    /// Whether the whole dataset is loaded (else what has arrived).
    pub complete: bool,
    /// Whether its source can be read again for the points (a file read as it arrived past
    /// what its page keeps cannot: the methods that work on the CPU are then unavailable).
    pub readable: bool,
    pub hint: ViewHint,
    /// One-column per-vertex fields, with their 2nd–98th percentile ranges.
    pub fields: Vec<(String, [f32; 2])>,
    /// One-column per-streamline fields (.trk properties, TRX dps), with their smallest and
    /// largest finite values: what the side panel selects by.
    pub streamline_fields: Vec<(String, [f32; 2])>,
    /// The names of its groups (TRX), in the file's order: the colours of
    /// [`lineao::Colormap::Categories`] in turn.
    pub groups: Vec<String>,
    /// The longest streamline's arc length (world units).
    pub max_length: f32,
    /// Milliseconds to the first picture's data on the GPU, and to all of it.
    pub first_ms: f64,
    pub load_ms: f64,
}

/// Where a worker's frames go.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Output {
    /// Read back into RGBA images: the native window's render thread, on a device of its own.
    Readback,
    /// Left on the GPU in one texture per panel, which the window's renderer samples: the web
    /// page, whose device is the window's.
    Textures,
}

/// A rendered frame.
pub struct Frame {
    pub view: View,
    /// RGBA8 (sRGB) per panel, `size` each ([`Output::Readback`]).
    pub images: Vec<Vec<u8>>,
    /// The panels' Rgba8UnormSrgb textures ([`Output::Textures`]).
    pub textures: Vec<wgpu::TextureView>,
    pub size: (u32, u32),
    pub times: Vec<Option<Vec<PassTime>>>,
    /// Per panel: how far its ray-traced picture is (`None`: another method).
    pub rays: Vec<Option<RayStatus>>,
    pub render_ms: f64,
    /// The streamlines selected and all of them, where a rule leaves some out.
    pub selected: Option<(usize, usize)>,
}

impl Frame {
    /// Whether every ray-traced panel has all its rays (other methods are complete at once).
    pub fn converged(&self) -> bool {
        self.rays.iter().flatten().all(|r| r.progress.converged())
    }
}

/// A ray-traced panel's picture after a frame.
#[derive(Clone, Copy, Debug)]
pub struct RayStatus {
    pub progress: RayProgress,
    /// Rays traced by the frame (its geometry pixels, guard band included, times the frame's
    /// rays per pixel) per second of the render thread's wall clock for the panel: recording,
    /// the GPU's work and reading the image back. `None` where frames are not read back
    /// ([`Output::Textures`]): the wall clock then sees only the recording.
    pub rays_per_second: Option<f64>,
}

pub enum FromWorker {
    /// Loading: bytes read of the total, when known.
    Progress {
        bytes: u64,
        total: Option<u64>,
    },
    Loaded(Dataset),
    /// The dataset's per-vertex fields changed ([`ToWorker::Values`]): all of them, as in
    /// [`Dataset::fields`].
    Fields(Vec<(String, [f32; 2])>),
    Frame(Box<Frame>),
    /// Something takes a while (computing object-space AO).
    Busy(String),
    /// The GPU times of the frame on screen, per panel ([`Output::Textures`], which reads them
    /// once the GPU has finished the frame, never waiting).
    Times(Vec<Option<Vec<PassTime>>>),
    Error(String),
}

/// The loaded data on the GPU: full detail and the preview's subset.
struct Scene {
    /// Full detail, with its attributes and object-space AO.
    lines: Lines,
    preview: Preview,
    /// The ray tracer's scene of the full detail, built when a panel first traces rays.
    rays: Option<Arc<RayScene>>,
    /// Where the lines came from: read again for their points where a method needs them.
    source: Source,
    /// The selection on the GPU ([`SceneRef::selected`]).
    selected: Option<Selected>,
}

/// A panel's chain and the geometry pixels of its ray-traced picture.
struct PanelChain {
    chain: AoChain,
    /// Geometry pixels of the ray-traced picture in progress (counted on its first frame).
    geometry_pixels: usize,
}

/// The renderer behind the viewer: the loaded dataset on the GPU, a chain per panel, and the
/// picture in progress. The native app runs it on its render thread ([`run`]); the web page
/// steps it on its own thread.
pub struct Worker {
    gpu: Gpu,
    output: Output,
    scene: Option<Scene>,
    /// A dataset being opened, drawn as it arrives.
    opening: Option<Opening>,
    /// Whether the app was told of the dataset being opened.
    announced: bool,
    /// The newest view asked for, drawn again as more of a dataset arrives.
    last_view: Option<View>,
    chains: Vec<PanelChain>,
    /// [`Output::Textures`]: each panel's texture.
    textures: Vec<lineao::targets::Target>,
    /// A view whose ray-traced picture is still accumulating: rendered again while nothing new
    /// is asked.
    continuing: Option<View>,
    /// [`Output::Textures`] with timings: the frame whose GPU times are awaited.
    timing: Option<Timing>,
    /// The anatomy the slices show, as loaded and on the GPU.
    anatomy: Option<(Arc<lineao_tracts::Volume>, Arc<SliceVolume>)>,
}

/// A frame whose GPU times are awaited, and how often its view was rendered again for them.
struct Timing {
    view: View,
    repeats: u32,
    /// Per panel, once read.
    times: Vec<Option<Vec<PassTime>>>,
}

/// Where times are read without waiting ([`Output::Textures`]), a view with timings is rendered
/// this many times again once the previous frame's times are in: the times shown are then a
/// frame's after the first, whose pipelines were new.
pub const TIMED_REPEATS: u32 = 3;

impl Worker {
    pub fn new(gpu: Gpu, output: Output) -> Worker {
        Worker {
            gpu,
            output,
            scene: None,
            opening: None,
            announced: false,
            last_view: None,
            chains: Vec::new(),
            textures: Vec::new(),
            continuing: None,
            timing: None,
            anatomy: None,
        }
    }

    pub fn gpu(&self) -> &Gpu {
        &self.gpu
    }

    /// Shows `anatomy`'s slices from now on (uploaded once, whatever the datasets); whether it
    /// changed. One that the GPU refuses is said, and the lines are shown without slices.
    fn set_anatomy(&mut self, anatomy: Option<&Arc<lineao_tracts::Volume>>, send: &dyn Fn(FromWorker)) -> bool {
        if same(anatomy, self.anatomy.as_ref().map(|(held, _)| held)) {
            return false;
        }
        self.anatomy = None;
        if let Some(volume) = anatomy {
            let dims = volume.dims.map(|d| d as u32);
            let (d, q) = (&self.gpu.device, &self.gpu.queue);
            match SliceVolume::new(d, q, dims, &volume.values, volume.affine.as_mat4()) {
                Ok(slices) => self.anatomy = Some((volume.clone(), Arc::new(slices))),
                Err(e) => send(FromWorker::Error(format!("the anatomy's volume: {e}"))),
            }
        }
        true
    }

    /// Whether a picture is still accumulating, a dataset still arriving, or a frame's times
    /// are awaited (so a step has work without commands).
    pub fn continuing(&self) -> bool {
        self.continuing.is_some() || self.timing.is_some() || self.opening.is_some()
    }

    /// Reads the awaited frame's times without waiting; `true` once every panel's are in (or
    /// the device has no timestamp queries).
    fn poll_times(&mut self) -> bool {
        let Some(timing) = &mut self.timing else { return true };
        if !self.gpu.device.features().contains(wgpu::Features::TIMESTAMP_QUERY) {
            return true;
        }
        timing.times.resize(timing.view.panels.len(), None);
        for (slot, panel) in timing.times.iter_mut().zip(&self.chains) {
            if slot.is_none() {
                *slot = panel.chain.pass_times(&self.gpu.device, false).ok().flatten();
            }
        }
        timing.times.iter().all(Option::is_some)
    }

    /// The chain of `panel`, as the last frame left it.
    pub fn chain(&self, panel: usize) -> Option<&AoChain> {
        self.chains.get(panel).map(|p| &p.chain)
    }

    /// [`Worker::step_async`], blocking on it: the render thread's (native wgpu answers its
    /// validation scopes at once).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn step(&mut self, pending: Vec<ToWorker>, send: &dyn Fn(FromWorker)) {
        pollster::block_on(self.step_async(pending, send));
    }

    /// Does what `pending` asks — every load in order, then the newest render asked after the
    /// last load — or, with nothing pending, the next frame of the picture in progress. A
    /// future: a web page's device answers validation scopes only once the page's event loop
    /// runs, so the page awaits it where the native worker blocks.
    pub async fn step_async(&mut self, mut pending: Vec<ToWorker>, send: &dyn Fn(FromWorker)) {
        // Nothing asked: the awaited times, then (a few times) the same view again.
        let mut repeats = 0;
        if pending.is_empty() && self.continuing.is_none() && self.opening.is_none() {
            if !self.poll_times() {
                return;
            }
            let Some(timing) = self.timing.take() else { return };
            send(FromWorker::Times(timing.times));
            if timing.repeats >= TIMED_REPEATS {
                return;
            }
            repeats = timing.repeats + 1;
            pending.push(ToWorker::Render(timing.view));
        }
        // The newest anatomy asked for (in a web page a volume arrives while a dataset does).
        let mut redraw = false;
        if let Some(ToWorker::Anatomy(anatomy)) = pending.iter().rfind(|c| matches!(c, ToWorker::Anatomy(_))) {
            redraw = self.set_anatomy(anatomy.as_ref(), send);
        }
        pending.retain(|c| !matches!(c, ToWorker::Anatomy(_)));
        // Values asked after the last load: for the dataset it opens, else the one there.
        let last_load = pending.iter().rposition(|c| matches!(c, ToWorker::Load(..)));
        let values: Vec<Arc<Sampled>> = (pending.iter().enumerate())
            .filter(|&(k, _)| last_load.is_none_or(|l| k > l))
            .filter_map(|(_, c)| if let ToWorker::Values(sampled) = c { Some(sampled.clone()) } else { None })
            .collect();
        pending.retain(|c| !matches!(c, ToWorker::Values(_)));
        let gpu = &self.gpu;
        let last_load = pending.iter().rposition(|c| matches!(c, ToWorker::Load(..)));
        let render =
            pending.iter().rposition(|c| matches!(c, ToWorker::Render(_))).filter(|&r| last_load.is_none_or(|l| r > l));
        if let Some(l) = last_load {
            let ToWorker::Load(source, sampled, regions) = &pending[l] else { unreachable!() };
            (self.scene, self.continuing, self.opening, self.announced) = (None, None, None, false);
            for panel in &mut self.chains {
                // The old dataset's BVH is freed now, not when the next one replaces it.
                panel.chain.set_ray_scene(&gpu.device, None);
            }
            match Opening::start(source.clone(), sampled.clone(), regions.clone(), gpu) {
                Ok(opening) => self.opening = Some(opening),
                Err(e) => send(FromWorker::Error(e)),
            }
        }
        for sampled in values {
            // A volume is sampled at the points: those of a tractogram streamed without them
            // are read again once it is whole (as for regions); one still arriving is too soon.
            let volume = !sampled.is_for_one_tractogram();
            let (lines, complete) = match (&mut self.scene, &mut self.opening) {
                (_, Some(opening)) if volume && !opening.lines.points_kept() => {
                    let name = &opening.lines.name;
                    send(FromWorker::Error(format!(
                        "{}: a volume colours {name} once it has arrived whole; it is still arriving",
                        sampled.field
                    )));
                    continue;
                }
                (_, Some(opening)) => (&mut opening.lines, false),
                (Some(scene), None) if volume && !scene.lines.points_kept() => {
                    send(FromWorker::Busy(format!("reading {} again for its points (a volume) …", scene.lines.name)));
                    if let Err(e) = scene.lines.load_points(&scene.source) {
                        send(FromWorker::Error(format!("{e:#}")));
                        continue;
                    }
                    (&mut scene.lines, true)
                }
                (Some(scene), None) => (&mut scene.lines, true),
                (None, None) => {
                    send(FromWorker::Error(format!("{}: no tractogram is open to colour", sampled.field)));
                    continue;
                }
            };
            match lines.add_values(sampled, complete) {
                Ok(()) => send(FromWorker::Fields(vertex_fields(lines))),
                Err(e) => send(FromWorker::Error(format!("{e:#}"))),
            }
            redraw = true;
        }
        // A dataset arriving: a step of reading, and once part of it is on the GPU, the newest
        // view drawn again.
        let mut more = false;
        if let Some(opening) = &mut self.opening {
            send(FromWorker::Progress { bytes: opening.progress.0, total: opening.progress.1 });
            // The GPU's memory is the limit of what arrives: a page's device says so only to an
            // error scope, which it answers once the page's event loop runs.
            let scope = gpu.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
            let stepped = match opening.step(gpu) {
                Ok(Step::Read) => opening.finish(gpu).await.map(|()| Step::Read),
                other => other,
            };
            let stepped = match scope.pop().await {
                None => stepped,
                Some(error) => Err(format!(
                    "{}: the GPU's memory is full after {} points ({} MB of lines on the GPU): {error}",
                    opening.lines.name,
                    opening.lines.geometry.vertices,
                    opening.lines.geometry.gpu_bytes() >> 20
                )),
            };
            match stepped {
                Ok(Step::Reading { drawn }) => {
                    if drawn && !self.announced {
                        self.announced = true;
                        send(FromWorker::Loaded(dataset(&opening.lines, opening, false)));
                    }
                    more = drawn;
                }
                Ok(Step::Read) => {
                    let opening = self.opening.take().expect("opening");
                    send(FromWorker::Loaded(dataset(&opening.lines, &opening, true)));
                    let (lines, preview, source) = opening.into_parts();
                    self.scene = Some(Scene { lines, preview, rays: None, source, selected: None });
                    more = true;
                }
                Err(e) => {
                    // All that arrived before the error goes on screen and stays (the file's
                    // error is shown beside it), drawn already or not: a file shorter than a
                    // page that fails within the first step's reading has drawn nothing yet, and
                    // the chunks decoded in the read that failed wait to be appended. The counts
                    // are its counts; a flush that fails, the GPU's memory full, leaves what was
                    // drawn, if anything was.
                    let mut opening = self.opening.take().expect("opening");
                    let _ = opening.flush_arrived(gpu);
                    if opening.drawn() {
                        send(FromWorker::Loaded(dataset(&opening.lines, &opening, false)));
                        let (lines, preview, source) = opening.into_parts();
                        self.scene = Some(Scene { lines, preview, rays: None, source, selected: None });
                    }
                    send(FromWorker::Error(e));
                }
            }
        }
        let view = match render {
            Some(r) => {
                let ToWorker::Render(view) = pending.swap_remove(r) else { unreachable!() };
                self.timing = None;
                self.last_view = Some(view.clone());
                Some(view)
            }
            None if pending.is_empty() && (more || redraw) => self.last_view.clone(),
            None if pending.is_empty() => self.continuing.take(),
            None => None,
        };
        // While a dataset arrives its frames are previews (every k-th streamline of what has
        // arrived, at half resolution): a frame of all of it would cost more than reading it.
        let view = match (view, self.opening.is_some()) {
            (Some(view), true) => Some(View { preview: true, ..view }),
            (view, _) => view,
        };
        let scene = match (&mut self.scene, &mut self.opening) {
            (Some(scene), _) => Some(SceneRef {
                lines: &mut scene.lines,
                preview: &mut scene.preview,
                rays: &mut scene.rays,
                source: &scene.source,
                opening: false,
                selected: &mut scene.selected,
            }),
            (None, Some(opening)) if opening.drawn() => Some(opening.scene()),
            _ => None,
        };
        if let (Some(view), Some(scene)) = (view, scene) {
            self.continuing = None;
            let outputs = (self.output, &mut self.textures);
            let anatomy = self.anatomy.as_ref().map(|(_, slices)| slices.clone());
            match render_frame(gpu, scene, &mut self.chains, outputs, (&view, anatomy), send).await {
                Ok(frame) => {
                    if self.output == Output::Textures && view.timings {
                        self.timing = Some(Timing { view: view.clone(), repeats, times: Vec::new() });
                    }
                    if !frame.converged() {
                        self.continuing = Some(view);
                    }
                    send(FromWorker::Frame(Box::new(frame)));
                }
                Err(e) => send(FromWorker::Error(e)),
            }
            // A lost device ends the picture with its reason, never a panic.
            if let Some(why) = gpu.lost() {
                self.continuing = None;
                send(FromWorker::Error(format!("the GPU device was lost: {why}")));
            }
        }
    }
}

/// Runs a worker on its own device until the app's sender is dropped. `repaint` asks the window
/// for a frame when something arrives.
#[cfg(not(target_arch = "wasm32"))]
pub fn run(rx: Receiver<ToWorker>, tx: Sender<FromWorker>, repaint: impl Fn() + Send + 'static) {
    let send = |message: FromWorker| {
        let _ = tx.send(message);
        repaint();
    };
    let mut worker = match Gpu::headless() {
        Ok(gpu) => Worker::new(gpu, Output::Readback),
        Err(e) => {
            send(FromWorker::Error(e.to_string()));
            return;
        }
    };
    loop {
        // The next command (or none, to continue a picture), then whatever else is waiting.
        let mut pending = Vec::new();
        if !worker.continuing() {
            let Ok(first) = rx.recv() else { return };
            pending.push(first);
        }
        loop {
            match rx.try_recv() {
                Ok(command) => pending.push(command),
                Err(TryRecvError::Empty) => break,
                Err(TryRecvError::Disconnected) => return,
            }
        }
        worker.step(pending, &send);
    }
}

/// `lines`' one-column per-vertex fields with their 2nd–98th percentile ranges: what the app
/// colours by.
fn vertex_fields(lines: &Lines) -> Vec<(String, [f32; 2])> {
    let fields = lines.tracts.vertex_fields.iter();
    let shown = fields.filter(|f| f.columns == 1 && f.name != crate::args::GROUP_FIELD);
    shown.map(|f| (f.name.clone(), crate::render::percentile_range(&f.values))).collect()
}

/// What the app is told of `lines`, being opened (`complete`: all of it is on the GPU).
fn dataset(lines: &Lines, opening: &Opening, complete: bool) -> Dataset {
    let fields = vertex_fields(lines);
    let (streamlines, vertices) = (lines.geometry.streamlines, lines.geometry.vertices);
    // While the data arrives, a camera that frames what has arrived.
    let hint = match complete {
        true => lines.hint,
        false => {
            let bounds = lines.geometry.bounds.expect("part of it is on the GPU");
            ViewHint::for_sphere(bounds.center.to_array(), bounds.radius)
        }
    };
    let elapsed = opening.started.elapsed().as_secs_f64() * 1e3;
    Dataset {
        name: lines.name.clone(),
        streamlines,
        vertices,
        complete,
        readable: opening.held,
        hint,
        fields,
        groups: lines.tracts.groups.iter().map(|g| g.name.clone()).collect(),
        streamline_fields: lines
            .tracts
            .streamline_fields
            .iter()
            .filter(|f| f.columns == 1)
            .map(|f| {
                let finite = f.values.iter().copied().filter(|v| v.is_finite());
                let range = finite.fold([f32::INFINITY, f32::NEG_INFINITY], |[lo, hi], v| [lo.min(v), hi.max(v)]);
                (f.name.clone(), if range[0] <= range[1] { range } else { [0.0, 0.0] })
            })
            .collect(),
        max_length: lines.lengths.iter().copied().fold(0.0, f32::max),
        first_ms: opening.first_ms().unwrap_or(elapsed),
        load_ms: elapsed,
    }
}

/// Whether both are the same allocation, or both none.
fn same<T>(a: Option<&Arc<T>>, b: Option<&Arc<T>>) -> bool {
    match (a, b) {
        (Some(a), Some(b)) => Arc::ptr_eq(a, b),
        (a, b) => a.is_none() && b.is_none(),
    }
}

/// Selects on the GPU (full detail and preview) what `selection` keeps, where it or the
/// streamlines changed since the scene was last selected: a bit per cluster, no geometry.
/// Regions need every point: the regions the file was opened with were judged as it arrived
/// ([`Lines::judged`]); others are judged by reading the file again (the first time, busy
/// meanwhile) once all of it has arrived, and while it arrives they wait.
fn select(
    gpu: &Gpu,
    scene: &mut SceneRef<'_>,
    selection: &lineao_tracts::Selection,
    send: &dyn Fn(FromWorker),
) -> Result<(), String> {
    let lines = &mut *scene.lines;
    let count = lines.lengths.len();
    if scene.selected.as_ref().is_some_and(|s| s.selection == *selection && s.streamlines == count) {
        return Ok(());
    }
    let mut kept = None;
    let (d, q) = (&gpu.device, &gpu.queue);
    let name = lines.name.clone();
    let error = |e: lineao::Error| format!("{name}: {e}");
    if selection.is_everything() {
        lines.geometry.set_selection(d, q, None).map_err(error)?;
        scene.preview.geometry.set_selection(d, q, None).map_err(error)?;
    } else if count == lines.geometry.streamlines {
        let rule = |e: lineao_tracts::selection::SelectionError| format!("{name}: {e}");
        let mut keep: Vec<bool> =
            lines.lengths.iter().enumerate().map(|(i, &l)| selection.keeps(i as u64, l)).collect();
        selection.apply_field(&mut keep, &lines.tracts).map_err(rule)?;
        let regions = selection.regions();
        let judged = lines.judged().filter(|(by, verdicts)| **by == regions && verdicts.len() == count);
        if let Some((_, verdicts)) = judged {
            keep.iter_mut().zip(verdicts).for_each(|(kept, passes)| *kept &= passes);
        } else if !regions.is_everything() && !scene.opening {
            if !lines.points_kept() {
                send(FromWorker::Busy(format!("reading {name} again for its points (regions) …")));
                lines.load_points(scene.source).map_err(|e| format!("{e:#}"))?;
            }
            selection.apply_regions(&mut keep, &lines.tracts);
        }
        selection.apply_groups(&mut keep, &lines.tracts.groups).map_err(rule)?;
        lines.geometry.set_selection(d, q, Some(&keep)).map_err(error)?;
        kept = Some(keep.iter().filter(|&&k| k).count());
        // The preview holds every k-th streamline.
        let shown = scene.preview.geometry.streamlines;
        let every = count.div_ceil(shown.max(1)).max(1);
        let preview: Vec<bool> = (0..shown).map(|j| keep.get(j * every).copied().unwrap_or(true)).collect();
        scene.preview.geometry.set_selection(d, q, Some(&preview)).map_err(error)?;
    }
    *scene.selected = Some(Selected { selection: selection.clone(), streamlines: count, kept });
    Ok(())
}

async fn render_frame(
    gpu: &Gpu,
    mut scene: SceneRef<'_>,
    chains: &mut Vec<PanelChain>,
    (output, textures): (Output, &mut Vec<lineao::targets::Target>),
    (view, anatomy): (&View, Option<Arc<SliceVolume>>),
    send: &dyn Fn(FromWorker),
) -> Result<Frame, String> {
    let start = web_time::Instant::now();
    let (d, q) = (&gpu.device, &gpu.queue);
    let preview = view.preview && scene.lines.geometry.vertices > PREVIEW_VERTICES;
    let size = if preview { ((view.size.0 / 2).max(1), (view.size.1 / 2).max(1)) } else { view.size };
    let bounds = scene.lines.geometry.bounds.expect("checked at load");
    select(gpu, &mut scene, &view.selection, send)?;
    // The anatomy's slices are framed with the lines.
    let slices = view.panels.first().and_then(|p| p.settings.slices.as_ref());
    let slice_bounds = anatomy.as_ref().zip(slices).and_then(|(volume, slices)| volume.slice_bounds(slices));
    let bounds = slice_bounds.map_or(bounds, |s| bounds.union(&s));
    let format = wgpu::TextureFormat::Rgba8UnormSrgb;
    let readback = output == Output::Readback;
    let target = match output {
        Output::Readback => Some(lineao::targets::Target::output(d, "lineao::view::frame", size, format)),
        Output::Textures => {
            textures.truncate(view.panels.len());
            textures.retain(|t| t.size() == size);
            while textures.len() < view.panels.len() {
                use wgpu::TextureUsages as U;
                let usage = U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | U::COPY_SRC;
                textures.push(lineao::targets::Target::new(d, "lineao::view::panel", size, format, usage));
            }
            None
        }
    };
    let (mut images, mut views, mut times, mut rays) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (i, panel) in view.panels.iter().enumerate() {
        let panel_start = web_time::Instant::now();
        let mut settings = panel.settings.clone();
        // What works on the CPU needs every point there: read again once all has arrived (while
        // it arrives, such a panel shows the lines alone).
        let cpu = panel.volume.is_some() || settings.method.info().traces_scene;
        let volume = match (cpu, scene.opening) {
            (true, true) => {
                settings.method = AoMethod::None;
                settings.volume = None;
                None
            }
            (true, false) => {
                if !scene.lines.points_kept() {
                    send(FromWorker::Busy(format!("reading {} again for its points …", scene.lines.name)));
                    scene.lines.load_points(scene.source).map_err(|e| format!("{e:#}"))?;
                }
                panel.volume.clone()
            }
            (false, _) => None,
        };
        // The geometry's attributes this panel needs: the scalar's field and object-space AO.
        let wanted = AttributeKey { scalar: view.scalar_field.clone(), radius: None, volume };
        let busy = || {
            if let Some(options) = &wanted.volume {
                send(FromWorker::Busy(format!("computing {} …", options.method.name())));
            }
        };
        let error = |e: crate::source::SourceError| format!("{e:#}");
        // Object-space AO first (computed once per options, busy meanwhile): its sky goes
        // into the settings, its octants into the attributes below.
        let sky = scene.lines.visibility(&wanted, busy).map_err(error)?.map(|v| v.sky);
        let geometry = if preview {
            let p = &mut *scene.preview;
            if p.attributes != wanted && (wanted.scalar.is_some() || wanted.volume.is_some()) {
                let lines = &mut scene.lines;
                let scalars = match &wanted.scalar {
                    Some(field) => Some(lines.field(field).map_err(error)?.to_vec()),
                    None => None,
                };
                let pick = |values: &[f32]| p.kept.iter().map(|&k| values[k]).collect::<Vec<f32>>();
                let visibility = lines.visibility(&wanted, || {}).map_err(error)?;
                let octants: Option<Vec<[f32; 8]>> = visibility.map(|v| p.kept.iter().map(|&k| v.octants[k]).collect());
                let scalar = scalars.as_deref().map(pick);
                let attributes =
                    VertexAttributes { octants: octants.as_deref(), scalar: scalar.as_deref(), radius: None };
                p.geometry.set_attributes(d, q, &attributes).map_err(|e| e.to_string())?;
                p.attributes = wanted.clone();
            }
            &p.geometry
        } else {
            scene.lines.hold((d, q), &wanted, || {}).map_err(error)?;
            &scene.lines.geometry
        };
        if let (Some(sky), Some(volume)) = (sky, &mut settings.volume) {
            volume.sky = sky;
        }
        if view.scalar_field.is_none() && matches!(settings.line_color, LineColor::Scalar { .. }) {
            settings.line_color = LineColor::Tangent;
        }
        let traced = settings.method.info().traces_scene;
        if chains.len() <= i {
            let chain = AoChain::new_async(d, format, settings.clone()).await.map_err(|e| e.to_string())?;
            chains.push(PanelChain { chain, geometry_pixels: 0 });
        } else if chains[i].chain.settings() != &settings {
            chains[i].chain.set_settings_async(d, settings).await.map_err(|e| e.to_string())?;
        }
        // The ray tracer's scene: the full detail, whatever this frame draws.
        let ray_scene = if traced {
            Some(match &scene.rays {
                Some(rays) => rays.clone(),
                None => {
                    send(FromWorker::Busy("building the ray tracer's BVH …".into()));
                    let tracts = &scene.lines.tracts;
                    let geometry = lineao::RayGeometry {
                        positions: &tracts.positions,
                        offsets: &tracts.offsets,
                        radii: None,
                        meshes: &[],
                    };
                    let rays = lineao::RayScene::new(d, q, &geometry).map_err(|e| e.to_string())?;
                    let rays = Arc::new(rays);
                    scene.rays.get_or_insert(rays).clone()
                }
            })
        } else {
            None
        };
        let frame = FrameScene {
            geometry,
            meshes: &[],
            camera: &view.camera,
            bounds: &bounds,
            rays: ray_scene,
            anatomy: anatomy.clone(),
        };
        let panel = &mut chains[i];
        let chain = &mut panel.chain;
        chain.set_timing(d, q, view.timings);
        chain.resize(size.0, size.1).map_err(|e| e.to_string())?;
        let target = match &target {
            Some(shared) => shared,
            None => &textures[i],
        };
        frame.submit(gpu, chain, &target.view).map_err(|e| e.to_string())?;
        if readback {
            times.push(if view.timings { chain.pass_times(d, true).map_err(|e| e.to_string())? } else { None });
            images.push(lineao::readback::read_texture(d, q, &target.texture).map_err(|e| e.to_string())?.bytes);
        } else {
            // Without waiting: they follow once the GPU has finished ([`FromWorker::Times`]).
            times.push(None);
            views.push(target.view.clone());
        }
        let progress = if traced {
            chain.stage().and_then(|s| s.downcast::<lineao::method::raytraced::RayTracedAo>()).map(|t| t.progress())
        } else {
            None
        };
        rays.push(match progress {
            Some(progress) if !readback => Some(RayStatus { progress, rays_per_second: None }),
            Some(progress) => {
                if progress.rays_per_pixel <= progress.frame_rays || panel.geometry_pixels == 0 {
                    // A new picture: the pixels its rays start from.
                    let nd = &chain.targets().expect("rendered").nd[0];
                    let nd = lineao::readback::read_rgba(d, q, nd).map_err(|e| e.to_string())?;
                    panel.geometry_pixels = nd.data.iter().filter(|texel| texel[..3] != [0.0; 3]).count();
                }
                let rays = panel.geometry_pixels as f64 * progress.frame_rays as f64;
                Some(RayStatus { progress, rays_per_second: Some(rays / panel_start.elapsed().as_secs_f64()) })
            }
            None => None,
        });
    }
    let render_ms = start.elapsed().as_secs_f64() * 1e3;
    let selected = scene.selected.as_ref().and_then(|s| Some((s.kept?, s.streamlines)));
    Ok(Frame { view: view.clone(), images, textures: views, size, times, rays, render_ms, selected })
}
