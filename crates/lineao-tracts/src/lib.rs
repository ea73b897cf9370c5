//! # lineao-tracts — streamlines for lineao, without a GPU
//!
//! One in-memory [`Tractogram`] (positions in RAS+ millimetres, N + 1 offsets, data by name,
//! groups, the voxel grid) loaded from every common tractography format, and the built-in
//! synthetic [`scenes`] that the demo, the tests and the benchmarks share.
//!
//! ```no_run
//! let loaded = lineao_tracts::load("bundle.trk")?;
//! println!("{} streamlines, {} vertices", loaded.tractogram.streamlines(), loaded.tractogram.vertices());
//! # Ok::<(), lineao_tracts::Error>(())
//! ```
//!
//! | format | read | write |
//! |---|---|---|
//! | TrackVis `.trk` (v1–v3, either byte order) | ✓ | ✓ |
//! | MRtrix `.tck` (Float32/64, LE/BE), `.tsf` | ✓ | `.tck` |
//! | TRX zip (stored/deflate) and directory, every dtype | ✓ | ✓ (zip, stored) |
//! | VTK legacy `.vtk` (ASCII/binary, ≤ 4.2 and 5.1 cells) | ✓ | |
//! | VTK XML `.vtp` (ascii/base64/appended, zlib) | ✓ | |
//! | DSI Studio `.tt.gz` | ✓ | |
//! | glTF line primitives, OBJ `l` polylines | ✓ | |
//!
//! Any of them may be gzip-wrapped; the format is found from the content. Errors name the file,
//! the byte offset and what was expected ([`Error`]); no header field sizes an allocation.
//!
//! Context surfaces (a brain hull shown with the tracts) load as a [`TriangleMesh`] from OBJ and
//! glTF ([`load_mesh`]).

#![deny(missing_docs)]

mod error;
pub mod formats;
mod input;
mod load;
pub mod mesh;
pub mod scenes;
pub mod selection;
mod stream;
mod tractogram;
pub mod volume;

pub use error::{Error, ErrorKind};
pub use input::{Progress, ProgressFn};
pub use load::{Compression, Format, LoadOptions, Loaded, load, load_from_bytes, load_with, parse_as, save};
pub use mesh::{TriangleMesh, load_mesh};
pub use scenes::{Scene, SceneKind, ViewHint};
pub use selection::{Region, Selection, SelectionError};
pub use stream::{ChunkDecoder, ChunkSink, Streamed, load_chunked};
pub use tractogram::{Bounds, Field, Group, IDENTITY, Tractogram, VoxelSpace};
pub use volume::Volume;
