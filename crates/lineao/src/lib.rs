//! # lineao — ambient occlusion for dense 3D lines, as wgpu passes
//!
//! Screen-space ambient occlusion fails on thin lines: a line has too little volume to occlude,
//! its width on screen stays fixed while one zooms, and sparse samples turn into noise. LineAO
//! (Eichelbaum, Hlawitschka, Scheuermann, TVCG 2013) samples several hemispheres of growing
//! radius, each on a coarser level of a Gaussian pyramid of normals and depth, and weights
//! occluders by depth difference and by the scene's lights. This crate implements it as wgpu
//! passes a host renderer can embed, with a plain-Rust CPU reference that proves every shader.
//!
//! - [`AoChain`] wires the passes for a method and owns every size-dependent texture:
//!   `resize`, `prepare`, `encode` into your `CommandEncoder` and target view. [`HostAo`] runs
//!   it over your renderer's own depth (and normals, colour); [`OverlayAo`] draws its lines
//!   into your frame, keeping your picture and depth (docs/embedding.md).
//! - [`method`]: one folder per method — [`LineAo`](method::line_ao::LineAo) and the
//!   alternatives LineAO is measured against, [`Ssao`](method::ssao::Ssao) (Crytek),
//!   [`VoLine`](method::vo_line::VoLine) and [`VoArea`](method::vo_area::VoArea) (Volumetric
//!   Obscurance), and the GPU ray tracer — each a [`method::Stage`] of the chain, listed by
//!   one registry that names, times and presets them.
//! - [`passes`]: what every method shares — [`LineRenderer`](passes::lines::LineRenderer)
//!   (fixed-width lines writing the
//!   G-buffer), [`NdPyramid`](passes::nd_pyramid::NdPyramid), the
//!   [`Bilateral`](passes::bilateral::Bilateral) blur and the
//!   [`Composite`](passes::composite::Composite), each usable alone.
//! - [`mod@reference`] (feature `reference`): the CPU reference of each pass, and [`verify`],
//!   which compares a chain's targets with it.
//! - [`truth`]: the ground truth's settings; with the feature `truth`, ambient occlusion ray
//!   traced on the CPU on the geometry the frame shows (a BVH over rounded cones and triangles),
//!   and the [`truth::metrics`] that score a method against it.
//! - [`volume`]: object-space AO's per-pixel term; with the feature `volume`, its density
//!   volumes, occlusion sweeping and variance maps on the CPU.
//!
//! An embedder's build (no feature) compiles the passes and the chain; the tools turn the
//! features on. The G-buffer contract (the ND map, the zoom map, normalized depth) is in
//! [`targets`] and [`FrameView`]; docs/reference.md in the repository is the full specification.
//!
//! Embedding the chain in a host's frame: a headless device here, your own `Device`, `Queue`
//! and target view in a renderer (docs/embedding.md has `HostAo`, over your own depth).
//!
//! ```
//! use lineao::{AoChain, Camera, ChainSettings, Gpu, LineGeometry, Projection};
//! # fn main() -> Result<(), lineao::Error> {
//! let gpu = Gpu::headless()?;
//! // Two streamlines as one array of points and the offsets where each starts (CSR).
//! let positions = [[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [10.0, 10.0, 0.0], [0.0, 5.0, -3.0], [12.0, 5.0, 3.0]];
//! let geometry = LineGeometry::new(&gpu.device, &gpu.queue, &positions, &[0, 3, 5])?;
//! let format = wgpu::TextureFormat::Rgba8UnormSrgb;
//! let mut chain = AoChain::new(&gpu.device, format, ChainSettings::default())?; // LineAO
//! chain.resize(320, 240)?;
//! let camera = Camera {
//!     eye: [5.0, 5.0, 40.0].into(),
//!     target: [5.0, 5.0, 0.0].into(),
//!     up: glam::Vec3::Y,
//!     projection: Projection::Perspective { fov_y_deg: 45.0 },
//! };
//! // The host's frame: the texture the composite writes.
//! let target = gpu.device.create_texture(&wgpu::TextureDescriptor {
//!     label: Some("frame"),
//!     size: wgpu::Extent3d { width: 320, height: 240, depth_or_array_layers: 1 },
//!     mip_level_count: 1,
//!     sample_count: 1,
//!     dimension: wgpu::TextureDimension::D2,
//!     format,
//!     usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
//!     view_formats: &[],
//! });
//! let view = target.create_view(&Default::default());
//! // Each frame: the camera, then the passes recorded into the host's encoder.
//! chain.prepare(&gpu.device, &gpu.queue, &camera, &geometry.bounds.unwrap());
//! let mut encoder = gpu.device.create_command_encoder(&Default::default());
//! chain.encode(&mut encoder, &geometry, &view)?;
//! gpu.queue.submit([encoder.finish()]);
//! # Ok(()) }
//! ```

