//! `lineao bench-load`: how fast files load, against reading their bytes and against nibabel.
//!
//! Writes a synthetic tractogram of `--vertices` points as `.tck`, `.trk` and stored `.trx` (our
//! writers), then for each file, in one run: the time to read its bytes from the page cache —
//! into a fresh buffer of the file's size (`std::fs::read`: what holding the bytes costs,
//! page faults included; the floor we are judged against) and into one reused 1 MiB buffer
//! (the copy alone) — `lineao_tracts::load` in process, the whole
//! `lineao info` process, its peak resident memory minus that of `lineao info` on an empty file
//! (docs/reference.md's memory measure), and — when Python has nibabel — nibabel's
//! `nibabel.streamlines.load` timed in process on the same file. Medians of `--repeat` runs.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};
use lineao_tracts::SceneKind;
use serde_json::json;

use crate::cli::BenchLoadArgs;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn time<T>(repeat: u32, mut f: impl FnMut() -> Result<T>) -> Result<f64> {
    let mut ms = Vec::new();
    for _ in 0..repeat {
        let start = Instant::now();
        std::hint::black_box(f()?);
        ms.push(start.elapsed().as_secs_f64() * 1e3);
    }
    Ok(median(ms))
}

fn read_bytes(path: &Path) -> Result<u64> {
    let mut f = std::fs::File::open(path)?;
    let mut buf = vec![0u8; 1 << 20];
    let mut total = 0u64;
    loop {
        match f.read(&mut buf)? {
            0 => return Ok(total),
            n => total += n as u64,
        }
    }
}

/// Wall time and peak RSS (KiB) of `lineao info FILE`, by wait4's rusage.
fn info_process(path: &Path) -> Result<(f64, u64)> {
    let exe = std::env::current_exe()?;
    let start = Instant::now();
    let child = std::process::Command::new(exe)
        .arg("info")
        .arg(path)
        .stdout(std::process::Stdio::null())
        .spawn()
        .context("starting lineao info")?;
    let mut status = 0;
    // SAFETY: an all-zero rusage is a valid value; wait4 fills it for our own child.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let pid = unsafe { libc::wait4(child.id() as i32, &mut status, 0, &mut usage) };
    let ms = start.elapsed().as_secs_f64() * 1e3;
    anyhow::ensure!(
        pid > 0 && libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0,
        "lineao info {} failed",
        path.display()
    );
    Ok((ms, usage.ru_maxrss as u64))
}

/// nibabel's in-process load time (median of `repeat`), if Python has nibabel.
fn nibabel(path: &Path, repeat: u32) -> Option<f64> {
    let script = format!(
        "import time, nibabel as nib\nts=[]\nfor _ in range({repeat}):\n    t=time.perf_counter(); s=nib.streamlines.load({:?}); n=len(s.streamlines._data); ts.append(time.perf_counter()-t)\nts.sort(); print(ts[len(ts)//2]*1e3)",
        path.to_string_lossy()
    );
    let out = std::process::Command::new("python3").args(["-c", &script]).output().ok()?;
    String::from_utf8_lossy(&out.stdout).trim().parse().ok()
}

pub fn run(args: &BenchLoadArgs) -> Result<()> {
    let dir = tempdir(args.dir.as_deref())?;
    let scene = SceneKind::Bundles.build(args.seed, args.vertices);
    let t = &scene.tractogram;
    let payload = (t.vertices() * 12 + t.offsets.len() * 8) as f64;
    eprintln!("lineao: bench-load: {} streamlines, {} vertices, in {}", t.streamlines(), t.vertices(), dir.display());
    let empty = dir.join("empty.tck");
    lineao_tracts::save(&lineao_tracts::Tractogram::new(), &empty)?;
    let (_, empty_rss) = info_process(&empty)?;
    let mut rows = Vec::new();
    for ext in &args.formats {
        let path = dir.join(format!("bench.{ext}"));
        lineao_tracts::save(t, &path)?;
        let bytes = std::fs::metadata(&path)?.len() as f64;
        read_bytes(&path)?; // into the page cache
        let read_ms = time(args.repeat, || read_bytes(&path))?;
        let fresh_ms = time(args.repeat, || Ok(std::fs::read(&path)?.len()))?;
        let load_ms = time(args.repeat, || Ok(lineao_tracts::load(&path)?.tractogram.vertices()))?;
        let mut info = Vec::new();
        let mut rss = 0;
        for _ in 0..args.repeat {
            let (ms, kib) = info_process(&path)?;
            info.push(ms);
            rss = rss.max(kib);
        }
        let info_ms = median(info);
        let nib_ms = if args.no_nibabel { None } else { nibabel(&path, args.repeat.min(3)) };
        let mb = bytes / 1e6;
        let rss_ratio = (rss.saturating_sub(empty_rss) * 1024) as f64 / payload;
        rows.push(json!({
            "format": ext,
            "file_mb": mb,
            "read_ms": read_ms,
            "fs_read_ms": fresh_ms,
            "fs_read_mb_s": mb / fresh_ms * 1e3,
            "info_over_fs_read": info_ms / fresh_ms,
            "load_ms": load_ms,
            "info_ms": info_ms,
            "read_mb_s": mb / read_ms * 1e3,
            "load_mb_s": mb / load_ms * 1e3,
            "info_over_read": info_ms / read_ms,
            "peak_rss_over_payload": rss_ratio,
            "nibabel_ms": nib_ms,
            "nibabel_mb_s": nib_ms.map(|ms| mb / ms * 1e3),
            "speedup_vs_nibabel": nib_ms.map(|ms| ms / load_ms),
        }));
    }
    let report =
        json!({ "vertices": t.vertices(), "streamlines": t.streamlines(), "payload_mb": payload / 1e6, "files": rows });
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        println!(
            "{:<5} {:>8} {:>10} {:>10} {:>10} {:>10} {:>9} {:>9} {:>10} {:>11}",
            "",
            "MB",
            "copy MB/s",
            "fs::read",
            "load MB/s",
            "info ms",
            "info/read",
            "RSS/data",
            "nib MB/s",
            "vs nibabel"
        );
        for r in report["files"].as_array().unwrap() {
            let f = |k: &str| r[k].as_f64().map_or("-".to_string(), |v| format!("{v:.2}"));
            println!(
                "{:<5} {:>8} {:>10} {:>10} {:>10} {:>10} {:>9} {:>9} {:>10} {:>11}",
                r["format"].as_str().unwrap(),
                f("file_mb"),
                f("read_mb_s"),
                f("fs_read_mb_s"),
                f("load_mb_s"),
                f("info_ms"),
                f("info_over_fs_read"),
                f("peak_rss_over_payload"),
                f("nibabel_mb_s"),
                f("speedup_vs_nibabel")
            );
        }
    }
    if args.dir.is_none() {
        std::fs::remove_dir_all(&dir).ok();
    }
    Ok(())
}

fn tempdir(dir: Option<&Path>) -> Result<PathBuf> {
    let dir = match dir {
        Some(d) => d.to_path_buf(),
        None => std::env::temp_dir().join(format!("lineao-bench-load-{}", std::process::id())),
    };
    std::fs::create_dir_all(&dir)?;
    Ok(dir)
}
