//! The viewer window: a menu bar, the controls on the left, the rendered image in the middle
//! (two methods split by a draggable divider in compare mode), a status bar below.
//!
//! Each UI frame turns the controls and the camera into a [`View`]; a view that differs from
//! the last one requested goes to the render thread ([`super::worker`]), and finished frames
//! come back as textures. The window never waits for the GPU: while a frame renders, the last
//! one stays on screen (stretched if the window was resized) and input goes on.
//!
//! In a web page ([`App::inline`]) the worker runs on the page's thread, one step per UI frame,
//! and its frames are textures on the window's own device.

use std::cell::RefCell;
use std::path::PathBuf;
use std::rc::Rc;
#[cfg(not(target_arch = "wasm32"))]
use std::sync::mpsc;
use std::sync::mpsc::{Receiver, Sender};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use web_time::Instant;

use egui::emath::GuiRounding;
use egui::{Align2, Color32, ColorImage, FontId, PointerButton, Pos2, Rect, Sense, TextureHandle, Vec2};
use egui_file_dialog::FileDialog;
use lineao_tracts::SceneKind;

use super::camera::OrbitCamera;
use super::controls::{ColorMode, Controls, RegionRule, method_label};
use super::keys::Action;
use super::loading::PREVIEW_VERTICES;
use super::worker::{self, Dataset, Frame, FromWorker, Output, Source, ToWorker, View, Worker};

/// How long after the last camera motion frames stay previews.
const MOTION_REST: Duration = Duration::from_millis(300);

/// What the viewer opens with.
pub struct Options {
    /// What to open first (`None`: nothing yet — the web page fetching `?url=`).
    pub source: Option<Source>,
    pub controls: Controls,
    pub orthographic: bool,
    /// `--orbit`: the camera of each dataset opened, as [`OrbitCamera::set_orbit_values`] takes.
    pub orbit: Option<[f32; 3]>,
    /// `--screenshot PNG --frames N`: save the window after N frames once the image is complete,
    /// then close.
    pub screenshot: Option<(PathBuf, u32)>,
    /// `--record MOVIE --frames N`: record N frames of the window once the image is complete,
    /// write the movie, then close.
    pub record: Option<(PathBuf, u32)>,
    /// `--scale K`: pictures saved (File ▸ Save picture at K×…, `--screenshot`) are the view
    /// rendered at K × the image's size; 1: `--screenshot` saves the window.
    pub scale: u32,
    /// `--color volume:FILE`: the volume sampled at every vertex of each dataset opened.
    pub sampled: Option<Arc<crate::source::Sampled>>,
    /// `--volume FILE`: the anatomy whose slices are shown with each dataset opened, and the
    /// name it was read from.
    pub anatomy: Option<(String, Arc<lineao_tracts::Volume>)>,
}

/// How a session ended, for `--screenshot`'s exit status.
#[derive(Debug, Default)]
pub struct Outcome {
    pub saved: Option<PathBuf>,
    /// What a recording wrote (`--record`).
    pub recorded: Option<String>,
    pub error: Option<String>,
}

/// A file being read.
struct Loading {
    name: String,
    bytes: u64,
    total: Option<u64>,
}

/// Where the worker runs.
#[cfg_attr(target_arch = "wasm32", allow(dead_code))]
enum Backend {
    /// The native window: a render thread with a device of its own.
    Thread {
        /// `None` once dropped, which ends the render thread.
        to_worker: Option<Sender<ToWorker>>,
        render_thread: Option<std::thread::JoinHandle<()>>,
        from_worker: Receiver<FromWorker>,
    },
    /// A web page: the worker on the page's thread and the window's device, one step at a time
    /// run as a future of the page (it awaits the device's validation), started by the UI.
    Inline {
        worker: Rc<RefCell<Worker>>,
        /// Whether a step is running (it holds the worker).
        stepping: Rc<std::cell::Cell<bool>>,
        /// What the steps sent.
        inbox: Rc<RefCell<Vec<FromWorker>>>,
        pending: Vec<ToWorker>,
        /// The UI frame that last queued a command: commands wait one frame, so that what the
        /// window says ("loading …") is painted before a step holds the page.
        queued_at: u64,
        render_state: eframe::egui_wgpu::RenderState,
        /// The panels' textures as the window's renderer knows them.
        ids: Vec<egui::TextureId>,
    },
}

pub struct App {
    backend: Backend,
    pub controls: Controls,
    pub camera: Option<OrbitCamera>,
    orthographic: bool,
    orbit: Option<[f32; 3]>,
    pub dataset: Option<Dataset>,
    loading: Option<Loading>,
    /// The camera that framed a dataset while it arrived: framed again once all of it has,
    /// unless moved since.
    framed: Option<OrbitCamera>,
    /// Milliseconds from opening the dataset to its first part on the GPU.
    pub first_picture: Option<f64>,
    /// When the dataset was asked for, and how long until its first picture was on screen.
    opened_at: Option<Instant>,
    pub first_frame_ms: Option<f64>,
    /// What the render thread is busy with besides rendering (object-space AO).
    busy: Option<String>,
    pub error: Option<String>,
    /// The error is the dataset's (its file ended in an error): it stays while the camera moves
    /// over what was drawn, where a frame's error goes with the next view.
    load_failed: bool,
    /// The last view sent to the render thread, and the frame on screen.
    pub requested: Option<View>,
    pub shown: Option<Box<Frame>>,
    /// Frames received from the render thread (a progressive picture sends one per frame).
    pub frames_received: u64,
    textures: Vec<TextureHandle>,
    /// Compare mode: where the divider is, as a fraction of the image's width.
    pub divider: f32,
    last_motion: Option<Instant>,
    /// Where the image is drawn (points).
    pub image_rect: Option<Rect>,
    open_dialog: FileDialog,
    save_dialog: FileDialog,
    screenshot: Option<(PathBuf, u32)>,
    screenshot_requested: bool,
    /// `--record`'s movie and frames, until its recording starts.
    record_at_start: Option<(PathBuf, u32)>,
    /// The recording under way (File ▸ Record movie…, or M).
    recording: Option<super::record::Recording>,
    record_dialog: FileDialog,
    /// `--scale`, the source a picture at a scale reads again (a file or a scene), the picture
    /// being rendered, and where to save one.
    scale: u32,
    picture_source: Option<Source>,
    picture: Option<(PathBuf, std::thread::JoinHandle<Result<PathBuf, String>>)>,
    picture_dialog: FileDialog,
    /// The page's recording of its canvas is under way (index.html).
    #[cfg(target_arch = "wasm32")]
    page_recording: bool,
    /// The volume each dataset opened is coloured by (`--color volume:FILE`), or the values of
    /// a .tsf opened before its tractogram, for the next one opened.
    sampled: Option<Arc<crate::source::Sampled>>,
    /// Values sent to the worker for the dataset ([`ToWorker::Values`]) and not answered yet.
    values_pending: usize,
    /// The anatomy's volume sampled at every vertex, asked for while the dataset arrived: sent
    /// once it is whole (a volume is sampled at the points, which a dataset streamed to the GPU
    /// keeps only when it is whole and read again).
    colour_when_whole: Option<Arc<crate::source::Sampled>>,
    /// The anatomy whose slices are shown, and the name it was read from.
    anatomy: Option<(String, Arc<lineao_tracts::Volume>)>,
    pub outcome: Arc<Mutex<Outcome>>,
    frames: u64,
    /// File ▸ Open… where the app has no file dialog of its own (the web page's file input).
    pub open_file: Option<Box<dyn Fn()>>,
}

