//! What every command renders from, shared by `render`, `score`, `bench` and the viewer's
//! worker: a source (a built-in scene or a file) loaded with progress into streamlines and a
//! view hint, or streamed chunk by chunk onto the GPU without keeping its points
//! ([`Lines::stream`]), with one set of error texts; and one frame of a chain recorded,
//! submitted and read back.

use std::path::PathBuf;
use std::sync::Arc;

use std::ops::ControlFlow;

use lineao::passes::lines::{GeometryOptions, VertexAttributes};
use lineao::passes::meshes::MeshGeometry;
use lineao::volume::{VertexVisibility, VolumeAoOptions};
use lineao::{AoChain, Camera, LineGeometry};
use lineao_tracts::{Field, Progress, SceneKind, Tractogram, ViewHint};

/// Why a source could not be shown, with the source named.
#[derive(Debug, thiserror::Error)]
pub enum SourceError {
    #[error(transparent)]
    Load(#[from] lineao_tracts::Error),
    #[error("{path}: a .{format} holds values without points; render its .tck with --color tsf:FILE")]
    ValuesWithoutPoints { path: String, format: &'static str },
    #[error("{0} has no finite points")]
    NoFinitePoints(String),
    /// A .tsf whose streamlines are not the tractogram's (`--color tsf:FILE`).
    #[error("{tsf} does not belong to {name}: {detail}")]
    ValuesMismatch { tsf: String, name: String, detail: String },
    #[error("{path}: a .{format} file, where --color tsf:FILE takes a track scalar file (.tsf)")]
    NotTsf { path: String, format: &'static str },
    /// The GPU refused the geometry (too large for its buffers, a lost device).
    #[error("{name}: {error}")]
    Gpu { name: String, error: lineao::Error },
    /// Object-space AO could not be computed with these options.
    #[error("{method}: {error}")]
    Volume { method: &'static str, error: lineao::Error },
    #[error("{name}: no per-vertex field '{field}' (the file has: {available})")]
    NoField { name: String, field: String, available: String },
    #[error("{name}: per-vertex field '{field}' has {columns} columns, not 1")]
    FieldColumns { name: String, field: String, columns: usize },
    /// A session streamed without keeping the points was asked for something that needs them
    /// on the CPU (a bug of the session: it decides what to keep from what it will draw).
    #[error("{0}: its points were streamed to the GPU and not kept on the CPU")]
    PointsNotKept(String),
    /// A file read as it arrived, whose bytes were not kept, cannot be read again.
    #[error("{0} was read as it arrived and not kept: open it again to use this")]
    NotReadable(String),
    /// A selection rule names what the file lacks. (Errors held as `error`, not `source`: the
    /// message says them, and a chain printed whole would say them twice.)
    #[error("{name}: {error}")]
    Selection { name: String, error: lineao_tracts::SelectionError },
}

type Result<T> = std::result::Result<T, SourceError>;

/// What to show.
#[derive(Clone, Debug, PartialEq)]
pub enum Source {
    /// A built-in scene of `vertices` vertices from `seed`.
    Scene {
        kind: SceneKind,
        vertices: usize,
        seed: u64,
    },
    File(PathBuf),
    /// A file's bytes already in memory, under its name (whose extension, and `.gz`, tell the
    /// format): a file dropped on or fetched by the web page, which has no file system.
    Bytes {
        name: String,
        bytes: std::sync::Arc<[u8]>,
    },
    /// A file's bytes as they arrive (the web page reading a dropped file or a download in
    /// pieces), under its name: the viewer decodes and draws them as they come, and keeps none.
    Feed {
        name: String,
        feed: SharedFeed,
    },
}

/// Bytes arriving from outside, pushed by their reader and taken by their decoder.
#[derive(Debug, Default)]
pub struct Feed {
    pieces: std::collections::VecDeque<Vec<u8>>,
    /// Bytes pushed so far, taken so far, and of how many (when known).
    pub received: u64,
    pub taken: u64,
    pub total: Option<u64>,
    /// The most bytes its decoder keeps to read the file again (for what needs every point on
    /// the CPU); past them it keeps none.
    pub keep_bytes: u64,
    ended: bool,
    failed: Option<String>,
}

impl Feed {
    /// The next piece of the file.
    pub fn push(&mut self, piece: Vec<u8>) {
        self.received += piece.len() as u64;
        self.pieces.push_back(piece);
    }

    /// The file has ended.
    pub fn end(&mut self) {
        self.ended = true;
    }

    /// Reading failed: the load fails with `message`.
    pub fn fail(&mut self, message: String) {
        self.failed = Some(message);
    }

    /// The next pieces that have arrived, about `bytes` of them (at least one piece when there
    /// is one: a decoder's step takes a bounded share however fast the file arrives); whether
    /// the file has ended with them; and a failure.
    pub fn take(&mut self, bytes: usize) -> (Vec<Vec<u8>>, bool, Option<String>) {
        let mut taken = Vec::new();
        let mut size = 0;
        while size < bytes
            && let Some(piece) = self.pieces.pop_front()
        {
            size += piece.len();
            taken.push(piece);
        }
        self.taken += size as u64;
        (taken, self.ended && self.pieces.is_empty(), self.failed.take())
    }
}

/// A [`Feed`] shared by its reader and its decoder; two are equal when they are the same feed.
#[derive(Clone, Debug)]
pub struct SharedFeed(pub std::sync::Arc<std::sync::Mutex<Feed>>);

impl PartialEq for SharedFeed {
    fn eq(&self, other: &SharedFeed) -> bool {
        std::sync::Arc::ptr_eq(&self.0, &other.0)
    }
}

impl SharedFeed {
    /// A feed of `total` bytes when known, of which its decoder keeps up to `keep_bytes`.
    pub fn new(total: Option<u64>, keep_bytes: u64) -> SharedFeed {
        let feed = Feed { total, keep_bytes, ..Feed::default() };
        SharedFeed(std::sync::Arc::new(std::sync::Mutex::new(feed)))
    }

    pub fn lock(&self) -> std::sync::MutexGuard<'_, Feed> {
        self.0.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// Bytes pushed and not yet taken by the decoder.
    pub fn ahead(&self) -> u64 {
        let feed = self.lock();
        feed.received - feed.taken
    }

    /// Whether only its reader holds it: its load has ended (failed, or another began).
    pub fn abandoned(&self) -> bool {
        std::sync::Arc::strong_count(&self.0) == 1
    }
}

/// A loaded source: its name (the scene's, or the file's path), its streamlines and the
/// camera it suggests (`None`: frame the streamlines, [`ViewHint::for_sphere`] of their
/// bounds once on the GPU).
pub struct Loaded {
    pub name: String,
    pub tracts: Tractogram,
    pub hint: Option<ViewHint>,
}

/// Points a chunk of a streamed source holds (about): 12 MB of f32 points.
pub const CHUNK_VERTICES: usize = 1 << 20;

impl Source {
    /// [`Source::load`] with a progress bar on a terminal ([`progress_bar`]): the CLI's.
    pub fn load_on_terminal(&self) -> Result<Loaded> {
        let bar = match self {
            Source::File(path) => progress_bar(path),
            Source::Scene { .. } | Source::Bytes { .. } | Source::Feed { .. } => None,
        };
        let Some(bar) = bar else { return self.load(None) };
        let loaded = self.load(Some(&mut |p: Progress| {
            bar.set_position(p.bytes);
            std::ops::ControlFlow::Continue(())
        }));
        bar.finish_and_clear();
        loaded
    }

    /// The name a loaded source goes by: the scene's, or the file's path.
    pub fn name(&self) -> String {
        match self {
            Source::Scene { kind, .. } => kind.name().to_string(),
            Source::File(path) => path.display().to_string(),
            Source::Bytes { name, .. } | Source::Feed { name, .. } => name.clone(),
        }
    }

    /// Hands the source's streamlines to `sink` in chunks of about [`CHUNK_VERTICES`] points
    /// as they are read (files: [`lineao_tracts::load_chunked`]) or made (the whole brain,
    /// streamline by streamline, on all cores; the other scenes are built whole), reporting the
    /// bytes read to `progress`. Returns the camera a built-in scene suggests.
    pub fn stream(
        &self,
        progress: Option<lineao_tracts::ProgressFn<'_>>,
        sink: &mut dyn FnMut(Tractogram) -> ControlFlow<()>,
    ) -> Result<(Option<ViewHint>, Vec<lineao_tracts::Group>)> {
        match self {
            Source::Scene { kind: SceneKind::WholeBrain, vertices, seed } => {
                whole_brain_in_chunks(*seed, *vertices as u64, sink);
                Ok((None, Vec::new()))
            }
            Source::Scene { kind, vertices, seed } => {
                let scene = kind.build(*seed, *vertices);
                let groups = scene.tractogram.groups.clone();
                let _ = sink(scene.tractogram);
                Ok((Some(scene.view), groups))
            }
            Source::File(path) => {
                let streamed = lineao_tracts::load_chunked(path, &Default::default(), CHUNK_VERTICES, progress, sink)?;
                if !streamed.has_points {
                    let path = path.display().to_string();
                    let format = streamed.format.map_or("tsf", |f| f.name());
                    return Err(SourceError::ValuesWithoutPoints { path, format });
                }
                Ok((None, streamed.groups))
            }
            Source::Feed { name, .. } => Err(SourceError::NotReadable(name.clone())),
            Source::Bytes { name, bytes } => {
                let mut decoder = lineao_tracts::ChunkDecoder::new(
                    name,
                    &Default::default(),
                    Some(bytes.len() as u64),
                    CHUNK_VERTICES,
                    sink,
                );
                decoder.push(bytes)?;
                let streamed = decoder.finish()?;
                if !streamed.has_points {
                    let format = streamed.format.map_or("tsf", |f| f.name());
                    return Err(SourceError::ValuesWithoutPoints { path: name.clone(), format });
                }
                Ok((None, streamed.groups))
            }
        }
    }

    /// Builds the scene or loads the file, reporting the bytes read to `progress` (files only).
    /// A file of values without points (a .tsf) is an error that says what to render instead.
    pub fn load(&self, progress: Option<lineao_tracts::ProgressFn<'_>>) -> Result<Loaded> {
        match self {
            Source::Scene { kind, vertices, seed } => {
                let scene = kind.build(*seed, *vertices);
                Ok(Loaded { name: kind.name().to_string(), tracts: scene.tractogram, hint: Some(scene.view) })
            }
            Source::File(path) => {
                let loaded = lineao_tracts::load_with(path, &Default::default(), progress)?;
                if !loaded.tractogram.has_points() {
                    let path = path.display().to_string();
                    return Err(SourceError::ValuesWithoutPoints { path, format: loaded.format.name() });
                }
                Ok(Loaded { name: path.display().to_string(), tracts: loaded.tractogram, hint: None })
            }
            Source::Feed { name, .. } => Err(SourceError::NotReadable(name.clone())),
            Source::Bytes { name, bytes } => {
                let loaded = lineao_tracts::load_from_bytes(bytes, name, &Default::default())?;
                if !loaded.tractogram.has_points() {
                    return Err(SourceError::ValuesWithoutPoints { path: name.clone(), format: loaded.format.name() });
                }
                Ok(Loaded { name: name.clone(), tracts: loaded.tractogram, hint: None })
            }
        }
    }
}

/// The whole brain of `seed` with about `vertices` points, in chunks of about
/// [`CHUNK_VERTICES`] made on all cores (in order: a chunk goes when it and those before are
/// made).
fn whole_brain_in_chunks(seed: u64, vertices: u64, sink: &mut dyn FnMut(Tractogram) -> ControlFlow<()>) {
    let brain = lineao_tracts::scenes::wholebrain::WholeBrain::new(seed, vertices);
    let per_chunk = (CHUNK_VERTICES as f64 / lineao_tracts::scenes::wholebrain::MEAN_POINTS) as u64;
    let chunks = brain.streamlines().div_ceil(per_chunk);
    let range = |k: u64| k * per_chunk..((k + 1) * per_chunk).min(brain.streamlines());
    #[cfg(target_arch = "wasm32")]
    for k in 0..chunks {
        if sink(brain.tractogram(range(k))).is_break() {
            return;
        }
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get()) as u64;
        let mut k = 0;
        while k < chunks {
            let batch: Vec<Tractogram> = std::thread::scope(|scope| {
                let handles: Vec<_> = (k..(k + threads).min(chunks))
                    .map(|j| {
                        let brain = &brain;
                        scope.spawn(move || brain.tractogram(range(j)))
                    })
                    .collect();
                handles.into_iter().map(|h| h.join().expect("a chunk of the whole brain")).collect()
            });
            k += batch.len() as u64;
            for chunk in batch {
                if sink(chunk).is_break() {
                    return;
                }
            }
        }
    }
}

/// How a session uploads its lines onto `gpu`: waiting after each page (the CLI and the
/// viewer's worker own their devices, so staging memory stays one page); pages of 4 M points on
/// a CPU adapter and of 16 M on a GPU (fewer pages: the cull dispatches its passes per page,
/// and lavapipe pays for each dispatch — at 50 M points in pages of 256 k a second of the
/// culled frame; every cluster is drawn in batches of 256 k points there, whatever the page:
/// `LineGeometry::draw_batches`); and the alternating strip's tolerance a hundredth of a
/// millimetre (files and the built-in scenes are in mm), whatever the chunks: a file streamed
/// and the same streamlines uploaded whole from memory draw the same pixels.
pub fn geometry_options(gpu: &lineao::Gpu) -> GeometryOptions {
    let cpu = gpu.adapter.get_info().device_type == wgpu::DeviceType::Cpu;
    let page_bytes = if cpu { 32 << 20 } else { 128 << 20 };
    GeometryOptions { bounded_staging: true, page_bytes, tolerance: Some(0.01), ..Default::default() }
}

/// `tracts` (of the source `name`) on the GPU, as a stream of it would be; an error naming it
/// when no point is finite.
pub fn upload(name: &str, tracts: &Tractogram, on: &lineao::Gpu) -> Result<LineGeometry> {
    let (device, queue) = (&on.device, &on.queue);
    let gpu = |error| SourceError::Gpu { name: name.to_string(), error };
    let mut geometry = LineGeometry::empty(device, geometry_options(on)).map_err(gpu)?;
    geometry.append(device, queue, &tracts.positions, &tracts.offsets).map_err(gpu)?;
    geometry.finish(device, queue).map_err(gpu)?;
    if geometry.bounds.is_none() {
        return Err(SourceError::NoFinitePoints(name.to_string()));
    }
    Ok(geometry)
}

/// What a frame draws beside its chain's settings: the lines and context surfaces seen by a
/// camera (with the bounds that set its depth range), the ray tracer's scene where a panel
/// traces it, the anatomy whose slices it shows. `render`, `score`, Python
/// ([`crate::render::Session::frame`]) and the viewer's worker submit their frames through it.
pub struct FrameScene<'a> {
    pub geometry: &'a LineGeometry,
    pub meshes: &'a [&'a MeshGeometry],
    pub camera: &'a Camera,
    pub bounds: &'a lineao::Bounds,
    /// The ray tracer's scene (none given: the chain keeps the one it has).
    pub rays: Option<Arc<lineao::RayScene>>,
    pub anatomy: Option<Arc<lineao::SliceVolume>>,
}

impl FrameScene<'_> {
    /// Records one frame of `chain` (already sized) into `target` (the chain's size and
    /// format) and submits it; a target the chain cannot draw into is its error, with nothing
    /// submitted. The same scene and anatomy again keep the chain's progressive picture.
    pub fn submit(
        &self,
        gpu: &lineao::Gpu,
        chain: &mut AoChain,
        target: &wgpu::TextureView,
    ) -> std::result::Result<(), lineao::Error> {
        let (d, q) = (&gpu.device, &gpu.queue);
        if let Some(rays) = &self.rays {
            chain.set_ray_scene(d, Some(rays.clone()));
        }
        chain.set_slice_volume(d, self.anatomy.clone());
        chain.prepare(d, q, self.camera, self.bounds);
        let mut encoder = d.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("lineao::frame") });
        chain.encode(&mut encoder, (self.geometry, self.meshes), target)?;
        q.submit([encoder.finish()]);
        Ok(())
    }
}

