//! Opening files: format by content (the extension only breaks ties), gzip around anything,
//! zip or directory TRX, progress, and the limits that keep bombs bounded.

use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Seek, SeekFrom, Write};
use std::path::Path;

use crate::error::{Error, ErrorKind, Parse};
use crate::formats::{gltf, mrtrix, obj, trk, trx, tt, vtk, vtp};
use crate::input::{Limited, ProgressFn, ProgressRead, Reader};
use crate::tractogram::Tractogram;

/// The file formats we read. [`Format::name`] is the `format` of `lineao info --json`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// TrackVis `.trk`.
    Trk,
    /// MRtrix `.tck`.
    Tck,
    /// MRtrix track scalar file `.tsf` (values, no points).
    Tsf,
    /// TRX (`.trx`, a zip of arrays).
    Trx,
    /// Legacy VTK polydata `.vtk`.
    Vtk,
    /// VTK XML polydata `.vtp`.
    Vtp,
    /// DSI Studio `.tt.gz`.
    Tt,
    /// glTF lines (`.gltf`, `.glb`).
    Gltf,
    /// Wavefront OBJ `l` polylines.
    Obj,
}

impl Format {
    /// The name `lineao info --json` writes (`trk`, `tck`, …).
    pub fn name(self) -> &'static str {
        match self {
            Format::Trk => "trk",
            Format::Tck => "tck",
            Format::Tsf => "tsf",
            Format::Trx => "trx",
            Format::Vtk => "vtk",
            Format::Vtp => "vtp",
            Format::Tt => "tt",
            Format::Gltf => "gltf",
            Format::Obj => "obj",
        }
    }

    /// The format an extension names (`.gz` stripped first), used only when content is ambiguous
    /// and to pick a writer.
    pub fn from_path(path: &Path) -> Option<Format> {
        let name = path.file_name()?.to_string_lossy().to_ascii_lowercase();
        let name = name.strip_suffix(".gz").unwrap_or(&name);
        let ext = name.rsplit('.').next()?;
        Some(match ext {
            "trk" => Format::Trk,
            "tck" => Format::Tck,
            "tsf" => Format::Tsf,
            "trx" => Format::Trx,
            "vtk" => Format::Vtk,
            "vtp" => Format::Vtp,
            "tt" => Format::Tt,
            "gltf" | "glb" => Format::Gltf,
            "obj" => Format::Obj,
            _ => return None,
        })
    }
}

/// What wrapped the format's bytes. [`Compression::name`] is `compression` in `info --json`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compression {
    /// Stored as is.
    None,
    /// gzip-wrapped (`.gz`).
    Gzip,
    /// A zip archive (TRX).
    Zip,
}

impl Compression {
    /// The name `lineao info --json` writes (`none`, `gzip`, `zip`).
    pub fn name(self) -> &'static str {
        match self {
            Compression::None => "none",
            Compression::Gzip => "gzip",
            Compression::Zip => "zip",
        }
    }
}

/// Limits for [`load_with`].
#[derive(Clone, Copy, Debug, Default)]
pub struct LoadOptions {
    /// The most bytes any decompressor (gzip, zip member, VTP zlib block) may produce. `None`:
    /// 256 MiB or 64 × the file's size, whichever is larger — far above what float data
    /// compresses to (≈ 1.1–3 ×), far below what a bomb (up to 1032 × for deflate) asks for.
    pub max_inflated_bytes: Option<u64>,
}

impl LoadOptions {
    fn limit(&self, file_len: u64) -> u64 {
        self.max_inflated_bytes.unwrap_or((256u64 << 20).max(file_len.saturating_mul(64)))
    }
}

/// A loaded file: the streamlines and what the file was.
#[derive(Clone, Debug)]
pub struct Loaded {
    /// The streamlines and their data.
    pub tractogram: Tractogram,
    /// The format it was read as.
    pub format: Format,
    /// How it was compressed.
    pub compression: Compression,
}

/// Loads any supported file (or TRX directory) with default limits and no progress.
pub fn load(path: impl AsRef<Path>) -> Result<Loaded, Error> {
    load_with(path, &LoadOptions::default(), None)
}

