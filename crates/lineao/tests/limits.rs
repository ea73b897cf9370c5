//! Size limits: geometry larger than the device's buffers is split, images larger than its
//! textures are a clear error, and empty sizes or empty geometry draw nothing.

mod common;

use common::{gpu, render_geometry};
use glam::Vec3;
use lineao::LineGeometry;
use lineao::{AoChain, AoMethod, ChainSettings, Error, Gpu};
use lineao::{Bounds, Camera, Projection};

fn spiral_bundle(lines: usize, points: usize) -> (Vec<[f32; 3]>, Vec<u64>) {
    let mut positions = Vec::with_capacity(lines * points);
    let mut offsets = vec![0u64];
    for k in 0..lines {
        let phase = k as f32 * 0.05;
        positions.extend((0..points).map(|i| {
            let s = i as f32 / (points - 1) as f32;
            [(20.0 + 10.0 * phase.sin()) * (6.0 * s + phase).cos(), -40.0 + 80.0 * s, 20.0 * (6.0 * s + phase).sin()]
        }));
        offsets.push(positions.len() as u64);
    }
    (positions, offsets)
}

fn camera() -> Camera {
    Camera {
        eye: Vec3::new(0.0, 10.0, 150.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        projection: Projection::Perspective { fov_y_deg: 45.0 },
    }
}

#[test]
fn a_device_with_small_buffers_gets_more_of_them_and_the_same_image() {
    let gpu = gpu();
    // The same adapter, as a host might open it: buffers of at most 256 KiB, storage bindings
    // of 64 KiB.
    let limits =
        wgpu::Limits { max_buffer_size: 256 << 10, max_storage_buffer_binding_size: 64 << 10, ..gpu.adapter.limits() };
    let descriptor = wgpu::DeviceDescriptor { required_limits: limits, ..Gpu::device_descriptor(&gpu.adapter) };
    let (device, queue) = pollster::block_on(gpu.adapter.request_device(&descriptor)).unwrap();
    let small = Gpu::new(gpu.instance.clone(), gpu.adapter.clone(), device, queue);

    let (positions, offsets) = spiral_bundle(100, 200);
    let big = LineGeometry::new(&gpu.device, &gpu.queue, &positions, &offsets).unwrap();
    let split = LineGeometry::new(&small.device, &small.queue, &positions, &offsets).unwrap();
    // 20 000 points in pages of 8 192 (64 KiB of octant visibilities at 8 bytes a point).
    // (Readback splits textures into bands of rows that fit the buffers; depth only fits whole.)
    assert_eq!(big.page_count(), 1);
    assert_eq!(split.page_count(), 3);

    let bounds = big.bounds.unwrap();
    // Both draw every line: the small device cannot cull (its storage bindings cannot hold
    // the depth pyramid), and culled lines are the full strip, not the alternating one.
    let settings = ChainSettings { cull: false, ..ChainSettings::default() };
    let a = render_geometry(&gpu, &big, &camera(), bounds, settings.clone(), (160, 120));
    let b = render_geometry(&small, &split, &camera(), bounds, settings, (160, 120));
    assert_eq!(a.nd[0], b.nd[0]);
    assert_eq!(a.ao, b.ao);
    assert!(a.ao.data.iter().any(|&v| v > 0.1));
}

#[test]
fn sizes_beyond_the_adapter_are_errors_and_zero_draws_nothing() {
    let gpu = gpu();
    let mut chain = AoChain::new(&gpu.device, common::OUTPUT_FORMAT, ChainSettings::default()).unwrap();
    let max = gpu.device.limits().max_texture_dimension_2d;
    match chain.resize(max, 16) {
        Err(Error::TooLarge { limit, message, .. }) => {
            assert_eq!(limit, lineao::Limit::TextureDimension2d);
            assert!(message.contains(&max.to_string()), "{message}");
        }
        other => panic!("expected TooLarge, got {other:?}"),
    }
    // A minimized window: no targets, no view, encoding records nothing.
    chain.resize(0, 0).unwrap();
    let bounds = Bounds { center: Vec3::ZERO, radius: 50.0 };
    assert!(chain.prepare(&gpu.device, &gpu.queue, &camera(), &bounds).is_none());
    let empty = LineGeometry::new(&gpu.device, &gpu.queue, &[], &[0]).unwrap();
    assert_eq!((empty.page_count(), empty.bounds), (0, None));
    let output = lineao::targets::Target::output(&gpu.device, "test::output", (8, 8), common::OUTPUT_FORMAT);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    chain.encode(&mut encoder, &empty, &output.view).unwrap();
    gpu.queue.submit([encoder.finish()]);

    // Back to a real size, empty geometry renders background only.
    let frame = render_geometry(&gpu, &empty, &camera(), bounds, ChainSettings::default(), (32, 24));
    assert!(frame.nd[0].data.iter().all(|t| *t == [0.0, 0.0, 0.0, 1.0]));
    assert!(frame.ao.data.iter().all(|&a| a == 0.0));
}

#[test]
fn a_moments_pyramid_beyond_the_storage_limit_is_an_error() {
    let gpu = gpu();
    let limits = wgpu::Limits { max_storage_buffer_binding_size: 1 << 20, ..gpu.adapter.limits() };
    let descriptor = wgpu::DeviceDescriptor { required_limits: limits, ..Gpu::device_descriptor(&gpu.adapter) };
    let (device, _queue) = pollster::block_on(gpu.adapter.request_device(&descriptor)).unwrap();
    let area = ChainSettings { method: lineao::AoMethod::VoArea, ..ChainSettings::default() };
    // 640 × 480 with the guard band needs about 4 MiB of moments.
    let mut chain = AoChain::new(&device, common::OUTPUT_FORMAT, area.clone()).unwrap();
    match chain.resize(640, 480) {
        Err(Error::TooLarge { limit, value, max, message }) => {
            assert_eq!(limit, lineao::Limit::StorageBuffer);
            assert!(value > max && message.contains("moments"), "{message}");
        }
        other => panic!("expected TooLarge, got {other:?}"),
    }
    chain.resize(64, 48).unwrap();
    // Switching to VO area at a size it cannot hold is refused the same way; LineAO is fine.
    let mut chain = AoChain::new(&device, common::OUTPUT_FORMAT, ChainSettings::default()).unwrap();
    chain.resize(640, 480).unwrap();
    assert!(matches!(chain.set_settings(&device, area), Err(Error::TooLarge { .. })));
}

#[test]
fn what_the_device_cannot_do_is_a_clear_error() {
    let gpu = gpu();
    lineao::check_adapter(&gpu.adapter).expect("the test adapter runs lineao");
    // A host's surface format that cannot be rendered to: refused by `new`, not wgpu's panic.
    let error = AoChain::new(&gpu.device, wgpu::TextureFormat::Rgb9e5Ufloat, ChainSettings::default()).err();
    let message = error.as_ref().map(ToString::to_string).unwrap_or_default();
    assert!(matches!(error, Some(Error::Unsupported(_))) && message.contains("Rgb9e5Ufloat"), "{message}");
    // The device stays usable afterwards.
    assert!(AoChain::new(&gpu.device, wgpu::TextureFormat::Rgba8Unorm, ChainSettings::default()).is_ok());
}

#[test]
fn a_chain_can_move_between_threads_and_be_shared() {
    fn send_and_sync<T: Send + Sync>() {}
    send_and_sync::<AoChain>();
    send_and_sync::<lineao::HostAo>();
    send_and_sync::<lineao::OverlayAo>();
    send_and_sync::<LineGeometry>();
}

/// One chain switched between methods and sizes (stages built lazily, kept ones rebound to the
/// targets of the moment) renders exactly what a fresh chain renders for each settings.
#[test]
fn a_chain_switching_methods_renders_what_fresh_chains_do() {
    let gpu = common::gpu();
    let (d, q) = (&gpu.device, &gpu.queue);
    let (positions, offsets) = common::polylines(60, 0.4);
    let geometry = lineao::LineGeometry::new(d, q, &positions, &offsets).unwrap();
    let bounds = geometry.bounds.unwrap();
    let (camera, _) = common::cameras_for_polylines();
    // No guard band for any method, so that a switch keeps the targets and only selecting a
    // stage can bind them to it.
    // Without levels of detail: a frame after the first would keep pieces within half a pixel of
    // the full strip, not equal to a fresh chain's first frame.
    let with = |method| ChainSettings { method, guard_max_px: 0, lod: false, ..ChainSettings::default() };
    let one_level =
        ChainSettings { line_ao: lineao::LineAoSettings { s_r: 1, ..Default::default() }, ..with(AoMethod::LineAo) };
    let steps = [
        (with(AoMethod::LineAo), (96, 72)),
        (with(AoMethod::Ssao), (96, 72)),
        // The same targets' layout as SSAO's: the new stage must bind them itself.
        (with(AoMethod::VoLine), (96, 72)),
        (with(AoMethod::Ssao), (96, 72)),
        (with(AoMethod::VoArea), (80, 60)),
        (with(AoMethod::None), (80, 60)),
        (one_level, (64, 48)),
        // A kept stage, bound to 96 × 72 targets long gone; the layout is unchanged, so only
        // selecting it can rebind it.
        (with(AoMethod::VoLine), (64, 48)),
        (with(AoMethod::LineAo), (64, 48)),
    ];
    let mut chain = AoChain::new(d, common::OUTPUT_FORMAT, steps[0].0.clone()).unwrap();
    for (i, (settings, (w, h))) in steps.into_iter().enumerate() {
        chain.set_settings(d, settings.clone()).unwrap();
        chain.resize(w, h).unwrap();
        chain.prepare(d, q, &camera, &bounds).unwrap();
        let output = lineao::targets::Target::output(d, "test::output", (w, h), common::OUTPUT_FORMAT);
        let mut encoder = d.create_command_encoder(&Default::default());
        chain.encode(&mut encoder, &geometry, &output.view).unwrap();
        q.submit([encoder.finish()]);
        let switched = lineao::readback::read_rgba(d, q, &output).unwrap();
        let fresh = common::render_geometry(&gpu, &geometry, &camera, bounds, settings.clone(), (w, h)).output;
        assert_eq!(switched.data, fresh.data, "step {i}: {:?} at {w}×{h}", settings.method);
        let ao = lineao::readback::read_f32(d, q, &chain.targets().unwrap().ao).unwrap();
        if settings.method != AoMethod::None {
            assert!(ao.data.iter().any(|&a| a > 0.05), "step {i}: no occlusion at all");
        }
    }
}

/// What a host does while a long frame runs on the GPU — upload geometry, make, size, prepare
/// and record a chain, poll its timings — returns before that frame is done: nothing waits for
/// the device (`GeometryOptions::bounded_staging` is off by default).
#[test]
fn prepare_encode_and_upload_do_not_wait_for_the_device() {
    use std::sync::Arc;
    use std::sync::atomic::{AtomicBool, Ordering};
    let gpu = gpu();
    let (d, q) = (&gpu.device, &gpu.queue);
    let (positions, offsets) = common::polylines(400, 0.3);
    let geometry = LineGeometry::new(d, q, &positions, &offsets).unwrap();
    let bounds = geometry.bounds.unwrap();
    let (camera, _) = common::cameras_for_polylines();
    // A long submission (seconds on lavapipe): LineAO with five hemispheres of up to 128
    // samples on 1536 × 1536.
    let heavy = ChainSettings {
        line_ao: lineao::LineAoSettings { s_r: 5, s_h: 128, ..Default::default() },
        ..ChainSettings::default()
    };
    let mut long = AoChain::new(d, common::OUTPUT_FORMAT, heavy).unwrap();
    long.resize(1536, 1536).unwrap();
    long.prepare(d, q, &camera, &bounds).unwrap();
    let output = lineao::targets::Target::output(d, "test::long", (1536, 1536), common::OUTPUT_FORMAT);
    let mut encoder = d.create_command_encoder(&Default::default());
    long.encode(&mut encoder, &geometry, &output.view).unwrap();
    q.submit([encoder.finish()]);
    let done = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&done);
    q.on_submitted_work_done(move || flag.store(true, Ordering::Release));

    let start = std::time::Instant::now();
    let uploaded = LineGeometry::new(d, q, &positions, &offsets).unwrap();
    // The constructor as a future, as a host on an async runtime (or the web) awaits it.
    let mut chain = pollster::block_on(AoChain::new_async(d, common::OUTPUT_FORMAT, ChainSettings::default())).unwrap();
    let calibrated = ChainSettings::default().with_preset(lineao::Preset::Physical);
    pollster::block_on(chain.set_settings_async(d, calibrated)).unwrap();
    chain.set_timing(d, q, true);
    chain.resize(256, 192).unwrap();
    chain.prepare(d, q, &camera, &bounds).unwrap();
    let small = lineao::targets::Target::output(d, "test::small", (256, 192), common::OUTPUT_FORMAT);
    let mut encoder = d.create_command_encoder(&Default::default());
    chain.encode(&mut encoder, &uploaded, &small.view).unwrap();
    assert_eq!(chain.pass_times(d, false).unwrap(), None, "no timed frame was submitted");
    let took = start.elapsed();
    assert!(!done.load(Ordering::Acquire), "the calls waited for the long frame ({took:?})");
    // The long frame was real: waiting for it now sees it finish.
    d.poll(wgpu::PollType::wait_indefinitely()).unwrap();
    assert!(done.load(Ordering::Acquire));
    println!("upload, chain, prepare and encode took {took:?} while the long frame ran");
}