/// A progress bar on stderr for loading `path` when stderr is a terminal and the file is
/// 32 MiB or more (smaller ones load before a bar would show).
pub fn progress_bar(path: &std::path::Path) -> Option<indicatif::ProgressBar> {
    use std::io::IsTerminal;
    let size = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    if !std::io::stderr().is_terminal() || size < 32 << 20 {
        return None;
    }
    let bar = indicatif::ProgressBar::new(size).with_style(
        indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {bytes}/{total_bytes} {bytes_per_sec}")
            .expect("a valid template")
            .progress_chars("=> "),
    );
    bar.set_message(format!("loading {}", path.display()));
    Some(bar)
}

/// Object-space AO of one tractogram, computed once per options and kept for a few (each holds
/// 32 bytes per vertex): what the CLI's panels and the viewer's frames share.
#[derive(Default)]
pub struct VolumeCache {
    /// The most recently computed last.
    entries: Vec<(VolumeAoOptions, VertexVisibility)>,
}

/// Options kept at most.
const VOLUMES_KEPT: usize = 4;

impl VolumeCache {
    /// The visibility of `tracts` under `options`, computed on first use (after `computing` is
    /// told, e.g. to show a busy state or time it).
    pub fn get(
        &mut self,
        tracts: &Tractogram,
        options: &VolumeAoOptions,
        computing: impl FnOnce(),
    ) -> Result<&VertexVisibility> {
        let index = match self.entries.iter().position(|(o, _)| o == options) {
            Some(index) => index,
            None => {
                computing();
                let computed = lineao::volume::vertex_visibility(&tracts.positions, &tracts.offsets, options)
                    .map_err(|error| SourceError::Volume { method: options.method.name(), error })?;
                if self.entries.len() == VOLUMES_KEPT {
                    self.entries.remove(0);
                }
                self.entries.push((options.clone(), computed));
                self.entries.len() - 1
            }
        };
        Ok(&self.entries[index].1)
    }
}

