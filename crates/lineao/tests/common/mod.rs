//! Shared by the GPU tests: a device on the default adapter (lavapipe on CI — a missing adapter
//! fails the test, it never skips) and ways to run the chain or single passes and read back.
#![allow(dead_code)]

use lineao::LineGeometry;
use lineao::method::line_ao::LineAo;
use lineao::passes::meshes::MeshGeometry;
use lineao::passes::nd_pyramid::NdPyramid;
use lineao::readback::{read_f32, read_rgba, write_target};
use lineao::reference::{Image, NdImage};
use lineao::targets::{FrameTargets, Target};
use lineao::{AoChain, ChainSettings, Gpu};
use lineao::{Bounds, Camera, FrameView};

pub fn gpu() -> Gpu {
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        // SAFETY: set before any thread of ours reads the environment.
        unsafe { std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir()) };
    }
    Gpu::headless().expect("a wgpu adapter (install mesa-vulkan-drivers for lavapipe)")
}

/// Everything a chain frame leaves in its targets, read back.
pub struct Frame {
    pub view: FrameView,
    pub guard: usize,
    pub color: NdImage,
    pub nd: Vec<NdImage>,
    pub zoom: Image<f32>,
    pub specular: Image<f32>,
    pub depth: Image<f32>,
    pub ao: Image<f32>,
    /// A method's occlusion before its blur (SSAO).
    pub ao_raw: Image<f32>,
    /// `ao` after the bilateral blur (when on).
    pub ao_blurred: Image<f32>,
    /// VO area's moments pyramid (empty for other methods).
    pub moments: Vec<lineao::reference::MomentsImage>,
    /// The composite's output (Rgba32Float, linear), visible size.
    pub output: NdImage,
    /// Object-space AO's packed octant visibilities and occlusion per pixel (with
    /// `ChainSettings::volume`).
    pub octants: Option<Image<[u32; 2]>>,
    pub volume_ao: Option<Image<f32>>,
}

pub const OUTPUT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

/// Renders polylines through the whole chain and reads every target back.
pub fn render(
    gpu: &Gpu,
    positions: &[[f32; 3]],
    offsets: &[u64],
    camera: &Camera,
    bounds: Option<Bounds>,
    settings: ChainSettings,
    (width, height): (u32, u32),
) -> Frame {
    let geometry = LineGeometry::new(&gpu.device, &gpu.queue, positions, offsets).unwrap();
    render_geometry(gpu, &geometry, camera, bounds.or(geometry.bounds).unwrap(), settings, (width, height))
}

pub fn render_geometry(
    gpu: &Gpu,
    geometry: &LineGeometry,
    camera: &Camera,
    bounds: Bounds,
    settings: ChainSettings,
    size: (u32, u32),
) -> Frame {
    render_scene(gpu, geometry, &[], camera, bounds, settings, size)
}

/// [`render_geometry`] with context surfaces (`meshes`) drawn into the same G-buffer.
pub fn render_scene(
    gpu: &Gpu,
    geometry: &LineGeometry,
    meshes: &[&MeshGeometry],
    camera: &Camera,
    bounds: Bounds,
    settings: ChainSettings,
    (width, height): (u32, u32),
) -> Frame {
    let mut chain = AoChain::new(&gpu.device, OUTPUT_FORMAT, settings).unwrap();
    chain.resize(width, height).unwrap();
    let view = chain.prepare(&gpu.device, &gpu.queue, camera, &bounds).unwrap();
    let output = Target::output(&gpu.device, "test::output", (width, height), OUTPUT_FORMAT);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    chain.encode(&mut encoder, (geometry, meshes), &output.view).unwrap();
    gpu.queue.submit([encoder.finish()]);
    let t = chain.targets().unwrap();
    let (d, q) = (&gpu.device, &gpu.queue);
    Frame {
        view,
        guard: t.guard as usize,
        color: read_rgba(d, q, &t.color).unwrap(),
        nd: t.nd.iter().map(|level| read_rgba(d, q, level).unwrap()).collect(),
        zoom: read_f32(d, q, &t.zoom).unwrap(),
        specular: read_f32(d, q, &t.specular).unwrap(),
        depth: read_f32(d, q, &t.depth).unwrap(),
        ao: read_f32(d, q, &t.ao).unwrap(),
        ao_raw: (chain.stage().and_then(|s| s.unblurred()))
            .map(|raw| read_f32(d, q, raw).unwrap())
            .unwrap_or_else(|| Image::from_fn(0, 0, |_, _| 0.0)),
        ao_blurred: t
            .ao_blurred
            .as_ref()
            .map(|b| read_f32(d, q, b).unwrap())
            .unwrap_or_else(|| Image::from_fn(0, 0, |_, _| 0.0)),
        moments: (chain
            .stage()
            .and_then(|s| s.downcast::<lineao::method::vo_area::VoArea>())
            .and_then(|s| s.moments()))
        .map(|m| m.read(d, q).unwrap())
        .unwrap_or_default(),
        output: read_rgba(d, q, &output).unwrap(),
        octants: t.octants.as_ref().map(|o| lineao::readback::read_image(d, q, o).unwrap()),
        volume_ao: t.volume_ao.as_ref().map(|v| read_f32(d, q, v).unwrap()),
    }
}

