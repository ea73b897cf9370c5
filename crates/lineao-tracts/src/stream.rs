//! Files delivered in chunks as they are read: a whole-brain tractogram (100 M–1 G points) is
//! drawn while it loads and never held whole as f32.
//!
//! [`ChunkDecoder`] is *pushed* bytes — a file read piece by piece ([`load_chunked`]), a
//! download or a dropped file as the browser hands it over — and hands whole streamlines, in
//! file order, to a sink in chunks: a chunk goes as soon as it holds `chunk_vertices` points,
//! so it holds fewer than `chunk_vertices` plus the longest streamline. Each chunk is a [`Tractogram`] of its streamlines with their
//! per-vertex and per-streamline fields; what belongs to the whole file (the voxel grid, the
//! groups, the format) comes back from [`ChunkDecoder::finish`] as a [`Streamed`].
//!
//! - MRtrix `.tck`/`.tsf` and TrackVis `.trk` are decoded as the bytes arrive: the header is
//!   parsed once it is complete, then records as they complete; a record split between two
//!   pushes waits for the rest. Memory is one chunk and one record.
//! - gzip around them is decompressed as it arrives (flate2's push decoder), capped as
//!   [`crate::load`] caps it.
//! - The other formats (TRX zip, VTK, VTP, DSI Studio, glTF, OBJ) need their whole file — a
//!   zip's directory is at its end, the text formats hold their counts after the data — so their
//!   bytes are kept until [`ChunkDecoder::finish`], parsed by [`crate::load_from_bytes`] and
//!   then handed over in chunks. A TRX directory is read whole the same way.
//!
//! Errors are the whole-file loaders' — the same kind, byte offset and words for a file cut
//! short inside its data — raised when found: what was handed over before stays handed over.

use std::io::{self, Read, Write};
use std::ops::ControlFlow;
use std::path::Path;

use crate::error::{Error, ErrorKind, Parse, bad};
use crate::formats::{mrtrix, trk};
use crate::input::{Endian, ProgressFn, Reader};
use crate::load::{Compression, Format, LoadOptions, Loaded, detect, load_from_bytes};
use crate::tractogram::{Field, Group, Tractogram, VoxelSpace};

/// What a file was, once all its chunks were handed over.
#[derive(Clone, Debug, Default)]
pub struct Streamed {
    /// The format detected from the first bytes.
    pub format: Option<Format>,
    /// The compression detected from the first bytes.
    pub compression: Option<Compression>,
    /// Streamlines decoded.
    pub streamlines: u64,
    /// Points decoded.
    pub vertices: u64,
    /// The voxel grid the streamlines were tracked in, where the format records one.
    pub space: Option<VoxelSpace>,
    /// Named subsets of streamlines, by index in the whole file (TRX groups).
    pub groups: Vec<Group>,
    /// Whether the file holds points (a `.tsf` holds values only: its chunks have none).
    pub has_points: bool,
}

/// Where a chunk goes; `Break` stops the load (which then fails with [`ErrorKind::Cancelled`]).
pub type ChunkSink<'a> = &'a mut dyn FnMut(Tractogram) -> ControlFlow<()>;

/// A sink a [`ChunkDecoder`] owns (a decoder kept between pushes holds its own).
type OwnedSink<'s> = Box<dyn FnMut(Tractogram) -> ControlFlow<()> + 's>;

/// Bytes kept before the format is known (as many as detection looks at).
const SNIFF: usize = 4096;
/// The largest `.tck` header we wait for before giving up on its END line.
const MAX_TCK_HEADER: usize = 64 << 20;

/// A decoder that bytes are pushed into (see the module documentation).
pub struct ChunkDecoder<'s> {
    name: String,
    options: LoadOptions,
    /// The file's size when known (decompression is capped by it).
    size_hint: Option<u64>,
    state: State<'s>,
}

