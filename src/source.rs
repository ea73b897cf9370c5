//! What every command renders from, shared by `render`, `score`, `bench` and the viewer's
//! worker: a source (a built-in scene or a file) loaded with progress into streamlines and a
//! view hint, with one set of error texts; and one frame of a chain recorded, submitted and read
//! back.

use std::path::PathBuf;

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
            Source::Scene { .. } => None,
        };
        let Some(bar) = bar else { return self.load(None) };
        let loaded = self.load(Some(&mut |p: Progress| bar.set_position(p.bytes)));
        bar.finish_and_clear();
        loaded
    }

    /// Builds the scene or loads the file, reporting the bytes read to `progress` (files only).
    /// A file of values without points (a .tsf) is an error that says what to render instead.
    pub fn load(&self, progress: Option<&mut dyn FnMut(Progress)>) -> Result<Loaded> {
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
