//! The viewer's render thread. It owns its own wgpu device (not the window's): one lavapipe frame
//! of 11 M vertices takes seconds, and a queue runs its work in order, so on the window's queue a
//! long LineAO submission would hold up every window frame behind it. Here the window keeps
//! drawing and answering input while frames render; finished frames come back as RGBA images.
//!
//! Requests are coalesced: only the newest view is rendered, and a load drops pending renders.
//! While the camera moves the app asks for *preview* frames: every k-th streamline (at most
//! [`PREVIEW_VERTICES`] vertices) at half resolution — visibly coarser, and replaced by the full
//! frame as soon as the camera rests.

use std::sync::mpsc::{Receiver, Sender, TryRecvError};

use lineao::camera::Camera;
use lineao::passes::lines::{LineGeometry, VertexAttributes};
use lineao::timing::PassTime;
use lineao::volume::VolumeAoOptions;
use lineao::{AoChain, ChainSettings, Gpu, LineColor};
use lineao_tracts::{Tractogram, ViewHint};

pub use crate::source::Source;
use crate::source::{AttributeKey, Lines, submit_frame};

/// Vertices of a preview frame at most.
pub const PREVIEW_VERTICES: usize = 250_000;

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
}

pub enum ToWorker {
    Load(Source),
    Render(View),
}

/// What the app learns about a loaded dataset.
#[derive(Clone, Debug)]
pub struct Dataset {
    pub name: String,
    pub streamlines: usize,
    pub vertices: usize,
    pub hint: ViewHint,
    /// One-column per-vertex fields, with their 2nd–98th percentile ranges.
    pub fields: Vec<(String, [f32; 2])>,
}

/// A rendered frame.
pub struct Frame {
    pub view: View,
    /// RGBA8 (sRGB) per panel, `size` each.
    pub images: Vec<Vec<u8>>,
    pub size: (u32, u32),
    pub times: Vec<Option<Vec<PassTime>>>,
    pub render_ms: f64,
}

pub enum FromWorker {
    /// Loading: bytes read of the total, when known.
    Progress {
        bytes: u64,
        total: Option<u64>,
    },
    Loaded(Dataset),
    Frame(Box<Frame>),
    /// Something takes a while (computing object-space AO).
    Busy(String),
    Error(String),
}

/// The loaded data on the GPU: full detail and the preview's subset.
struct Scene {
    /// Full detail, with its attributes and object-space AO.
    lines: Lines,
    preview: Option<Preview>,
}

/// Every k-th streamline: its geometry, and which full-detail vertices it keeps.
struct Preview {
    geometry: LineGeometry,
    kept: Vec<usize>,
    attributes: AttributeKey,
}

/// Runs the worker until the app's sender is dropped. `repaint` asks the window for a frame
/// when something arrives.
pub fn run(rx: Receiver<ToWorker>, tx: Sender<FromWorker>, repaint: impl Fn() + Send + 'static) {
    let send = |message: FromWorker| {
        let _ = tx.send(message);
        repaint();
    };
    let gpu = match Gpu::headless() {
        Ok(gpu) => gpu,
        Err(e) => {
            send(FromWorker::Error(e.to_string()));
            return;
        }
    };
    let mut scene: Option<Scene> = None;
    let mut chains: Vec<AoChain> = Vec::new();
    loop {
        // The next command, then whatever else is waiting: loads in order, the newest render.
        let Ok(first) = rx.recv() else { return };
        let mut pending = vec![first];
        loop {
            match rx.try_recv() {
                Ok(command) => pending.push(command),
                Err(TryRecvError::Empty) => break,
                Err(TryRecvError::Disconnected) => return,
            }
        }
        let last_load = pending.iter().rposition(|c| matches!(c, ToWorker::Load(_)));
        let render =
            pending.iter().rposition(|c| matches!(c, ToWorker::Render(_))).filter(|&r| last_load.is_none_or(|l| r > l));
        if let Some(l) = last_load {
            let ToWorker::Load(source) = &pending[l] else { unreachable!() };
            scene = None;
            match load(&gpu, source, &send) {
                Ok((loaded, dataset)) => {
                    scene = Some(loaded);
                    send(FromWorker::Loaded(dataset));
                }
                Err(e) => send(FromWorker::Error(e)),
            }
        }
        if let (Some(r), Some(scene)) = (render, scene.as_mut()) {
            let ToWorker::Render(view) = &pending[r] else { unreachable!() };
            match render_frame(&gpu, scene, &mut chains, view, &send) {
                Ok(frame) => send(FromWorker::Frame(Box::new(frame))),
                Err(e) => send(FromWorker::Error(e)),
            }
        }
    }
}