/// A view for G-buffers written from the CPU: `width` × `height` visible, `guard` around, the
/// scene a unit sphere 10 units in front of the camera (only the reference variant reads it).
pub fn flat_view(width: u32, height: u32, guard: u32) -> FrameView {
    let camera = Camera {
        eye: glam::Vec3::new(0.0, 0.0, 10.0),
        target: glam::Vec3::ZERO,
        up: glam::Vec3::Y,
        projection: lineao::Projection::Perspective { fov_y_deg: 45.0 },
    };
    FrameView::new(&camera, &Bounds { center: glam::Vec3::ZERO, radius: 1.0 }, width, height, guard, 1.0)
}

/// Runs the ND pyramid and LineAO passes alone on a G-buffer written from the CPU (as a host
/// with its own geometry would), returning the GPU's pyramid and AO.
pub fn line_ao_on(
    gpu: &Gpu,
    nd0: &NdImage,
    zoom: &Image<f32>,
    settings: &ChainSettings,
    guard: u32,
) -> (Vec<NdImage>, Image<f32>) {
    let (d, q) = (&gpu.device, &gpu.queue);
    let (w, h) = (nd0.width as u32 - 2 * guard, nd0.height as u32 - 2 * guard);
    let targets = FrameTargets::new(d, w, h, guard, settings.levels());
    write_target(q, &targets.nd[0], nd0);
    write_target(q, &targets.zoom, zoom);
    let mut pyramid = NdPyramid::new(d);
    pyramid.resize(d, &targets);
    let mut line_ao = LineAo::new(d, &settings.line_ao, &settings.lighting);
    line_ao.resize(d, &targets);
    line_ao.prepare(q, &targets, &flat_view(w, h, guard), &settings.line_ao, settings.r0(), &settings.lighting);
    let mut encoder = d.create_command_encoder(&Default::default());
    pyramid.encode(&mut encoder, &targets, None);
    line_ao.encode(&mut encoder, &targets, None);
    q.submit([encoder.finish()]);
    let levels = targets.nd.iter().map(|level| read_rgba(d, q, level).unwrap()).collect();
    (levels, read_f32(d, q, &targets.ao).unwrap())
}

/// [`polylines`] on the GPU, every vertex seeing `c` of each octant (object-space AO's
/// attribute).
pub fn polylines_with_octants(gpu: &Gpu, count: usize, seed: f32, c: f32) -> LineGeometry {
    let (positions, offsets) = polylines(count, seed);
    let octants = vec![[c; 8]; positions.len()];
    let mut geometry = LineGeometry::new(&gpu.device, &gpu.queue, &positions, &offsets).unwrap();
    let attributes = lineao::passes::lines::VertexAttributes { octants: Some(&octants), ..Default::default() };
    geometry.set_attributes(&gpu.device, &gpu.queue, &attributes).unwrap();
    geometry
}

pub fn is_geometry(nd: [f32; 4]) -> bool {
    nd[..3] != [0.0; 3]
}

/// `count` helical polylines of 60 points around the y axis (radius 10–35, height ±40), the
/// scene of the GPU-vs-CPU tests.
pub fn polylines(count: usize, seed: f32) -> (Vec<[f32; 3]>, Vec<u64>) {
    let mut positions = Vec::new();
    let mut offsets = vec![0u64];
    for k in 0..count {
        let phase = seed + k as f32 * 0.61;
        positions.extend((0..60).map(|i| {
            let s = i as f32 / 59.0;
            let r = 10.0 + 25.0 * (phase * 3.1).sin().abs();
            [r * (phase + 3.0 * s).cos(), -40.0 + 80.0 * s + 5.0 * (phase * 5.0).sin(), r * (phase + 3.0 * s).sin()]
        }));
        offsets.push(positions.len() as u64);
    }
    (positions, offsets)
}

/// A perspective and an orthographic camera framing [`polylines`].
pub fn cameras_for_polylines() -> (Camera, Camera) {
    let perspective = Camera {
        eye: glam::Vec3::new(20.0, 30.0, 140.0),
        target: glam::Vec3::ZERO,
        up: glam::Vec3::Y,
        projection: lineao::Projection::Perspective { fov_y_deg: 40.0 },
    };
    (perspective, Camera { projection: lineao::Projection::Orthographic { height: 110.0 }, ..perspective })
}

