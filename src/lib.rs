//! The command line's library: what `lineao render`, `score`, `bench`, `info` and `view` do,
//! behind the `lineao` binary (`main.rs`) and the Python package (`crates/lineao-py`), which
//! parses its keyword arguments as `render`'s command line so that both share one set of
//! names, defaults and checks.

pub mod bench;
pub mod bench_load;
pub mod cli;
pub mod dump;
pub mod fit;
pub mod info;
pub mod kwargs;
pub mod label;
pub mod output;
pub mod render;
pub mod score;
pub mod source;
pub mod truth;
#[cfg(feature = "viewer")]
pub mod view;