/// Which per-vertex attributes a geometry holds, by what they come from: compared before
/// uploading others.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AttributeKey {
    /// The per-vertex field [`lineao::LineColor::Scalar`] colors by.
    pub scalar: Option<String>,
    /// The per-vertex field that gives tubes their radii.
    pub radius: Option<String>,
    /// The object-space AO whose octant visibilities it holds.
    pub volume: Option<VolumeAoOptions>,
}

impl AttributeKey {
    fn is_empty(&self) -> bool {
        self.scalar.is_none() && self.radius.is_none() && self.volume.is_none()
    }
}

/// A loaded source on the GPU, with the attributes its geometry holds and the object-space AO
/// computed for it: what a render session keeps per dataset (the CLI's `Session`, the viewer's
/// worker).
pub struct Lines {
    pub name: String,
    /// The streamlines on the CPU: kept where something needs them there (object-space AO, the
    /// truth, the ray tracer's scene, the viewer's previews), else only their per-vertex
    /// fields that colour the lines (`tracts.positions` empty, `points_kept` false).
    pub tracts: Tractogram,
    points_kept: bool,
    /// What a stream keeps of each chunk.
    keep: Keep,
    pub hint: ViewHint,
    pub geometry: LineGeometry,
    pub volumes: VolumeCache,
    held: AttributeKey,
    /// With a selection, whether each streamline is shown (what has arrived so far).
    pub selected: Option<Vec<bool>>,
    /// With [`Keep::lengths`], every streamline's arc length (what has arrived so far).
    pub lengths: Vec<f32>,
}