/// Loads with explicit limits, reporting progress in bytes of the file read.
pub fn load_with(
    path: impl AsRef<Path>,
    options: &LoadOptions,
    progress: Option<ProgressFn<'_>>,
) -> Result<Loaded, Error> {
    let path = path.as_ref();
    load_inner(path, options, progress).map_err(|kind| kind.at(path))
}

fn load_inner(path: &Path, options: &LoadOptions, progress: Option<ProgressFn<'_>>) -> Parse<Loaded> {
    if path.is_dir() {
        if !trx::is_trx_dir(path) {
            return Err(ErrorKind::UnknownFormat("a directory without a TRX header.json".into()));
        }
        return Ok(Loaded {
            tractogram: checked(trx::read_dir(path)?)?,
            format: Format::Trx,
            compression: Compression::None,
        });
    }
    let file = File::open(path)?;
    let len = file.metadata()?.len();
    let mut file = ProgressRead::new(file, Some(len), progress);
    let loaded = load_from(&mut file, len, path, path.parent(), None, options);
    // Whatever a parser made of the failed read, the load was cancelled.
    let loaded = if file.cancelled { Err(ErrorKind::Cancelled) } else { loaded }?;
    file.finish();
    Ok(loaded)
}

/// Loads from bytes in memory (a download, an upload, a fuzzer's input). `name` only breaks
/// ties between formats as a file name would; glTF external buffers are refused.
pub fn load_from_bytes(bytes: &[u8], name: &str, options: &LoadOptions) -> Result<Loaded, Error> {
    load_from(std::io::Cursor::new(bytes), bytes.len() as u64, Path::new(name), None, None, options)
        .map_err(|k| k.at(name))
}

/// Parses bytes in memory as `format` (gzip-wrapped or not), skipping detection: one parser,
/// directly — what the fuzz targets drive.
pub fn parse_as(bytes: &[u8], format: Format, options: &LoadOptions) -> Result<Tractogram, ErrorKind> {
    let name = format!("memory.{}", format.name());
    load_from(std::io::Cursor::new(bytes), bytes.len() as u64, Path::new(&name), None, Some(format), options)
        .map(|l| l.tractogram)
}

/// The one loading path: zip → TRX; gzip → decompress (capped) and look again; then by content.
fn load_from<R: Read + Seek>(
    mut src: R,
    len: u64,
    name: &Path,
    dir: Option<&Path>,
    forced: Option<Format>,
    options: &LoadOptions,
) -> Parse<Loaded> {
    let limit = options.limit(len);
    let mut magic = [0u8; 4];
    let got = read_up_to(&mut src, &mut magic)?;
    src.seek(SeekFrom::Start(0))?;
    if forced.map_or(trx::sniff(&magic[..got]), |f| f == Format::Trx) {
        let t = trx::read_zip(src, len, limit)?;
        return Ok(Loaded { tractogram: checked(t)?, format: Format::Trx, compression: Compression::Zip });
    }
    let gzip = magic[..got].starts_with(&[0x1f, 0x8b]);
    let compression = if gzip { Compression::Gzip } else { Compression::None };
    let stream: Box<dyn Read + '_> = if gzip {
        let decoder = flate2::read::MultiGzDecoder::new(BufReader::with_capacity(1 << 16, src));
        Box::new(Limited { inner: decoder, left: limit, limit })
    } else {
        Box::new(src)
    };
    let mut r = Reader::new(stream);
    let size_hint = (!gzip).then_some(len);
    let head = r.peek(4096)?.to_vec();
    let format = match forced {
        Some(f) => f,
        None => detect(&head, name)?,
    };
    let tractogram = match format {
        Format::Trk => trk::read(&mut r, size_hint)?,
        Format::Tck | Format::Tsf => mrtrix::read(&mut r, size_hint)?.0,
        Format::Trx => return Err(ErrorKind::Unsupported("a TRX zip inside gzip".into())),
        other => {
            let bytes = r.read_to_end()?;
            match other {
                Format::Vtk => vtk::read(&bytes)?,
                Format::Vtp => vtp::read(&bytes, limit)?,
                Format::Tt => tt::read(&bytes)?,
                Format::Gltf => gltf::read(&bytes, dir, limit)?,
                _ => obj::read(&bytes)?,
            }
        }
    };
    Ok(Loaded { tractogram: checked(tractogram)?, format, compression })
}

