//! The list of methods, one line each, and [`AoMethod`] made of it.
//!
//! A line names the method's variant, its folder (`method/<folder>/`, whose `METHOD` is its
//! [`super::MethodInfo`]) and — when it has settings of its own — the field of
//! [`crate::ChainSettings`] that holds them and their type in that folder (`{ field: Type }`,
//! the `--settings` JSON's key). A method is its folder and one line here.
//!
//! The list is handed to a macro (`for_each_method!(callback)`), so that each part of the
//! crate takes from it what it needs at its own level: here the enum, in
//! [`crate::settings`] the chain's fields, in [`super`] what the registry holds of each method
//! ([`AoMethod::info`]). The list itself names nothing: a line's folder and type are paths
//! only where a callback makes them.

/// The methods, in the order front ends list them (see the module documentation).
macro_rules! for_each_method {
    ($callback:ident) => {
        $callback! {
            /// Plain lines (with the illuminated-lines specular), no occlusion.
            None => none,
            /// LineAO (Eichelbaum et al. 2013).
            LineAo => line_ao { line_ao: LineAoSettings },
            /// Volumetric Obscurance with line samples (Loos & Sloan 2010, §4.1).
            VoLine => vo_line { vo: VoSettings },
            /// Volumetric Obscurance with area samples over a pyramid of depth moments (§4.2),
            /// with VO line's settings.
            VoArea => vo_area,
            /// Crytek SSAO (Mittring 2007), the LineAO paper's baseline, with its 4 × 4 blur.
            Ssao => ssao { ssao: SsaoSettings },
            /// Ray-traced AO on the GPU, progressive: the ground truth ([`crate::truth`]) where
            /// the view rests. Rays go through the scene, not the screen, so it needs no guard band.
            RayTraced => raytraced { raytraced: RayTracedSettings },
            /// A method made by the registry alone, which the tests find everywhere methods are
            /// listed (feature `toy-method`, for tests only).
            #[cfg(any(test, feature = "toy-method"))]
            Toy => toy { toy: ToySettings },
        }
    };
}
pub(crate) use for_each_method;

/// Makes [`AoMethod`] of the list.
macro_rules! ao_method {
    ($( $(#[doc = $doc:literal])* $(#[cfg($cfg:meta)])? $variant:ident => $folder:ident $({ $($own:tt)* })? ),+ $(,)?) => {
        /// Which ambient occlusion the chain computes: one variant per method of the registry
        /// ([`crate::method`]), each described by [`AoMethod::info`].
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum AoMethod {
            $( $(#[doc = $doc])* $(#[cfg($cfg)])? $variant, )+
        }

        impl AoMethod {
            /// Every method, in the registry's order.
            pub const REGISTRY: &'static [AoMethod] = &[$( $(#[cfg($cfg)])? AoMethod::$variant, )+];

            /// The methods built for tests only (behind a feature), which a user's build lacks:
            /// generated docs leave them out.
            pub const FOR_TESTS: &'static [AoMethod] = &[$( $( #[cfg($cfg)] AoMethod::$variant, )? )+];
        }
    };
}

for_each_method!(ao_method);

impl Default for AoMethod {
    /// LineAO.
    fn default() -> AoMethod {
        AoMethod::LineAo
    }
}
