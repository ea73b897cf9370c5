//! Colormaps for per-vertex scalars ([`crate::settings::LineColor::Scalar`]): sRGB control
//! points, decoded to linear RGB and tabulated for the geometry passes.

use crate::named::{Named, named};

named!(Colormap {
    Viridis => "Perceptually uniform, dark blue to yellow",
    Gray => "Black to white",
    CoolWarm => "Moreland's diverging blue–white–red",
    Categories => "Sixteen distinct colours for whole numbers 0–15 over the range [0, 15] (TRX groups)",
});

/// Colormaps for [`LineColor::Scalar`](crate::LineColor::Scalar), perceptually ordered where it matters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Colormap {
    /// Matplotlib's viridis: perceptually uniform, readable in grayscale and by most color-blind
    /// viewers. The default.
    #[default]
    Viridis,
    /// Black to white.
    Gray,
    /// Blue through white to red (Moreland's diverging map), for signed values.
    CoolWarm,
    /// Sixteen distinct colours (Tableau's 10, then 6 of its lighter 20), one per table entry:
    /// over the range [0, 15] the whole number k takes colour k exactly (`--color groups`).
    Categories,
}

impl Colormap {
    /// Every colormap, the default first.
    pub const ALL: [Colormap; 4] = [Colormap::Viridis, Colormap::Gray, Colormap::CoolWarm, Colormap::Categories];

    /// Its name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Colormap::Viridis => "viridis",
            Colormap::Gray => "gray",
            Colormap::CoolWarm => "coolwarm",
            Colormap::Categories => "categories",
        }
    }

    /// sRGB control points at evenly spaced positions from 0 to 1.
    // Viridis samples, not approximations of π (0.318) or e.
    #[allow(clippy::approx_constant)]
    fn control_points(self) -> &'static [[f32; 3]] {
        match self {
            Colormap::Viridis => &[
                [0.267, 0.005, 0.329],
                [0.283, 0.141, 0.458],
                [0.254, 0.265, 0.530],
                [0.207, 0.372, 0.553],
                [0.164, 0.471, 0.558],
                [0.128, 0.567, 0.551],
                [0.135, 0.659, 0.518],
                [0.267, 0.749, 0.441],
                [0.478, 0.821, 0.318],
                [0.741, 0.873, 0.150],
                [0.993, 0.906, 0.144],
            ],
            Colormap::Gray => &[[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]],
            Colormap::CoolWarm => &[[0.230, 0.299, 0.754], [0.865, 0.865, 0.865], [0.706, 0.016, 0.150]],
            // As many control points as table entries, so that entry k is point k.
            Colormap::Categories => &[
                [0.122, 0.467, 0.706],
                [1.000, 0.498, 0.055],
                [0.173, 0.627, 0.173],
                [0.839, 0.153, 0.157],
                [0.580, 0.404, 0.741],
                [0.549, 0.337, 0.294],
                [0.890, 0.467, 0.761],
                [0.498, 0.498, 0.498],
                [0.737, 0.741, 0.133],
                [0.090, 0.745, 0.812],
                [0.682, 0.780, 0.910],
                [1.000, 0.733, 0.471],
                [0.596, 0.875, 0.541],
                [1.000, 0.596, 0.588],
                [0.773, 0.690, 0.835],
                [0.769, 0.612, 0.580],
            ],
        }
    }

    /// The linear RGB color at `t` in [0, 1] (clamped): the sRGB control points interpolated,
    /// then decoded.
    pub fn color(self, t: f32) -> [f32; 3] {
        let points = self.control_points();
        let x = t.clamp(0.0, 1.0) * (points.len() - 1) as f32;
        let k = (x as usize).min(points.len() - 2);
        let f = x - k as f32;
        let decode = |c: f32| if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) };
        std::array::from_fn(|c| decode(points[k][c] * (1.0 - f) + points[k + 1][c] * f))
    }

    /// `COLORMAP_ENTRIES` linear RGB entries from 0 to 1, as the shaders interpolate them.
    pub fn table(self) -> [[f32; 4]; COLORMAP_ENTRIES] {
        std::array::from_fn(|k| {
            let [r, g, b] = self.color(k as f32 / (COLORMAP_ENTRIES - 1) as f32);
            [r, g, b, 1.0]
        })
    }
}

/// Entries of a colormap's table in the geometry passes' uniform.
pub const COLORMAP_ENTRIES: usize = 16;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_category_is_its_own_table_entry() {
        let table = Colormap::Categories.table();
        let points = Colormap::Categories.control_points();
        assert_eq!(points.len(), COLORMAP_ENTRIES);
        for (entry, point) in table.iter().zip(points) {
            let expected = point.map(|c| if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) });
            for c in 0..3 {
                assert!((entry[c] - expected[c]).abs() < 1e-6, "{entry:?} against {expected:?}");
            }
        }
    }
}
