//! WGSL sources, embedded at compile time, and the one-line `#import path` directive that lets a
//! pass shader include code from `shaders/shared/` instead of pasting it.
//!
//! Imports are resolved recursively, each file at most once per composed module, before the
//! source reaches naga; the naga validation test composes every file the same way.

use std::borrow::Cow;

/// The WGSL files of the shared passes (under `shaders/`), by path relative to that folder;
/// each method's are in its folder and its [`Library`].
const SHARED: &[(&str, &str)] = &[
    ("shared/billboard.wgsl", include_str!("../../shaders/shared/billboard.wgsl")),
    ("shared/clusters.wgsl", include_str!("../../shaders/shared/clusters.wgsl")),
    ("shared/cone.wgsl", include_str!("../../shaders/shared/cone.wgsl")),
    ("shared/fullscreen.wgsl", include_str!("../../shaders/shared/fullscreen.wgsl")),
    ("shared/gbuffer.wgsl", include_str!("../../shaders/shared/gbuffer.wgsl")),
    ("shared/geometry.wgsl", include_str!("../../shaders/shared/geometry.wgsl")),
    ("shared/lighting.wgsl", include_str!("../../shaders/shared/lighting.wgsl")),
    ("shared/line_strip.wgsl", include_str!("../../shaders/shared/line_strip.wgsl")),
    ("shared/nd.wgsl", include_str!("../../shaders/shared/nd.wgsl")),
    ("shared/object_ao.wgsl", include_str!("../../shaders/shared/object_ao.wgsl")),
    ("shared/pieces.wgsl", include_str!("../../shaders/shared/pieces.wgsl")),
    ("shared/view.wgsl", include_str!("../../shaders/shared/view.wgsl")),
    ("shared/vo.wgsl", include_str!("../../shaders/shared/vo.wgsl")),
    ("shared/vo_pass.wgsl", include_str!("../../shaders/shared/vo_pass.wgsl")),
    ("bilateral.wgsl", include_str!("../../shaders/bilateral.wgsl")),
    ("composite.wgsl", include_str!("../../shaders/composite.wgsl")),
    ("cull.wgsl", include_str!("../../shaders/cull.wgsl")),
    ("depth_pyramid.wgsl", include_str!("../../shaders/depth_pyramid.wgsl")),
    ("line_geometry.wgsl", include_str!("../../shaders/line_geometry.wgsl")),
    ("lines.wgsl", include_str!("../../shaders/lines.wgsl")),
    ("meshes.wgsl", include_str!("../../shaders/meshes.wgsl")),
    ("nd_from_depth.wgsl", include_str!("../../shaders/nd_from_depth.wgsl")),
    ("nd_pyramid.wgsl", include_str!("../../shaders/nd_pyramid.wgsl")),
    ("raster.wgsl", include_str!("../../shaders/raster.wgsl")),
    ("seed_depth.wgsl", include_str!("../../shaders/seed_depth.wgsl")),
    ("slices.wgsl", include_str!("../../shaders/slices.wgsl")),
    ("strip.wgsl", include_str!("../../shaders/strip.wgsl")),
    ("transparency.wgsl", include_str!("../../shaders/transparency.wgsl")),
    ("tubes.wgsl", include_str!("../../shaders/tubes.wgsl")),
    ("volume_ao.wgsl", include_str!("../../shaders/volume_ao.wgsl")),
];

/// WGSL functions a host renderer can paste into (or concatenate with) its own shaders to write
/// the ND map and zoom map of docs/reference.md: `gbuffer_nd`, `gbuffer_zoom`, `gbuffer_depth`,
/// `gbuffer_line_normal`, `gbuffer_eye_direction` (`shaders/shared/gbuffer.wgsl`; no bindings,
/// no imports).
pub const GBUFFER_WGSL: &str = include_str!("../../shaders/shared/gbuffer.wgsl");

