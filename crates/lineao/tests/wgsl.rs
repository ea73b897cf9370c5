//! Every WGSL file parses and validates with naga, imports resolved — no GPU needed.

use std::path::Path;

fn validate(path: &str) -> Result<(), String> {
    let source = lineao::shader::compose(path);
    let module = naga::front::wgsl::parse_str(&source).map_err(|e| e.emit_to_string(&source))?;
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default())
        .validate(&module)
        .map_err(|e| e.emit_to_string(&source))?;
    Ok(())
}

#[test]
fn every_wgsl_file_validates() {
    let failures: Vec<String> = lineao::shader::FILES
        .iter()
        .filter_map(|(path, _)| validate(path).err().map(|e| format!("{path}:\n{e}")))
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn every_wgsl_file_on_disk_is_embedded() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let mut on_disk = Vec::new();
    for dir in [root.clone(), root.join("shared")] {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "wgsl") {
                on_disk.push(path.strip_prefix(&root).unwrap().to_string_lossy().replace('\\', "/"));
            }
        }
    }
    on_disk.sort();
    let mut embedded: Vec<String> = lineao::shader::FILES.iter().map(|(p, _)| p.to_string()).collect();
    embedded.sort();
    assert_eq!(on_disk, embedded);
    for (path, source) in lineao::shader::FILES {
        assert_eq!(std::fs::read_to_string(root.join(path)).unwrap(), *source, "{path} is stale");
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
