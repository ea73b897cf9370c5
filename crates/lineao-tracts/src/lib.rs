//! # lineao-tracts — streamlines for lineao, without a GPU
//!
//! One in-memory [`Tractogram`] (positions in RAS+ millimetres, N + 1 offsets) and the built-in
//! synthetic [`scenes`] that the demo, the tests and the benchmarks share. File formats (TrackVis,
//! MRtrix, TRX, VTK, …) load into the same type.

pub mod scenes;
mod tractogram;

pub use scenes::{Scene, SceneKind, ViewHint};
pub use tractogram::Tractogram;
