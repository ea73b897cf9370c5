//! Bind group layout entries and bind groups without the boilerplate: every pass declares its
//! bindings as a list of [`Slot`]s in shader order.

/// What a binding holds.
#[derive(Clone, Copy, Debug)]
pub enum Slot {
    Uniform,
    /// Read-only storage buffer.
    Storage,
    /// Read-write storage buffer.
    StorageReadWrite,
    /// `texture_2d<f32>` read with `textureLoad` (unfilterable, so f32 formats work everywhere).
    Texture,
    /// `texture_3d<f32>` read with `textureLoad` (unfilterable).
    Texture3d,
    /// `texture_3d<f32>` sampled through a filtering sampler (f32 formats need the device's
    /// `FLOAT32_FILTERABLE`).
    FilterableTexture3d,
    /// A filtering `sampler`.
    Sampler,
    /// `texture_2d<u32>` read with `textureLoad`.
    UintTexture,
    /// `texture_2d_array<u32>` read with `textureLoad`.
    UintTextureArray,
    /// `texture_depth_2d`, or `texture_depth_multisampled_2d` when `multisampled`.
    DepthTexture {
        multisampled: bool,
    },
    /// `texture_storage_2d<format, write>`.
    StorageTexture(wgpu::TextureFormat),
}

/// A layout with binding i = `slots[i]`.
pub fn layout(
    device: &wgpu::Device,
    label: &str,
    visibility: wgpu::ShaderStages,
    slots: &[Slot],
) -> wgpu::BindGroupLayout {
    let entries: Vec<_> = slots
        .iter()
        .enumerate()
        .map(|(i, slot)| wgpu::BindGroupLayoutEntry {
            binding: i as u32,
            visibility,
            ty: match *slot {
                Slot::Uniform => wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                Slot::Storage | Slot::StorageReadWrite => wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only: matches!(slot, Slot::Storage) },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                Slot::Texture => wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                Slot::Texture3d | Slot::FilterableTexture3d => wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float {
                        filterable: matches!(slot, Slot::FilterableTexture3d),
                    },
                    view_dimension: wgpu::TextureViewDimension::D3,
                    multisampled: false,
                },
                Slot::Sampler => wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                Slot::DepthTexture { multisampled } => wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Depth,
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled,
                },
                Slot::UintTexture | Slot::UintTextureArray => wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Uint,
                    view_dimension: if matches!(slot, Slot::UintTexture) {
                        wgpu::TextureViewDimension::D2
                    } else {
                        wgpu::TextureViewDimension::D2Array
                    },
                    multisampled: false,
                },
                Slot::StorageTexture(format) => wgpu::BindingType::StorageTexture {
                    access: wgpu::StorageTextureAccess::WriteOnly,
                    format,
                    view_dimension: wgpu::TextureViewDimension::D2,
                },
            },
            count: None,
        })
        .collect();
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries: &entries })
}

/// A bind group with binding i = `resources[i]`.
pub fn group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    resources: &[wgpu::BindingResource],
) -> wgpu::BindGroup {
    let entries: Vec<_> = resources
        .iter()
        .enumerate()
        .map(|(i, resource)| wgpu::BindGroupEntry { binding: i as u32, resource: resource.clone() })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(label), layout, entries: &entries })
}

/// A uniform buffer sized for `T`, written by `prepare`.
pub fn uniform_buffer<T: bytemuck::Pod>(device: &wgpu::Device, label: &str) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: std::mem::size_of::<T>() as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// A compute pipeline over one bind group, with WGSL `override` constants.
pub fn compute_pipeline<'a>(
    device: &wgpu::Device,
    label: &str,
    group: &wgpu::BindGroupLayout,
    shader: impl Into<crate::shader::Source<'a>>,
    entry_point: &str,
    constants: &[(&str, f64)],
) -> wgpu::ComputePipeline {
    let module = crate::shader::module(device, shader);
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(&pipeline_layout(device, label, group)),
        module: &module,
        entry_point: Some(entry_point),
        compilation_options: wgpu::PipelineCompilationOptions { constants, ..Default::default() },
        cache: None,
    })
}

/// A pipeline layout with one bind group.
pub fn pipeline_layout(device: &wgpu::Device, label: &str, group: &wgpu::BindGroupLayout) -> wgpu::PipelineLayout {
    device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &[Some(group)],
        immediate_size: 0,
    })
}

/// `vectors` (up to 4 components) as vec4s, missing components 0, zero-padded to `len`
/// entries: the sample and noise tables of the passes.
pub fn vec4_buffer<const N: usize>(
    device: &wgpu::Device,
    label: &str,
    vectors: &[[f32; N]],
    len: usize,
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    use wgpu::util::DeviceExt;
    let mut padded: Vec<[f32; 4]> = vectors
        .iter()
        .map(|v| {
            let mut row = [0.0; 4];
            row[..N].copy_from_slice(v);
            row
        })
        .collect();
    padded.resize(padded.len().max(len), [0.0; 4]);
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: bytemuck::cast_slice(&padded),
        usage,
    })
}

/// Two tables in one uniform buffer of vec4s: `first` from entry 0, `second` from entry `at`.
pub fn two_tables<const N: usize>(
    device: &wgpu::Device,
    label: &str,
    first: &[[f32; N]],
    at: usize,
    second: &[[f32; N]],
) -> wgpu::Buffer {
    let mut rows = first.to_vec();
    rows.resize(at, [0.0; N]);
    rows.extend_from_slice(second);
    vec4_buffer(device, label, &rows, rows.len(), wgpu::BufferUsages::UNIFORM)
}

/// A layout of buffers at the bindings given (which need not follow each other, as a shader's
/// bindings shared by several passes that each read a few).
pub fn buffers_layout(
    device: &wgpu::Device,
    label: &str,
    visibility: wgpu::ShaderStages,
    entries: &[(u32, wgpu::BufferBindingType)],
) -> wgpu::BindGroupLayout {
    let entries: Vec<_> = entries
        .iter()
        .map(|&(binding, ty)| wgpu::BindGroupLayoutEntry {
            binding,
            visibility,
            ty: wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None },
            count: None,
        })
        .collect();
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries: &entries })
}

/// A bind group of whole buffers at their bindings ([`buffers_layout`]).
pub fn buffers_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    buffers: &[(u32, &wgpu::Buffer)],
) -> wgpu::BindGroup {
    let entries: Vec<_> = buffers
        .iter()
        .map(|&(binding, buffer)| wgpu::BindGroupEntry { binding, resource: buffer.as_entire_binding() })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(label), layout, entries: &entries })
}