/// A minimal host renderer: `triangles` (world positions, three per triangle) into a new
/// Depth32Float texture of `size` with `samples` per pixel, through `view_proj`, cleared to
/// 1 (or 0 with `reversed_z`, testing Greater), as a renderer that is not ours would.
pub fn host_depth(
    gpu: &Gpu,
    triangles: &[[f32; 3]],
    view_proj: glam::Mat4,
    size: (u32, u32),
    samples: u32,
    reversed_z: bool,
) -> wgpu::Texture {
    use wgpu::util::DeviceExt;
    let d = &gpu.device;
    let texture = d.create_texture(&wgpu::TextureDescriptor {
        label: Some("test::host_depth"),
        size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: samples,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Depth32Float,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    });
    let shader = d.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("test::host"),
        source: wgpu::ShaderSource::Wgsl(
            "@group(0) @binding(0) var<uniform> view_proj: mat4x4<f32>;
             @vertex fn vs(@location(0) p: vec3<f32>) -> @builtin(position) vec4<f32> { return view_proj * vec4<f32>(p, 1.0); }"
                .into(),
        ),
    });
    let uniform = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: bytemuck::bytes_of(&view_proj.to_cols_array()),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let vertices = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: bytemuck::cast_slice(triangles),
        usage: wgpu::BufferUsages::VERTEX,
    });
    let pipeline = d.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("test::host"),
        layout: None,
        vertex: wgpu::VertexState {
            module: &shader,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: 12,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &wgpu::vertex_attr_array![0 => Float32x3],
            })],
        },
        primitive: Default::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: wgpu::TextureFormat::Depth32Float,
            depth_write_enabled: Some(true),
            depth_compare: Some(if reversed_z { wgpu::CompareFunction::Greater } else { wgpu::CompareFunction::Less }),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: wgpu::MultisampleState { count: samples, ..Default::default() },
        fragment: None,
        multiview_mask: None,
        cache: None,
    });
    let group = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() }],
    });
    let view = texture.create_view(&Default::default());
    let mut encoder = d.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("test::host"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(if reversed_z { 0.0 } else { 1.0 }),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.set_vertex_buffer(0, vertices.slice(..));
        pass.draw(0..triangles.len() as u32, 0..1);
    }
    gpu.queue.submit([encoder.finish()]);
    texture
}

/// A UV sphere of `radius` around `centre` as a triangle list (`rings` × 2 `rings` quads).
pub fn sphere_triangles(centre: glam::Vec3, radius: f32, rings: usize) -> Vec<[f32; 3]> {
    let point = |i: usize, j: usize| {
        let (theta, phi) =
            (std::f32::consts::PI * i as f32 / rings as f32, std::f32::consts::PI * j as f32 / rings as f32);
        (centre + radius * glam::Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin())).to_array()
    };
    let mut out = Vec::new();
    for i in 0..rings {
        for j in 0..2 * rings {
            let (a, b, c, e) = (point(i, j), point(i + 1, j), point(i + 1, j + 1), point(i, j + 1));
            out.extend([a, b, c, a, c, e]);
        }
    }
    out
}

/// A camera 5 units in front of a unit sphere of bounds at the origin (45° field of view).
pub fn unit_sphere_view() -> (Camera, Bounds) {
    let camera = Camera {
        eye: glam::Vec3::new(0.0, 0.0, 5.0),
        target: glam::Vec3::ZERO,
        up: glam::Vec3::Y,
        projection: lineao::Projection::Perspective { fov_y_deg: 45.0 },
    };
    (camera, Bounds { center: glam::Vec3::ZERO, radius: 1.0 })
}

/// A view of a new texture of `size`, `format`, `usage` and `samples`.
pub fn texture(
    gpu: &lineao::Gpu,
    size: (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
    samples: u32,
) -> wgpu::TextureView {
    gpu.device
        .create_texture(&wgpu::TextureDescriptor {
            label: Some("test::texture"),
            size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: samples,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
        .create_view(&Default::default())
}

/// A host's frame as a host leaves it: `color` (where given) cleared to its colour and `depth`
/// to `wall` (the host drew a wall at that depth), stored.
pub fn host_frame(
    encoder: &mut wgpu::CommandEncoder,
    color: Option<(&wgpu::TextureView, wgpu::Color)>,
    depth: &wgpu::TextureView,
    wall: f32,
) {
    let color = color.map(|(view, clear)| wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops: wgpu::Operations { load: wgpu::LoadOp::Clear(clear), store: wgpu::StoreOp::Store },
    });
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("test::host_frame"),
        color_attachments: &[color],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: depth,
            depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(wall), store: wgpu::StoreOp::Store }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
}

/// The G-buffer in `targets` (color, ND, zoom, hardware depth), read back; the scalar maps in
/// the first channel.
pub fn read_gbuffer(gpu: &Gpu, targets: &FrameTargets) -> [NdImage; 4] {
    let (d, q) = (&gpu.device, &gpu.queue);
    let scalar = |texture| {
        let image = read_f32(d, q, texture).unwrap();
        NdImage {
            width: image.width,
            height: image.height,
            data: image.data.iter().map(|&v| [v, 0.0, 0.0, 0.0]).collect(),
        }
    };
    [
        read_rgba(d, q, &targets.color).unwrap(),
        read_rgba(d, q, &targets.nd[0]).unwrap(),
        scalar(&targets.zoom),
        scalar(&targets.depth),
    ]
}
