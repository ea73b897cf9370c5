//! The passes, one module (and one WGSL file) each. Every pass owns its long-lived pipeline and
//! layouts, rebuilds its bind groups on `resize`, writes its uniforms in `prepare` and records
//! itself in `encode`, so a host with its own render graph can use any of them alone.

pub mod composite;
pub mod line_ao;
pub mod lines;
pub mod nd_pyramid;

/// Workgroup size of the compute passes (8 × 8, as in the WGSL files).
pub(crate) const WORKGROUP: u32 = 8;

pub(crate) fn dispatch_size((width, height): (u32, u32)) -> (u32, u32) {
    (width.div_ceil(WORKGROUP), height.div_ceil(WORKGROUP))
}
