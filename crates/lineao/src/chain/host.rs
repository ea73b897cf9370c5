//! The chain over a host renderer's own buffers: a host that draws its scene itself hands lineao
//! its depth (and, if it has them, its normals and lit color) and gets LineAO, VO or SSAO of
//! that picture, with no change to its shaders.
//!
//! ```text
//!   host depth, normals?, color? ─▶ NdFromDepth ─▶ nd[0], zoom, color, depth
//!                                                     │
//!                     the chain's method, blur ◀──────┘ ao
//!                                                     │
//!   target view? ◀─ Composite ◀───────────────────────┘   (or the host reads AoChain::ao_view)
//! ```
//!
//! [`HostAo`] wraps an [`AoChain`]: the chain keeps its settings, size and timing
//! ([`HostAo::chain`], [`HostAo::chain_mut`]); the host's matrices replace the chain's camera
//! ([`HostAo::prepare`] with [`FrameView::from_matrices`], no guard band), and the G-buffer comes
//! from [`crate::passes::nd_from_depth`] instead of the line renderer.

use super::AoChain;
use crate::Error;
use crate::camera::FrameView;
use crate::passes::nd_from_depth::{self, HostConfig, HostInputs, NdFromDepth};

/// An [`AoChain`] over a host renderer's own depth, normals and color.
///
/// ```no_run
/// use lineao::glam::{Mat4, Vec3};
/// use lineao::{AoChain, Bounds, ChainSettings, FrameView, HostAo, HostConfig, HostInputs, wgpu};
///
/// /// One frame of a host that has drawn its scene into `depth` (Depth32Float, usage
/// /// RENDER_ATTACHMENT | TEXTURE_BINDING, stored) and `color`, seen through `view`, `proj`.
/// fn frame(
///     device: &wgpu::Device,
///     queue: &wgpu::Queue,
///     (depth, color, output): (&wgpu::TextureView, &wgpu::TextureView, &wgpu::TextureView),
///     (view, proj): (Mat4, Mat4),
/// ) -> Result<(), lineao::Error> {
///     let (width, height) = (1280, 1024);
///     // Once: the composite's format, the size, what the host's depth is like.
///     let mut chain = AoChain::new(device, wgpu::TextureFormat::Rgba8UnormSrgb, ChainSettings::default())?;
///     chain.resize(width, height)?;
///     let mut host = HostAo::new(device, chain, HostConfig { depth_samples: 1, reversed_z: false, normals: None })?;
///     // Per frame: the host's matrices, and the sphere that holds the scene (its depth range).
///     let bounds = Bounds { center: Vec3::ZERO, radius: 100.0 };
///     host.prepare(device, queue, FrameView::from_matrices(view, proj, width, height, &bounds))?;
///     let mut encoder = device.create_command_encoder(&Default::default());
///     let inputs = HostInputs { depth, normals: None, color: Some(color) };
///     host.encode(device, &mut encoder, &inputs, Some(output))?;
///     queue.submit([encoder.finish()]);
///     Ok(())
/// }
/// ```
pub struct HostAo {
    chain: AoChain,
    pass: NdFromDepth,
}

impl HostAo {
    /// `chain` made ready for a host's buffers: their depth's samples and convention and whether
    /// they have normals. A sample count outside 1..=32 is an [`Error::OutOfRange`]. Blocks
    /// on wgpu's validation answer as [`AoChain::new`] does; [`HostAo::new_async`] awaits it.
    pub fn new(device: &wgpu::Device, chain: AoChain, config: HostConfig) -> Result<HostAo, Error> {
        pollster::block_on(Self::new_async(device, chain, config))
    }

    /// [`HostAo::new`] as a future.
    pub async fn new_async(device: &wgpu::Device, chain: AoChain, config: HostConfig) -> Result<HostAo, Error> {
        Ok(HostAo { chain, pass: Self::pass(device, config).await? })
    }