enum State<'s> {
    /// Too few bytes yet to tell gzip or zip from the rest.
    Start(Vec<u8>, Body<'s>),
    Gzip(Box<flate2::write::MultiGzDecoder<Body<'s>>>),
    Plain(Body<'s>),
    Done,
}

/// The decompressed bytes' decoder: it implements `Write`, so flate2 can push into it.
struct Body<'s> {
    /// Bytes of this stream received so far (decompressed for gzip).
    received: u64,
    /// Whether the bytes come out of a decompressor, and the most it may produce.
    limit: Option<u64>,
    /// Received but not yet decoded: a partial header or record.
    pending: Vec<u8>,
    /// Stream offset of `pending[0]`.
    pending_at: u64,
    format: Decoding,
    chunk: Chunker<'s>,
    /// The first error, kept here because flate2 sees only `io::Error`s.
    error: Option<ErrorKind>,
    name: String,
    /// The format, once detected, and the voxel grid its header records.
    detected: Option<Format>,
    space: Option<VoxelSpace>,
}

enum Decoding {
    /// Not enough bytes to tell the format.
    Detecting,
    Tck(Tck),
    Trk(Box<Trk>),
    /// A format parsed whole at the end: its bytes so far.
    Whole(Format),
    /// An Inf (tck) or the header's count (trk) ended the data; the rest is ignored.
    Ended,
}

/// A `.tck`/`.tsf` after its header.
#[derive(Clone, Copy)]
struct Tck {
    /// Stream offsets where the header ends and the data starts.
    header_end: u64,
    data_at: u64,
    width: usize,
    endian: Endian,
    scalars: bool,
}

/// A `.trk` after its header.
struct Trk {
    header: trk::Header,
    decoder: trk::Decoder,
    streamlines: u64,
}

/// Collects whole streamlines into chunks and hands them over.
struct Chunker<'s> {
    chunk_vertices: usize,
    current: Tractogram,
    /// The vertex count of the current streamline so far (tck, tsf: values without an end yet).
    open: u64,
    streamlines: u64,
    vertices: u64,
    /// `None` once its decoder is finished.
    sink: Option<OwnedSink<'s>>,
    cancelled: bool,
    /// Empty fields of every chunk (trk scalars and properties, the tsf's values).
    vertex_fields: Vec<Field>,
    streamline_fields: Vec<Field>,
}