/// What a stream keeps on the CPU beside the GPU's geometry.
#[derive(Clone, Debug, Default)]
pub struct Keep {
    /// Every point, offset and field (a tractogram as [`Source::load`] gives it).
    pub points: bool,
    /// The per-vertex field the lines are coloured by, uploaded with each chunk and kept for
    /// its colour range (one f32 a vertex).
    pub scalar: Option<String>,
    /// The per-vertex field that gives tubes their radii, uploaded with each chunk.
    pub radius: Option<String>,
    /// Every one-column per-vertex and per-streamline field, and the offsets (the viewer colours
    /// by the first, selects by the second, and colours by group).
    pub fields: bool,
    /// A volume sampled at every vertex as it arrives, kept as a per-vertex field.
    pub sampled: Option<std::sync::Arc<Sampled>>,
    /// The streamlines shown (`--subset`, `--length`, `--include`, …), judged as they arrive;
    /// the others stay on the GPU, selected out.
    pub selection: Option<std::sync::Arc<lineao_tracts::Selection>>,
    /// Every streamline's arc length (4 bytes a streamline: a viewer selects by it).
    pub lengths: bool,
}

/// Values from a file beside the tractogram, one a vertex, as the per-vertex field named
/// `field`: a volume sampled at every vertex (`--color volume:FILE`), or an MRtrix track scalar
/// file's values (`--color tsf:FILE`).
#[derive(Debug)]
pub struct Sampled {
    pub field: String,
    from: SampledFrom,
}

