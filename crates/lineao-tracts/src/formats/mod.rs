//! One module per file format family; each parses from bytes or from the crate's buffered reader and
//! knows nothing about files, compression or progress (that is [`crate::load`]'s job).

pub mod gltf;
pub mod mrtrix;
pub mod obj;
pub mod trk;
pub mod trx;
pub mod tt;
pub mod vtk;
pub mod vtp;
