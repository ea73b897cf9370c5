//! Opening a dataset as it arrives: the worker reads (or makes) a piece of the source per step,
//! appends its whole streamlines to the GPU's geometry, and draws what has arrived — the first
//! picture of a whole-brain file within a second, however large, while the window stays
//! interactive and shows the progress.
//!
//! What is kept on the CPU: the one-column per-vertex fields (the viewer colours by any of
//! them) and a *preview*, every k-th streamline (k from the source's size, for at most
//! [`PREVIEW_VERTICES`] points), drawn while the camera moves. Not the points: a method that
//! needs them on the CPU (object-space AO, the ray tracer's BVH) reads the source again when it
//! is first asked for ([`Lines::load_points`]). A web page's file read as it arrives
//! ([`Source::Feed`]) keeps its bytes up to the feed's `keep_bytes` for that, and past them it
//! cannot.

use std::collections::VecDeque;
use std::ops::ControlFlow;
use std::sync::{Arc, Mutex};

use lineao::{Gpu, LineGeometry};
use lineao_tracts::{ChunkDecoder, SceneKind, Tractogram};
use web_time::Instant;

use crate::source::{CHUNK_VERTICES, Keep, Lines, Sampled, Source, SourceError};

/// How long a step reads and uploads before it lets the worker draw and listen, at least; a
/// step reads as long as the time between steps (what the frames and the window took), up to
/// [`STEP_MOST_MS`], so that the reading has half the time however slow the frames are.
/// Vertices of a preview frame at most.
pub const PREVIEW_VERTICES: usize = 250_000;

/// A selection on the GPU: its rules, the streamlines there were, and how many it kept (`None`:
/// every one).
#[derive(Clone, Debug)]
pub struct Selected {
    pub selection: lineao_tracts::Selection,
    pub streamlines: usize,
    pub kept: Option<usize>,
}

/// The parts of a scene a frame reads: the loaded one's, or those of one being opened.
pub struct SceneRef<'a> {
    pub lines: &'a mut Lines,
    pub preview: &'a mut Preview,
    pub rays: &'a mut Option<Arc<lineao::RayScene>>,
    pub source: &'a Source,
    /// Still arriving: what needs every point on the CPU waits until it is all there.
    pub opening: bool,
    /// The selection last written to the GPU, and the streamlines there were then.
    pub selected: &'a mut Option<Selected>,
}

const STEP_BUDGET_MS: f64 = 60.0;
const STEP_MOST_MS: f64 = 500.0;
/// How much reading passes between two draws of what has arrived (a flush of the geometry's
/// pending page), after the first chunk, which is drawn at once: at least this, and three times
/// what the last draw took (a page on SwiftShader draws a preview in about a second).
const FLUSH_EVERY_MS: f64 = 400.0;
/// Bytes read from a file at a time.
const READ_BYTES: usize = 4 << 20;

/// Every `every`-th streamline of what is loaded: its geometry, and which vertices of the full
/// detail it holds (to pick their attributes).
pub struct Preview {
    pub geometry: LineGeometry,
    pub kept: Vec<usize>,
    pub attributes: crate::source::AttributeKey,
    every: usize,
}

/// Where a dataset's pieces come from.
enum Input {
    File {
        file: std::fs::File,
        read: u64,
        size: u64,
    },
    Bytes {
        bytes: Arc<[u8]>,
        at: usize,
    },
    /// A web page's file as it arrives, and its bytes so far while they fit its `keep_bytes`.
    Feed {
        feed: crate::source::SharedFeed,
        kept: Option<Vec<u8>>,
        limit: u64,
    },
    /// The whole brain, streamline by streamline: the next chunk of its streamlines.
    WholeBrain {
        brain: lineao_tracts::scenes::wholebrain::WholeBrain,
        next: u64,
    },
    /// Another built-in scene, made whole in one step.
    Scene {
        kind: SceneKind,
        vertices: usize,
        seed: u64,
    },
    Done,
}

