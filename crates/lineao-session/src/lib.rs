//! The render session that `lineao render`, `score` and `info`, the viewer and the Python
//! package share: a source (a file or a built-in scene) loaded, its lines on the GPU, one pass
//! chain per panel, the picture read back — with `render`'s arguments ([`args`]), from a
//! command line (clap) or from typed keyword arguments ([`kwargs`]).
//!
//! Its own crate, so Python (and later the browser) build it without the command line's
//! subcommands and the viewer (egui, eframe).

pub mod args;
pub mod cameras;
pub mod dump;
pub mod figure;
pub mod info;
pub mod kwargs;
pub mod label;
pub mod method_args;
pub mod output;
pub mod render;
pub mod score;
pub mod source;
mod text;
pub mod truth;