    async fn pass(device: &wgpu::Device, config: HostConfig) -> Result<NdFromDepth, Error> {
        if config.depth_samples == 0 || config.depth_samples > 32 {
            return Err(Error::out_of_range("HostConfig::depth_samples", config.depth_samples, "1..=32"));
        }
        crate::gpu::validated_async(device, "creating the host pass", || NdFromDepth::new(device, config)).await
    }

    /// Follows a change of the host's buffers (its depth's samples or convention, its normals).
    /// Blocks as [`HostAo::new`] does; [`HostAo::set_config_async`] awaits.
    pub fn set_config(&mut self, device: &wgpu::Device, config: HostConfig) -> Result<(), Error> {
        pollster::block_on(self.set_config_async(device, config))
    }

    /// [`HostAo::set_config`] as a future.
    pub async fn set_config_async(&mut self, device: &wgpu::Device, config: HostConfig) -> Result<(), Error> {
        if self.pass.config() != config {
            self.pass = Self::pass(device, config).await?;
        }
        Ok(())
    }

    /// What the host's buffers are like.
    pub fn config(&self) -> HostConfig {
        self.pass.config()
    }

    /// The chain: its settings, size, timing, AO view.
    pub fn chain(&self) -> &AoChain {
        &self.chain
    }

    /// The chain, to change its settings or size ([`AoChain::resize`] with the host's size).
    pub fn chain_mut(&mut self) -> &mut AoChain {
        &mut self.chain
    }

    /// Writes the frame's uniforms for the host's matrices ([`FrameView::from_matrices`], no
    /// guard band). `Ok(None)` while the chain is 0 × 0 (nothing is recorded then); a view of
    /// another size than the chain's is an [`Error::Usage`].
    pub fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        view: FrameView,
    ) -> Result<Option<FrameView>, Error> {
        let view = self.chain.prepare_view(device, queue, view)?;
        if let Some(view) = &view {
            self.pass.prepare(queue, view);
        }
        Ok(view)
    }

    /// Records a frame over the host's buffers (after [`HostAo::prepare`]): the G-buffer derived
    /// from its depth, normals and color, the method, and the composite into `target`; or only
    /// the AO (`target` `None`), which the host then reads from [`AoChain::ao_view`].
    ///
    /// Writes nothing to the queue. Every texture is checked first
    /// ([`nd_from_depth::check_inputs`] has the table): a missing `prepare` or a texture of the
    /// wrong size, format, usage or sample count is an [`Error::Usage`] saying what to change,
    /// with nothing recorded. At 0 × 0 it records nothing and returns `Ok`.
    pub fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        inputs: &HostInputs,
        target: Option<&wgpu::TextureView>,
    ) -> Result<(), Error> {
        let chain = &self.chain;
        if chain.size.0 == 0 || chain.size.1 == 0 {
            return Ok(());
        }
        if chain.targets.is_none() || chain.view.is_none() {
            return Err(Error::Usage(crate::Misuse::Order { call: "HostAo::encode", first: "HostAo::prepare" }));
        }
        nd_from_depth::check_inputs(&self.pass.config(), inputs, chain.size)?;
        if let Some(target) = target {
            chain.check_target(target)?;
        }
        chain.record(
            encoder,
            |encoder, targets, span| self.pass.encode(device, encoder, targets, inputs, span),
            |composite, encoder, span| {
                if let Some(target) = target {
                    composite.encode(encoder, target, span("composite"));
                }
            },
        );
        Ok(())
    }

    /// Never waits: how many pixels of an earlier frame showed geometry outside the bounds given
    /// to [`FrameView::from_matrices`] (nearer than their near end or beyond their far end:
    /// clamped there, so their occlusion is wrong), once the GPU has finished that frame; `None`
    /// while it has not. A host asks once per frame and, seeing a count above 0, grows its
    /// bounds.
    pub fn pixels_outside_bounds(&self, device: &wgpu::Device) -> Result<Option<u32>, Error> {
        self.pass.try_outside(device)
    }
}