impl App {
    /// The viewer on `ctx`, whose repaint the render thread requests when a frame is ready.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn new(ctx: &egui::Context, options: Options) -> App {
        let (to_worker, worker_rx) = mpsc::channel();
        let (worker_tx, from_worker) = mpsc::channel();
        let ctx = ctx.clone();
        let render_thread = std::thread::Builder::new()
            .name("lineao-render".into())
            .spawn(move || worker::run(worker_rx, worker_tx, move || ctx.request_repaint()))
            .expect("spawning the render thread");
        let backend = Backend::Thread { to_worker: Some(to_worker), render_thread: Some(render_thread), from_worker };
        App::with_backend(backend, options)
    }

    /// The viewer of a web page: its worker on this thread, rendering with the window's device
    /// (`render_state`), wrapped in `gpu` (lineao's device-lost callback installed).
    pub fn inline(gpu: lineao::Gpu, render_state: eframe::egui_wgpu::RenderState, options: Options) -> App {
        let worker = Rc::new(RefCell::new(Worker::new(gpu, Output::Textures)));
        let backend = Backend::Inline {
            worker,
            stepping: Rc::default(),
            inbox: Rc::default(),
            pending: Vec::new(),
            queued_at: 0,
            render_state,
            ids: Vec::new(),
        };
        App::with_backend(backend, options)
    }

    fn with_backend(backend: Backend, options: Options) -> App {
        let extensions = vec!["trk", "tck", "trx", "tsf", "vtk", "vtp", "gz", "gltf", "glb", "obj", "nii"];
        let mut app = App {
            backend,
            controls: options.controls,
            camera: None,
            orthographic: options.orthographic,
            orbit: options.orbit,
            dataset: None,
            loading: None,
            framed: None,
            first_picture: None,
            opened_at: None,
            first_frame_ms: None,
            busy: None,
            error: None,
            load_failed: false,
            requested: None,
            shown: None,
            frames_received: 0,
            textures: Vec::new(),
            divider: 0.5,
            last_motion: None,
            image_rect: None,
            open_dialog: FileDialog::new()
                .title("Open a tractogram, a mesh, an anatomy (NIfTI) or a .tck's values (.tsf)")
                .add_file_filter_extensions("Tractograms, meshes and volumes", extensions)
                .default_file_filter("Tractograms, meshes and volumes"),
            save_dialog: FileDialog::new().title("Save a screenshot (PNG)").default_file_name("lineao-view.png"),
            screenshot: options.screenshot,
            record_at_start: options.record,
            scale: options.scale.max(1),
            picture_source: None,
            picture: None,
            picture_dialog: FileDialog::new().title("Save the view as a picture (PNG)").default_file_name("lineao.png"),
            recording: None,
            #[cfg(target_arch = "wasm32")]
            page_recording: false,
            record_dialog: FileDialog::new()
                .title("Record a movie (.apng; .mp4 or .webm with ffmpeg)")
                .default_file_name("lineao-recording.apng"),
            sampled: options.sampled,
            values_pending: 0,
            colour_when_whole: None,
            anatomy: options.anatomy,
            screenshot_requested: false,
            outcome: Arc::default(),
            frames: 0,
            open_file: None,
        };
        if let Some((_, anatomy)) = &app.anatomy {
            app.send(ToWorker::Anatomy(Some(anatomy.clone())));
        }
        if let Some(source) = options.source {
            app.load(source);
        }
        app
    }

    /// The worker, where it runs on this thread (the web page) and no step holds it.
    pub fn worker(&self) -> Option<std::cell::Ref<'_, Worker>> {
        match &self.backend {
            Backend::Inline { worker, .. } => worker.try_borrow().ok(),
            Backend::Thread { .. } => None,
        }
    }

    /// Whether a file is being read or a dataset being built.
    pub fn is_loading(&self) -> bool {
        self.loading.is_some()
    }

    /// Bytes read of how many, while a dataset loads.
    pub fn progress(&self) -> Option<(u64, Option<u64>)> {
        self.loading.as_ref().map(|l| (l.bytes, l.total))
    }

    /// The message on screen for a failure, if any.
    pub fn error(&self) -> Option<&str> {
        self.error.as_deref()
    }

    /// Shows `name` as loading, `bytes` of `total` read: a file being read outside the worker
    /// (the web page fetching it).
    pub fn show_loading(&mut self, name: &str, bytes: u64, total: Option<u64>) {
        if self.loading.as_ref().is_none_or(|l| l.name != name) {
            (self.dataset, self.shown, self.requested, self.error, self.busy) = (None, None, None, None, None);
            self.load_failed = false;
        }
        self.loading = Some(Loading { name: name.to_string(), bytes, total });
    }

    /// Says `what` the viewer is busy with (a web page fetching the file that colours the lines
    /// before it opens them), until a frame arrives or a load begins.
    pub fn show_busy(&mut self, what: String) {
        self.busy = Some(what);
    }

    /// What the viewer is busy with besides rendering, if anything (the status bar says it).
    pub fn busy(&self) -> Option<&str> {
        self.busy.as_deref()
    }

    /// Opens a file or builds a scene (on the render thread).
    pub fn load(&mut self, source: Source) {
        self.picture_source = matches!(source, Source::File(_) | Source::Scene { .. }).then(|| source.clone());
        let name = match &source {
            Source::Scene { kind, .. } => format!("scene {}", kind.name()),
            source => source.name(),
        };
        self.loading = Some(Loading { name, bytes: 0, total: None });
        (self.dataset, self.shown, self.requested, self.error, self.busy) = (None, None, None, None, None);
        self.load_failed = false;
        (self.camera, self.framed, self.first_picture, self.first_frame_ms) = (None, None, None, None);
        self.opened_at = Some(Instant::now());
        // The regions set now are judged as the streamlines arrive. A .tsf's values belong to
        // this one tractogram, a volume's to every one.
        let sampled = match &self.sampled {
            Some(values) if values.is_for_one_tractogram() => self.sampled.take(),
            sampled => sampled.clone(),
        };
        // Values sent for the dataset before are answered, or dropped with it; the anatomy
        // colours the new one as it arrives (`sampled`).
        self.values_pending = 0;
        self.colour_when_whole = None;
        self.send(ToWorker::Load(source, sampled, self.controls.selection().regions()));
    }

    /// Shows `volume` (read from `name`)'s slices with every dataset from now on, at
    /// `positions` (default: three through its centre): a volume opened or dropped beside the
    /// tractogram, which stays.
    pub fn set_anatomy(&mut self, name: &str, volume: Arc<lineao_tracts::Volume>, positions: Option<[Option<f32>; 3]>) {
        self.controls.set_anatomy(name, volume.world_box(), positions);
        self.anatomy = Some((name.to_string(), volume.clone()));
        self.send(ToWorker::Anatomy(Some(volume)));
    }

    /// The anatomy whose slices are shown, if any.
    pub fn anatomy(&self) -> Option<&lineao_tracts::Volume> {
        self.anatomy.as_ref().map(|(_, volume)| &**volume)
    }

    /// Colours the lines by the anatomy's values at their points (the side panel's colour
    /// "anatomy", `--color volume:` of the anatomy's file): the dataset shown — read again for
    /// its points where it was streamed without them — once it has arrived whole, and every
    /// dataset opened after it as it arrives.
    pub fn colour_by_anatomy(&mut self) {
        let Some((name, volume)) = &self.anatomy else { return };
        let values = Arc::new(crate::source::Sampled::from_volume(name, volume.clone()));
        self.sampled = Some(values.clone());
        if self.loading.is_some() {
            self.controls.color = ColorMode::Field(values.field.clone());
            self.colour_when_whole = Some(values);
        } else {
            self.colour_by(values);
        }
    }

    /// Opens a file by its name: a NIfTI volume is the anatomy, a track scalar file (.tsf) the
    /// values the dataset is coloured by, anything else a dataset.
    pub fn open_path(&mut self, path: PathBuf) {
        if is_tsf(&path) {
            return match crate::source::Sampled::of(&crate::args::ColorArg::Tsf(path)) {
                Ok(sampled) => self.colour_by(sampled.expect("a .tsf")),
                Err(e) => self.error = Some(format!("{e:#}")),
            };
        }
        if !lineao_tracts::Volume::is_nifti_name(&path.to_string_lossy()) {
            return self.load(Source::File(path));
        }
        match lineao_tracts::Volume::load(&path) {
            Ok(volume) => self.set_anatomy(&path.display().to_string(), Arc::new(volume), None),
            Err(e) => self.error = Some(format!("{e}; the tractogram is shown without slices")),
        }
    }

    /// Colours the lines by `values` (a .tsf opened or dropped beside the tractogram, which it
    /// belongs to): the dataset shown or arriving takes them, else the next one opened.
    pub fn colour_by(&mut self, values: Arc<crate::source::Sampled>) {
        self.controls.color = ColorMode::Field(values.field.clone());
        if self.dataset.is_some() || self.loading.is_some() {
            self.values_pending += 1;
            self.send(ToWorker::Values(values));
        } else {
            self.sampled = Some(values);
        }
    }

    fn send(&mut self, message: ToWorker) {
        match &mut self.backend {
            Backend::Thread { to_worker, .. } => {
                if let Some(to_worker) = to_worker {
                    let _ = to_worker.send(message);
                }
            }
            Backend::Inline { pending, queued_at, .. } => {
                pending.push(message);
                *queued_at = self.frames;
            }
        }
    }

    /// What the worker sent: from the render thread, or from a step of the inline worker.
    // A step holds the worker across its awaits by design: nothing else borrows it mutably, the
    // UI starts no step while one runs (`stepping`) and only `try_borrow`s it ([`App::worker`]).
    #[allow(clippy::await_holding_refcell_ref)]
    fn messages(&mut self, ctx: &egui::Context) -> Vec<FromWorker> {
        match &mut self.backend {
            Backend::Thread { from_worker, .. } => from_worker.try_iter().collect(),
            Backend::Inline { worker, stepping, inbox, pending, queued_at, .. } => {
                let ready = !pending.is_empty() && self.frames > *queued_at;
                if !pending.is_empty() && !ready {
                    ctx.request_repaint();
                }
                if !stepping.get() && (ready || worker.borrow().continuing()) {
                    stepping.set(true);
                    let (worker, stepping, sink, ctx) = (worker.clone(), stepping.clone(), inbox.clone(), ctx.clone());
                    let commands = std::mem::take(pending);
                    spawn(async move {
                        let mut worker = worker.borrow_mut();
                        worker.step_async(commands, &|m| sink.borrow_mut().push(m)).await;
                        stepping.set(false);
                        ctx.request_repaint();
                    });
                }
                inbox.take()
            }
        }
    }

    /// Whether what is on screen is final: [`App::settled`], and each ray-traced picture has
    /// all its rays.
    pub fn complete(&self) -> bool {
        self.settled() && (self.error.is_some() || self.shown.as_ref().is_some_and(|f| f.converged()))
    }

    /// Whether the newest view is on screen (a ray-traced picture may still be gaining rays), or
    /// an error is.
    pub fn settled(&self) -> bool {
        if self.error.is_some() {
            return true;
        }
        self.loading.is_none()
            && self.values_pending == 0
            && self.requested.is_some()
            && self.shown.as_ref().map(|f| &f.view) == self.requested.as_ref()
    }

    /// Shows `message` as a failure (and ends a load in progress; what it drew stays on screen).
    pub fn fail(&mut self, message: String) {
        // What arrived before a load failed stays, shown yet or not: the worker keeps it and
        // sent it first (`FromWorker::Loaded`); a load that failed before anything arrived
        // leaves nothing (`load` cleared the dataset before).
        let loading = self.loading.take().is_some();
        self.load_failed |= loading;
        self.busy = None;
        self.outcome.lock().expect("not poisoned").error = Some(message.clone());
        self.error = Some(message);
        // Values that failed (a .tsf of another tractogram) colour nothing.
        if let (ColorMode::Field(name), Some(dataset)) = (&self.controls.color, &self.dataset)
            && !dataset.fields.iter().any(|(f, _)| f == name)
        {
            self.controls.color = ColorMode::Tangent;
        }
    }

    fn receive(&mut self, ctx: &egui::Context) {
        for message in self.messages(ctx) {
            match message {
                FromWorker::Progress { bytes, total } => {
                    if let Some(loading) = &mut self.loading {
                        (loading.bytes, loading.total) = (bytes, total);
                    }
                }
                FromWorker::Loaded(dataset) => {
                    if dataset.complete {
                        self.loading = None;
                    }
                    // The camera frames what has arrived, and again all of it once it is there
                    // unless it was moved meanwhile.
                    let reframe = match (&self.camera, &self.framed) {
                        (None, _) => true,
                        (Some(camera), Some(framed)) => camera == framed,
                        (Some(_), None) => false,
                    };
                    if reframe {
                        let mut camera = OrbitCamera::from_hint(&dataset.hint);
                        camera.orthographic = self.orthographic;
                        if let Some(orbit) = self.orbit {
                            camera.set_orbit_values(orbit);
                        }
                        self.framed = (!dataset.complete).then_some(camera);
                        self.camera = Some(camera);
                    }
                    if self.dataset.is_none() || !dataset.complete {
                        self.first_picture.get_or_insert(dataset.first_ms);
                    }
                    if dataset.complete {
                        let first = self.first_frame_ms.map_or("none yet".into(), |ms| format!("{ms:.0} ms"));
                        eprintln!(
                            "lineao: view: {}: {} vertices; the first on the GPU after {:.0} ms, the first picture \
                             after {first}, all on the GPU after {:.0} ms",
                            dataset.name, dataset.vertices, dataset.first_ms, dataset.load_ms
                        );
                    }
                    self.controls.set_zoom_unit(dataset.hint.zoom_unit);
                    let distance = glam::Vec3::from(dataset.hint.eye).distance(glam::Vec3::from(dataset.hint.target));
                    self.controls.slab_reach = 0.5 * distance;
                    self.controls.region_home = (dataset.hint.target, 0.1 * distance);
                    self.controls.max_length = dataset.max_length;
                    self.controls.set_groups(&dataset.groups, dataset.complete);
                    self.controls.set_streamline_fields(&dataset.streamline_fields);
                    let waiting = self.colour_when_whole.as_ref().map(|values| &values.field);
                    if let ColorMode::Field(name) = &self.controls.color
                        && !dataset.fields.iter().any(|(f, _)| f == name)
                        && waiting != Some(name)
                    {
                        self.controls.color = ColorMode::Tangent;
                    }
                    let complete = dataset.complete;
                    self.dataset = Some(dataset);
                    if complete && let Some(values) = self.colour_when_whole.take() {
                        self.colour_by(values);
                    }
                }
                FromWorker::Fields(fields) => {
                    self.values_pending = self.values_pending.saturating_sub(1);
                    if let Some(dataset) = &mut self.dataset {
                        dataset.fields = fields;
                    }
                }
                FromWorker::Frame(frame) if self.dataset.is_some() => {
                    self.busy = None;
                    if self.first_frame_ms.is_none() {
                        self.first_frame_ms = self.opened_at.map(|t| t.elapsed().as_secs_f64() * 1e3);
                    }
                    self.frames_received += 1;
                    if let Backend::Inline { render_state, ids, .. } = &mut self.backend {
                        let mut renderer = render_state.renderer.write();
                        ids.truncate(frame.textures.len());
                        for (i, view) in frame.textures.iter().enumerate() {
                            let (device, filter) = (&render_state.device, wgpu::FilterMode::Linear);
                            match ids.get(i) {
                                Some(&id) => renderer.update_egui_texture_from_wgpu_texture(device, view, filter, id),
                                None => ids.push(renderer.register_native_texture(device, view, filter)),
                            }
                        }
                    }
                    let (w, h) = (frame.size.0 as usize, frame.size.1 as usize);
                    self.textures.truncate(frame.images.len());
                    for (i, bytes) in frame.images.iter().enumerate() {
                        let image = ColorImage::from_rgba_unmultiplied([w, h], bytes);
                        match self.textures.get_mut(i) {
                            Some(texture) => texture.set(image, egui::TextureOptions::LINEAR),
                            None => self.textures.push(ctx.load_texture(
                                format!("lineao-frame-{i}"),
                                image,
                                egui::TextureOptions::LINEAR,
                            )),
                        }
                    }
                    self.shown = Some(frame);
                }
                FromWorker::Frame(_) => {}
                FromWorker::Busy(what) => self.busy = Some(what),
                FromWorker::Times(times) => {
                    if let Some(frame) = &mut self.shown {
                        frame.times = times;
                    }
                }
                FromWorker::Error(message) => {
                    // Values are answered by their error where they fail.
                    self.values_pending = self.values_pending.saturating_sub(1);
                    self.fail(message);
                }
            }
        }
    }

    /// The view the controls and the camera describe, for an image of `size` pixels.
    fn view(&self, size: (u32, u32)) -> Option<View> {
        let (dataset, camera) = (self.dataset.as_ref()?, self.camera.as_ref()?);
        let groups = (crate::args::GROUP_FIELD.to_string(), [0.0, (lineao::COLORMAP_ENTRIES - 1) as f32]);
        let field = match &self.controls.color {
            ColorMode::Field(name) => dataset.fields.iter().find(|(f, _)| f == name),
            ColorMode::Groups if !dataset.groups.is_empty() => Some(&groups),
            _ => None,
        };
        Some(View {
            size,
            camera: camera.camera(),
            panels: self.controls.panels(camera.up, field.map(|(_, range)| *range), self.moving()),
            preview: self.moving() && dataset.vertices > PREVIEW_VERTICES,
            timings: self.controls.timings,
            scalar_field: field.map(|(name, _)| name.clone()),
            selection: self.controls.selection(),
        })
    }

    fn moving(&self) -> bool {
        self.last_motion.is_some_and(|t| t.elapsed() < MOTION_REST)
    }

    /// Sends the current view to the render thread if it is new.
    fn request_render(&mut self, ctx: &egui::Context) {
        let Some(rect) = self.image_rect else { return };
        let ppp = ctx.pixels_per_point();
        let size = ((rect.width() * ppp).round().max(1.0) as u32, (rect.height() * ppp).round().max(1.0) as u32);
        let Some(view) = self.view(size) else { return };
        if self.requested.as_ref() != Some(&view) {
            if !self.load_failed {
                self.error = None;
            }
            self.requested = Some(view.clone());
            self.send(ToWorker::Render(view));
        }
        if self.moving() {
            // Once the camera rests, the full-detail frame.
            ctx.request_repaint_after(MOTION_REST);
        }
    }

    fn menu(&mut self, ui: &mut egui::Ui) {
        egui::Panel::top("menu").show(ui, |ui| {
            egui::MenuBar::new().ui(ui, |ui| {
                ui.menu_button("File", |ui| {
                    if ui.button("Open…").clicked() {
                        match &self.open_file {
                            Some(open) => open(),
                            None => self.open_dialog.pick_file(),
                        }
                        ui.close();
                    }
                    ui.menu_button("Built-in scene", |ui| {
                        for kind in SceneKind::ALL {
                            if ui.button(kind.name()).clicked() {
                                self.load(Source::Scene { kind, vertices: kind.default_vertices(), seed: 1 });
                                ui.close();
                            }
                        }
                    });
                    // A page has no file system to save to: the browser downloads its picture
                    // and movie (index.html), and a page is closed as a tab.
                    #[cfg(target_arch = "wasm32")]
                    {
                        if ui.button("Save picture").clicked() {
                            page_call("lineaoSavePicture");
                            ui.close();
                        }
                        let label = if self.page_recording { "Stop recording (M)" } else { "Record movie (M)" };
                        if ui.button(label).clicked() {
                            self.page_recording = page_call("lineaoToggleRecording");
                            ui.close();
                        }
                    }
                    if matches!(self.backend, Backend::Thread { .. }) {
                        if ui.button("Save screenshot…").clicked() {
                            self.save_dialog.save_file();
                            ui.close();
                        }
                        if ui.button(format!("Save picture at {}×…", self.scale)).clicked() {
                            self.picture_dialog.save_file();
                            ui.close();
                        }
                        let label = if self.recording.is_some() { "Stop recording (M)" } else { "Record movie… (M)" };
                        if ui.button(label).clicked() {
                            match self.recording.is_some() {
                                true => self.stop_recording(),
                                false => self.record_dialog.save_file(),
                            }
                            ui.close();
                        }
                        if ui.button("Quit").clicked() {
                            ui.ctx().send_viewport_cmd(egui::ViewportCommand::Close);
                        }
                    }
                });
                ui.menu_button("View", |ui| {
                    if ui.button("Reset view (R)").clicked() {
                        if let Some(camera) = &mut self.camera {
                            camera.reset();
                        }
                        ui.close();
                    }
                    if ui.checkbox(&mut self.orthographic, "Orthographic (O)").changed()
                        && let Some(camera) = &mut self.camera
                    {
                        camera.orthographic = self.orthographic;
                    }
                    ui.checkbox(&mut self.controls.compare, "Compare side by side");
                    ui.checkbox(&mut self.controls.timings, "GPU time per pass");
                });
                ui.separator();
                if let Some(d) = &self.dataset {
                    ui.label(format!("{} · {} streamlines · {} vertices", d.name, d.streamlines, d.vertices));
                }
            });
        });
    }

    fn status_bar(&mut self, ui: &mut egui::Ui) {
        egui::Panel::bottom("status").show(ui, |ui| {
            ui.horizontal(|ui| {
                if let Some(loading) = &self.loading {
                    let mib = loading.bytes as f64 / (1 << 20) as f64;
                    match loading.total.filter(|&t| t > 0) {
                        Some(total) => {
                            let fraction = loading.bytes as f32 / total as f32;
                            let text = format!(
                                "loading {}: {mib:.1} of {:.1} MiB",
                                loading.name,
                                total as f64 / (1 << 20) as f64
                            );
                            ui.add(egui::ProgressBar::new(fraction).text(text).desired_width(420.0));
                        }
                        None => {
                            ui.spinner();
                            ui.label(format!("loading {}: {mib:.1} MiB", loading.name));
                        }
                    }
                } else if let Some(recording) = &self.recording {
                    ui.colored_label(
                        egui::Color32::from_rgb(200, 30, 30),
                        format!("REC {} frames (M stops)", recording.frames),
                    );
                } else if let Some(error) = &self.error {
                    ui.colored_label(ui.visuals().error_fg_color, error);
                } else if let Some(busy) = &self.busy {
                    ui.spinner();
                    ui.label(busy);
                } else if !self.settled() && self.dataset.is_some() {
                    ui.spinner();
                    ui.label("rendering…");
                } else if let Some(frame) = &self.shown {
                    let (w, h) = frame.size;
                    let what = if frame.images.is_empty() { "recorded" } else { "render and read back" };
                    ui.label(format!("{w} × {h} px · {:.0} ms ({what})", frame.render_ms));
                    if let Some((kept, all)) = frame.selected {
                        ui.separator();
                        ui.label(format!("{kept} of {all} streamlines selected"));
                    }
                    for status in frame.rays.iter().flatten() {
                        ui.separator();
                        if !status.progress.converged() {
                            ui.spinner();
                        }
                        ui.label(ray_status(status));
                    }
                }
            });
        });
    }

    /// The image, the divider, the overlays, and the camera's input.
    fn viewport(&mut self, ui: &mut egui::Ui) {
        // On whole pixels, so that the frame's texels map 1:1 onto the screen's.
        let rect = ui.available_rect_before_wrap().round_to_pixels(ui.pixels_per_point());
        self.image_rect = Some(rect);
        let response = ui.allocate_rect(rect, Sense::click_and_drag());
        let painter = ui.painter_at(rect);
        painter.rect_filled(rect, 0.0, Color32::from_gray(255));
        let uv = |a: f32, b: f32| Rect::from_min_max(Pos2::new(a, 0.0), Pos2::new(b, 1.0));
        let split = rect.left() + self.divider * rect.width();
        let ids: Vec<egui::TextureId> = match &self.backend {
            Backend::Inline { ids, .. } => ids.clone(),
            Backend::Thread { .. } => self.textures.iter().map(TextureHandle::id).collect(),
        };
        match (&self.shown, &ids[..]) {
            (Some(_), [only]) => {
                painter.image(*only, rect, uv(0.0, 1.0), Color32::WHITE);
            }
            (Some(_), [left, right]) => {
                let (l, r) = (
                    Rect::from_x_y_ranges(rect.left()..=split, rect.y_range()),
                    Rect::from_x_y_ranges(split..=rect.right(), rect.y_range()),
                );
                painter.image(*left, l, uv(0.0, self.divider), Color32::WHITE);
                painter.image(*right, r, uv(self.divider, 1.0), Color32::WHITE);
            }
            _ => {
                let text = match (&self.loading, &self.error) {
                    (Some(_), _) => "loading…",
                    (None, Some(_)) => {
                        "Could not show this — see the message below.\nOpen a file (File ▸ Open…, or drop it here) or pick a built-in scene."
                    }
                    _ => "rendering…",
                };
                painter.text(
                    rect.center(),
                    Align2::CENTER_CENTER,
                    text,
                    FontId::proportional(16.0),
                    Color32::DARK_GRAY,
                );
            }
        }
        if let Some(frame) = &self.shown {
            let names: Vec<String> = frame.view.panels.iter().map(panel_label).collect();
            if let [left, right] = &names[..] {
                painter.line_segment(
                    [Pos2::new(split, rect.top()), Pos2::new(split, rect.bottom())],
                    (2.0, Color32::from_gray(40)),
                );
                badge(&painter, Pos2::new(split - 8.0, rect.top() + 8.0), Align2::RIGHT_TOP, left);
                badge(&painter, Pos2::new(split + 8.0, rect.top() + 8.0), Align2::LEFT_TOP, right);
            }
            if self.controls.timings {
                for (i, times) in frame.times.iter().enumerate() {
                    let text = match times {
                        Some(times) => {
                            let mut lines: Vec<String> =
                                times.iter().map(|t| format!("{:<12}{:8.2} ms", t.name, t.ms)).collect();
                            lines.push(format!("{:<12}{:8.2} ms", "sum", times.iter().map(|t| t.ms).sum::<f64>()));
                            lines.join("\n")
                        }
                        None => "no timestamp queries on this adapter".into(),
                    };
                    let (x, align) = if i == 0 {
                        (rect.left() + 8.0, Align2::LEFT_BOTTOM)
                    } else {
                        (rect.right() - 8.0, Align2::RIGHT_BOTTOM)
                    };
                    badge(&painter, Pos2::new(x, rect.bottom() - 8.0), align, &text);
                }
            }
            regions_overlay(&painter, rect, &frame.view.camera, &self.controls.regions);
            if frame.view.preview {
                badge(
                    &painter,
                    Pos2::new(rect.center().x, rect.bottom() - 8.0),
                    Align2::CENTER_BOTTOM,
                    "preview: fewer streamlines, half resolution",
                );
            }
        }
        if ui.ctx().input(|i| !i.raw.hovered_files.is_empty()) {
            painter.rect_filled(rect, 0.0, Color32::from_black_alpha(120));
            painter.text(
                rect.center(),
                Align2::CENTER_CENTER,
                "Drop to open",
                FontId::proportional(24.0),
                Color32::WHITE,
            );
        }

        if self.controls.compare {
            let handle = Rect::from_x_y_ranges(split - 5.0..=split + 5.0, rect.y_range());
            let divider = ui
                .interact(handle, ui.id().with("divider"), Sense::drag())
                .on_hover_cursor(egui::CursorIcon::ResizeHorizontal);
            if divider.dragged()
                && let Some(pointer) = divider.interact_pointer_pos()
            {
                self.divider = ((pointer.x - rect.left()) / rect.width()).clamp(0.02, 0.98);
            }
        }
        self.camera_input(ui, &response, rect);
    }

    fn camera_input(&mut self, ui: &egui::Ui, response: &egui::Response, rect: Rect) {
        let Some(camera) = &mut self.camera else { return };
        let before = *camera;
        let delta = response.drag_delta();
        let shift = ui.input(|i| i.modifiers.shift);
        if response.dragged_by(PointerButton::Primary) && !shift {
            camera.orbit(delta.x * 0.008, delta.y * 0.008);
        } else if response.dragged_by(PointerButton::Secondary)
            || response.dragged_by(PointerButton::Middle)
            || (response.dragged_by(PointerButton::Primary) && shift)
        {
            camera.pan(delta.x, delta.y, rect.height());
        }
        if response.hovered() {
            let (scroll, pinch) = ui.input(|i| (i.smooth_scroll_delta.y, i.zoom_delta()));
            if scroll != 0.0 || pinch != 1.0 {
                camera.zoom((-scroll * 0.0015).exp() / pinch);
            }
        }
        if response.double_clicked() {
            camera.reset();
        }
        let mut record_key = false;
        if !ui.ctx().egui_wants_keyboard_input() {
            let step = 5f32.to_radians();
            for (action, (x, y)) in ui.input(super::keys::pressed) {
                match action {
                    Action::Orbit => camera.orbit(step * x, step * y),
                    Action::Pan => camera.pan(20.0 * x, 20.0 * y, rect.height()),
                    Action::Zoom(factor) => camera.zoom(factor),
                    Action::Reset => camera.reset(),
                    Action::Orthographic => camera.orthographic = !camera.orthographic,
                    Action::Slab(steps) => self.controls.move_slab(steps),
                    Action::Transparency => self.controls.toggle_transparency(),
                    Action::Record => record_key = true,
                }
            }
            self.orthographic = camera.orthographic;
        }
        if *camera != before {
            self.last_motion = Some(Instant::now());
        }
        // M starts recording into lineao-recording.apng (the menu asks where), or stops; in a
        // page the browser records its canvas.
        if record_key && matches!(self.backend, Backend::Thread { .. }) {
            match self.recording.is_some() {
                true => self.stop_recording(),
                false => _ = self.start_recording(PathBuf::from("lineao-recording.apng"), None),
            }
        }
        #[cfg(target_arch = "wasm32")]
        if record_key {
            self.page_recording = page_call("lineaoToggleRecording");
        }
    }

    /// Starts recording into `movie` (`limit` frames, then the window closes: `--record`); a
    /// movie that cannot be written is said and nothing is recorded.
    fn start_recording(&mut self, movie: PathBuf, limit: Option<u32>) -> bool {
        match super::record::Recording::start(&movie, limit) {
            Ok(recording) => self.recording = Some(recording),
            Err(e) => self.fail(format!("{e:#}")),
        }
        self.recording.is_some()
    }

    /// Renders the view on screen at `--scale` × the image's size into `path`, on a thread.
    fn save_picture(&mut self, ctx: &egui::Context, path: PathBuf) {
        let Some(rect) = self.image_rect else { return };
        let ppp = ctx.pixels_per_point();
        let size = ((rect.width() * ppp).round().max(1.0) as u32, (rect.height() * ppp).round().max(1.0) as u32);
        let (Some(view), Some(source)) = (self.view(size), &self.picture_source) else {
            return self.fail("a picture needs a tractogram read from a file, or a scene".into());
        };
        match super::export::render_args(source, &view, self.scale, path.clone()) {
            Ok(args) => {
                self.busy = Some(format!("rendering {} at {}× …", path.display(), self.scale));
                self.picture = Some((path, super::export::save(args)));
            }
            Err(e) => self.fail(e),
        }
    }

    /// A picture at a scale that finished: saved (and, for --screenshot, the window closed).
    fn picture_done(&mut self, ctx: &egui::Context) {
        let finished = self.picture.as_ref().is_some_and(|(_, thread)| thread.is_finished());
        if !finished {
            if self.picture.is_some() {
                ctx.request_repaint_after(Duration::from_millis(100));
            }
            return;
        }
        let (path, thread) = self.picture.take().expect("finished");
        self.busy = None;
        match thread.join().unwrap_or_else(|_| Err("the picture's thread failed".into())) {
            Ok(saved) => self.outcome.lock().expect("not poisoned").saved = Some(saved),
            Err(e) => self.fail(e),
        }
        if self.screenshot.as_ref().is_some_and(|(p, _)| *p == path) {
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
    }

    /// Stops recording and writes the movie of the frames recorded.
    fn stop_recording(&mut self) {
        let Some(recording) = self.recording.take() else { return };
        match recording.finish() {
            Ok(written) => {
                eprintln!("lineao: recorded {written}");
                let mut outcome = self.outcome.lock().expect("not poisoned");
                outcome.recorded = Some(written);
            }
            Err(e) => self.fail(format!("the recording: {e:#}")),
        }
    }

    /// Files from the dialogs and from drag-and-drop; screenshots requested and delivered.
    fn files(&mut self, ctx: &egui::Context) {
        self.open_dialog.update(ctx);
        if let Some(path) = self.open_dialog.take_picked() {
            self.open_path(path);
        }
        self.save_dialog.update(ctx);
        if let Some(path) = self.save_dialog.take_picked() {
            ctx.send_viewport_cmd(egui::ViewportCommand::Screenshot(egui::UserData::new(path)));
        }
        self.picture_dialog.update(ctx);
        if let Some(path) = self.picture_dialog.take_picked() {
            self.save_picture(ctx, path);
        }
        self.picture_done(ctx);
        self.record_dialog.update(ctx);
        if let Some(path) = self.record_dialog.take_picked() {
            self.start_recording(path, None);
        }
        // --record: once the image is complete.
        if self.recording.is_none()
            && self.complete()
            && let Some((path, frames)) = self.record_at_start.take()
            && !self.start_recording(path, Some(frames))
        {
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
        if let Some(recording) = &mut self.recording {
            if !recording.pending {
                recording.pending = true;
                let capture = egui::UserData::new(super::record::RecordFrame);
                ctx.send_viewport_cmd(egui::ViewportCommand::Screenshot(capture));
            }
            ctx.request_repaint();
        }
        // Several files at once: a volume and a tractogram dropped together are both opened, a
        // .tsf after the tractogram it colours.
        let mut dropped: Vec<PathBuf> =
            ctx.input(|i| i.raw.dropped_files.iter().map(|f| f.path().to_path_buf()).collect());
        dropped.sort_by_key(|path| is_tsf(path));
        for path in dropped {
            self.open_path(path);
        }
        let captures: Vec<Arc<ColorImage>> = ctx.input(|i| {
            let captures = i.events.iter().filter_map(|e| match e {
                egui::Event::Screenshot { user_data, image, .. } => {
                    user_data.data.as_ref()?.downcast_ref::<super::record::RecordFrame>()?;
                    Some(image.clone())
                }
                _ => None,
            });
            captures.collect()
        });
        for image in captures {
            let Some(recording) = &mut self.recording else { break };
            let rgba: Vec<u8> = image.pixels.iter().flat_map(|c| c.to_array()).collect();
            let [w, h] = image.size.map(|s| s as u32);
            if let Err(e) = recording.push(w, h, &rgba) {
                self.recording = None;
                self.fail(format!("recording stopped: {e:#}"));
                break;
            }
            if recording.done() {
                self.stop_recording();
                ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            }
        }
        let shots: Vec<(PathBuf, Arc<ColorImage>)> = ctx.input(|i| {
            i.events
                .iter()
                .filter_map(|e| match e {
                    egui::Event::Screenshot { user_data, image, .. } => {
                        let path = user_data.data.as_ref()?.downcast_ref::<PathBuf>()?;
                        Some((path.clone(), image.clone()))
                    }
                    _ => None,
                })
                .collect()
        });
        for (path, image) in shots {
            let rgba: Vec<u8> = image.pixels.iter().flat_map(|c| c.to_array()).collect();
            let [w, h] = image.size.map(|s| s as u32);
            match crate::output::write_png(&path, w, h, &rgba) {
                Ok(()) => self.outcome.lock().expect("not poisoned").saved = Some(path.clone()),
                Err(e) => self.fail(format!("{e:#}")),
            }
            if self.screenshot.as_ref().is_some_and(|(p, _)| *p == path) {
                ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            }
        }
        // --screenshot: once N frames have passed and the image is complete (with --scale, the
        // view at that scale).
        if let Some((path, frames)) = self.screenshot.clone() {
            if !self.screenshot_requested && self.frames >= u64::from(frames) && self.complete() {
                self.screenshot_requested = true;
                match self.scale {
                    1 => ctx.send_viewport_cmd(egui::ViewportCommand::Screenshot(egui::UserData::new(path))),
                    _ => self.save_picture(ctx, path),
                }
            }
            ctx.request_repaint();
        }
    }
}

impl Drop for App {
    /// Ends the render thread and waits for it: a process must not exit while another thread
    /// still submits Vulkan work (lavapipe's teardown then corrupts its heap).
    fn drop(&mut self) {
        if let Backend::Thread { to_worker, render_thread, .. } = &mut self.backend {
            *to_worker = None;
            if let Some(thread) = render_thread.take() {
                let _ = thread.join();
            }
        }
    }
}

impl eframe::App for App {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.show(ui);
    }
}