#![deny(missing_docs)]
// The docs link the CPU reference, the truth and the volumes from the passes that they prove;
// built without those features (an embedder's default) the links have no target and stay text.
// docs.rs builds with every feature (Cargo.toml), where each link resolves.
#![cfg_attr(
    not(all(feature = "reference", feature = "truth", feature = "volume")),
    allow(rustdoc::broken_intra_doc_links)
)]

// What an embedding names is at the root (below); the modules that stay public are the passes
// and the parts a tool builds on: each method's stage, the targets, timing, readback, the
// truth's settings; with the feature `reference` also the CPU reference, `verify` and the
// tables the shaders use (noise, sample sets), which the tests recompute frames from.
pub(crate) mod binding;
mod camera;
mod chain;
mod colormap;
mod gbuffer;
mod gpu;
#[cfg(feature = "reference")]
mod image;
pub mod lighting;
mod line_geometry;
pub mod method;
mod named;
#[cfg(feature = "reference")]
pub mod noise;
#[cfg(not(feature = "reference"))]
pub(crate) mod noise;
pub mod passes;
mod preset;
mod ray_scene;
pub mod readback;
#[cfg(feature = "reference")]
pub mod reference;
#[cfg(feature = "reference")]
pub mod sample_sets;
#[cfg(not(feature = "reference"))]
pub(crate) mod sample_sets;
mod settings;
pub(crate) mod shader;
mod stage;
pub mod targets;
pub mod timing;
pub mod truth;
#[cfg(feature = "reference")]
pub mod verify;
mod view_params;
pub mod volume;

// The exact versions lineao's API speaks: a host names `lineao::wgpu` and `lineao::glam` and
// never fights a second copy.
pub use glam;
pub use wgpu;

// What an embedding needs first, at the root.
pub use camera::{Bounds, Camera, FrameView, Projection, Tile};
pub use chain::{AoChain, Drawn, HostAo, OverlayAo};
pub use colormap::{COLORMAP_ENTRIES, Colormap};
pub use gpu::{Gpu, Lacking, check_adapter};
pub use line_geometry::LineGeometry;
pub use method::AoMethod;
pub use method::line_ao::settings::{LineAoOuter, LineAoSettings, LineAoVariant, R0};
pub use method::raytraced::settings::{RayDenoiseSettings, RayTracedSettings};
pub use method::ssao::settings::{SsaoKernel, SsaoSettings};
pub use method::vo_line::settings::{VoCombine, VoSettings};
pub use named::Named;
pub use passes::meshes::MeshGeometry;
pub use passes::nd_from_depth::{HostConfig, HostInputs};
pub use passes::seed_depth::OverlayDepth;
pub use passes::slices::SliceVolume;
pub use preset::Preset;
pub use ray_scene::{RayGeometry, RayScene};
pub use settings::{
    BilateralSettings, ChainSettings, DebugView, LineColor, Slab, SlabAxis, SliceSettings, SurfaceSettings,
    TransparencySettings, TubeSettings, VolumeAoSettings,
};
pub use shader::GBUFFER_WGSL;