fn load(gpu: &Gpu, source: &Source, send: &dyn Fn(FromWorker)) -> Result<(Scene, Dataset), String> {
    let mut report = |p: lineao_tracts::Progress| send(FromWorker::Progress { bytes: p.bytes, total: p.total });
    let loaded = source.load(Some(&mut report)).map_err(|e| format!("{e:#}"))?;
    let lines = Lines::new(loaded, &gpu.device, &gpu.queue).map_err(|e| format!("{e:#}"))?;
    let fields = lines
        .tracts
        .vertex_fields
        .iter()
        .filter(|f| f.columns == 1)
        .map(|f| (f.name.clone(), crate::render::percentile_range(&f.values)))
        .collect();
    let (streamlines, vertices) = (lines.geometry.streamlines, lines.geometry.vertices);
    let dataset = Dataset { name: lines.name.clone(), streamlines, vertices, hint: lines.hint, fields };
    let scene = Scene { lines, preview: None };
    Ok((scene, dataset))
}

/// Every `k`-th streamline of `tracts`, with the indices of the vertices kept.
fn subset(tracts: &Tractogram, k: usize) -> (Vec<[f32; 3]>, Vec<u64>, Vec<usize>) {
    let (mut positions, mut offsets, mut kept) = (Vec::new(), vec![0u64], Vec::new());
    for range in tracts.offsets.windows(2).step_by(k) {
        let (a, b) = (range[0] as usize, range[1] as usize);
        positions.extend_from_slice(&tracts.positions[a..b]);
        kept.extend(a..b);
        offsets.push(positions.len() as u64);
    }
    (positions, offsets, kept)
}

fn render_frame(
    gpu: &Gpu,
    scene: &mut Scene,
    chains: &mut Vec<AoChain>,
    view: &View,
    send: &dyn Fn(FromWorker),
) -> Result<Frame, String> {
    let start = std::time::Instant::now();
    let (d, q) = (&gpu.device, &gpu.queue);
    let preview = view.preview && scene.lines.geometry.vertices > PREVIEW_VERTICES;
    let size = if preview { ((view.size.0 / 2).max(1), (view.size.1 / 2).max(1)) } else { view.size };
    if preview && scene.preview.is_none() {
        let k = scene.lines.geometry.vertices.div_ceil(PREVIEW_VERTICES);
        let (positions, offsets, kept) = subset(&scene.lines.tracts, k);
        let geometry = LineGeometry::new(d, q, &positions, &offsets).map_err(|e| e.to_string())?;
        scene.preview = Some(Preview { geometry, kept, attributes: AttributeKey::default() });
    }
    let bounds = scene.lines.geometry.bounds.expect("checked at load");
    let format = wgpu::TextureFormat::Rgba8UnormSrgb;
    let target = lineao::targets::Target::output(d, "lineao::view::frame", size, format);
    let (mut images, mut times) = (Vec::new(), Vec::new());
    for (i, panel) in view.panels.iter().enumerate() {
        // The geometry's attributes this panel needs: the scalar's field and object-space AO.
        let wanted = AttributeKey { scalar: view.scalar_field.clone(), radius: None, volume: panel.volume.clone() };
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
            let p = scene.preview.as_mut().expect("made above");
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
        let mut settings = panel.settings.clone();
        if let (Some(sky), Some(volume)) = (sky, &mut settings.volume) {
            volume.sky = sky;
        }
        if view.scalar_field.is_none() && matches!(settings.line_color, LineColor::Scalar { .. }) {
            settings.line_color = LineColor::Tangent;
        }
        if chains.len() <= i {
            chains.push(AoChain::new(d, format, settings.clone()).map_err(|e| e.to_string())?);
        } else if chains[i].settings() != &settings {
            chains[i].set_settings(d, settings).map_err(|e| e.to_string())?;
        }
        let chain = &mut chains[i];
        if chain.timing() != view.timings {
            chain.set_timing(d, q, view.timings);
        }
        chain.resize(size.0, size.1).map_err(|e| e.to_string())?;
        submit_frame(gpu, chain, (geometry, &[]), (&view.camera, &bounds), &target.view);
        times.push(if view.timings { chain.pass_times(d).map_err(|e| e.to_string())? } else { None });
        images.push(lineao::readback::read_texture(d, q, &target.texture).map_err(|e| e.to_string())?.bytes);
    }
    Ok(Frame { view: view.clone(), images, size, times, render_ms: start.elapsed().as_secs_f64() * 1e3 })
}
