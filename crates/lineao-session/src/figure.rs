//! Figures and movies: standard anatomical views of one data set in a labelled figure
//! (`--views`), and turntables (`--turntable N`): a PNG a frame and a movie of them.
//!
//! A turntable turns the eye about the target around the camera's up axis (Rodrigues'
//! rotation, in f64), N frames over `--turntable-degrees` (a whole turn by default, the last
//! frame one step short of the first); with two or more `--orbit` keyframes (the viewer's and
//! the page's azimuth, elevation and zoom around the data's own camera) the N frames run from
//! the first keyframe to the last, linear in each between two. The session loads the data once and keeps one chain per
//! panel across the frames, so a frame costs what a still picture costs; the ray-traced method
//! accumulates each frame to its `--rays`.
//!
//! The movie: an animated PNG (APNG) by default, written by the `png` crate lineao writes its
//! pictures with — lossless, no program to install, played by every current browser —, frame by
//! frame as they are rendered (one frame in memory). A `--movie` of another extension (`.mp4`,
//! `.webm`, `.mkv`, `.mov`, `.gif`) is encoded by the `ffmpeg` program from the PNG frames once
//! they are all written: H.264 or VP9 are what talks and journals take, and ffmpeg is the
//! well-kept encoder of them; asked for where it is not installed, the command stops before it
//! renders, naming the flag. A movie that cannot be written leaves every PNG frame written.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use crate::args::{FigureArgs, RenderArgs};
use crate::label::Rgba8;
use crate::render::Session;

/// The file of frame `k` of `frames` beside `output`: `NAME-007.png` (at least three digits).
pub fn frame_path(output: &Path, k: u32, frames: u32) -> PathBuf {
    let digits = (frames.saturating_sub(1).max(1).ilog10() + 1).max(3) as usize;
    let stem = output.file_stem().map_or("lineao".into(), |s| s.to_string_lossy().into_owned());
    output.with_file_name(format!("{stem}-{k:0digits$}.png"))
}

/// How the turntable's movie is written.
#[derive(Clone, Debug, PartialEq)]
pub enum Movie {
    /// No movie: the PNG frames only.
    None,
    /// An animated PNG, frame by frame as they are rendered.
    Apng(PathBuf),
    /// A file `ffmpeg` encodes from the PNG frames once they are written.
    Ffmpeg(PathBuf),
}

impl Movie {
    /// The movie `--movie` asks for (by default the output with `.apng`), checked before
    /// anything is rendered: an extension lineao cannot write, or `ffmpeg` missing, is an error
    /// naming the flag.
    pub fn of(figure: &FigureArgs, output: &Path) -> Result<Movie> {
        match &figure.movie {
            Some(path) => Movie::named(path, "--movie"),
            None => Movie::named(&output.with_extension("apng"), "--movie"),
        }
    }

    /// The movie `path` names (`none`: none), checked as [`Movie::of`] checks it; an error
    /// names `flag`.
    pub fn named(path: &Path, flag: &str) -> Result<Movie> {
        if path.as_os_str() == "none" {
            return Ok(Movie::None);
        }
        let path = path.to_path_buf();
        let extension = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
        match extension.as_str() {
            "png" | "apng" => Ok(Movie::Apng(path)),
            "mp4" | "mkv" | "mov" | "webm" | "gif" => {
                anyhow::ensure!(
                    ffmpeg_available(),
                    "{flag} {}: writing .{extension} needs the ffmpeg program, which is not installed (apt-get \
                     install ffmpeg), or give --movie with .apng",
                    path.display()
                );
                Ok(Movie::Ffmpeg(path))
            }
            _ => anyhow::bail!(
                "{flag} {}: expected a .apng or .png file, or .mp4, .mkv, .mov, .webm or .gif (through ffmpeg), or none",
                path.display()
            ),
        }
    }
}