// docs/embedding.md's code compiles as it stands: `cargo test --doc` checks it.
#[cfg(doctest)]
#[doc = include_str!("../../../docs/embedding.md")]
pub struct EmbeddingGuide;

/// Pyramid levels (and so LineAO hemispheres) the shaders can bind.
pub const MAX_LEVELS: u32 = 5;

/// The limit an [`Error::TooLarge`] names: wgpu's `Limits` field, or lineao's own.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Limit {
    /// `max_texture_dimension_2d` (less the guard band, for the chain's frame).
    TextureDimension2d,
    /// `max_texture_dimension_3d`: an anatomy volume's voxels a side.
    TextureDimension3d,
    /// Texels of the largest 2-D texture array (`max_texture_array_layers` ×
    /// `max_texture_dimension_2d`²): the ray tracer's scene.
    TextureArrayTexels,
    /// `max_buffer_size`.
    BufferSize,
    /// The largest storage buffer bound (`max_storage_buffer_binding_size`, at most
    /// `max_buffer_size`).
    StorageBuffer,
    /// The device's memory (it refused an allocation; `max` is its largest buffer).
    Memory,
    /// The points of a line geometry's page (`GeometryOptions::page_bytes`).
    PagePoints,
}

/// Errors at the crate boundary: device creation, settings, sizes, geometry, readback.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error("no GPU adapter found (install a Vulkan driver, e.g. mesa-vulkan-drivers): {0}")]
    /// No adapter was found; the driver's message.
    NoAdapter(String),
    #[error("the GPU adapter refused a device: {0}")]
    /// The adapter refused a device; the driver's message.
    RequestDevice(String),
    /// A setting outside its range: its flag (without the dashes), or the field of a type that
    /// has no flag (`HostConfig::depth_samples`), the value and what it takes, in its unit
    /// (`[0.25, 4] zoom units`, `> 0 world units`, `5, 7 or 9`) — what a host matches on to say
    /// which setting to change.
    #[error("invalid settings: {} must be {}{expected}, got {value}", flag(setting), if expected.starts_with(['[', '(']) || expected.contains("..=") { "in " } else { "" })]
    OutOfRange {
        /// The setting's flag, without the dashes (`ssao-radius`), or its type's field.
        setting: &'static str,
        /// The value given.
        value: String,
        /// What it takes, in its unit.
        expected: String,
    },
    /// Two settings that do not go together: the one that cannot be used, the other that
    /// rules it out (flags, as [`Error::OutOfRange`]'s), and why.
    #[error("invalid settings: {} does not go with {}: {why}", flag(setting), flag(with))]
    Conflict {
        /// The setting that cannot be used (`outer`).
        setting: &'static str,
        /// The setting that rules it out (`variant`).
        with: &'static str,
        /// Why, in words.
        why: &'static str,
    },
    #[error("invalid line geometry: {0}")]
    /// A line geometry that cannot be made (offsets out of order, points that are not finite).
    InvalidGeometry(String),
    /// More than the device allows: which limit, how much was asked and the most it takes (what
    /// a host matches on to shrink the frame or the data), and what was being made.
    #[error("too large for this adapter: {message}")]
    TooLarge {
        /// Which limit.
        limit: Limit,
        /// How much was asked.
        value: u64,
        /// The most the device takes.
        max: u64,
        /// What was being made, in words.
        message: String,
    },
    #[error("GPU operation failed: {0}")]
    /// A GPU operation failed (mapping a buffer, a submission); the driver's message.
    Gpu(String),
    /// An adapter without what lineao's passes need ([`check_adapter`]): its name and backend,
    /// and each thing it lacks — what a host matches on to fall back or say which.
    #[error("the GPU cannot run lineao: {adapter} lacks {}", lacking.iter().map(|l| l.to_string()).collect::<Vec<_>>().join(", "))]
    AdapterLacks {
        /// The adapter's name and backend.
        adapter: String,
        /// Each thing it lacks.
        lacking: Vec<Lacking>,
    },
    /// What the device refused to make (a validation error wgpu would panic with).
    #[error("the GPU cannot run lineao: {0}")]
    Unsupported(String),
    #[error("stopped before it finished")]
    /// Cancelled by its caller before it finished.
    Cancelled,
    /// The device is gone (a driver reset, a removed GPU, `Device::destroy`): what was being
    /// rendered or accumulated stops; a new device starts again.
    #[error("the GPU device was lost: {0}")]
    DeviceLost(String),
    /// A call out of order, or a host's texture or input that does not fit: which, and what to
    /// change.
    #[error("wrong use of lineao: {0}")]
    Usage(Misuse),
}

