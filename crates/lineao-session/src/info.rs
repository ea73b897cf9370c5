//! `lineao info` and `lineao convert`, and the progress bar every file-loading command shares.

use std::path::Path;

use anyhow::Result;
use lineao_tracts::{LoadOptions, Loaded, Tractogram};
use serde_json::{Value, json};

use crate::args::{ConvertArgs, InfoArgs};

/// Loads a file, with a progress bar on a terminal for files over 32 MiB.
pub fn load(path: &Path) -> Result<Loaded> {
    let Some(bar) = crate::source::progress_bar(path) else { return Ok(lineao_tracts::load(path)?) };
    let mut report = |p: lineao_tracts::Progress| {
        bar.set_position(p.bytes);
        std::ops::ControlFlow::Continue(())
    };
    let loaded = lineao_tracts::load_with(path, &LoadOptions::default(), Some(&mut report));
    bar.finish_and_clear();
    Ok(loaded?)
}

/// docs/reference.md's `lineao info --json` object.
pub fn describe(loaded: &Loaded) -> Value {
    let t = &loaded.tractogram;
    let point = |p: Option<&[f32; 3]>| p.map_or(Value::Null, |p| json!(p));
    let (first, last) = if t.has_points() { (t.positions.first(), t.positions.last()) } else { (None, None) };
    let fields = |fields: &[lineao_tracts::Field]| {
        Value::Object(fields.iter().map(|f| (trimmed(&f.name), json!(f.columns))).collect())
    };
    json!({
        "format": loaded.format.name(),
        "compression": loaded.compression.name(),
        "streamlines": t.streamlines(),
        "vertices": t.vertices(),
        "first_point": point(first),
        "last_point": point(last),
        "bounds": t.bounds().map_or(Value::Null, |b| json!({"min": b.min, "max": b.max})),
        "vertex_fields": fields(&t.vertex_fields),
        "streamline_fields": fields(&t.streamline_fields),
        "groups": Value::Object(t.groups.iter().map(|g| (trimmed(&g.name), json!(g.streamlines.len()))).collect()),
        "affine": t.space.map_or(Value::Null, |s| json!(s.affine)),
        "dimensions": t.space.map_or(Value::Null, |s| json!(s.dimensions)),
        "voxel_sizes": t.space.and_then(|s| s.voxel_sizes).map_or(Value::Null, |v| json!(v)),
    })
}

fn trimmed(name: &str) -> String {
    name.trim_end_matches([' ', '\0']).to_string()
}

pub fn run(args: &InfoArgs) -> Result<()> {
    let loaded = load(&args.file)?;
    let mut info = describe(&loaded);
    if let Some(selection) = args.select.selection() {
        let selected =
            selection.mask(&loaded.tractogram).map_err(|e| anyhow::anyhow!("{}: {e}", args.file.display()))?;
        info["selected"] = json!(selected.iter().filter(|&&k| k).count());
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&info)?);
        return Ok(());
    }
    let t: &Tractogram = &loaded.tractogram;
    println!("file         {}", args.file.display());
    println!("format       {} ({})", loaded.format.name(), loaded.compression.name());
    println!("streamlines  {}", t.streamlines());
    println!("vertices     {}", t.vertices());
    for key in ["first_point", "last_point", "bounds", "affine", "dimensions", "voxel_sizes"] {
        println!("{key:<12} {}", info[key]);
    }
    for key in ["vertex_fields", "streamline_fields", "groups"] {
        println!("{key:<12} {}", info[key]);
    }
    if let Some(selected) = info.get("selected") {
        println!("selected     {selected}");
    }
    Ok(())
}

pub fn convert(args: &ConvertArgs) -> Result<()> {
    let (input, output, tractogram) = match (args.scene, &args.output) {
        (Some(kind), None) => {
            let vertices = args.vertices.unwrap_or(kind.default_vertices());
            let name = format!("{} ({vertices} vertices, seed {})", kind.name(), args.seed);
            (name, &args.input, kind.build(args.seed, vertices).tractogram)
        }
        (None, Some(output)) => (args.input.display().to_string(), output, load(&args.input)?.tractogram),
        (Some(_), Some(_)) => anyhow::bail!("convert --scene KIND takes the file to write alone"),
        (None, None) => unreachable!("clap requires OUTPUT without --scene"),
    };
    let dropped = lineao_tracts::save(&tractogram, output)?;
    if !dropped.is_empty() {
        eprintln!("lineao: warning: {} cannot hold these fields, left out: {}", output.display(), dropped.join(", "));
    }
    eprintln!(
        "lineao: {input} ({} streamlines, {} vertices) -> {}",
        tractogram.streamlines(),
        tractogram.vertices(),
        output.display()
    );
    Ok(())
}