/// A number Rust and WGSL share, written into WGSL by Rust ([`CONSTANTS`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Constant {
    /// A float constant.
    F32(f32),
    /// An unsigned constant.
    U32(u32),
}

/// The file, made by Rust, of the constants that the CPU reference and the shaders share: a
/// shader that says `#import rust/constants.wgsl` gets the passes' ([`PASS_CONSTANTS`]) and its
/// method's ([`Library::constants`]) as WGSL `const`s, so no number is written twice.
pub const CONSTANTS: &str = "rust/constants.wgsl";

/// The side of the tiles in which the slices mark their pixels for the bilateral blur.
pub const SLICE_TILE: u32 = 8;

/// The corners of the polygon a transparent slice is drawn as.
pub const OUTLINE_SIDES: usize = 32;

/// The passes' shared numbers.
pub const PASS_CONSTANTS: &[(&str, Constant)] =
    &[("SLICE_TILE", Constant::U32(SLICE_TILE)), ("OUTLINE_SIDES", Constant::U32(OUTLINE_SIDES as u32))];

/// What a composed shader draws on besides the shared files: a method's own WGSL files and the
/// numbers its WGSL shares with its CPU reference (each method's registry entry holds its own).
#[derive(Clone, Copy, Debug)]
pub struct Library {
    /// Its WGSL files, by the name its shaders import them under.
    pub files: &'static [(&'static str, &'static str)],
    /// The numbers Rust writes into its WGSL ([`CONSTANTS`]).
    pub constants: &'static [(&'static str, Constant)],
}

impl Library {
    /// The shared files alone.
    pub const SHARED: Library = Library { files: &[], constants: &[] };

    /// Its file `path` (or a shared one), to compose.
    pub fn source(self, path: &str) -> Source<'_> {
        Source { path, library: self }
    }
}

/// A WGSL file to compose, and the library its imports are found in: a shared pass's file is
/// its path (`"cull.wgsl".into()`), a method's is [`Library::source`].
#[derive(Clone, Copy, Debug)]
pub struct Source<'a> {
    /// The path relative to `shaders/`, or a method's file name.
    pub path: &'a str,
    /// The library beyond the shared files.
    pub library: Library,
}

impl<'a> From<&'a str> for Source<'a> {
    fn from(path: &'a str) -> Source<'a> {
        Source { path, library: Library::SHARED }
    }
}

/// [`CONSTANTS`]' text for `library`: `const NAME: f32 = …;` per constant, each f32 written
/// with as many digits as give it back exactly.
pub fn constants(library: &Library) -> String {
    let all = library.constants.iter().chain(PASS_CONSTANTS);
    all.map(|(name, value)| match value {
        Constant::F32(v) => format!("const {name}: f32 = {v:?};\n"),
        Constant::U32(v) => format!("const {name}: u32 = {v}u;\n"),
    })
    .collect()
}

/// Files that are a pass's body rather than a module: they use what their importer defines (VO's
/// entry point calls its method's `obscurance`; object-space AO reads its importer's table), so
/// they validate within their importers only.
#[cfg(test)]
pub(crate) const FRAGMENTS: &[&str] = &["shared/vo_pass.wgsl", "shared/object_ao.wgsl"];

/// The embedded WGSL files `library` composes from, (name, source): the shared ones, then its own.
pub fn files(library: &Library) -> impl Iterator<Item = (&'static str, &'static str)> {
    SHARED.iter().chain(library.files).copied()
}

/// The embedded source of `path` (relative to `shaders/`, or a file of `library`), without
/// imports resolved.
pub fn raw(path: &str, library: &Library) -> Option<&'static str> {
    files(library).find(|(p, _)| *p == path).map(|(_, s)| s)
}

/// `source` with every `#import` resolved. Panics only on a missing import, which the naga test
/// catches for every embedded file.
pub fn compose<'a>(source: impl Into<Source<'a>>) -> String {
    let source = source.into();
    let mut out = String::new();
    let mut seen = Vec::new();
    append(source.path, &source.library, &mut out, &mut seen);
    out
}