/// A dataset being opened: its lines (on the GPU and growing), its preview, and its input.
pub struct Opening {
    pub source: Source,
    pub lines: Lines,
    pub preview: Preview,
    input: Input,
    decoder: Option<ChunkDecoder<'static>>,
    /// Chunks the decoder has handed over, not yet appended.
    chunks: Arc<Mutex<VecDeque<Tractogram>>>,
    /// The camera a built-in scene suggests.
    hint: Option<lineao_tracts::ViewHint>,
    /// Streamlines seen (the preview's count).
    streamlines: usize,
    /// Whether anything was drawn yet; the reading since the last draw (ms); the time between
    /// the steps after the last draw (what drawing it took); when the last step ended.
    flushed: bool,
    read_since_flush: f64,
    draw_ms: f64,
    after_flush: bool,
    last_step_end: Option<Instant>,
    first_ms: Option<f64>,
    /// Whether the source can be read again for its points (a feed's bytes were kept).
    pub held: bool,
    /// Never built while the data arrives (the ray tracer waits for all of it).
    rays: Option<Arc<lineao::RayScene>>,
    /// The selection on the GPU so far ([`SceneRef::selected`]).
    selected: Option<Selected>,
    /// The file's groups, once it is read.
    groups: Vec<lineao_tracts::Group>,
    pub started: Instant,
    /// Bytes read of how many (files), for the progress bar.
    pub progress: (u64, Option<u64>),
}

/// What a step of opening came to.
pub enum Step {
    /// More to read; `drawn` says whether a new part arrived on screen (a flush).
    Reading { drawn: bool },
    /// Everything is read: [`Opening::finish`] puts the rest on the GPU.
    Read,
}

impl Opening {
    /// Starts opening `source` on `gpu`: nothing read yet; `sampled`, a volume sampled at
    /// every vertex as a field; `regions`, include and exclude regions (a selection of them
    /// alone) each streamline is judged by as it arrives, so that they select while the file
    /// arrives and need no second read of it ([`Lines::judged`]).
    pub fn start(
        source: Source,
        sampled: Option<Arc<Sampled>>,
        regions: lineao_tracts::Selection,
        gpu: &Gpu,
    ) -> Result<Opening, String> {
        let error = |e: SourceError| format!("{e:#}");
        // The lengths: the side panel selects by them.
        let selection = (!regions.is_everything()).then(|| Arc::new(regions));
        let keep = Keep { fields: true, sampled, lengths: true, selection, ..Keep::default() };
        let lines = Lines::empty(source.name(), &keep, gpu).map_err(error)?;
        let chunks: Arc<Mutex<VecDeque<Tractogram>>> = Arc::default();
        let sink = {
            let chunks = chunks.clone();
            move |chunk: Tractogram| {
                chunks.lock().expect("not poisoned").push_back(chunk);
                ControlFlow::Continue(())
            }
        };
        let decoder = |name: &str, size: Option<u64>| {
            Some(ChunkDecoder::new(name, &Default::default(), size, CHUNK_VERTICES / 4, sink))
        };
        // The preview takes every k-th streamline: k from the points the source holds, about
        // (12 bytes a point in a .tck, a little more elsewhere; gzip: three times its size).
        let (input, decoder, points) = match &source {
            Source::File(path) => {
                let file = std::fs::File::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
                let size = file.metadata().map_err(|e| format!("{}: {e}", path.display()))?.len();
                let name = path.display().to_string();
                let gz = name.ends_with(".gz");
                let points = size * if gz { 3 } else { 1 } / 12;
                (Input::File { file, read: 0, size }, decoder(&name, Some(size)), points)
            }
            Source::Bytes { name, bytes } => {
                let points = bytes.len() as u64 / 12;
                (Input::Bytes { bytes: bytes.clone(), at: 0 }, decoder(name, Some(bytes.len() as u64)), points)
            }
            Source::Feed { name, feed } => {
                let (total, limit) = {
                    let feed = feed.lock();
                    (feed.total, feed.keep_bytes)
                };
                let kept = total.is_none_or(|t| t <= limit).then(Vec::new);
                (Input::Feed { feed: feed.clone(), kept, limit }, decoder(name, total), total.unwrap_or(0) / 12)
            }
            Source::Scene { kind: SceneKind::WholeBrain, vertices, seed } => {
                let brain = lineao_tracts::scenes::wholebrain::WholeBrain::new(*seed, *vertices as u64);
                (Input::WholeBrain { brain, next: 0 }, None, *vertices as u64)
            }
            Source::Scene { kind, vertices, seed } => {
                (Input::Scene { kind: *kind, vertices: *vertices, seed: *seed }, None, *vertices as u64)
            }
        };
        let every = (points as usize).div_ceil(PREVIEW_VERTICES).max(1);
        let geometry =
            LineGeometry::empty(&gpu.device, crate::source::geometry_options(gpu)).map_err(|e| e.to_string())?;
        let preview = Preview { geometry, kept: Vec::new(), attributes: Default::default(), every };
        Ok(Opening {
            source,
            lines,
            preview,
            input,
            decoder,
            chunks,
            hint: None,
            streamlines: 0,
            flushed: false,
            read_since_flush: 0.0,
            draw_ms: 0.0,
            after_flush: false,
            last_step_end: None,
            first_ms: None,
            held: true,
            rays: None,
            selected: None,
            groups: Vec::new(),
            started: Instant::now(),
            progress: (0, None),
        })
    }