/// Whether the `ffmpeg` program runs here.
fn ffmpeg_available() -> bool {
    std::process::Command::new("ffmpeg")
        .arg("-version")
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// An animated PNG written frame by frame: every frame whole (no blending, no disposal), each
/// shown 1/fps s, looping forever.
pub struct ApngWriter {
    writer: png::Writer<std::io::BufWriter<std::fs::File>>,
    size: (u32, u32),
}

impl ApngWriter {
    pub fn create(path: &Path, width: u32, height: u32, frames: u32, fps: u32) -> Result<ApngWriter> {
        let file = std::fs::File::create(path).with_context(|| format!("cannot create {}", path.display()))?;
        let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), width, height);
        encoder.set_color(png::ColorType::Rgba);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
        encoder.set_animated(frames, 0)?;
        encoder.set_frame_delay(1, fps.min(u16::MAX as u32) as u16)?;
        // Fast deflate: a frame's encoding stays a small share of its rendering.
        encoder.set_compression(png::Compression::Fast);
        let writer = encoder.write_header()?;
        Ok(ApngWriter { writer, size: (width, height) })
    }

    pub fn push(&mut self, image: &Rgba8) -> Result<()> {
        anyhow::ensure!((image.width, image.height) == self.size, "a frame differs in size from the first");
        self.writer.write_image_data(&image.data)?;
        Ok(())
    }

    pub fn finish(self) -> Result<()> {
        self.writer.finish()?;
        Ok(())
    }
}

/// Writes `frames` as the movie `path` names (as `--movie` takes it; `none` writes nothing) at
/// `fps`: what a turntable writes, for frames rendered elsewhere (Python's `Renderer.orbit`).
pub fn write_movie(frames: &[Rgba8], path: &Path, fps: u32) -> Result<()> {
    anyhow::ensure!((1..=240).contains(&fps), "fps must be in 1..=240, got {fps}");
    let (Some(first), Ok(count)) = (frames.first(), u32::try_from(frames.len())) else {
        anyhow::bail!("a movie needs at least one frame");
    };
    match Movie::named(path, "movie")? {
        Movie::None => Ok(()),
        Movie::Apng(path) => {
            let mut writer = ApngWriter::create(&path, first.width, first.height, count, fps)?;
            for frame in frames {
                writer.push(frame)?;
            }
            writer.finish().with_context(|| format!("writing {}", path.display()))
        }
        Movie::Ffmpeg(path) => {
            let dir = tempdir_beside(&path)?;
            let output = dir.join("frame.png");
            let written = (0..count).zip(frames).try_for_each(|(k, frame)| {
                crate::output::write_png(&frame_path(&output, k, count), frame.width, frame.height, &frame.data)
            });
            let encoded = written.and_then(|()| encode_with_ffmpeg(&frame_pattern(&output, count), &path, fps));
            let _ = std::fs::remove_dir_all(&dir);
            encoded
        }
    }
}

/// Writes the `count` PNG frames `named(k)` as the movie `movie` at `fps`, reading one frame
/// at a time: a recording's movie (the viewer's). Through ffmpeg the names must be
/// [`frame_path`]'s for some count.
pub fn write_named_movie(named: &dyn Fn(u32) -> PathBuf, count: u32, movie: &Movie, fps: u32) -> Result<()> {
    anyhow::ensure!(count > 0, "a movie needs at least one frame");
    match movie {
        Movie::None => Ok(()),
        Movie::Apng(path) => {
            let mut writer: Option<ApngWriter> = None;
            for k in 0..count {
                let frame = read_png(&named(k))?;
                let writer = match &mut writer {
                    Some(writer) => writer,
                    None => writer.insert(ApngWriter::create(path, frame.width, frame.height, count, fps)?),
                };
                writer.push(&frame)?;
            }
            writer.expect("a frame at least").finish().with_context(|| format!("writing {}", path.display()))
        }
        Movie::Ffmpeg(path) => {
            // ffmpeg's pattern of the names: the first frame's digits as %0Nd.
            let first = named(0);
            let name = first.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            let digits = name.trim_end_matches(".png").chars().rev().take_while(char::is_ascii_digit).count();
            let stem = &name[..name.len() - ".png".len() - digits];
            encode_with_ffmpeg(&first.with_file_name(format!("{stem}%0{digits}d.png")), path, fps)
        }
    }
}

