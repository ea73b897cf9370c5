//! The command line's library: what `lineao bench`, `bench-load`, `score --fit` and `view` do,
//! behind the `lineao` binary (`main.rs`). The render session that `render`, `score` and `info`
//! run — and the Python package too — is the crate `lineao-session`, re-exported here under
//! its module names.

pub mod bench;
// Child processes and their peak memory (`wait4`): not in a web page.
#[cfg(not(target_arch = "wasm32"))]
pub mod bench_load;
pub mod cli;
pub mod fit;
#[cfg(feature = "viewer")]
pub mod options_doc;
#[cfg(feature = "viewer")]
pub mod view;

pub use lineao_session::{args, cameras, dump, figure, info, kwargs, label, output, render, score, source, truth};
