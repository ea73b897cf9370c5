//! Byte sources for the parsers: a buffered reader that knows its offset, progress reporting on
//! the file itself, and a hard cap on what a decompressor may produce.
//!
//! Parsers never allocate by a count read from a header: they ask this reader for bounded pieces
//! (at most [`Reader::CHUNK`] bytes at a time) and grow their output as the bytes arrive, so a
//! lying header runs into the end of the file, not into the allocator.

use std::io::{self, Read, Seek, SeekFrom};
use std::ops::ControlFlow;

use crate::error::{ErrorKind, Parse, bad};

/// How far loading has got: bytes of the file read so far, of `total` when the size is known.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress {
    /// Bytes read so far.
    pub bytes: u64,
    /// The total, where known (a file's size; not a stream's).
    pub total: Option<u64>,
}

/// A callback that receives [`Progress`] every few MiB; `ControlFlow::Break` cancels the load
/// (which then fails with [`ErrorKind::Cancelled`]: a Ctrl-C, a closed dialog).
pub type ProgressFn<'a> = &'a mut dyn FnMut(Progress) -> ControlFlow<()>;

/// Counts the bytes read from the file and reports them, every `STEP` bytes and at the end.
/// Seeks (a zip's directory first, then its members) do not move the count: it is the bytes
/// read so far, capped at the file's size, so a progress bar only moves forward.
pub(crate) struct ProgressRead<'p, R> {
    inner: R,
    /// Bytes read so far.
    position: u64,
    total: Option<u64>,
    reported: u64,
    progress: Option<ProgressFn<'p>>,
    /// The callback asked to stop: every read fails from then on.
    pub cancelled: bool,
}

impl<'p, R> ProgressRead<'p, R> {
    const STEP: u64 = 4 << 20;

    pub fn new(inner: R, total: Option<u64>, progress: Option<ProgressFn<'p>>) -> Self {
        ProgressRead { inner, position: 0, total, reported: 0, progress, cancelled: false }
    }

    fn report(&mut self, force: bool) {
        if let Some(cb) = self.progress.as_mut()
            && (force || self.position >= self.reported + Self::STEP)
        {
            self.reported = self.position;
            let bytes = self.total.map_or(self.position, |t| self.position.min(t));
            if cb(Progress { bytes, total: self.total }).is_break() {
                self.cancelled = true;
            }
        }
    }

    /// Reports the final position (the whole file when it was read to the end).
    pub fn finish(&mut self) {
        self.report(true);
    }
}

impl<R: Read> Read for ProgressRead<'_, R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if self.cancelled {
            return Err(io::Error::other("loading was cancelled"));
        }
        let n = self.inner.read(buf)?;
        self.position += n as u64;
        self.report(false);
        Ok(n)
    }
}

impl<R: Seek> Seek for ProgressRead<'_, R> {
    fn seek(&mut self, pos: SeekFrom) -> io::Result<u64> {
        self.inner.seek(pos)
    }
}

/// The error a [`Limited`] reader raises; recognised by [`io_error`].
#[derive(Debug)]
pub(crate) struct LimitExceeded(pub u64);

impl std::fmt::Display for LimitExceeded {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "decompressed data exceeds {} bytes", self.0)
    }
}

impl std::error::Error for LimitExceeded {}

/// Fails once more than `limit` bytes came out of a decompressor: bounded memory on bombs.
pub(crate) struct Limited<R> {
    pub inner: R,
    pub left: u64,
    pub limit: u64,
}

impl<R: Read> Read for Limited<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if self.left == 0 {
            // One more byte means the stream is larger than allowed; zero bytes means it ended.
            let mut probe = [0u8; 1];
            return match self.inner.read(&mut probe)? {
                0 => Ok(0),
                _ => Err(io::Error::other(LimitExceeded(self.limit))),
            };
        }
        let max = buf.len().min(self.left.min(usize::MAX as u64) as usize);
        let n = self.inner.read(&mut buf[..max])?;
        self.left -= n as u64;
        Ok(n)
    }
}