#[derive(Debug)]
enum SampledFrom {
    /// Sampled trilinearly at every vertex (shared: a viewer's anatomy colours by its slices'
    /// volume).
    Volume(std::sync::Arc<lineao_tracts::Volume>),
    /// A .tsf read whole (4 bytes a vertex): streamline k's values are its run k, in the order
    /// MRtrix writes a .tsf beside the .tck it belongs to.
    Tsf { path: String, values: Box<Tractogram> },
}

impl SampledFrom {
    /// A loaded file that must be a .tsf.
    fn tsf(path: String, loaded: lineao_tracts::Loaded) -> Result<SampledFrom> {
        if loaded.format != lineao_tracts::Format::Tsf {
            return Err(SourceError::NotTsf { path, format: loaded.format.name() });
        }
        Ok(SampledFrom::Tsf { path, values: Box::new(loaded.tractogram) })
    }
}

impl Sampled {
    /// The volume of `--color volume:FILE` or the .tsf of `--color tsf:FILE`, where the colour
    /// asks for one.
    pub fn of(color: &crate::args::ColorArg) -> Result<Option<std::sync::Arc<Sampled>>> {
        use crate::args::ColorArg;
        let from = match color {
            ColorArg::Volume(path) => {
                SampledFrom::Volume(lineao_tracts::Volume::load(path).map_err(SourceError::Load)?.into())
            }
            ColorArg::Tsf(path) => SampledFrom::tsf(path.display().to_string(), lineao_tracts::load(path)?)?,
            _ => return Ok(None),
        };
        Ok(Some(std::sync::Arc::new(Sampled { field: color.field().expect("a file's field"), from })))
    }

    /// `volume`, read from `name` (fetched by a web page, or a viewer's anatomy), sampled at
    /// every vertex.
    pub fn from_volume(name: &str, volume: impl Into<std::sync::Arc<lineao_tracts::Volume>>) -> Sampled {
        let field = crate::args::ColorArg::Volume(name.into()).field().expect("a file's field");
        Sampled { field, from: SampledFrom::Volume(volume.into()) }
    }

    /// A .tsf's bytes named `name` (dropped on a web page or a window).
    pub fn tsf_from_bytes(name: &str, bytes: &[u8]) -> Result<Sampled> {
        let loaded = lineao_tracts::load_from_bytes(bytes, name, &Default::default())?;
        let field = crate::args::ColorArg::Tsf(name.into()).field().expect("a file's field");
        Ok(Sampled { field, from: SampledFrom::tsf(name.to_string(), loaded)? })
    }

    /// Whether the values belong to one tractogram (a .tsf), not to a space (a volume).
    pub fn is_for_one_tractogram(&self) -> bool {
        matches!(self.from, SampledFrom::Tsf { .. })
    }

    /// Adds the values at `tracts`' vertices as its field (replacing one of that name), where
    /// `tracts` begins at streamline `first` of the tractogram `name` (a chunk of it).
    pub fn add_to(&self, tracts: &mut Tractogram, first: usize, name: &str) -> Result<()> {
        let values = match &self.from {
            SampledFrom::Volume(volume) => volume.sample_points(&tracts.positions),
            SampledFrom::Tsf { path, values: tsf } => {
                let mismatch =
                    |detail: String| SourceError::ValuesMismatch { tsf: path.clone(), name: name.into(), detail };
                let (have, wanted) = (tsf.streamlines(), tracts.streamlines());
                if first + wanted > have {
                    return Err(mismatch(format!("it holds values for {have} streamlines, the tractogram more")));
                }
                let runs = tsf.offsets.get(first..first + wanted + 1).unwrap_or_default();
                for (k, (run, line)) in runs.windows(2).zip(tracts.offsets.windows(2)).enumerate() {
                    let (values, points) = (run[1] - run[0], line[1] - line[0]);
                    if values != points {
                        let detail = format!("streamline {} holds {values} values and {points} points", first + k);
                        return Err(mismatch(detail));
                    }
                }
                let span = runs.first().zip(runs.last()).map_or(0..0, |(&a, &b)| a as usize..b as usize);
                let all = tsf.vertex_fields.first().map_or(&[][..], |f| &f.values[..]);
                all.get(span).ok_or_else(|| mismatch("its values end early".into()))?.to_vec()
            }
        };
        tracts.vertex_fields.retain(|f| f.name != self.field);
        tracts.vertex_fields.push(Field { name: self.field.clone(), columns: 1, values });
        Ok(())
    }

