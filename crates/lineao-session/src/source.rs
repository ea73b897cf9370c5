//! What every command renders from, shared by `render`, `score`, `bench` and the viewer's
//! worker: a source (a built-in scene or a file) loaded with progress into streamlines and a
//! view hint, with one set of error texts; and one frame of a chain recorded, submitted and read
//! back.

use std::path::PathBuf;

use lineao::passes::lines::VertexAttributes;
use lineao::passes::meshes::MeshGeometry;
use lineao::volume::{VertexVisibility, VolumeAoOptions};
use lineao::{AoChain, Camera, LineGeometry};
use lineao_tracts::{Progress, SceneKind, Tractogram, ViewHint};

/// Why a source could not be shown, with the source named.
#[derive(Debug, thiserror::Error)]
pub enum SourceError {
    #[error(transparent)]
    Load(#[from] lineao_tracts::Error),
    #[error("{path}: a .{format} holds values without points; render its .tck")]
    ValuesWithoutPoints { path: String, format: &'static str },
    #[error("{0} has no finite points")]
    NoFinitePoints(String),
    /// The GPU refused the geometry (too large for its buffers, a lost device).
    #[error("{name}: {source}")]
    Gpu { name: String, source: lineao::Error },
    /// Object-space AO could not be computed with these options.
    #[error("{method}: {source}")]
    Volume { method: &'static str, source: lineao::Error },
    #[error("{name}: no per-vertex field '{field}' (the file has: {available})")]
    NoField { name: String, field: String, available: String },
    #[error("{name}: per-vertex field '{field}' has {columns} columns, not 1")]
    FieldColumns { name: String, field: String, columns: usize },
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
}

/// A loaded source: its name (the scene's, or the file's path), its streamlines and the
/// camera it suggests.
pub struct Loaded {
    pub name: String,
    pub tracts: Tractogram,
    pub hint: ViewHint,
}

impl Source {
    /// [`Source::load`] with a progress bar on a terminal ([`progress_bar`]): the CLI's.
    pub fn load_on_terminal(&self) -> Result<Loaded> {
        let bar = match self {
            Source::File(path) => progress_bar(path),
            Source::Scene { .. } | Source::Bytes { .. } => None,
        };
        let Some(bar) = bar else { return self.load(None) };
        let loaded = self.load(Some(&mut |p: Progress| {
            bar.set_position(p.bytes);
            std::ops::ControlFlow::Continue(())
        }));
        bar.finish_and_clear();
        loaded
    }

    /// Builds the scene or loads the file, reporting the bytes read to `progress` (files only).
    /// A file of values without points (a .tsf) is an error that says what to render instead.
    pub fn load(&self, progress: Option<lineao_tracts::ProgressFn<'_>>) -> Result<Loaded> {
        match self {
            Source::Scene { kind, vertices, seed } => {
                let scene = kind.build(*seed, *vertices);
                Ok(Loaded { name: kind.name().to_string(), tracts: scene.tractogram, hint: scene.view })
            }
            Source::File(path) => {
                let loaded = lineao_tracts::load_with(path, &Default::default(), progress)?;
                if !loaded.tractogram.has_points() {
                    let path = path.display().to_string();
                    return Err(SourceError::ValuesWithoutPoints { path, format: loaded.format.name() });
                }
                let hint = ViewHint::for_tractogram(&loaded.tractogram);
                Ok(Loaded { name: path.display().to_string(), tracts: loaded.tractogram, hint })
            }
            Source::Bytes { name, bytes } => {
                let loaded = lineao_tracts::load_from_bytes(bytes, name, &Default::default())?;
                if !loaded.tractogram.has_points() {
                    return Err(SourceError::ValuesWithoutPoints { path: name.clone(), format: loaded.format.name() });
                }
                let hint = ViewHint::for_tractogram(&loaded.tractogram);
                Ok(Loaded { name: name.clone(), tracts: loaded.tractogram, hint })
            }
        }
    }
}

/// `tracts` (of the source `name`) on the GPU; an error naming it when no point is finite. The
/// CLI and the viewer's worker own their devices, so they bound the staging memory (peak: the
/// strip plus one buffer) by waiting after each buffer.
pub fn upload(name: &str, tracts: &Tractogram, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<LineGeometry> {
    let options = lineao::passes::lines::GeometryOptions { bounded_staging: true, ..Default::default() };
    let geometry = LineGeometry::with_options(device, queue, &tracts.positions, &tracts.offsets, options)
        .map_err(|source| SourceError::Gpu { name: name.to_string(), source })?;
    if geometry.bounds.is_none() {
        return Err(SourceError::NoFinitePoints(name.to_string()));
    }
    Ok(geometry)
}

/// Records one frame of `chain` (already sized) over `geometry` and `meshes`, seen by
/// `camera`, into `target` (the chain's size and format), and submits it.
pub fn submit_frame(
    gpu: &lineao::Gpu,
    chain: &mut AoChain,
    (geometry, meshes): (&LineGeometry, &[&MeshGeometry]),
    (camera, bounds): (&Camera, &lineao::Bounds),
    target: &wgpu::TextureView,
) {
    let (d, q) = (&gpu.device, &gpu.queue);
    chain.prepare(d, q, camera, bounds);
    let mut encoder = d.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("lineao::frame") });
    chain.encode_with_meshes(&mut encoder, geometry, meshes, target);
    q.submit([encoder.finish()]);
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
                    .map_err(|source| SourceError::Volume { method: options.method.name(), source })?;
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
    pub tracts: Tractogram,
    pub hint: ViewHint,
    pub geometry: LineGeometry,
    pub volumes: VolumeCache,
    held: AttributeKey,
}

impl Lines {
    /// `loaded` uploaded ([`upload`]).
    pub fn new(Loaded { name, tracts, hint }: Loaded, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<Lines> {
        let geometry = upload(&name, &tracts, device, queue)?;
        Ok(Lines { name, tracts, hint, geometry, volumes: VolumeCache::default(), held: AttributeKey::default() })
    }

    /// The values of the per-vertex field `field` (one column).
    pub fn field(&self, field: &str) -> Result<&[f32]> {
        vertex_field(&self.name, &self.tracts, field)
    }

    /// The object-space AO `wanted` asks for, computed on first use (after `computing` is told).
    pub fn visibility(&mut self, wanted: &AttributeKey, computing: impl FnOnce()) -> Result<Option<&VertexVisibility>> {
        match &wanted.volume {
            Some(options) => Ok(Some(self.volumes.get(&self.tracts, options, computing)?)),
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
            .map_err(|source| SourceError::Gpu { name: name.clone(), source })?;
        self.held = wanted.clone();
        Ok(())
    }
}

/// The values of the per-vertex field `field` of `tracts` (source `name`), one column.
pub fn vertex_field<'t>(name: &str, tracts: &'t Tractogram, field: &str) -> Result<&'t [f32]> {
    let found = tracts.vertex_field(field).ok_or_else(|| {
        let names: Vec<&str> = tracts.vertex_fields.iter().map(|f| f.name.as_str()).collect();
        let available = if names.is_empty() { "none".to_string() } else { names.join(", ") };
        SourceError::NoField { name: name.to_string(), field: field.to_string(), available }
    })?;
    if found.columns != 1 {
        let (name, field) = (name.to_string(), field.to_string());
        return Err(SourceError::FieldColumns { name, field, columns: found.columns });
    }
    Ok(&found.values)
}