impl App {
    /// One UI frame: menu, status bar, controls and the viewport, in `ui` (the window's, or a
    /// test harness's).
    pub fn show(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        self.frames += 1;
        self.receive(&ctx);
        self.menu(ui);
        self.status_bar(ui);
        let fields = self.dataset.as_ref().map(|d| d.fields.clone()).unwrap_or_default();
        egui::Panel::left("controls").default_size(300.0).show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| self.controls.ui(ui, &fields));
        });
        if std::mem::take(&mut self.controls.colour_by_anatomy) {
            self.colour_by_anatomy();
        }
        egui::CentralPanel::no_frame().show(ui, |ui| self.viewport(ui));
        self.request_render(&ctx);
        self.files(&ctx);
    }
}

/// What a panel's label says: its method, and its variant's where it shows that form.
fn panel_label(panel: &worker::Panel) -> String {
    let method = crate::cli::Method { screen: panel.settings.method, volume: panel.volume.as_ref().map(|v| v.method) };
    let mut label = method_label(method);
    if let Some(variant) = panel.settings.method.info().variant_of(&panel.settings) {
        label += &format!(" ({})", variant.label);
    }
    label
}

/// Runs a step of the inline worker: as a task of the page, or (natively, where nothing runs
/// an app inline but tests might) to its end.
fn spawn(step: impl std::future::Future<Output = ()> + 'static) {
    #[cfg(target_arch = "wasm32")]
    wasm_bindgen_futures::spawn_local(step);
    #[cfg(not(target_arch = "wasm32"))]
    pollster::block_on(step);
}