fn append(path: &str, library: &Library, out: &mut String, seen: &mut Vec<String>) {
    if seen.iter().any(|p| p == path) {
        return;
    }
    seen.push(path.to_owned());
    if path == CONSTANTS {
        return out.push_str(&constants(library));
    }
    let source = raw(path, library).unwrap_or_else(|| panic!("WGSL file {path} is not embedded"));
    for line in source.lines() {
        match line.trim().strip_prefix("#import ") {
            Some(import) => append(import.trim(), library, out, seen),
            None => {
                out.push_str(line);
                out.push('\n');
            }
        }
    }
}

/// A shader module from the composed `source`, labelled `lineao::<path>`.
pub fn module<'a>(device: &wgpu::Device, source: impl Into<Source<'a>>) -> wgpu::ShaderModule {
    module_with(device, source, &[])
}

/// [`module`] with textual `replacements` (from, to) applied: a binding's type that override
/// constants cannot change (e.g. `texture_depth_2d` → `texture_depth_multisampled_2d`).
pub fn module_with<'a>(
    device: &wgpu::Device,
    source: impl Into<Source<'a>>,
    replacements: &[(&str, &str)],
) -> wgpu::ShaderModule {
    let source = source.into();
    let composed = replacements.iter().fold(compose(source), |s, (from, to)| s.replace(from, to));
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(&format!("lineao::{}", source.path)),
        source: wgpu::ShaderSource::Wgsl(Cow::Owned(composed)),
    })
}

/// In a test: asserts that the `#[repr(C)]` Rust struct `$rust` has the memory layout of the
/// WGSL struct `$wgsl` of the composed shader `$file`, as naga lays it out: the same size and,
/// member by member, the same names and byte offsets (padding members, whose names start with
/// `_`, left out on both sides). List every field of `$rust` but its padding: a field added on
/// one side only, renamed or reordered fails it.
#[cfg(test)]
macro_rules! assert_wgsl_layout {
    ($rust:ty, $file:expr, $wgsl:literal, [$($field:ident),+ $(,)?]) => {
        $crate::shader::check_layout(
            $file,
            $wgsl,
            std::mem::size_of::<$rust>(),
            &[$((stringify!($field), std::mem::offset_of!($rust, $field))),+],
        )
    };
}
#[cfg(test)]
pub(crate) use assert_wgsl_layout;

/// [`assert_wgsl_layout`]'s check: `fields` (name, offset) and `size` against naga's layout of
/// `wgsl` in the composed `file`.
#[cfg(test)]
pub(crate) fn check_layout<'a>(file: impl Into<Source<'a>>, wgsl: &str, size: usize, fields: &[(&str, usize)]) {
    let file = file.into();
    let source = compose(file);
    let file = file.path;
    let module =
        naga::front::wgsl::parse_str(&source).unwrap_or_else(|e| panic!("{file}: {}", e.emit_to_string(&source)));
    let (members, span) = module
        .types
        .iter()
        .find_map(|(_, ty)| match (&ty.name, &ty.inner) {
            (Some(name), naga::TypeInner::Struct { members, span }) if name == wgsl => Some((members, *span)),
            _ => None,
        })
        .unwrap_or_else(|| panic!("no struct {wgsl} in {file}"));
    let wgsl_fields: Vec<(&str, usize)> = members
        .iter()
        .filter_map(|m| m.name.as_deref().map(|n| (n, m.offset as usize)))
        .filter(|(n, _)| !n.starts_with('_'))
        .collect();
    let rust_fields: Vec<(&str, usize)> = fields.iter().copied().filter(|(n, _)| !n.starts_with('_')).collect();
    assert_eq!(rust_fields, wgsl_fields, "{wgsl} in {file}: fields (name, offset), Rust then WGSL");
    assert_eq!(size, span as usize, "{wgsl} in {file}: size, Rust then WGSL");
}