/// Content first; the name only decides between text formats that look alike.
pub(crate) fn detect(head: &[u8], path: &Path) -> Parse<Format> {
    if trk::sniff(head) {
        return Ok(Format::Trk);
    }
    if let Some(scalars) = mrtrix::sniff(head) {
        return Ok(if scalars { Format::Tsf } else { Format::Tck });
    }
    if vtk::sniff(head) {
        return Ok(Format::Vtk);
    }
    if vtp::sniff(head) {
        return Ok(Format::Vtp);
    }
    if gltf::sniff(head) {
        return Ok(Format::Gltf);
    }
    if trx::sniff(head) {
        return Ok(Format::Trx);
    }
    if tt::sniff(head) {
        return Ok(Format::Tt);
    }
    if obj::sniff(head) {
        return Ok(Format::Obj);
    }
    // Nothing matched: let the parser the name asks for say precisely what is wrong.
    if let Some(format) = Format::from_path(path).filter(|f| *f != Format::Trx) {
        return Ok(format);
    }
    if crate::volume::is_nifti(head) {
        let what = "a NIfTI volume, an image and not streamlines: open it as the anatomy beside a tractogram";
        return Err(ErrorKind::UnknownFormat(what.into()));
    }
    let shown: String = head.iter().take(16).map(|&b| if b.is_ascii_graphic() { b as char } else { '.' }).collect();
    Err(ErrorKind::UnknownFormat(format!("the file starts with '{shown}'")))
}

fn read_up_to(f: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut n = 0;
    while n < buf.len() {
        match f.read(&mut buf[n..])? {
            0 => break,
            k => n += k,
        }
    }
    Ok(n)
}

fn checked(t: Tractogram) -> Parse<Tractogram> {
    match t.validate() {
        Ok(()) => Ok(t),
        // The parsers guarantee these invariants; reaching this is a bug, reported, not a panic.
        Err(e) => Err(ErrorKind::Format { offset: 0, expected: format!("a consistent tractogram ({e})") }),
    }
}

/// Writes `t` as `.tck`, `.trk` or `.trx`, chosen by `path`'s extension. Returns the names of
/// fields the format cannot hold (TrackVis: more than ten names, long names). A failed write
/// removes the partial file.
pub fn save(t: &Tractogram, path: impl AsRef<Path>) -> Result<Vec<String>, Error> {
    let path = path.as_ref();
    let format = match Format::from_path(path) {
        Some(f @ (Format::Tck | Format::Trk | Format::Trx)) => f,
        _ => {
            let ext = path.extension().map(|e| e.to_string_lossy().to_string()).unwrap_or_default();
            return Err(ErrorKind::Unsupported(format!("writing '{ext}': we write .tck, .trk and .trx")).at(path));
        }
    };
    if !t.has_points() {
        return Err(
            ErrorKind::Unsupported("values without points (a .tsf) cannot be written as streamlines".into()).at(path)
        );
    }
    let write = || -> std::io::Result<Vec<String>> {
        let file = File::create(path)?;
        if format == Format::Trx {
            return trx::write(t, BufWriter::new(file)).map(|_| Vec::new());
        }
        let mut out = BufWriter::with_capacity(1 << 20, file);
        let dropped = if format == Format::Tck {
            mrtrix::write_tck(t, &mut out)?;
            t.vertex_fields.iter().chain(&t.streamline_fields).map(|f| f.name.clone()).collect()
        } else {
            trk::write(t, &mut out)?
        };
        out.flush()?;
        Ok(dropped)
    };
    write().map_err(|e| {
        let _ = std::fs::remove_file(path);
        ErrorKind::Io(e).at(path)
    })
}