/// What the status bar says of a ray-traced picture: rays per pixel so far and the speed.
pub fn ray_status(status: &worker::RayStatus) -> String {
    let p = status.progress;
    let speed = match status.rays_per_second {
        Some(speed) if speed >= 1e6 => format!(" · {:.1} M rays/s", speed / 1e6),
        Some(speed) => format!(" · {:.0} k rays/s", speed / 1e3),
        None => String::new(),
    };
    if p.converged() {
        format!("ray traced: {} rays per pixel, complete", p.rays_per_pixel)
    } else {
        format!("ray traced: {} of {} rays per pixel{speed}", p.rays_per_pixel, p.max_rays)
    }
}

/// Monospace text on a dark rounded box, `align`ed at `anchor`.
/// The selection's regions outlined over the picture seen by `camera` in `rect`: spheres as
/// circles, boxes as their edges; include regions green, exclude red.
fn regions_overlay(painter: &egui::Painter, rect: Rect, camera: &lineao::Camera, regions: &[RegionRule]) {
    let view = camera.view_matrix();
    let half = 0.5 * rect.height();
    // Pixels per world unit at view depth z (< 0), as the frame's projection has them.
    let scale = |z: f32| match camera.projection {
        lineao::Projection::Perspective { fov_y_deg } => half / ((0.5 * fov_y_deg).to_radians().tan() * -z),
        lineao::Projection::Orthographic { height } => half / (0.5 * height),
    };
    let project = |p: glam::Vec3| {
        let v = view.transform_point3(p);
        (v.z < -1e-6 * camera.eye.distance(camera.target)).then(|| rect.center() + scale(v.z) * egui::vec2(v.x, -v.y))
    };
    for rule in regions {
        let color = if rule.include { Color32::from_rgb(40, 170, 60) } else { Color32::from_rgb(210, 50, 40) };
        let stroke = egui::Stroke::new(2.0, color);
        match rule.region {
            lineao_tracts::Region::Sphere { center, radius } => {
                let center = glam::Vec3::from(center);
                if let Some(at) = project(center) {
                    let z = view.transform_point3(center).z;
                    painter.circle_stroke(at, radius * scale(z), stroke);
                }
            }
            lineao_tracts::Region::Box { min, max } => {
                let corner =
                    |i: usize| glam::Vec3::from(std::array::from_fn(|a| if i >> a & 1 == 1 { max[a] } else { min[a] }));
                for i in 0..8 {
                    for bit in [1, 2, 4] {
                        if i & bit == 0
                            && let (Some(a), Some(b)) = (project(corner(i)), project(corner(i | bit)))
                        {
                            painter.line_segment([a, b], stroke);
                        }
                    }
                }
            }
        }
    }
}