/// An 8-bit RGBA PNG (as lineao writes them).
fn read_png(path: &Path) -> Result<Rgba8> {
    let file = std::fs::File::open(path).with_context(|| format!("cannot open {}", path.display()))?;
    let mut reader = png::Decoder::new(std::io::BufReader::new(file)).read_info()?;
    let mut data = vec![0; reader.output_buffer_size().context("a PNG too large")?];
    let info = reader.next_frame(&mut data)?;
    anyhow::ensure!(
        info.color_type == png::ColorType::Rgba && info.bit_depth == png::BitDepth::Eight,
        "{}: not an 8-bit RGBA PNG",
        path.display()
    );
    data.truncate(info.buffer_size());
    Ok(Rgba8 { width: info.width, height: info.height, data })
}

/// A new folder beside `path` for its frames, removed by the caller.
fn tempdir_beside(path: &Path) -> Result<PathBuf> {
    let parent = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let name = path.file_name().map_or("movie".into(), |n| n.to_string_lossy().into_owned());
    let dir = parent.join(format!(".{name}.frames-{}", std::process::id()));
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    Ok(dir)
}

/// Encodes the PNG frames `pattern` (ffmpeg's `NAME-%03d.png`) into `path` at `fps`.
fn encode_with_ffmpeg(pattern: &Path, path: &Path, fps: u32) -> Result<()> {
    let extension = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
    let mut command = std::process::Command::new("ffmpeg");
    command.args(["-hide_banner", "-loglevel", "error", "-y", "-framerate", &fps.to_string(), "-start_number", "0"]);
    command.arg("-i").arg(pattern);
    match extension.as_str() {
        // H.264 in 4:2:0, which players take, needs even sizes.
        "mp4" | "mkv" | "mov" => {
            command.args([
                "-c:v",
                "libx264",
                "-crf",
                "18",
                "-pix_fmt",
                "yuv420p",
                "-vf",
                "pad=ceil(iw/2)*2:ceil(ih/2)*2",
            ]);
        }
        "webm" => {
            command.args(["-c:v", "libvpx-vp9", "-crf", "24", "-b:v", "0", "-pix_fmt", "yuv420p"]);
        }
        _ => {}
    }
    let output = command.arg(path).output().context("running ffmpeg")?;
    anyhow::ensure!(
        output.status.success(),
        "ffmpeg could not write {}: {}",
        path.display(),
        String::from_utf8_lossy(&output.stderr).trim()
    );
    Ok(())
}

/// `lineao render`: a turntable (`--turntable`), a picture as tiles straight into its PNG, or
/// the picture the session composes.
pub fn run(args: &RenderArgs) -> Result<()> {
    let mut session = Session::open(args)?;
    if let Some(frames) = args.figure.turntable {
        return run_turntable(args, &mut session, frames);
    }
    let output = args.image.output.clone().unwrap_or_else(|| "lineao.png".into());
    if write_tiled_picture(args, &mut session, &output)? {
        return Ok(());
    }
    crate::render::write(args, &mut session, &output)
}