impl<'s> Chunker<'s> {
    fn new(chunk_vertices: usize, sink: Option<OwnedSink<'s>>) -> Chunker<'s> {
        Chunker {
            chunk_vertices: chunk_vertices.max(1),
            current: Tractogram::new(),
            open: 0,
            streamlines: 0,
            vertices: 0,
            sink,
            cancelled: false,
            vertex_fields: Vec::new(),
            streamline_fields: Vec::new(),
        }
    }

    fn set_fields(&mut self, vertex: Vec<Field>, streamline: Vec<Field>) {
        self.current.vertex_fields = vertex.clone();
        self.current.streamline_fields = streamline.clone();
        (self.vertex_fields, self.streamline_fields) = (vertex, streamline);
    }

    /// Vertices in the current chunk (points, or a tsf's values).
    fn chunk_len(&self) -> u64 {
        *self.current.offsets.last().unwrap_or(&0) + self.open
    }

    /// Ends the open streamline, handing the chunk over when it is full.
    fn end_streamline(&mut self) {
        let end = self.chunk_len();
        self.current.offsets.push(end);
        self.open = 0;
        self.streamlines += 1;
        if end as usize >= self.chunk_vertices {
            self.hand_over();
        }
    }

    fn hand_over(&mut self) {
        if self.current.streamlines() == 0 || self.cancelled {
            return;
        }
        let empty = Tractogram {
            vertex_fields: self.vertex_fields.clone(),
            streamline_fields: self.streamline_fields.clone(),
            ..Tractogram::new()
        };
        let chunk = std::mem::replace(&mut self.current, empty);
        self.vertices += chunk.offsets.last().copied().unwrap_or(0);
        if self.sink.as_mut().is_some_and(|sink| sink(chunk).is_break()) {
            self.cancelled = true;
        }
    }

    /// Hands over `t`, a whole file parsed at once, in chunks.
    fn split(&mut self, t: &Tractogram) {
        let mut first = 0;
        while first < t.streamlines() && !self.cancelled {
            let start = t.offsets[first];
            let mut last = first + 1;
            while last < t.streamlines() && (t.offsets[last + 1] - start) as usize <= self.chunk_vertices {
                last += 1;
            }
            self.current = slice(t, first..last);
            self.streamlines += (last - first) as u64;
            self.hand_over();
            first = last;
        }
    }
}

/// Streamlines `range` of `t` with their fields (offsets from 0; no groups, no space).
fn slice(t: &Tractogram, range: std::ops::Range<usize>) -> Tractogram {
    let (v0, v1) = (t.offsets[range.start] as usize, t.offsets[range.end] as usize);
    let rows = |f: &Field, a: usize, b: usize| Field {
        name: f.name.clone(),
        columns: f.columns,
        values: f.values[a * f.columns..b * f.columns].to_vec(),
    };
    Tractogram {
        positions: if t.has_points() { t.positions[v0..v1].to_vec() } else { Vec::new() },
        offsets: t.offsets[range.start..=range.end].iter().map(|o| o - v0 as u64).collect(),
        vertex_fields: t.vertex_fields.iter().map(|f| rows(f, v0, v1)).collect(),
        streamline_fields: t.streamline_fields.iter().map(|f| rows(f, range.start, range.end)).collect(),
        groups: Vec::new(),
        space: None,
    }
}

impl<'s> ChunkDecoder<'s> {
    /// A decoder for the file `name` (its extension breaks ties between formats) that hands
    /// chunks of at most `chunk_vertices` points to `sink`; `size_hint` is the file's size
    /// when known (it sets the decompression cap as [`crate::load`]'s).
    pub fn new(
        name: &str,
        options: &LoadOptions,
        size_hint: Option<u64>,
        chunk_vertices: usize,
        sink: impl FnMut(Tractogram) -> ControlFlow<()> + 's,
    ) -> Self {
        let body = Body {
            received: 0,
            limit: None,
            pending: Vec::new(),
            pending_at: 0,
            format: Decoding::Detecting,
            chunk: Chunker::new(chunk_vertices, Some(Box::new(sink))),
            error: None,
            name: name.to_string(),
            detected: None,
            space: None,
        };
        ChunkDecoder { name: name.to_string(), options: *options, size_hint, state: State::Start(Vec::new(), body) }
    }

    /// Decodes `bytes`, the next piece of the file; chunks that complete are handed over.
    pub fn push(&mut self, bytes: &[u8]) -> Result<(), Error> {
        self.push_inner(bytes).map_err(|kind| kind.at(&self.name))
    }

    fn push_inner(&mut self, bytes: &[u8]) -> Parse<()> {
        match std::mem::replace(&mut self.state, State::Done) {
            State::Start(mut head, body) => {
                head.extend_from_slice(bytes);
                if head.len() < 4 {
                    self.state = State::Start(head, body);
                    return Ok(());
                }
                self.begin(head, body)
            }
            State::Gzip(mut decoder) => {
                let result = decoder.write_all(bytes);
                let outcome = gzip_outcome(decoder.get_mut(), result);
                self.state = State::Gzip(decoder);
                outcome
            }
            State::Plain(mut body) => {
                let result = body.take(bytes);
                self.state = State::Plain(body);
                result
            }
            State::Done => Err(ErrorKind::Unsupported("pushing into a finished decoder".into())),
        }
    }

    /// With the first bytes: gzip, a zip (TRX, parsed whole) or anything else.
    fn begin(&mut self, head: Vec<u8>, mut body: Body<'s>) -> Parse<()> {
        let limit = self
            .options
            .max_inflated_bytes
            .unwrap_or((256u64 << 20).max(self.size_hint.unwrap_or(0).saturating_mul(64)));
        if crate::formats::trx::sniff(&head) {
            body.format = Decoding::Whole(Format::Trx);
            let result = body.take(&head);
            self.state = State::Plain(body);
            return result;
        }
        if head.starts_with(&[0x1f, 0x8b]) {
            body.limit = Some(limit);
            let mut decoder = Box::new(flate2::write::MultiGzDecoder::new(body));
            let result = decoder.write_all(&head);
            let outcome = gzip_outcome(decoder.get_mut(), result);
            self.state = State::Gzip(decoder);
            return outcome;
        }
        let result = body.take(&head);
        self.state = State::Plain(body);
        result
    }

