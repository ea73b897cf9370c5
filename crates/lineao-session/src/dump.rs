//! `--dump DIR` (docs/reference.md): the method's inputs and raw output at the guard-banded size, so an
//! outside implementation can recompute the result: `nd_<j>.npy`, `zoom.npy`, `ao.npy`,
//! `noise.npy`, `samples.npy` (LineAO), `ssao_kernel.npy`, `ssao_noise.npy` (SSAO) or
//! `vo_samples.npy`, `vo_noise.npy` (VO; area sampling adds `moments_<l>.npy`, H_l × W_l × 2),
//! and `params.json`. `ao.npy` is the method's raw occlusion, before SSAO's blur and before the
//! bilateral blur; with the bilateral blur `ao_blurred.npy` (H × W) is what it made of it, our
//! extension.
//!
//! Object-space AO (our extension of docs/reference.md) adds `octants.npy` (H × W × 8: the lines'
//! octant visibilities per pixel, as the `volume_ao` pass reads them), `geometry_term.npy`
//! (T × T × 8: G_o over the octahedral map) and `volume_ao.npy` (H × W), and the keys `volume`
//! (`sweep`, `variance-volume`), `volume_normal` (`pixel`, `tangent`, `none`), `sky` (eight
//! weights), `view_to_world` (3 × 3, row-major), `volume_resolution`, `occupancy_radius`,
//! `sweep_alpha` or `variance` ({`levels`, `iso`, `offset`}), and with a screen-space method
//! `volume_combine`. `method` is then `sweep`, `variance-volume` or e.g. `lineao+sweep`;
//! `ao.npy` is `volume_ao.npy` alone, the screen-space method's otherwise.
//!
//! Lines (not tubes) also write `line_shading` (`specular` or `cylinder`, `--line-shading`), our
//! extension too.

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use anyhow::{Context, Result};
use lineao::method::setting::{Kind, Value};
use lineao::readback::read_texture;
use lineao::volume::{ScalarForm, VolumeAoOptions, VolumeMethod};
use lineao::{AoChain, AoMethod, Gpu};
use lineao::{Camera, Projection};
use npyz::WriterBuilder;
use serde_json::json;

fn write_npy(dir: &Path, name: &str, shape: &[u64], data: &[f32]) -> Result<()> {
    write_typed_npy(dir, name, shape, data)
}

/// `selected.npy`: with a selection, one byte per streamline, 1 where it is shown.
pub fn write_selection(dir: &Path, selected: &[bool]) -> Result<()> {
    let bytes: Vec<u8> = selected.iter().map(|&s| s as u8).collect();
    write_typed_npy(dir, "selected.npy", &[bytes.len() as u64], &bytes)
}

fn write_typed_npy<T: npyz::Serialize + npyz::AutoSerialize + Copy>(
    dir: &Path,
    name: &str,
    shape: &[u64],
    data: &[T],
) -> Result<()> {
    let path = dir.join(name);
    let file = File::create(&path).with_context(|| format!("cannot create {}", path.display()))?;
    let mut writer = npyz::WriteOptions::new()
        .default_dtype()
        .shape(shape)
        .writer(BufWriter::new(file))
        .begin_nd()
        .with_context(|| format!("cannot write {}", path.display()))?;
    writer.extend(data.iter().copied()).with_context(|| format!("cannot write {}", path.display()))?;
    writer.finish().with_context(|| format!("cannot write {}", path.display()))?;
    Ok(())
}

/// Adds the keys of the JSON object `extra` to the object `params`.
fn merge(params: &mut serde_json::Value, extra: serde_json::Value) {
    if let (Some(params), serde_json::Value::Object(extra)) = (params.as_object_mut(), extra) {
        params.extend(extra);
    }
}

