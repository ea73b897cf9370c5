//! The page's readback check on a frame rendered natively: the chain's own targets pass it,
//! and an AO off by 0.5 on 1 % of the geometry pixels fails it — so the browser test's check
//! can tell a wrong frame from a right one.

use lineao::readback::{read_f32, read_rgba};
use lineao::targets::Target;
use lineao::{AoChain, AoMethod, Camera, ChainSettings, Gpu, LineGeometry, Preset};
use lineao_web::check::{Meta, Readback, check};

fn frame(gpu: &Gpu, method: AoMethod) -> Readback {
    let (d, q) = (&gpu.device, &gpu.queue);
    let scene = lineao_tracts::SceneKind::Bundles.build(1, 30_000);
    let tracts = &scene.tractogram;
    let geometry = LineGeometry::new(d, q, &tracts.positions, &tracts.offsets).unwrap();
    let settings = ChainSettings { method, ..ChainSettings::default() }.with_preset(Preset::Legible);
    let format = wgpu::TextureFormat::Rgba8UnormSrgb;
    let mut chain = AoChain::new(d, format, settings).unwrap();
    chain.resize(200, 150).unwrap();
    let v = &scene.view;
    let camera = Camera {
        eye: v.eye.into(),
        target: v.target.into(),
        up: v.up.into(),
        projection: lineao::Projection::Perspective { fov_y_deg: v.fov_y_deg },
    };
    let view = chain.prepare(d, q, &camera, &geometry.bounds.unwrap()).unwrap();
    let output = Target::output(d, "test::output", (200, 150), format);
    let mut encoder = d.create_command_encoder(&Default::default());
    chain.encode(&mut encoder, &geometry, &output.view).unwrap();
    q.submit([encoder.finish()]);
    let targets = chain.targets().unwrap();
    let raw = match method {
        AoMethod::Ssao => chain.stage().and_then(|s| s.unblurred()).unwrap(),
        _ => &targets.ao,
    };
    let nd: Vec<_> = targets.nd.iter().map(|t| read_rgba(d, q, t).unwrap()).collect();
    let levels = nd.iter().map(|l| [l.width as u32, l.height as u32]).collect();
    let meta = Meta { settings: chain.settings().clone(), view, levels, adapter: gpu.describe() };
    Readback { meta, nd, zoom: read_f32(d, q, &targets.zoom).unwrap(), ao: read_f32(d, q, raw).unwrap() }
}

#[test]
fn a_right_frame_passes_and_a_wrong_one_fails() {
    let gpu = Gpu::headless().unwrap();
    let dir = std::env::temp_dir().join(format!("lineao-web-check-{}", std::process::id()));
    for method in [AoMethod::LineAo, AoMethod::Ssao] {
        let frame = frame(&gpu, method);
        // Through the files the browser test writes.
        frame.write(&dir).unwrap();
        let mut read = Readback::read(&dir).unwrap();
        let agreement = check(&read).unwrap_or_else(|e| panic!("{}: {e}", method.name()));
        assert!(agreement.pixels > 1000, "{}: {agreement}", method.name());
        let geometry: Vec<usize> = (0..read.ao.data.len()).filter(|&i| read.nd[0].data[i][..3] != [0.0; 3]).collect();
        for &i in geometry.iter().step_by(100) {
            let a = read.ao.data[i];
            read.ao.data[i] = if a > 0.5 { a - 0.5 } else { a + 0.5 };
        }
        let error = check(&read).unwrap_err();
        assert!(error.contains("GPU vs CPU"), "{}: {error}", method.name());
        // A file cut short is named with what it should hold.
        std::fs::write(dir.join("ao.f32"), [0u8; 12]).unwrap();
        let error = format!("{:#}", Readback::read(&dir).err().unwrap());
        assert!(error.contains("ao.f32: 3 values, expected"), "{error}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