    /// The end of the file: what is pending is decoded (or a whole-file format parsed) and
    /// handed over; a file cut short is the error the whole-file loader gives.
    pub fn finish(mut self) -> Result<Streamed, Error> {
        let name = self.name.clone();
        self.finish_inner().map_err(|kind| kind.at(name))
    }

    fn finish_inner(&mut self) -> Parse<Streamed> {
        let (mut body, compression) = match std::mem::replace(&mut self.state, State::Done) {
            State::Start(head, body) => {
                let mut body = body;
                body.take(&head)?;
                (body, Compression::None)
            }
            State::Plain(body) => {
                let compression = if matches!(body.format, Decoding::Whole(Format::Trx)) {
                    Compression::Zip
                } else {
                    Compression::None
                };
                (body, compression)
            }
            State::Gzip(decoder) => {
                let mut decoder = *decoder;
                // A gzip stream that ends early, as the whole-file loader's decompressor reads
                // it: cut inside its deflate data, the data is cut short there — unless the
                // format's data had ended (a .trk's count, a .tck's Inf), where that loader
                // reads no further; cut inside its 8-byte trailer (flate2 says InvalidInput),
                // all the data is there.
                let ended = matches!(decoder.get_ref().format, Decoding::Ended);
                let result = match decoder.try_finish() {
                    Err(_) if decoder.get_ref().error.is_some() => Err(io::Error::other("decoding stopped")),
                    Err(e) if ended || e.kind() == io::ErrorKind::InvalidInput => Ok(()),
                    Err(_) => {
                        let offset = decoder.get_ref().received;
                        return Err(ErrorKind::Format { offset, expected: "more data (the file ends)".into() });
                    }
                    Ok(()) => Ok(()),
                };
                gzip_outcome(decoder.get_mut(), result)?;
                let body = std::mem::replace(decoder.get_mut(), Body::finished());
                (body, Compression::Gzip)
            }
            State::Done => return Err(ErrorKind::Unsupported("finishing a finished decoder".into())),
        };
        let mut streamed = body.end(&self.name, &self.options)?;
        if body.chunk.cancelled {
            return Err(ErrorKind::Cancelled);
        }
        streamed.compression = Some(compression);
        streamed.streamlines = body.chunk.streamlines;
        streamed.vertices = body.chunk.vertices;
        Ok(streamed)
    }
}

/// What a write into flate2's decoder came to: our own error first (flate2 sees only a
/// generic one), then the decompressor's.
fn gzip_outcome(body: &mut Body, result: io::Result<()>) -> Parse<()> {
    if let Some(error) = body.error.take() {
        return Err(error);
    }
    result.map_err(|e| crate::input::io_error(e, body.received, "more gzip data"))
}

impl Write for Body<'_> {
    fn write(&mut self, bytes: &[u8]) -> io::Result<usize> {
        if self.error.is_some() {
            return Err(io::Error::other("decoding stopped"));
        }
        match self.take(bytes) {
            Ok(()) => Ok(bytes.len()),
            Err(kind) => {
                self.error = Some(kind);
                Err(io::Error::other("decoding stopped"))
            }
        }
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

impl<'s> Body<'s> {
    /// A body left behind in a finished decoder.
    fn finished() -> Body<'s> {
        Body {
            received: 0,
            limit: None,
            pending: Vec::new(),
            pending_at: 0,
            format: Decoding::Ended,
            chunk: Chunker::new(1, None),
            error: None,
            name: String::new(),
            detected: None,
            space: None,
        }
    }

    /// Takes the next bytes of the (decompressed) stream and decodes what completes.
    fn take(&mut self, bytes: &[u8]) -> Parse<()> {
        if let Some(limit) = self.limit
            && self.received + bytes.len() as u64 > limit
        {
            return Err(ErrorKind::TooLarge { offset: limit, limit });
        }
        self.received += bytes.len() as u64;
        if self.chunk.cancelled {
            return Err(ErrorKind::Cancelled);
        }
        match self.format {
            Decoding::Ended => return Ok(()),
            Decoding::Whole(_) => {
                self.pending.extend_from_slice(bytes);
                return Ok(());
            }
            _ => self.pending.extend_from_slice(bytes),
        }
        self.decode(false)
    }

    /// Decodes as much of `pending` as is whole; at the end of the stream (`last`) the rest.
    fn decode(&mut self, last: bool) -> Parse<()> {
        if let Decoding::Detecting = self.format {
            if self.pending.len() < SNIFF && !last {
                return Ok(());
            }
            let head = &self.pending[..self.pending.len().min(SNIFF)];
            let format = detect(head, Path::new(&self.name))?;
            self.detected = Some(format);
            self.format = match format {
                Format::Tck | Format::Tsf | Format::Trk => Decoding::Detecting,
                other => Decoding::Whole(other),
            };
            match format {
                Format::Tck | Format::Tsf => self.tck_header(last)?,
                Format::Trk => self.trk_header(last)?,
                _ => return Ok(()),
            }
        }
        let consumed = match &mut self.format {
            Decoding::Tck(tck) => {
                let tck = *tck;
                self.tck_data(&tck, last)?
            }
            Decoding::Trk(_) => self.trk_data(last)?,
            _ => 0,
        };
        self.pending.drain(..consumed);
        self.pending_at += consumed as u64;
        if matches!(self.format, Decoding::Ended) {
            self.pending.clear();
        }
        Ok(())
    }

    /// Parses the `.tck`/`.tsf` header once its END line is in (at the end: whatever is in,
    /// for the whole-file loader's error).
    fn tck_header(&mut self, last: bool) -> Parse<()> {
        let end = self.pending.split_inclusive(|&b| b == b'\n').scan(0usize, |at, line| {
            *at += line.len();
            Some((*at, line))
        });
        let end = end.skip(1).find(|(_, line)| line.trim_ascii() == b"END").map(|(at, _)| at);
        let header_bytes = match end {
            Some(end) => &self.pending[..end],
            None if last => &self.pending[..],
            None if self.pending.len() > MAX_TCK_HEADER => {
                return bad(0, format!("a header that ends in an END line within {MAX_TCK_HEADER} bytes"));
            }
            None => return Ok(()),
        };
        let mut r = Reader::new(header_bytes);
        let header = mrtrix::read_header(&mut r)?;
        let header_end = r.offset();
        let (width, endian) = mrtrix::datatype(&header, header_end)?;
        let data_at = mrtrix::data_offset(&header, header_end)?;
        if header.scalars {
            self.chunk.set_fields(vec![Field { name: "tsf".into(), columns: 1, values: Vec::new() }], Vec::new());
        }
        self.chunk.current.offsets = vec![0];
        self.format = Decoding::Tck(Tck { header_end, data_at, width, endian, scalars: header.scalars });
        Ok(())
    }

    /// Decodes whole elements of `pending` (after the data offset); returns the bytes used.
    fn tck_data(&mut self, tck: &Tck, last: bool) -> Parse<usize> {
        let element = if tck.scalars { tck.width } else { 3 * tck.width };
        // Skip the padding up to the data offset.
        let skip = tck.data_at.saturating_sub(self.pending_at).min(self.pending.len() as u64) as usize;
        if self.pending_at + (skip as u64) < tck.data_at {
            if last {
                return Err(padding_cut_short(tck, self.received));
            }
            return Ok(skip);
        }
        let bytes = &self.pending[skip..];
        let whole = bytes.len() / element * element;
        let decode = |b: &[u8]| -> f32 {
            match (tck.width, tck.endian) {
                (4, e) => e.f32(b),
                (_, Endian::Little) => f64::from_le_bytes(b[..8].try_into().unwrap()) as f32,
                (_, Endian::Big) => f64::from_be_bytes(b[..8].try_into().unwrap()) as f32,
            }
        };
        let mut used = 0;
        for e in bytes[..whole].chunks_exact(element) {
            used += element;
            let x = decode(e);
            if x.is_nan() {
                self.chunk.end_streamline();
            } else if x.is_infinite() {
                self.format = Decoding::Ended;
                break;
            } else {
                if tck.scalars {
                    self.chunk.current.vertex_fields[0].values.push(x);
                } else {
                    let w = tck.width;
                    self.chunk.current.positions.push([x, decode(&e[w..]), decode(&e[2 * w..])]);
                }
                self.chunk.open += 1;
            }
            if self.chunk.cancelled {
                return Err(ErrorKind::Cancelled);
            }
        }
        if last && !matches!(self.format, Decoding::Ended) && whole < bytes.len() {
            return bad(self.pending_at + (skip + whole) as u64, mrtrix::truncated_element(element, tck.scalars));
        }
        Ok(skip + used)
    }

    fn trk_header(&mut self, last: bool) -> Parse<()> {
        if self.pending.len() < trk::HEADER_SIZE {
            if last {
                return bad(
                    0,
                    format!(
                        "a 1000-byte TrackVis header ({} bytes; the file ends after {} more)",
                        trk::HEADER_SIZE,
                        self.pending.len()
                    ),
                );
            }
            return Ok(());
        }
        let header = trk::parse_header(&self.pending[..trk::HEADER_SIZE])?;
        let decoder = trk::Decoder::new(&header);
        self.space = Some(header.space());
        let (vertex, streamline) = header.fields();
        self.chunk.set_fields(vertex, streamline);
        self.chunk.current.offsets = vec![0];
        self.pending.drain(..trk::HEADER_SIZE);
        self.pending_at += trk::HEADER_SIZE as u64;
        self.format = Decoding::Trk(Box::new(Trk { header, decoder, streamlines: 0 }));
        Ok(())
    }

    /// Decodes whole streamline records of `pending`; returns the bytes used.
    fn trk_data(&mut self, last: bool) -> Parse<usize> {
        let Decoding::Trk(trk) = &mut self.format else { return Ok(0) };
        let mut at = 0usize;
        let mut ended = false;
        loop {
            if trk.header.n_count != 0 && trk.streamlines >= trk.header.n_count {
                ended = true;
                break;
            }
            let offset = self.pending_at + at as u64;
            let rest = &self.pending[at..];
            if rest.is_empty() {
                break;
            }
            if rest.len() < 4 {
                if last {
                    return bad(offset, "a streamline's point count (4 bytes)");
                }
                break;
            }
            let n = trk.header.endian.i32(rest);
            let need = trk.decoder.record_bytes(n, offset)?;
            if need > rest.len() - 4 {
                if last {
                    return bad(offset + 4, format!("{n} points of {} bytes and the properties", trk.decoder.record));
                }
                break;
            }
            let record = trk.decoder.record;
            let body = &rest[4..4 + need];
            for p in body[..n as usize * record].chunks_exact(record) {
                trk.decoder.scalars(&p[12..], &mut self.chunk.current.vertex_fields);
                self.chunk.current.positions.push(trk.decoder.point(p[..12].try_into().unwrap()));
            }
            trk.decoder.properties(&body[n as usize * record..], &mut self.chunk.current.streamline_fields);
            self.chunk.open = n as u64;
            trk.streamlines += 1;
            self.chunk.end_streamline();
            at += 4 + need;
            if self.chunk.cancelled {
                return Err(ErrorKind::Cancelled);
            }
        }
        if ended {
            self.format = Decoding::Ended;
        }
        Ok(at)
    }

    /// The end of the stream: decodes the rest, or parses a whole-file format, and hands over
    /// the last chunk.
    fn end(&mut self, name: &str, options: &LoadOptions) -> Parse<Streamed> {
        if let Decoding::Detecting = self.format {
            // A file shorter than what detection looks at: its format now.
            self.decode(true)?;
        }
        if let Decoding::Whole(_) = self.format {
            let bytes = std::mem::take(&mut self.pending);
            let Loaded { tractogram, format, .. } = load_from_bytes(&bytes, name, options).map_err(|e| e.kind)?;
            drop(bytes);
            self.chunk.split(&tractogram);
            return Ok(Streamed {
                format: Some(format),
                space: tractogram.space,
                has_points: tractogram.has_points(),
                groups: tractogram.groups,
                ..Streamed::default()
            });
        }
        if !matches!(self.format, Decoding::Ended) {
            self.decode(true)?;
        }
        // A missing NaN before the Inf, or a missing Inf: the data still ends the last
        // streamline (tck); the last chunk goes.
        if self.chunk.open > 0 {
            self.chunk.end_streamline();
        }
        self.chunk.hand_over();
        Ok(Streamed {
            format: self.detected,
            space: self.space,
            has_points: self.detected != Some(Format::Tsf),
            ..Streamed::default()
        })
    }
}

/// The whole-file loader's words for a `.tck` that ends before its data offset, after
/// `received` bytes: it skips the padding in steps of at most [`Reader::CHUNK`] bytes, and the
/// step the file ends in fails.
fn padding_cut_short(tck: &Tck, received: u64) -> ErrorKind {
    let (mut at, mut left) = (tck.header_end, tck.data_at - tck.header_end);
    loop {
        let step = left.min(Reader::CHUNK as u64);
        if received - at < step {
            return ErrorKind::Format {
                offset: at,
                expected: format!(
                    "the padding before the data offset ({step} bytes; the file ends after {} more)",
                    received - at
                ),
            };
        }
        at += step;
        left -= step;
    }
}

/// Reads the file (or TRX directory) at `path` and hands its streamlines to `sink` in chunks
/// of at most `chunk_vertices` points as they are read (see the module documentation),
/// reporting the bytes read to `progress`, which may cancel.
pub fn load_chunked(
    path: impl AsRef<Path>,
    options: &LoadOptions,
    chunk_vertices: usize,
    progress: Option<ProgressFn<'_>>,
    sink: ChunkSink<'_>,
) -> Result<Streamed, Error> {
    let path = path.as_ref();
    let name = path.display().to_string();
    if path.is_dir() {
        return whole_in_chunks(path, options, chunk_vertices, progress, sink);
    }
    let mut file = std::fs::File::open(path).map_err(|e| ErrorKind::Io(e).at(path))?;
    let size = file.metadata().map_err(|e| ErrorKind::Io(e).at(path))?.len();
    // Formats read whole are read by the file loader (a glTF's buffers lie beside it).
    let mut head = Vec::with_capacity(SNIFF);
    (&mut file).take(SNIFF as u64).read_to_end(&mut head).map_err(|e| ErrorKind::Io(e).at(path))?;
    let pushed = head.starts_with(&[0x1f, 0x8b])
        || matches!(detect(&head, path), Ok(Format::Tck | Format::Tsf | Format::Trk) | Err(_));
    if !pushed {
        return whole_in_chunks(path, options, chunk_vertices, progress, sink);
    }
    let mut decoder = ChunkDecoder::new(&name, options, Some(size), chunk_vertices, sink);
    decoder.push(&head)?;
    let mut progress = progress;
    let mut buffer = vec![0u8; 4 << 20];
    let mut read = head.len() as u64;
    loop {
        let n = match file.read(&mut buffer) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(ErrorKind::Io(e).at(path)),
        };
        decoder.push(&buffer[..n])?;
        read += n as u64;
        if let Some(report) = progress.as_mut()
            && report(crate::Progress { bytes: read, total: Some(size) }).is_break()
        {
            return Err(ErrorKind::Cancelled.at(path));
        }
    }
    decoder.finish()
}

/// A file (or TRX directory) of a format read whole, handed over in chunks.
fn whole_in_chunks(
    path: &Path,
    options: &LoadOptions,
    chunk_vertices: usize,
    progress: Option<ProgressFn<'_>>,
    sink: ChunkSink<'_>,
) -> Result<Streamed, Error> {
    let loaded = crate::load_with(path, options, progress)?;
    let mut chunker = Chunker::new(chunk_vertices, Some(Box::new(sink)));
    chunker.split(&loaded.tractogram);
    if chunker.cancelled {
        return Err(ErrorKind::Cancelled.at(path));
    }
    let t = loaded.tractogram;
    Ok(Streamed {
        format: Some(loaded.format),
        compression: Some(loaded.compression),
        streamlines: chunker.streamlines,
        vertices: chunker.vertices,
        space: t.space,
        has_points: t.has_points(),
        groups: t.groups,
    })
}
