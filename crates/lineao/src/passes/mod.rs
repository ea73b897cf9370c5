//! The passes every method shares — the geometry (lines, tubes, meshes, anatomy slices, a host's
//! depth), the ND
//! pyramid, the bilateral blur, object-space AO and the composite — one module (and one WGSL
//! file) each; the methods' own passes are in [`crate::method`]. Every pass owns its long-lived pipeline and
//! layouts, rebuilds its bind groups on `resize`, writes its uniforms in `prepare` and records
//! itself in `encode`, so a host with its own render graph can use any of them alone.

pub use crate::gbuffer::{Load, clear};

pub mod bilateral;
pub mod composite;
pub mod cull;
pub mod depth_pyramid;
pub mod lines;
pub mod meshes;
pub mod nd_from_depth;
pub mod nd_pyramid;
pub mod raster;
pub mod seed_depth;
pub mod slices;
pub mod transparency;
pub mod tubes;
pub mod volume_ao;

/// Workgroup size of the compute passes (8 × 8, as in the WGSL files).
pub(crate) const WORKGROUP: u32 = 8;

pub(crate) fn dispatch_size((width, height): (u32, u32)) -> (u32, u32) {
    (width.div_ceil(WORKGROUP), height.div_ceil(WORKGROUP))
}

/// Records one compute pass over every pixel of `targets` (8 × 8 workgroups), timed into
/// `span` when given: the whole `encode` of a full-screen compute pass.
pub(crate) fn dispatch_full_screen(
    encoder: &mut wgpu::CommandEncoder,
    label: &str,
    pipeline: &wgpu::ComputePipeline,
    group: &wgpu::BindGroup,
    size: (u32, u32),
    span: Option<crate::timing::Span>,
) {
    let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some(label),
        timestamp_writes: crate::timing::compute_writes(span),
    });
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, group, &[]);
    let (x, y) = dispatch_size(size);
    pass.dispatch_workgroups(x, y, 1);
}