/// `render --turntable N`: every frame's PNG as it is rendered, the cameras, then the movie.
/// A second thread encodes and writes each frame while the next one renders (at most two
/// frames wait for it).
pub fn run_turntable(args: &RenderArgs, session: &mut Session, frames: u32) -> Result<()> {
    let figure = &args.figure;
    let output = args.image.output.clone().unwrap_or_else(|| "lineao.png".into());
    let movie = Movie::of(figure, &output)?;
    let cameras = match &figure.orbit[..] {
        [_, _, ..] => crate::cameras::camera_path(&session.camera, &figure.orbit, frames),
        _ => crate::cameras::turntable(&session.camera, frames, figure.turntable_degrees),
    };
    let start = std::time::Instant::now();
    let mut render_seconds = 0.0;
    let (send, receive) = std::sync::mpsc::sync_channel::<(u32, Rgba8)>(2);
    let apng_path = match &movie {
        Movie::Apng(path) => Some(path.clone()),
        _ => None,
    };
    let (rendered, written) = std::thread::scope(|scope| {
        let writer = scope.spawn(|| write_frames(receive, &output, frames, apng_path.as_deref(), figure.fps));
        let mut chains = Vec::new();
        let mut rendered = Ok(());
        for (k, camera) in (0..frames).zip(&cameras) {
            session.camera = *camera;
            let at = std::time::Instant::now();
            match session.compose(args, &mut chains) {
                Ok((image, _)) => {
                    render_seconds += at.elapsed().as_secs_f64();
                    // The writer stopped: its error is the one to say.
                    if send.send((k, image)).is_err() {
                        break;
                    }
                }
                Err(e) => {
                    rendered = Err(e.context(format!("turntable frame {k}")));
                    break;
                }
            }
        }
        drop(send);
        (rendered, writer.join().expect("the frame writer does not panic"))
    });
    session.camera = cameras[0];
    rendered?;
    written?;
    let records: Vec<serde_json::Value> = (0..frames)
        .zip(&cameras)
        .map(|(k, camera)| {
            serde_json::json!({
                "file": frame_path(&output, k, frames).file_name().map(|n| n.to_string_lossy().into_owned()),
                "eye": camera.eye.to_array(),
                "target": camera.target.to_array(),
                "up": camera.up.to_array(),
            })
        })
        .collect();
    let cameras_file = output.with_extension("json");
    let document = serde_json::json!({
        "frames": frames,
        "fps": figure.fps,
        "degrees": if figure.orbit.len() >= 2 { None } else { Some(figure.turntable_degrees) },
        "keyframes": figure.orbit,
        "cameras": records,
    });
    std::fs::write(&cameras_file, serde_json::to_string_pretty(&document)? + "\n")
        .with_context(|| format!("cannot write {}", cameras_file.display()))?;
    let written = match &movie {
        Movie::Apng(path) => Some(path),
        Movie::Ffmpeg(path) => {
            let pattern = frame_pattern(&output, frames);
            encode_with_ffmpeg(&pattern, path, figure.fps)
                .with_context(|| format!("--movie {} (the PNG frames are written)", path.display()))?;
            Some(path)
        }
        Movie::None => None,
    };
    let seconds = start.elapsed().as_secs_f64();
    let path = match figure.orbit.len() {
        0 | 1 => format!("{} degrees", figure.turntable_degrees),
        n => format!("through {n} keyframes"),
    };
    eprintln!(
        "lineao: turntable of {frames} frames ({path}) of {} on {} in {seconds:.2} s ({:.1} ms a frame, {:.1} of them \
         rendering) -> {} .. {}, {}{}",
        session.lines.name,
        session.gpu.describe(),
        1e3 * seconds / frames as f64,
        1e3 * render_seconds / frames as f64,
        frame_path(&output, 0, frames).display(),
        frame_path(&output, frames - 1, frames).display(),
        cameras_file.display(),
        written.map_or(String::new(), |p| format!(", {}", p.display()))
    );
    Ok(())
}

/// The turntable's writer: each frame received as its PNG beside `output` and, with `apng`,
/// into that movie. A movie that fails stops there, the PNGs go on (its error is said at the
/// end); a movie with fewer frames than it says it has (a frame failed to render) is removed.
fn write_frames(
    frames: std::sync::mpsc::Receiver<(u32, Rgba8)>,
    output: &Path,
    count: u32,
    apng: Option<&Path>,
    fps: u32,
) -> Result<()> {
    let mut movie: Option<ApngWriter> = None;
    let mut failed: Option<anyhow::Error> = None;
    let mut received = 0;
    for (k, image) in frames {
        crate::output::write_png(&frame_path(output, k, count), image.width, image.height, &image.data)?;
        received += 1;
        let Some(path) = apng.filter(|_| failed.is_none()) else { continue };
        let pushed = match &mut movie {
            Some(writer) => writer.push(&image),
            None => ApngWriter::create(path, image.width, image.height, count, fps).and_then(|mut writer| {
                writer.push(&image)?;
                movie = Some(writer);
                Ok(())
            }),
        };
        if let Err(e) = pushed {
            movie = None;
            failed = Some(e.context(format!("writing {}", path.display())));
        }
    }
    let finished = match movie {
        Some(writer) if received == count => writer.finish(),
        Some(writer) => {
            drop(writer);
            apng.map(std::fs::remove_file);
            Ok(())
        }
        None => Ok(()),
    };
    match failed.map_or(finished, Err) {
        Err(e) => Err(e.context(format!("the movie (the {received} PNG frames are written)"))),
        Ok(()) => Ok(()),
    }
}