fn badge(painter: &egui::Painter, anchor: Pos2, align: Align2, text: &str) {
    let galley = painter.layout_no_wrap(text.to_string(), FontId::monospace(12.0), Color32::WHITE);
    let rect = align.anchor_size(anchor, galley.size() + Vec2::new(12.0, 8.0));
    painter.rect_filled(rect, 4.0, Color32::from_black_alpha(170));
    painter.galley(rect.min + Vec2::new(6.0, 4.0), galley, Color32::WHITE);
}

/// Whether a file is named as an MRtrix track scalar file (the loaders' rule: `.tsf`, gzipped or
/// not, any case): values for the tractogram shown, not a dataset.
pub fn is_tsf(path: &std::path::Path) -> bool {
    lineao_tracts::Format::from_path(path) == Some(lineao_tracts::Format::Tsf)
}

/// Calls the page's `window.NAME()` (index.html); whether it answered true.
#[cfg(target_arch = "wasm32")]
fn page_call(name: &str) -> bool {
    use wasm_bindgen::JsCast;
    let global = js_sys::global();
    let function = js_sys::Reflect::get(&global, &name.into()).ok().and_then(|f| f.dyn_into::<js_sys::Function>().ok());
    function.and_then(|f| f.call0(&global).ok()).is_some_and(|answer| answer.is_truthy())
}