    /// Reads and uploads for a step's budget; what has arrived goes on screen at once the first
    /// time, then every [`FLUSH_EVERY_MS`]. At the end the geometry is finished (exact bounds)
    /// and the source, where it came as a feed with its bytes kept, becomes those bytes.
    pub fn step(&mut self, gpu: &Gpu) -> Result<Step, String> {
        let start = Instant::now();
        let gap = self.last_step_end.map_or(0.0, |t| (start - t).as_secs_f64() * 1e3);
        if std::mem::take(&mut self.after_flush) {
            self.draw_ms = gap;
        }
        let budget = gap.clamp(STEP_BUDGET_MS, STEP_MOST_MS);
        let mut ended = false;
        while start.elapsed().as_secs_f64() * 1e3 < budget && !ended {
            ended = self.read(gpu)?;
            self.append_chunks(gpu)?;
            if matches!(self.input, Input::Feed { .. })
                && !ended
                && self.chunks.lock().expect("not poisoned").is_empty()
            {
                // The page has given what it has: draw it and wait for more.
                break;
            }
        }
        self.read_since_flush += start.elapsed().as_secs_f64() * 1e3;
        self.last_step_end = Some(Instant::now());
        if ended {
            return Ok(Step::Read);
        }
        let due = !self.flushed || self.read_since_flush >= FLUSH_EVERY_MS.max(3.0 * self.draw_ms);
        let arrived = self.lines.geometry.vertices > 0;
        if due && arrived {
            self.flush(gpu)?;
            self.after_flush = true;
            return Ok(Step::Reading { drawn: true });
        }
        Ok(Step::Reading { drawn: false })
    }

    /// After [`Step::Read`]: the rest on the GPU, the geometry finished (its exact bounds) and
    /// the source, where it came as a feed whose bytes were kept, those bytes.
    pub async fn finish(&mut self, gpu: &Gpu) -> Result<(), String> {
        self.lines.finish_async(self.hint, gpu).await.map_err(|e| format!("{e:#}"))?;
        // The groups: the side panel colours and selects by them.
        if !self.groups.is_empty() {
            self.lines.tracts.groups = std::mem::take(&mut self.groups);
            crate::source::add_group_field(&mut self.lines.tracts);
        }
        self.preview.geometry.finish_async(&gpu.device, &gpu.queue).await.map_err(|e| e.to_string())?;
        match std::mem::replace(&mut self.input, Input::Done) {
            Input::Feed { kept: Some(bytes), .. } => {
                self.source = Source::Bytes { name: self.source.name(), bytes: bytes.into() };
            }
            Input::Feed { kept: None, .. } => self.held = false,
            _ => {}
        }
        Ok(())
    }

    /// After an error: the chunks decoded before it appended too, and all of it on screen.
    pub fn flush_arrived(&mut self, gpu: &Gpu) -> Result<(), String> {
        self.append_chunks(gpu)?;
        self.flush(gpu)
    }

    /// Puts what is pending on screen.
    pub fn flush(&mut self, gpu: &Gpu) -> Result<(), String> {
        self.lines.geometry.flush(&gpu.device, &gpu.queue).map_err(|e| e.to_string())?;
        self.preview.geometry.flush(&gpu.device, &gpu.queue).map_err(|e| e.to_string())?;
        (self.flushed, self.read_since_flush) = (true, 0.0);
        self.first_ms.get_or_insert(self.started.elapsed().as_secs_f64() * 1e3);
        Ok(())
    }

    /// Whether what has arrived is on screen (a flush happened).
    pub fn drawn(&self) -> bool {
        self.first_ms.is_some() && self.lines.geometry.bounds.is_some()
    }

    /// Milliseconds from the start to the first part on screen.
    pub fn first_ms(&self) -> Option<f64> {
        self.first_ms
    }

