//! lineao's viewer in a web page, on WebGPU: the native viewer's app (`lineao_cli::view`) run
//! by eframe's web runner, with its worker stepped on the page's thread (a page has no
//! threads) and rendering on the page's one device.
//!
//! - [`query`]: the page's URL as `lineao view`'s options (`?url=`, `?scene=`, methods,
//!   preset, camera), and the link of a view.
//! - `page` (wasm32 only): the runner; files dropped, picked or fetched with progress and a
//!   size limit; `window.lineaoStatus`; the AO and ND maps read back for tests.
//! - [`check`]: natively, a page's read-back maps against lineao's CPU reference.
//!
//! `scripts/web.sh` builds the bundle (`target/web/`) and serves it; `scripts/test-web.sh`
//! drives it in headless Chromium.

pub mod check;
#[cfg(target_arch = "wasm32")]
mod page;
pub mod query;

/// The largest file the page reads: a page's WebAssembly memory is at most 4 GiB, and a file's
/// points need about as much again as its bytes (decompressed, parsed and staged for the GPU).
pub const MAX_FILE_BYTES: u64 = 1 << 30;

/// The refusal of a file of `bytes` bytes, before anything is allocated for it.
pub fn too_large(name: &str, bytes: u64) -> Option<String> {
    (bytes > MAX_FILE_BYTES).then(|| {
        let mib = |b: u64| b as f64 / (1 << 20) as f64;
        format!(
            "{name}: {:.0} MiB is more than this page can hold (at most {:.0} MiB a file): open it with `lineao view`",
            mib(bytes),
            mib(MAX_FILE_BYTES)
        )
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn files_over_the_limit_are_refused_by_size() {
        assert_eq!(super::too_large("a.trk", super::MAX_FILE_BYTES), None);
        let message = super::too_large("big.trk", 3 << 30).unwrap();
        assert!(message.contains("big.trk: 3072 MiB") && message.contains("at most 1024 MiB"), "{message}");
    }
}
