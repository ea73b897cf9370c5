//! A page's frame against lineao's CPU reference: the browser adds no error. The page reads
//! back what its chain's method read (the ND pyramid and the zoom map) and what it wrote (the
//! raw AO, before any blur), with the frame's view and settings ([`Readback`]); the test saves
//! them ([`Readback::write`]) and runs the reference natively on exactly those inputs
//! ([`check`]), judged by docs/reference.md's agreement policy ([`lineao::verify::check_policy`]).

use std::path::Path;

use anyhow::{Context, Result, bail};
use lineao::reference::{Image, NdImage};
use lineao::verify::{Agreement, FrameInputs, check_policy, reference_ao};
use lineao::{ChainSettings, FrameView};
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
    let inputs = FrameInputs { settings: s, view: &frame.meta.view, nd: &frame.nd, zoom: &frame.zoom };
    let expected = reference_ao(&inputs)
        .ok_or_else(|| {
            format!("the page's check covers the methods with a CPU reference of their frame, not {}", s.method.name())
        })?
        .map_err(|e| e.to_string())?;
    check_policy(&frame.ao, &expected.ao, &frame.nd[0], expected.every_pixel_bound)
}
