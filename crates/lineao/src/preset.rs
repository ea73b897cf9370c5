//! The named sets of parameters ([`Preset`]): each method's strength and reach as the papers
//! give them, or fitted for legibility or to the truth (each method's own values are its
//! folder's: its settings' `preset`).

use crate::named::{Named, named};

/// A named set of parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Preset {
    /// The papers' values (`ChainSettings::papers`).
    Paper,
    /// Each method's strength and reach fitted for *legibility* — visibly darker pixels lie
    /// deeper ([`crate::truth::legibility`]) — with the picture kept readable (near-black ≤ 2 %,
    /// mean darkening in [0.15, 0.45]): `lineao score --fit`, docs/ground-truth.md.
    #[default]
    Legible,
    /// Each method's strength and reach fitted to the local ray-traced truth (binary AO within
    /// 2 mm, least RMSE): physically close at that reach, but so faint on whole brains that it
    /// looks like no AO at all. Was called `calibrated`, a name still accepted.
    Physical,
    /// For a few streamlines far apart (flow fields, a single bundle): the papers' values with
    /// every method reaching farther, so that neighbours and not just a line's own body occlude
    /// — LineAO's four hemispheres (the fourth reaches twice as far as the third), SSAO's and
    /// VO's spheres of 6 zoom units — at a softer strength (0.8): the viewer's values for sparse
    /// streamlines (`--scene vortex`), chosen by eye, not fitted.
    Sparse,
}

named!(Preset {
    Legible => "Each method's strength and reach chosen so that darker lines lie deeper (the default)",
    Physical => "Fitted to binary AO within 2 mm (was `calibrated`; faint on whole brains)",
    Paper => "The papers' values (`dense` too: whole-brain tractography)",
    Sparse => "Few streamlines far apart: every method reaching farther, a softer strength",
});

impl Preset {
    /// Every preset, the default first.
    pub const ALL: [Preset; 4] = [Preset::Legible, Preset::Physical, Preset::Paper, Preset::Sparse];

    /// The name on the command line (`legible`, `physical`, `paper`, `sparse`).
    pub fn name(self) -> &'static str {
        match self {
            Preset::Paper => "paper",
            Preset::Legible => "legible",
            Preset::Physical => "physical",
            Preset::Sparse => "sparse",
        }
    }

    /// The preset called `name`; `calibrated`, the name `physical` had before, and `dense`, the
    /// viewer's name for the papers' values, too.
    pub fn from_name(name: &str) -> Option<Preset> {
        match name {
            "calibrated" => Some(Preset::Physical),
            "dense" => Some(Preset::Paper),
            _ => Preset::ALL.into_iter().find(|p| p.name() == name),
        }
    }
}