    /// The parts of the scene a frame reads while it arrives.
    pub fn scene(&mut self) -> SceneRef<'_> {
        SceneRef {
            lines: &mut self.lines,
            preview: &mut self.preview,
            rays: &mut self.rays,
            source: &self.source,
            opening: true,
            selected: &mut self.selected,
        }
    }

    /// The opened dataset: its lines, preview and (readable) source.
    pub fn into_parts(self) -> (Lines, Preview, Source) {
        (self.lines, self.preview, self.source)
    }

    /// The next piece of the input into the decoder (or the next chunk of a scene); `true`
    /// once the input has ended and the decoder finished.
    fn read(&mut self, gpu: &Gpu) -> Result<bool, String> {
        let _ = gpu;
        let error = |e: lineao_tracts::Error| e.to_string();
        let push = |decoder: &mut Option<ChunkDecoder<'static>>, bytes: &[u8]| match decoder {
            Some(d) => d.push(bytes).map_err(error),
            None => Ok(()),
        };
        let piece_ended = match &mut self.input {
            Input::File { file, read, size } => {
                use std::io::Read;
                let mut buffer = vec![0u8; READ_BYTES];
                let n = file.read(&mut buffer).map_err(|e| format!("{}: {e}", self.source.name()))?;
                *read += n as u64;
                self.progress = (*read, Some(*size));
                push(&mut self.decoder, &buffer[..n])?;
                n == 0
            }
            Input::Bytes { bytes, at } => {
                let end = (*at + READ_BYTES).min(bytes.len());
                push(&mut self.decoder, &bytes[*at..end])?;
                *at = end;
                self.progress = (end as u64, Some(bytes.len() as u64));
                end == bytes.len()
            }
            Input::Feed { feed, kept, limit } => {
                let (pieces, ended, failed, taken, total) = {
                    let mut feed = feed.lock();
                    let (pieces, ended, failed) = feed.take(READ_BYTES);
                    (pieces, ended, failed, feed.taken, feed.total)
                };
                if let Some(message) = failed {
                    return Err(message);
                }
                for piece in &pieces {
                    push(&mut self.decoder, piece)?;
                    if let Some(bytes) = kept {
                        if bytes.len() as u64 + piece.len() as u64 > *limit {
                            *kept = None;
                        } else {
                            bytes.extend_from_slice(piece);
                        }
                    }
                }
                self.progress = (taken, total);
                ended
            }
            Input::WholeBrain { brain, next } => {
                let per_chunk = (CHUNK_VERTICES as f64 / 4.0 / lineao_tracts::scenes::wholebrain::MEAN_POINTS) as u64;
                let end = (*next + per_chunk).min(brain.streamlines());
                self.chunks.lock().expect("not poisoned").push_back(brain.tractogram(*next..end));
                *next = end;
                end == brain.streamlines()
            }
            Input::Scene { kind, vertices, seed } => {
                let scene = kind.build(*seed, *vertices);
                self.hint = Some(scene.view);
                self.chunks.lock().expect("not poisoned").push_back(scene.tractogram);
                true
            }
            Input::Done => true,
        };
        if piece_ended && let Some(decoder) = self.decoder.take() {
            let streamed = decoder.finish().map_err(error)?;
            if !streamed.has_points {
                let format = streamed.format.map_or("tsf", |f| f.name());
                return Err(format!("{}: a .{format} holds values without points; open its .tck", self.source.name()));
            }
            // A TRX file's groups (its chunks may still be queued: [`Opening::finish`]).
            self.groups = streamed.groups;
        }
        Ok(piece_ended)
    }

    /// Appends the decoded chunks to the lines and their preview.
    fn append_chunks(&mut self, gpu: &Gpu) -> Result<(), String> {
        loop {
            let Some(chunk) = self.chunks.lock().expect("not poisoned").pop_front() else { return Ok(()) };
            let base = self.lines.geometry.vertices;
            // The preview: every k-th streamline of the whole, and which vertices those are.
            let every = self.preview.every;
            let (mut positions, mut offsets) = (Vec::new(), vec![0u64]);
            for (i, range) in chunk.offsets.windows(2).enumerate() {
                if (self.streamlines + i).is_multiple_of(every) {
                    let (a, b) = (range[0] as usize, range[1] as usize);
                    positions.extend_from_slice(chunk.positions.get(a..b).unwrap_or(&[]));
                    self.preview.kept.extend(base + a..base + b);
                    offsets.push(positions.len() as u64);
                }
            }
            self.streamlines += chunk.streamlines();
            let (d, q) = (&gpu.device, &gpu.queue);
            self.preview.geometry.append(d, q, &positions, &offsets).map_err(|e| e.to_string())?;
            self.lines.append_chunk(chunk, gpu).map_err(|e| format!("{e:#}"))?;
        }
    }
}
