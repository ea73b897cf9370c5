//! lineao's viewer in a web page, on WebGPU: the native viewer's app (`lineao_cli::view`) run
//! by eframe's web runner, with its worker stepped on the page's thread (a page has no
//! threads) and rendering on the page's one device.
//!
//! - [`query`]: the page's URL as `lineao view`'s options (`?url=`, `?scene=`, methods,
//!   preset, camera), and the link of a view.
//! - `page` (wasm32 only): the runner; files dropped, picked or fetched and drawn as they
//!   arrive (a size limit only for the formats read whole); `window.lineaoStatus`; the AO and
//!   ND maps read back for tests.
//! - [`check`]: natively, a page's read-back maps against lineao's CPU reference.
//!
//! `scripts/web.sh` builds the bundle (`target/web/`) and serves it; `scripts/test-web.sh`
//! drives it in headless Chromium.

pub mod check;
#[cfg(target_arch = "wasm32")]
mod page;
pub mod query;

/// The largest file of a format read whole (TRX, VTK, VTP, DSI Studio, glTF, OBJ) the page
/// reads: a page's WebAssembly memory is at most 4 GiB, and such a file's points need about as
/// much again as its bytes. A .tck, .tsf or .trk (gzip or not) is decoded as it arrives and
/// has no such limit.
pub const MAX_FILE_BYTES: u64 = 1 << 30;

/// The most of a streamed file the page keeps by default (the URL's `hold=MIB`), to read its
/// points again for the ray tracer's BVH: about 22 M points, whose BVH (31 bytes a point) still
/// fits beside them in the page's 4 GiB; a larger file is drawn and not kept.
pub const HOLD_BYTES: u64 = 256 << 20;

/// Whether the page decodes a file named `name` as it arrives (by its extension, `.gz` aside).
pub fn streamed(name: &str) -> bool {
    let name = name.to_ascii_lowercase();
    let name = name.strip_suffix(".gz").unwrap_or(&name);
    [".tck", ".tsf", ".trk"].iter().any(|ext| name.ends_with(ext))
}

/// The refusal of a file of `bytes` bytes, before anything is allocated for it: a format read
/// whole, over [`MAX_FILE_BYTES`].
pub fn too_large(name: &str, bytes: u64) -> Option<String> {
    if streamed(name) { None } else { too_large_whole(name, bytes) }
}

/// The refusal of `bytes` bytes of a file the page holds whole whatever its format (the file
/// that colours the lines), over [`MAX_FILE_BYTES`].
pub fn too_large_whole(name: &str, bytes: u64) -> Option<String> {
    (bytes > MAX_FILE_BYTES).then(|| {
        let mib = |b: u64| b as f64 / (1 << 20) as f64;
        format!(
            "{name}: {:.0} MiB is more than this page can hold (at most {:.0} MiB a file): open it with `lineao view`",
            mib(bytes),
            mib(MAX_FILE_BYTES)
        )
    })
}

/// The NIfTI volume in `bytes` (gzip or not), read from `name`: what the page shows as slices,
/// or samples to colour the lines by. Inflated to at most 256 MiB or 64 × the file, whichever
/// is larger (the loaders' limit).
pub fn volume(name: &str, bytes: &[u8]) -> Result<lineao_tracts::Volume, String> {
    let limit = (256u64 << 20).max((bytes.len() as u64).saturating_mul(64));
    lineao_tracts::Volume::from_bytes(bytes, limit).map_err(|kind| kind.at(std::path::Path::new(name)).to_string())
}

#[cfg(test)]
mod tests {
    #[test]
    fn files_over_the_limit_are_refused_by_size() {
        assert_eq!(super::too_large("a.trx", super::MAX_FILE_BYTES), None);
        let message = super::too_large("big.trx", 3 << 30).unwrap();
        assert!(message.contains("big.trx: 3072 MiB") && message.contains("at most 1024 MiB"), "{message}");
        // What is decoded as it arrives has no limit, unless the page holds it whole.
        for name in ["big.trk", "big.tck.gz", "big.TSF"] {
            assert_eq!(super::too_large(name, 3 << 30), None, "{name}");
            assert!(super::too_large_whole(name, 3 << 30).is_some_and(|m| m.contains("3072 MiB")), "{name}");
        }
    }

    #[test]
    fn a_volume_that_cannot_be_read_names_its_file() {
        let message = super::volume("data/t1.nii.gz", &[0x1f, 0x8b, 0, 0]).unwrap_err();
        assert!(message.starts_with("data/t1.nii.gz") && message.contains("gzip"), "{message}");
    }
}
