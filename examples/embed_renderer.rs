//! A small but complete wgpu renderer of its own — triangle meshes, a depth prepass, Lambert
//! shading into color and view-space normal targets, reversed-Z with an infinite far plane — that
//! adds LineAO through lineao's public API only, headless, and writes a PNG. What an
//! integration into an existing renderer looks like:
//!
//! 1. `AoChain::new` with the host's output format, `resize` with its size;
//! 2. `enable_host` with what its buffers are (depth samples, reversed-Z, normals);
//! 3. per frame `prepare_view` with its own view and projection matrices and the scene's bounds;
//! 4. `encode_host` with its depth, normal and color views into its encoder: the ND and zoom
//!    maps are derived there, LineAO runs, the composite writes the output.
//!
//! ```sh
//! cargo run --release --example embed_renderer -- embed.png
//! ```

use glam::Vec3;
use lineao::camera::{Bounds, FrameView};
use lineao::passes::nd_from_depth::{HostConfig, HostInputs, HostNormals};
use lineao::{AoChain, ChainSettings};
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

/// What one frame produced: the image, and the chain with its device (the test reads its
/// targets back).
#[cfg_attr(not(test), allow(dead_code))]
struct Rendered {
    rgba: Vec<u8>,
    chain: AoChain,
    device: wgpu::Device,
    queue: wgpu::Queue,
    settings: ChainSettings,
}

fn render(width: u32, height: u32) -> Result<Rendered, Box<dyn std::error::Error>> {
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
    let eye = Vec3::new(18.0, 16.0, 30.0);
    let view = glam::camera::rh::view::look_at_mat4(eye, Vec3::new(0.0, 3.0, 0.0), Vec3::Y);
    let proj = glam::camera::rh::proj::directx::perspective_infinite_reverse(
        40f32.to_radians(),
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
            primitive: wgpu::PrimitiveState { cull_mode: Some(wgpu::Face::Back), ..Default::default() },
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

    // LineAO through the public API: the chain writes into the host's output format.
    // LineAO is made for lines; on a host's meshes three settings matter. Scene units are ~10 × a
    // tractogram's millimetres: hemispheres grow by z(P) per 0.1 unit. Depth differences below a
    // facet's sag (~1e-4 of the depth range here) are the mesh, not an occluder: ε above it.
    // The bilateral blur smooths the sampling noise.
    let settings = ChainSettings {
        strength: 0.8,
        zoom_unit: 0.1,
        line_ao: lineao::LineAoSettings { epsilon: 5e-4, delta0: 1e-3, ..Default::default() },
        blur: Some(lineao::BilateralSettings::default()),
        ..ChainSettings::default()
    };
    let mut chain = AoChain::new(&device, wgpu::TextureFormat::Rgba8UnormSrgb, settings.clone())?;
    chain.resize(width, height)?;
    chain.enable_host(
        &device,
        HostConfig {
            depth_samples: 1,
            reversed_z: true,
            normals: Some(HostNormals { world_space: false, unorm: false }),
        },
    )?;
    let bounds = Bounds { center: Vec3::new(0.0, 4.0, 0.0), radius: 45.0 };
    chain.prepare_view(&device, &queue, FrameView::from_matrices(view, proj, width, height, &bounds))?;

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
    chain.encode_host(&device, &mut encoder, &inputs, Some(&output_view))?;
    queue.submit([encoder.finish()]);

    let rgba = lineao::readback::read_texture(&device, &queue, &output)?.bytes;
    Ok(Rendered { rgba, chain, device, queue, settings })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1).unwrap_or_else(|| "embed.png".into());
    let (width, height) = (800, 600);
    let rendered = render(width, height)?;
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(std::fs::File::create(&path)?), width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.write_header()?.write_image_data(&rendered.rgba)?;
    println!("wrote {path}");
    Ok(())
}

#[cfg(test)]
mod tests {
    use lineao::reference::{self, LineAoParams};
    use lineao::verify::{check_policy, line_ao_flip_bound, read_f32, read_rgba};

    /// The example's AO against the CPU reference run on its own inputs (the G-buffer the chain
    /// derived from the host's buffers, read back).
    #[test]
    fn the_host_renderers_ao_matches_the_cpu_reference() {
        if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
            // SAFETY: set before any thread of ours reads the environment.
            unsafe { std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir()) };
        }
        let r = super::render(200, 150).unwrap();
        let (d, q) = (&r.device, &r.queue);
        let t = r.chain.targets().unwrap();
        let view = *r.chain.frame_view().unwrap();
        let nd: Vec<_> = t.nd.iter().map(|level| read_rgba(d, q, level).unwrap()).collect();
        let zoom = read_f32(d, q, &t.zoom).unwrap();
        let gpu = read_f32(d, q, &t.ao).unwrap();
        let s = &r.settings;
        let cpu = reference::line_ao(
            &nd,
            &zoom,
            &lineao::noise::noise_tile(s.line_ao.noise_seed),
            &lineao::passes::line_ao::sample_table(&s.line_ao),
            &LineAoParams::new(s, &view),
        );
        let stats = check_policy(&gpu, &cpu, &nd[0], line_ao_flip_bound(s.line_ao.s_r, s.line_ao.s_h)).unwrap();
        println!("embed_renderer: {stats}");
        let geometry = nd[0].data.iter().filter(|n| n[..3] != [0.0; 3]).count();
        assert!(geometry > 15_000, "{geometry} pixels of meshes");
        assert!(gpu.data.iter().filter(|&&a| a > 0.2).count() > 1000, "the meshes occlude each other");
        assert_eq!(r.rgba.len(), 200 * 150 * 4);
    }
}