/// In a test: asserts that a vertex buffer of `$rust` with `$attributes` (the pipeline's
/// `VertexBufferLayout`, stride the struct's size) is what the WGSL vertex input `$wgsl` of the
/// composed shader `$file` reads: attribute k at field k's offset and as wide as it, and each
/// attribute's location a member of the WGSL struct holding as many floats as its format.
/// List the fields in location order.
#[cfg(test)]
macro_rules! assert_vertex_layout {
    ($rust:ty, $file:expr, $wgsl:literal, $attributes:expr, [$($field:ident),+ $(,)?]) => {{
        fn width<T, F>(_: fn(&T) -> &F) -> usize {
            std::mem::size_of::<F>()
        }
        $crate::shader::check_vertex_layout(
            $file,
            $wgsl,
            std::mem::size_of::<$rust>(),
            &$attributes,
            &[$((std::mem::offset_of!($rust, $field), width(|v: &$rust| &v.$field))),+],
        )
    }};
}
#[cfg(test)]
pub(crate) use assert_vertex_layout;

/// [`assert_vertex_layout`]'s check: `fields` (offset, size) against `attributes`, and those
/// against the locations of `wgsl` in the composed `file`.
#[cfg(test)]
pub(crate) fn check_vertex_layout<'a>(
    file: impl Into<Source<'a>>,
    wgsl: &str,
    size: usize,
    attributes: &[wgpu::VertexAttribute],
    fields: &[(usize, usize)],
) {
    let floats = |format: wgpu::VertexFormat| match format {
        wgpu::VertexFormat::Float32 => 1,
        wgpu::VertexFormat::Float32x2 => 2,
        wgpu::VertexFormat::Float32x3 => 3,
        wgpu::VertexFormat::Float32x4 | wgpu::VertexFormat::Snorm16x4 | wgpu::VertexFormat::Unorm8x4 => 4,
        other => panic!("{other:?}: add its float count"),
    };
    let rust: Vec<(u64, u64)> = fields.iter().map(|&(offset, width)| (offset as u64, width as u64)).collect();
    let declared: Vec<(u64, u64)> = attributes.iter().map(|a| (a.offset, a.format.size())).collect();
    assert_eq!(declared, rust, "{wgsl}'s attributes (offset, size), then the Rust fields'");
    let end = attributes.iter().map(|a| a.offset + a.format.size()).max().unwrap_or(0);
    assert!(end as usize <= size, "{wgsl}: the attributes end at {end}, past the struct's {size} bytes");
    let file = file.into();
    let source = compose(file);
    let file = file.path;
    let module =
        naga::front::wgsl::parse_str(&source).unwrap_or_else(|e| panic!("{file}: {}", e.emit_to_string(&source)));
    let members = module
        .types
        .iter()
        .find_map(|(_, ty)| match (&ty.name, &ty.inner) {
            (Some(name), naga::TypeInner::Struct { members, .. }) if name == wgsl => Some(members.clone()),
            _ => None,
        })
        .unwrap_or_else(|| panic!("no struct {wgsl} in {file}"));
    let read: Vec<(u32, u32)> = members
        .iter()
        .filter_map(|m| match (&m.binding, &module.types[m.ty].inner) {
            (Some(naga::Binding::Location { location, .. }), naga::TypeInner::Vector { size, scalar })
                if scalar.kind == naga::ScalarKind::Float =>
            {
                Some((*location, *size as u32))
            }
            (Some(naga::Binding::Location { location, .. }), naga::TypeInner::Scalar(scalar))
                if scalar.kind == naga::ScalarKind::Float =>
            {
                Some((*location, 1))
            }
            _ => None,
        })
        .collect();
    let given: Vec<(u32, u32)> = attributes.iter().map(|a| (a.shader_location, floats(a.format))).collect();
    assert_eq!(given, read, "{wgsl} in {file}: (location, floats) given, then read");
}

#[cfg(test)]
mod tests;