impl Error {
    /// [`Error::OutOfRange`]: `setting` took `value`, and takes `expected`.
    pub(crate) fn out_of_range(setting: &'static str, value: impl std::fmt::Display, expected: &str) -> Error {
        Error::OutOfRange { setting, value: value.to_string(), expected: expected.to_string() }
    }
}

/// A setting's name as an error shows it: a flag with its dashes, a type's field as it is.
fn flag(setting: &str) -> String {
    if setting.contains("::") { setting.to_string() } else { format!("--{setting}") }
}

/// How a host used lineao wrongly ([`Error::Usage`]): what a host matches on, each saying what
/// to change.
#[derive(Debug, thiserror::Error)]
pub enum Misuse {
    /// A call before the one it needs first (`AoChain::encode` before `AoChain::prepare`).
    #[error("{call} before {first}: call {first} first")]
    Order {
        /// What was called.
        call: &'static str,
        /// What must be called first.
        first: &'static str,
    },
    /// A texture without a usage it needs.
    #[error("{texture} lacks TextureUsages::{usage:?} (has {has:?}): add it where the texture is created")]
    TextureUsage {
        /// Which texture (`the composite's target`).
        texture: String,
        /// The usage it needs.
        usage: wgpu::TextureUsages,
        /// The usages it has.
        has: wgpu::TextureUsages,
    },
    /// A texture of a format or sample count the call cannot take.
    #[error("{texture} is {format:?} with {samples} samples; it must be {expected}")]
    TextureFormat {
        /// Which texture.
        texture: String,
        /// Its format.
        format: wgpu::TextureFormat,
        /// Its samples per pixel.
        samples: u32,
        /// What it must be.
        expected: String,
    },
    /// A texture or a view of another size than the chain's.
    #[error("{texture} is {}×{} but the chain is {}×{}: call AoChain::resize with the host's size", size.0, size.1, chain.0, chain.1)]
    Size {
        /// Which texture or view.
        texture: String,
        /// Its size.
        size: (u32, u32),
        /// The chain's visible size.
        chain: (u32, u32),
    },
    /// A tile that does not lie inside its picture.
    #[error("a {}×{} tile at ({}, {}) lies outside its {}×{} picture: resize the chain to the tile first", size.0, size.1, tile.origin[0], tile.origin[1], tile.picture[0], tile.picture[1])]
    TileOutside {
        /// The chain's size.
        size: (u32, u32),
        /// The tile.
        tile: Tile,
    },
    /// Something the call needs that is not there (the prepass depth of a Bevy camera).
    #[error("{input} is missing: {fix}")]
    Missing {
        /// What is missing.
        input: &'static str,
        /// What to change.
        fix: &'static str,
    },
    /// An input passed that the configuration says is absent (`given`), or missing where it
    /// says it is there.
    #[error("{input} was {} but {config} says {}: {fix}", if *given { "passed" } else { "not passed" }, if *given { "none" } else { "there is one" })]
    Input {
        /// The input (`the overlay's depth`, `HostInputs::normals`).
        input: &'static str,
        /// Whether it was passed.
        given: bool,
        /// What says otherwise (`OverlayAo::set_depth`, `HostConfig::normals`).
        config: &'static str,
        /// What to change.
        fix: &'static str,
    },
}
