//! The chain drawing into a host's frame: the lines (or tubes, with their context surfaces) and
//! their occlusion over the picture the host drew, so a host adds lineao's geometry to its scene
//! instead of the scene to lineao's.
//!
//! The chain renders its G-buffer and method as ever; only the composite changes
//! ([`crate::passes::composite`]): it loads the host's colour instead of clearing it, discards
//! the background, and with the host's depth ([`OverlayDepth`]) writes each line pixel's depth
//! as the host's projection puts it, tested against what the host drew before and kept for what
//! it draws after. A host depth the chain can read (`TEXTURE_BINDING`) also seeds the
//! G-buffer's depth ([`crate::passes::seed_depth`]): the lines behind the host's picture are
//! culled like any hidden line and occlude nothing.

use super::AoChain;
use crate::Error;
use crate::LineGeometry;
use crate::passes::meshes::MeshGeometry;
use crate::passes::seed_depth::OverlayDepth;
use crate::passes::seed_depth::{SeedDepth, can_read};

/// An [`AoChain`] that draws its geometry into a host's frame.
pub struct OverlayAo {
    chain: AoChain,
}

impl OverlayAo {
    /// `chain` made ready to draw into a host's frame, keeping the host's picture; with `depth`,
    /// the lines also write (and test against) the host's depth as its projection `depth.proj`
    /// puts them, so the host can draw after lineao. A `depth.format` without a depth aspect is
    /// an [`Error::Usage`].
    pub fn new(device: &wgpu::Device, chain: AoChain, depth: Option<OverlayDepth>) -> Result<OverlayAo, Error> {
        let mut overlay = OverlayAo { chain };
        overlay.set_depth(device, depth)?;
        Ok(overlay)
    }

    /// Follows the host's projection or depth format (cheap: the pipeline is rebuilt only for a
    /// new depth format or direction); it takes effect at the next `prepare`.
    pub fn set_depth(&mut self, device: &wgpu::Device, depth: Option<OverlayDepth>) -> Result<(), Error> {
        if let Some(d) = depth
            && !d.format.has_depth_aspect()
        {
            return Err(Error::Usage(crate::Misuse::TextureFormat {
                texture: "the overlay's depth".into(),
                format: d.format,
                samples: 1,
                expected: "a depth format".into(),
            }));
        }
        self.chain.composite.set_overlay(device, depth);
        match (depth, &self.chain.seed) {
            (None, _) => self.chain.seed = None,
            (Some(_), None) => self.chain.seed = Some(SeedDepth::new(device)),
            (Some(_), Some(_)) => {}
        }
        Ok(())
    }

    /// The chain: its settings, size, camera ([`AoChain::prepare`]), timing.
    pub fn chain(&self) -> &AoChain {
        &self.chain
    }

    /// The chain, to change its settings or size and to `prepare` each frame.
    pub fn chain_mut(&mut self) -> &mut AoChain {
        &mut self.chain
    }

    /// [`AoChain::encode`] with its meshes drawn into a host's frame (after the chain's `prepare`):
    /// `target`'s colour is loaded, not cleared, and only the geometry's pixels are written (the
    /// background shows the host's picture); `depth`, required when the overlay was made with
    /// depth and refused otherwise, gets the lines' depth at the visible size. Both are the
    /// chain's visible size, one sample; `target` of the chain's format with
    /// `RENDER_ATTACHMENT`, `depth` of the overlay's format with `RENDER_ATTACHMENT` and its
    /// stored contents (`StoreOp::Store` where the host drew it). A mismatch is an
    /// [`Error::Usage`] with nothing recorded. A `depth` with `TEXTURE_BINDING` too seeds the
    /// G-buffer's depth ([`crate::passes::seed_depth`]): what the host's picture hides is not
    /// drawn (culled, where the chain culls) and darkens nothing.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &LineGeometry,
        meshes: &[&MeshGeometry],
        target: &wgpu::TextureView,
        depth: Option<&wgpu::TextureView>,
    ) -> Result<(), Error> {
        let chain = &self.chain;
        if chain.size.0 == 0 || chain.size.1 == 0 {
            return Ok(());
        }
        chain.check_target(target)?;
        match (chain.composite.overlay_depth().flatten(), depth) {
            (None, Some(_)) => {
                return Err(Error::Usage(crate::Misuse::Input {
                    input: "a depth",
                    given: true,
                    config: "OverlayAo::set_depth",
                    fix: "give OverlayAo::set_depth Some(OverlayDepth { format, proj })",
                }));
            }
            (Some(_), None) => {
                return Err(Error::Usage(crate::Misuse::Input {
                    input: "the overlay's depth",
                    given: false,
                    config: "OverlayAo::set_depth",
                    fix: "pass OverlayAo::encode the depth, or give OverlayAo::set_depth None",
                }));
            }
            (Some(config), Some(view)) => chain.check_attachment(
                "the overlay's depth",
                view.texture(),
                config.format,
                "the overlay was made for",
            )?,
            (None, None) => {}
        }
        // The host's depth, where the chain can read it, seeds the G-buffer's.
        let seed = chain.seed.as_ref().zip(depth.filter(|view| can_read(view)));
        chain.record(
            encoder,
            |encoder, targets, span| {
                let background = chain.settings.background;
                let load = match seed {
                    Some((seed, depth)) => {
                        seed.encode(encoder, targets, depth);
                        crate::passes::Load::ClearOverDepth(background)
                    }
                    None => crate::passes::Load::Clear(background),
                };
                chain.draw_geometry(encoder, targets, geometry, meshes, load, span)
            },
            |composite, encoder, span| {
                composite.encode_overlay(encoder, target, depth, span("composite"));
                chain.encode_transparency(encoder, geometry, target, span("transparency"));
            },
        );
        Ok(())
    }
}