    /// Checks, once the tractogram `name` has arrived whole with `streamlines`, that the values
    /// were for all of it (a .tsf with more streamlines belongs to another tractogram).
    pub fn check_whole(&self, streamlines: usize, name: &str) -> Result<()> {
        match &self.from {
            SampledFrom::Tsf { path, values } if values.streamlines() != streamlines => {
                let detail =
                    format!("it holds values for {} streamlines, the tractogram {streamlines}", values.streamlines());
                Err(SourceError::ValuesMismatch { tsf: path.clone(), name: name.into(), detail })
            }
            _ => Ok(()),
        }
    }
}

/// Adds `tracts`' group of each vertex as the per-vertex field [`crate::args::GROUP_FIELD`]
/// (`--color groups`): a colour index of [`lineao::Colormap::Categories`], NaN outside every group.
pub fn add_group_field(tracts: &mut Tractogram) {
    let name = crate::args::GROUP_FIELD;
    let values = tracts.group_indices(lineao::COLORMAP_ENTRIES);
    tracts.vertex_fields.retain(|f| f.name != name);
    tracts.vertex_fields.push(Field { name: name.into(), columns: 1, values });
}

impl Lines {
    /// `loaded` uploaded ([`upload`]).
    pub fn new(Loaded { name, tracts, hint }: Loaded, gpu: &lineao::Gpu) -> Result<Lines> {
        let geometry = upload(&name, &tracts, gpu)?;
        let hint = hint.unwrap_or_else(|| framing(&geometry));
        Ok(Lines {
            name,
            tracts,
            points_kept: true,
            keep: Keep { points: true, ..Keep::default() },
            hint,
            geometry,
            volumes: VolumeCache::default(),
            held: AttributeKey::default(),
            selected: None,
            lengths: Vec::new(),
        })
    }

    /// `source` streamed onto the GPU chunk by chunk as it is read, keeping on the CPU only
    /// what `keep` asks for; `progress` hears of the bytes read. The chunks of a file are never
    /// all in memory at once unless `keep.points`.
    pub fn stream(
        source: &Source,
        keep: &Keep,
        progress: Option<lineao_tracts::ProgressFn<'_>>,
        on: &lineao::Gpu,
    ) -> Result<Lines> {
        let mut lines = Lines::empty(source.name(), keep, on)?;
        let mut failed: Option<SourceError> = None;
        let mut sink = |chunk: Tractogram| match lines.append_chunk(chunk, on) {
            Ok(()) => ControlFlow::Continue(()),
            Err(e) => {
                failed = Some(e);
                ControlFlow::Break(())
            }
        };
        let streamed = source.stream(progress, &mut sink);
        if let Some(error) = failed {
            return Err(error);
        }
        let (hint, groups) = streamed?;
        lines.finish(hint, on)?;
        lines.apply_selection(&groups, on)?;
        if lines.points_kept {
            lines.tracts.groups = groups;
        }
        Ok(lines)
    }

    /// Lines named `name` with nothing on the GPU yet, to [`Lines::append_chunk`] to: a source
    /// streamed chunk by chunk (the viewer draws what has arrived between chunks), keeping on the
    /// CPU what `keep` asks for.
    pub fn empty(name: String, keep: &Keep, on: &lineao::Gpu) -> Result<Lines> {
        let geometry = LineGeometry::empty(&on.device, geometry_options(on))
            .map_err(|error| SourceError::Gpu { name: name.clone(), error })?;
        Ok(Lines {
            name,
            // No offsets yet: the first chunk decides which of its fields are kept (`append`).
            tracts: Tractogram::default(),
            points_kept: keep.points,
            keep: keep.clone(),
            hint: ViewHint::for_sphere([0.0; 3], 1.0),
            geometry,
            volumes: VolumeCache::default(),
            held: AttributeKey { scalar: keep.scalar.clone(), radius: keep.radius.clone(), volume: None },
            selected: None,
            lengths: Vec::new(),
        })
    }

    /// Appends a chunk of whole streamlines: onto the GPU (with the attributes the lines hold),
    /// and what the lines keep of it on the CPU. What has not filled a page yet is drawn after
    /// [`LineGeometry::flush`].
    pub fn append_chunk(&mut self, mut chunk: Tractogram, on: &lineao::Gpu) -> Result<()> {
        if !chunk.has_points() {
            return Err(SourceError::ValuesWithoutPoints { path: self.name.clone(), format: "tsf" });
        }
        if let Some(sampled) = &self.keep.sampled {
            sampled.add_to(&mut chunk, self.geometry.streamlines, &self.name)?;
        }
        // A per-streamline field named for the colour or the radii: at every vertex.
        for field in [&self.held.scalar, &self.held.radius].into_iter().flatten() {
            chunk.spread_streamline_field(field);
        }
        let name = &self.name;
        if let Some(selection) = &self.keep.selection {
            let first = self.geometry.streamlines as u64;
            let chunk_selected =
                selection.chunk(&chunk, first).map_err(|error| SourceError::Selection { name: name.clone(), error })?;
            self.selected.get_or_insert_default().extend(chunk_selected);
        }
        if self.keep.lengths {
            let lines = chunk.offsets.windows(2).map(|w| &chunk.positions[w[0] as usize..w[1] as usize]);
            self.lengths.extend(lines.map(lineao_tracts::selection::arc_length));
        }
        let values = |field: &Option<String>| field.as_deref().map(|f| vertex_field(name, &chunk, f)).transpose();
        let attributes =
            VertexAttributes { scalar: values(&self.held.scalar)?, radius: values(&self.held.radius)?, octants: None };
        self.geometry
            .append_with(&on.device, &on.queue, &chunk.positions, &chunk.offsets, &attributes)
            .map_err(|error| SourceError::Gpu { name: name.clone(), error })?;
        append(&mut self.tracts, chunk, &self.keep);
        Ok(())
    }