/// Writes the dump of the frame `chain` last prepared, for `method` (its name in `params.json`)
/// with object-space AO computed by `volume` where the chain shows it.
pub fn write(
    dir: &Path,
    gpu: &Gpu,
    chain: &AoChain,
    camera: &Camera,
    method: &str,
    volume: Option<&VolumeAoOptions>,
) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let (targets, view) = chain.targets().zip(chain.frame_view()).context("nothing was rendered")?;
    let s = chain.settings();
    let read = |texture: &wgpu::Texture| read_texture(&gpu.device, &gpu.queue, texture);

    for (j, level) in targets.nd.iter().enumerate() {
        let data = read(&level.texture)?;
        write_npy(dir, &format!("nd_{j}.npy"), &[data.height as u64, data.width as u64, 4], &data.to_f32())?;
    }
    let (w, h) = (targets.size.0 as u64, targets.size.1 as u64);
    write_npy(dir, "zoom.npy", &[h, w], &read(&targets.zoom.texture)?.to_f32())?;
    // A method's before its own blur (SSAO's 4 × 4 box).
    let unblurred = chain.stage().and_then(|s| s.unblurred());
    let raw = match (s.method, &targets.volume_ao, unblurred) {
        (AoMethod::None, Some(volume_ao), _) => volume_ao,
        (_, _, Some(raw)) => raw,
        _ => &targets.ao,
    };
    write_npy(dir, "ao.npy", &[h, w], &read(&raw.texture)?.to_f32())?;
    if let (Some(blurred), true) = (&targets.ao_blurred, s.bilateral().is_some()) {
        // Our extension of docs/reference.md: what the bilateral blur (the denoiser) made of `ao.npy`.
        write_npy(dir, "ao_blurred.npy", &[h, w], &read(&blurred.texture)?.to_f32())?;
    }

    let mut params = json!({
        "method": method,
        "geometry": if s.tubes.is_some() { "tubes" } else { "lines" },
        "strength": s.strength,
        "zoom_unit": s.zoom_unit,
        "guard_px": targets.guard,
        "depth_near": view.near,
        "depth_far": view.far,
        "width": view.width,
        "height": view.height,
        "camera": match camera.projection {
            Projection::Perspective { fov_y_deg } => json!({
                "eye": camera.eye.to_array(), "target": camera.target.to_array(), "up": camera.up.to_array(), "fov_y_deg": fov_y_deg,
            }),
            Projection::Orthographic { height } => json!({
                "eye": camera.eye.to_array(), "target": camera.target.to_array(), "up": camera.up.to_array(), "ortho_height": height,
            }),
        },
    });
    merge(
        &mut params,
        match &s.tubes {
            Some(tubes) => json!({"tube_radius_world": tubes.radius_world}),
            None => json!({"line_width_px": s.line_width_px, "line_shading": s.lighting.line_shading.name()}),
        },
    );
    if let Some(stage) = chain.stage() {
        // The method's keys and tables, from its folder.
        let dump = stage.dump(gpu, s, view)?;
        params.as_object_mut().context("params.json is an object")?.extend(dump.params);
        for (name, shape, values) in &dump.arrays {
            write_npy(dir, &format!("{name}.npy"), shape, values)?;
        }
    }
    if let (Some(options), Some(settings), Some(octants), Some(volume_ao)) =
        (volume, &s.volume, &targets.octants, &targets.volume_ao)
    {
        let packed: lineao::reference::Image<[u32; 2]> =
            lineao::readback::read_image(&gpu.device, &gpu.queue, octants)?;
        let unpacked: Vec<f32> = packed.data.iter().flat_map(|&p| lineao::reference::unpack_octants(p)).collect();
        write_npy(dir, "octants.npy", &[h, w, 8], &unpacked)?;
        write_npy(dir, "volume_ao.npy", &[h, w], &read(&volume_ao.texture)?.to_f32())?;
        let size = lineao::volume::geometry_term::TABLE_SIZE;
        let table = lineao::volume::geometry_term::GeometryTable::normals(size);
        write_npy(dir, "geometry_term.npy", &[size as u64, size as u64, 8], &table.values.concat())?;
        let rotation = lineao::passes::volume_ao::view_to_world(view).transpose().to_cols_array_2d();
        let mut extra = json!({
            "volume": options.method.name(),
            "volume_normal": match options.form {
                None => "pixel",
                Some(ScalarForm::AroundTangent) => "tangent",
                Some(ScalarForm::NoGeometryTerm) => "none",
            },
            "sky": settings.sky,
            "view_to_world": rotation,
            "volume_resolution": options.density.resolution,
            "occupancy_radius": options.density.occupancy_radius,
        });
        merge(
            &mut extra,
            match options.method {
                VolumeMethod::Sweep => json!({"sweep_alpha": options.sweep.alpha}),
                VolumeMethod::VarianceVolume => json!({"variance": {
                    "levels": options.variance.levels, "iso": options.variance.iso, "offset": options.variance.offset,
                }}),
            },
        );
        if s.method != AoMethod::None {
            merge(&mut extra, json!({"volume_combine": settings.combine.name()}));
        }
        merge(&mut params, extra);
    }
    if let Some((blur, slices_only)) = s.bilateral() {
        // Our extension of docs/reference.md: the blur after `ao.npy` (what the image shows), over
        // every pixel or the anatomy slices' alone.
        let bilateral = json!({"radius_px": blur.radius_px, "depth_sigma_world": blur.depth_sigma_world, "slices_only": slices_only});
        merge(&mut params, json!({ "bilateral": bilateral }));
    }
    // Our extension of docs/reference.md: the method's described settings (`lineao::method::setting`)
    // by their keywords, as `render` takes them (a switch: whether its flag is in force).
    let flags = s.method.info().settings().map(|d| {
        let value = match (d.get(s), d.kind) {
            (Value::Number(x), _) => json!(x),
            (share @ Value::Share(_), _) => json!(share.to_string()),
            (Value::Count(n), _) => json!(n),
            (Value::Choice(name), _) => json!(name),
            (Value::Switch(on), Kind::Switch { given }) => json!(on == given),
            (Value::Switch(on), _) => json!(on),
        };
        (d.keyword(), value)
    });
    merge(&mut params, json!({ "flags": serde_json::Map::from_iter(flags) }));
    let path = dir.join("params.json");
    let text = serde_json::to_string_pretty(&params)?;
    std::fs::write(&path, text + "\n").with_context(|| format!("cannot write {}", path.display()))?;
    Ok(())
}

