//! Helpers the end-to-end tests share: running the `lineao` binary and scratch folders.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs the `lineao` binary under test.
#[allow(dead_code)]
pub fn lineao(args: &[&str]) -> Output {
    lineao_command().args(args).output().unwrap()
}

/// The `lineao` binary under test, for callers that set more than arguments.
#[allow(dead_code)]
pub fn lineao_command() -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_lineao"));
    command.env("XDG_RUNTIME_DIR", std::env::temp_dir());
    command
}

/// An empty folder under cargo's test scratch space.
pub fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// An 8-bit RGBA PNG's size and pixels.
#[allow(dead_code)]
pub fn read_png(path: &Path) -> ((u32, u32), Vec<u8>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buffer = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buffer).unwrap();
    buffer.truncate(info.buffer_size());
    ((info.width, info.height), buffer)
}