    /// The end of a stream: the geometry flushed with its exact bounds, and the camera `hint`
    /// suggests (else one framing the bounds). An error where no point was finite.
    pub fn finish(&mut self, hint: Option<ViewHint>, on: &lineao::Gpu) -> Result<()> {
        pollster::block_on(self.finish_async(hint, on))
    }

    /// [`Lines::finish`] as a future (a web page's device answers the bounds' readback only
    /// once the page's event loop runs).
    pub async fn finish_async(&mut self, hint: Option<ViewHint>, on: &lineao::Gpu) -> Result<()> {
        let name = &self.name;
        self.geometry
            .finish_async(&on.device, &on.queue)
            .await
            .map_err(|error| SourceError::Gpu { name: name.clone(), error })?;
        if self.geometry.bounds.is_none() {
            return Err(SourceError::NoFinitePoints(name.clone()));
        }
        if let Some(sampled) = &self.keep.sampled {
            sampled.check_whole(self.geometry.streamlines, name)?;
        }
        self.hint = hint.unwrap_or_else(|| framing(&self.geometry));
        Ok(())
    }

    /// Applies the selection's group rule with the file's `groups` (known once it is read) and
    /// selects out on the GPU what the selection leaves out.
    pub fn apply_selection(&mut self, groups: &[lineao_tracts::Group], on: &lineao::Gpu) -> Result<()> {
        let (Some(selection), Some(selected)) = (&self.keep.selection, &mut self.selected) else { return Ok(()) };
        let name = &self.name;
        selection
            .apply_groups(selected, groups)
            .map_err(|error| SourceError::Selection { name: name.clone(), error })?;
        let shown = if selected.iter().all(|&s| s) { None } else { Some(&selected[..]) };
        self.geometry
            .set_selection(&on.device, &on.queue, shown)
            .map_err(|error| SourceError::Gpu { name: name.clone(), error })
    }

    /// Selects the streamlines of lines made whole ([`Lines::new`]) by `selection`.
    pub fn select(&mut self, selection: std::sync::Arc<lineao_tracts::Selection>, on: &lineao::Gpu) -> Result<()> {
        let name = &self.name;
        let selected =
            selection.chunk(&self.tracts, 0).map_err(|error| SourceError::Selection { name: name.clone(), error })?;
        (self.keep.selection, self.selected) = (Some(selection), Some(selected));
        let groups = std::mem::take(&mut self.tracts.groups);
        let applied = self.apply_selection(&groups, on);
        self.tracts.groups = groups;
        applied
    }

    /// Colours by `sampled` (a .tsf opened beside the tractogram) from now on: its values for
    /// the streamlines here already, whose offsets a stream keeps with the fields
    /// ([`Keep::fields`]; a .tsf needs no points), and for each chunk to come; `complete`: all of
    /// the tractogram is here, and the values must be for all of it.
    pub fn add_values(&mut self, sampled: std::sync::Arc<Sampled>, complete: bool) -> Result<()> {
        // A volume is sampled at the points.
        if !sampled.is_for_one_tractogram() && !self.points_kept {
            return Err(SourceError::PointsNotKept(self.name.clone()));
        }
        sampled.add_to(&mut self.tracts, 0, &self.name)?;
        if complete {
            sampled.check_whole(self.geometry.streamlines, &self.name)?;
        }
        self.keep.sampled = Some(sampled);
        Ok(())
    }

    /// The selection the streamlines were judged by as they arrived ([`Keep::selection`]) and
    /// the verdicts so far, one a streamline.
    pub fn judged(&self) -> Option<(&lineao_tracts::Selection, &[bool])> {
        self.keep.selection.as_deref().zip(self.selected.as_deref())
    }

    /// How many streamlines are shown (all without a selection).
    pub fn selected_count(&self) -> usize {
        self.selected.as_ref().map_or(self.geometry.streamlines, |s| s.iter().filter(|&&k| k).count())
    }

    /// Whether the streamlines are kept on the CPU.
    pub fn points_kept(&self) -> bool {
        self.points_kept
    }

    /// Reads `source` (what these lines were streamed from) again for its points, which a
    /// method that works on the CPU needs (object-space AO, the ray tracer's BVH).
    pub fn load_points(&mut self, source: &Source) -> Result<()> {
        if self.points_kept {
            return Ok(());
        }
        let loaded = source.load(None)?;
        (self.tracts.positions, self.tracts.offsets) = (loaded.tracts.positions, loaded.tracts.offsets);
        self.tracts.streamline_fields = loaded.tracts.streamline_fields;
        self.tracts.vertex_fields = loaded.tracts.vertex_fields;
        if let Some(sampled) = &self.keep.sampled {
            sampled.add_to(&mut self.tracts, 0, &self.name)?;
        }
        for field in [&self.held.scalar, &self.held.radius].into_iter().flatten() {
            self.tracts.spread_streamline_field(field);
        }
        self.points_kept = true;
        Ok(())
    }