/// The ray-traced truth's part of a dump (method `raytraced`, traced on the CPU or the GPU;
/// `ao.npy` holds its AO already, denoised with `--denoise`): `ao_stderr.npy` (the rays' mean's
/// standard error, before any denoising) and the `params.json` keys `rays`, `ao_distance_world`,
/// `ao_falloff`, `ray_seed`, and our `buried_share` and `ray_epsilon_world`.
pub fn write_truth(dir: &Path, truth: &lineao::truth::Truth, settings: &lineao::truth::TruthSettings) -> Result<()> {
    let (w, h) = (truth.stderr.width as u64, truth.stderr.height as u64);
    write_npy(dir, "ao_stderr.npy", &[h, w], &truth.stderr.data)?;
    let path = dir.join("params.json");
    let text = std::fs::read_to_string(&path).with_context(|| format!("cannot read {}", path.display()))?;
    let mut params: serde_json::Value = serde_json::from_str(&text)?;
    merge(
        &mut params,
        json!({
            "rays": settings.rays,
            "ao_distance_world": settings.distance_world,
            "ao_falloff": settings.falloff.name(),
            "ray_seed": settings.seed,
            "ray_epsilon_world": lineao::truth::EPSILON_PER_DISTANCE * settings.distance_world as f64,
            "buried_share": truth.buried_share(),
        }),
    );
    let text = serde_json::to_string_pretty(&params)?;
    std::fs::write(&path, text + "\n").with_context(|| format!("cannot write {}", path.display()))?;
    Ok(())
}
