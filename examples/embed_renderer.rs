//! A small but complete wgpu renderer of its own — triangle meshes, a depth prepass, Lambert
//! shading into color and view-space normal targets, reversed-Z with an infinite far plane — that
//! adds LineAO through lineao's public API only, headless, and writes a PNG. What an
//! integration into an existing renderer looks like:
//!
//! 1. `AoChain::new` with the host's output format, `resize` with its size;
//! 2. `HostAo::new` over the chain with what its buffers are (depth samples, reversed-Z, normals);
//! 3. per frame `HostAo::prepare` with its own view and projection matrices and the scene's bounds;
//! 4. `HostAo::encode` with its depth, normal and color views into its encoder: the ND and zoom
//!    maps are derived there, LineAO runs, the composite writes the output.
//!
//! ```sh
//! cargo run --release --example embed_renderer -- embed.png
//! ```

use glam::Vec3;
use lineao::passes::nd_from_depth::{HostConfig, HostInputs, HostNormals};
use lineao::{AoChain, ChainSettings, HostAo};
use lineao::{Bounds, FrameView};
use wgpu::util::DeviceExt;

/// The host's shaders: one vertex stage for both passes (bit-identical depth), Lambert shading.
const SHADER: &str = "
struct Frame { view_proj: mat4x4<f32>, view: mat4x4<f32> }
@group(0) @binding(0) var<uniform> frame: Frame;
struct Out { @builtin(position) clip: vec4<f32>, @location(0) normal: vec3<f32>, @location(1) color: vec3<f32> }
@vertex fn vs(@location(0) p: vec3<f32>, @location(1) n: vec3<f32>, @location(2) c: vec3<f32>) -> Out {
    return Out(frame.view_proj * vec4<f32>(p, 1.0), (frame.view * vec4<f32>(n, 0.0)).xyz, c);
}
struct Targets { @location(0) color: vec4<f32>, @location(1) normal: vec4<f32> }
@fragment fn fs(in: Out) -> Targets {
    let n = normalize(in.normal);
    let sun = normalize((frame.view * vec4<f32>(0.4, 1.0, 0.3, 0.0)).xyz);
    let light = 0.35 + 0.65 * max(dot(n, sun), 0.0);
    return Targets(vec4<f32>(in.color * light, 1.0), vec4<f32>(n, 0.0));
}";

/// One vertex of the host's meshes.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Vertex {
    position: [f32; 3],
    normal: [f32; 3],
    color: [f32; 3],
}

/// The scene: a ground plane, spheres resting on it and a ring standing on it.
fn scene() -> (Vec<Vertex>, Vec<u32>) {
    let (mut vertices, mut indices) = (Vec::new(), Vec::new());
    let mut add = |points: Vec<(Vec3, Vec3)>, tris: Vec<u32>, color: [f32; 3]| {
        let base = vertices.len() as u32;
        vertices.extend(points.into_iter().map(|(p, n)| Vertex { position: p.into(), normal: n.into(), color }));
        indices.extend(tris.into_iter().map(|i| i + base));
    };
    add(
        [(-30.0, -30.0), (30.0, -30.0), (30.0, 30.0), (-30.0, 30.0)]
            .map(|(x, z)| (Vec3::new(x, 0.0, z), Vec3::Y))
            .to_vec(),
        vec![0, 2, 1, 0, 3, 2],
        [0.8, 0.8, 0.75],
    );
    // A parametric surface (u, v) ∈ [0, 1]², `n` × `n` quads, normals from the function.
    let surface = |n: u32, f: &dyn Fn(f32, f32) -> (Vec3, Vec3)| {
        let points = (0..=n)
            .flat_map(|i| (0..=n).map(move |j| (i, j)))
            .map(|(i, j)| f(i as f32 / n as f32, j as f32 / n as f32));
        let tris = (0..n)
            .flat_map(|i| (0..n).map(move |j| (i, j)))
            .flat_map(|(i, j)| {
                let (a, b, c, d) =
                    (i * (n + 1) + j, (i + 1) * (n + 1) + j, (i + 1) * (n + 1) + j + 1, i * (n + 1) + j + 1);
                [a, b, c, a, c, d]
            })
            .collect();
        (points.collect::<Vec<_>>(), tris)
    };
    let tau = std::f32::consts::TAU;
    for (centre, r, color) in [
        (Vec3::new(-8.0, 4.0, 2.0), 4.0, [0.9, 0.35, 0.3]),
        (Vec3::new(1.5, 2.5, 6.0), 2.5, [0.3, 0.6, 0.9]),
        (Vec3::new(9.0, 5.0, -3.0), 5.0, [0.4, 0.8, 0.4]),
    ] {
        let (points, tris) = surface(32, &|u, v| {
            let (theta, phi) = (u * std::f32::consts::PI, v * tau);
            let n = Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
            (centre + r * n, n)
        });
        add(points, tris, color);
    }
    let (points, tris) = surface(48, &|u, v| {
        // A torus standing upright on the ground: ring radius 6, tube radius 1.5.
        let (a, b) = (u * tau, v * tau);
        let ring = Vec3::new(a.cos(), a.sin(), 0.0);
        let n = ring * b.cos() + Vec3::Z * b.sin();
        (Vec3::new(-1.0, 7.5, -9.0) + 6.0 * ring + 1.5 * n, n)
    });
    add(points, tris, [0.95, 0.8, 0.3]);
    (vertices, indices)
}