    /// The streamlines on the CPU, when the session kept them.
    pub fn points(&self) -> Result<&Tractogram> {
        if self.points_kept { Ok(&self.tracts) } else { Err(SourceError::PointsNotKept(self.name.clone())) }
    }

    /// The values of the per-vertex field `field` (one column).
    pub fn field(&self, field: &str) -> Result<&[f32]> {
        vertex_field(&self.name, &self.tracts, field)
    }

    /// The object-space AO `wanted` asks for, computed on first use (after `computing` is told).
    pub fn visibility(&mut self, wanted: &AttributeKey, computing: impl FnOnce()) -> Result<Option<&VertexVisibility>> {
        match &wanted.volume {
            Some(options) => {
                let tracts = if self.points_kept {
                    &self.tracts
                } else {
                    return Err(SourceError::PointsNotKept(self.name.clone()));
                };
                Ok(Some(self.volumes.get(tracts, options, computing)?))
            }
            None => Ok(None),
        }
    }

    /// Makes the geometry hold the attributes `wanted` names, uploading them unless it holds
    /// them already (or nothing is wanted: what it holds then is not read).
    pub fn hold(
        &mut self,
        (device, queue): (&wgpu::Device, &wgpu::Queue),
        wanted: &AttributeKey,
        computing: impl FnOnce(),
    ) -> Result<()> {
        if wanted.is_empty() || self.held == *wanted {
            return Ok(());
        }
        // Object-space AO works on the points; the fields are kept without them.
        if wanted.volume.is_some() && !self.points_kept {
            return Err(SourceError::PointsNotKept(self.name.clone()));
        }
        let Lines { name, tracts, geometry, volumes, .. } = self;
        let octants = match &wanted.volume {
            Some(options) => Some(volumes.get(tracts, options, computing)?.octants.as_slice()),
            None => None,
        };
        let scalar = wanted.scalar.as_deref().map(|f| vertex_field(name, tracts, f)).transpose()?;
        let radius = wanted.radius.as_deref().map(|f| vertex_field(name, tracts, f)).transpose()?;
        let attributes = VertexAttributes { octants, scalar, radius };
        geometry
            .set_attributes(device, queue, &attributes)
            .map_err(|error| SourceError::Gpu { name: name.clone(), error })?;
        self.held = wanted.clone();
        Ok(())
    }
}

/// The values of the per-vertex field `field` of `tracts` (source `name`), one column.
pub fn vertex_field<'t>(name: &str, tracts: &'t Tractogram, field: &str) -> Result<&'t [f32]> {
    let found = tracts.vertex_field(field).ok_or_else(|| {
        let per_streamline = tracts.streamline_fields.iter().filter(|f| f.columns == 1);
        let names: Vec<&str> = tracts.vertex_fields.iter().chain(per_streamline).map(|f| f.name.as_str()).collect();
        let available = if names.is_empty() { "none".to_string() } else { names.join(", ") };
        SourceError::NoField { name: name.to_string(), field: field.to_string(), available }
    })?;
    if found.columns != 1 {
        let (name, field) = (name.to_string(), field.to_string());
        return Err(SourceError::FieldColumns { name, field, columns: found.columns });
    }
    Ok(&found.values)
}

/// The camera that frames `geometry` (uploaded, so its bounds are known) as a loaded tractogram
/// is framed.
fn framing(geometry: &LineGeometry) -> ViewHint {
    let bounds = geometry.bounds.expect("checked after the upload");
    ViewHint::for_sphere(bounds.center.to_array(), bounds.radius)
}

/// Adds `chunk` to what a stream keeps: everything with `keep.points`, else the fields named.
fn append(kept: &mut Tractogram, chunk: Tractogram, keep: &Keep) {
    let base = kept.offsets.last().copied().unwrap_or(0);
    if kept.offsets.is_empty() {
        kept.offsets.push(0);
        let wanted = |f: &&Field| {
            keep.points
                || (keep.fields && f.columns == 1)
                || [&keep.scalar, &keep.radius].iter().any(|k| k.as_deref() == Some(&*f.name))
        };
        let empty = |f: &Field| Field { name: f.name.clone(), columns: f.columns, values: Vec::new() };
        kept.vertex_fields = chunk.vertex_fields.iter().filter(wanted).map(empty).collect();
        let per_streamline = |f: &&Field| keep.points || (keep.fields && f.columns == 1);
        kept.streamline_fields = chunk.streamline_fields.iter().filter(per_streamline).map(empty).collect();
    }
    for field in &mut kept.vertex_fields {
        if let Some(from) = chunk.vertex_fields.iter().find(|f| f.name == field.name) {
            field.values.extend_from_slice(&from.values);
        }
    }
    // The offsets with the fields: a per-streamline value (a group's colour) spread over them.
    if keep.points || keep.fields {
        kept.offsets.extend(chunk.offsets[1..].iter().map(|o| o + base));
    }
    for field in &mut kept.streamline_fields {
        if let Some(from) = chunk.streamline_fields.iter().find(|f| f.name == field.name) {
            field.values.extend_from_slice(&from.values);
        }
    }
    if keep.points {
        kept.positions.extend_from_slice(&chunk.positions);
    }
}