/// ffmpeg's input pattern of the frames [`frame_path`] names.
fn frame_pattern(output: &Path, frames: u32) -> PathBuf {
    let digits = (frames.saturating_sub(1).max(1).ilog10() + 1).max(3);
    let stem = output.file_stem().map_or("lineao".into(), |s| s.to_string_lossy().into_owned());
    output.with_file_name(format!("{stem}-%0{digits}d.png"))
}

/// `render` of one method as tiles straight into its PNG, a row of tiles at a time (what a
/// picture larger than memory needs), where nothing is composed over it (no --compare,
/// --grid, --views or --legend). `Ok(false)`: the picture is not tiled, or is composed.
pub fn write_tiled_picture(args: &RenderArgs, session: &mut Session, output: &Path) -> Result<bool> {
    let composed = args.shown.compare.is_some() || args.shown.grid || !args.figure.views.is_empty();
    // Object-space AO's visibilities are the session's to compute first: the composed path.
    if composed || args.image.legend || args.shown.method.volume.is_some() {
        return Ok(false);
    }
    let method = args.shown.method;
    let settings = session.settings(args, method);
    settings.validate().with_context(|| format!("method {}", method.name()))?;
    let Some(tile) = crate::render::tile_size(args, &session.gpu.device.limits(), &settings) else { return Ok(false) };
    let panel = crate::render::Panel::new(method, settings);
    crate::render::check_tiled(args, &panel, args.image.dump.as_deref())?;
    let format = wgpu::TextureFormat::Rgba8UnormSrgb;
    let mut chain = lineao::AoChain::new(&session.gpu.device, format, panel.settings.clone())?;
    let (width, height) = (args.image.width, args.image.height);
    let file = std::fs::File::create(output).with_context(|| format!("cannot create {}", output.display()))?;
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    let mut rows = encoder.write_header()?.into_stream_writer()?;
    let options = crate::render::FrameOptions { settled: true, ..Default::default() };
    session.render_tiles(args, &mut chain, tile, options, |_, band| {
        std::io::Write::write_all(&mut rows, &band.data).with_context(|| format!("writing {}", output.display()))
    })?;
    rows.finish().with_context(|| format!("writing {}", output.display()))?;
    eprintln!(
        "lineao: {} ({} streamlines, {} vertices) with {} at {width} x {height} in tiles of {tile} px on {} -> {}",
        session.lines.name,
        session.lines.geometry.streamlines,
        session.lines.geometry.vertices,
        panel.label,
        session.gpu.describe(),
        output.display()
    );
    Ok(true)
}