/// Maps an I/O error at `offset` to the error kind users see.
pub(crate) fn io_error(e: io::Error, offset: u64, expected: &str) -> ErrorKind {
    if let Some(LimitExceeded(limit)) = e.get_ref().and_then(|r| r.downcast_ref::<LimitExceeded>()) {
        return ErrorKind::TooLarge { offset, limit: *limit };
    }
    match e.kind() {
        io::ErrorKind::UnexpectedEof => ErrorKind::Format { offset, expected: format!("{expected} (the file ends)") },
        io::ErrorKind::InvalidData | io::ErrorKind::InvalidInput => {
            ErrorKind::Format { offset, expected: format!("{expected} (the decompressor says: {e})") }
        }
        _ => ErrorKind::Io(e),
    }
}

/// A buffered reader that knows its offset and hands out bounded slices.
pub(crate) struct Reader<'a> {
    inner: Box<dyn Read + 'a>,
    buf: Box<[u8]>,
    start: usize,
    end: usize,
    /// Offset of `buf[start]` in the stream.
    offset: u64,
    eof: bool,
}

impl<'a> Reader<'a> {
    /// The largest piece one call may ask for.
    pub const CHUNK: usize = 1 << 20;

    pub fn new(inner: impl Read + 'a) -> Reader<'a> {
        Reader {
            inner: Box::new(inner),
            buf: vec![0u8; 2 * Self::CHUNK].into_boxed_slice(),
            start: 0,
            end: 0,
            offset: 0,
            eof: false,
        }
    }

    pub fn offset(&self) -> u64 {
        self.offset
    }

    /// Buffers at least `n` (≤ CHUNK) bytes unless the stream ends first; returns what is buffered.
    fn fill(&mut self, n: usize) -> Parse<usize> {
        debug_assert!(n <= Self::CHUNK);
        if self.end - self.start >= n || self.eof {
            return Ok(self.end - self.start);
        }
        if self.start + n > self.buf.len() {
            self.buf.copy_within(self.start..self.end, 0);
            self.end -= self.start;
            self.start = 0;
        }
        while self.end - self.start < n {
            match self.inner.read(&mut self.buf[self.end..]) {
                Ok(0) => {
                    self.eof = true;
                    break;
                }
                Ok(k) => self.end += k,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => return Err(io_error(e, self.offset + (self.end - self.start) as u64, "more data")),
            }
        }
        Ok(self.end - self.start)
    }

    /// Up to `n` (≤ CHUNK) bytes without consuming them; fewer only at the end of the stream.
    pub fn peek(&mut self, n: usize) -> Parse<&[u8]> {
        let have = self.fill(n)?.min(n);
        Ok(&self.buf[self.start..self.start + have])
    }

    /// Exactly `n` (≤ CHUNK) bytes, or a format error saying what was `expected`.
    pub fn take(&mut self, n: usize, expected: &str) -> Parse<&[u8]> {
        if self.fill(n)? < n {
            return bad(
                self.offset,
                format!("{expected} ({n} bytes; the file ends after {} more)", self.end - self.start),
            );
        }
        let s = self.start;
        self.start += n;
        self.offset += n as u64;
        Ok(&self.buf[s..s + n])
    }

    /// Up to `n` (≤ CHUNK) bytes, consumed; fewer only at the end of the stream.
    pub fn take_up_to(&mut self, n: usize) -> Parse<&[u8]> {
        let have = self.fill(n)?.min(n);
        let s = self.start;
        self.start += have;
        self.offset += have as u64;
        Ok(&self.buf[s..s + have])
    }

    /// True when no byte is left.
    pub fn at_end(&mut self) -> Parse<bool> {
        Ok(self.fill(1)? == 0)
    }

    /// Skips `n` bytes; a format error if the stream ends first.
    pub fn skip(&mut self, mut n: u64, expected: &str) -> Parse<()> {
        while n > 0 {
            let step = n.min(Self::CHUNK as u64) as usize;
            self.take(step, expected)?;
            n -= step as u64;
        }
        Ok(())
    }

    /// One line without its `\n` (and `\r`), at most `max` bytes; `None` at the end of the stream.
    pub fn line(&mut self, max: usize, expected: &str) -> Parse<Option<&[u8]>> {
        let max = max.min(Self::CHUNK - 1);
        let avail = self.fill(max + 1)?;
        if avail == 0 {
            return Ok(None);
        }
        let window = &self.buf[self.start..self.start + avail.min(max + 1)];
        let (len, used) = match window.iter().position(|&b| b == b'\n') {
            Some(i) => (i, i + 1),
            None if avail <= max => (avail, avail),
            None => return bad(self.offset, format!("{expected} (a line of at most {max} bytes)")),
        };
        let s = self.start;
        self.start += used;
        self.offset += used as u64;
        let line = &self.buf[s..s + len];
        Ok(Some(line.strip_suffix(b"\r").unwrap_or(line)))
    }

    /// Fills `out` from what is buffered, then straight from the source (no intermediate copy);
    /// returns the bytes read, fewer than `out.len()` only at the end of the stream.
    pub fn read_into(&mut self, out: &mut [u8]) -> Parse<usize> {
        let buffered = (self.end - self.start).min(out.len());
        out[..buffered].copy_from_slice(&self.buf[self.start..self.start + buffered]);
        self.start += buffered;
        let mut n = buffered;
        while n < out.len() && !self.eof {
            match self.inner.read(&mut out[n..]) {
                Ok(0) => self.eof = true,
                Ok(k) => n += k,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => return Err(io_error(e, self.offset + n as u64, "more data")),
            }
        }
        self.offset += n as u64;
        Ok(n)
    }

    /// Everything that is left, in pieces of at most CHUNK bytes.
    pub fn read_to_end(&mut self) -> Parse<Vec<u8>> {
        let mut out = Vec::new();
        loop {
            let piece = self.take_up_to(Self::CHUNK)?;
            if piece.is_empty() {
                return Ok(out);
            }
            out.extend_from_slice(piece);
        }
    }
}

/// Reads the rest of a plain file of `len` bytes straight into storage for points, so a parser
/// can decode in place: every point it keeps takes no more bytes than the record it came from,
/// so writing point w at bytes 12w never overtakes the reading position. The allocation is the
/// file's size (zeroed by the allocator, so untouched pages cost nothing) — not a header count.
/// Returns the storage and the number of bytes read into it.
pub(crate) fn read_rest_as_points(r: &mut Reader, len: u64) -> Parse<(Vec<[f32; 3]>, usize)> {
    let n = usize::try_from(len.saturating_sub(r.offset()))
        .map_err(|_| ErrorKind::Unsupported("a file larger than the address space".into()))?;
    let mut points = vec![[0f32; 3]; n.div_ceil(12)];
    advise_huge_pages(bytemuck::cast_slice_mut(&mut points));
    let got = r.read_into(&mut bytemuck::cast_slice_mut::<[f32; 3], u8>(&mut points)[..n])?;
    Ok((points, got))
}

/// Asks Linux to back a large buffer with transparent huge pages. Filling 100 MB of fresh memory
/// otherwise takes ~25 000 page faults, which cost more than the copy itself on our machines
/// (measured with `lineao bench-load`); with 2 MiB pages it takes ~50. Advisory only: where
/// THP is off, nothing changes.
pub(crate) fn advise_huge_pages(buf: &mut [u8]) {
    #[cfg(target_os = "linux")]
    {
        const PAGE: usize = 4096;
        if buf.len() < 4 << 20 {
            return;
        }
        let start = (buf.as_ptr() as usize).next_multiple_of(PAGE);
        let end = (buf.as_ptr() as usize + buf.len()) / PAGE * PAGE;
        if end > start {
            // SAFETY: the range lies inside memory this buffer owns; MADV_HUGEPAGE changes no
            // contents and no mapping, only how the kernel backs untouched pages.
            unsafe { libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE) };
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = buf;
}

/// Little- or big-endian scalar decoding for the binary formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Endian {
    Little,
    Big,
}

impl Endian {
    pub fn u32(self, b: &[u8]) -> u32 {
        let a = b[..4].try_into().unwrap();
        match self {
            Endian::Little => u32::from_le_bytes(a),
            Endian::Big => u32::from_be_bytes(a),
        }
    }
    pub fn i32(self, b: &[u8]) -> i32 {
        self.u32(b) as i32
    }
    pub fn i16(self, b: &[u8]) -> i16 {
        let a = b[..2].try_into().unwrap();
        match self {
            Endian::Little => i16::from_le_bytes(a),
            Endian::Big => i16::from_be_bytes(a),
        }
    }
    pub fn f32(self, b: &[u8]) -> f32 {
        f32::from_bits(self.u32(b))
    }
}
