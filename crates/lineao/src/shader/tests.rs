//! The shader tests: every WGSL file parses and validates with naga, imports resolved — no GPU needed.

use std::path::Path;

use super::Library;

/// The capabilities a file's module is made with: the device's 64-bit atomics for the lines
/// rasterized in compute (made only where the device has them), WebGPU's `pack2x16float` for
/// the transparent lines' K-buffer (which wgpu grants every device but the oldest GL), the
/// defaults for every other.
fn capabilities(path: &str) -> naga::valid::Capabilities {
    use naga::valid::Capabilities;
    match path {
        "raster.wgsl" => {
            Capabilities::default() | Capabilities::SHADER_INT64 | Capabilities::SHADER_INT64_ATOMIC_MIN_MAX
        }
        "transparency.wgsl" => Capabilities::default() | Capabilities::SHADER_FLOAT16_IN_FLOAT32,
        _ => Capabilities::default(),
    }
}

/// The shared files, then each method's with the library it composes them in.
fn libraries() -> impl Iterator<Item = (Library, Vec<(&'static str, &'static str)>)> {
    let shared = std::iter::once((Library::SHARED, super::files(&Library::SHARED).collect()));
    let methods = crate::AoMethod::REGISTRY.iter().map(|m| m.info().library).map(|l| (l, l.files.to_vec()));
    shared.chain(methods)
}

fn validate(path: &str, library: Library) -> Result<(), String> {
    let source = super::compose(library.source(path));
    let module = naga::front::wgsl::parse_str(&source).map_err(|e| e.emit_to_string(&source))?;
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), capabilities(path))
        .validate(&module)
        .map_err(|e| e.emit_to_string(&source))?;
    Ok(())
}

#[test]
fn every_wgsl_file_validates() {
    let modules = libraries().flat_map(|(library, files)| files.into_iter().map(move |(path, _)| (library, path)));
    let failures: Vec<String> = modules
        .filter(|(_, path)| !super::FRAGMENTS.contains(path))
        .filter_map(|(library, path)| validate(path, library).err().map(|e| format!("{path}:\n{e}")))
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // A fragment validates within the modules that import it: at least one does.
    for fragment in super::FRAGMENTS {
        let import = format!("#import {fragment}");
        let importers =
            libraries().flat_map(|(_, files)| files).filter(|(_, source)| source.lines().any(|l| l.trim() == import));
        assert!(importers.count() > 0, "{fragment} is imported by no module");
    }
}

/// The shared passes' files under `shaders/` (by path relative to it) and each method's in its
/// folder `src/method/<name>/` (by file name).
#[test]
fn every_wgsl_file_on_disk_is_embedded() {
    let crate_root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let shaders = crate_root.join("shaders");
    let mut folders = vec![(shaders.clone(), shaders.clone()), (shaders.join("shared"), shaders.clone())];
    for entry in std::fs::read_dir(crate_root.join("src/method")).unwrap() {
        let dir = entry.unwrap().path();
        // The toy method (`method/toy/`) is registered with the feature `toy-method` only.
        let registered = !dir.ends_with("toy") || crate::AoMethod::from_name("toy").is_some();
        if dir.is_dir() && registered {
            folders.push((dir.clone(), dir));
        }
    }
    let mut on_disk = Vec::new();
    for (dir, root) in folders {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "wgsl") {
                let name = path.strip_prefix(&root).unwrap().to_string_lossy().replace('\\', "/");
                on_disk.push((name, std::fs::read_to_string(&path).unwrap()));
            }
        }
    }
    on_disk.sort();
    let mut embedded: Vec<(String, String)> =
        libraries().flat_map(|(_, files)| files).map(|(p, s)| (p.to_string(), s.to_string())).collect();
    embedded.sort();
    let names = |files: &[(String, String)]| files.iter().map(|(p, _)| p.clone()).collect::<Vec<_>>();
    assert_eq!(names(&on_disk), names(&embedded));
    for ((path, on_disk), (_, embedded)) in on_disk.iter().zip(&embedded) {
        assert_eq!(on_disk, embedded, "{path} is stale");
    }
}

#[test]
fn a_broken_shader_is_reported() {
    // The check above can fail: naga rejects a type error in a composed module.
    let source = "fn f() -> f32 { return vec2<f32>(1.0); }";
    let module = naga::front::wgsl::parse_str(source).unwrap();
    let result = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default())
        .validate(&module);
    assert!(result.is_err());
}

/// The check fails on a reordered field: a Rust struct whose first two fields are swapped
/// against `Levels` (shared/nd.wgsl: scale, then size).
#[test]
#[should_panic(expected = "fields (name, offset)")]
fn a_reordered_field_fails_the_layout_check() {
    #[repr(C)]
    struct Swapped {
        size: [[u32; 4]; 5],
        scale: [[f32; 4]; 5],
    }
    super::assert_wgsl_layout!(Swapped, "shared/nd.wgsl", "Levels", [size, scale]);
}

/// The vertex check fails on an attribute at another field's offset.
#[test]
#[should_panic(expected = "attributes (offset, size)")]
fn a_vertex_attribute_at_the_wrong_offset_fails() {
    #[repr(C)]
    struct Vertex {
        normal: [f32; 3],
        position: [f32; 3],
    }
    let attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3];
    super::assert_vertex_layout!(Vertex, "meshes.wgsl", "MeshVertex", attributes, [position, normal]);
}