/// `score` takes `render`'s options for its frame, but not these: an error naming them.
pub fn refuse_in_score(figure: &FigureArgs) -> Result<()> {
    let given = [("--views", !figure.views.is_empty()), ("--turntable", figure.turntable.is_some())];
    match given.iter().find(|(_, given)| *given) {
        Some((flag, _)) => anyhow::bail!("{flag} is render's: score scores one frame"),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cameras::{AnatomicalView, check_views, parse_view, turntable};
    use glam::Vec3;
    use lineao::Camera;

    #[test]
    fn views_parse_by_name_and_synonym_once_each() {
        let views: Vec<AnatomicalView> =
            "left,Right, superior,anterior".split(',').map(|v| parse_view(v).unwrap()).collect();
        assert_eq!(views, [AnatomicalView::Left, AnatomicalView::Right, AnatomicalView::Top, AnatomicalView::Front]);
        assert!(check_views(&views).is_ok());
        assert!(parse_view("sideways").unwrap_err().contains("'sideways' is not a view"));
        let twice = [AnatomicalView::Top, AnatomicalView::Left, AnatomicalView::Top];
        assert!(check_views(&twice).unwrap_err().contains("'top' twice"));
    }

    #[test]
    fn a_view_keeps_the_target_and_distance_and_looks_from_its_side() {
        let base = Camera {
            eye: Vec3::new(10.0, -200.0, 30.0),
            target: Vec3::new(10.0, 0.0, 30.0),
            up: Vec3::Z,
            projection: lineao::Projection::Perspective { fov_y_deg: 30.0 },
        };
        let left = AnatomicalView::Left.camera(&base);
        assert_eq!((left.eye, left.up, left.target), (Vec3::new(-190.0, 0.0, 30.0), Vec3::Z, base.target));
        let top = AnatomicalView::Top.camera(&base);
        assert_eq!((top.eye, top.up), (Vec3::new(10.0, 0.0, 230.0), Vec3::Y));
    }

    #[test]
    fn a_turntable_turns_about_the_up_axis_keeping_distance_and_height() {
        let base = Camera {
            eye: Vec3::new(0.0, -100.0, 20.0),
            target: Vec3::ZERO,
            up: Vec3::new(0.0, 0.0, 2.0),
            projection: lineao::Projection::Perspective { fov_y_deg: 30.0 },
        };
        let cameras = turntable(&base, 4, 360.0);
        assert_eq!(cameras[0], base);
        // A quarter turn counter-clockwise seen from above: -y goes to +x.
        assert!(cameras[1].eye.distance(Vec3::new(100.0, 0.0, 20.0)) < 1e-4, "{}", cameras[1].eye);
        assert!(cameras[2].eye.distance(Vec3::new(0.0, 100.0, 20.0)) < 1e-4, "{}", cameras[2].eye);
        assert!(turntable(&base, 2, -180.0)[1].eye.distance(Vec3::new(-100.0, 0.0, 20.0)) < 1e-4);
    }

    #[test]
    fn frames_are_named_with_enough_digits_to_sort() {
        let out = Path::new("/tmp/spin.png");
        assert_eq!(frame_path(out, 7, 36), Path::new("/tmp/spin-007.png"));
        assert_eq!(frame_path(out, 12, 2000), Path::new("/tmp/spin-0012.png"));
        assert_eq!(frame_pattern(out, 36), Path::new("/tmp/spin-%03d.png"));
        assert_eq!(crate::render::columns(4), 2);
        assert_eq!(crate::render::columns(5), 3);
        assert_eq!(crate::render::columns(1), 1);
    }

    #[test]
    fn a_movie_is_an_apng_unless_named_otherwise() {
        let figure = |movie: Option<&str>| FigureArgs { movie: movie.map(PathBuf::from), ..Default::default() };
        let out = Path::new("spin.png");
        assert_eq!(Movie::of(&figure(None), out).unwrap(), Movie::Apng("spin.apng".into()));
        assert_eq!(Movie::of(&figure(Some("none")), out).unwrap(), Movie::None);
        assert_eq!(Movie::of(&figure(Some("a.PNG")), out).unwrap(), Movie::Apng("a.PNG".into()));
        assert!(Movie::of(&figure(Some("a.avi")), out).unwrap_err().to_string().starts_with("--movie a.avi"));
        if !ffmpeg_available() {
            let e = Movie::of(&figure(Some("a.mp4")), out).unwrap_err().to_string();
            assert!(e.contains("--movie a.mp4") && e.contains("ffmpeg"), "{e}");
        }
    }

    /// The pixels where two pictures of one size differ, and the share of those within
    /// `reach` pixels of a seam between tiles of `tile`.
    fn differences(a: &Rgba8, b: &Rgba8, tile: u32, reach: u32) -> (usize, usize) {
        assert_eq!((a.width, a.height), (b.width, b.height));
        let near_seam = |v: u32, side: u32| {
            let m = v % tile;
            (v >= tile || m >= tile - reach) && v < side && (m < reach || m >= tile - reach)
        };
        let mut differ = (0, 0);
        for (k, (p, q)) in a.data.chunks(4).zip(b.data.chunks(4)).enumerate() {
            if p != q {
                let (x, y) = (k as u32 % a.width, k as u32 / a.width);
                differ.0 += 1;
                differ.1 += (near_seam(x, a.width) || near_seam(y, a.height)) as usize;
            }
        }
        differ
    }

    fn session(extra: &[&str]) -> (Box<RenderArgs>, Session) {
        let argv = ["lineao", "render", "--vertices", "60000", "--width", "320", "--height", "256"];
        let args = crate::args::parse_render(argv.iter().chain(extra));
        let session = Session::open(&args).unwrap();
        (args, session)
    }

    /// A picture rendered as tiles equals the picture rendered whole but where float rounding
    /// moves a line's edge across a pixel centre (the tile's projection is the picture's moved
    /// off axis: its vertices land within 1e-4 px of the picture's): scattered pixels, none of
    /// them along a seam; the guard band is what keeps the seams away (without it the AO at a
    /// tile's border misses what lies beyond).
    #[test]
    fn tiles_stitch_into_the_picture_without_a_seam() {
        // Dense tubes tie in depth where two nearly coincide, and a tie goes either way.
        let cases: [(&[&str], u32, f64); 6] = [
            (&["--method", "none"], 128, 0.0002),
            (&["--geometry", "tubes"], 128, 0.05),
            (&["--method", "lineao"], 128, 0.001),
            (&["--method", "lineao"], 192, 0.001),
            (&["--method", "vo-line"], 128, 0.002),
            (&["--method", "ssao", "--ortho", "160"], 64, 0.002),
        ];
        for (extra, tile, bound) in cases {
            let (args, mut whole_session) = session(extra);
            let (whole, _) = whole_session.compose(&args, &mut Vec::new()).unwrap();
            let tiled_args = crate::args::parse_render(
                [
                    "lineao",
                    "render",
                    "--vertices",
                    "60000",
                    "--width",
                    "320",
                    "--height",
                    "256",
                    "--tile",
                    &tile.to_string(),
                ]
                .iter()
                .chain(extra),
            );
            let (tiled, _) = whole_session.compose(&tiled_args, &mut Vec::new()).unwrap();
            let (differ, at_seams) = differences(&whole, &tiled, tile, 2);
            let share = differ as f64 / (320.0 * 256.0);
            eprintln!("{extra:?} --tile {tile}: {differ} pixels differ, {at_seams} of them within 2 px of a seam");
            assert!(share <= bound, "{extra:?} --tile {tile}: {differ} pixels differ");
            assert!(at_seams <= differ / 4 + 2, "{extra:?} --tile {tile}: {at_seams} of {differ} at seams");
            // The same without a guard band: seams.
            if extra.contains(&"lineao") && tile == 128 {
                let no_guard = |mut a: Box<RenderArgs>| {
                    a.chain.guard_max = 0;
                    a
                };
                let (whole, _) = whole_session.compose(&no_guard(args.clone()), &mut Vec::new()).unwrap();
                let (tiled, _) = whole_session.compose(&no_guard(tiled_args.clone()), &mut Vec::new()).unwrap();
                let (differ, at_seams) = differences(&whole, &tiled, tile, 2);
                // Far more pixels, a share of them along the seams themselves.
                let many = 20.0 * bound * 320.0 * 256.0;
                assert!(
                    differ as f64 > many && at_seams > 200,
                    "without a guard band: {at_seams} of {differ} at seams"
                );
            }
        }
    }

    /// Each panel of `--views` is the picture `render` makes from that view's camera (the
    /// label and the grid's lines aside), with --compare too.
    #[test]
    fn each_view_of_the_figure_is_that_views_picture() {
        for extra in [&[][..], &["--compare", "none,lineao"]] {
            let mut argv = vec!["--views", "left,top,back"];
            argv.extend(extra);
            let (args, mut session) = session(&argv);
            let (figure, _) = session.compose(&args, &mut Vec::new()).unwrap();
            assert_eq!((figure.width, figure.height), (2 * 320, 2 * 256));
            let base = session.camera;
            let single = crate::args::parse_render(
                ["lineao", "render", "--vertices", "60000", "--width", "320", "--height", "256"].iter().chain(extra),
            );
            for (k, view) in [AnatomicalView::Left, AnatomicalView::Top, AnatomicalView::Back].into_iter().enumerate() {
                session.camera = view.camera(&base);
                let (picture, _) = session.compose(&single, &mut Vec::new()).unwrap();
                session.camera = base;
                let (x0, y0) = ((k as u32 % 2) * 320, (k as u32 / 2) * 256);
                // Below the labels (the view's, and --compare's), right of the grid's line.
                let mut differ = 0;
                for y in 40..256 {
                    for x in 4..320 {
                        let at = |img: &Rgba8, x: u32, y: u32| {
                            let i = 4 * (y as usize * img.width as usize + x as usize);
                            img.data[i..i + 4].to_vec()
                        };
                        differ += (at(&figure, x0 + x, y0 + y) != at(&picture, x, y)) as usize;
                    }
                }
                assert_eq!(differ, 0, "{extra:?}: the {} panel", view.name());
            }
        }
    }
}