/// What one frame produced: the image, and the host chain with its device (the test reads its
/// targets back).
#[cfg_attr(not(test), allow(dead_code))]
struct Rendered {
    rgba: Vec<u8>,
    host: HostAo,
    device: wgpu::Device,
    queue: wgpu::Queue,
    settings: ChainSettings,
    /// The scene and camera, for the ray-traced truth.
    vertices: Vec<Vertex>,
    indices: Vec<u32>,
    camera: lineao::Camera,
    bounds: Bounds,
}

/// The camera: where the host looks from, and its field of view.
const EYE: Vec3 = Vec3::new(18.0, 16.0, 30.0);
const TARGET: Vec3 = Vec3::new(0.0, 3.0, 0.0);
const FOV_Y_DEG: f32 = 40.0;
/// The sphere that holds the scene (its depth range).
const BOUNDS: Bounds = Bounds { center: Vec3::new(0.0, 4.0, 0.0), radius: 45.0 };

fn render(width: u32, height: u32, settings: ChainSettings) -> Result<Rendered, Box<dyn std::error::Error>> {
    // The host's own device.
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(instance.request_adapter(&Default::default()))?;
    let (device, queue) = pollster::block_on(adapter.request_device(&Default::default()))?;

    let (vertices, indices) = scene();
    let vertex_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("host::vertices"),
        contents: bytemuck::cast_slice(&vertices),
        usage: wgpu::BufferUsages::VERTEX,
    });
    let index_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("host::indices"),
        contents: bytemuck::cast_slice(&indices),
        usage: wgpu::BufferUsages::INDEX,
    });
    let view = glam::camera::rh::view::look_at_mat4(EYE, TARGET, Vec3::Y);
    let proj = glam::camera::rh::proj::directx::perspective_infinite_reverse(
        FOV_Y_DEG.to_radians(),
        width as f32 / height as f32,
        0.5,
    );
    let frame = [proj * view, view].map(|m| m.to_cols_array()).concat();
    let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("host::frame"),
        contents: bytemuck::cast_slice(&frame),
        usage: wgpu::BufferUsages::UNIFORM,
    });

    let texture = |label, format, usage| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    };
    use wgpu::TextureUsages as U;
    let depth = texture("host::depth", wgpu::TextureFormat::Depth32Float, U::RENDER_ATTACHMENT | U::TEXTURE_BINDING);
    let color = texture("host::color", wgpu::TextureFormat::Rgba8UnormSrgb, U::RENDER_ATTACHMENT | U::TEXTURE_BINDING);
    let normals = texture("host::normals", wgpu::TextureFormat::Rgba16Float, U::RENDER_ATTACHMENT | U::TEXTURE_BINDING);
    let output = texture("host::output", wgpu::TextureFormat::Rgba8UnormSrgb, U::RENDER_ATTACHMENT | U::COPY_SRC);
    let [depth_view, color_view, normal_view, output_view] =
        [&depth, &color, &normals, &output].map(|t| t.create_view(&Default::default()));

    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("host::shader"),
        source: wgpu::ShaderSource::Wgsl(SHADER.into()),
    });
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("host::layout"),
        entries: &[wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        }],
    });
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("host::group"),
        layout: &layout,
        entries: &[wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() }],
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("host::pipeline_layout"),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x3];
    let buffers = [Some(wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &attributes,
    })];
    let pipeline = |label, write_depth: bool, compare, fragment: Option<wgpu::FragmentState>| {
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs"),
                compilation_options: Default::default(),
                buffers: &buffers,
            },
            // No culling: the parametric surfaces wind either way, and the depth test keeps the
            // nearest side (culling by the wrong winding drew the spheres' far halves, which
            // the ray-traced truth of `--fit` showed as occluded from inside).
            primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: wgpu::TextureFormat::Depth32Float,
                depth_write_enabled: Some(write_depth),
                depth_compare: Some(compare),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment,
            multiview_mask: None,
            cache: None,
        })
    };
    // Reversed-Z: nearer is greater.
    let prepass = pipeline("host::prepass", true, wgpu::CompareFunction::Greater, None);
    let targets = [
        Some(wgpu::ColorTargetState::from(wgpu::TextureFormat::Rgba8UnormSrgb)),
        Some(wgpu::ColorTargetState::from(wgpu::TextureFormat::Rgba16Float)),
    ];
    let shading = pipeline(
        "host::shading",
        false,
        wgpu::CompareFunction::Equal,
        Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &targets,
        }),
    );

    // The occlusion through the public API: the chain writes into the host's output format.
    let mut chain = AoChain::new(&device, wgpu::TextureFormat::Rgba8UnormSrgb, settings.clone())?;
    chain.resize(width, height)?;
    let mut host = HostAo::new(
        &device,
        chain,
        HostConfig {
            depth_samples: 1,
            reversed_z: true,
            normals: Some(HostNormals { world_space: false, unorm: false }),
        },
    )?;
    host.prepare(&device, &queue, FrameView::from_matrices(view, proj, width, height, &BOUNDS))?;

    let mut encoder = device.create_command_encoder(&Default::default());
    let clear = |r, g, b| wgpu::Operations {
        load: wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a: 1.0 }),
        store: wgpu::StoreOp::Store,
    };
    for (pass_pipeline, colors) in [(&prepass, false), (&shading, true)] {
        let attachments = if colors {
            vec![
                Some(wgpu::RenderPassColorAttachment {
                    view: &color_view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: clear(0.92, 0.94, 1.0),
                }),
                Some(wgpu::RenderPassColorAttachment {
                    view: &normal_view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: clear(0.0, 0.0, 0.0),
                }),
            ]
        } else {
            vec![]
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("host::pass"),
            color_attachments: &attachments,
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: if colors { wgpu::LoadOp::Load } else { wgpu::LoadOp::Clear(0.0) },
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(pass_pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.set_vertex_buffer(0, vertex_buffer.slice(..));
        pass.set_index_buffer(index_buffer.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..indices.len() as u32, 0, 0..1);
    }
    let inputs = HostInputs { depth: &depth_view, normals: Some(&normal_view), color: Some(&color_view) };
    host.encode(&device, &mut encoder, &inputs, Some(&output_view))?;
    queue.submit([encoder.finish()]);

    let rgba = lineao::readback::read_texture(&device, &queue, &output)?.bytes;
    let camera = lineao::Camera {
        eye: EYE,
        target: TARGET,
        up: Vec3::Y,
        projection: lineao::Projection::Perspective { fov_y_deg: FOV_Y_DEG },
    };
    Ok(Rendered { rgba, host, device, queue, settings, vertices, indices, camera, bounds: BOUNDS })
}

/// How a method's occlusion compares with the truth ray traced on the host's own triangles
/// (binary AO to `reach`, cosine-weighted rays over each pixel's hemisphere).
#[cfg_attr(not(test), allow(dead_code))]
struct MeshScore {
    scores: lineao::truth::metrics::Scores,
    /// The mean occlusion the composite applies (strength · ao) on the ground where the truth
    /// sees no occluder, and where it sees at least a third of the hemisphere blocked.
    open_ground: f64,
    contacts: f64,
    contacts_truth: f64,
    /// The RMSE of what the composite applies against the truth.
    rmse: f64,
}

fn measure(r: &Rendered, reach: f32, rays: u32) -> Result<MeshScore, Box<dyn std::error::Error>> {
    use lineao::truth::{Bvh, Frame, TruthSettings};
    let (d, q) = (&r.device, &r.queue);
    let targets = r.host.chain().targets().ok_or("no frame")?;
    let nd = lineao::readback::read_rgba(d, q, &targets.nd[0])?;
    let ao = lineao::readback::read_f32(d, q, targets.shown())?;
    let positions: Vec<[f32; 3]> = r.vertices.iter().map(|v| v.position).collect();
    let bvh = Bvh::build(Vec::new(), lineao::truth::mesh_triangles(&positions, &r.indices));
    // The host's projection has an infinite far plane; the truth's rays need a finite one:
    // lineao's own view of the same camera has the same pixels and depth range.
    let view = FrameView::new(&r.camera, &r.bounds, nd.width as u32, nd.height as u32, 0, r.settings.zoom_unit);
    let settings = TruthSettings { rays, distance_world: reach, ..TruthSettings::default() };
    let cancel = std::sync::atomic::AtomicBool::new(false);
    let truth =
        lineao::truth::compute(&bvh, &Frame { nd: &nd, view: &view, lines: false }, &settings, &|_, _| {}, &cancel)?;
    let geometry: Vec<bool> = nd.data.iter().map(|n| n[..3] != [0.0; 3]).collect();
    let up = view.view.transform_vector3(Vec3::Y);
    let ground = |i: usize| geometry[i] && Vec3::new(nd.data[i][0], nd.data[i][1], nd.data[i][2]).dot(up) > 0.999;
    let strength = r.settings.strength as f64;
    let mean_where = |keep: &dyn Fn(usize) -> bool, of: &dyn Fn(usize) -> f64| {
        let (sum, n) = (0..nd.data.len()).filter(|&i| keep(i)).fold((0.0, 0), |(s, n), i| (s + of(i), n + 1));
        sum / n.max(1) as f64
    };
    let shown = |i: usize| (strength * ao.data[i] as f64).min(1.0);
    let contact = |i: usize| ground(i) && truth.ao.data[i] >= 1.0 / 3.0;
    Ok(MeshScore {
        scores: lineao::truth::metrics::score(&ao, &truth.ao, &geometry),
        open_ground: mean_where(&|i| ground(i) && truth.ao.data[i] == 0.0, &shown),
        contacts: mean_where(&contact, &shown),
        contacts_truth: mean_where(&contact, &|i| truth.ao.data[i] as f64),
        rmse: mean_where(&|i| geometry[i], &|i| (shown(i) - truth.ao.data[i] as f64).powi(2)).sqrt(),
    })
}

/// The candidates `--fit` scores on this scene: each method at reach `reach` (world units).
fn candidates(reach: f32) -> Vec<(&'static str, ChainSettings)> {
    use lineao::{AoMethod, BilateralSettings, LineAoSettings, Preset};
    let blur = Some(BilateralSettings::default());
    let with_reach = |method, normal_clamp, thickness| {
        let mut s = ChainSettings { method, blur: blur.clone(), ..ChainSettings::default() };
        s.vo.radius_world = reach;
        s.vo.normal_clamp = normal_clamp;
        s.vo.thickness_world = thickness * reach;
        s.ssao.radius_world = reach;
        s.ssao.range_world = reach;
        s
    };
    // LineAO reaches r0 + 2 z(P) px (its widest hemisphere): a zoom unit of half the reach.
    let line_ao =
        |line_ao| ChainSettings { zoom_unit: 0.5 * reach, line_ao, blur: blur.clone(), ..ChainSettings::default() };
    vec![
        ("lineao (paper)", line_ao(LineAoSettings::default())),
        ("lineao (legible)", line_ao(LineAoSettings::default()).with_preset(Preset::Legible)),
        ("lineao (eps 5e-4)", line_ao(LineAoSettings { epsilon: 5e-4, delta0: 1e-3, ..Default::default() })),
        ("vo-line", with_reach(AoMethod::VoLine, true, 0.0)),
        ("vo-line (no clamp)", with_reach(AoMethod::VoLine, false, 0.0)),
        ("vo-line (thickness R)", with_reach(AoMethod::VoLine, true, 1.0)),
        ("vo-line (thickness R/2)", with_reach(AoMethod::VoLine, true, 0.5)),
        ("vo-line (thickness R, no blur)", ChainSettings { blur: None, ..with_reach(AoMethod::VoLine, true, 1.0) }),
        ("vo-area", with_reach(AoMethod::VoArea, true, 0.0)),
        ("vo-area (thickness R)", with_reach(AoMethod::VoArea, true, 1.0)),
        ("ssao", with_reach(AoMethod::Ssao, true, 0.0)),
    ]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().is_some_and(|a| a == "--fit") {
        // `ChainSettings::for_meshes`'s measurement: every candidate against the truth, with
        // its best strength (the least-squares scale).
        let (width, height, rays) = (320, 240, 128);
        println!("| reach | method | RMSE (best strength) | strength | correlation | open ground | contacts (truth) |");
        println!("|---|---|---:|---:|---:|---:|---:|");
        for fraction in [0.05, 0.1] {
            let reach = fraction * BOUNDS.radius;
            for (name, settings) in candidates(reach) {
                let r = render(width, height, ChainSettings { strength: 1.0, ..settings })?;
                let m = measure(&r, reach, rays)?;
                let s = m.scores.scale;
                println!(
                    "| {fraction} R | {name} | {:.4} | {s:.2} | {:.3} | {:.4} | {:.3} ({:.3}) |",
                    m.scores.scaled.rmse,
                    m.scores.correlation,
                    m.open_ground * s,
                    m.contacts * s,
                    m.contacts_truth
                );
            }
        }
        return Ok(());
    }
    let path = args.first().cloned().unwrap_or_else(|| "embed.png".into());
    let (width, height) = (800, 600);
    let rendered = render(width, height, ChainSettings::for_meshes(BOUNDS.radius))?;
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(std::fs::File::create(&path)?), width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.write_header()?.write_image_data(&rendered.rgba)?;
    println!("wrote {path}");
    Ok(())
}

#[cfg(test)]
mod tests {
    use lineao::readback::{read_f32, read_rgba};
    use lineao::reference::line_ao_flip_bound;
    use lineao::reference::{self, LineAoParams};
    use lineao::verify::check_policy;

    /// The example's AO against the CPU reference run on its own inputs (the G-buffer the chain
    /// derived from the host's buffers, read back).
    #[test]
    fn the_host_renderers_ao_matches_the_cpu_reference() {
        if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
            // SAFETY: set before any thread of ours reads the environment.
            unsafe { std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir()) };
        }
        // LineAO, as the paper's method is what the CPU reference here checks; on meshes it
        // wants a zoom unit of the scene's scale and ε above the facets' sag.
        let settings = lineao::ChainSettings {
            strength: 0.8,
            zoom_unit: 0.1,
            line_ao: lineao::LineAoSettings { epsilon: 5e-4, delta0: 1e-3, ..Default::default() },
            blur: Some(lineao::BilateralSettings::default()),
            ..lineao::ChainSettings::default()
        };
        let r = super::render(200, 150, settings).unwrap();
        let (d, q) = (&r.device, &r.queue);
        let t = r.host.chain().targets().unwrap();
        let view = *r.host.chain().frame_view().unwrap();
        let nd: Vec<_> = t.nd.iter().map(|level| read_rgba(d, q, level).unwrap()).collect();
        let zoom = read_f32(d, q, &t.zoom).unwrap();
        let gpu = read_f32(d, q, &t.ao).unwrap();
        let s = &r.settings;
        let cpu = reference::line_ao(
            &nd,
            &zoom,
            &lineao::noise::noise_tile(s.line_ao.noise_seed),
            &lineao::method::line_ao::sample_table(&s.line_ao),
            &LineAoParams::new(s, &view),
        );
        let stats = check_policy(&gpu, &cpu, &nd[0], line_ao_flip_bound(s.line_ao.s_r, s.line_ao.s_h)).unwrap();
        println!("embed_renderer: {stats}");
        let geometry = nd[0].data.iter().filter(|n| n[..3] != [0.0; 3]).count();
        assert!(geometry > 15_000, "{geometry} pixels of meshes");
        assert!(gpu.data.iter().filter(|&&a| a > 0.2).count() > 1000, "the meshes occlude each other");
        assert_eq!(r.rgba.len(), 200 * 150 * 4);
    }

    /// `ChainSettings::for_meshes` on this host's scene against the ray-traced truth: the open
    /// ground stays open (mean occlusion below 0.02), the contacts darken visibly (above 0.3,
    /// the truth about 0.5), and the map follows the truth (RMSE below 0.08 at its strength).
    #[test]
    fn the_mesh_settings_leave_open_ground_open_and_darken_the_contacts() {
        if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
            // SAFETY: set before any thread of ours reads the environment.
            unsafe { std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir()) };
        }
        let settings = lineao::ChainSettings::for_meshes(super::BOUNDS.radius);
        let reach = settings.vo.radius_world;
        let r = super::render(200, 150, settings).unwrap();
        let m = super::measure(&r, reach, 64).unwrap();
        let rmse = m.rmse;
        println!(
            "for_meshes: open ground {:.4}, contacts {:.3} (truth {:.3}), RMSE {rmse:.4}, correlation {:.3}",
            m.open_ground, m.contacts, m.contacts_truth, m.scores.correlation
        );
        assert!(m.open_ground < 0.02, "open ground {}", m.open_ground);
        assert!(m.contacts > 0.3, "contacts {}", m.contacts);
        assert!(rmse < 0.08, "RMSE {rmse}");
    }
}