/// The chain allocates only what its method reads and writes: SSAO's `ao_raw`, the blur's two,
/// `outer = level`'s and VO area's moments exist only when asked for.
#[test]
fn the_chain_allocates_only_the_targets_its_method_uses() {
    let gpu = common::gpu();
    let (d, q) = (&gpu.device, &gpu.queue);
    let (camera, bounds) = common::unit_sphere_view();
    let with = |method| ChainSettings { method, ..ChainSettings::default() };
    let level = lineao::LineAoSettings { outer: lineao::LineAoOuter::Level, ..Default::default() };
    let blur = Some(lineao::BilateralSettings::default());
    for (settings, raw, blurred, outer, moments) in [
        (with(AoMethod::LineAo), false, false, false, false),
        (ChainSettings { line_ao: level, ..with(AoMethod::LineAo) }, false, false, true, false),
        (with(AoMethod::Ssao), true, false, false, false),
        (ChainSettings { blur, ..with(AoMethod::VoLine) }, false, true, false, false),
        (with(AoMethod::VoArea), false, false, false, true),
    ] {
        let mut chain = AoChain::new(d, common::OUTPUT_FORMAT, settings.clone()).unwrap();
        chain.resize(64, 48).unwrap();
        chain.prepare(d, q, &camera, &bounds).unwrap();
        let t = chain.targets().unwrap();
        // The method's own (its stage's), and the blur's (shared).
        let has = (
            chain.stage().and_then(|s| s.unblurred()).is_some(),
            t.ao_blurred.is_some(),
            chain
                .stage()
                .and_then(|s| s.downcast::<lineao::method::line_ao::LineAoStage>())
                .is_some_and(|s| !s.outer().is_empty()),
            chain
                .stage()
                .and_then(|s| s.downcast::<lineao::method::vo_area::VoArea>())
                .and_then(|s| s.moments())
                .is_some(),
        );
        assert_eq!(has, (raw, blurred, outer, moments), "{:?}", settings.method);
    }
}
