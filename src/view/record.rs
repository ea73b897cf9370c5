//! Recording what the viewer shows: while it records, every UI frame the window is captured
//! (egui's screenshot of the whole window, panels and all), each capture written at once as a
//! PNG beside the movie (`rec.apng` → `rec-00000.png`, …); on stop the movie is written from
//! those frames at the rate they came (an animated PNG, or through ffmpeg as `render
//! --turntable`'s `--movie`: [`lineao_session::figure`]). The PNGs stay.

use std::path::{Path, PathBuf};

use anyhow::Result;
use lineao_session::figure::{self, Movie};
use web_time::Instant;

/// The frame names' width: up to 100 000 frames sort by name.
const NAMED_FRAMES: u32 = 100_000;

/// A recording under way.
pub struct Recording {
    movie: Movie,
    /// What the frames are named after: the movie's path as a PNG.
    frames_at: PathBuf,
    /// Frames written.
    pub frames: u32,
    /// A capture asked for and not yet come back.
    pub pending: bool,
    started: Instant,
    /// `--record`'s frame count: stop after it.
    pub limit: Option<u32>,
}

/// A capture of the window for the recording, as egui's screenshot's user data.
pub struct RecordFrame;

impl Recording {
    /// A recording into `movie` (an `.apng`/`.png`, or a file ffmpeg writes), checked before any
    /// frame is captured: an extension lineao cannot write, or ffmpeg missing, is an error.
    pub fn start(movie: &Path, limit: Option<u32>) -> Result<Recording> {
        let movie = Movie::named(movie, "--record")?;
        let frames_at = match &movie {
            Movie::Apng(path) | Movie::Ffmpeg(path) => path.with_extension("png"),
            Movie::None => PathBuf::from("lineao-recording.png"),
        };
        Ok(Recording { movie, frames_at, frames: 0, pending: false, started: Instant::now(), limit })
    }

    /// Writes a captured frame as the next PNG.
    pub fn push(&mut self, width: u32, height: u32, rgba: &[u8]) -> Result<()> {
        let path = figure::frame_path(&self.frames_at, self.frames, NAMED_FRAMES);
        lineao_session::output::write_png(&path, width, height, rgba)?;
        self.frames += 1;
        self.pending = false;
        Ok(())
    }

    /// Whether `--record`'s frames are all written.
    pub fn done(&self) -> bool {
        self.limit.is_some_and(|n| self.frames >= n)
    }

    /// Writes the movie of the frames at the rate they were captured (1 to 60 a second);
    /// returns what it wrote.
    pub fn finish(self) -> Result<String> {
        anyhow::ensure!(self.frames > 0, "the recording has no frame");
        let seconds = self.started.elapsed().as_secs_f64().max(1e-3);
        let fps = ((self.frames as f64 / seconds).round() as u32).clamp(1, 60);
        // The frames are named for NAMED_FRAMES; the movie reads them by that name.
        let count = self.frames;
        let named = |k| figure::frame_path(&self.frames_at, k, NAMED_FRAMES);
        let movie = match &self.movie {
            Movie::None => return Ok(format!("{count} frames, {} …", named(0).display())),
            Movie::Apng(path) | Movie::Ffmpeg(path) => path.clone(),
        };
        figure::write_named_movie(&named, count, &self.movie, fps)?;
        Ok(format!("{} ({count} frames at {fps} a second; the frames {} …)", movie.display(), named(0).display()))
    }
}
