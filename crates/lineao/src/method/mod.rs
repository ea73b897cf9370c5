//! The ambient occlusion methods: one folder each, and one registry line.
//!
//! A method's folder holds everything that is the method's own: its passes and their WGSL, the
//! [`Stage`] that puts them in the chain, its settings (units, ranges, defaults, validation and
//! its values in each [`crate::Preset`], all on its own settings type: `Own`), and its CPU
//! reference (re-exported by [`crate::reference`]). The folder ends in one [`MethodInfo`], and
//! the list (`list.rs`'s `for_each_method!`) names every method by its folder. Everything that
//! names methods derives from the registry: [`AoMethod`] itself, its names and help, the
//! chain's timing spans ([`pass_names`]), the shaders the naga test validates, the presets,
//! and — in the front ends — the command line's values, the bench's passes, `score`'s rows,
//! the viewer's labels and Python's `methods()`.
//!
//! ```text
//!   method/<name>/mod.rs        the passes, the Stage, `pub(crate) const METHOD: MethodInfo`
//!   method/<name>/settings.rs   the settings, their descriptions (`setting::Setting`), presets
//!   method/<name>/reference.rs  the CPU reference, line by line the WGSL's arithmetic
//!   method/<name>/*.wgsl        the shaders
//! ```
//!
//! Adding a method: its folder and its line in `for_each_method!` (with its settings' field of
//! [`crate::ChainSettings`] when it has settings of its own). Its settings' descriptions
//! ([`MethodInfo::settings`]) give the front ends its flags, keywords, controls and URL keys.
//!
//! The files stand in layers, each importing only those below: the list and a method's own
//! settings (`<name>/settings.rs`, on [`setting`]) under [`crate::ChainSettings`], which holds
//! them; [`MethodInfo`] and [`Stage`] (`info.rs`) over it; each method's stage and `METHOD`;
//! and the registry (`registry.rs`) on top: [`AoMethod::info`], and what the chain's settings
//! do through every method (presets, validation, the pyramid's levels). This file declares
//! them and names what the crate shows of them.

mod info;
pub(crate) mod list;
mod none;
mod registry;

#[cfg(all(feature = "serde", feature = "reference"))]
pub use info::Dump;
pub use info::{BenchPass, ChainSetting, Estimate, FitCandidate, MethodInfo, Reach, Stage, Variant};
pub(crate) use info::{Own, fits_always, fits_storage};
pub use list::AoMethod;
pub use registry::{bench_passes, build, pass_names};

pub mod line_ao;
pub mod raytraced;
pub mod setting;
pub mod ssao;
#[cfg(any(test, feature = "toy-method"))]
pub mod toy;
pub mod vo_area;
pub mod vo_line;
