//! A page's frame against lineao's CPU reference: the browser adds no error. The page reads
//! back what its chain's method read (the ND pyramid and the zoom map) and what it wrote (the
//! raw AO, before any blur), with the frame's view and settings ([`Readback`]); the test saves
//! them ([`Readback::write`]) and runs the reference natively on exactly those inputs
//! ([`check`]), judged by docs/reference.md's agreement policy ([`lineao::verify::check_policy`]).

use std::path::Path;

use anyhow::{Context, Result, bail};
use lineao::reference::{self, Image, LineAoParams, NdImage, SsaoParams, ViewParams};
use lineao::verify::{Agreement, check_policy, line_ao_flip_bound, line_ao_reference_flip_bound};
use lineao::{AoMethod, ChainSettings, FrameView, LineAoVariant, SsaoKernel, noise};
use serde::{Deserialize, Serialize};

/// What `meta.json` says of a read-back frame.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Meta {
    pub settings: ChainSettings,
    /// The view as the passes saw it.
    pub view: FrameView,
    /// Each ND level's width and height (level 0: the guard-banded frame).
    pub levels: Vec<[u32; 2]>,
    /// The adapter that rendered it.
    pub adapter: String,
}

/// A frame read back from the page.
pub struct Readback {
    pub meta: Meta,
    pub nd: Vec<NdImage>,
    pub zoom: Image<f32>,
    /// The method's raw occlusion (SSAO's before its blur; before the bilateral blur).
    pub ao: Image<f32>,
}

fn f32s(bytes: &[u8]) -> Vec<f32> {
    bytes.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect()
}

impl Readback {
    /// Reads `dir`: `meta.json`, `nd_<j>.f32` (RGBA), `zoom.f32` and `ao.f32`, little-endian f32.
    pub fn read(dir: &Path) -> Result<Readback> {
        let read = |name: &str| std::fs::read(dir.join(name)).with_context(|| format!("{}/{name}", dir.display()));
        let meta: Meta = serde_json::from_slice(&read("meta.json")?).context("meta.json")?;
        let [w, h] = *meta.levels.first().context("meta.json: no ND levels")?;
        let image = |name: &str, channels: usize, [w, h]: [u32; 2]| -> Result<Vec<f32>> {
            let values = f32s(&read(name)?);
            if values.len() != w as usize * h as usize * channels {
                bail!("{}/{name}: {} values, expected {w} × {h} × {channels}", dir.display(), values.len());
            }
            Ok(values)
        };
        let mut nd = Vec::new();
        for (j, &size) in meta.levels.iter().enumerate() {
            let data = image(&format!("nd_{j}.f32"), 4, size)?;
            let texels = data.chunks_exact(4).map(|t| [t[0], t[1], t[2], t[3]]).collect();
            nd.push(Image { width: size[0] as usize, height: size[1] as usize, data: texels });
        }
        let (width, height) = (w as usize, h as usize);
        let zoom = Image { width, height, data: image("zoom.f32", 1, [w, h])? };
        let ao = Image { width, height, data: image("ao.f32", 1, [w, h])? };
        Ok(Readback { meta, nd, zoom, ao })
    }

    /// Writes what [`Readback::read`] reads.
    pub fn write(&self, dir: &Path) -> Result<()> {
        std::fs::create_dir_all(dir)?;
        let bytes = |values: &mut dyn Iterator<Item = f32>| values.flat_map(f32::to_le_bytes).collect::<Vec<u8>>();
        for (j, level) in self.nd.iter().enumerate() {
            std::fs::write(dir.join(format!("nd_{j}.f32")), bytes(&mut level.data.iter().flatten().copied()))?;
        }
        std::fs::write(dir.join("zoom.f32"), bytes(&mut self.zoom.data.iter().copied()))?;
        std::fs::write(dir.join("ao.f32"), bytes(&mut self.ao.data.iter().copied()))?;
        std::fs::write(dir.join("meta.json"), serde_json::to_vec_pretty(&self.meta)?)?;
        Ok(())
    }
}

/// The CPU reference of the frame's method on its read-back inputs, against its AO.
pub fn check(frame: &Readback) -> Result<Agreement, String> {
    let s = &frame.meta.settings;
    let view = frame.meta.view;
    let (cpu, bound) = match s.method {
        AoMethod::LineAo => {
            let ao = &s.line_ao;
            let params = LineAoParams::new(s, &view);
            let table = lineao::method::line_ao::sample_table(ao);
            let cpu = reference::line_ao(&frame.nd, &frame.zoom, &noise::noise_tile(ao.noise_seed), &table, &params);
            let bound = match ao.variant {
                LineAoVariant::Paper => line_ao_flip_bound(ao.s_r, ao.s_h),
                LineAoVariant::Reference => line_ao_reference_flip_bound(ao.s_h),
            };
            (cpu, bound)
        }
        AoMethod::Ssao => {
            let ssao = &s.ssao;
            let params = SsaoParams {
                view: ViewParams::of(&view),
                radius: ssao.radius_world,
                range: ssao.range_world,
                noise_origin: [view.guard as i32; 2],
            };
            let points = match ssao.kernel {
                SsaoKernel::Crytek => noise::ssao_kernel(ssao.noise_seed, ssao.samples),
                SsaoKernel::Sphere => lineao::sample_sets::vo_sphere_samples(ssao.samples)
                    .ok_or_else(|| format!("no sphere set of {} samples", ssao.samples))?
                    .to_vec(),
            };
            let cpu = reference::ssao(&frame.nd[0], &points, &noise::ssao_noise(ssao.noise_seed), &params);
            (cpu, 2.0 / ssao.samples as f32)
        }
        other => return Err(format!("the page's check covers LineAO and Crytek SSAO, not {}", other.name())),
    };
    check_policy(&frame.ao, &cpu, &frame.nd[0], bound)
}
